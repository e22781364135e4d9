//! The stages of 000 Alg. 1 at one shading point, as a flat list to step through: built from
//! the recording the renderer's own `shade` call produced (never recomputed here).

use crate::inspect::Probe;
use crate::shading::{DifferenceMethod, LightRecord, Lobe, SetDifferenceRecord, StageRecording};

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
    /// The derivative along a rigid motion (`shading::shade_with_rate`): the visible
    /// polygon's edges that move, their shares of the rate and the light's rate.
    Derivative,
}

/// One step: which light record of the recording, what it shows, and a label.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Step {
    /// Index into `StageRecording::lights`.
    pub record: usize,
    pub kind: StepKind,
    pub label: String,
}

/// How a step names its light record: "light NAME", with the face for a light taken face by
/// face.
fn light_label(lr: &LightRecord, light_name: &impl Fn(usize) -> String) -> String {
    match lr.piece {
        Some(f) => format!("light {} face {f}", light_name(lr.light)),
        None => format!("light {}", light_name(lr.light)),
    }
}

/// Every step of a recording, light record by light record, in pipeline order.
pub(crate) fn steps(
    rec: &StageRecording,
    light_name: impl Fn(usize) -> String,
    occluder_name: impl Fn(usize) -> String,
) -> Vec<Step> {
    let mut out = Vec::new();
    for (r, lr) in rec.lights.iter().enumerate() {
        let who = light_label(lr, &light_name);
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
        // What the point's tile shared for an occluder's outline in the light's window.
        let shared = |occluder: usize| match lr.tile_shares.iter().find(|t| t.occluder == occluder)
        {
            Some(t) => match t.shared_edges {
                Some(n) => format!(
                    "; inside the light's window, from the {n} of {} edges its tile's region \
                     (radius {:.3}) keeps",
                    t.mesh_edges, t.radius
                ),
                None => "; inside the light's window, its own candidate edges".into(),
            },
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
                    format!(
                        "occluder {name}: silhouette (line 9{}{})",
                        exact(Some(*oi)),
                        piece.map_or_else(|| shared(*oi), |_| String::new())
                    ),
                ),
                _ => push(
                    StepKind::OccluderClipped { k },
                    format!("occluder {name}: clipped and projected (lines 10–11)"),
                ),
            }
        }
        for (k, sd) in lr.set_differences.iter().enumerate() {
            let name = occluder_name(sd.occluder);
            let how = match sd.method {
                DifferenceMethod::Classified => ", decided before clipping",
                DifferenceMethod::GreinerHormann => "",
                DifferenceMethod::Hole => ": its part inside the light, integrated as a hole",
                DifferenceMethod::HoleSettled => {
                    ", again: its hole made a polygon for the next occluder"
                }
            };
            push(
                StepKind::SetDifference { k, phase: None },
                format!("set difference − {name}{how} (line 12)"),
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
        if !lr.moving_edges.is_empty() {
            let moving = lr.moving_edges.iter().filter(|e| moves(e)).count();
            push(
                StepKind::Derivative,
                format!(
                    "derivative: moving edges ({moving} of {} edges move)",
                    lr.moving_edges.len()
                ),
            );
        }
    }
    out
}

/// Whether an edge of a visible polygon moves with the derivative's motion: it has a share of
/// the rate, or it lies on a moving mesh edge's plane (the edges the sphere draws with their
/// velocity and the numbers list).
pub fn moves(e: &crate::shading::MovingEdge) -> bool {
    e.diffuse != 0.0
        || e.lobe != 0.0
        || matches!(
            e.support,
            crate::shading::EdgeSupport::MeshEdge { moving: true, .. }
        )
}

/// Steps the stepper shows as one: the run of an occluder the renderer took face by face (its
/// faces' polygons, or its set differences, one per face), else one step alone. A group stands
/// at its last step, which draws all of the run (the faces so far, the last difference).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StepGroup {
    /// Index into the steps of its first step.
    pub first: usize,
    /// Steps in it (1 for a step alone).
    pub len: usize,
    pub label: String,
}

impl StepGroup {
    /// The step the group stands at.
    pub fn last(&self) -> usize {
        self.first + self.len - 1
    }

    pub fn contains(&self, step: usize) -> bool {
        (self.first..self.first + self.len).contains(&step)
    }
}

/// The groups of `steps` (as `steps` made them from `rec`), in order, covering every step.
pub fn groups(
    rec: &StageRecording,
    steps: &[Step],
    light_name: impl Fn(usize) -> String,
    occluder_name: impl Fn(usize) -> String,
) -> Vec<StepGroup> {
    // What a face-by-face run is made of: (record, occluder, set differences or polygons).
    let run_of = |s: &Step| -> Option<(usize, usize, bool)> {
        let lr = rec.lights.get(s.record)?;
        let faced = |oi: usize| {
            lr.occluder_polygons
                .iter()
                .any(|(o, piece, _, _)| *o == oi && piece.is_some())
        };
        match s.kind {
            StepKind::OccluderSilhouette { k } | StepKind::OccluderClipped { k } => {
                let (oi, piece, _, _) = lr.occluder_polygons.get(k)?;
                piece.map(|_| (s.record, *oi, false))
            }
            StepKind::SetDifference { k, .. } => {
                let oi = lr.set_differences.get(k)?.occluder;
                faced(oi).then_some((s.record, oi, true))
            }
            _ => None,
        }
    };
    let mut out: Vec<StepGroup> = Vec::new();
    let mut i = 0;
    while i < steps.len() {
        let run = run_of(&steps[i]);
        let mut len = 1;
        while run.is_some() && i + len < steps.len() && run_of(&steps[i + len]) == run {
            len += 1;
        }
        let label = match run {
            Some((r, oi, differences)) if len > 1 => {
                let lr = &rec.lights[r];
                let who = light_label(lr, &light_name);
                let name = occluder_name(oi);
                if differences {
                    let n = lr
                        .set_differences
                        .iter()
                        .filter(|sd| sd.occluder == oi)
                        .count();
                    format!("{who}: set differences − {name}, face by face ({n} faces, line 12)")
                } else {
                    let mut faces: Vec<usize> = lr
                        .occluder_polygons
                        .iter()
                        .filter(|p| p.0 == oi)
                        .filter_map(|p| p.1)
                        .collect();
                    faces.sort_unstable();
                    faces.dedup();
                    format!(
                        "{who}: occluder {name}, face by face: {} faces' silhouettes, clipped \
                         and projected (lines 9–11)",
                        faces.len()
                    )
                }
            }
            _ => steps[i].label.clone(),
        };
        out.push(StepGroup {
            first: i,
            len,
            label,
        });
        i += len;
    }
    out
}

/// The groups of a probe's steps ([`probe_steps`]), named as the probe names its lights and
/// occluders.
pub fn probe_groups(probe: &Probe, steps: &[Step]) -> Vec<StepGroup> {
    let (light_name, occluder_name) = probe_names(probe);
    groups(&probe.recording, steps, light_name, occluder_name)
}

/// How a probe names its lights and its occluders, by index.
fn probe_names(probe: &Probe) -> (impl Fn(usize) -> String + '_, impl Fn(usize) -> String + '_) {
    let (names, lights) = (&probe.occluder_names, &probe.lights);
    (
        move |i| {
            lights
                .iter()
                .find(|l| l.light == i)
                .map_or_else(|| i.to_string(), |l| l.name.clone())
        },
        move |i| names.get(i).cloned().unwrap_or_else(|| format!("#{i}")),
    )
}

/// The steps of a probe's recording, lights and occluders named as the probe names them: the
/// numbering the workbench's stepper shows and `penumbra figure --stage` takes.
pub fn probe_steps(probe: &Probe) -> Vec<Step> {
    let (light_name, occluder_name) = probe_names(probe);
    steps(&probe.recording, light_name, occluder_name)
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
        StepKind::Visible | StepKind::Derivative => of_stage(Stage::Visible),
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
        // The default scene: fig4's occluders are convex and take every last difference as a
        // hole; here a region held with a hole meets a second occluder.
        let scene = scene_file::load_embedded("default").unwrap();
        let ctx = RenderContext::new(&scene);
        let cam = scene.camera.unwrap();
        // Scan for a pixel whose recording has a Greiner–Hormann difference.
        let mut found = None;
        'scan: for y in (20..64).step_by(4) {
            for x in (0..64).step_by(4) {
                let p = probe(
                    &ctx,
                    "default",
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
                    .any(|l| l.set_differences.iter().any(|sd| sd.steps.is_some()))
                {
                    found = Some(p);
                    break 'scan;
                }
            }
        }
        let p = found.expect("default has Greiner–Hormann differences");
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

    /// An occluder taken face by face is one group for its faces' polygons and one for its
    /// set differences; the steps of a whole occluder stay alone; the groups cover every step
    /// once, in order.
    #[test]
    fn a_mesh_taken_face_by_face_is_one_group_per_stage() {
        use crate::geometry::{PlanarPolygon, SphericalPolygon};
        use crate::shading::{LightRecord, SetDifferenceRecord, Stage};
        let mut lr = LightRecord::default();
        let poly = SphericalPolygon::new();
        // Occluder 0 whole, occluder 1 in three faces.
        lr.occluder_polygons
            .push((0, None, Stage::Silhouette, poly.clone()));
        lr.occluder_polygons
            .push((0, None, Stage::HorizonClipped, poly.clone()));
        for f in [4, 7, 9] {
            lr.occluder_polygons
                .push((1, Some(f), Stage::Silhouette, poly.clone()));
            lr.occluder_polygons
                .push((1, Some(f), Stage::HorizonClipped, poly.clone()));
        }
        let sd = |occluder| SetDifferenceRecord {
            occluder,
            method: DifferenceMethod::GreinerHormann,
            before: PlanarPolygon::default(),
            clip: PlanarPolygon::default(),
            after: PlanarPolygon::default(),
            steps: None,
        };
        lr.set_differences = vec![sd(0), sd(1), sd(1), sd(1)];
        let mut rec = StageRecording::new(false);
        rec.lights.push(lr);
        let s = steps(&rec, |i| format!("L{i}"), |i| format!("O{i}"));
        let g = groups(&rec, &s, |i| format!("L{i}"), |i| format!("O{i}"));
        // Every step in exactly one group, in order.
        assert_eq!(g[0].first, 0);
        for w in g.windows(2) {
            assert_eq!(w[0].first + w[0].len, w[1].first);
        }
        assert_eq!(g.last().map(|x| x.first + x.len), Some(s.len()));
        let big: Vec<&StepGroup> = g.iter().filter(|x| x.len > 1).collect();
        assert_eq!(big.len(), 2, "{g:?}");
        assert_eq!(big[0].len, 6);
        assert!(big[0].label.contains("3 faces"), "{}", big[0].label);
        assert_eq!(big[1].len, 3);
        assert!(
            big[1].label.contains("face by face (3 faces"),
            "{}",
            big[1].label
        );
        // The group stands at its last step: the last face's clipped polygon, the last
        // difference.
        assert_eq!(s[big[0].last()].kind, StepKind::OccluderClipped { k: 7 });
        assert_eq!(
            s[big[1].last()].kind,
            StepKind::SetDifference { k: 3, phase: None }
        );
        // Alone: everything of the whole occluder.
        assert_eq!(s.len() - 9 + 2, g.len());
    }
}
