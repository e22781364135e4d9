//! The light-structure pane: a light's polyhedron with what the renderer recorded for it at
//! the picked point (its contour, the BSP tree it looked the silhouette up in).

use super::super::*;
use super::PaneView;

/// Its own state: the structure view's orientation and layers.
#[derive(Default)]
pub struct LightStructurePane {
    pub view: light_view::LightView,
}

impl PaneView for LightStructurePane {
    fn ui(&mut self, ui: &mut Ui, app: &mut AppState) {
        let Some(ctx) = &app.ctx else {
            return;
        };
        let names: Vec<String> = ctx
            .prepared
            .lights
            .iter()
            .map(|&(id, _)| ctx.prepared.objects[id as usize].name.clone())
            .collect();
        egui::ComboBox::from_label("light")
            .selected_text(
                app.selected_light
                    .and_then(|l| names.get(l).cloned())
                    .unwrap_or_else(|| "none".into()),
            )
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut app.selected_light, None, "none");
                for (i, n) in names.iter().enumerate() {
                    ui.selectable_value(&mut app.selected_light, Some(i), n);
                }
            });
        if let Some((obj, point, record)) = app.light_subject() {
            self.view.ui(ui, obj, point, record);
        }
    }
}

impl AppState {
    /// The light the structure pane shows: its prepared object, the picked point and the
    /// light's record there taken whole (a light taken face by face has no outline).
    pub fn light_subject(&self) -> Option<LightSubject<'_>> {
        let ctx = self.ctx.as_ref()?;
        let l = self.selected_light?;
        let &(id, _) = ctx.prepared.lights.get(l)?;
        let obj = &ctx.prepared.objects[id as usize];
        let probe = self.inspector.as_ref().map(|i| &i.probe);
        let point = probe.and_then(|p| p.point).map(|p| p.position);
        let record = probe.and_then(|p| {
            p.recording
                .lights
                .iter()
                .find(|r| r.light == l && r.piece.is_none())
        });
        Some((obj, point, record))
    }
}

/// A light's prepared object, the picked point, and the light's record there.
pub type LightSubject<'a> = (
    &'a crate::shading::PreparedObject,
    Option<glam::DVec3>,
    Option<&'a crate::shading::LightRecord>,
);
