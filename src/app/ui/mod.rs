//! The panes and bars of the workbench, one file each. A pane is its own type
//! (`PaneView`) in a file named after it, holding only its own view state and drawing
//! itself from the app's state and the picked point's recording; the sphere's two panes and
//! the view state they share are in `sphere/`. The bars (menu, status), dialogs, picking and
//! the lesson capture are `impl AppState` blocks, so that `app/mod.rs` keeps the state and its
//! lifecycle.
//!
//! A new pane: a variant of `layout::Pane` (its title, where the presets put it), a type here
//! in its own file implementing `PaneView`, and its field in [`Panes`].

mod command_palette;
mod dialogs;
mod environment_pane;
mod frame;
mod lesson_capture;
mod light_structure_pane;
mod menu;
mod numbers_pane;
mod picking;
mod planar_pane;
mod plots_pane;
mod scene_pane;
mod settings_pane;
mod sphere;
mod stages_pane;
mod status;
mod viewport_pane;

pub use command_palette::CommandPalette;
pub use environment_pane::EnvironmentPane;
pub use light_structure_pane::LightStructurePane;
pub use numbers_pane::NumbersPane;
pub use planar_pane::PlanarPane;
pub use plots_pane::PlotsPane;
pub use scene_pane::ScenePane;
pub use settings_pane::SettingsPane;
pub use sphere::{HemispherePane, SphereFigure, SpherePane, SphereView};
pub use stages_pane::StagesPane;
pub use viewport_pane::ViewportPane;

use super::AppState;
use super::layout::Pane;
use egui::Ui;

/// What a pane of the picked point says before a pick.
const PICK_FIRST: &str = "Click a pixel of the viewport to see its shading point here.";

/// A pane of the workbench.
pub(crate) trait PaneView {
    /// Draws the pane from `app` (changing it through its methods and commands).
    fn ui(&mut self, ui: &mut Ui, app: &mut AppState);
}

/// One of each pane, with its view state.
#[derive(Default)]
pub struct Panes {
    pub viewport: ViewportPane,
    pub sphere: SpherePane,
    pub hemisphere: HemispherePane,
    pub planar: PlanarPane,
    pub stages: StagesPane,
    pub numbers: NumbersPane,
    pub settings: SettingsPane,
    pub scene: ScenePane,
    pub light_structure: LightStructurePane,
    pub plots: PlotsPane,
    pub environment: EnvironmentPane,
}

impl Panes {
    /// The pane that draws `pane`.
    pub(crate) fn get(&mut self, pane: Pane) -> &mut dyn PaneView {
        match pane {
            Pane::Viewport => &mut self.viewport,
            Pane::Sphere => &mut self.sphere,
            Pane::Hemisphere => &mut self.hemisphere,
            Pane::Planar => &mut self.planar,
            Pane::Stages => &mut self.stages,
            Pane::Numbers => &mut self.numbers,
            Pane::Settings => &mut self.settings,
            Pane::Scene => &mut self.scene,
            Pane::LightStructure => &mut self.light_structure,
            Pane::Plots => &mut self.plots,
            Pane::Environment => &mut self.environment,
        }
    }
}

/// The id of a scrolled pane's scroll area.
fn scroll_id(pane: Pane) -> &'static str {
    match pane {
        Pane::Numbers => "numbers_scroll",
        Pane::Settings => "settings_scroll",
        Pane::Scene => "scene_scroll",
        Pane::LightStructure => "light_scroll",
        Pane::Plots => "plots_scroll",
        Pane::Environment => "env_scroll",
        Pane::Viewport | Pane::Sphere | Pane::Hemisphere | Pane::Planar | Pane::Stages => "pane",
    }
}
