//! `penumbra probe`: one pixel's stages as the JSON debug dump.

use super::args::*;
use super::render::camera;
use super::render::prepared_scene;
use anyhow::{Context, Result};
use std::path::Path;

/// Writes the debug dump of one shading point (`penumbra probe`).
pub fn probe(args: &RenderArgs, pixel: (f64, f64), gh_steps: bool, json: &Path) -> Result<()> {
    let dump = probe_dump(args, Some(pixel), gh_steps)?;
    if let Some(dir) = json.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create directory", dir.display()))?;
    }
    std::fs::write(json, serde_json::to_string_pretty(&dump)?)
        .with_context(|| format!("{}", json.display()))?;
    report(&dump, pixel);
    say!("wrote {}", json.display());
    Ok(())
}

/// The recording of one shading point, as `penumbra render` with the same arguments computes
/// it there, with its Monte Carlo check: the debug dump (`probe`, `figure`). Without a pixel,
/// the penumbra pixel the workbench picks on its own (`inspect::interesting_pixel`).
pub(crate) fn probe_dump(
    args: &RenderArgs,
    pixel: Option<(f64, f64)>,
    gh_steps: bool,
) -> Result<penumbra::inspect::Probe> {
    // Prepared as `penumbra render` prepares the same image (the same environment, LTC table
    // and settings), so that the probe records what that render computes at this pixel.
    let request = super::render::request(args)?;
    let (scene, prepared) = prepared_scene(args, &request)?;
    let cam = camera(&args.camera, &scene)?;
    let ctx = prepared.ctx;
    let pixel = match pixel {
        Some(p) => p,
        None => match penumbra::inspect::interesting_pixel(&ctx, &cam, args.size, 24) {
            Some(p) => p,
            // Lit by the environment alone: the image's centre.
            None if ctx.environment.is_some() => {
                (0.5 * args.size.0 as f64, 0.5 * args.size.1 as f64)
            }
            None => anyhow::bail!(
                "--pixel auto: no pixel of the image is lit by a light (give --pixel X,Y)"
            ),
        },
    };
    // `--derivative OBJECT:AXIS`: the point shaded with its rate, as the derivative's render
    // shades it (the recording then holds the moving edges the sphere's figure draws).
    let motion = match &args.derivative {
        Some(spec) => Some(
            penumbra::render::derivative::parse_motion(&ctx, spec).map_err(anyhow::Error::msg)?,
        ),
        None => None,
    };
    penumbra::inspect::debug_dump_with(
        &ctx,
        &args.scene,
        &cam,
        &request.settings,
        pixel,
        gh_steps,
        motion.as_ref(),
    )
    .map_err(anyhow::Error::msg)
}

/// The dump's numbers on standard output.
fn report(dump: &penumbra::inspect::Probe, pixel: (f64, f64)) {
    say!("radiance {} at pixel {pixel:?}", dump.radiance);
    for l in &dump.lights {
        say!(
            "  light {} '{}': shadowed {} unshadowed {}, visible {:.1} % of {:.4} sr",
            l.light,
            l.name,
            l.shadowed,
            l.unshadowed,
            100.0 * l.visible_fraction(),
            l.solid_angle
        );
    }
    if let Some(d) = &dump.derivative {
        let moving = dump
            .recording
            .lights
            .iter()
            .flat_map(|l| &l.moving_edges)
            .filter(|e| penumbra::views::stages::moves(e))
            .count();
        say!(
            "  derivative {}: rate {} per {}, {moving} moving edges",
            d.label(),
            d.rate,
            if d.axis == penumbra::shading::derivative::Axis::Ry {
                "radian"
            } else {
                "scene unit"
            }
        );
    }
    if let Some(mc) = dump.monte_carlo {
        say!(
            "  Monte Carlo ({} samples): {} ± {} (1σ)",
            mc.samples,
            mc.mean,
            mc.stderr
        );
    }
    if let Some(e) = &dump.environment {
        let env = &dump.recording.environment;
        say!(
            "  environment {} (rotate {}°, scale {}), {}: radiance {}{}",
            e.label,
            e.rotate_deg,
            e.scale,
            e.settings.map_or("", |s| s.method.name()),
            e.radiance,
            if e.filtered_in_render {
                " (before the 5×5 filter)"
            } else {
                ""
            }
        );
        if let Some(s) = &e.sample {
            say!(
                "    E_unshadowed {} E_static {:?} E_occluded {:?} E {}",
                s.unshadowed,
                s.e_static,
                s.occluded,
                s.irradiance
            );
        }
        if let (Some(st), Some(oc)) = (e.exact_static, e.exact_occluded) {
            say!("    exact: E_static {st} E_occluded {oc}");
        }
        let terms = if env.terms.is_empty() {
            &e.exact_terms
        } else {
            &env.terms
        };
        say!(
            "    {} union terms, {} cones ({} merged), {} rays ({} traced)",
            terms.len(),
            env.cones.len(),
            env.merged_cones.len(),
            env.rays.len(),
            env.rays
                .iter()
                .filter(|r| r.outcome != penumbra::shading::RayOutcome::Culled)
                .count()
        );
    }
}
