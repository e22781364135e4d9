//! The environment pane: the environment light's map, rotation, scale and method.

use super::super::*;
use super::PaneView;

/// Its own state: the sliders being dragged (`EnvironmentPanel`); the choice itself is a
/// setting, applied by `AppState::set_environment`.
#[derive(Default)]
pub struct EnvironmentPane {
    panel: environment_panel::EnvironmentPanel,
}

impl PaneView for EnvironmentPane {
    fn ui(&mut self, ui: &mut Ui, app: &mut AppState) {
        let mut choice = app.settings.environment.clone();
        if self.panel.ui(ui, &mut choice, app.env_error.as_deref()) {
            app.set_environment(choice);
        }
        #[cfg(target_arch = "wasm32")]
        if std::mem::take(&mut self.panel.wants_file) {
            app.inbox
                .pick(app.wake.clone(), "environment map", &["hdr", "exr"]);
        }
    }
}
