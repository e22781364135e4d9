//! How each pane of the tile tree is drawn: the `egui_tiles` behaviour of the workbench. The
//! panes call the workbench's own views; this file only routes a pane to its view and adds
//! the tab bar's "maximise" button.

use super::WorkbenchApp;
use super::layout::Pane;
use egui::Ui;
use egui_tiles::{SimplificationOptions, TileId, Tiles, UiResponse};

/// The behaviour the tree is drawn with, borrowing the workbench for one frame.
pub(crate) struct PaneHost<'a> {
    pub app: &'a mut WorkbenchApp,
    /// A pane whose "maximise" button was pressed this frame.
    pub maximise: Option<Pane>,
}

impl egui_tiles::Behavior<Pane> for PaneHost<'_> {
    fn pane_ui(&mut self, ui: &mut Ui, _tile_id: TileId, pane: &mut Pane) -> UiResponse {
        self.app.pane_ui(ui, *pane);
        UiResponse::None
    }

    fn tab_title_for_pane(&mut self, pane: &Pane) -> egui::WidgetText {
        pane.title().into()
    }

    fn top_bar_right_ui(
        &mut self,
        tiles: &Tiles<Pane>,
        ui: &mut Ui,
        _tile_id: TileId,
        tabs: &egui_tiles::Tabs,
        _scroll_offset: &mut f32,
    ) {
        // The views are worth a whole window (a lecture hall's projector); the forms are not.
        let Some(active) = tabs
            .active
            .and_then(|id| tiles.get_pane(&id))
            .filter(|p| p.is_view())
        else {
            return;
        };
        if ui
            .small_button("maximise")
            .on_hover_text(format!("Show {} alone (Esc restores)", active.title()))
            .clicked()
        {
            self.maximise = Some(*active);
        }
    }

    fn simplification_options(&self) -> SimplificationOptions {
        SimplificationOptions {
            // Every pane keeps a tab: the handle to drag it elsewhere.
            all_panes_must_have_tabs: true,
            ..Default::default()
        }
    }

    fn min_size(&self) -> f32 {
        60.0
    }
}
