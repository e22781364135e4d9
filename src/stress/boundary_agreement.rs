//! The visible integral from its boundary (`geometry::boundary_pieces`) against what the
//! renderer's Greiner–Hormann set difference computed, for one recorded light piece: the
//! oracle of the boundary formulation (docs/boundary-integral.md), shared by `penumbra stress`
//! and `tests/boundary_agreement.rs`.
//!
//! The polygons come from a [`StageRecording`](crate::shading::StageRecording) of the
//! renderer's own shading: the light clipped to the horizon and each occluder's outline (or
//! face) clipped to the horizon. Both lobes are compared: the diffuse one as the form factor of
//! the boundary pieces, the specular one by mapping the pieces with `M⁻¹` and clipping them to
//! the lobe's horizon (`clamped_integral_of_boundary`). The bound is relative to the whole
//! light's form factor, the scale of every value the light can give a pixel.

use crate::geometry::{
    BoundaryScratch, HorizonScratch, PlanarPolygon, ProjectionPlane, SetDifference,
    SphericalPolygon, boundary_pieces, clamped_integral_of_boundary, clip_to_horizon,
};
use crate::ltc::{LtcEntry, edge_integral, form_factor};
use crate::math::{Frame, angle_between};
use crate::shading::{LightRecord, Lobe, Stage};
use glam::DVec3;
use std::f64::consts::TAU;

/// The bound, relative to the light's form factor.
pub const BOUND: f64 = 1e-10;

/// Reused buffers of [`compare_light_piece`].
#[derive(Default)]
pub struct AgreementScratch {
    boundary: BoundaryScratch,
    arcs: Vec<(DVec3, DVec3)>,
    welded_arcs: Vec<(DVec3, DVec3)>,
    crossings: Vec<(f64, bool, DVec3)>,
}

/// What one recorded light piece gave.
#[derive(Clone, Debug, PartialEq)]
pub enum PieceComparison {
    /// Nothing of the light above the horizon: no integral recorded.
    Empty,
    /// The light's own image in a sky window (two diffuse integrals recorded): not compared.
    Skipped,
    Compared {
        /// Occluders were subtracted (where the two algorithms differ in kind).
        shadowed: bool,
        /// The renderer's diffuse value was off by more than the bound and Greiner–Hormann in a
        /// frame about the light agreed with the boundary: Alg. 1's projection at the horizon,
        /// not the boundary, was off.
        second_frame: bool,
        /// The boundary agreed only once vertices within [`WELD`] of each other were made one:
        /// the renderer's copies of a mesh vertex (a neighbouring face cut at a light face's
        /// plane) differ by up to 1e-9, and the sliver between the two copies of their edge
        /// is kept by the boundary's tolerance and dropped by Greiner–Hormann's.
        welded: bool,
        /// Greiner–Hormann disagreed and the boundary's own pieces are witnessed by points
        /// ([`witnessed`]): V has what the boundary found, a sliver narrower than Greiner–
        /// Hormann's tolerances (which drop those under about 1e-9).
        witnessed: bool,
        /// The largest disagreement of the two lobes, relative to the light's form factor,
        /// beyond the rounding of the two sums.
        worst: f64,
        /// Why it fails, where it does.
        failure: Option<String>,
    },
}

/// The scales of the bound for light `light`: its whole diffuse form factor and its whole
/// specular lobe value (`entry`) above the horizon, from its recorded pieces (one per light, or
/// one per face on the per-triangle path). A sharp lobe magnifies what lies near its peak, so
/// each lobe is measured against its own value.
pub fn light_scales(
    records: &[LightRecord],
    light: usize,
    entry: &LtcEntry,
    scratch: &mut AgreementScratch,
) -> LobeScales {
    let mut scales = LobeScales::default();
    for record in records.iter().filter(|r| r.light == light) {
        let Some((_, p)) = record
            .polygons
            .iter()
            .find(|(s, _)| *s == Stage::HorizonClipped)
        else {
            continue;
        };
        let e = form_factor(p.loops());
        scales.diffuse += e.abs();
        let mapped = p.loops().flat_map(|lp| {
            (0..lp.len()).map(move |k| {
                (
                    entry.transform(lp[k]),
                    entry.transform(lp[(k + 1) % lp.len()]),
                )
            })
        });
        if let Some(lobe) =
            clamped_integral_of_boundary(mapped, &mut scratch.crossings, edge_integral)
        {
            scales.specular += entry.mix((lobe / TAU).max(0.0), e.max(0.0)).abs();
        }
    }
    scales
}

/// The values the bound is relative to ([`light_scales`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LobeScales {
    pub diffuse: f64,
    pub specular: f64,
}

/// Compares the boundary formulation with the renderer's recorded integrals for `record`,
/// shaded with the lobe `entry` (its specular lobe only where one was recorded), to
/// [`BOUND`] of `scales`, the whole light's value in each lobe ([`light_scales`]).
///
/// On the per-triangle path a piece is one face of the light with the light's own faces cut
/// at its plane among the occluders: their shared edges are computed twice, and the slivers
/// between the two copies (areas of 1e-12 sr and below on Blender's meshes) are decided by each
/// algorithm's own tolerances. What the pixel receives is the sum over the faces, so the bound
/// is the whole light's, not the face's.
pub fn compare_light_piece(
    record: &LightRecord,
    entry: &LtcEntry,
    scales: LobeScales,
    scratch: &mut AgreementScratch,
) -> PieceComparison {
    let Some((_, light)) = record
        .polygons
        .iter()
        .find(|(s, _)| *s == Stage::HorizonClipped)
    else {
        return PieceComparison::Empty;
    };
    let mut diffuse = record.lobes.iter().filter(|x| x.0 == Lobe::Diffuse);
    let recorded_diffuse = match (diffuse.next(), diffuse.next()) {
        (None, _) => return PieceComparison::Empty,
        (Some(d), None) => d.3,
        (Some(_), Some(_)) => return PieceComparison::Skipped,
    };
    let recorded_specular = record
        .lobes
        .iter()
        .find(|x| x.0 == Lobe::Specular)
        .map(|x| x.3);
    let occluders: Vec<&SphericalPolygon> = record
        .occluder_polygons
        .iter()
        .filter(|o| o.2 == Stage::HorizonClipped)
        .map(|o| &o.3)
        .collect();
    let recorded = Recorded {
        light,
        diffuse: recorded_diffuse,
        specular: recorded_specular,
        entry,
        scales,
    };
    let arcs = &mut scratch.arcs;
    arcs.clear();
    boundary_pieces(
        light,
        occluders.iter().copied(),
        &mut scratch.boundary,
        |p| arcs.push((p.start, p.end)),
    );
    let first = recorded.errors(arcs, &mut scratch.crossings);
    let shadowed = !occluders.is_empty();
    if first.worst() <= BOUND {
        return PieceComparison::Compared {
            shadowed,
            second_frame: false,
            welded: false,
            witnessed: false,
            worst: first.worst(),
            failure: None,
        };
    }
    // The renderer's copies of one mesh vertex may differ by rounding: welded, the sliver
    // between the two copies of their edge is gone.
    let (welded_light, welded_occluders) = welded_copies(light, &occluders);
    let welded_arcs = &mut scratch.welded_arcs;
    welded_arcs.clear();
    boundary_pieces(
        &welded_light,
        welded_occluders.iter(),
        &mut scratch.boundary,
        |p| welded_arcs.push((p.start, p.end)),
    );
    let welded = recorded.errors(welded_arcs, &mut scratch.crossings);
    // Or both algorithms on the same welded input, where the renderer's slivers are closed
    // for both: Greiner–Hormann in a frame about the light, for each lobe.
    let welded_refs: Vec<&SphericalPolygon> = welded_occluders.iter().collect();
    let agree_on_welded = || {
        let gh = greiner_hormann_about_the_light(&welded_light, &welded_refs)?;
        let mut worst = welded.off(welded.boundary_diffuse, gh, scales.diffuse);
        if let Some(b) = welded.boundary_specular {
            let lobe = lobe_by_greiner_hormann(&welded_light, &welded_refs, entry)?;
            let g = entry.mix(lobe, gh.max(0.0));
            worst = worst.max(((b - g).abs() - welded.rounding).max(0.0) / scales.specular);
        }
        Some(worst)
    };
    let welded_worst = match agree_on_welded() {
        Some(w) if welded.worst() > BOUND => w,
        _ => welded.worst(),
    };
    if welded_worst <= BOUND {
        return PieceComparison::Compared {
            shadowed,
            second_frame: false,
            welded: true,
            witnessed: false,
            worst: welded_worst,
            failure: None,
        };
    }
    // Alg. 1 projects from the normal, where a light reaching the horizon has vertices at
    // infinity: Greiner–Hormann in a frame about the light is a second opinion of the diffuse
    // value.
    let second = greiner_hormann_about_the_light(light, &occluders);
    if first.specular <= BOUND
        && let Some(g) = second
        && first.off(first.boundary_diffuse, g, scales.diffuse) <= BOUND
    {
        return PieceComparison::Compared {
            shadowed,
            second_frame: true,
            welded: false,
            witnessed: false,
            worst: first.specular,
            failure: None,
        };
    }
    // A third opinion, from the definition of V: points beside each of the boundary's pieces.
    if witnessed(light, &occluders, &scratch.arcs) {
        return PieceComparison::Compared {
            shadowed,
            second_frame: false,
            welded: false,
            witnessed: true,
            worst: first.worst(),
            failure: None,
        };
    }
    let failure = if first.diffuse > BOUND {
        format!(
            "diffuse: boundary {} vs Greiner–Hormann {recorded_diffuse} ({:.1e} of the light's, \
             {} occluders; welded {:.1e}; in a frame about the light {second:?})",
            first.boundary_diffuse,
            first.diffuse,
            occluders.len(),
            welded.diffuse,
        )
    } else {
        format!(
            "specular: boundary {:?} vs Greiner–Hormann {recorded_specular:?} ({:.1e} of the \
             light's lobe; welded {:.1e})",
            first.boundary_specular, first.specular, welded.specular
        )
    };
    PieceComparison::Compared {
        shadowed,
        second_frame: false,
        welded: false,
        witnessed: false,
        worst: first.worst(),
        failure: Some(failure),
    }
}

/// Offsets (radians) at which [`witnessed`] looks beside a piece: from ten thousand times the
/// rounding of a unit vector's coordinates to well above Greiner–Hormann's tolerances.
const WITNESS_OFFSETS: [f64; 7] = [1e-12, 1e-11, 1e-10, 1e-9, 1e-8, 1e-7, 1e-6];

/// Whether the oriented pieces `arcs` are witnessed as V's boundary by points, V's definition
/// (in the light, in no occluder; winding numbers at points far from every edge by rounding's
/// measure): the pieces close (every end is a piece's start, to 1e-14), and beside the middle of
/// every piece, at some offset [`WITNESS_OFFSETS`] of at most a tenth of its length, the point on
/// its left lies in V and the point on its right does not. A piece too short to look beside
/// (under 1e-11) leaves the boundary unwitnessed. Closed and locally right everywhere, the
/// pieces bound V, whatever Greiner–Hormann's tolerances dropped (a component of V's boundary
/// missing altogether is not seen: the witness is of what was found).
pub fn witnessed(
    light: &SphericalPolygon,
    occluders: &[&SphericalPolygon],
    arcs: &[(DVec3, DVec3)],
) -> bool {
    if arcs.is_empty() {
        return false;
    }
    let closes = arcs.iter().all(|&(_, end)| {
        arcs.iter()
            .any(|&(start, _)| (start - end).length() <= 1e-14)
    });
    if !closes {
        return false;
    }
    let in_v = |p: DVec3| {
        light.contains_within(p, 0.0) && !occluders.iter().any(|o| o.contains_within(p, 0.0))
    };
    arcs.iter().all(|&(a, b)| {
        let length = angle_between(a, b);
        let (Some(mid), Some(left)) = ((a + b).try_normalize(), a.cross(b).try_normalize()) else {
            return false;
        };
        WITNESS_OFFSETS
            .iter()
            .filter(|&&d| d <= 0.1 * length)
            .any(|&d| {
                let (l, r) = ((mid + left * d).normalize(), (mid - left * d).normalize());
                in_v(l) && !in_v(r)
            })
    })
}

/// What the renderer recorded for one light piece, and the scales of the bound.
struct Recorded<'a> {
    light: &'a SphericalPolygon,
    diffuse: f64,
    specular: Option<f64>,
    entry: &'a LtcEntry,
    scales: LobeScales,
}

/// The boundary's values and their disagreements with the recorded ones, relative to the
/// whole light's value in each lobe, beyond the rounding of the two sums.
struct Errors {
    boundary_diffuse: f64,
    boundary_specular: Option<f64>,
    diffuse: f64,
    /// Infinite where the lobe's horizon crossings do not alternate.
    specular: f64,
    rounding: f64,
}

impl Errors {
    fn worst(&self) -> f64 {
        self.diffuse.max(self.specular)
    }

    fn off(&self, ours: f64, theirs: f64, scale: f64) -> f64 {
        ((ours - theirs.max(0.0)).abs() - self.rounding).max(0.0) / scale.max(1e-300)
    }
}

impl Recorded<'_> {
    fn errors(&self, arcs: &[(DVec3, DVec3)], crossings: &mut Vec<(f64, bool, DVec3)>) -> Errors {
        let e_diffuse =
            (arcs.iter().map(|&(a, b)| edge_integral(a, b)).sum::<f64>() / TAU).max(0.0);
        // The rounding of the two sums: near the horizon the edge terms are far larger than
        // the integral, whose value they give by cancelling: 64 ulps of their magnitudes.
        let magnitude = self
            .light
            .loops()
            .flat_map(|lp| (0..lp.len()).map(move |k| (lp[k], lp[(k + 1) % lp.len()])))
            .chain(arcs.iter().copied())
            .map(|(a, b)| edge_integral(a, b).abs())
            .sum::<f64>()
            / TAU;
        let mut errors = Errors {
            boundary_diffuse: e_diffuse,
            boundary_specular: None,
            diffuse: 0.0,
            specular: 0.0,
            rounding: 64.0 * f64::EPSILON * magnitude,
        };
        errors.diffuse = errors.off(e_diffuse, self.diffuse, self.scales.diffuse);
        let Some(recorded) = self.specular else {
            return errors;
        };
        let entry = self.entry;
        let mapped = arcs
            .iter()
            .map(|&(a, b)| (entry.transform(a), entry.transform(b)));
        let mut lobe_magnitude = 0.0;
        let lobe = clamped_integral_of_boundary(mapped, crossings, |a, b| {
            let t = edge_integral(a, b);
            lobe_magnitude += t.abs();
            t
        });
        errors.specular = match lobe {
            Some(lobe) => {
                let e_spec = entry.mix((lobe / TAU).max(0.0), e_diffuse);
                errors.boundary_specular = Some(e_spec);
                // The lobe's sums round at the magnitude of their own terms (a sharp lobe's
                // are far larger than the diffuse ones).
                let rounding = errors.rounding + 64.0 * f64::EPSILON * 2.0 * lobe_magnitude / TAU;
                ((e_spec - recorded.max(0.0)).abs() - rounding).max(0.0)
                    / self.scales.specular.max(1e-300)
            }
            None => f64::INFINITY,
        };
        errors
    }
}

/// The LTC lobe's integral `E(clip(M⁻¹V))` by Greiner–Hormann: every polygon mapped by M⁻¹
/// and clipped to the lobe's horizon, then [`greiner_hormann_about_the_light`] (V ∩ H is the
/// light's part above it less the occluders' parts above it).
fn lobe_by_greiner_hormann(
    light: &SphericalPolygon,
    occluders: &[&SphericalPolygon],
    entry: &LtcEntry,
) -> Option<f64> {
    let mapped = |p: &SphericalPolygon| {
        let mut m = p.clone();
        m.map_vertices(|v| entry.transform(v).normalize());
        let mut c = SphericalPolygon::new();
        clip_to_horizon(&m, &mut c, &mut HorizonScratch::default());
        c
    };
    let light = mapped(light);
    if light.is_empty() {
        return Some(0.0);
    }
    let occluders: Vec<SphericalPolygon> = occluders.iter().map(|p| mapped(p)).collect();
    let refs: Vec<&SphericalPolygon> = occluders.iter().filter(|p| !p.is_empty()).collect();
    greiner_hormann_about_the_light(&light, &refs).map(|e| e.max(0.0))
}

/// The distance (chord) within which `welded_copies` makes vertices one.
pub const WELD: f64 = 1e-8;

/// Copies of the polygons in which each vertex within [`WELD`] of an earlier one (the light's
/// first, then the occluders' in order) is replaced by it.
fn welded_copies(
    light: &SphericalPolygon,
    occluders: &[&SphericalPolygon],
) -> (SphericalPolygon, Vec<SphericalPolygon>) {
    let mut seen: Vec<DVec3> = Vec::new();
    let mut weld = |p: &SphericalPolygon| {
        let mut c = p.clone();
        c.map_vertices(|v| match seen.iter().find(|s| (**s - v).length() <= WELD) {
            Some(s) => *s,
            None => {
                seen.push(v);
                v
            }
        });
        c
    };
    let l = weld(light);
    let o = occluders.iter().map(|p| weld(p)).collect();
    (l, o)
}

/// A second opinion where the two disagree: Greiner–Hormann again, in a frame whose z axis is
/// the light's mean direction, so that no vertex lies on the projection's horizon (Alg. 1
/// projects from the normal, where a light reaching the horizon has vertices at infinity).
/// Every polygon is turned into that frame and clipped to its upper hemisphere (V lies inside
/// the light, which lies inside it); the integral of `z` over V is that of `ω · R z`.
pub fn greiner_hormann_about_the_light(
    light: &SphericalPolygon,
    occluders: &[&SphericalPolygon],
) -> Option<f64> {
    let centre = light
        .vertices()
        .iter()
        .copied()
        .sum::<DVec3>()
        .try_normalize()?;
    let frame = Frame::from_z(centre);
    let turn = |p: &SphericalPolygon| {
        let mut t = p.clone();
        t.map_vertices(|v| frame.to_local(v));
        let mut c = SphericalPolygon::new();
        clip_to_horizon(&t, &mut c, &mut HorizonScratch::default());
        c
    };
    let plane = ProjectionPlane::NORMAL;
    let mut v = PlanarPolygon::new();
    plane.project(&turn(light), &mut v);
    let (mut clip, mut out) = (PlanarPolygon::new(), PlanarPolygon::new());
    let mut sd = SetDifference::new();
    for o in occluders {
        if v.is_empty() {
            break;
        }
        plane.project(&turn(o), &mut clip);
        sd.subtract(&v, &clip, &mut out, None);
        if sd.last_bound_crossed() || !sd.last_traversal_consistent() {
            return None;
        }
        std::mem::swap(&mut v, &mut out);
    }
    let mut sph = SphericalPolygon::new();
    plane.reproject(&v, &mut sph);
    // ∫_V z dω = (1/2π) Σ θ_ab (a × b)/|a × b| · n with n the old z axis in the new frame.
    let n = frame.to_local(DVec3::Z);
    let mut sum = 0.0;
    for lp in sph.loops() {
        for k in 0..lp.len() {
            let (a, b) = (lp[k], lp[(k + 1) % lp.len()]);
            let w = a.cross(b);
            let len = w.length();
            if len > 0.0 {
                sum += len.atan2(a.dot(b)) * w.dot(n) / len;
            }
        }
    }
    Some(sum / TAU)
}
