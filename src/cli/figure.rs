//! `penumbra figure`: a view of one pixel's recording as a figure (`views`), written as SVG,
//! PDF or PNG from the one description.

use super::args::*;
use super::probe::probe_dump;
use anyhow::{Context, Result, bail};
use penumbra::figure::Figure;
use penumbra::inspect::Probe;
use penumbra::views::stages::probe_steps;
use penumbra::views::{FigureRequest, SphereCamera, Style, current_stage, recording_figure};
use std::path::Path;

pub(crate) fn figure(args: &RenderArgs, f: &FigureArgs) -> Result<()> {
    let style = Style::from_name(&f.style)
        .with_context(|| format!("--style {}: expected print or screen", f.style))?;
    let out = &args.out;
    let format = out.extension().and_then(|e| e.to_str()).unwrap_or("");
    if !["svg", "pdf", "png"].contains(&format) {
        bail!(
            "{}: the figure is written as .svg, .pdf or .png",
            out.display()
        );
    }
    let orbit = f.orbit.as_deref().map(parse_orbit).transpose()?;
    // A debug dump in place of the scene: the same figure from the recording.
    let dump_path = Path::new(&args.scene);
    let probe: Probe = if args.scene.ends_with(".json") && dump_path.is_file() {
        let text = std::fs::read_to_string(dump_path)
            .with_context(|| format!("{}: cannot read", dump_path.display()))?;
        Probe::from_json(&text, &args.scene).map_err(anyhow::Error::msg)?
    } else {
        let pixel = match f.pixel.as_str() {
            "auto" => None,
            p => Some(parse_vec2(p).map_err(|e| anyhow::anyhow!("--pixel {p}: {e}"))?),
        };
        // With the GH steps, as the workbench records a pick: the stage numbers are its.
        probe_dump(args, pixel, true)?
    };
    let figure = match f.view.as_str() {
        "light" | "bsp" => light_view_figure(args, &probe, f, style, orbit)?,
        view => {
            let request = FigureRequest {
                view: view.to_string(),
                stage: f.stage,
                difference: f.difference,
                style,
                size: f.figure_size,
                orbit,
                fit: f.fit,
            };
            recording_figure(&probe, &request).map_err(anyhow::Error::msg)?
        }
    };
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create directory", dir.display()))?;
    }
    penumbra::figure::save(&figure, out)?;
    say!(
        "wrote {} ({} view of pixel {:?})",
        out.display(),
        f.view,
        probe.pixel
    );
    Ok(())
}

/// `--orbit YAW,PITCH[,ZOOM]` (degrees).
fn parse_orbit(s: &str) -> Result<SphereCamera> {
    let v: Vec<f32> = s
        .split(',')
        .map(|x| x.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| anyhow::anyhow!("--orbit {s}: expected YAW,PITCH[,ZOOM] in degrees"))?;
    match v[..] {
        [yaw, pitch] | [yaw, pitch, _] if v.iter().all(|x| x.is_finite()) => Ok(SphereCamera {
            yaw: yaw.to_radians(),
            pitch: pitch.to_radians().clamp(-1.5, 1.5),
            zoom: v.get(2).copied().unwrap_or(1.0).clamp(0.1, 100.0),
        }),
        _ => bail!("--orbit {s}: expected YAW,PITCH[,ZOOM] in degrees"),
    }
}

/// The light structure (`--view light`) or its BSP tree's planes (`--view bsp`) of the light
/// of the stage (the first light recorded without --stage). The light's mesh and tree come
/// from the scene, prepared as `penumbra render` prepares it (a dump names its scene); what
/// is drawn on them comes from the recording.
fn light_view_figure(
    args: &RenderArgs,
    probe: &Probe,
    f: &FigureArgs,
    style: Style,
    orbit: Option<SphereCamera>,
) -> Result<Figure> {
    use penumbra::views::light::{LightCamera, light_figure};
    let steps = probe_steps(probe);
    let light = match (&f.light, f.stage) {
        (Some(name), _) => probe
            .lights
            .iter()
            .find(|l| &l.name == name)
            .map(|l| l.light)
            .with_context(|| {
                let names: Vec<&str> = probe.lights.iter().map(|l| l.name.as_str()).collect();
                format!("--light {name}: the lights are {}", names.join(", "))
            })?,
        (None, stage) => {
            let record = current_stage(&steps, stage)
                .map_err(anyhow::Error::msg)?
                .map_or(0, |i| steps[i].record);
            probe
                .recording
                .lights
                .get(record)
                .map(|r| r.light)
                .context("the recording at this point has no light")?
        }
    };
    let scene_name = if args.scene.ends_with(".json") {
        probe.scene.clone()
    } else {
        args.scene.clone()
    };
    // Prepared as `penumbra render` prepares it, the scene a dump names in place of the dump.
    let scene_args = RenderArgs {
        scene: scene_name.clone(),
        ..args.clone()
    };
    let (_, prepared) = super::environment::prepared_scene(&scene_args)
        .with_context(|| format!("the light's mesh comes from the scene '{scene_name}'"))?;
    let ctx = prepared.ctx;
    let &(id, _) = ctx
        .prepared
        .lights
        .get(light)
        .with_context(|| format!("scene '{scene_name}' has no light {light}"))?;
    let obj = &ctx.prepared.objects[id as usize];
    let rec = probe
        .recording
        .lights
        .iter()
        .find(|r| r.light == light && r.piece.is_none());
    let mut camera = LightCamera::default();
    if let Some(o) = orbit {
        (camera.yaw, camera.pitch, camera.zoom) = (o.yaw, o.pitch, o.zoom);
    }
    if f.view == "bsp" {
        camera.levels = 2;
    } else {
        camera.path_planes = false;
    }
    let point = probe.point.map(|p| p.position);
    Ok(light_figure(obj, point, rec, &camera, f.figure_size, style).0)
}
