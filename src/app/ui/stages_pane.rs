//! The stages pane: the stepper through the picked point's recorded stages, the lesson text
//! of the current step, its details, and the lesson export.

use super::super::*;
use super::PaneView;
use crate::inspect::Probe;
use crate::shading::LightRecord;
use crate::views::stages::{Step, StepKind};

/// Draws the picked point's recording; the step shown lives in the inspector.
#[derive(Default)]
pub struct StagesPane;

impl PaneView for StagesPane {
    fn ui(&mut self, ui: &mut Ui, app: &mut AppState) {
        let Some(ins) = &mut app.inspector else {
            ui.label("Click a pixel to inspect its shading point, or open a debug dump.");
            return;
        };
        if let Some(command) = stepper_ui(ui, ins) {
            app.run_command(command);
        }
        let Some(ins) = &app.inspector else {
            return;
        };
        ui.separator();
        lesson_ui(ui, ins);
        step_details_ui(ui, &ins.probe, ins.current());
        ui.separator();
        match &app.lesson_capture {
            Some(c) => {
                let (done, all) = c.progress();
                ui.label(format!("exporting the lesson: {done} of {all} frames…"));
            }
            None => {
                let why_not = crate::app::platform::unavailable_here("exporting a lesson");
                let button = ui
                    .add_enabled(why_not.is_none(), egui::Button::new("Export lesson…"))
                    .on_hover_text(
                        "Every stage of this point as numbered PNG frames, an animated GIF and \
                         the lesson text (lesson.md), for slides",
                    )
                    .on_disabled_hover_text(why_not.unwrap_or_default());
                if button.clicked() {
                    app.run_command(Command::ExportLesson);
                }
            }
        }
    }
}

/// Previous / next / play and the step list (which moves the inspector's step); the command
/// a button asks for, which the caller runs (`AppState::run_command`), as the keys run it.
fn stepper_ui(ui: &mut Ui, ins: &mut Inspector) -> Option<Command> {
    let mut command = None;
    ui.horizontal_wrapped(|ui| {
        let play = if ins.playing { "pause" } else { "play" };
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
        ui.label(match ins.step {
            Some(i) => match ins.group_of(i) {
                Some(g) if ins.groups[g].len > 1 => format!(
                    "stage {}/{}, in group {}/{} ({} stages)",
                    i + 1,
                    ins.steps.len(),
                    g + 1,
                    ins.groups.len(),
                    ins.groups[g].len
                ),
                _ => format!("stage {}/{}", i + 1, ins.steps.len()),
            },
            None => format!(
                "all {} stages in {} groups",
                ins.steps.len(),
                ins.groups.len()
            ),
        });
    });
    // The current stage's label: the group's, where it stands for a closed group.
    let label = ins.step.map(|i| match ins.group_of(i) {
        Some(g) if ins.groups[g].len > 1 && ins.open_group != Some(g) => {
            ins.groups[g].label.clone()
        }
        _ => ins.steps[i].label.clone(),
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
            for (g, group) in ins.groups.iter().enumerate() {
                let here = ins.step.is_some_and(|i| group.contains(i));
                if group.len == 1 {
                    if ui.selectable_label(here, &group.label).clicked() {
                        ins.step = Some(group.first);
                    }
                    continue;
                }
                let open = ins.open_group == Some(g);
                ui.horizontal(|ui| {
                    let arrow = if open { "▾" } else { "▸" };
                    if ui
                        .small_button(format!("{arrow} {}", group.len))
                        .on_hover_text("Step through the group's stages one by one")
                        .clicked()
                    {
                        ins.open_group = if open { None } else { Some(g) };
                    }
                    if ui.selectable_label(here && !open, &group.label).clicked() {
                        ins.step = Some(group.last());
                    }
                });
                if open {
                    for i in group.first..group.first + group.len {
                        ui.horizontal(|ui| {
                            ui.add_space(18.0);
                            let s = &ins.steps[i];
                            if ui.selectable_label(ins.step == Some(i), &s.label).clicked() {
                                ins.step = Some(i);
                            }
                        });
                    }
                }
            }
        });
    command
}

/// The lesson of the current step: what the stage does, its equation, and this point's
/// numbers (text from docs/analytic-pipeline.md, `app::lesson`).
fn lesson_ui(ui: &mut Ui, ins: &Inspector) {
    let Some(step) = ins.current() else {
        ui.label(
            "Step through the stages (next >, or the arrow keys) to read what each one \
             does, its equation, and its numbers at this point.",
        );
        return;
    };
    let Some(l) = lesson::lesson(&ins.probe, step) else {
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

/// How the exact silhouette of the step's mesh (if non-convex) was found, in words.
fn exact_silhouette_text(rec: &LightRecord, step: &Step) -> Option<String> {
    let occluder = match step.kind {
        StepKind::LightSilhouette => None,
        StepKind::OccluderSilhouette { k } => Some(rec.occluder_polygons.get(k)?.0),
        _ => return None,
    };
    let ex = rec.exact.iter().find(|e| e.occluder == occluder)?;
    let crossings = format!(
        "{} apparent intersection(s) (Eq. 4.4, magenta circles: contour edges crossing as \
         seen from the point)",
        ex.crossings.len()
    );
    Some(if ex.from_tree {
        format!(
            "Exact silhouette read from the BSP tree: {crossings}. A tree stores only the \
             result, so no rejected contour pieces are recorded; untick \"silhouettes from \
             BSP trees\" to see them."
        )
    } else {
        format!(
            "Exact silhouette computed at the point: {crossings}; {} contour piece(s) rejected \
             by the ray test (dim red: hidden by the mesh itself).",
            ex.rejected.len()
        )
    })
}

/// What the current step adds in words: how an exact silhouette was found, and at the
/// integral step each lobe's value with its per-edge terms (000 Eq. 9's sum, over 2π).
fn step_details_ui(ui: &mut Ui, probe: &Probe, step: Option<&Step>) {
    let Some(s) = step else {
        return;
    };
    let Some(rec) = probe.recording.lights.get(s.record) else {
        return;
    };
    if let Some(text) = exact_silhouette_text(rec, s) {
        ui.add(egui::Label::new(egui::RichText::new(text).small()).wrap());
    }
    if s.kind == StepKind::Derivative {
        ui.add(
            egui::Label::new(
                RichText::new(
                    "On the sphere: each moving edge of the visible polygon (pink) with an arrow \
                     at its midpoint, v_n times the outward normal, the fastest longest. The \
                     Numbers pane lists each edge's support and shares.",
                )
                .small(),
            )
            .wrap(),
        );
    }
    if s.kind == StepKind::Integral {
        for ((lobe, _, _, integral), (_, terms)) in rec.lobes.iter().zip(&rec.lobe_edge_terms) {
            ui.label(format!("{lobe:?} lobe: ∫ = {integral:.6}; per edge:"));
            for (li, loop_terms) in terms.iter().enumerate() {
                let parts: Vec<String> = loop_terms.iter().map(|t| format!("{t:+.5}")).collect();
                ui.add(egui::Label::new(format!("  loop {li}: {}", parts.join(" "))).wrap());
            }
        }
    }
}
