//! The picked shading point: its numbers, the stage stepper, the sphere view and the planar
//! view of the set differences. Everything shown comes from the [`Probe`] (the renderer's own
//! recording), so a loaded debug dump replays without the scene.

use super::command::Command;
use super::figure_painter::{self, FigureRect};
use super::sphere_view::SphereView;
use crate::inspect::{MonteCarloEstimate, Probe};
use crate::shading::{EnvironmentSide, RayOutcome, SetDifferenceRecord};
use crate::views::stages::{
    GhPhase, Step, StepGroup, StepKind, plane_subject, probe_groups, probe_steps,
};
use crate::views::{Style, plane_figure};
use egui::{RichText, Ui};

/// The picked point and where the stepper stands.
pub struct Inspector {
    pub probe: Probe,
    pub steps: Vec<Step>,
    /// The steps as the stepper lists them: a mesh taken face by face is one group.
    pub groups: Vec<StepGroup>,
    /// The group opened to step through its members one by one.
    pub open_group: Option<usize>,
    /// Index into `steps`; `None` shows every stage at once.
    pub step: Option<usize>,
    pub playing: bool,
    /// Seconds since the last automatic step.
    pub play_clock: f64,
}

impl Inspector {
    pub fn new(probe: Probe) -> Self {
        let steps = probe_steps(&probe);
        let groups = probe_groups(&probe, &steps);
        Inspector {
            probe,
            steps,
            groups,
            open_group: None,
            step: None,
            playing: false,
            play_clock: 0.0,
        }
    }

    pub fn current(&self) -> Option<&Step> {
        self.step.and_then(|i| self.steps.get(i))
    }

    /// The group of step `i`.
    fn group_of(&self, i: usize) -> Option<usize> {
        self.groups.iter().position(|g| g.contains(i))
    }

    /// Where stepping into group `g` lands: its first step when it is open, else the step it
    /// stands at (its last).
    fn entry(&self, g: usize, forwards: bool) -> usize {
        let group = &self.groups[g];
        if self.open_group == Some(g) && forwards {
            group.first
        } else {
            group.last()
        }
    }

    /// The next stage: the next step inside an open group, else the next group.
    pub fn next(&mut self) {
        if self.groups.is_empty() {
            return;
        }
        self.step = Some(match self.step {
            None => self.entry(0, true),
            Some(i) => match self.group_of(i) {
                Some(g) if self.open_group == Some(g) && i < self.groups[g].last() => i + 1,
                Some(g) if g + 1 < self.groups.len() => self.entry(g + 1, true),
                _ => i,
            },
        });
    }

    /// The previous stage: the previous step inside an open group, else the previous group.
    pub fn previous(&mut self) {
        self.step = match self.step.and_then(|i| Some((i, self.group_of(i)?))) {
            Some((i, g)) if self.open_group == Some(g) && i > self.groups[g].first => Some(i - 1),
            Some((_, g)) if g > 0 => Some(self.entry(g - 1, false)),
            _ => None,
        };
    }

    /// Advances the player by `dt` seconds (one step per 0.8 s); stops at the end.
    pub fn tick(&mut self, dt: f64) -> bool {
        if !self.playing {
            return false;
        }
        self.play_clock += dt;
        if self.play_clock < 0.8 {
            return false;
        }
        self.play_clock = 0.0;
        let at_end = self.step.is_some_and(|i| i + 1 >= self.steps.len());
        if at_end {
            self.playing = false;
        } else {
            self.next();
        }
        true
    }

    /// The numbers of the point: per light U and S, solid angles, the MC check.
    pub fn numbers_ui(&self, ui: &mut Ui, monte_carlo: Option<&MonteCarloEstimate>) {
        let p = &self.probe;
        let Some(sp) = p.point else {
            ui.label("The ray hits nothing.");
            return;
        };
        egui::Grid::new("point_numbers")
            .num_columns(2)
            .striped(true)
            .show(ui, |ui| {
                ui.label("pixel");
                ui.label(format!(
                    "({:.1}, {:.1}) of {}×{}",
                    p.pixel.0, p.pixel.1, p.size.0, p.size.1
                ));
                ui.end_row();
                ui.label("object");
                ui.label(p.object_name.clone().unwrap_or_default());
                ui.end_row();
                ui.label("position");
                ui.label(fmt3(sp.position));
                ui.end_row();
                ui.label("normal");
                ui.label(fmt3(sp.normal));
                ui.end_row();
                ui.label("view");
                ui.label(fmt3(sp.view));
                ui.end_row();
                if let Some(m) = &p.material {
                    ui.label("material");
                    ui.label(format!(
                        "{}: kd {} ks {} α {:.3}",
                        m.name,
                        fmt3(m.kd),
                        fmt3(m.ks),
                        m.alpha
                    ));
                    ui.end_row();
                }
                ui.label("radiance");
                ui.label(RichText::new(fmt3(p.radiance)).strong());
                ui.end_row();
                if let Some(c) = &p.correction {
                    // analytic-exact: radiance = LTC + this sampled correction.
                    ui.label("GGX − LTC (sampled)");
                    ui.label(format!(
                        "{} ± {} (95 %, {} directions per light)",
                        fmt3(c.value),
                        fmt3(c.stderr * 1.96),
                        c.samples
                    ));
                    ui.end_row();
                }
                if let Some(mc) = monte_carlo {
                    ui.label("Monte Carlo");
                    ui.label(format!(
                        "{} ± {} (95 %, {} samples)",
                        fmt3(mc.mean + p.emitted),
                        fmt3(mc.stderr * 1.96),
                        mc.samples
                    ));
                    ui.end_row();
                }
            });
        ui.add_space(4.0);
        let corrected = p.correction.is_some();
        egui::Grid::new("light_numbers")
            .num_columns(5 + usize::from(corrected))
            .striped(true)
            .show(ui, |ui| {
                ui.strong("light");
                ui.strong("unshadowed U");
                ui.strong("shadowed S");
                if corrected {
                    ui.strong("GGX − LTC");
                }
                ui.strong("solid angle (sr)");
                ui.strong("visible");
                ui.end_row();
                for l in &p.lights {
                    ui.label(&l.name);
                    ui.label(fmt3(l.unshadowed));
                    ui.label(fmt3(l.shadowed));
                    if corrected {
                        ui.label(fmt3(l.correction));
                    }
                    ui.label(format!("{:.5}", l.solid_angle));
                    ui.label(format!("{:.1} %", 100.0 * l.visible_fraction()));
                    ui.end_row();
                }
            });
    }

    /// The environment's numbers at the point (paper 002): E_unshadowed (Eq. 7), E_static,
    /// E_occluded, E (Eq. 3) and ρ/π·E, the exact integrals beside a ray-traced method's,
    /// and the union terms with their integrals and sums.
    pub fn environment_ui(&self, ui: &mut Ui) {
        let p = &self.probe;
        let Some(e) = &p.environment else {
            return;
        };
        let rec = &p.recording.environment;
        ui.add_space(4.0);
        let method = e.settings.map_or("?", |s| s.method.name());
        ui.strong(format!(
            "environment {} (rotate {:.0}°, scale {}), {method}",
            e.label, e.rotate_deg, e.scale
        ));
        egui::Grid::new("environment_numbers")
            .num_columns(2)
            .striped(true)
            .show(ui, |ui| {
                let mut row = |name: &str, value: String| {
                    ui.label(name);
                    ui.label(value);
                    ui.end_row();
                };
                if let Some(s) = &e.sample {
                    row("E_unshadowed (Eq. 7)", fmt3(s.unshadowed));
                    if let Some(st) = s.e_static {
                        row("E_static", fmt3(st));
                    }
                    if let Some(oc) = s.occluded {
                        row("E_occluded", fmt3(oc));
                    }
                    row("E (Eq. 3)", fmt3(s.irradiance));
                    if let Some(se) = s.stderr {
                        row("standard error of E", fmt3(se));
                    }
                    row("ρ/π · E", fmt3(s.radiance));
                }
                if e.filtered_in_render {
                    row(
                        "",
                        "(the render filters E_occluded 5×5: its pixel differs)".into(),
                    );
                }
                if method != "analytic" {
                    if let Some(st) = e.exact_static {
                        row("exact E_static", fmt3(st));
                    }
                    if let Some(oc) = e.exact_occluded {
                        row("exact E_occluded", fmt3(oc));
                    }
                }
                if !rec.rays.is_empty() {
                    let count = |o: RayOutcome| rec.rays.iter().filter(|r| r.outcome == o).count();
                    row(
                        "rays",
                        format!(
                            "{} traced ({} hit dynamic, {} static, {} escaped), {} culled of {}",
                            rec.rays.len() - count(RayOutcome::Culled),
                            count(RayOutcome::Dynamic),
                            count(RayOutcome::Static),
                            count(RayOutcome::Escaped),
                            count(RayOutcome::Culled),
                            rec.rays.len()
                        ),
                    );
                    row(
                        "cones",
                        format!(
                            "{} (Eq. 4), {} merged (Alg. 1)",
                            rec.cones.len(),
                            rec.merged_cones.len()
                        ),
                    );
                }
            });
        let terms = if rec.terms.is_empty() {
            &e.exact_terms
        } else {
            &rec.terms
        };
        if terms.is_empty() {
            return;
        }
        ui.label(if rec.terms.is_empty() {
            "union terms of the exact method (for comparison):"
        } else {
            "union terms integrated:"
        });
        let name = |i: usize| {
            p.occluder_names
                .get(i)
                .cloned()
                .unwrap_or_else(|| format!("#{i}"))
        };
        egui::Grid::new("environment_terms")
            .num_columns(4)
            .striped(true)
            .show(ui, |ui| {
                ui.strong("term");
                ui.strong("occluder");
                ui.strong("vertices");
                ui.strong("∫ L cos (RGB)");
                ui.end_row();
                for t in terms {
                    ui.label(match t.side {
                        EnvironmentSide::Static => "S_k − S_<k",
                        EnvironmentSide::Dynamic => "D_i − S − D_<i",
                    });
                    ui.label(name(t.occluder));
                    ui.label(t.polygon.vertices().len().to_string());
                    ui.label(fmt3(t.integral));
                    ui.end_row();
                }
                let sums = [
                    (EnvironmentSide::Static, "Σ static"),
                    (EnvironmentSide::Dynamic, "Σ dynamic = E_occluded"),
                ];
                for (side, label) in sums {
                    let sum: glam::DVec3 = terms
                        .iter()
                        .filter(|t| t.side == side)
                        .map(|t| t.integral)
                        .sum();
                    ui.strong(label);
                    ui.label("");
                    ui.label("");
                    ui.strong(fmt3(sum));
                    ui.end_row();
                }
            });
    }

    /// Previous / next / play and the step list; the command a button asks for, which the
    /// caller runs (`AppState::run_command`), as the keys run it.
    pub fn stepper_ui(&mut self, ui: &mut Ui) -> Option<Command> {
        let mut command = None;
        ui.horizontal_wrapped(|ui| {
            let play = if self.playing { "pause" } else { "play" };
            for (text, hover, c) in [
                ("all stages", "Show every stage (Home)", Command::AllStages),
                ("< previous", "Previous stage (←)", Command::PreviousStage),
                ("next >", "Next stage (→)", Command::NextStage),
                (play, "Step automatically (P)", Command::PlayStages),
            ] {
                if ui.button(text).on_hover_text(hover).clicked() {
                    command = Some(c);
                }
            }
            ui.label(match self.step {
                Some(i) => match self.group_of(i) {
                    Some(g) if self.groups[g].len > 1 => format!(
                        "stage {}/{}, in group {}/{} ({} stages)",
                        i + 1,
                        self.steps.len(),
                        g + 1,
                        self.groups.len(),
                        self.groups[g].len
                    ),
                    _ => format!("stage {}/{}", i + 1, self.steps.len()),
                },
                None => format!(
                    "all {} stages in {} groups",
                    self.steps.len(),
                    self.groups.len()
                ),
            });
        });
        // The current stage's label: the group's, where it stands for a closed group.
        let label = self.step.map(|i| match self.group_of(i) {
            Some(g) if self.groups[g].len > 1 && self.open_group != Some(g) => {
                self.groups[g].label.clone()
            }
            _ => self.steps[i].label.clone(),
        });
        if let Some(label) = label {
            // Wrapped at the visible edge: the panel scrolls sideways for its wide tables, and
            // a long stage label would run out of sight.
            let visible = ui.clip_rect().max.x - ui.cursor().min.x;
            ui.scope(|ui| {
                ui.set_max_width(visible);
                ui.add(egui::Label::new(RichText::new(label).strong()).wrap());
            });
        }
        egui::ScrollArea::vertical()
            .id_salt("step_list")
            .max_height(140.0)
            .show(ui, |ui| {
                for (g, group) in self.groups.iter().enumerate() {
                    let here = self.step.is_some_and(|i| group.contains(i));
                    if group.len == 1 {
                        if ui.selectable_label(here, &group.label).clicked() {
                            self.step = Some(group.first);
                        }
                        continue;
                    }
                    let open = self.open_group == Some(g);
                    ui.horizontal(|ui| {
                        let arrow = if open { "▾" } else { "▸" };
                        if ui
                            .small_button(format!("{arrow} {}", group.len))
                            .on_hover_text("Step through the group's stages one by one")
                            .clicked()
                        {
                            self.open_group = if open { None } else { Some(g) };
                        }
                        if ui.selectable_label(here && !open, &group.label).clicked() {
                            self.step = Some(group.last());
                        }
                    });
                    if open {
                        for i in group.first..group.first + group.len {
                            ui.horizontal(|ui| {
                                ui.add_space(18.0);
                                let s = &self.steps[i];
                                if ui
                                    .selectable_label(self.step == Some(i), &s.label)
                                    .clicked()
                                {
                                    self.step = Some(i);
                                }
                            });
                        }
                    }
                }
            });
        command
    }

    /// The lesson of the current step: what the stage does, its equation, and this point's
    /// numbers (text from docs/analytic-pipeline.md, `super::lesson`).
    pub fn lesson_ui(&self, ui: &mut Ui) {
        let Some(step) = self.current() else {
            ui.label(
                "Step through the stages (next >, or the arrow keys) to read what each one \
                 does, its equation, and its numbers at this point.",
            );
            return;
        };
        let Some(l) = super::lesson::lesson(&self.probe, step) else {
            return;
        };
        ui.label(RichText::new(&l.title).strong().size(15.0));
        ui.add(egui::Label::new(&l.text).wrap());
        if !l.equation.is_empty() {
            ui.add_space(4.0);
            ui.add(egui::Label::new(RichText::new(&l.equation).monospace().size(13.0)).wrap());
        }
        if !l.here.is_empty() {
            ui.add_space(4.0);
            ui.add(egui::Label::new(RichText::new(format!("Here: {}", l.here)).strong()).wrap());
        }
    }

    /// The set difference the planar view shows: the current step's, else the last one at
    /// or before the current step, else the first one recorded; with the GH phase stepped.
    fn planar_subject(&self) -> Option<(&SetDifferenceRecord, Option<GhPhase>)> {
        plane_subject(&self.probe, &self.steps, self.step)
    }

    /// Whether the current step is a set difference (the planar view is then the one to see).
    pub fn at_set_difference(&self) -> bool {
        matches!(
            self.current().map(|s| s.kind),
            Some(StepKind::SetDifference { .. })
        )
    }

    /// The header of a view: the layer menu and the current stage's label.
    fn view_header(&self, ui: &mut Ui, sphere: &mut SphereView) {
        ui.horizontal(|ui| {
            sphere.layers_ui(ui, &self.probe);
            let label = match self.current() {
                Some(s) => s.label.clone(),
                None => format!("all {} stages", self.steps.len()),
            };
            ui.add(egui::Label::new(RichText::new(label).strong()).truncate());
        });
    }

    /// The 3D unit sphere at the point, the current step's polygons on it.
    pub fn sphere_pane(&self, ui: &mut Ui, sphere: &mut SphereView) {
        self.view_header(ui, sphere);
        sphere.sphere_ui(ui, &self.probe, self.current());
    }

    /// The hemisphere seen from the normal.
    pub fn hemisphere_pane(&self, ui: &mut Ui, sphere: &mut SphereView) {
        self.view_header(ui, sphere);
        sphere.hemisphere_ui(ui, &self.probe, self.current());
    }

    /// The set difference in the occluder's projection plane, phase by phase.
    pub fn planar_pane(&self, ui: &mut Ui) {
        if self.planar_subject().is_none() {
            ui.label("No occluder is subtracted at this point (Alg. 1 line 12 does not run).");
            return;
        }
        ui.small(
            "The projection plane, compressed radially (q -> q/(1+|q|)): the rim is the horizon.",
        );
        let style = if ui.visuals().dark_mode {
            Style::Screen
        } else {
            Style::Print
        };
        let avail = ui.available_size();
        let side = avail.x.min(avail.y).max(160.0);
        let (rect, _) = ui.allocate_exact_size(egui::Vec2::splat(side), egui::Sense::hover());
        if let Some(fig) = self.plane_figure(side.round() as u32, style) {
            figure_painter::paint(ui.painter(), &fig, FigureRect::fit(&fig, rect));
        }
    }

    /// The projected plane of the set difference at the current step (the last one before
    /// it, or the first), `side` pixels square; `None` when no occluder is subtracted.
    pub fn plane_figure(&self, side: u32, style: Style) -> Option<crate::figure::Figure> {
        let (sd, phase) = self.planar_subject()?;
        let name = self
            .probe
            .occluder_names
            .get(sd.occluder)
            .cloned()
            .unwrap_or_default();
        Some(plane_figure(sd, &name, phase, side, style))
    }
}

pub fn fmt3(v: glam::DVec3) -> String {
    format!("({:.5}, {:.5}, {:.5})", v.x, v.y, v.z)
}
