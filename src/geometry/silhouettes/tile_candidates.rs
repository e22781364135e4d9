//! Candidate edges shared by the shading points of a tile (docs/silhouettes.md, "Candidates
//! shared by a tile").
//!
//! The renderer shades an image in tiles of 16 × 16 pixels and cuts each into regions: the
//! points of one block of pixels on one object, in a small ball. From every point of a region
//! a mesh has nearly the same contour and the light lies in nearly the same directions, yet
//! the window query of the edge hierarchy ([`EdgeHierarchy::candidates_in_window`]) at each
//! point walks the tree again and hands out hundreds of edges, most of which are no contour
//! edge there. Here a region finds once the edges that can be a contour or boundary edge in
//! the window of any of its points ([`EdgeHierarchy::tile_candidates`]), in the tree's order,
//! and each point takes those instead of its own query.
//!
//! Why the per-point result is unchanged. Every edge that a point's windowed silhouette makes
//! an arc of is a contour or boundary edge there (or borders a face through the point) with a
//! part inside its window, and is in the region's list, in the order of the point's query:
//! so are its arcs, and the silhouette, bit for bit. An edge of the point's own query left
//! out of the list yields no arc there. The one configuration that can differ is one the
//! windowed silhouette gives up on anyway (an end of an edge outside the window lying on the
//! great circle of a window's side), and the path it then falls back to is exact too.
//!
//! Why the list holds those edges (Eq. EH.2 of docs/silhouettes.md). Let the region's points
//! lie in the ball `B(c, ρ)` and the light in the ball `B(c_L, R_L)`.
//! - Contour: a face plane `s(x) = n · x − d` changes by at most `|n| ρ` over the ball, so an
//!   edge whose two faces have `s > |n| ρ + tol` (or both `< −(|n| ρ + tol)`) at `c` is seen
//!   from the same side, beyond the coplanarity tolerance, from every point: no contour edge,
//!   no face through a point. The hierarchy's normal-cone test moves to the ball the same way.
//! - Cone: every direction from a point `x` of the ball to the light is within
//!   `asin((R_L + ρ) / |c_L − c|)` of `c_L − c`. A point's window is the light (or a face of
//!   it) clipped to the horizon and widened by `WIDEN` in its gnomonic plane, which moves a
//!   corner by at most `WIDEN / 2` radians (the window is narrower than 60° from its centre);
//!   so every window lies in the cone from `c` of half-angle `θ = asin(…) + ANGLE_SLACK`. A
//!   point `p = x + t u` seen in a window has `p + (c − x)`, within `ρ` of `p`, in that cone
//!   from `c`: a ball holding `p`, grown by `ρ`, meets the cone.
//! - Pyramid: when the window of the point `x₀` that builds the list is the whole light (no
//!   horizon clips it), each side `n` of it has `n · (l − x₀) ≥ 0` for every point `l` of the
//!   light. For another point `x`, within `r₀ = |x₀ − c| + ρ` of `x₀`, `n · (l − x) ≥ −r₀`,
//!   so a direction `u` in its window has `n · u ≥ −r₀ / (|c_L − c| − R_L − ρ) − ANGLE_SLACK`
//!   (the spread σ), and `p = x + t u` has `n · (p − x₀) ≥ −r₀ − t σ`
//!   ([`RegionPyramid`]).

use crate::geometry::mesh::edge_hierarchy::{EdgeHierarchy, RegionCone, RegionPyramid};
use crate::geometry::mesh::polyhedron::{NO_FACE, Plane, Polyhedron};
use glam::DVec3;
use std::sync::atomic::{AtomicU64, Ordering};

/// Added to the cone's half-angle: the widening of the window (at most 5e-4 rad) and the
/// queries' own slack, with room to spare.
const ANGLE_SLACK: f64 = 2e-3;

/// Cones wider than this (half-angle, radians) would keep nearly every node: the points then
/// take the whole tree.
const MAX_HALF_ANGLE: f64 = 1.2;

/// Edge lists kept per thread at once (one per region, occluder and light in the current tiles).
const SLOTS: usize = 8;

/// The shading points of one tile on one object: a ball holding them all, and an id no other
/// region of this process has (so that what was found for it is never taken for another).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TileRegion {
    pub id: u64,
    pub centre: DVec3,
    pub radius: f64,
}

impl TileRegion {
    /// The smallest box-centred ball around points whose box is `lo`–`hi`, with a fresh id.
    pub fn around(lo: DVec3, hi: DVec3) -> TileRegion {
        static NEXT: AtomicU64 = AtomicU64::new(1);
        let centre = 0.5 * (lo + hi);
        // Rounding of the centre and of the distances: a relative 1e-12 of the coordinates.
        let radius = 0.5 * (hi - lo).length() * (1.0 + 1e-12)
            + 1e-12 * (centre.abs().max_element() + (hi - lo).max_element());
        TileRegion {
            id: NEXT.fetch_add(1, Ordering::Relaxed),
            centre,
            radius,
        }
    }
}

/// What one windowed query may share: the region of its shading point, the ball bounding the
/// light its window comes from, and a key naming the mesh and light (the same key must name
/// the same pair within a region).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TileQuery {
    pub region: TileRegion,
    pub light_centre: DVec3,
    pub light_radius: f64,
    pub key: u64,
    /// The window of the point is the whole light as seen from it (no horizon clips it, it
    /// is not a part of a split window): its pyramid holds the light.
    pub whole_light: bool,
}

impl TileQuery {
    /// The cone from the region's centre holding every window of its points (module docs);
    /// `None` where the light is too close or too wide for one to pay.
    pub(crate) fn cone(&self) -> Option<RegionCone> {
        let to_light = self.light_centre - self.region.centre;
        let dist = to_light.length();
        let reach = self.light_radius + self.region.radius;
        // (NaN coordinates fail this too.)
        if reach.is_nan() || dist.is_nan() || reach >= dist {
            return None;
        }
        let theta = (reach / dist).asin() + ANGLE_SLACK;
        if theta > MAX_HALF_ANGLE {
            return None;
        }
        Some(RegionCone {
            centre: self.region.centre,
            radius: self.region.radius,
            axis: to_light / dist,
            cos_theta: theta.cos(),
            sin_theta: theta.sin(),
        })
    }

    /// The pyramid of the whole light seen from `x`, a point of the region (module docs),
    /// where [`TileQuery::cone`] is `Some`.
    fn pyramid<'a>(&self, x: DVec3, sides: &'a [DVec3]) -> RegionPyramid<'a> {
        let r = &self.region;
        let reach = (x - r.centre).length() + r.radius;
        let nearest = (self.light_centre - r.centre).length() - self.light_radius - r.radius;
        RegionPyramid {
            apex: x,
            sides,
            reach: reach * (1.0 + 1e-12),
            spread: reach / nearest + ANGLE_SLACK,
        }
    }
}

/// The candidate edges of a few (region, mesh and light) of the current tiles, reused from one
/// tile to the next (per thread).
#[derive(Clone, Debug, Default)]
pub struct TileCandidates {
    slots: Vec<Slot>,
    clock: u64,
    /// Edge lists built, and queries that used one (for the measurements).
    pub built: u64,
    pub shared: u64,
    /// The length of the list the last windowed query took, if it took one.
    pub last: Option<u32>,
}

#[derive(Clone, Debug, Default)]
struct Slot {
    region: u64,
    key: u64,
    used: u64,
    /// `false`: the region's cone was too wide; its points take the whole hierarchy.
    valid: bool,
    centre: DVec3,
    radius: f64,
    edges: Vec<u32>,
    /// The planes of the two faces of each edge of `edges[..planes.len()]` (the edges with
    /// two faces; the boundary edges follow them), side by side for the points' own test.
    planes: Vec<[Plane; 2]>,
}

impl TileCandidates {
    /// Writes into `out` the candidate edges of `poly` (through its `hierarchy`) for the
    /// window of the point `x` of `query`'s region: the region's list
    /// ([`EdgeHierarchy::tile_candidates`], found or built) without the edges that the
    /// windowed silhouette passes over at `x` as no contour edge (both faces present, seen
    /// from the same side), by the same test on the same planes. `false` (and `out`
    /// untouched) when `x` is outside the region or the region's cone is too wide.
    ///
    /// `sides`: the inward normals of the point's widened window (world directions); when the
    /// window is the whole light, a list built here is restricted to its pyramid too.
    /// `edge_on`: the coplanarity tolerance when `x` lies on the mesh (a face within it of `x`
    /// is left out, and its edges count as boundary edges).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn fill(
        &mut self,
        hierarchy: &EdgeHierarchy,
        poly: &Polyhedron,
        query: &TileQuery,
        x: DVec3,
        sides: &[DVec3],
        edge_on: Option<f64>,
        out: &mut Vec<u32>,
    ) -> bool {
        self.clock += 1;
        let found = self
            .slots
            .iter()
            .position(|s| s.region == query.region.id && s.key == query.key);
        let at = match found {
            Some(at) => at,
            None => {
                let at = if self.slots.len() < SLOTS {
                    self.slots.push(Slot::default());
                    self.slots.len() - 1
                } else {
                    // The least recently used slot; its buffer is reused.
                    (0..self.slots.len())
                        .min_by_key(|&i| self.slots[i].used)
                        .unwrap_or(0)
                };
                let slot = &mut self.slots[at];
                slot.region = query.region.id;
                slot.key = query.key;
                slot.centre = query.region.centre;
                slot.radius = query.region.radius;
                slot.valid = match query.cone() {
                    Some(cone) => {
                        let pyramid = query.whole_light.then(|| query.pyramid(x, sides));
                        hierarchy.tile_candidates(poly, &cone, pyramid.as_ref(), &mut slot.edges);
                        slot.planes.clear();
                        for &e in &slot.edges {
                            let [g0, g1] = poly.edges[e as usize].faces;
                            if g0 == NO_FACE || g1 == NO_FACE {
                                break; // the boundary edges, last
                            }
                            slot.planes.push([
                                poly.face_planes[g0 as usize],
                                poly.face_planes[g1 as usize],
                            ]);
                        }
                        true
                    }
                    None => false,
                };
                self.built += 1;
                at
            }
        };
        let slot = &mut self.slots[at];
        slot.used = self.clock;
        let holds = (x - slot.centre).length_squared() <= slot.radius * slot.radius;
        if !(slot.valid && holds) {
            return false;
        }
        self.shared += 1;
        self.last = Some(slot.edges.len() as u32);
        let (with_faces, boundary) = slot.edges.split_at(slot.planes.len());
        // Written without a branch per edge (few of them are kept, at no predictable place):
        // every edge is stored, and the end moves past the kept ones only.
        let tol = edge_on.unwrap_or(-1.0);
        let mut end = out.len();
        out.resize(end + with_faces.len(), 0);
        for (&e, [p0, p1]) in with_faces.iter().zip(&slot.planes) {
            let (s0, s1) = (p0.eval(x), p1.eval(x));
            let keep = (s0.abs() <= tol) | (s1.abs() <= tol) | ((s0 > 0.0) != (s1 > 0.0));
            out[end] = e;
            end += keep as usize;
        }
        out.truncate(end);
        out.extend_from_slice(boundary);
        true
    }
}
