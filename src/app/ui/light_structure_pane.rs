//! The light-structure pane: a light's polyhedron with what the renderer recorded for it at
//! the picked point (its contour, the BSP tree it looked the silhouette up in).

use super::super::*;
use super::PaneView;

/// Its own state: the light shown, and the structure view's orientation and layers.
#[derive(Default)]
pub struct LightStructurePane {
    pub view: light_view::LightView,
    /// The light shown (index into the prepared lights).
    pub light: Option<usize>,
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
                self.light
                    .and_then(|l| names.get(l).cloned())
                    .unwrap_or_else(|| "none".into()),
            )
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut self.light, None, "none");
                for (i, n) in names.iter().enumerate() {
                    ui.selectable_value(&mut self.light, Some(i), n);
                }
            });
        if let Some((obj, point, record)) = subject(self.light, app) {
            self.view.ui(ui, obj, point, record);
        }
    }
}

impl LightStructurePane {
    /// The light the pane shows: its prepared object, the picked point and the light's record
    /// there taken whole (a light taken face by face has no outline).
    pub(crate) fn subject<'a>(&self, app: &'a AppState) -> Option<LightSubject<'a>> {
        subject(self.light, app)
    }
}

fn subject(light: Option<usize>, app: &AppState) -> Option<LightSubject<'_>> {
    let ctx = app.ctx.as_ref()?;
    let l = light?;
    let &(id, _) = ctx.prepared.lights.get(l)?;
    let obj = &ctx.prepared.objects[id as usize];
    let probe = app.inspector.as_ref().map(|i| &i.probe);
    let point = probe.and_then(|p| p.point).map(|p| p.position);
    let record = probe.and_then(|p| {
        p.recording
            .lights
            .iter()
            .find(|r| r.light == l && r.piece.is_none())
    });
    Some((obj, point, record))
}

impl WorkbenchApp {
    /// Shows the light named `name` in the light structure pane (a status message if none).
    pub fn select_light(&mut self, name: &str) {
        let found = self.app.ctx.as_ref().and_then(|ctx| {
            ctx.prepared
                .lights
                .iter()
                .position(|&(id, _)| ctx.prepared.objects[id as usize].name == name)
        });
        match found {
            Some(l) => {
                self.panes.light_structure.light = Some(l);
                layout::reveal(&mut self.app.tree, Pane::LightStructure);
            }
            None => self.app.status = format!("no light named '{name}'"),
        }
    }
}

/// A light's prepared object, the picked point, and the light's record there.
pub(crate) type LightSubject<'a> = (
    &'a crate::shading::PreparedObject,
    Option<glam::DVec3>,
    Option<&'a crate::shading::LightRecord>,
);
