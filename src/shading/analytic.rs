//! 000 Alg. 1: the radiance at a shading point, light by light.
//!
//! ```text
//! for each light l:                                   shade
//!     l' = SphPolySilhouette(l, x, n)                 PreparedObject::spherical_polygon
//!     l'_clip = ClipToHorizon(l')                     clip_to_horizon
//!     l'_xy = project(l'_clip, p)                     ProjectionPlane::project
//!     B_bw = GetBetween(x, l, B)                      get_between
//!     for b in B_bw:                                  subtract_occluder
//!         b' = SphPolySilhouette(b, x, n), clip, project
//!         l'_xy = SetDifference(l'_xy, b'_xy)          SetDifference::subtract
//!     l' = reproject(l'_xy, p)                        ProjectionPlane::reproject
//!     l_ltc = ApplyLTC(l', ρ); ClipToHorizon(l_ltc)   integrate_lobes
//!     I += AnalyticIntegrate(l_ltc, ρ)                form_factor
//! ```
//!
//! How a mesh's spherical polygon is found is the prepared object's business
//! ([`super::outline`]); this module only handles the two answers: the mesh as a whole, or face
//! by face. Face by face, an occluder face is first cut to the part in front of the light
//! face's plane, so that faces of one mesh hiding each other are exact.
//!
//! What cannot matter is skipped and counted ([`Shortcuts`]): a light whose bounding sphere is
//! below the tangent plane is not looked at; one whose polygon clips away at the horizon stops
//! there; with no occluder between, or every occluder disjoint from it, it is fully lit without
//! a set difference; once an occluder covers it, the others are not looked at.

use super::face_sides::{InFront, in_front, light_face_cut};
mod occluder_cache;
mod sky_windows;
use super::derivative::{self, DerivativeScratch, FD_STEP, LobeMap, PointMotion, PointRates};
use super::get_between::get_between;
use super::invariant::visible_within_light;
use super::ltc_correction::{
    CorrectionEstimate, CorrectionSampling, CorrectionScratch, GlossyLobe, estimate_correction,
};
use super::outline::{Fallbacks, Outline, OutlineScratch, Role};
use super::recorder::{
    DifferenceMethod, ExactSilhouetteRecord, Lobe, Recorder, Stage, TileShareRecord,
    TreeLookupRecord,
};
use super::{Method, PreparedObject, PreparedScene, ShadingPoint};
use crate::geometry::spherical::horizon_split::HorizonSplit;
use crate::geometry::spherical::spherical_polygon::clip_loop_to_half_spaces;
use crate::geometry::{
    ExactSilhouetteScratch, FrontCut, HoleScratch, HorizonScratch, Overlap, PlanarPolygon,
    PolygonLoops, ProjectionPlane, SetDifference, Sidedness, SilhouettePoint, SphericalPolygon,
    TileQuery, TileRegion, classify_overlap, clip_to_horizon, clip_to_window, contour_edges,
    face_polygon, part_inside_convex, window_cone,
};
use crate::ltc::{LtcEntry, form_factor, form_factor_terms};
use crate::math::Frame;
use crate::scene::Material;
use glam::DVec3;
use occluder_cache::OccluderCache;

/// Counters of the work done at the last shading point (for AOVs and benchmarks).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct ShadingStats {
    /// Occluders kept by `GetBetween`, summed over lights.
    pub occluders_kept: u32,
    /// Edges of the light polygons after horizon clipping, summed over lights.
    pub light_edges: u32,
    /// Set differences performed.
    pub set_differences: u32,
    /// How each light piece ended.
    pub shortcuts: Shortcuts,
    /// Light pieces whose visible polygon is not inside the light's (`super::invariant`): a
    /// bug wherever it is not zero.
    pub violations: u32,
    /// Paths that gave up at the point for one that is exact there.
    pub fallbacks: Fallbacks,
    /// Occluders subtracted inside a light's window split at the horizon (`subtract_split`:
    /// a point on the occluder's own surface under a light that reaches its horizon).
    pub horizon_splits: u32,
}

/// How many light pieces (a light taken whole, or one face of a light taken face by face) at a
/// shading point ended in each way; every piece is counted once.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Shortcuts {
    /// The light's bounding sphere lies below the tangent plane: not looked at.
    pub light_below_horizon: u32,
    /// Nothing of the piece's polygon is above the horizon (found by clipping).
    pub clipped_away: u32,
    /// `GetBetween` kept no occluder: fully lit, no set difference.
    pub no_occluder: u32,
    /// Occluders were kept, but each was disjoint from the visible polygon: fully lit, no set
    /// difference.
    pub all_disjoint: u32,
    /// An occluder covered what was left of the piece: the remaining occluders were skipped.
    pub covered: u32,
    /// The rest: at least one set difference (a penumbra or a partial cover).
    pub subtracted: u32,
}

impl Shortcuts {
    /// Component-wise sum.
    pub(crate) fn add(&mut self, o: &Shortcuts) {
        self.light_below_horizon += o.light_below_horizon;
        self.clipped_away += o.clipped_away;
        self.no_occluder += o.no_occluder;
        self.all_disjoint += o.all_disjoint;
        self.covered += o.covered;
        self.subtracted += o.subtracted;
    }

    /// Every piece counted.
    pub(crate) fn total(&self) -> u64 {
        [
            self.light_below_horizon,
            self.clipped_away,
            self.no_occluder,
            self.all_disjoint,
            self.covered,
            self.subtracted,
        ]
        .iter()
        .map(|&c| c as u64)
        .sum()
    }
}

/// Per-thread buffers of the pipeline, reused from one shading point to the next so that the
/// hot loop allocates nothing once they have grown.
#[derive(Default)]
pub struct ShadingScratch {
    pub(super) outline: OutlineScratch,
    pub(super) horizon: HorizonScratch,
    pub(super) difference: SetDifference,
    pub(super) hole: HoleScratch,
    /// The part of an occluder inside a convex visible polygon, while that difference is held
    /// as a hole (`geometry::spherical::hole_difference`, [`subtract_planar`]): the visible region is
    /// `visible` less it. Empty otherwise.
    pub(super) visible_hole: PlanarPolygon,
    /// The occluder polygon the hole came from, and its index: what [`settle_hole`] subtracts.
    pub(super) hole_occluder: PlanarPolygon,
    pub(super) hole_oi: usize,
    /// A second occluder's, while `visible_hole` holds two holes and their overlap
    /// ([`second_hole`]: its loop count is then above one).
    pub(super) hole_occluder2: PlanarPolygon,
    pub(super) hole_oi2: usize,
    /// The first hole alone, the second hole and the two holes' overlap, while a second hole
    /// is taken; and the first difference of a region with two holes (`sampled_region`).
    pub(super) hole_first: PlanarPolygon,
    pub(super) hole_second: PlanarPolygon,
    pub(super) hole_overlap: PlanarPolygon,
    pub(super) sampled_plane: PlanarPolygon,
    /// One loop of the holes, for the specular lobe (`integrate_lobes`).
    pub(super) hole_loop: SphericalPolygon,
    pub(super) hole_sph: SphericalPolygon,
    /// The region the LTC's correction samples when it is held with a hole (`sampled_region`).
    pub(super) sampled: SphericalPolygon,
    /// Kept aside while [`settle_hole`] takes an occluder face by face.
    pub(super) occ_plane_aside: PlanarPolygon,
    pub(super) face_list_aside: Vec<u32>,
    /// The hole through a lobe's transform, and clipped again (`integrate_lobes`).
    pub(super) hole_lobe: SphericalPolygon,
    pub(super) hole_lobe_clip: SphericalPolygon,
    /// The visible region with its hole as one polygon (the hole reversed), for the recorder.
    pub(super) visible_shown: SphericalPolygon,
    pub(super) light_sph: SphericalPolygon,
    pub(super) light_clip: SphericalPolygon,
    /// The light's edge normals, for the invariant's check.
    pub(super) light_normals: Vec<(DVec3, f64)>,
    /// The form factor of `visible_sph` where the region is held with holes (`visible_on_sphere`).
    pub(super) f_region: Option<f64>,
    pub(super) occ_sph: SphericalPolygon,
    pub(super) occ_clip: SphericalPolygon,
    pub(super) occ_plane: PlanarPolygon,
    pub(super) visible: PlanarPolygon,
    pub(super) visible_next: PlanarPolygon,
    pub(super) visible_sph: SphericalPolygon,
    pub(super) lobe_poly: SphericalPolygon,
    pub(super) lobe_clip: SphericalPolygon,
    pub(super) kept: Vec<u32>,
    /// What this point keeps of each occluder for its next lights.
    occluders: OccluderCache,
    pub(super) face_buf: Vec<DVec3>,
    /// The faces of an occluder taken face by face that can overlap the light.
    pub(super) face_list: Vec<u32>,
    pub(super) cone_buf: Vec<DVec3>,
    pub(super) window_bufs: [Vec<DVec3>; 3],
    /// A light's window split at the horizon for a point on the occluder (`subtract_split`).
    pub(super) split: HorizonSplit,
    /// A face clipped to the lower part of that split.
    pub(super) split_face: Vec<DVec3>,
    /// The images of a light's faces that reach below the sky windows (`sky_windows`), one
    /// after another, and per face its index and the range of its image.
    pub(super) sky_face: Vec<DVec3>,
    pub(super) sky_faces: Vec<(u32, u32, u32)>,
    pub(super) split_tmp: Vec<DVec3>,
    /// The faces of an occluder taken face by face under the environment (`environment`).
    pub(super) env_faces: Vec<u32>,
    pub(super) correction: CorrectionScratch,
    /// The sampled correction of the LTC at the last shading point (`shade_corrected`), summed
    /// over lights and weighted by their radiance, and its variance.
    pub(super) correction_sum: CorrectionEstimate,
    /// The region of the point's tile on its object, when the renderer shades tiles: windowed
    /// outlines take their candidate edges from what the region shares
    /// (`geometry::silhouettes::tile_candidates`), the same edges as alone.
    tile_region: Option<TileRegion>,
    pub stats: ShadingStats,
    /// The derivative's buffers and the point's rate ([`shade_with_rate`]).
    pub(super) derivative: DerivativeScratch,
}

impl ShadingScratch {
    /// Starts a new shading point: counters reset, the occluder cache invalidated.
    pub(super) fn begin_point(&mut self, scene: &PreparedScene) {
        self.stats = ShadingStats::default();
        self.outline.fallbacks = Fallbacks::default();
        self.correction_sum = CorrectionEstimate::default();
        self.occluders.begin_point(scene.occluders.len());
    }

    /// Caps the set difference's walks at `steps` when the polygon subtracted has more than
    /// `clip_vertices` vertices (tests of what a bound crossing does); `None` lifts the cap.
    #[doc(hidden)]
    pub fn limit_set_difference_walks(&mut self, cap: Option<(usize, usize)>) {
        self.difference.limit_walks(cap);
    }

    /// The region of the tile the next shading points belong to (`None`: each point alone).
    /// The points must lie in its ball; one that does not takes the whole hierarchy.
    pub fn share_with_tile(&mut self, region: Option<TileRegion>) {
        self.tile_region = region;
    }

    /// Subtrees of edge hierarchies built for tiles, and windowed queries that used one.
    pub fn tile_sharing(&self) -> (u64, u64) {
        let t = &self.outline.window.tile_candidates;
        (t.built, t.shared)
    }

    /// Ends a shading point: the silhouette stage's fallbacks join the point's counters.
    pub(super) fn end_point(&mut self) {
        self.stats.fallbacks.add(&self.outline.fallbacks);
        self.outline.fallbacks = Fallbacks::default();
    }
}

/// Convex occluder outlines with more vertices than this are clipped to the light's window
/// before the set difference (`clip_to_window`).
const WINDOW_CLIP_MIN_VERTICES: usize = 12;

/// Relative distance (of the mesh's radius) below which a face is taken to contain the shading
/// point (its spherical polygon is a sliver of zero area on the horizon), and by which a light
/// face's cut plane is moved toward its front (`face_sides::light_face_cut`). Four orders above
/// the rounding of a plane's evaluation at a vertex on it, and no more: the moved plane trims a
/// neighbouring face's shared edge by the offset over the sine of their dihedral angle (up to
/// 1e-7 on Blender's nearly flat neighbours at 1e-9), slivers that the boundary formulation
/// keeps and the derivative's supports miss (docs/boundary-integral.md, "Under stress").
pub(super) const COPLANAR: f64 = 1e-12;

/// The BRDF lobes of a material at one shading point.
pub(super) struct Lobes {
    pub(super) kd: DVec3,
    pub(super) specular: Option<(LtcEntry, DVec3)>,
    /// The GGX lobe against its LTC, when the LTC's error is to be corrected.
    pub(super) glossy: Option<GlossyLobe>,
}

/// What every stage at one shading point reads.
pub(super) struct PointContext<'a> {
    pub(super) scene: &'a PreparedScene,
    pub(super) sp: &'a ShadingPoint,
    pub(super) frame: Frame,
    pub(super) lobes: Lobes,
    pub(super) method: Method,
    /// Samples of the LTC's correction (`shade_corrected`), if any.
    pub(super) correction: Option<CorrectionSampling>,
    /// The motion a derivative follows (`shade_with_rate`), if any.
    pub(super) rates: Option<PointRates<'a>>,
}

/// Outgoing radiance at `sp` toward the viewer, by 000 Alg. 1 (diffuse + specular). `rec`
/// receives every intermediate polygon; pass [`super::NoRecorder`] to record nothing.
pub fn shade<R: Recorder>(
    scene: &PreparedScene,
    sp: &ShadingPoint,
    material: &Material,
    method: Method,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) -> DVec3 {
    shade_point(scene, sp, material, method, None, None, scratch, rec)
}

/// Radiance at a shading point split into the LTC's value and a sampled correction of it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CorrectedRadiance {
    /// What [`shade`] returns: exact visibility, LTC shading.
    pub ltc: DVec3,
    /// Estimate of `∫_V (f_GGX cos − s D̂_M) L` summed over lights (zero for a Lambertian
    /// material): `ltc + correction` is an unbiased estimate of the GGX radiance.
    pub correction: DVec3,
    /// Variance of `correction`.
    pub variance: DVec3,
}

/// A pixel of `analytic-exact`: what the camera ray sees emitted, plus the LTC image, plus the
/// LTC's sampled correction, summed in that order. The one composition of the render (on its
/// per-pixel buffers) and of the probe (on the picked ray), so that both give the same bits.
#[inline]
pub fn analytic_exact_pixel(emitted: DVec3, ltc: DVec3, correction: DVec3) -> DVec3 {
    emitted + ltc + correction
}

impl CorrectedRadiance {
    pub fn total(&self) -> DVec3 {
        self.ltc + self.correction
    }
}

/// [`shade`] plus the LTC's error sampled inside each exact visible polygon
/// (`super::ltc_correction`): `--method analytic-exact`, and the unbiased U of the ratio
/// estimator with `Method::Unshadowed`.
pub fn shade_corrected<R: Recorder>(
    scene: &PreparedScene,
    sp: &ShadingPoint,
    material: &Material,
    method: Method,
    sampling: &CorrectionSampling,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) -> CorrectedRadiance {
    let ltc = shade_point(
        scene,
        sp,
        material,
        method,
        Some(sampling),
        None,
        scratch,
        rec,
    );
    CorrectedRadiance {
        ltc,
        correction: scratch.correction_sum.mean,
        variance: scratch.correction_sum.variance,
    }
}

/// [`shade`] and its derivative along `motion` at the point (docs/derivatives.md): returns
/// the radiance and its rate `dL/dθ`. The same stages compute the radiance; the derivative is
/// taken of the visible polygons they found. What made the rate unreliable at the point is
/// in [`ShadingScratch::rate_notes`].
pub fn shade_with_rate<R: Recorder>(
    scene: &PreparedScene,
    sp: &ShadingPoint,
    material: &Material,
    method: Method,
    motion: &PointMotion,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) -> (DVec3, DVec3) {
    let l = shade_point(
        scene,
        sp,
        material,
        method,
        None,
        Some(motion),
        scratch,
        rec,
    );
    (l, scratch.derivative.sum)
}

/// What made a point's rate unreliable ([`shade_with_rate`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RateNotes {
    /// Edges of a visible polygon whose support was not found though they may move.
    pub unsupported: u32,
    /// The LTC lookup lies within the finite-difference step of a table node.
    pub near_table_node: bool,
}

impl ShadingScratch {
    /// What made the last point's rate unreliable.
    pub fn rate_notes(&self) -> RateNotes {
        RateNotes {
            unsupported: self.derivative.unsupported,
            near_table_node: self.derivative.near_table_node,
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn shade_point<R: Recorder>(
    scene: &PreparedScene,
    sp: &ShadingPoint,
    material: &Material,
    method: Method,
    correction: Option<&CorrectionSampling>,
    motion: Option<&PointMotion>,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) -> DVec3 {
    scratch.begin_point(scene);
    let frame = Frame::from_normal_and_view(sp.normal, sp.view);
    let correction = correction.filter(|c| c.samples > 0 && material.has_specular());
    let specular = material.has_specular().then(|| {
        let entry = scene
            .ltc
            .lookup(sp.normal.dot(sp.view).clamp(0.0, 1.0), material.alpha);
        // Schlick's Fresnel per channel: F0 (norm − fresnel) + fresnel (see docs/ltc.md).
        let scale = material.ks.map(|f0| entry.specular_scale(f0));
        (entry, scale)
    });
    let glossy = correction
        .and(specular.as_ref())
        .and_then(|(entry, scale)| {
            let v = frame.to_local(sp.view);
            GlossyLobe::new(entry, *scale, v, material.alpha, material.ks)
        });
    let rates = motion.map(|point| {
        point_rates(
            scene,
            sp,
            material,
            point,
            specular.is_some(),
            &mut scratch.derivative,
        )
    });
    let lobes = Lobes {
        kd: material.kd,
        specular,
        glossy,
    };
    let ctx = PointContext {
        scene,
        sp,
        frame,
        lobes,
        method,
        correction: correction.copied(),
        rates,
    };
    let mut total = DVec3::ZERO;
    for l in 0..scene.lights.len() {
        total += shade_light(&ctx, l, scratch, rec);
    }
    scratch.end_point();
    total
}

/// The rates of a point with a derivative (its buffers begun: only such a point pays for
/// them), and the LTC entry's rate where the normal turns. Out of line, as `lobe_rates`.
#[inline(never)]
fn point_rates<'a>(
    scene: &PreparedScene,
    sp: &ShadingPoint,
    material: &Material,
    point: &'a PointMotion,
    specular: bool,
    d: &mut DerivativeScratch,
) -> PointRates<'a> {
    d.begin_point(scene.objects.len());
    let cos = sp.normal.dot(sp.view).clamp(0.0, 1.0);
    let ltc = (point.cos_rate != 0.0 && specular).then(|| {
        let (rate, node) = scene.ltc.lookup_rate(cos, material.alpha);
        d.near_table_node = node <= 2.0 * FD_STEP * point.cos_rate.abs();
        rate.scaled(point.cos_rate)
    });
    PointRates { point, ltc }
}

/// Alg. 1 lines 2–16 for light `l` (index into `scene.lights`).
fn shade_light<R: Recorder>(
    ctx: &PointContext,
    l: usize,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) -> DVec3 {
    let (scene, sp) = (ctx.scene, ctx.sp);
    let (light_id, radiance) = scene.lights[l];
    let light = &scene.objects[light_id as usize];
    let on_light = sp.object == Some(light.object);
    // Entirely below the tangent plane: every part of it would clip away at the horizon.
    if sp.normal.dot(light.poly.center - sp.position) < -light.poly.radius {
        scratch.stats.shortcuts.light_below_horizon += 1;
        rec.begin_light(l, None);
        rec.end_light(DVec3::ZERO, DVec3::ZERO);
        return DVec3::ZERO;
    }
    // An occluder passing through the light (no plane separates them) is in front of some of
    // its faces and behind others: the light goes face by face, each face cutting the occluder
    // at its plane, which is exact.
    let outline = if scene.light_is_crossed(l) {
        Outline::Faces
    } else {
        light.spherical_polygon(
            sp.position,
            &ctx.frame,
            Role::Light,
            ctx.method,
            on_light,
            None,
            &mut scratch.light_sph,
            &mut scratch.outline,
        )
    };
    match outline {
        Outline::Nothing => DVec3::ZERO,
        Outline::Whole { exact, from_tree } => {
            // A closed non-convex light as a whole: its exact silhouette already accounts for
            // the faces it hides of itself (001 Fig. 4.1), so its own mesh is not subtracted.
            rec.begin_light(l, None);
            record_contour(
                rec,
                None,
                light,
                outline,
                false,
                &scratch.light_sph,
                sp,
                &ctx.frame,
            );
            if exact {
                let exact_scratch = &scratch.outline.exact;
                record_exact(light, None, from_tree, sp, &ctx.frame, exact_scratch, rec);
            }
            let whole = LightPiece {
                light: l,
                radiance,
                face: None,
                sky_window: None,
            };
            shade_light_piece(ctx, &whole, scratch, rec)
        }
        // At a point on a large closed light, the light's own image over the point's sky, window
        // by window, instead of its faces one by one against each other.
        Outline::Faces
            if on_light
                && let Some(own) = sky_windows::own_occluder(ctx, l)
                && let Some(total) = sky_windows::shade_own_light(ctx, l, own, scratch, rec) =>
        {
            total
        }
        Outline::Faces => {
            // A stand-in is for the silhouette path: face by face, the mesh's own faces (its
            // triangles when some face is bent).
            let faces = light.face_pieces();
            let mut total = DVec3::ZERO;
            for f in 0..faces.face_count() {
                if on_light && skip_own_face(light, f, sp) {
                    continue;
                }
                if faces.face_planes[f].eval(sp.position) <= 0.0 {
                    continue; // lights emit from the front only
                }
                let piece = LightPiece {
                    light: l,
                    radiance,
                    face: Some((f, light_face_cut(faces, f))),
                    sky_window: None,
                };
                rec.begin_light(l, Some(f));
                face_polygon(
                    faces,
                    f,
                    sp.position,
                    &ctx.frame,
                    Sidedness::FrontOnly,
                    None,
                    &mut scratch.light_sph,
                    &mut scratch.face_buf,
                );
                total += shade_light_piece(ctx, &piece, scratch, rec);
            }
            total
        }
    }
}

/// Tells a recorder how the exact silhouette just computed was found (read from the scratch of
/// that same call, or from the tree's leaf); nothing at all for [`super::NoRecorder`].
fn record_exact<R: Recorder>(
    obj: &PreparedObject,
    occluder: Option<usize>,
    from_tree: bool,
    sp: &ShadingPoint,
    frame: &Frame,
    scratch: &ExactSilhouetteScratch,
    rec: &mut R,
) {
    if !R::ENABLED {
        return;
    }
    let x = sp.position;
    let local = |d: DVec3| frame.to_local(d);
    let record = if from_tree {
        let crossings = obj
            .silhouette_tree()
            .and_then(|t| t.leaf_loops(&obj.poly, obj.tree_point(x)))
            .map(|loops| {
                loops
                    .into_iter()
                    .flatten()
                    .filter(|p| matches!(p, SilhouettePoint::Crossing(..)))
                    .filter_map(|p| p.direction(&obj.poly, x))
                    .map(local)
                    .collect()
            })
            .unwrap_or_default();
        ExactSilhouetteRecord {
            occluder,
            from_tree,
            crossings,
            rejected: Vec::new(),
        }
    } else {
        ExactSilhouetteRecord {
            occluder,
            from_tree,
            crossings: scratch.crossings().iter().map(|&d| local(d)).collect(),
            rejected: scratch
                .rejected_pieces()
                .map(|[a, b]| [local(a), local(b)])
                .collect(),
        }
    };
    rec.exact_silhouette(&record);
}

/// Hands a recorder the contour edges the outline stage worked from, and only those (the
/// debugger draws the recording, never a recomputation; nothing at all for
/// [`super::NoRecorder`]):
///
/// * a convex silhouette read from a BSP tree: its arcs, which are the contour edges of a convex
///   mesh (the tree stores them as the silhouette's cycle);
/// * a silhouette chained or an exact one computed at the point: the contour edges from `x`
///   (`contour_edges`, the predicate both start from);
/// * an exact silhouette read from a tree, one found inside a light's window, or a mesh taken
///   face by face: none, since none were computed.
///
/// And, when the outline stage consulted the mesh's tree (every whole outline but a windowed
/// one), the lookup: which tree, the planes on the point's path, whether its leaf answered.
#[allow(clippy::too_many_arguments)]
fn record_contour<R: Recorder>(
    rec: &mut R,
    occluder: Option<usize>,
    obj: &PreparedObject,
    outline: Outline,
    windowed: bool,
    silhouette: &SphericalPolygon,
    sp: &ShadingPoint,
    frame: &Frame,
) {
    if !R::ENABLED {
        return;
    }
    let Outline::Whole { exact, from_tree } = outline else {
        return;
    };
    let (poly, x) = (&obj.poly, sp.position);
    let tree = obj.silhouette_tree().filter(|_| !windowed);
    let tree_x = obj.tree_point(x);
    if let Some(t) = tree {
        rec.tree_lookup(&TreeLookupRecord {
            occluder,
            kind: t.kind(),
            tree_point: tree_x,
            steps: t.path(tree_x).map(|p| p.steps).unwrap_or_default(),
            answered: from_tree,
        });
    }
    let (edges, world): (Vec<[DVec3; 2]>, Vec<[DVec3; 2]>) = match (exact, from_tree) {
        (false, true) => {
            let edges = silhouette
                .loops()
                .flat_map(|lp| (0..lp.len()).map(move |k| [lp[k], lp[(k + 1) % lp.len()]]))
                .collect();
            // The same loops' vertices on the mesh (a convex tree stores vertices only); a
            // vertex at the point itself has no direction and is left out of both.
            let mut world = Vec::new();
            for lp in tree
                .and_then(|t| t.leaf_loops(poly, tree_x))
                .unwrap_or_default()
            {
                let pts: Vec<DVec3> = lp
                    .iter()
                    .filter_map(|p| match *p {
                        SilhouettePoint::Vertex(v) => Some(poly.vertices[v as usize]),
                        SilhouettePoint::Crossing(..) => None,
                    })
                    .filter(|&w| (w - x).try_normalize().is_some())
                    .collect();
                world.extend((0..pts.len()).map(|k| [pts[k], pts[(k + 1) % pts.len()]]));
            }
            (edges, world)
        }
        (_, false) if !windowed => {
            let at = |i: u32| poly.vertices[i as usize];
            let dir = |i: u32| frame.to_local(at(i) - x).normalize_or_zero();
            contour_edges(poly, x)
                .map(|[a, b]| ([dir(a), dir(b)], [at(a), at(b)]))
                .unzip()
        }
        _ => return,
    };
    rec.contour(occluder, &edges, &world);
}

/// Is face `f` of `obj` the face the shading point lies on, or coplanar with it?
#[inline]
fn skip_own_face(obj: &PreparedObject, f: usize, sp: &ShadingPoint) -> bool {
    let pieces = obj.face_pieces();
    sp.face == Some(obj.piece_face(f))
        || pieces.face_planes[f].eval(sp.position).abs() <= COPLANAR * pieces.radius
}

/// What one pass of lines 5–16 integrates: a whole light (its silhouette), or one face of it
/// with the face's plane offset by the coplanarity tolerance toward the shading point.
pub(super) struct LightPiece {
    light: usize,
    radiance: DVec3,
    face: Option<(usize, FrontCut)>,
    /// A window of the sky at a point on the light itself (`sky_windows`): what lights the
    /// point there is the part of the window the light's own mesh (this occluder) covers.
    sky_window: Option<usize>,
}

/// Lines 5–16 of Alg. 1 for one light piece, whose spherical polygon is in `scratch.light_sph`.
fn shade_light_piece<R: Recorder>(
    ctx: &PointContext,
    piece: &LightPiece,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) -> DVec3 {
    rec.light_polygon(Stage::Silhouette, &scratch.light_sph);
    clip_to_horizon(
        &scratch.light_sph,
        &mut scratch.light_clip,
        &mut scratch.horizon,
    );
    rec.light_polygon(Stage::HorizonClipped, &scratch.light_clip);
    if scratch.light_clip.is_empty() {
        scratch.stats.shortcuts.clipped_away += 1;
        rec.end_light(DVec3::ZERO, DVec3::ZERO);
        return DVec3::ZERO;
    }
    scratch.stats.light_edges += scratch.light_clip.vertex_count() as u32;
    let plane = ProjectionPlane::NORMAL;
    plane.project(&scratch.light_clip, &mut scratch.visible);
    scratch.visible_hole.clear();

    // A light handled face by face hides parts of itself.
    let self_occluding = piece.face.is_some();
    let scene = ctx.scene;
    let differences_before = scratch.stats.set_differences;
    let considered = match ctx.method {
        Method::Unshadowed => {
            // No occluders, but a non-convex light still hides its own faces.
            let own = self_occluding
                .then(|| {
                    let light_id = scene.lights[piece.light].0;
                    scene.occluders.iter().position(|&o| o == light_id)
                })
                .flatten();
            if let Some(oi) = own {
                subtract_occluder(ctx, oi, Some(piece), scratch, rec);
            }
            own.is_some() as usize
        }
        Method::Analytic | Method::PerTriangle => {
            get_between(
                scene,
                piece.light,
                ctx.sp,
                self_occluding,
                &mut scratch.kept,
            );
            if R::ENABLED {
                let kept: Vec<usize> = scratch.kept.iter().map(|&k| k as usize).collect();
                rec.culled_occluders(&kept);
            }
            scratch.stats.occluders_kept += scratch.kept.len() as u32;
            for k in 0..scratch.kept.len() {
                if scratch.visible.is_empty() {
                    break;
                }
                let oi = scratch.kept[k] as usize;
                subtract_occluder(ctx, oi, Some(piece), scratch, rec);
            }
            scratch.kept.len()
        }
    };
    let shortcuts = &mut scratch.stats.shortcuts;
    if considered == 0 {
        shortcuts.no_occluder += 1;
    } else if scratch.visible.is_empty() {
        shortcuts.covered += 1;
    } else if scratch.stats.set_differences > differences_before {
        shortcuts.subtracted += 1;
    } else {
        shortcuts.all_disjoint += 1;
    }

    let f_visible = visible_on_sphere(scratch, rec);
    // Without a set difference the visible polygon is the light's: nothing to check.
    if scratch.stats.set_differences > differences_before
        && !visible_within_light(
            &scratch.light_clip,
            &scratch.visible_sph,
            &scratch.hole_sph,
            f_visible,
            scratch.f_region,
            &mut scratch.light_normals,
        )
    {
        scratch.stats.violations += 1;
    }
    let (mut diffuse, mut specular, mut rate) =
        integrate_lobes(ctx, piece, f_visible, scratch, rec);
    if let Some(own) = piece.sky_window
        && !scratch.visible.is_empty()
    {
        // The light's own image in the window (less the other occluders): the window, less
        // what is left of it once the light's mesh is subtracted as well.
        subtract_occluder(ctx, own, Some(piece), scratch, rec);
        let f_rest = visible_on_sphere(scratch, rec);
        let (d, s, r) = integrate_lobes(ctx, piece, f_rest, scratch, rec);
        rate -= r;
        // Rounding can leave the difference of two equal integrals a few ulps below zero.
        diffuse = (diffuse - d).max(DVec3::ZERO);
        specular = (specular - s).max(DVec3::ZERO);
    }
    if ctx.rates.is_some() {
        scratch.derivative.sum += rate;
        rec.light_rate(rate);
    }
    rec.end_light(diffuse, specular);
    diffuse + specular
}

/// The visible region on the sphere (`visible_sph`, less `hole_sph` while a difference is held
/// as a hole), recorded, and its form factor: the diffuse lobe's integral, and the invariant's.
fn visible_on_sphere<R: Recorder>(scratch: &mut ShadingScratch, rec: &mut R) -> f64 {
    let plane = ProjectionPlane::NORMAL;
    plane.reproject(&scratch.visible, &mut scratch.visible_sph);
    scratch.f_region = None;
    if scratch.visible_hole.is_empty() {
        scratch.hole_sph.clear();
        rec.light_polygon(Stage::Visible, &scratch.visible_sph);
        return form_factor(scratch.visible_sph.loops());
    }
    plane.reproject(&scratch.visible_hole, &mut scratch.hole_sph);
    let (f_region, scale_region) = form_factor_and_scale(&scratch.visible_sph);
    let (f_hole, scale_hole) = form_factor_and_scale(&scratch.hole_sph);
    let f = f_region - f_hole;
    scratch.f_region = Some(f_region);
    if f <= HOLE_COVERS * (scale_region + scale_hole) {
        // The hole is the whole region, up to the rounding of two equal integrals: empty, as
        // Greiner–Hormann's difference is there.
        for poly in [&mut scratch.visible, &mut scratch.visible_hole] {
            poly.clear();
        }
        scratch.visible_sph.clear();
        scratch.hole_sph.clear();
        rec.light_polygon(Stage::Visible, &scratch.visible_sph);
        return 0.0;
    }
    if R::ENABLED {
        with_hole(
            &scratch.visible_sph,
            &scratch.hole_sph,
            &mut scratch.visible_shown,
        );
        rec.light_polygon(Stage::Visible, &scratch.visible_shown);
    }
    f
}

/// A region less a hole is empty when its form factor is below this fraction of the sum of the
/// magnitudes of the edge terms (both polygons'): that is the rounding of the difference of two
/// nearly equal integrals (a region covered with contacts along its boundary, which
/// `geometry::spherical::overlap` cannot call covered). Each term carries a few ulps (acos, a cross
/// product, a normalisation: under 8ε) and the sum one per term, so for up to 64 edges the
/// rounding stays below 72ε ≈ 1.6e-14 of the magnitudes. Near the horizon the terms are far
/// larger than the integral (their cosine factors cancel), which a bound relative to the
/// region's integral would not see.
const HOLE_COVERS: f64 = 1e-13;

/// The form factor of `poly` (000 Eq. 9) and the sum of the magnitudes of its terms, on the
/// same scale: the size of its rounding.
fn form_factor_and_scale(poly: &SphericalPolygon) -> (f64, f64) {
    let (mut sum, mut magnitude) = (0.0, 0.0);
    form_factor_terms(poly.loops(), |_, _, t| {
        sum += t;
        magnitude += t.abs();
    });
    (
        sum / std::f64::consts::TAU,
        magnitude / std::f64::consts::TAU,
    )
}

/// `region` and `hole` reversed, as one polygon: what a recording shows of a region with a hole.
fn with_hole(region: &PolygonLoops, hole: &PolygonLoops, out: &mut PolygonLoops) {
    out.copy_from(region);
    for lp in hole.loops() {
        out.push_loop(lp.iter().rev().copied());
    }
}

/// Subtracts occluder `oi` from the light piece (000 Alg. 1, lines 8–10): as a whole where it
/// has one outline at the point, else face by face.
pub(super) fn subtract_occluder<R: Recorder>(
    ctx: &PointContext,
    oi: usize,
    piece: Option<&LightPiece>,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) {
    let scene = ctx.scene;
    let occ_id = scene.occluders[oi];
    let own_mesh = piece.is_some_and(|p| occ_id == scene.lights[p.light].0);
    let cut = match depth_cut(ctx, oi, own_mesh, piece) {
        DepthCut::Behind => return,
        DepthCut::InFront => None,
        DepthCut::Across(plane) => Some(plane),
    };
    let skip_face = piece
        .filter(|_| own_mesh)
        .and_then(|p| p.face.map(|(f, _)| f));
    if cut.is_none() && skip_face.is_none() && subtract_whole(ctx, oi, piece, scratch, rec) {
        return;
    }
    subtract_faces(ctx, oi, piece, cut.as_ref(), skip_face, false, scratch, rec);
}

/// Where an occluder lies against the face of the light piece, for depth.
enum DepthCut {
    /// Wholly behind the face's plane: it hides nothing of it.
    Behind,
    /// In front wherever it overlaps the light: no cut.
    InFront,
    /// On both sides: only its part in front of this plane counts.
    Across(FrontCut),
}

/// How occluder `oi` must be cut for depth against the light piece. An occluder separated from
/// the whole light by a plane is in front of it wherever they overlap (`get_between` checked
/// the side of the point); otherwise, and for the light's own mesh, only what lies in front of
/// the light face's plane hides it.
fn depth_cut(
    ctx: &PointContext,
    oi: usize,
    own_mesh: bool,
    piece: Option<&LightPiece>,
) -> DepthCut {
    let Some((l, (f, cut))) = piece.and_then(|p| p.face.map(|face| (p.light, face))) else {
        return DepthCut::InFront;
    };
    if !own_mesh && ctx.scene.separation(l, oi).is_some() {
        return DepthCut::InFront;
    }
    let occ = &ctx.scene.objects[ctx.scene.occluders[oi] as usize];
    // The light's own mesh against its own face: decided when the scene was prepared.
    let side = match (own_mesh, &occ.face_sides) {
        (true, Some(sides)) => sides.get(f),
        _ => in_front(occ.face_pieces(), &cut.front_plane()),
    };
    match side {
        InFront::Nothing => DepthCut::Behind,
        InFront::All => DepthCut::InFront,
        InFront::Part => DepthCut::Across(cut),
    }
}

/// Subtracts occluder `oi` as a whole: its outline at the point, clipped to the horizon,
/// projected and subtracted. Its projection, and a convex outline before a window clipped it,
/// do not depend on the light: the point keeps them for its next lights
/// ([`OccluderCache`]). `false` when it must go face by face: no single outline here, or the
/// set difference crossed a bound.
fn subtract_whole<R: Recorder>(
    ctx: &PointContext,
    oi: usize,
    piece: Option<&LightPiece>,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) -> bool {
    let occ = &ctx.scene.objects[ctx.scene.occluders[oi] as usize];
    // A large mesh's polygon is found inside the light's window: not kept for other lights.
    let windowed =
        piece.is_some() && occ.kind().is_windowed() && scratch.light_clip.loop_count() == 1;
    if !windowed
        && scratch
            .occluders
            .lend_projected::<R>(oi, &mut scratch.occ_plane)
    {
        let done = subtract_planar(ctx, piece, oi, piece.is_some(), scratch, rec);
        scratch.occluders.take_back(oi, &mut scratch.occ_plane);
        if done {
            return true;
        }
    }
    let (outline, kept_outline) = whole_outline(ctx, oi, piece, windowed, scratch, rec);
    // At a point on this mesh under a light that reaches the horizon, the windowed outline
    // cannot take the light's window (its own face's edges lie on the horizon): split the
    // window along a circle tilted just above the horizon, the outline in the part above it
    // and the faces one by one in the thin part below.
    if windowed
        && ctx.sp.object == Some(occ.object)
        && matches!(outline, Outline::Faces)
        && scratch.split.split(scratch.light_clip.loop_at(0))
        && subtract_split(ctx, oi, piece, scratch, rec)
    {
        return true;
    }
    let Outline::Whole { exact, from_tree } = outline else {
        return false;
    };
    let (sp, frame) = (ctx.sp, &ctx.frame);
    record_contour(
        rec,
        Some(oi),
        occ,
        outline,
        windowed,
        &scratch.occ_sph,
        sp,
        frame,
    );
    if exact && !windowed {
        record_exact(
            occ,
            Some(oi),
            from_tree,
            sp,
            frame,
            &scratch.outline.exact,
            rec,
        );
    }
    // A convex outline of many vertices around a small light: only its part near the light
    // reaches the set difference (the same difference, far fewer vertices).
    let clipped = piece.is_some()
        && !exact
        && scratch.occ_sph.vertex_count() > WINDOW_CLIP_MIN_VERTICES
        && scratch.light_clip.loop_count() == 1
        && clip_to_window(
            &scratch.occ_sph,
            scratch.light_clip.loop_at(0),
            &mut scratch.occ_clip,
            &mut scratch.window_bufs,
        );
    if clipped {
        if !windowed && !kept_outline {
            scratch.occluders.keep_outline::<R>(oi, &scratch.occ_sph);
        }
        std::mem::swap(&mut scratch.occ_sph, &mut scratch.occ_clip);
    }
    clip_and_project(oi, None, scratch, rec);
    let done = subtract_planar(ctx, piece, oi, piece.is_some(), scratch, rec);
    if !windowed && !clipped {
        scratch
            .occluders
            .keep_projected::<R>(oi, &mut scratch.occ_plane);
    }
    // Not done: the set difference with the whole outline crossed a bound; face by face,
    // which is exact too.
    done
}

/// Occluder `oi`'s outline at the point into `scratch.occ_sph`, found inside the light's
/// window when `windowed` (with the tile's shared candidate edges), or the outline this point
/// kept (the second value); the tile's sharing recorded.
fn whole_outline<R: Recorder>(
    ctx: &PointContext,
    oi: usize,
    piece: Option<&LightPiece>,
    windowed: bool,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) -> (Outline, bool) {
    let scene = ctx.scene;
    let occ = &scene.objects[scene.occluders[oi] as usize];
    // The window's points share their candidate edges within the tile's region: the light's
    // bounding ball bounds every window of the region's points.
    scratch.outline.window.tile = match (windowed, scratch.tile_region, piece) {
        // A sky window is not bounded by the light's cone (the region's lists assume so).
        (true, Some(region), Some(p)) if p.sky_window.is_none() => {
            let light = &scene.objects[scene.lights[p.light].0 as usize].poly;
            let sph = &scratch.light_sph;
            Some(TileQuery {
                region,
                light_centre: light.center,
                light_radius: light.radius,
                key: ((p.light as u64) << 32) | oi as u64,
                whole_light: p.face.is_none()
                    && sph.loop_count() == 1
                    && sph.loop_at(0).iter().all(|v| v.z > 0.0),
            })
        }
        _ => None,
    };
    if scratch
        .occluders
        .copy_outline::<R>(oi, &mut scratch.occ_sph)
    {
        let kept = Outline::Whole {
            exact: false,
            from_tree: false,
        };
        return (kept, true);
    }
    let window = windowed.then(|| scratch.light_clip.loop_at(0));
    let outline = occ.spherical_polygon(
        ctx.sp.position,
        &ctx.frame,
        Role::Occluder,
        ctx.method,
        ctx.sp.object == Some(occ.object),
        window,
        &mut scratch.occ_sph,
        &mut scratch.outline,
    );
    if R::ENABLED
        && windowed
        && let Some(q) = &scratch.outline.window.tile
    {
        rec.tile_share(&TileShareRecord {
            occluder: oi,
            centre: q.region.centre,
            radius: q.region.radius,
            shared_edges: scratch.outline.window.tile_candidates.last,
            mesh_edges: occ.poly.edges.len() as u32,
        });
    }
    (outline, false)
}

/// Subtracts occluder `oi` face by face: the faces the face hierarchy finds in a cone around
/// the light's polygon (all of them for small meshes), in index order as the scan visits them,
/// but the point's own face (and `skip_face`) and, for a closed mesh, the faces turned away
/// from the point. `lower`: each face clipped first to the lower part of `scratch.split`.
#[allow(clippy::too_many_arguments)]
fn subtract_faces<R: Recorder>(
    ctx: &PointContext,
    oi: usize,
    piece: Option<&LightPiece>,
    cut: Option<&FrontCut>,
    skip_face: Option<usize>,
    lower: bool,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) {
    let (scene, sp, frame) = (ctx.scene, ctx.sp, &ctx.frame);
    let occ = &scene.objects[scene.occluders[oi] as usize];
    let on_this = sp.object == Some(occ.object);
    let faces = occ.face_pieces();
    let closed = faces.diagnostics.closed_manifold;
    scratch.face_list.clear();
    let cone = match (&faces.index.face_bvh, scratch.light_clip.loop_count()) {
        (Some(_), 1) if piece.is_some() => {
            window_cone(scratch.light_clip.loop_at(0), frame, &mut scratch.cone_buf)
        }
        _ => None,
    };
    match (cone, &faces.index.face_bvh) {
        (Some((axis, cos, sin)), Some(bvh)) => {
            let list = &mut scratch.face_list;
            // A face wholly behind the cut would be clipped away whole.
            let front = cut.map(FrontCut::front_plane);
            bvh.for_each_in_cone(sp.position, axis, cos, sin, front.as_ref(), |f| {
                list.push(f)
            });
            list.sort_unstable();
        }
        _ => scratch.face_list.extend(0..faces.face_count() as u32),
    }
    for k in 0..scratch.face_list.len() {
        let g = scratch.face_list[k] as usize;
        if scratch.visible.is_empty() {
            break;
        }
        if (on_this && skip_own_face(occ, g, sp)) || skip_face == Some(g) {
            continue;
        }
        // A ray from x (outside a closed mesh) that meets the mesh enters it first through a
        // face turned toward x: the front faces alone cover its projection.
        if closed && faces.face_planes[g].eval(sp.position) <= 0.0 {
            continue;
        }
        face_polygon(
            faces,
            g,
            sp.position,
            frame,
            Sidedness::TwoSided,
            cut,
            &mut scratch.occ_sph,
            &mut scratch.face_buf,
        );
        if lower && !scratch.occ_sph.is_empty() {
            // One loop: a face's polygon, cut by a plane at most. Entirely above the tilted
            // circle, it is in the upper part, which the outline took care of; a convex face
            // is clipped to the lower part; a non-convex one (an n-gon from an exporter) is
            // subtracted whole, which removes nothing the mesh does not cover.
            let lp = scratch.occ_sph.loop_at(0);
            let tilt = -scratch.split.lower_planes[0];
            if lp.iter().all(|d| d.dot(tilt) > 0.0) {
                continue;
            }
            if is_convex_loop(lp) {
                let part = &mut scratch.split_face;
                clip_loop_to_half_spaces(
                    lp,
                    &scratch.split.lower_planes,
                    part,
                    &mut scratch.split_tmp,
                );
                scratch.occ_sph.clear();
                if !part.is_empty() {
                    scratch.occ_sph.push_loop(part.iter().copied());
                }
            }
        }
        if !scratch.occ_sph.is_empty() {
            subtract_polygon(ctx, piece, oi, g, scratch, rec);
        }
    }
}

/// Whether a loop of unit directions turns one way at every corner (a convex spherical
/// polygon, for a loop in an open hemisphere).
fn is_convex_loop(lp: &[DVec3]) -> bool {
    let n = lp.len();
    if n <= 3 {
        return true;
    }
    let turn = |k: usize| lp[k].cross(lp[(k + 1) % n]).dot(lp[(k + 2) % n]);
    let first = turn(0).signum();
    (1..n).all(|k| turn(k) * first >= 0.0)
}

/// Occluder `oi` (a large mesh the point lies on) subtracted inside the light's window split
/// at the horizon (`scratch.split`, `geometry::spherical::horizon_split`): its windowed outline in the
/// upper part, its faces one by one clipped to the lower part. `false`, with nothing
/// subtracted, when the outline cannot be found in the upper part either (the caller then
/// takes every face).
fn subtract_split<R: Recorder>(
    ctx: &PointContext,
    oi: usize,
    piece: Option<&LightPiece>,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) -> bool {
    let (scene, sp, frame) = (ctx.scene, ctx.sp, &ctx.frame);
    let occ = &scene.objects[scene.occluders[oi] as usize];
    if !scratch.split.upper.is_empty() {
        // The upper part of the window is not the whole light.
        if let Some(q) = &mut scratch.outline.window.tile {
            q.whole_light = false;
        }
        let outline = occ.spherical_polygon(
            sp.position,
            frame,
            Role::Occluder,
            ctx.method,
            true,
            Some(&scratch.split.upper),
            &mut scratch.occ_sph,
            &mut scratch.outline,
        );
        if !matches!(outline, Outline::Whole { .. }) {
            return false;
        }
        record_contour(
            rec,
            Some(oi),
            occ,
            outline,
            true,
            &scratch.occ_sph,
            sp,
            frame,
        );
        clip_and_project(oi, None, scratch, rec);
        if !subtract_planar(ctx, piece, oi, false, scratch, rec) {
            return false;
        }
    }
    subtract_faces(ctx, oi, piece, None, None, true, scratch, rec);
    scratch.stats.horizon_splits += 1;
    true
}

/// Puts occluder `oi`'s outline at the point, clipped to the horizon and projected, into
/// `scratch.visible` (the environment's union of occluders, `super::environment_occlusion`), and keeps
/// it in the per-point cache like [`subtract_occluder`] does. Returns false when the occluder
/// has no single outline there (it is taken face by face).
pub(super) fn load_occluder<R: Recorder>(
    ctx: &PointContext,
    oi: usize,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) -> bool {
    let (scene, sp, frame) = (ctx.scene, ctx.sp, &ctx.frame);
    let occ = &scene.objects[scene.occluders[oi] as usize];
    if scratch
        .occluders
        .copy_projected::<R>(oi, &mut scratch.visible)
    {
        return true;
    }
    let on_this = sp.object == Some(occ.object);
    let outline = occ.spherical_polygon(
        sp.position,
        frame,
        Role::Occluder,
        ctx.method,
        on_this,
        None,
        &mut scratch.occ_sph,
        &mut scratch.outline,
    );
    match outline {
        Outline::Faces => false,
        Outline::Nothing => {
            scratch.visible.clear();
            true
        }
        Outline::Whole { exact, from_tree } => {
            if exact {
                record_exact(
                    occ,
                    Some(oi),
                    from_tree,
                    sp,
                    frame,
                    &scratch.outline.exact,
                    rec,
                );
            }
            clip_and_project(oi, None, scratch, rec);
            scratch.visible.copy_from(&scratch.occ_plane);
            scratch
                .occluders
                .keep_projected::<R>(oi, &mut scratch.occ_plane);
            true
        }
    }
}

/// The faces of occluder `oi` (taken face by face) that can hide anything from the point, for
/// the environment: all but the point's own face and, for a closed mesh, those facing away
/// (the front faces alone cover a closed mesh's projection). Into `scratch.env_faces`.
pub(super) fn environment_faces(ctx: &PointContext, oi: usize, scratch: &mut ShadingScratch) {
    let sp = ctx.sp;
    let occ = &ctx.scene.objects[ctx.scene.occluders[oi] as usize];
    let faces = occ.face_pieces();
    let on_this = sp.object == Some(occ.object);
    let closed = faces.diagnostics.closed_manifold;
    scratch.env_faces.clear();
    for g in 0..faces.face_count() {
        if (on_this && skip_own_face(occ, g, sp))
            || (closed && faces.face_planes[g].eval(sp.position) <= 0.0)
        {
            continue;
        }
        scratch.env_faces.push(g as u32);
    }
}

/// Face `g` of occluder `oi` at the point, clipped to the horizon and projected, into
/// `scratch.occ_plane` (empty when nothing of it is above the horizon).
pub(super) fn project_face<R: Recorder>(
    ctx: &PointContext,
    oi: usize,
    g: usize,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) {
    let occ = &ctx.scene.objects[ctx.scene.occluders[oi] as usize];
    face_polygon(
        occ.face_pieces(),
        g,
        ctx.sp.position,
        &ctx.frame,
        Sidedness::TwoSided,
        None,
        &mut scratch.occ_sph,
        &mut scratch.face_buf,
    );
    if scratch.occ_sph.is_empty() {
        scratch.occ_plane.clear();
        return;
    }
    clip_and_project(oi, Some(g), scratch, rec);
}

/// Subtracts face `g` of occluder `oi` from the visible polygon.
pub(super) fn subtract_face<R: Recorder>(
    ctx: &PointContext,
    oi: usize,
    g: usize,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) {
    project_face(ctx, oi, g, scratch, rec);
    subtract_planar(ctx, None, oi, false, scratch, rec);
}

/// Clips face `g`'s polygon of occluder `oi` in `scratch.occ_sph`, projects it and subtracts it
/// from the visible polygon.
fn subtract_polygon<R: Recorder>(
    ctx: &PointContext,
    piece: Option<&LightPiece>,
    oi: usize,
    g: usize,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) {
    clip_and_project(oi, Some(g), scratch, rec);
    subtract_planar(ctx, piece, oi, false, scratch, rec);
}

/// Alg. 1 lines 10–11: `scratch.occ_sph` clipped to the horizon and projected into
/// `scratch.occ_plane`.
fn clip_and_project<R: Recorder>(
    oi: usize,
    piece: Option<usize>,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) {
    rec.occluder_polygon(oi, piece, Stage::Silhouette, &scratch.occ_sph);
    clip_to_horizon(
        &scratch.occ_sph,
        &mut scratch.occ_clip,
        &mut scratch.horizon,
    );
    rec.occluder_polygon(oi, piece, Stage::HorizonClipped, &scratch.occ_clip);
    ProjectionPlane::NORMAL.project(&scratch.occ_clip, &mut scratch.occ_plane);
}

/// Subtracts the projected occluder polygon in `scratch.occ_plane` from the visible polygon.
/// Returns false, with the visible polygon unchanged and the crossing counted, when the set
/// difference crossed the bound of one of its walks.
///
/// `holes`: the difference may be taken as a hole (`geometry::spherical::hole_difference`), when the
/// visible polygon is one convex loop and the occluder one loop: the visible region is then
/// `visible` less `visible_hole`, and stays so while the next occluders miss `visible` or hide
/// all of it, and until it is integrated. An occluder that overlaps it first turns it back into
/// a polygon ([`settle_hole`]). `ctx` and `piece` are what that needs.
fn subtract_planar<R: Recorder>(
    ctx: &PointContext,
    piece: Option<&LightPiece>,
    oi: usize,
    holes: bool,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) -> bool {
    if scratch.occ_plane.is_empty() {
        return true;
    }
    // Exact fast paths for convex clips; the difference for the rest. With a hole, `visible`
    // holds the region: missing it misses the region, and hiding it hides the region.
    let relation = if scratch.occ_plane.loop_count() == 1 {
        classify_overlap(&scratch.visible, scratch.occ_plane.loop_at(0))
    } else {
        Overlap::Unknown
    };
    let method = match relation {
        Overlap::Disjoint => {
            rec.set_difference(
                oi,
                DifferenceMethod::Classified,
                &scratch.visible,
                &scratch.occ_plane,
                &scratch.visible,
            );
            return true;
        }
        Overlap::SubjectInside => {
            scratch.visible_hole.clear();
            scratch.visible_next.clear();
            DifferenceMethod::Classified
        }
        Overlap::Unknown => {
            if holes && scratch.visible_hole.loop_count() == 1 && second_hole(oi, scratch) {
                // The visible region is `visible` less both holes plus their overlap.
                scratch.stats.set_differences += 1;
                if R::ENABLED {
                    let mut before = PlanarPolygon::new();
                    with_hole(&scratch.visible, &scratch.hole_first, &mut before);
                    record_hole(rec, oi, &before, scratch);
                }
                return true;
            }
            if !scratch.visible_hole.is_empty() {
                settle_hole(ctx, piece, scratch, rec);
                if scratch.visible.is_empty() {
                    rec.set_difference(
                        oi,
                        DifferenceMethod::Classified,
                        &scratch.visible,
                        &scratch.occ_plane,
                        &scratch.visible,
                    );
                    return true;
                }
            }
            scratch.stats.set_differences += 1;
            if holes
                && part_inside_convex(
                    &scratch.visible,
                    &scratch.occ_plane,
                    &mut scratch.visible_hole,
                    &mut scratch.hole,
                )
            {
                // The visible region is `visible` less the hole: `visible` stays.
                if !scratch.visible_hole.is_empty() {
                    scratch.hole_occluder.copy_from(&scratch.occ_plane);
                    scratch.hole_oi = oi;
                }
                if R::ENABLED {
                    let before = scratch.visible.clone();
                    record_hole(rec, oi, &before, scratch);
                }
                return true;
            }
            scratch.difference.subtract(
                &scratch.visible,
                &scratch.occ_plane,
                &mut scratch.visible_next,
                rec.gh_steps(),
            );
            if scratch.difference.last_bound_crossed() {
                scratch.stats.fallbacks.bounds_crossed += 1;
                return false;
            }
            DifferenceMethod::GreinerHormann
        }
    };
    rec.set_difference(
        oi,
        method,
        &scratch.visible,
        &scratch.occ_plane,
        &scratch.visible_next,
    );
    std::mem::swap(&mut scratch.visible, &mut scratch.visible_next);
    true
}

/// Records occluder `oi`'s difference taken as a hole: the region `before` it, the occluder,
/// and the region after it, `visible` with the holes reversed (filled non-zero), shown in
/// `visible_next`.
fn record_hole<R: Recorder>(
    rec: &mut R,
    oi: usize,
    before: &PlanarPolygon,
    scratch: &mut ShadingScratch,
) {
    with_hole(
        &scratch.visible,
        &scratch.visible_hole,
        &mut scratch.visible_next,
    );
    rec.set_difference(
        oi,
        DifferenceMethod::Hole,
        before,
        &scratch.occ_plane,
        &scratch.visible_next,
    );
}

/// The loop of `visible_hole` that holds the two holes' overlap, reversed ([`second_hole`]).
const OVERLAP_LOOP: usize = 2;

/// A second hole in a region that holds one (`visible` less the first hole, `hole_first`):
/// with `H₁ = A ∩ O₁` and `H₂ = A ∩ O₂`, `A ∖ (O₁ ∪ O₂)` is `A − H₁ − H₂ + H₁ ∩ H₂` in winding
/// number (inclusion–exclusion), and `H₁ ∩ H₂ = H₁ ∩ O₂` is one more convex clip, as `H₁` is
/// convex when `O₁` is. `visible_hole` then holds `H₁`, `H₂` and the overlap reversed, so
/// that the integral of its loops is `∫H₁ + ∫H₂ − ∫H₁∩H₂` and every integral of the region
/// stays `∫A − ∫holes`. Returns `false`, with nothing changed, where either clip declines (a
/// first hole that is not strictly convex, an occluder of more than one loop); an occluder
/// with nothing inside `A` adds nothing and is done.
fn second_hole(oi: usize, scratch: &mut ShadingScratch) -> bool {
    if !part_inside_convex(
        &scratch.visible,
        &scratch.occ_plane,
        &mut scratch.hole_second,
        &mut scratch.hole,
    ) {
        return false;
    }
    scratch.hole_first.clear();
    scratch
        .hole_first
        .push_loop(scratch.visible_hole.loop_at(0).iter().copied());
    if scratch.hole_second.is_empty() {
        return true;
    }
    if !part_inside_convex(
        &scratch.hole_first,
        &scratch.occ_plane,
        &mut scratch.hole_overlap,
        &mut scratch.hole,
    ) {
        return false;
    }
    scratch
        .visible_hole
        .push_loop(scratch.hole_second.loop_at(0).iter().copied());
    if !scratch.hole_overlap.is_empty() {
        scratch
            .visible_hole
            .push_loop(scratch.hole_overlap.loop_at(0).iter().rev().copied());
    }
    scratch.hole_occluder2.copy_from(&scratch.occ_plane);
    scratch.hole_oi2 = oi;
    true
}

/// Turns a visible region held as `visible` less `visible_hole` back into a polygon, for
/// another difference to be taken from it: Greiner–Hormann's differences of `visible` and the
/// occluders the holes came from (`hole_occluder`, then `hole_occluder2` where there are two
/// holes), which is what [`subtract_planar`] would have computed without the holes. Should one
/// cross a bound, that occluder is subtracted face by face instead (exact too), with the
/// current occluder's polygon and face list kept aside.
fn settle_hole<R: Recorder>(
    ctx: &PointContext,
    piece: Option<&LightPiece>,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) {
    let two = scratch.visible_hole.loop_count() > 1;
    scratch.visible_hole.clear();
    settle_one(ctx, piece, false, scratch, rec);
    if two && !scratch.visible.is_empty() {
        settle_one(ctx, piece, true, scratch, rec);
    }
}

/// One occluder of [`settle_hole`]: the first hole's, or the second's.
fn settle_one<R: Recorder>(
    ctx: &PointContext,
    piece: Option<&LightPiece>,
    second: bool,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) {
    let (oi, occluder) = if second {
        (scratch.hole_oi2, &scratch.hole_occluder2)
    } else {
        (scratch.hole_oi, &scratch.hole_occluder)
    };
    scratch.difference.subtract(
        &scratch.visible,
        occluder,
        &mut scratch.visible_next,
        rec.gh_steps(),
    );
    if !scratch.difference.last_bound_crossed() {
        rec.set_difference(
            oi,
            DifferenceMethod::HoleSettled,
            &scratch.visible,
            occluder,
            &scratch.visible_next,
        );
        std::mem::swap(&mut scratch.visible, &mut scratch.visible_next);
        return;
    }
    scratch.stats.fallbacks.bounds_crossed += 1;
    std::mem::swap(&mut scratch.occ_plane, &mut scratch.occ_plane_aside);
    std::mem::swap(&mut scratch.face_list, &mut scratch.face_list_aside);
    subtract_faces(ctx, oi, piece, None, None, false, scratch, rec);
    std::mem::swap(&mut scratch.occ_plane, &mut scratch.occ_plane_aside);
    std::mem::swap(&mut scratch.face_list, &mut scratch.face_list_aside);
}

/// The visible region held with a hole, as the polygon the LTC's correction samples, into
/// `scratch.sampled`: Greiner–Hormann's difference, as without the hole (the same samples), or
/// the region and the hole reversed should that cross a bound (the fan's signed triangles
/// sample that as well).
fn sampled_region(scratch: &mut ShadingScratch) {
    scratch.difference.subtract(
        &scratch.visible,
        &scratch.hole_occluder,
        &mut scratch.visible_next,
        None,
    );
    let mut crossed = scratch.difference.last_bound_crossed();
    let region = if scratch.visible_hole.loop_count() > 1 && !crossed {
        scratch.difference.subtract(
            &scratch.visible_next,
            &scratch.hole_occluder2,
            &mut scratch.sampled_plane,
            None,
        );
        crossed = scratch.difference.last_bound_crossed();
        &scratch.sampled_plane
    } else {
        &scratch.visible_next
    };
    if crossed {
        with_hole(
            &scratch.visible_sph,
            &scratch.hole_sph,
            &mut scratch.sampled,
        );
    } else {
        ProjectionPlane::NORMAL.reproject(region, &mut scratch.sampled);
    }
}

/// The LTC integral of `poly` for one lobe (000 Eq. 9 after M⁻¹): `poly` transformed into
/// `transformed`, clipped to the horizon again into `clipped`, and integrated.
fn lobe_form_factor(
    entry: &LtcEntry,
    poly: &SphericalPolygon,
    transformed: &mut SphericalPolygon,
    clipped: &mut SphericalPolygon,
    horizon: &mut HorizonScratch,
) -> f64 {
    transformed.copy_from(poly);
    transformed.map_vertices(|w| entry.transform(w));
    // A linear map with negative determinant mirrors the sphere and flips orientation.
    if entry.m_inv.determinant() < 0.0 {
        transformed.reverse_loops();
    }
    clip_to_horizon(transformed, clipped, horizon);
    form_factor(clipped.loops())
}

/// Lines 14–16 of Alg. 1: the diffuse lobe integrates the clamped cosine over the visible
/// polygon directly (the identity LTC, exact: `f_visible`, the visible polygon's form factor);
/// the specular lobe transforms it by M⁻¹, clips it to the horizon again and integrates.
/// Returns (diffuse, specular) radiance.
fn integrate_lobes<R: Recorder>(
    ctx: &PointContext,
    piece: &LightPiece,
    f_visible: f64,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) -> (DVec3, DVec3, DVec3) {
    let (lobes, radiance) = (&ctx.lobes, piece.radiance);
    // Rounding can leave a value a few ulps below zero for an empty visible region.
    let e_diffuse = f_visible.max(0.0);
    let hole = !scratch.hole_sph.is_empty();
    if R::ENABLED {
        let shown = if hole {
            &scratch.visible_shown
        } else {
            &scratch.visible_sph
        };
        rec.lobe(Lobe::Diffuse, shown, shown, e_diffuse);
    }
    let diffuse = lobes.kd * radiance * e_diffuse;
    let mut specular = DVec3::ZERO;
    let mut lobe_mass = 0.0;
    let mut f_lobe_value = 0.0;
    if let Some((entry, scale)) = &lobes.specular {
        let mut f_lobe = lobe_form_factor(
            entry,
            &scratch.visible_sph,
            &mut scratch.lobe_poly,
            &mut scratch.lobe_clip,
            &mut scratch.horizon,
        );
        // Each loop of the holes clipped to the horizon on its own, apart from the region
        // (`geometry::spherical::hole_difference`): loops that touch along a boundary where they cross
        // the horizon would leave the pairing of their crossings to rounding. The clip keeps
        // a positively oriented loop's inside, so the two holes' overlap, held reversed, is
        // turned back, clipped and added.
        for k in 0..scratch.hole_sph.loop_count() {
            let overlap = k == OVERLAP_LOOP;
            let lp = scratch.hole_sph.loop_at(k);
            scratch.hole_loop.clear();
            if overlap {
                scratch.hole_loop.push_loop(lp.iter().rev().copied());
            } else {
                scratch.hole_loop.push_loop(lp.iter().copied());
            }
            let sign = if overlap { -1.0 } else { 1.0 };
            f_lobe -= sign
                * lobe_form_factor(
                    entry,
                    &scratch.hole_loop,
                    &mut scratch.hole_lobe,
                    &mut scratch.hole_lobe_clip,
                    &mut scratch.horizon,
                );
            if R::ENABLED {
                for (whole, part) in [
                    (&mut scratch.lobe_poly, &scratch.hole_lobe),
                    (&mut scratch.lobe_clip, &scratch.hole_lobe_clip),
                ] {
                    for lp in part.loops() {
                        if overlap {
                            whole.push_loop(lp.iter().copied());
                        } else {
                            whole.push_loop(lp.iter().rev().copied());
                        }
                    }
                }
            }
        }
        // The fitted distribution: the LTC plus its cosine tail, whose integral over the
        // visible polygon is the diffuse form factor (LtcEntry::mix).
        let e_spec = entry.mix(f_lobe.max(0.0), e_diffuse);
        rec.lobe(
            Lobe::Specular,
            &scratch.lobe_poly,
            &scratch.lobe_clip,
            e_spec,
        );
        specular = *scale * radiance * e_spec;
        lobe_mass = e_spec;
        f_lobe_value = f_lobe.max(0.0);
    }
    let rate = ctx.rates.as_ref().map_or(DVec3::ZERO, |r| {
        lobe_rates(ctx, r, piece, e_diffuse, f_lobe_value, scratch, rec)
    });
    if let (Some(glossy), Some(sampling)) = (&lobes.glossy, &ctx.correction) {
        let mut rng = sampling.rng(piece.light, piece.face.map(|(f, _)| f));
        let region = if hole {
            sampled_region(scratch);
            &scratch.sampled
        } else {
            &scratch.visible_sph
        };
        let c = estimate_correction(
            region,
            glossy,
            lobe_mass,
            sampling.samples,
            &mut rng,
            &mut scratch.correction,
        );
        rec.correction(c.mean * radiance);
        scratch.correction_sum.mean += c.mean * radiance;
        scratch.correction_sum.variance += c.variance * radiance * radiance;
    }
    (diffuse, specular, rate)
}

/// The rate `d(diffuse + specular)/dθ` of one light piece's radiance, from the rates of the
/// visible region's form factors (`derivative::region_rates`) and, where the point's normal
/// turns, of the LTC entry: `e_spec = (1 − c) f_lobe + c e_diffuse` and the specular scale
/// `s (f0 (norm − fresnel) + fresnel)` change with it.
// Kept out of line: the image alone (no derivative) runs the lobes' code as it was.
#[inline(never)]
fn lobe_rates<R: Recorder>(
    ctx: &PointContext,
    rates: &PointRates,
    piece: &LightPiece,
    e_diffuse: f64,
    f_lobe: f64,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) -> DVec3 {
    let (scene, pm, x) = (ctx.scene, rates.point, ctx.sp.position);
    let light = scene.lights[piece.light].0;
    let kept = scratch.kept.iter().map(|&k| scene.occluders[k as usize]);
    let objects = std::iter::once(light)
        .chain(kept)
        .chain(piece.sky_window.map(|_| light));
    let light_face = piece.face.map(|(f, _)| (light, f));
    if !derivative::begin_piece(&mut scratch.derivative, scene, pm, x, objects, light_face)
        && rates.ltc.is_none()
    {
        return DVec3::ZERO;
    }
    let lobe = ctx
        .lobes
        .specular
        .as_ref()
        .map(|(entry, _)| LobeMap::new(entry, rates.ltc.as_ref()));
    let (d_diffuse, d_lobe) = derivative::region_rates(
        &mut scratch.derivative,
        pm,
        x,
        &ctx.frame,
        &scratch.visible_sph,
        &scratch.hole_sph,
        lobe.as_ref(),
        rec,
    );
    let radiance = piece.radiance;
    let mut rate = ctx.lobes.kd * radiance * d_diffuse;
    if let Some((entry, scale)) = &ctx.lobes.specular {
        let e_spec = entry.mix(f_lobe, e_diffuse);
        let mut d_spec = entry.mix(d_lobe, d_diffuse);
        let mut d_scale = DVec3::ZERO;
        if let Some(r) = &rates.ltc {
            d_spec += r.cosine * (e_diffuse - f_lobe);
            let ks = ctx
                .sp
                .object
                .map_or(DVec3::ZERO, |o| ctx.scene.materials[o as usize].ks);
            d_scale = ks.map(|f0| {
                r.scale * (f0 * (entry.norm - entry.fresnel) + entry.fresnel)
                    + entry.scale * (f0 * (r.norm - r.fresnel) + r.fresnel)
            });
        }
        rate += radiance * (*scale * d_spec + d_scale * e_spec);
    }
    rate
}
