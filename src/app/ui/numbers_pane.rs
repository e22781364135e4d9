//! The numbers pane: the picked point's numbers (radiance, per light and lobe, the environment
//! terms) and the Monte Carlo check of them.

use super::super::*;
use super::PaneView;

/// Draws the picked point's recorded numbers; no state of its own.
#[derive(Default)]
pub struct NumbersPane;

impl PaneView for NumbersPane {
    fn ui(&mut self, ui: &mut Ui, app: &mut AppState) {
        let Some(ins) = &mut app.inspector else {
            ui.label("Click a pixel to inspect its shading point, or open a debug dump.");
            return;
        };
        ins.numbers_ui(ui, app.monte_carlo.as_ref());
        ins.environment_ui(ui);
        if ui.button("Monte Carlo check (65536 samples)").clicked() {
            app.run_command(Command::MonteCarloCheck);
        }
    }
}
