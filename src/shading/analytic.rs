//! 000 Alg. 1: the radiance at a shading point, light by light.
//!
//! ```text
//! for each light l:                                   shade
//!     l' = SphPolySilhouette(l, x, n)                 silhouette / face_polygon
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
//! Convex and flat meshes take the silhouette path (read from a BSP tree where they have one);
//! closed non-convex meshes take their exact silhouette (001 Sect. 4.3, from a BSP tree where
//! they have one, 001 Sect. 5.2). Open meshes, points on a non-convex mesh itself, degenerate
//! points and every mesh under [`Method::PerTriangle`] go face by face, where an occluder face
//! is first cut to the part in front of the light face's plane, so that faces of one mesh
//! hiding each other are exact.

use super::get_between::get_between;
use super::recorder::{ExactSilhouetteRecord, Lobe, Recorder, Stage};
use super::{Method, PreparedObject, PreparedScene, ShadingPoint};
use crate::geometry::{
    ExactSilhouetteScratch, HorizonScratch, Overlap, PlanarPolygon, Plane, Polyhedron,
    ProjectionPlane, SetDifference, Sidedness, SilhouettePoint, SilhouetteScratch,
    SphericalPolygon, classify_overlap, clip_to_horizon, contour_edges, exact_silhouette,
    face_polygon, silhouette,
};
use crate::ltc::{LtcEntry, form_factor};
use crate::math::Frame;
use crate::scene::Material;
use glam::DVec3;

/// Counters of the work done at the last shading point (for AOVs and benchmarks).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct ShadingStats {
    /// Occluders kept by `GetBetween`, summed over lights.
    pub occluders_kept: u32,
    /// Edges of the light polygons after horizon clipping, summed over lights.
    pub light_edges: u32,
    /// Set differences performed.
    pub set_differences: u32,
}

/// Per-thread buffers of the pipeline, reused from one shading point to the next so that the
/// hot loop allocates nothing once they have grown.
#[derive(Default)]
pub struct ShadingScratch {
    silhouette: SilhouetteScratch,
    exact: ExactSilhouetteScratch,
    horizon: HorizonScratch,
    difference: SetDifference,
    light_sph: SphericalPolygon,
    light_clip: SphericalPolygon,
    occ_sph: SphericalPolygon,
    occ_clip: SphericalPolygon,
    occ_plane: PlanarPolygon,
    visible: PlanarPolygon,
    visible_next: PlanarPolygon,
    visible_sph: SphericalPolygon,
    lobe_poly: SphericalPolygon,
    lobe_clip: SphericalPolygon,
    kept: Vec<u32>,
    /// Per occluder: its projected, horizon-clipped silhouette at the shading point `stamp`.
    occluder_cache: Vec<CachedOccluder>,
    /// Counts shading points, to invalidate `occluder_cache` without clearing it.
    stamp: u64,
    face_buf: Vec<DVec3>,
    pub stats: ShadingStats,
}

#[derive(Default)]
struct CachedOccluder {
    stamp: u64,
    poly: PlanarPolygon,
}

/// Relative distance below which a face is taken to contain the shading point (its spherical
/// polygon is a sliver of zero area on the horizon).
const COPLANAR: f64 = 1e-9;

/// The BRDF lobes of a material at one shading point.
struct Lobes {
    kd: DVec3,
    specular: Option<(LtcEntry, DVec3)>,
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
    scratch.stats = ShadingStats::default();
    scratch.stamp += 1;
    if scratch.occluder_cache.len() < scene.occluders.len() {
        scratch
            .occluder_cache
            .resize_with(scene.occluders.len(), CachedOccluder::default);
    }
    let frame = Frame::from_normal_and_view(sp.normal, sp.view);
    let lobes = Lobes {
        kd: material.kd,
        specular: material.has_specular().then(|| {
            let entry = scene
                .ltc
                .lookup(sp.normal.dot(sp.view).clamp(0.0, 1.0), material.alpha);
            // Schlick's Fresnel per channel: F0 (norm − fresnel) + fresnel (see docs/ltc.md).
            let scale = material.ks.map(|f0| entry.specular_scale(f0));
            (entry, scale)
        }),
    };
    let mut total = DVec3::ZERO;
    for l in 0..scene.lights.len() {
        let (light_id, radiance) = scene.lights[l];
        let light = &scene.objects[light_id as usize];
        let on_light = sp.object == Some(light.object);
        let whole = LightPiece {
            light: l,
            face: None,
        };
        if light.simple && method != Method::PerTriangle {
            // A convex or flat light does not light points on itself.
            if on_light {
                continue;
            }
            rec.begin_light(l, None);
            record_contour(rec, None, &light.poly, sp.position, &frame);
            convex_silhouette(
                light,
                sp.position,
                &frame,
                Sidedness::FrontOnly,
                &mut scratch.light_sph,
                &mut scratch.silhouette,
            );
            total += shade_light_piece(
                scene, &whole, sp, &frame, &lobes, radiance, method, scratch, rec,
            );
        } else if let Some(from_tree) = uses_exact_silhouette(light, method, on_light)
            .then(|| {
                nonconvex_silhouette_from(
                    light,
                    sp.position,
                    &frame,
                    &mut scratch.light_sph,
                    &mut scratch.exact,
                )
            })
            .flatten()
        {
            // A closed non-convex light as a whole: its exact silhouette already accounts for
            // the faces it hides of itself (001 Fig. 4.1), so its own mesh is not subtracted.
            rec.begin_light(l, None);
            record_contour(rec, None, &light.poly, sp.position, &frame);
            record_exact(
                light,
                None,
                from_tree,
                sp.position,
                &frame,
                &scratch.exact,
                rec,
            );
            total += shade_light_piece(
                scene, &whole, sp, &frame, &lobes, radiance, method, scratch, rec,
            );
        } else {
            // A stand-in is for the silhouette path: face by face, the mesh's own faces.
            let faces = light.faces();
            for f in 0..faces.face_count() {
                if on_light && skip_own_face(light, f, sp) {
                    continue;
                }
                let plane = faces.face_planes[f];
                if plane.eval(sp.position) <= 0.0 {
                    continue; // lights emit from the front only
                }
                // What lies within rounding of the light face's plane is not in front of it.
                let tol = COPLANAR * faces.radius;
                let piece = LightPiece {
                    light: l,
                    face: Some((
                        f,
                        Plane {
                            n: plane.n,
                            d: plane.d + tol,
                        },
                    )),
                };
                rec.begin_light(l, Some(f));
                record_contour(rec, None, faces, sp.position, &frame);
                face_polygon(
                    faces,
                    f,
                    sp.position,
                    &frame,
                    Sidedness::FrontOnly,
                    None,
                    &mut scratch.light_sph,
                    &mut scratch.face_buf,
                );
                total += shade_light_piece(
                    scene, &piece, sp, &frame, &lobes, radiance, method, scratch, rec,
                );
            }
        }
    }
    total
}

/// `SphPolySilhouette` of a convex or flat mesh: read from its BSP tree of precomputed
/// silhouettes where it has one (001 Sect. 5.1), else chained from the contour edges.
#[inline]
fn convex_silhouette(
    obj: &PreparedObject,
    x: DVec3,
    frame: &Frame,
    sidedness: Sidedness,
    out: &mut SphericalPolygon,
    scratch: &mut SilhouetteScratch,
) {
    if !silhouette_from_tree(obj, x, frame, out, &mut scratch.hoisted) {
        silhouette(&obj.poly, x, frame, sidedness, out, scratch);
    }
}

/// The silhouette of `obj` from `x` read from its tree (the hoisted form when present), looked
/// up at the point in the tree's frame; `false` without a tree, outside its box, or in a leaf
/// left to the on-the-fly path.
#[inline]
fn silhouette_from_tree(
    obj: &PreparedObject,
    x: DVec3,
    frame: &Frame,
    out: &mut SphericalPolygon,
    hoisted_buf: &mut Vec<[u32; 2]>,
) -> bool {
    let tree_x = obj.tree_point(x);
    if let Some(h) = &obj.hoisted {
        return h.silhouette_at(&obj.poly, x, tree_x, frame, out, hoisted_buf);
    }
    match (&obj.bsp, &obj.exact_bsp) {
        (Some(t), _) => t.silhouette_at(&obj.poly, x, tree_x, frame, out),
        (None, Some(t)) => t.silhouette_at(&obj.poly, x, tree_x, frame, out),
        (None, None) => false,
    }
}

/// The exact silhouette of a closed non-convex mesh: read from its BSP tree where it has one
/// (001 Sect. 5.2), else computed on the fly (001 Sect. 4.3); `false` at degenerate points.
#[inline]
pub fn nonconvex_silhouette(
    obj: &PreparedObject,
    x: DVec3,
    frame: &Frame,
    out: &mut SphericalPolygon,
    scratch: &mut ExactSilhouetteScratch,
) -> bool {
    nonconvex_silhouette_from(obj, x, frame, out, scratch).is_some()
}

/// [`nonconvex_silhouette`], saying where it came from: `Some(true)` from the tree.
#[inline]
fn nonconvex_silhouette_from(
    obj: &PreparedObject,
    x: DVec3,
    frame: &Frame,
    out: &mut SphericalPolygon,
    scratch: &mut ExactSilhouetteScratch,
) -> Option<bool> {
    if silhouette_from_tree(obj, x, frame, out, &mut scratch.hoisted) {
        return Some(true);
    }
    exact_silhouette(&obj.poly, x, frame, out, scratch)
        .is_ok()
        .then_some(false)
}

/// [`nonconvex_silhouette`] that tells a recorder how the silhouette was found.
fn recorded_nonconvex_silhouette<R: Recorder>(
    obj: &PreparedObject,
    occluder: Option<usize>,
    x: DVec3,
    frame: &Frame,
    out: &mut SphericalPolygon,
    scratch: &mut ExactSilhouetteScratch,
    rec: &mut R,
) -> bool {
    let Some(from_tree) = nonconvex_silhouette_from(obj, x, frame, out, scratch) else {
        return false;
    };
    record_exact(obj, occluder, from_tree, x, frame, scratch, rec);
    true
}

/// Tells a recorder how the exact silhouette just computed was found (read from the scratch of
/// that same call, or from the tree's leaf); nothing at all for [`super::NoRecorder`].
fn record_exact<R: Recorder>(
    obj: &PreparedObject,
    occluder: Option<usize>,
    from_tree: bool,
    x: DVec3,
    frame: &Frame,
    scratch: &ExactSilhouetteScratch,
    rec: &mut R,
) {
    if !R::ENABLED {
        return;
    }
    let local = |d: DVec3| frame.to_local(d);
    let record = if from_tree {
        let crossings = obj
            .exact_bsp
            .as_ref()
            .and_then(|t| t.leaf_points(obj.tree_point(x)))
            .map(|pts| {
                pts.filter(|p| matches!(p, SilhouettePoint::Crossing(..)))
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

/// Whether a non-convex mesh is taken whole, through its exact silhouette: closed meshes under
/// the analytic method and its unshadowed U (a light hides itself in both), except at points
/// on the mesh itself (whose own face lies in the tangent plane there; the face-by-face path
/// skips it exactly).
#[inline]
fn uses_exact_silhouette(obj: &PreparedObject, method: Method, on_it: bool) -> bool {
    matches!(method, Method::Analytic | Method::Unshadowed)
        && !on_it
        && obj.poly.diagnostics.closed_manifold
}

/// Hands the contour edges of `poly` seen from `x` (the predicate the silhouette stage chains
/// by, `contour_edges`) to a recorder that keeps them; nothing at all for [`super::NoRecorder`].
fn record_contour<R: Recorder>(
    rec: &mut R,
    occluder: Option<usize>,
    poly: &Polyhedron,
    x: DVec3,
    frame: &Frame,
) {
    if !R::ENABLED {
        return;
    }
    let dir = |i: u32| {
        frame
            .to_local(poly.vertices[i as usize] - x)
            .normalize_or_zero()
    };
    let edges: Vec<[DVec3; 2]> = contour_edges(poly, x)
        .map(|[a, b]| [dir(a), dir(b)])
        .collect();
    rec.contour(occluder, &edges);
}

/// Is face `f` of `obj` the face the shading point lies on, or coplanar with it?
#[inline]
fn skip_own_face(obj: &PreparedObject, f: usize, sp: &ShadingPoint) -> bool {
    sp.face == Some(f as u32)
        || obj.faces().face_planes[f].eval(sp.position).abs() <= COPLANAR * obj.faces().radius
}

/// What one pass of lines 5–16 integrates: a whole light (its silhouette), or one face of it
/// with the face's plane offset by the coplanarity tolerance toward the shading point.
struct LightPiece {
    light: usize,
    face: Option<(usize, Plane)>,
}

/// Lines 5–16 of Alg. 1 for one light piece, whose spherical polygon is in `scratch.light_sph`.
#[allow(clippy::too_many_arguments)]
fn shade_light_piece<R: Recorder>(
    scene: &PreparedScene,
    piece: &LightPiece,
    sp: &ShadingPoint,
    frame: &Frame,
    lobes: &Lobes,
    radiance: DVec3,
    method: Method,
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
        rec.end_light(DVec3::ZERO, DVec3::ZERO);
        return DVec3::ZERO;
    }
    scratch.stats.light_edges += scratch.light_clip.vertex_count() as u32;
    let plane = ProjectionPlane::NORMAL;
    plane.project(&scratch.light_clip, &mut scratch.visible);

    // A light handled face by face hides parts of itself.
    let self_occluding = piece.face.is_some();
    match method {
        Method::Unshadowed => {
            // No occluders, but a non-convex light still hides its own faces.
            if self_occluding {
                let light_id = scene.lights[piece.light].0;
                if let Some(oi) = scene.occluders.iter().position(|&o| o == light_id) {
                    subtract_occluder(scene, oi, piece, sp, frame, method, scratch, rec);
                }
            }
        }
        Method::Analytic | Method::PerTriangle => {
            get_between(scene, piece.light, sp, self_occluding, &mut scratch.kept);
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
                subtract_occluder(scene, oi, piece, sp, frame, method, scratch, rec);
            }
        }
    }

    plane.reproject(&scratch.visible, &mut scratch.visible_sph);
    rec.light_polygon(Stage::Visible, &scratch.visible_sph);
    let (diffuse, specular) = integrate_lobes(lobes, radiance, scratch, rec);
    rec.end_light(diffuse, specular);
    diffuse + specular
}

/// Lines 9–12 of Alg. 1 for occluder `oi` (index into `scene.occluders`).
#[allow(clippy::too_many_arguments)]
fn subtract_occluder<R: Recorder>(
    scene: &PreparedScene,
    oi: usize,
    piece: &LightPiece,
    sp: &ShadingPoint,
    frame: &Frame,
    method: Method,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) {
    let occ_id = scene.occluders[oi];
    let occ = &scene.objects[occ_id as usize];
    let own_mesh = occ_id == scene.lights[piece.light].0;
    // Depth against a light face: an occluder separated from the whole light by a plane is in
    // front of it wherever they overlap (get_between checked the side of x); otherwise, and for
    // the light's own mesh, keep only what lies in front of the light face's plane.
    let mut cut = match piece.face {
        Some((_, plane)) if own_mesh || scene.separation(piece.light, oi).is_none() => Some(plane),
        _ => None,
    };
    if let Some(pp) = cut {
        let mut front = 0usize;
        let mut total = 0usize;
        for &i in &occ.faces().face_indices {
            total += 1;
            if pp.eval(occ.faces().vertices[i as usize]) > 0.0 {
                front += 1;
            }
        }
        if front == 0 {
            return; // entirely behind the light face
        }
        if front == total {
            cut = None; // entirely in front: no cut needed
        }
    }
    let cut = cut.as_ref();
    record_contour(rec, Some(oi), &occ.poly, sp.position, frame);
    let skip_face = if own_mesh {
        piece.face.map(|(f, _)| f)
    } else {
        None
    };
    let on_this = sp.object == Some(occ.object);
    let closed = occ.poly.diagnostics.closed_manifold;
    let exact = !occ.simple
        && cut.is_none()
        && skip_face.is_none()
        && uses_exact_silhouette(occ, method, on_this);
    if exact {
        // A closed non-convex occluder as a whole (its silhouette may have several loops and
        // holes); the per-shading-point cache as for convex ones. Degenerate points fall back
        // to the faces below.
        let cache_hit = !R::ENABLED && scratch.occluder_cache[oi].stamp == scratch.stamp;
        let ok = cache_hit
            || recorded_nonconvex_silhouette(
                occ,
                Some(oi),
                sp.position,
                frame,
                &mut scratch.occ_sph,
                &mut scratch.exact,
                rec,
            );
        if ok {
            if cache_hit {
                std::mem::swap(&mut scratch.occ_plane, &mut scratch.occluder_cache[oi].poly);
            } else {
                clip_and_project(oi, None, scratch, rec);
            }
            subtract_planar(oi, scratch, rec);
            if !R::ENABLED {
                std::mem::swap(&mut scratch.occ_plane, &mut scratch.occluder_cache[oi].poly);
                scratch.occluder_cache[oi].stamp = scratch.stamp;
            }
            return;
        }
    }
    if occ.simple && method != Method::PerTriangle && cut.is_none() {
        // An occluder's projected silhouette depends on the shading point and frame only, not
        // on the light: computed once per shading point and kept for the next lights. (With a
        // recorder every stage is recomputed so that it reaches the recording; same numbers.)
        let cache_hit = !R::ENABLED && scratch.occluder_cache[oi].stamp == scratch.stamp;
        if cache_hit {
            std::mem::swap(&mut scratch.occ_plane, &mut scratch.occluder_cache[oi].poly);
        } else {
            convex_silhouette(
                occ,
                sp.position,
                frame,
                Sidedness::TwoSided,
                &mut scratch.occ_sph,
                &mut scratch.silhouette,
            );
            clip_and_project(oi, None, scratch, rec);
        }
        subtract_planar(oi, scratch, rec);
        if !R::ENABLED {
            std::mem::swap(&mut scratch.occ_plane, &mut scratch.occluder_cache[oi].poly);
            scratch.occluder_cache[oi].stamp = scratch.stamp;
        }
    } else {
        let faces = occ.faces();
        for g in 0..faces.face_count() {
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
            if !scratch.occ_sph.is_empty() {
                subtract_polygon(oi, Some(g), scratch, rec);
            }
        }
    }
}

/// Clips the occluder polygon in `scratch.occ_sph`, projects it and subtracts it from the
/// visible polygon.
fn subtract_polygon<R: Recorder>(
    oi: usize,
    piece: Option<usize>,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) {
    clip_and_project(oi, piece, scratch, rec);
    subtract_planar(oi, scratch, rec);
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
fn subtract_planar<R: Recorder>(oi: usize, scratch: &mut ShadingScratch, rec: &mut R) {
    if scratch.occ_plane.is_empty() {
        return;
    }
    // Exact fast paths for convex clips; Greiner–Hormann for the rest.
    let relation = if scratch.occ_plane.loop_count() == 1 {
        classify_overlap(&scratch.visible, scratch.occ_plane.loop_at(0))
    } else {
        Overlap::Unknown
    };
    match relation {
        Overlap::Disjoint => {
            rec.set_difference(oi, &scratch.visible, &scratch.occ_plane, &scratch.visible);
            return;
        }
        Overlap::SubjectInside => scratch.visible_next.clear(),
        Overlap::Unknown => {
            scratch.difference.subtract(
                &scratch.visible,
                &scratch.occ_plane,
                &mut scratch.visible_next,
                rec.gh_steps(),
            );
            scratch.stats.set_differences += 1;
        }
    }
    rec.set_difference(
        oi,
        &scratch.visible,
        &scratch.occ_plane,
        &scratch.visible_next,
    );
    std::mem::swap(&mut scratch.visible, &mut scratch.visible_next);
}

/// Lines 14–16 of Alg. 1: the diffuse lobe integrates the clamped cosine over the visible
/// polygon directly (the identity LTC, exact); the specular lobe transforms it by M⁻¹, clips it
/// to the horizon again and integrates. Returns (diffuse, specular) radiance.
fn integrate_lobes<R: Recorder>(
    lobes: &Lobes,
    radiance: DVec3,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) -> (DVec3, DVec3) {
    // Rounding can leave a value a few ulps below zero for an empty visible region.
    let e_diffuse = form_factor(scratch.visible_sph.loops()).max(0.0);
    rec.lobe(
        Lobe::Diffuse,
        &scratch.visible_sph,
        &scratch.visible_sph,
        e_diffuse,
    );
    let diffuse = lobes.kd * radiance * e_diffuse;
    let mut specular = DVec3::ZERO;
    if let Some((entry, scale)) = &lobes.specular {
        scratch.lobe_poly.copy_from(&scratch.visible_sph);
        scratch.lobe_poly.map_vertices(|w| entry.transform(w));
        // A linear map with negative determinant mirrors the sphere and flips orientation.
        if entry.m_inv.determinant() < 0.0 {
            scratch.lobe_poly.reverse_loops();
        }
        clip_to_horizon(
            &scratch.lobe_poly,
            &mut scratch.lobe_clip,
            &mut scratch.horizon,
        );
        let e_spec = form_factor(scratch.lobe_clip.loops()).max(0.0);
        rec.lobe(
            Lobe::Specular,
            &scratch.lobe_poly,
            &scratch.lobe_clip,
            e_spec,
        );
        specular = *scale * radiance * e_spec;
    }
    (diffuse, specular)
}
