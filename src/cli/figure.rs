//! `penumbra figure`: a view of one pixel's recording as a figure (`views`), written as SVG,
//! PDF or PNG from the one description.

use super::args::*;
use super::probe::probe_dump;
use anyhow::{Context, Result, bail};
use penumbra::inspect::Probe;
use penumbra::views::{FigureRequest, SphereCamera, Style, recording_figure};
use std::path::Path;

pub fn figure(args: &RenderArgs, f: &FigureArgs) -> Result<()> {
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
    let request = FigureRequest {
        view: f.view.clone(),
        stage: f.stage,
        difference: f.difference,
        light: f.light.clone(),
        style,
        size: f.figure_size,
        orbit,
        fit: f.fit,
    };
    // The light and bsp views draw on the light's mesh and tree: the scene prepared as
    // `penumbra render` prepares it (a dump names its scene).
    let prepared = if matches!(f.view.as_str(), "light" | "bsp") {
        let scene = if args.scene.ends_with(".json") {
            probe.scene.clone()
        } else {
            args.scene.clone()
        };
        let scene_args = RenderArgs {
            scene: scene.clone(),
            ..args.clone()
        };
        let (_, prepared) =
            super::render::prepared_scene(&scene_args, &super::render::request(&scene_args)?)
                .with_context(|| format!("the light's mesh comes from the scene '{scene}'"))?;
        Some(prepared)
    } else {
        None
    };
    let figure = recording_figure(&probe, prepared.as_ref().map(|p| &p.ctx), &request)
        .map_err(anyhow::Error::msg)?;
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
