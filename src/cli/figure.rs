//! `penumbra figure`: a view of one pixel's recording as a figure (`views`), written as SVG or
//! PNG from the one description.

use super::args::*;
use super::probe::probe_dump;
use anyhow::{Context, Result, bail};
use penumbra::inspect::Probe;
use penumbra::views::{self, Style};
use std::path::Path;

#[allow(clippy::too_many_arguments)]
pub(crate) fn figure(
    args: &RenderArgs,
    pixel: Option<(f64, f64)>,
    view: &str,
    difference: usize,
    style: &str,
    size: u32,
    out: &Path,
) -> Result<()> {
    let style = Style::from_name(style)
        .with_context(|| format!("--style {style}: expected print or screen"))?;
    // A debug dump in place of the scene: the same figure from the recording.
    let dump_path = Path::new(&args.scene);
    let dump: Probe = if args.scene.ends_with(".json") && dump_path.is_file() {
        let text = std::fs::read_to_string(dump_path)
            .with_context(|| format!("{}: cannot read", dump_path.display()))?;
        Probe::from_json(&text, &args.scene).map_err(anyhow::Error::msg)?
    } else {
        let pixel = pixel.context("--pixel X,Y is needed to probe a scene")?;
        probe_dump(args, pixel, false)?
    };
    let figure = match view {
        "plane" => {
            let all: Vec<_> = dump
                .recording
                .lights
                .iter()
                .flat_map(|l| &l.set_differences)
                .collect();
            let Some(sd) = all.get(difference) else {
                bail!(
                    "--difference {difference}: the recording has {} set difference(s) at this \
                     point (pick a pixel in a penumbra)",
                    all.len()
                );
            };
            let name = dump
                .occluder_names
                .get(sd.occluder)
                .cloned()
                .unwrap_or_else(|| format!("#{}", sd.occluder));
            views::plane_figure(sd, &name, size, style)
        }
        other => bail!(
            "--view {other}: not available as a figure yet (available: plane); the workbench \
             shows every view"
        ),
    };
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create directory", dir.display()))?;
    }
    match out.extension().and_then(|e| e.to_str()) {
        Some("svg") => std::fs::write(out, penumbra::figure::svg::to_svg(&figure))
            .with_context(|| format!("{}: writing SVG", out.display()))?,
        Some("png") => {
            penumbra::figure::plot::save_pixmap_png(&penumbra::figure::raster::render(&figure), out)
                .with_context(|| format!("{}: writing PNG", out.display()))?
        }
        _ => bail!("{}: the figure is written as .svg or .png", out.display()),
    }
    say!("wrote {}", out.display());
    Ok(())
}
