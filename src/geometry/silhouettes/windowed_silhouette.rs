//! The exact silhouette of a large closed or open mesh *inside a window*: only the part of the region
//! the mesh covers that lies in a small convex spherical polygon (the light, seen from the
//! shading point), which is all a set difference with that light needs.
//!
//! [`exact_silhouette`](crate::geometry::silhouettes::exact_silhouette) looks at every contour edge, every pair that
//! may cross and every piece, wherever they are on the sphere. Under a light that subtends a
//! small solid angle, almost all of that work is for parts of the outline no light is behind.
//! Here the work is restricted to the window `W` (the light's polygon, in the world orientation
//! of directions from `x`) widened a little to `W'`:
//!
//! 1. the contour edges from `x` (001 Eq. 4.2), and the boundary edges of an open mesh, that may
//!    meet a cone around `W'` and the pyramid of `W'` itself: through the normal-cone
//!    hierarchy with a ball per node (`EdgeHierarchy::candidates_in_window`) where the mesh
//!    has one (over the part of it that the point's tile can need, `tile_candidates`, when
//!    the caller names the tile), else the edges of the faces whose boxes meet both (the face hierarchy,
//!    `FaceBvh::for_each_in_window`; an edge whose arc meets `W'` has its faces meeting both);
//! 2. each contour arc clipped to `W'` (convex: one interval of the chord a + t(b − a));
//! 3. apparent intersections (001 Eq. 4.4) among the clipped arcs only;
//! 4. the pieces between them, kept when their midpoint ray meets no other face (the same
//!    exact test, through the same hierarchy, as the full method);
//! 5. the kept pieces chained; a chain that enters and leaves `W'` is closed along the boundary
//!    of `W'` (Weiler–Atherton: from each exit, along `∂W'` in the window's orientation, to the
//!    next entry). With no chain crossing `∂W'`, one ray at a corner of `W'` says whether `W'`
//!    lies inside the covered region, and then `W'` itself is a loop.
//!
//! The loops describe a region `R'` with `R' ∩ W' = R ∩ W'` for the covered region `R`, so
//! `W ∖ R' = W ∖ R`: subtracting them from the light gives what subtracting the whole
//! silhouette gives. `W'` is `W` scaled about its centre by `1 + WIDEN` in the gnomonic plane,
//! so the closing arcs lie strictly outside `W` and never run along the light's own edges.
//!
//! Anything that the construction cannot decide exactly — a contour vertex or crossing on
//! `∂W'`, an arc touching it, a corner of `W'` on a contour arc, a window too wide for its
//! gnomonic plane, chains that do not alternate along `∂W'` — returns `None`, and the caller
//! takes the full exact silhouette.

use crate::geometry::SphericalPolygon;
use crate::geometry::mesh::mesh_index::IndexedPolyhedron;
use crate::geometry::mesh::polyhedron::NO_FACE;
use crate::geometry::silhouettes::contour_pieces::{ArcPosition, ContourArc, ContourPieces, End};
use crate::geometry::silhouettes::exact_silhouette::{Degenerate, blocked_ray};
use crate::geometry::silhouettes::quantitative_invisibility::QiScratch;
use crate::geometry::silhouettes::tile_candidates::{TileCandidates, TileQuery};
use crate::geometry::spherical::spherical_polygon::clip_loop_to_half_spaces;
use crate::math::Frame;
use glam::DVec3;

/// How much wider than the light `W'` is (relative, in the window's gnomonic plane).
const WIDEN: f64 = 1e-3;

/// Windows wider than this (the largest angle from the centre to a corner, as a cosine) are
/// left to the full silhouette.
const MIN_COS_HALF_ANGLE: f64 = 0.5;

/// Window corners at most.
pub(crate) const MAX_WINDOW_CORNERS: usize = 64;

/// Relative tolerance of the boundary tests (far above rounding of unit vectors).
const TOL: f64 = 1e-10;

/// Reusable buffers of [`exact_silhouette_in_window`].
#[derive(Clone, Debug, Default)]
pub struct WindowScratch {
    window: Vec<DVec3>,
    sides: Vec<DVec3>,
    edge_stamp: Vec<u32>,
    stamp: u32,
    candidates: Vec<u32>,
    /// The clipped arcs and the stages shared with the whole silhouette.
    pieces: ContourPieces,
    /// Open chains: the range of `chain_pieces` each one takes.
    chains: Vec<(u32, u32)>,
    /// The pieces of the open chains, in walking order.
    chain_pieces: Vec<u32>,
    /// Per open chain: the index of its exit in `order`, and whether a loop has taken it.
    exit_at: Vec<(u32, bool)>,
    order: Vec<(f64, u32, bool)>,
    loop_buf: Vec<DVec3>,
    /// Test every pair of arcs and cast one ray per piece (the reference the sweep and the
    /// propagation are tested against).
    pub all_pairs: bool,
    /// One ray per piece instead of quantitative invisibility (implied by `all_pairs`).
    pub per_piece_rays: bool,
    /// The propagation of quantitative invisibility (step 5).
    pub qi: QiScratch,
    /// What the next call may share with the other points of its tile (set by the caller
    /// before each call; `None`: the whole hierarchy).
    pub tile: Option<TileQuery>,
    /// The hierarchy's subtrees for the current tiles.
    pub tile_candidates: TileCandidates,
}

/// What the windowed silhouette did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WindowStats {
    pub candidate_edges: u32,
    pub contour_arcs: u32,
    pub pieces: u32,
    pub kept: u32,
    /// Rays cast: for the pieces, and at a corner of `W'` when no chain crosses it.
    pub rays: u32,
}

/// Writes into `out` (in `frame`) loops whose covered region agrees with the exact silhouette
/// of the closed mesh `poly` seen from `x` inside the convex window `window` (unit directions
/// in `frame`, one positively oriented loop, as a light polygon is). `None` when the mesh has
/// no face hierarchy, the window is too wide or a configuration is on the edge of what it
/// decides (see the module docs): take the full silhouette then.
///
/// `on_mesh`: `x` lies on the mesh itself (self-shadowing). Its own face, and every face whose
/// plane passes within the coplanarity tolerance of `x`, is then seen edge-on: its image has
/// no area, so it is left out, and the faces next to it end at its edges (edges between it and
/// a face that is not left out count as boundary edges of that face). The own face's edges lie
/// on the horizon, so this is done only with `W'` strictly above the horizon, where no arc on
/// the horizon can reach.
pub fn exact_silhouette_in_window(
    poly: &IndexedPolyhedron,
    x: DVec3,
    frame: &Frame,
    window: &[DVec3],
    on_mesh: bool,
    out: &mut SphericalPolygon,
    scratch: &mut WindowScratch,
) -> Result<WindowStats, Degenerate> {
    out.clear();
    let bvh = poly.index.face_bvh.as_ref().ok_or(Degenerate::Window)?;
    let face_edges = poly.index.face_edges.as_ref().ok_or(Degenerate::Window)?;
    let m = window.len();
    if !(3..=MAX_WINDOW_CORNERS).contains(&m) {
        return Err(Degenerate::Window);
    }
    let tol = 1e-9 * poly.radius.max(f64::MIN_POSITIVE);
    // 0. The widened window W' in world directions, and its sides' inward normals.
    let centre = widened_window(window, frame, &mut scratch.window).ok_or(Degenerate::Window)?;
    let orient = scratch.window[0]
        .cross(scratch.window[1])
        .dot(scratch.window[2])
        .signum();
    scratch.sides.clear();
    for i in 0..m {
        let (a, b) = (scratch.window[i], scratch.window[(i + 1) % m]);
        let n = (a.cross(b) * orient)
            .try_normalize()
            .ok_or(Degenerate::Window)?;
        scratch.sides.push(n);
    }
    // Convex and positively turning: every corner strictly inside the other sides.
    for i in 0..m {
        for (j, n) in scratch.sides.iter().enumerate() {
            if j != i && (j + 1) % m != i && n.dot(scratch.window[i]) <= TOL {
                return Err(Degenerate::Window);
            }
        }
    }
    let (cos_cone, sin_cone) = cone_of(&scratch.window, centre);
    // On the mesh: W' strictly above the horizon (above the tangent plane by far more than the
    // rounding of the directions), so that the edge-on faces' edges cannot reach it.
    if on_mesh && scratch.window.iter().any(|w| w.dot(frame.z) <= 1e3 * TOL) {
        return Err(Degenerate::Window);
    }
    // A face's plane at x (front facing: positive), and whether the face is left out: none,
    // or seen edge-on from a point on the mesh.
    let side = |f: u32| match f {
        NO_FACE => f64::NAN,
        f => poly.face_planes[f as usize].eval(x),
    };
    let left_out = |f: u32, s: f64| f == NO_FACE || on_mesh && s.abs() <= tol;
    let absent = |f: u32| left_out(f, side(f));

    // 1. Candidate edges: through the mesh's edge hierarchy, the contour and boundary edges
    //    that may meet the cone and the pyramid of W' (all skip tests at once); without one,
    //    the edges of the faces whose boxes meet both.
    scratch.candidates.clear();
    scratch.tile_candidates.last = None;
    let hierarchy = poly.index.edge_hierarchy.as_deref();
    let shared = match (hierarchy, &scratch.tile) {
        (Some(h), Some(q)) => scratch.tile_candidates.fill(
            h,
            poly,
            q,
            x,
            &scratch.sides,
            on_mesh.then_some(tol),
            &mut scratch.candidates,
        ),
        _ => false,
    };
    let per_point = hierarchy.filter(|_| poly.index.edge_hierarchy_per_point);
    if shared {
        // The region's list, filtered for this point: nothing more to find.
    } else if let Some(h) = per_point {
        // The point's own query, where the hierarchy pays for single points.
        h.candidates_in_window(
            x,
            centre,
            cos_cone,
            sin_cone,
            &scratch.sides,
            &mut scratch.candidates,
        );
    } else {
        // Else through the faces' hierarchy.
        // One stamp per call: marks left by other meshes are older, so the buffer is shared
        // by every mesh this thread meets and only ever grows.
        if scratch.edge_stamp.len() < poly.edges.len() {
            scratch.edge_stamp.resize(poly.edges.len(), 0);
        }
        scratch.stamp = scratch.stamp.wrapping_add(1);
        if scratch.stamp == 0 {
            scratch.edge_stamp.iter_mut().for_each(|s| *s = 0);
            scratch.stamp = 1;
        }
        let stamp = scratch.stamp;
        let (edge_stamp, candidates) = (&mut scratch.edge_stamp, &mut scratch.candidates);
        bvh.for_each_in_window(x, centre, cos_cone, sin_cone, &scratch.sides, |f| {
            for &e in face_edges.edges_of(f as usize) {
                if edge_stamp[e as usize] != stamp {
                    edge_stamp[e as usize] = stamp;
                    candidates.push(e);
                }
            }
        });
    }
    let mut stats = WindowStats {
        candidate_edges: scratch.candidates.len() as u32,
        ..WindowStats::default()
    };

    // 2. Contour arcs among them, oriented with the mesh on the side `orient` of a × b (the
    //    window's own orientation, both being positively oriented loops), clipped to W'.
    let pieces = &mut scratch.pieces;
    pieces.clear();
    for &e in &scratch.candidates {
        let edge = &poly.edges[e as usize];
        let [g0, g1] = edge.faces;
        // Each face's plane at x, evaluated once.
        let (s0, s1) = (side(g0), side(g1));
        let (out0, out1) = (left_out(g0, s0), left_out(g1, s1));
        // The mesh to the left: a contour edge between a front and a back face; a boundary edge
        // (of an open mesh, or next to a face left out) whichever way its one face turns.
        let [i, j] = match (out0, out1) {
            (true, true) => continue,
            (false, false) => match (s0 > 0.0, s1 > 0.0) {
                (true, false) => [edge.v[1], edge.v[0]],
                (false, true) => [edge.v[0], edge.v[1]],
                _ => continue,
            },
            (false, true) if s0 > 0.0 => [edge.v[1], edge.v[0]],
            (false, true) => [edge.v[0], edge.v[1]],
            // Its face runs along it the other way.
            (true, false) if s1 > 0.0 => [edge.v[0], edge.v[1]],
            (true, false) => [edge.v[1], edge.v[0]],
        };
        if (!out0 && s0.abs() <= tol) || (!out1 && s1.abs() <= tol) {
            return Err(Degenerate::Window); // a face plane through x
        }
        let (va, vb) = (poly.vertices[i as usize] - x, poly.vertices[j as usize] - x);
        if wholly_outside(&scratch.sides, va, vb) {
            continue;
        }
        let a = va.normalize();
        let b = vb.normalize();
        let Some(n) = a.cross(b).try_normalize() else {
            continue; // seen end-on
        };
        // Clip the chord a + t (b − a) to every side: linear constraints in t.
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        let (mut s0, mut s1) = (None, None);
        for (s, side) in scratch.sides.iter().enumerate() {
            let (fa, fb) = (side.dot(a), side.dot(b));
            if fa.abs() <= TOL || fb.abs() <= TOL {
                return Err(Degenerate::Window); // an end on the side's great circle
            }
            match (fa > 0.0, fb > 0.0) {
                (true, true) => {}
                (false, false) => {
                    t0 = 1.0;
                    t1 = 0.0;
                }
                (true, false) => {
                    let t = fa / (fa - fb);
                    if t < t1 {
                        t1 = t;
                        s1 = Some(s as u32);
                    }
                }
                (false, true) => {
                    let t = fa / (fa - fb);
                    if t > t0 {
                        t0 = t;
                        s0 = Some(s as u32);
                    }
                }
            }
        }
        if t1 - t0 <= TOL {
            if t1 - t0 > -TOL {
                return Err(Degenerate::Window); // touches W' at a corner
            }
            continue;
        }
        stats.contour_arcs += 1;
        pieces.arcs.push(ContourArc {
            faces: edge.faces,
            v: [i, j],
            n,
            from: (a + t0 * (b - a)).normalize(),
            to: (a + t1 * (b - a)).normalize(),
            from_side: s0,
            to_side: s1,
        });
    }

    // 3.-4. Apparent intersections among the clipped arcs (Eq. 4.4), strictly inside both,
    //    and the pieces between them (`contour_pieces`, as the whole silhouette); boundary ends
    //    get ids of their own.
    pieces.find_crossings(scratch.all_pairs, |e, p| inside_arc(e.from, e.to, e.n, p))?;
    pieces.split_into_pieces();
    stats.pieces = pieces.pieces.len() as u32;
    // Positions along ∂W': side index plus the angle from the side's first corner over the
    // side's angle (monotone along the side).
    for b in &mut pieces.boundary {
        let s = b.0 as usize;
        let (c0, c1) = (scratch.window[s], scratch.window[(s + 1) % m]);
        let whole = c0.cross(c1).length().atan2(c0.dot(c1));
        let part = c0.cross(b.2).length().atan2(c0.dot(b.2));
        let f = part / whole;
        if !(TOL..=1.0 - TOL).contains(&f) {
            return Err(Degenerate::Window); // at a corner of W'
        }
        b.1 = s as f64 + f;
    }

    // 5. Keep the pieces whose midpoint ray meets no face but the arc's own two: one ray per
    //    piece, or quantitative invisibility (one ray per connected set of pieces in W').
    //    Faces left out cannot block a ray (they are met edge-on at most).
    let edge_on = on_mesh.then_some(tol);
    stats.rays = pieces.keep_visible(
        poly,
        x,
        scratch.all_pairs || scratch.per_piece_rays,
        false,
        edge_on,
        absent,
        &mut scratch.qi,
    );
    stats.kept = pieces.kept.len() as u32;

    // 6. Chains. Open chains first, from every piece that starts on ∂W'; the next piece
    //    starts where the current one ends. Then the closed loops inside W'.
    //    Each step marks one unused piece as used, so all the walks together take at most
    //    `kept.len()` steps, and every piece is in one chain or loop at most.
    pieces.index_starts();
    scratch.chains.clear();
    scratch.chain_pieces.clear();
    scratch.loop_buf.clear();
    for s in 0..pieces.kept.len() {
        let first = pieces.kept[s] as usize;
        if pieces.pieces[first].used || !matches!(pieces.pieces[first].start, End::Boundary(_)) {
            continue;
        }
        let start = scratch.chain_pieces.len() as u32;
        let mut cur = first;
        loop {
            pieces.pieces[cur].used = true;
            scratch.chain_pieces.push(cur as u32);
            match pieces.pieces[cur].end {
                End::Boundary(_) => break,
                end => cur = pieces.next_piece(end).ok_or(Degenerate::OpenChain)?,
            }
        }
        scratch
            .chains
            .push((start, scratch.chain_pieces.len() as u32));
    }
    if pieces.chain_closed_loops(frame, out).is_err() {
        out.clear();
        return Err(Degenerate::Window);
    }
    // Open chains closed along ∂W', or W' itself.
    if scratch.chains.is_empty() {
        // Is ∂W' inside the covered region? One ray at a corner, away from every arc.
        let corner = scratch.window[0];
        for e in &pieces.arcs {
            if e.n.dot(corner).abs() <= 1e3 * TOL
                && inside_arc(e.from, e.to, e.n, corner) != ArcPosition::Outside
            {
                out.clear();
                return Err(Degenerate::Window);
            }
        }
        stats.rays += 1;
        if blocked_ray(poly, x, corner, [NO_FACE; 2], false, edge_on) {
            for &w in &scratch.window {
                out.push_vertex(frame.to_local(w));
            }
            out.close_loop();
        }
        return Ok(stats);
    }
    // Boundary events in order along ∂W': (position, chain, is the chain's exit).
    scratch.order.clear();
    for (c, &(first, last)) in scratch.chains.iter().enumerate() {
        let pos = |e: End, boundary: &[(u32, f64, DVec3)]| match e {
            End::Boundary(id) => Some(boundary[id as usize].1),
            _ => None,
        };
        let first = scratch.chain_pieces[first as usize] as usize;
        let last = scratch.chain_pieces[last as usize - 1] as usize;
        let entry = pos(pieces.pieces[first].start, &pieces.boundary).ok_or(Degenerate::Window)?;
        let exit = pos(pieces.pieces[last].end, &pieces.boundary).ok_or(Degenerate::Window)?;
        scratch.order.push((entry, c as u32, false));
        scratch.order.push((exit, c as u32, true));
    }
    scratch.order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    for w in scratch.order.windows(2) {
        if w[1].0 - w[0].0 <= TOL {
            out.clear();
            return Err(Degenerate::Window); // two boundary points within rounding of each other
        }
    }
    let n_events = scratch.order.len();
    // Each exit must be followed (cyclically) by an entry.
    for k in 0..n_events {
        if scratch.order[k].2 && scratch.order[(k + 1) % n_events].2 {
            out.clear();
            return Err(Degenerate::Window);
        }
        if !scratch.order[k].2 && !scratch.order[(k + 1) % n_events].2 {
            out.clear();
            return Err(Degenerate::Window);
        }
    }
    // Per chain: where its exit stands in `order`, and whether it is in a loop yet.
    scratch.exit_at.clear();
    scratch.exit_at.resize(scratch.chains.len(), (0, false));
    for (k, &(_, c, exit)) in scratch.order.iter().enumerate() {
        if exit {
            scratch.exit_at[c as usize].0 = k as u32;
        }
    }
    // Bound: the loop below takes one chain not done yet per step, and between two chains at
    // most `m` corners: the outline has at most `kept.len() + chains.len() · (m + 1)` vertices.
    for c0 in 0..scratch.chains.len() {
        if scratch.exit_at[c0].1 {
            continue;
        }
        let mut c = c0;
        loop {
            scratch.exit_at[c].1 = true;
            // The chain's pieces.
            let (first, last) = scratch.chains[c];
            // Replays the chain the first walk recorded: a second walk that chose among the
            // pieces starting at a shared point could take another one there and never return.
            for &q in &scratch.chain_pieces[first as usize..last as usize] {
                out.push_vertex(frame.to_local(pieces.pieces[q as usize].from));
            }
            let cur = scratch.chain_pieces[last as usize - 1] as usize;
            out.push_vertex(frame.to_local(pieces.pieces[cur].to));
            // Along ∂W' from this exit to the next entry, through the corners passed.
            let k = scratch.exit_at[c].0 as usize;
            let (exit_pos, _, _) = scratch.order[k];
            let (entry_pos, next, _) = scratch.order[(k + 1) % n_events];
            let exit_side = exit_pos.floor() as usize;
            let entry_side = entry_pos.floor() as usize;
            let mut side = exit_side;
            // Corners after the exit's side up to the entry's side (wrapping once at most).
            let wraps = entry_pos < exit_pos;
            if side != entry_side || wraps {
                loop {
                    side = (side + 1) % m;
                    out.push_vertex(frame.to_local(scratch.window[side]));
                    if side == entry_side {
                        break;
                    }
                }
            }
            c = next as usize;
            if scratch.exit_at[c].1 {
                break;
            }
        }
        if c != c0 {
            out.clear();
            return Err(Degenerate::Window);
        }
        out.close_loop();
    }
    Ok(stats)
}

impl WindowScratch {
    /// Per piece of the last call that used quantitative invisibility: the ray through its
    /// midpoint (unit, world orientation), its arc's own faces, its count `c` and whether that
    /// count came from a ray at the piece (for tests: every count equals the ray's).
    pub fn qi_counts(&self) -> impl Iterator<Item = (DVec3, [u32; 2], i32, bool)> + '_ {
        ContourPieces::qi_counts(&self.qi)
    }
}

/// Whether the arc from the direction of `va` to that of `vb` lies wholly outside the great
/// circle of one of `sides`, with neither end within twice the boundary tolerance of any
/// side's circle: without a square root, what the clipping of step 2 would find from the unit
/// directions (both ends outside that side, and no end on a circle), hence a `continue` there.
/// The margin `2 TOL` is far above the rounding of normalising (a few 1e-16), so the signs and
/// the tolerance tests agree with the unit directions'.
#[inline]
fn wholly_outside(sides: &[DVec3], va: DVec3, vb: DVec3) -> bool {
    let margin = 4.0 * TOL * TOL;
    let (la, lb) = (margin * va.length_squared(), margin * vb.length_squared());
    let mut outside = false;
    for side in sides {
        let (fa, fb) = (side.dot(va), side.dot(vb));
        if fa * fa <= la || fb * fb <= lb {
            return false;
        }
        outside |= fa < 0.0 && fb < 0.0;
    }
    outside
}

/// `W'`: the window (unit directions in `frame`) in world directions, scaled about its centre
/// by `1 + WIDEN` in the gnomonic plane there; returns the centre. `None` for a window wider
/// than [`MIN_COS_HALF_ANGLE`] allows.
fn widened_window(window: &[DVec3], frame: &Frame, out: &mut Vec<DVec3>) -> Option<DVec3> {
    widened(window, |w| frame.to_world(w), out)
}

/// [`widened_window`] with the corners mapped by `map` first.
fn widened(window: &[DVec3], map: impl Fn(DVec3) -> DVec3, out: &mut Vec<DVec3>) -> Option<DVec3> {
    let centre = window
        .iter()
        .map(|&w| map(w))
        .sum::<DVec3>()
        .try_normalize()?;
    out.clear();
    for &w in window {
        let w = map(w);
        let c = w.dot(centre);
        if c < MIN_COS_HALF_ANGLE {
            return None;
        }
        let g = w / c - centre;
        out.push((centre + g * (1.0 + WIDEN)).normalize());
    }
    Some(centre)
}

/// The cosine and sine of the half-angle of the cone about `axis` through the farthest corner.
fn cone_of(corners: &[DVec3], axis: DVec3) -> (f64, f64) {
    let cos = corners.iter().map(|w| w.dot(axis)).fold(1.0f64, f64::min);
    (cos, (1.0 - cos * cos).max(0.0).sqrt())
}

/// A cone of directions from the shading point (world axis, cosine and sine of its half-angle)
/// that contains the window (unit directions in `frame`): the faces of a mesh that can overlap
/// the window are among those the face hierarchy finds in it. `buf` is scratch.
pub fn window_cone(
    window: &[DVec3],
    frame: &Frame,
    buf: &mut Vec<DVec3>,
) -> Option<(DVec3, f64, f64)> {
    if window.len() < 3 {
        return None;
    }
    let centre = widened_window(window, frame, buf)?;
    let (c, s) = cone_of(buf, centre);
    Some((centre, c, s))
}

/// Sides of the polygon [`clip_to_window`] clips to: an octagon around the window in its
/// gnomonic plane, two sides for each of these directions (in units of the plane's axes u, v).
const CLIP_DIRECTIONS: [(f64, f64); 4] = [
    (1.0, 0.0),
    (0.0, 1.0),
    (
        std::f64::consts::FRAC_1_SQRT_2,
        std::f64::consts::FRAC_1_SQRT_2,
    ),
    (
        std::f64::consts::FRAC_1_SQRT_2,
        -std::f64::consts::FRAC_1_SQRT_2,
    ),
];

/// The one convex loop `subject` (a convex mesh's silhouette, in the window's frame) clipped
/// to an octagon `B` around the window `W` (Sutherland–Hodgman, each side a great circle;
/// intersections on the chords, so they lie on both great circles up to rounding), into `out`.
///
/// `B` is the octagon of the window's corners in the gnomonic plane at their mean direction
/// `c` (the extremes along u, v, u ± v), widened by `WIDEN` of its extent. A great-circle arc
/// is a segment in that plane, so `B`, convex there and holding every corner, holds all of `W`
/// whether or not `W` is convex, and with a margin: `W ∖ (subject ∩ B) = W ∖ subject`, with
/// far fewer vertices for the set difference when the subject is a large outline around a
/// small light, and never more than eight of `B`'s own (the window's corners could be 30 for a
/// cylinder light seen from the side). The side through the extreme `s` along a unit direction
/// `d` of the plane is the great circle of the points `w` with `w·d = s (w·c)`, whose normal is
/// `s c − d` (inside: `w·(s c − d) ≥ 0`). `false` (and `out` untouched) when the window is too
/// wide for its gnomonic plane (`MIN_COS_HALF_ANGLE`), degenerate, or the subject not one loop.
pub fn clip_to_window(
    subject: &SphericalPolygon,
    window: &[DVec3],
    out: &mut SphericalPolygon,
    bufs: &mut [Vec<DVec3>; 3],
) -> bool {
    if subject.loop_count() != 1 || window.len() < 3 {
        return false;
    }
    let [sides, a, b] = bufs;
    let Some(c) = window.iter().sum::<DVec3>().try_normalize() else {
        return false;
    };
    let u = c.any_orthonormal_vector();
    let v = c.cross(u);
    let mut lo = [f64::INFINITY; 4];
    let mut hi = [f64::NEG_INFINITY; 4];
    for &w in window {
        let cw = w.dot(c);
        if cw < MIN_COS_HALF_ANGLE {
            return false;
        }
        let (gu, gv) = (w.dot(u) / cw, w.dot(v) / cw);
        for (k, &(du, dv)) in CLIP_DIRECTIONS.iter().enumerate() {
            let s = gu * du + gv * dv;
            (lo[k], hi[k]) = (lo[k].min(s), hi[k].max(s));
        }
    }
    let extent = (0..4).map(|k| hi[k] - lo[k]).fold(0.0f64, f64::max);
    if extent.is_nan() || extent <= 1e-12 {
        return false; // a window of no extent: nothing to clip to
    }
    let margin = WIDEN * extent;
    sides.clear();
    for (k, &(du, dv)) in CLIP_DIRECTIONS.iter().enumerate() {
        let d = u * du + v * dv;
        sides.push(c * (hi[k] + margin) - d);
        sides.push(d - c * (lo[k] - margin));
    }
    clip_loop_to_half_spaces(subject.loop_at(0), sides, a, b);
    out.clear();
    if !a.is_empty() {
        out.push_loop(a.iter().copied());
    }
    true
}

/// Where `p` (on the great circle of normal `n`) lies on the arc from `a` to `b`: strictly
/// inside, clearly outside, or within rounding of an end.
#[inline]
fn inside_arc(a: DVec3, b: DVec3, n: DVec3, p: DVec3) -> ArcPosition {
    // p is inside iff it is on the positive side of both a's and b's perpendicular planes.
    let sa = n.cross(a).dot(p); // > 0: past a toward b
    let sb = b.cross(n).dot(p); // > 0: before b
    let e = 1e-10;
    if sa > e && sb > e && p.dot(a + b) > 0.0 {
        ArcPosition::Inside
    } else if sa < -e || sb < -e || p.dot(a + b) <= 0.0 {
        ArcPosition::Outside
    } else {
        ArcPosition::AtEnd
    }
}
