//! A point on a large closed light, lit by the rest of that light: its sky cut into windows.
//!
//! Seen from a point `x` on a closed mesh (outside it, on its surface), every ray above the
//! tangent plane that meets the mesh enters it through a face turned toward `x`, which emits.
//! So the light that reaches `x` from its own light is the light's radiance over `R ∩ H⁺`: the
//! image `R` of the mesh (less the faces through `x`, seen edge-on) above the horizon. Taking
//! the light's faces one by one, each less the faces in front of it, costs O(F²) per point.
//! Here `H⁺` is cut instead into
//! - [`SECTORS`] windows `W_k`, the spherical triangles from the zenith to two corners at a
//!   small elevation, strictly above the horizon. `R ∩ W_k` is `W_k` less `W_k ∖ R`, and
//!   `W_k ∖ R` is what subtracting the mesh from `W_k` as an occluder leaves: the exact
//!   silhouette inside the window (`geometry::silhouettes::windowed_silhouette`, with the faces through
//!   `x` left out), or, where that is undecided, its exact fallbacks. The point's other
//!   occluders are subtracted from `W_k` first (`shade_light_piece`).
//! - the thin band below the windows, `S_k` between the horizon and the window's lower side:
//!   there the light's faces that reach below the band's top go one by one as before, each
//!   clipped to the band (all four sides are great circles, so each `S_k` is convex).
//!
//! The windows and the bands tile `H⁺` (their shared sides have no area), so the sum is the
//! integral over `R ∩ H⁺`: the same region as face by face, by another exact construction
//! (test `tests/one_code_path.rs`: a point on the torus light, against the faces one by one).

use super::{COPLANAR, LightPiece, PointContext, ShadingScratch, shade_light_piece, skip_own_face};
use crate::geometry::spherical::spherical_polygon::clip_loop_to_half_spaces;
use crate::geometry::{IndexedPolyhedron, Sidedness, face_polygon};
use crate::shading::face_sides::light_face_cut;
use crate::shading::{Method, PathKind, Recorder};
use glam::DVec3;
use std::f64::consts::TAU;

/// Windows around the zenith. With their lower corners at [`CORNER_SIN`], every corner lies
/// within 60° of the window's centre (the windowed silhouette's limit; the zenith is the
/// farthest, at 58.2°), and the band below them stays under 0.071° of elevation.
const SECTORS: usize = 5;

/// Sine of the elevation of the windows' lower corners: far above the windowed silhouette's
/// margin from the horizon (1e-7), low enough that few faces reach into the band.
const CORNER_SIN: f64 = 0.001;

/// Sine of an elevation within rounding of the horizon: a face whose corners all lie below it
/// has no area above the horizon.
const HORIZON_SIN: f64 = 1e-9;

/// The occluder index of light `l`'s own mesh, when a point on it can take the windows: a
/// large closed light (its silhouette computed inside windows), the analytic method without a
/// sampled correction (whose per-piece streams assume the faces), the point on the light's
/// outer side.
pub(super) fn own_occluder(ctx: &PointContext, l: usize) -> Option<usize> {
    let scene = ctx.scene;
    let light_id = scene.lights[l].0;
    let light = &scene.objects[light_id as usize];
    if light.kind() != PathKind::ExactInWindow
        || ctx.method == Method::PerTriangle
        || ctx.correction.is_some()
    {
        return None;
    }
    // The point's side of the mesh: that of every face whose plane passes through it (the
    // faces `skip_own_face` leaves out), of which there is at least one.
    let faces = light.face_pieces();
    let tol = COPLANAR * faces.radius;
    let mut through = false;
    for (f, plane) in faces.face_planes.iter().enumerate() {
        if plane.eval(ctx.sp.position).abs() <= tol && contains(faces, f, ctx.sp.position, tol) {
            if plane.n.dot(ctx.sp.normal) <= 0.0 {
                return None;
            }
            through = true;
        }
    }
    through.then(|| scene.occluders.iter().position(|&o| o == light_id))?
}

/// The same at every point, in the point's own frame: computed once.
static SKY: std::sync::LazyLock<Sky> = std::sync::LazyLock::new(Sky::new);

/// The windows' corners and the bands' sides, in the point's frame (z the normal).
struct Sky {
    corners: [DVec3; SECTORS],
    /// Per band: its sides' inward normals (two meridians, the window's lower side reversed,
    /// the horizon).
    bands: [[DVec3; 4]; SECTORS],
    /// Sine of the band's highest elevation (the middle of a window's lower side), with a
    /// margin for rounding.
    band_top_sin: f64,
}

impl Sky {
    fn new() -> Self {
        let cos = (1.0 - CORNER_SIN * CORNER_SIN).sqrt();
        let corners: [DVec3; SECTORS] = std::array::from_fn(|k| {
            let (s, c) = (TAU * k as f64 / SECTORS as f64).sin_cos();
            DVec3::new(cos * c, cos * s, CORNER_SIN)
        });
        let bands = std::array::from_fn(|k| {
            let (a, b) = (corners[k], corners[(k + 1) % SECTORS]);
            [
                DVec3::Z.cross(a).normalize(),
                b.cross(DVec3::Z).normalize(),
                -a.cross(b).normalize(),
                DVec3::Z,
            ]
        });
        // The lower side's top: its middle, at elevation atan(tan e / cos(π / SECTORS)).
        let half = std::f64::consts::PI / SECTORS as f64;
        let top = (CORNER_SIN / cos / half.cos()).atan().sin();
        Sky {
            corners,
            bands,
            band_top_sin: top * (1.0 + 1e-6) + 1e-12,
        }
    }
}

/// What light `l` (whose own mesh is occluder `own`) sends to the point, which lies on it:
/// `None` when a face that reaches the band is not convex (the band's clip takes convex faces),
/// and the caller goes face by face.
pub(super) fn shade_own_light<R: Recorder>(
    ctx: &PointContext,
    l: usize,
    own: usize,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) -> Option<DVec3> {
    let (scene, sp, frame) = (ctx.scene, ctx.sp, &ctx.frame);
    let (light_id, radiance) = scene.lights[l];
    let light = &scene.objects[light_id as usize];
    let faces = light.face_pieces();
    let sky = &*SKY;
    // The faces turned toward the point that reach below the band's top (the lowest point of
    // a face's image above the horizon is at a corner, or on the horizon where it crosses).
    scratch.sky_faces.clear();
    scratch.sky_face.clear();
    for f in 0..faces.face_count() {
        if skip_own_face(light, f, sp) || faces.face_planes[f].eval(sp.position) <= 0.0 {
            continue;
        }
        // Above the horizon somewhere (a face that only touches it has no area there) and
        // below the band's top somewhere.
        let (mut low, mut above) = (false, false);
        for &i in faces.face(f) {
            let d = frame.to_local(faces.vertices[i as usize] - sp.position);
            let len = d.length();
            low |= d.z <= sky.band_top_sin * len;
            above |= d.z > HORIZON_SIN * len;
        }
        if !(low && above) {
            continue;
        }
        face_polygon(
            faces,
            f,
            sp.position,
            frame,
            Sidedness::FrontOnly,
            None,
            &mut scratch.light_sph,
            &mut scratch.face_buf,
        );
        if scratch.light_sph.is_empty() {
            continue;
        }
        if !convex_face(faces, f) {
            return None;
        }
        // Kept for the bands below (the light polygon is needed for the windows first).
        let start = scratch.sky_face.len() as u32;
        scratch
            .sky_face
            .extend_from_slice(scratch.light_sph.loop_at(0));
        scratch
            .sky_faces
            .push((f as u32, start, scratch.sky_face.len() as u32));
    }
    let mut total = DVec3::ZERO;
    for k in 0..SECTORS {
        let corners = [DVec3::Z, sky.corners[k], sky.corners[(k + 1) % SECTORS]];
        scratch.light_sph.clear();
        scratch.light_sph.push_loop(corners.iter().copied());
        rec.begin_light(l, None);
        let window = LightPiece {
            light: l,
            radiance,
            face: None,
            sky_window: Some(own),
        };
        total += shade_light_piece(ctx, &window, scratch, rec);
    }
    for i in 0..scratch.sky_faces.len() {
        let (f, start, end) = scratch.sky_faces[i];
        let f = f as usize;
        for band in &sky.bands {
            clip_loop_to_half_spaces(
                &scratch.sky_face[start as usize..end as usize],
                band,
                &mut scratch.split_face,
                &mut scratch.split_tmp,
            );
            if scratch.split_face.is_empty() {
                continue;
            }
            scratch.light_sph.clear();
            scratch
                .light_sph
                .push_loop(scratch.split_face.iter().copied());
            rec.begin_light(l, Some(f));
            let piece = LightPiece {
                light: l,
                radiance,
                face: Some((f, light_face_cut(faces, f))),
                sky_window: None,
            };
            total += shade_light_piece(ctx, &piece, scratch, rec);
        }
    }
    Some(total)
}

/// Whether face `f` turns one way at every corner in its plane: its image from any point in
/// front of it is then a convex spherical polygon (seen nearly edge-on, rounding may make the
/// image's corners look otherwise, so the face itself is asked).
fn convex_face(faces: &IndexedPolyhedron, f: usize) -> bool {
    let idx = faces.face(f);
    let n = idx.len();
    if n <= 3 {
        return true;
    }
    let normal = faces.face_planes[f].n;
    let p = |k: usize| faces.vertices[idx[k % n] as usize];
    (0..n).all(|k| {
        let (a, b, c) = (p(k), p(k + 1), p(k + 2));
        (b - a).cross(c - b).dot(normal) >= 0.0
    })
}

/// Whether `x`, within `tol` of face `f`'s plane, lies on the face (inside every edge's side,
/// within `tol`): the faces through the point, not faces elsewhere in the same plane.
fn contains(faces: &IndexedPolyhedron, f: usize, x: DVec3, tol: f64) -> bool {
    let idx = faces.face(f);
    let n = faces.face_planes[f].n;
    let p = |k: usize| faces.vertices[idx[k % idx.len()] as usize];
    (0..idx.len()).all(|k| {
        let (a, b) = (p(k), p(k + 1));
        let edge = b - a;
        edge.cross(x - a).dot(n) >= -tol * edge.length()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ltc::form_factor;

    /// The windows and the bands tile the upper hemisphere: their cosine-weighted solid angles
    /// (the form factor, exactly 1 for the whole hemisphere) add up to 1, each is positive
    /// (positively oriented loops), and every window fits the windowed silhouette's limit.
    #[test]
    fn windows_and_bands_tile_the_hemisphere() {
        let sky = Sky::new();
        let mut total = 0.0;
        for k in 0..SECTORS {
            let (a, b) = (sky.corners[k], sky.corners[(k + 1) % SECTORS]);
            let w = [DVec3::Z, a, b];
            let centre = (w[0] + w[1] + w[2]).normalize();
            assert!(w.iter().all(|c| c.dot(centre) > 0.5 + 1e-3));
            let window = form_factor([&w[..]]);
            assert!(window > 0.0);
            // The band: from the horizon below the window's lower corners up to them.
            let foot = |c: DVec3| DVec3::new(c.x, c.y, 0.0).normalize();
            let band_loop = [foot(a), foot(b), b, a];
            for c in band_loop {
                assert!(sky.bands[k].iter().all(|n| c.dot(*n) >= -1e-15));
            }
            let band = form_factor([&band_loop[..]]);
            assert!(
                band > 0.0 && band < 1e-2 * window,
                "band {band}, window {window}"
            );
            assert!(sky.band_top_sin > a.z && sky.band_top_sin < 2.0 * a.z);
            total += window + band;
        }
        assert!((total - 1.0).abs() < 1e-12, "{total}");
    }
}
