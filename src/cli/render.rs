//! `penumbra render`, `reference` and `compare`: images of a scene, and their comparison.

use super::args::*;
use super::env_options::environment_options;
use anyhow::{Context, Result, bail};
use glam::DVec3;
use penumbra::raster::Image;
use penumbra::raster::io as image_io;
use penumbra::render::request::{PreparedRender, RenderRequest};
use penumbra::render::{RenderContext, RenderSettings};
use penumbra::scene::{Camera, Scene};
use std::path::{Path, PathBuf};

pub fn load_scene(name: &str) -> Result<Scene> {
    let scene = penumbra::scene::scene_file::load_scene_by_name(name)?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    Ok(scene)
}

pub fn camera(args: &CameraArgs, scene: &Scene) -> Result<Camera> {
    let base = scene.camera;
    let pick = |v: Option<DVec3>, f: fn(&Camera) -> DVec3, what: &str| -> Result<DVec3> {
        v.or(base.as_ref().map(f))
            .with_context(|| format!("the scene has no camera: pass --{what}"))
    };
    let cam = Camera {
        eye: pick(args.eye, |c| c.eye, "eye")?,
        target: pick(args.target, |c| c.target, "target")?,
        up: pick(args.up, |c| c.up, "up")?,
        fov_deg: args
            .fov
            .or(base.map(|c| c.fov_deg))
            .context("the scene has no camera: pass --fov")?,
        // A field of view given by flag is vertical, whatever the image's aspect.
        aspect: if args.fov.is_some() {
            None
        } else {
            base.and_then(|c| c.aspect)
        },
    };
    cam.basis().map_err(anyhow::Error::msg)?;
    Ok(cam)
}

pub(crate) fn write_outputs(img: &Image, out: &Path, exposure: f64) -> Result<Vec<PathBuf>> {
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create directory", dir.display()))?;
    }
    let rgb = img.to_rgb32();
    let pfm = out.with_extension("pfm");
    let exr = out.with_extension("exr");
    let png = out.with_extension("png");
    image_io::write_pfm(&pfm, img.width, img.height, &rgb)
        .with_context(|| format!("{}", pfm.display()))?;
    image_io::write_exr(&exr, img.width, img.height, &rgb)?;
    image_io::write_png(&png, img.width, img.height, &rgb, exposure)?;
    Ok(vec![pfm, exr, png])
}

/// `dir/name_stderr.pfm` beside `dir/name.ext`: the standard error of a reference image.
pub(crate) fn stderr_path(out: &Path) -> PathBuf {
    out.with_file_name(format!(
        "{}_stderr.pfm",
        out.file_stem()
            .map(|s| s.to_string_lossy())
            .unwrap_or_default()
    ))
}

/// The request `args` make: the library's defaults ([`RenderRequest::default`]) overridden by
/// what was given, the LTC table named, and the preparation the environment asks for.
pub(crate) fn request(args: &RenderArgs) -> Result<RenderRequest> {
    let defaults = RenderRequest::default();
    Ok(RenderRequest {
        settings: RenderSettings {
            width: args.size.0,
            height: args.size.1,
            aa: args.aa,
            method: args.method,
            spp: args.spp.unwrap_or(defaults.settings.spp),
            seed: args.seed,
            light_sampling: args.light_sampling,
            collect_stats: false,
            exact_u: args.exact_u,
        },
        environment: environment_options(args),
        ltc: super::ltc::ltc_table(&args.ltc_table)?,
        prepare: super::process_env::prepare_config(),
    })
}

/// Loads `args.scene` and prepares it for `request` (`RenderRequest::prepare`: its environment
/// merged, its trees, its LTC table), printing the library's notes.
pub(crate) fn prepared_scene(
    args: &RenderArgs,
    request: &RenderRequest,
) -> Result<(Scene, PreparedRender)> {
    let mut scene = load_scene(&args.scene)?;
    let prepared = request.prepare(&mut scene).map_err(anyhow::Error::msg)?;
    for n in &prepared.notes {
        eprintln!("note: {n}");
    }
    Ok((scene, prepared))
}

pub fn render(args: &RenderArgs) -> Result<()> {
    let request = request(args)?;
    let (scene, prepared) = prepared_scene(args, &request)?;
    let cam = camera(&args.camera, &scene)?;
    if let Some(spec) = &args.derivative {
        return render_derivative(args, &request, prepared, &cam, spec);
    }
    let settings = request.settings;
    let (ctx, env) = (prepared.ctx, prepared.environment);
    let out = super::progress::with_tile_bar(|| ctx.render_full(&cam, &settings, None))
        .map_err(anyhow::Error::msg)?;
    let (img, stats) = (&out.image, out.stats);
    let (nan, inf, neg) = img.invalid_counts();
    let mut files = write_outputs(img, &args.out, args.exposure)?;
    if let Some(err) = &out.stderr {
        let p = stderr_path(&args.out);
        image_io::write_pfm(&p, err.width, err.height, &err.to_rgb32())?;
        files.push(p);
    }
    say!(
        "{} {}x{} aa {} method {}: {:.3} s, {:.0} pixels/s ({} threads)",
        args.scene,
        settings.width,
        settings.height,
        settings.aa,
        settings.method.name(),
        stats.seconds,
        stats.pixels_per_second,
        rayon::current_num_threads()
    );
    if let (Some(env), Some(e)) = (env, &out.environment) {
        let t = &e.stats;
        say!(
            "environment {} method {} spp {}: g-buffer {:.3} s, occlusion {:.3} s, filter {:.3} s, composition {:.3} s; rays traced {} of {}",
            ctx.environment
                .as_ref()
                .map_or("", |x| x.light.label.as_str()),
            env.method.name(),
            env.spp,
            t.gbuffer_seconds,
            t.occlusion_seconds,
            t.filter_seconds,
            t.composition_seconds,
            t.rays_traced,
            t.rays_total
        );
        if let Some(r) = ctx.environment.as_ref().and_then(|x| x.transfer_report) {
            say!("precomputed transfer (PRT) of the static surfaces: {r}");
        }
    }
    if nan + inf + neg > 0 {
        eprintln!("warning: {nan} NaN, {inf} infinite and {neg} negative pixel values");
    }
    if settings.method.analytic().is_some() {
        say!(
            "invariant, shadowed <= unshadowed per light piece: {} violations, {} bounds \
             crossed ({} degenerate fallbacks)",
            stats.violations,
            stats.fallbacks.bounds_crossed,
            stats.fallbacks.degenerate
        );
    }
    if stats.violations > 0 {
        let p = args.out.with_extension("violations.json");
        std::fs::write(&p, serde_json::to_string(&out.violation_pixels)?)
            .with_context(|| format!("writing {}", p.display()))?;
        eprintln!(
            "warning: {} light pieces saw more than the light (a visible polygon not inside the \
             light's: shadowed > unshadowed) at the pixels listed in {}; this is a bug, please \
             report it with the scene",
            stats.violations,
            p.display()
        );
    }
    for f in files {
        say!("wrote {}", f.display());
    }
    Ok(())
}

/// `OUT_suffix.ext` beside `OUT.png`.
fn beside(out: &Path, suffix: &str, ext: &str) -> PathBuf {
    out.with_file_name(format!(
        "{}_{suffix}.{ext}",
        out.file_stem()
            .map(|s| s.to_string_lossy())
            .unwrap_or_default()
    ))
}

/// `penumbra render --derivative OBJECT:AXIS`: the image as usual and its derivative beside
/// it (`render::derivative`).
fn render_derivative(
    args: &RenderArgs,
    request: &RenderRequest,
    prepared: PreparedRender,
    cam: &Camera,
    spec: &str,
) -> Result<()> {
    use penumbra::render::derivative::{parse_motion, write_derivative_png};
    let ctx = prepared.ctx;
    let motion = parse_motion(&ctx, spec).map_err(anyhow::Error::msg)?;
    let settings = request.settings;
    let out =
        super::progress::with_tile_bar(|| ctx.render_derivative(cam, &settings, &motion, None))
            .map_err(anyhow::Error::msg)?;
    let mut files = write_outputs(&out.image, &args.out, args.exposure)?;
    let d = &out.derivative;
    let rgb = d.to_rgb32();
    let (pfm, exr, png) = (
        beside(&args.out, "derivative", "pfm"),
        beside(&args.out, "derivative", "exr"),
        beside(&args.out, "derivative", "png"),
    );
    image_io::write_pfm(&pfm, d.width, d.height, &rgb)
        .with_context(|| format!("{}", pfm.display()))?;
    image_io::write_exr(&exr, d.width, d.height, &rgb)?;
    let unit = if motion.axis == penumbra::shading::derivative::Axis::Ry {
        "radian"
    } else {
        "scene unit"
    };
    write_derivative_png(d, &out.mask, unit, &png).map_err(anyhow::Error::msg)?;
    let mask = beside(&args.out, "derivative_mask", "pfm");
    image_io::write_pfm(&mask, d.width, d.height, &out.mask.to_rgb32())
        .with_context(|| format!("{}", mask.display()))?;
    files.extend([pfm, exr, png, mask]);
    let m = out.masked;
    say!(
        "{} {}x{} aa {} with d/d{} of '{}': {:.3} s ({} threads)",
        args.scene,
        settings.width,
        settings.height,
        settings.aa,
        motion.axis.name(),
        ctx.scene.objects[motion.object as usize].name,
        out.stats.seconds,
        rayon::current_num_threads()
    );
    say!(
        "masked {} of {} pixels: {} see several faces, {} change face within the step, {} \
         degenerate, {} with an unsupported edge, {} at an LTC table node",
        m.pixels,
        settings.width * settings.height,
        m.several_faces,
        m.face_changes,
        m.degenerate,
        m.unsupported,
        m.table_nodes
    );
    for f in files {
        say!("wrote {}", f.display());
    }
    Ok(())
}

pub(crate) fn reference(args: &RenderArgs, samples: u32, seed: u64) -> Result<()> {
    let scene = load_scene(&args.scene)?;
    let cam = camera(&args.camera, &scene)?;
    let request = request(args)?;
    let ctx = RenderContext::for_render(&scene, &request);
    let start = web_time::Instant::now();
    let (img, err) =
        penumbra::reference::render_reference(&ctx, &cam, &request.settings, samples, seed)
            .map_err(anyhow::Error::msg)?;
    say!(
        "reference {}: {samples} samples per light, {:.3} s",
        args.scene,
        start.elapsed().as_secs_f64()
    );
    for f in write_outputs(&img, &args.out, args.exposure)? {
        say!("wrote {}", f.display());
    }
    let stderr_path = stderr_path(&args.out);
    image_io::write_pfm(&stderr_path, err.width, err.height, &err.to_rgb32())?;
    say!("wrote {}", stderr_path.display());
    Ok(())
}

pub fn compare(image: &Path, reference: &Path, stderr: Option<&Path>) -> Result<()> {
    let read = |p: &Path| image_io::read_pfm(p).with_context(|| format!("{}", p.display()));
    let (w, h, a) = read(image)?;
    let (w2, h2, b) = read(reference)?;
    if (w, h) != (w2, h2) {
        bail!(
            "{} is {w}x{h} but {} is {w2}x{h2}",
            image.display(),
            reference.display()
        );
    }
    let s = stderr.map(read).transpose()?;
    let stats = penumbra::render::compare::compare(&a, &b, s.as_ref().map(|s| &s.2[..]));
    say!("{}", serde_json::to_string_pretty(&stats)?);
    Ok(())
}
