//! The stages of 000 Alg. 1 at one shading point, as a flat list to step through: built from
//! the recording the renderer's own `shade` call produced (never recomputed here).

use crate::inspect::Probe;
use crate::shading::{Lobe, SetDifferenceRecord, StageRecording};

/// The three Greiner–Hormann phases, stepped one by one inside a set difference.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum GhPhase {
    Intersections,
    Labels,
    Traversal,
}

/// What one step shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum StepKind {
    /// Alg. 1 line 4: the light's silhouette.
    LightSilhouette,
    /// Line 5: clipped to the horizon.
    LightClipped,
    /// GetBetween: the occluders kept.
    Culling,
    /// Lines 9–10 for occluder record `k` of the light record: silhouette, then clipped.
    OccluderSilhouette {
        k: usize,
    },
    OccluderClipped {
        k: usize,
    },
    /// Line 12: set difference `k` of the light record, optionally one GH phase of it.
    SetDifference {
        k: usize,
        phase: Option<GhPhase>,
    },
    /// Line 13: the visible polygon, reprojected.
    Visible,
    /// Lines 14–15: lobe `k` after the LTC transform, then clipped again.
    LtcTransformed {
        k: usize,
    },
    LtcClipped {
        k: usize,
    },
    /// Line 16: the light's contribution.
    Integral,
}

/// One step: which light record of the recording, what it shows, and a label.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Step {
    /// Index into `StageRecording::lights`.
    pub record: usize,
    pub kind: StepKind,
    pub label: String,
}

/// Every step of a recording, light record by light record, in pipeline order.
pub fn steps(
    rec: &StageRecording,
    light_name: impl Fn(usize) -> String,
    occluder_name: impl Fn(usize) -> String,
) -> Vec<Step> {
    let mut out = Vec::new();
    for (r, lr) in rec.lights.iter().enumerate() {
        let who = match lr.piece {
            Some(f) => format!("light {} face {f}", light_name(lr.light)),
            None => format!("light {}", light_name(lr.light)),
        };
        // How the exact silhouette of a non-convex mesh was found, if it was.
        let exact = |occluder: Option<usize>| match lr.exact.iter().find(|e| e.occluder == occluder)
        {
            Some(e) if e.from_tree => {
                format!("; exact, from the tree: {} crossings", e.crossings.len())
            }
            Some(e) => format!(
                "; exact, at the point: {} crossings, {} rejected",
                e.crossings.len(),
                e.rejected.len()
            ),
            None => String::new(),
        };
        let mut push = |kind: StepKind, what: String| {
            out.push(Step {
                record: r,
                kind,
                label: format!("{who}: {what}"),
            })
        };
        let contour = match lr.contours.iter().find(|(o, _)| o.is_none()) {
            Some((_, edges)) => format!(", from {} contour edges", edges.len()),
            None => String::new(),
        };
        push(
            StepKind::LightSilhouette,
            format!("silhouette (line 4{contour}{})", exact(None)),
        );
        push(
            StepKind::LightClipped,
            "clipped to the horizon (line 5)".into(),
        );
        push(
            StepKind::Culling,
            format!(
                "GetBetween kept {} occluder(s) (line 8)",
                lr.occluders_kept.len()
            ),
        );
        for (k, (oi, piece, stage, _)) in lr.occluder_polygons.iter().enumerate() {
            let name = match piece {
                Some(f) => format!("{} face {f}", occluder_name(*oi)),
                None => occluder_name(*oi),
            };
            match stage {
                crate::shading::Stage::Silhouette => push(
                    StepKind::OccluderSilhouette { k },
                    format!("occluder {name}: silhouette (line 9{})", exact(Some(*oi))),
                ),
                _ => push(
                    StepKind::OccluderClipped { k },
                    format!("occluder {name}: clipped and projected (lines 10–11)"),
                ),
            }
        }
        for (k, sd) in lr.set_differences.iter().enumerate() {
            let name = occluder_name(sd.occluder);
            push(
                StepKind::SetDifference { k, phase: None },
                format!("set difference − {name} (line 12)"),
            );
            if sd.steps.is_some() {
                for (phase, what) in [
                    (GhPhase::Intersections, "phase 1: intersections"),
                    (GhPhase::Labels, "phase 2: entry/exit labels"),
                    (GhPhase::Traversal, "phase 3: traversal"),
                ] {
                    push(
                        StepKind::SetDifference {
                            k,
                            phase: Some(phase),
                        },
                        format!("set difference − {name}: {what}"),
                    );
                }
            }
        }
        push(
            StepKind::Visible,
            "visible polygon, reprojected (line 13)".into(),
        );
        for (k, (lobe, _, _, _)) in lr.lobes.iter().enumerate() {
            let l = match lobe {
                Lobe::Diffuse => "diffuse",
                Lobe::Specular => "specular",
            };
            push(
                StepKind::LtcTransformed { k },
                format!("{l} lobe: LTC-transformed (line 14)"),
            );
            push(
                StepKind::LtcClipped { k },
                format!("{l} lobe: clipped again (line 15)"),
            );
        }
        push(StepKind::Integral, "integral (line 16)".into());
    }
    out
}

/// The steps of a probe's recording, lights and occluders named as the probe names them: the
/// numbering the workbench's stepper shows and `penumbra figure --stage` takes.
pub fn probe_steps(probe: &Probe) -> Vec<Step> {
    let names = &probe.occluder_names;
    let lights = &probe.lights;
    steps(
        &probe.recording,
        |i| {
            lights
                .iter()
                .find(|l| l.light == i)
                .map_or_else(|| i.to_string(), |l| l.name.clone())
        },
        |i| names.get(i).cloned().unwrap_or_else(|| format!("#{i}")),
    )
}

/// The set difference the projected plane shows at step `current` (every stage: `None`): the
/// last one at or before it, with the GH phase when the step is that phase; else the
/// recording's first.
pub fn plane_subject<'a>(
    probe: &'a Probe,
    steps: &[Step],
    current: Option<usize>,
) -> Option<(&'a SetDifferenceRecord, Option<GhPhase>)> {
    let rec = &probe.recording.lights;
    let at = |record: usize, k: usize| rec.get(record).and_then(|r| r.set_differences.get(k));
    let upto = current.unwrap_or(steps.len().saturating_sub(1));
    for (i, s) in steps[..(upto + 1).min(steps.len())]
        .iter()
        .enumerate()
        .rev()
    {
        if let StepKind::SetDifference { k, phase } = s.kind {
            let phase = if Some(i) == current { phase } else { None };
            return at(s.record, k).map(|sd| (sd, phase));
        }
    }
    rec.iter()
        .find_map(|r| r.set_differences.first())
        .map(|sd| (sd, None))
}

/// The polygon step `step` produces, as loops of points: unit directions in the shading frame
/// for the spherical stages, homogeneous points (x, y, w) of the occluder's projection plane
/// for a set difference (its result), none for the stages that make no polygon (GetBetween,
/// the integral).
pub fn step_polygon(probe: &Probe, step: &Step) -> Vec<Vec<glam::DVec3>> {
    use crate::shading::Stage;
    let Some(rec) = probe.recording.lights.get(step.record) else {
        return Vec::new();
    };
    let loops = |p: &crate::geometry::PolygonLoops| p.loops().map(|l| l.to_vec()).collect();
    let of_stage = |want: Stage| {
        rec.polygons
            .iter()
            .find(|(s, _)| *s == want)
            .map_or_else(Vec::new, |(_, p)| loops(p))
    };
    match step.kind {
        StepKind::LightSilhouette => of_stage(Stage::Silhouette),
        StepKind::LightClipped => of_stage(Stage::HorizonClipped),
        StepKind::Visible => of_stage(Stage::Visible),
        StepKind::OccluderSilhouette { k } | StepKind::OccluderClipped { k } => rec
            .occluder_polygons
            .get(k)
            .map_or_else(Vec::new, |(_, _, _, p)| loops(p)),
        StepKind::SetDifference { k, .. } => {
            rec.set_differences.get(k).map_or_else(Vec::new, |sd| {
                sd.after.loops().map(|l| l.to_vec()).collect()
            })
        }
        StepKind::LtcTransformed { k } => rec.lobes.get(k).map_or_else(Vec::new, |l| loops(&l.1)),
        StepKind::LtcClipped { k } => rec.lobes.get(k).map_or_else(Vec::new, |l| loops(&l.2)),
        StepKind::Culling | StepKind::Integral => Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inspect::probe;
    use crate::render::RenderContext;
    use crate::scene::scene_file;
    use crate::shading::Method;

    /// The steps of a recorded penumbra point follow Alg. 1's order for every light and
    /// include the GH phases when they were recorded.
    #[test]
    fn steps_follow_the_pipeline() {
        let scene = scene_file::load_embedded("fig4").unwrap();
        let ctx = RenderContext::new(&scene);
        let cam = scene.camera.unwrap();
        // Scan for a pixel whose recording has a set difference.
        let mut found = None;
        'scan: for y in (20..60).step_by(4) {
            for x in (0..64).step_by(4) {
                let p = probe(
                    &ctx,
                    "fig4",
                    &cam,
                    (64, 64),
                    (x as f64, y as f64),
                    Method::Analytic,
                    true,
                )
                .unwrap();
                if p.recording
                    .lights
                    .iter()
                    .any(|l| !l.set_differences.is_empty())
                {
                    found = Some(p);
                    break 'scan;
                }
            }
        }
        let p = found.expect("fig4 has penumbra pixels");
        let s = steps(&p.recording, |i| format!("L{i}"), |i| format!("#{i}"));
        let gh = s
            .iter()
            .position(|x| {
                matches!(
                    x.kind,
                    StepKind::SetDifference {
                        phase: Some(GhPhase::Traversal),
                        ..
                    }
                )
            })
            .unwrap();
        // Within the light record of that set difference: silhouette < GH phases < visible.
        let rec = s[gh].record;
        let first = |k: StepKind| s.iter().position(|x| x.record == rec && x.kind == k);
        let sil = first(StepKind::LightSilhouette).unwrap();
        let vis = first(StepKind::Visible).unwrap();
        assert!(sil < gh && gh < vis, "{sil} {gh} {vis}");
        assert_eq!(s.last().unwrap().kind, StepKind::Integral);
        assert_eq!(
            s.iter().filter(|x| x.kind == StepKind::Integral).count(),
            p.recording.lights.len()
        );
    }
}
