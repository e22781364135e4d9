//! The environment panel (paper 002): which map lights the scene (none, the embedded sky, its
//! SH projection, or an `.hdr`/`.exr` file), its rotation and scale, and how its shadows are
//! computed. A small self-contained panel in the manner of egui's demo panels: it edits an
//! [`EnvironmentChoice`] and says when the choice changed; the app turns the choice into a
//! lit render context (`MapCache::light`) and restarts the progressive render.

use crate::environment::{EnvMethod, EnvironmentLight, EnvironmentSource, EnvironmentSpec};
use egui::Ui;
use std::path::PathBuf;
use std::sync::Arc;

/// Where the environment's radiance comes from, as the panel offers it.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum MapChoice {
    None,
    Sky,
    SkySh,
    File(PathBuf),
    /// A file's name and content, handed over by the browser (not kept between sessions).
    Content(String, #[serde(skip)] Arc<[u8]>),
}

impl MapChoice {
    /// `none`, `sky`, `sky-sh` or a file path (the command line's `--env`).
    pub fn parse(s: &str) -> Self {
        match EnvironmentSource::from_name(s) {
            _ if s == "none" => MapChoice::None,
            None => MapChoice::None,
            Some(EnvironmentSource::Sky) => MapChoice::Sky,
            Some(EnvironmentSource::SkySh) => MapChoice::SkySh,
            Some(EnvironmentSource::File(p)) => MapChoice::File(p),
        }
    }

    fn label(&self) -> String {
        match self {
            MapChoice::None => "none".into(),
            MapChoice::Sky => EnvironmentSource::Sky.name(),
            MapChoice::SkySh => EnvironmentSource::SkySh.name(),
            MapChoice::File(p) => p
                .file_name()
                .map_or_else(|| p.display().to_string(), |f| f.to_string_lossy().into()),
            MapChoice::Content(name, _) => name.clone(),
        }
    }

    fn source(&self) -> Option<EnvironmentSource> {
        match self {
            MapChoice::None => None,
            MapChoice::Sky => Some(EnvironmentSource::Sky),
            MapChoice::SkySh => Some(EnvironmentSource::SkySh),
            MapChoice::File(p) => Some(EnvironmentSource::File(p.clone())),
            // Read by `MapCache::light` from the content.
            MapChoice::Content(name, _) => Some(EnvironmentSource::File(name.into())),
        }
    }
}

/// The environment as the panel sets it (persisted between sessions; a scene file's
/// `[environment]` replaces it when that scene loads).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EnvironmentChoice {
    pub map: MapChoice,
    /// Rotation about +y, degrees.
    pub rotate_deg: f64,
    pub scale: f64,
    pub method: EnvMethod,
    /// Rays per camera ray (`rt`, `rt-unculled`, `rtao`, `reference`).
    pub spp: u32,
    /// `rt`: the 5×5 cross-bilateral filter on E_occluded (002 Sect. 4).
    pub filter: bool,
}

impl Default for EnvironmentChoice {
    fn default() -> Self {
        EnvironmentChoice {
            map: MapChoice::None,
            rotate_deg: 0.0,
            scale: 1.0,
            method: EnvMethod::Analytic,
            spp: crate::scene::environment_spec::DEFAULT_SPP,
            filter: true,
        }
    }
}

impl EnvironmentChoice {
    /// The choice a scene file's `[environment]` makes (`None`: the scene has none). The
    /// method and rays of `self` are kept where the scene file does not set them.
    pub fn from_spec(&self, spec: Option<&EnvironmentSpec>) -> Self {
        let Some(spec) = spec else {
            return EnvironmentChoice {
                map: MapChoice::None,
                ..self.clone()
            };
        };
        EnvironmentChoice {
            map: match &spec.source {
                EnvironmentSource::Sky => MapChoice::Sky,
                EnvironmentSource::SkySh => MapChoice::SkySh,
                EnvironmentSource::File(p) => MapChoice::File(p.clone()),
            },
            rotate_deg: spec.rotate_deg,
            scale: spec.scale,
            method: spec.method.unwrap_or(self.method),
            spp: spec.spp.unwrap_or(self.spp),
            filter: self.filter,
        }
    }

    /// The render settings of this choice, with the request's default seed (the workbench's
    /// render's, `AppState::request`).
    pub(crate) fn settings(&self) -> crate::render::environment_passes::EnvironmentSettings {
        let mut s = crate::render::environment_passes::EnvironmentSettings::new(
            self.method,
            self.spp.max(1),
            crate::render::request::RenderRequest::default()
                .settings
                .seed,
        );
        s.filter = s.filter && self.filter;
        s
    }
}

/// Loaded maps, so that turning the rotation or the scale does not read the file again.
#[derive(Default)]
pub(crate) struct MapCache {
    loaded: Option<(MapChoice, crate::environment::EnvironmentMap, String)>,
}

impl MapCache {
    /// The light of `choice` (`Ok(None)` for no environment): the map loaded once per source,
    /// rotated, scaled and projected (`EnvironmentLight::from_map`).
    pub(crate) fn light(
        &mut self,
        choice: &EnvironmentChoice,
    ) -> crate::Result<Option<Arc<EnvironmentLight>>> {
        let Some(source) = choice.map.source() else {
            return Ok(None);
        };
        if self
            .loaded
            .as_ref()
            .is_none_or(|(m, _, _)| *m != choice.map)
        {
            let (map, label) = match &choice.map {
                MapChoice::Content(name, bytes) => (
                    crate::environment::EnvironmentMap::from_bytes(bytes, name)?,
                    name.clone(),
                ),
                _ => EnvironmentLight::load_map(&source)?,
            };
            self.loaded = Some((choice.map.clone(), map, label));
        }
        let (_, map, label) = self.loaded.as_ref().expect("just loaded");
        Ok(Some(Arc::new(EnvironmentLight::from_map(
            map.clone()
                .with_rotation(choice.rotate_deg)
                .with_scale(choice.scale),
            label.clone(),
        ))))
    }
}

/// The panel. `ui` returns true when the choice changed (the caller relights and restarts
/// the render).
#[derive(Default)]
pub(crate) struct EnvironmentPanel {
    /// Rotation and scale while their slider is dragged (applied when it is let go: each
    /// change projects the map on SH again and restarts the render).
    rotate_edit: Option<f64>,
    scale_edit: Option<f64>,
    /// "file…" was clicked in the browser: the app opens its picker.
    #[cfg(target_arch = "wasm32")]
    pub wants_file: bool,
}

impl EnvironmentPanel {
    /// The controls over `choice`, with `error` (from the last load) under them; `true` when
    /// the choice changed.
    pub(crate) fn ui(
        &mut self,
        ui: &mut Ui,
        choice: &mut EnvironmentChoice,
        error: Option<&str>,
    ) -> bool {
        let mut changed = false;
        let before = choice.clone();
        ui.horizontal_wrapped(|ui| {
            ui.label("map");
            for (m, tip) in [
                (MapChoice::None, "no environment light"),
                (MapChoice::Sky, "the embedded procedural sky"),
                (
                    MapChoice::SkySh,
                    "the sky's 3-band SH projection: band-limited, so analytic is exact on it",
                ),
            ] {
                let label = m.label();
                if ui
                    .selectable_label(choice.map == m, label)
                    .on_hover_text(tip)
                    .clicked()
                {
                    choice.map = m;
                }
            }
            if let MapChoice::File(_) | MapChoice::Content(..) = &choice.map {
                let _ = ui.selectable_label(true, choice.map.label());
            }
            #[cfg(not(target_arch = "wasm32"))]
            if ui
                .button("file…")
                .on_hover_text("an equirectangular .hdr or .exr map (or drop one on the window)")
                .clicked()
                && let Some(p) = super::platform::pick_file("environment map", &["hdr", "exr"])
            {
                choice.map = MapChoice::File(p);
            }
            // The browser's picker answers later, through the app's inbox.
            #[cfg(target_arch = "wasm32")]
            if ui
                .button("file…")
                .on_hover_text("an equirectangular .hdr or .exr map (or drop one on the page)")
                .clicked()
            {
                self.wants_file = true;
            }
        });
        if choice.map != MapChoice::None {
            let mut rotate = self.rotate_edit.unwrap_or(choice.rotate_deg);
            let r = ui.add(
                egui::Slider::new(&mut rotate, -180.0..=180.0)
                    .suffix("°")
                    .text("rotate about +y"),
            );
            let mut scale = self.scale_edit.unwrap_or(choice.scale);
            let s = ui.add(
                egui::Slider::new(&mut scale, 0.0..=16.0)
                    .logarithmic(true)
                    .text("scale"),
            );
            self.rotate_edit = Some(rotate);
            self.scale_edit = Some(scale);
            if !r.dragged() {
                choice.rotate_deg = rotate;
                self.rotate_edit = None;
            }
            if !s.dragged() {
                choice.scale = scale;
                self.scale_edit = None;
            }
            egui::ComboBox::from_label("shadows")
                .selected_text(choice.method.name())
                .show_ui(ui, |ui| {
                    for m in EnvMethod::ALL {
                        ui.selectable_value(&mut choice.method, m, m.name());
                    }
                });
            if choice.method.is_stochastic() {
                ui.add(
                    egui::Slider::new(&mut choice.spp, 1..=1024)
                        .logarithmic(true)
                        .text("rays per point"),
                );
            }
            if choice.method.is_filterable() {
                ui.checkbox(&mut choice.filter, "5×5 cross-bilateral filter");
            }
        }
        if let Some(e) = error {
            ui.colored_label(egui::Color32::LIGHT_RED, e);
        }
        changed |= *choice != before;
        changed
    }
}
