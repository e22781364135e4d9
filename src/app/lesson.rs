//! The lesson: a short explanation of each stage of 000 Alg. 1, its equation, and the picked
//! point's numbers. The text is the section "The stages in brief" of
//! `docs/analytic-pipeline.md`, read at compile time: the page is its only copy.
//!
//! Plain data, no egui: the Stages pane draws it, the frame export writes it, the tests check
//! that every stage has its text and every `{name}` a number.

use crate::geometry::PolygonLoops;
use crate::inspect::Probe;
use crate::shading::{Lobe, Stage};
use crate::views::stages::{GhPhase, Step, StepKind};
use std::sync::OnceLock;

const PAGE: &str = include_str!("../../docs/analytic-pipeline.md");

/// One stage's text as written in the page.
#[derive(Clone, Debug, PartialEq)]
pub struct LessonStage {
    pub key: String,
    pub title: String,
    pub text: String,
    pub equation: String,
    /// The `Here:` line, with `{name}` placeholders.
    pub here: String,
}

/// One stage's text with the point's numbers filled in.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Lesson {
    pub key: String,
    pub title: String,
    pub text: String,
    pub equation: String,
    pub here: String,
}

/// Every stage of the page, in its order.
pub fn stages() -> &'static [LessonStage] {
    static STAGES: OnceLock<Vec<LessonStage>> = OnceLock::new();
    STAGES.get_or_init(|| parse(PAGE))
}

/// Parses the `### lesson: KEY — title` sections of a page.
pub(crate) fn parse(page: &str) -> Vec<LessonStage> {
    let mut out: Vec<LessonStage> = Vec::new();
    let mut current: Option<LessonStage> = None;
    for line in page.lines() {
        if line.starts_with('#') {
            out.extend(current.take());
            if let Some(head) = line.strip_prefix("### lesson: ") {
                let (key, title) = head.split_once(" — ").unwrap_or((head, head));
                current = Some(LessonStage {
                    key: key.trim().to_string(),
                    title: title.trim().to_string(),
                    text: String::new(),
                    equation: String::new(),
                    here: String::new(),
                });
            }
            continue;
        }
        let Some(stage) = &mut current else {
            continue;
        };
        if let Some(eq) = line.strip_prefix("Equation: ") {
            stage.equation = eq.trim().to_string();
        } else if let Some(h) = line.strip_prefix("Here: ") {
            stage.here = h.trim().to_string();
        } else if !line.trim().is_empty() && stage.equation.is_empty() {
            // The explanation: the lines before the equation, joined into one paragraph.
            if !stage.text.is_empty() {
                stage.text.push(' ');
            }
            stage.text.push_str(line.trim());
        }
    }
    out.extend(current);
    out
}

/// The page's key of a step kind.
pub(crate) fn key_of(kind: StepKind) -> &'static str {
    match kind {
        StepKind::LightSilhouette => "light-silhouette",
        StepKind::LightClipped => "light-clipped",
        StepKind::Culling => "culling",
        StepKind::OccluderSilhouette { .. } => "occluder-silhouette",
        StepKind::OccluderClipped { .. } => "occluder-clipped",
        StepKind::SetDifference { phase: None, .. } => "set-difference",
        StepKind::SetDifference {
            phase: Some(GhPhase::Intersections),
            ..
        } => "gh-intersections",
        StepKind::SetDifference {
            phase: Some(GhPhase::Labels),
            ..
        } => "gh-labels",
        StepKind::SetDifference {
            phase: Some(GhPhase::Traversal),
            ..
        } => "gh-traversal",
        StepKind::Visible => "visible",
        StepKind::LtcTransformed { .. } => "ltc-transformed",
        StepKind::LtcClipped { .. } => "ltc-clipped",
        StepKind::Integral => "integral",
        StepKind::Derivative => "derivative",
    }
}

fn sr(x: f64) -> String {
    format!("{x:.5}")
}

fn rgb(v: glam::DVec3) -> String {
    format!("({:.5}, {:.5}, {:.5})", v.x, v.y, v.z)
}

fn loops_of(p: &PolygonLoops) -> (usize, usize) {
    (p.vertex_count(), p.loop_count())
}

/// The numbers of `step` at the probed point, by the names the `Here:` lines use.
pub(crate) fn numbers(probe: &Probe, step: &Step) -> Vec<(&'static str, String)> {
    let mut out = Vec::new();
    let Some(rec) = probe.recording.lights.get(step.record) else {
        return out;
    };
    let occluder = |i: usize| {
        probe
            .occluder_names
            .get(i)
            .cloned()
            .unwrap_or_else(|| format!("#{i}"))
    };
    let light_poly = |s: Stage| rec.polygons.iter().find(|(st, _)| *st == s).map(|(_, p)| p);
    let solid =
        |s: Stage| light_poly(s).map_or(0.0, |p| p.signed_solid_angle_about(glam::DVec3::Z));
    match step.kind {
        StepKind::LightSilhouette => {
            let edges = rec
                .contours
                .iter()
                .find(|(o, _)| o.is_none())
                .map_or(0, |(_, e)| e.len());
            let p = light_poly(Stage::Silhouette);
            out.push(("vertices", p.map_or(0, |p| p.vertex_count()).to_string()));
            out.push(("contour_edges", edges.to_string()));
            out.push(("solid_angle", sr(p.map_or(0.0, |p| p.signed_solid_angle()))));
        }
        StepKind::LightClipped => {
            let p = light_poly(Stage::HorizonClipped);
            out.push(("vertices", p.map_or(0, |p| p.vertex_count()).to_string()));
            out.push(("solid_angle", sr(solid(Stage::HorizonClipped))));
            out.push((
                "solid_angle_before",
                sr(light_poly(Stage::Silhouette).map_or(0.0, |p| p.signed_solid_angle())),
            ));
        }
        StepKind::Culling => {
            out.push(("kept", rec.occluders_kept.len().to_string()));
            let names: Vec<String> = rec.occluders_kept.iter().map(|&i| occluder(i)).collect();
            out.push((
                "kept_names",
                if names.is_empty() {
                    "none".into()
                } else {
                    names.join(", ")
                },
            ));
        }
        StepKind::OccluderSilhouette { k } | StepKind::OccluderClipped { k } => {
            if let Some((oi, _, _, p)) = rec.occluder_polygons.get(k) {
                out.push(("occluder", occluder(*oi)));
                out.push(("vertices", p.vertex_count().to_string()));
                let about = if matches!(step.kind, StepKind::OccluderClipped { .. }) {
                    p.signed_solid_angle_about(glam::DVec3::Z)
                } else {
                    p.signed_solid_angle()
                };
                out.push(("solid_angle", sr(about)));
            }
        }
        StepKind::SetDifference { k, .. } => {
            if let Some(sd) = rec.set_differences.get(k) {
                let (bv, _) = loops_of(&sd.before);
                let (av, al) = loops_of(&sd.after);
                out.push(("occluder", occluder(sd.occluder)));
                out.push(("method", format!("{:?}", sd.method)));
                out.push(("before_vertices", bv.to_string()));
                out.push(("after_vertices", av.to_string()));
                out.push(("after_loops", al.to_string()));
                let (n, entries, exits) = sd.steps.as_ref().map_or((0, 0, 0), |st| {
                    use crate::geometry::spherical::set_difference::Transition;
                    let count = |t| st.labels.iter().filter(|l| l.transition == Some(t)).count();
                    (
                        st.intersections.len(),
                        count(Transition::Entry),
                        count(Transition::Exit),
                    )
                });
                out.push(("intersections", n.to_string()));
                out.push(("entries", entries.to_string()));
                out.push(("exits", exits.to_string()));
            }
        }
        StepKind::Visible => {
            let vis = solid(Stage::Visible);
            let clipped = solid(Stage::HorizonClipped);
            out.push(("solid_angle", sr(vis)));
            out.push(("solid_angle_clipped", sr(clipped)));
            out.push((
                "fraction",
                if clipped > 0.0 {
                    format!("{:.1} %", 100.0 * vis / clipped)
                } else {
                    "none".into()
                },
            ));
        }
        StepKind::LtcTransformed { k } | StepKind::LtcClipped { k } => {
            if let Some((lobe, transformed, clipped, _)) = rec.lobes.get(k) {
                let name = match lobe {
                    Lobe::Diffuse => "diffuse",
                    Lobe::Specular => "specular",
                };
                let p = if matches!(step.kind, StepKind::LtcTransformed { .. }) {
                    transformed
                } else {
                    clipped
                };
                out.push(("lobe", name.to_string()));
                out.push(("vertices", p.vertex_count().to_string()));
                out.push((
                    "solid_angle",
                    sr(p.signed_solid_angle_about(glam::DVec3::Z)),
                ));
            }
        }
        StepKind::Integral => {
            out.push(("diffuse", rgb(rec.diffuse)));
            out.push(("specular", rgb(rec.specular)));
        }
        StepKind::Derivative => {
            let moving: Vec<_> = rec
                .moving_edges
                .iter()
                .filter(|e| crate::views::stages::moves(e))
                .collect();
            out.push((
                "motion",
                probe
                    .derivative
                    .as_ref()
                    .map_or_else(|| "the motion".into(), |d| d.label()),
            ));
            out.push(("moving", moving.len().to_string()));
            out.push(("edges", rec.moving_edges.len().to_string()));
            out.push((
                "diffuse_rate",
                format!("{:+.5e}", moving.iter().map(|e| e.diffuse).sum::<f64>()),
            ));
            out.push((
                "lobe_rate",
                format!("{:+.5e}", moving.iter().map(|e| e.lobe).sum::<f64>()),
            ));
            out.push(("rate", rgb(rec.rate)));
        }
    }
    out
}

/// Replaces each `{name}` of `template` by its number; a name without one stays visible as
/// `{name?}` (the tests require none).
pub(crate) fn fill(template: &str, numbers: &[(&str, String)]) -> String {
    let mut out = String::with_capacity(template.len());
    let mut rest = template;
    while let Some(start) = rest.find('{') {
        out.push_str(&rest[..start]);
        let after = &rest[start + 1..];
        let Some(end) = after.find('}') else {
            out.push_str(&rest[start..]);
            return out;
        };
        let name = &after[..end];
        match numbers.iter().find(|(n, _)| *n == name) {
            Some((_, v)) => out.push_str(v),
            None => {
                out.push('{');
                out.push_str(name);
                out.push_str("?}");
            }
        }
        rest = &after[end + 1..];
    }
    out.push_str(rest);
    out
}

/// The lesson of `step` at the probed point (`None` if the page lacks the stage).
pub fn lesson(probe: &Probe, step: &Step) -> Option<Lesson> {
    let key = key_of(step.kind);
    let s = stages().iter().find(|s| s.key == key)?;
    Some(Lesson {
        key: key.to_string(),
        title: s.title.clone(),
        text: s.text.clone(),
        equation: s.equation.clone(),
        here: fill(&s.here, &numbers(probe, step)),
    })
}
