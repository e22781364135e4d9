//! `penumbra gui`: the workbench's flags, turned into the library's [`RunOptions`].

use super::args::parse_vec2;
use super::choice::choice;
use penumbra::app::RunOptions;
use penumbra::app::layout::Preset;
use penumbra::render::RenderMethod;
use penumbra::scene::environment_spec::EnvMethod;
use std::path::PathBuf;

/// What `penumbra gui` does besides showing the window.
#[derive(Clone, Debug, clap::Args)]
pub(crate) struct GuiArgs {
    /// A penumbra scene file (.toml), a Wavefront OBJ (.obj, with its .mtl), a glTF 2.0 file
    /// (.glb or .gltf), or the name of an embedded scene (default: the last one used).
    scene: Option<String>,
    /// Save a screenshot of the window here once the render has finished, then quit.
    #[arg(long)]
    screenshot: Option<PathBuf>,
    /// With --screenshot: take it after at most this many seconds.
    #[arg(long, default_value_t = penumbra::app::DEFAULT_SCREENSHOT_WAIT)]
    after: f64,
    /// Measure responsiveness (time to the first image after a camera change, UI frame
    /// intervals while rendering, as a `Measurement`), write it here as JSON, then quit.
    #[arg(long)]
    measure: Option<PathBuf>,
    /// Measure the latency of moving an object: drag the occluder of the picked point 12
    /// times (as the handles do) and time each update to the redrawn sphere view and to the
    /// first image, as a `DragMeasurement` in JSON; then quit.
    #[arg(long)]
    measure_drag: Option<PathBuf>,
    /// With --screenshot: first pick the pixel at these fractions of the viewport, e.g. 0.5,0.7.
    #[arg(long, value_parser = parse_vec2, allow_hyphen_values = true)]
    pick: Option<(f64, f64)>,
    /// With --pick: step to this stage (gh, labels, visible, ltc, silhouette:LIGHT for the
    /// silhouette of the light named LIGHT, or a stage number).
    #[arg(long)]
    step: Option<String>,
    /// Open these files at start (bench JSON, reference PFM, debug dump).
    #[arg(long)]
    open: Vec<PathBuf>,
    /// Render method at start.
    #[arg(long, value_parser = choice::<RenderMethod>())]
    method: Option<RenderMethod>,
    /// The environment's shadows at start (the scene needs an environment, or pass --env).
    #[arg(long, value_parser = choice::<EnvMethod>())]
    env_method: Option<EnvMethod>,
    /// Light the scene with this environment at start: sky, sky-sh, an .hdr/.exr file, none.
    #[arg(long)]
    env: Option<String>,
    /// Select this object (by name or index) at start: its move handles show in the viewport.
    #[arg(long)]
    select: Option<String>,
    /// Show this light (by object name) in the light structure view at start.
    #[arg(long)]
    light: Option<String>,
    /// Compute every silhouette at its point instead of reading it from a BSP tree.
    #[arg(long)]
    no_trees: bool,
    /// Zoom the sphere view's flat hemisphere to fit the polygons drawn.
    #[arg(long)]
    fit: bool,
    /// Arrange the tiles by this preset at start: explore, teach, benchmark.
    #[arg(long, value_parser = parse_preset)]
    preset: Option<Preset>,
    /// Once the render has finished, export the lesson of the picked point (the one chosen
    /// at start, or --pick) into this directory: frame_NNN.png, lesson.gif, lesson.md; then quit.
    #[arg(long)]
    export_lesson: Option<PathBuf>,
}

fn parse_preset(s: &str) -> Result<Preset, String> {
    Preset::from_name(s).ok_or_else(|| {
        let names: Vec<&str> = Preset::ALL.iter().map(|p| p.name()).collect();
        format!("no preset '{s}' (presets: {})", names.join(", "))
    })
}

impl GuiArgs {
    /// The workbench's options these flags ask for.
    pub(crate) fn options(self) -> RunOptions {
        RunOptions {
            scene: self.scene,
            screenshot: self.screenshot,
            after: self.after,
            measure: self.measure,
            measure_drag: self.measure_drag,
            pick: self.pick,
            step: self.step,
            open: self.open,
            method: self.method,
            env_method: self.env_method,
            env: self.env,
            select: self.select,
            light: self.light,
            no_trees: self.no_trees,
            fit: self.fit,
            preset: self.preset,
            export_lesson: self.export_lesson,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::{Args, FromArgMatches};

    /// A pick may be negative (outside the viewport, clamped later): `-0.25` is a value, not
    /// a flag.
    #[test]
    fn a_negative_pick_parses_as_a_pair() {
        let cmd = GuiArgs::augment_args(clap::Command::new("gui"));
        let m = cmd
            .try_get_matches_from(["gui", "--pick", "-0.25,0.5", "--method", "per-triangle"])
            .expect("a negative pick parses");
        let opts = GuiArgs::from_arg_matches(&m).unwrap().options();
        assert_eq!(opts.pick, Some((-0.25, 0.5)));
        assert_eq!(opts.method, Some(RenderMethod::PerTriangle));
        assert_eq!(opts.after, penumbra::app::DEFAULT_SCREENSHOT_WAIT);
    }
}
