//! A bounding-volume hierarchy over the faces of one polyhedron, for the ray tests of the
//! exact silhouette (001 Sect. 4.3: one ray per contour piece). A scanned mesh of thousands of
//! faces would otherwise test every face for every piece at every point.
//!
//! The hierarchy only *enumerates* the faces a ray may meet: its boxes are the faces' boxes,
//! widened by a relative margin far above rounding, and the caller runs its own exact test on
//! each face it is handed. So a query with the hierarchy answers what the scan over all faces
//! answers, bit for bit; it only skips faces whose box the ray misses.

use crate::geometry::mesh::polyhedron::Plane;
use glam::DVec3;

/// Meshes with fewer faces are scanned (the hierarchy does not pay).
pub(crate) const FACE_BVH_MIN_FACES: usize = 64;

/// Faces per leaf, at most.
const LEAF_FACES: usize = 4;

/// Depth of the traversal stack: a median split halves the faces at each level.
const STACK: usize = 64;

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: DVec3,
    hi: DVec3,
    /// Leaf: `count > 0` faces from `start` in `faces`; inner: children `start`, `start + 1`.
    start: u32,
    count: u32,
}

/// Face boxes in a binary tree (median splits along the longest axis of the centroids).
#[derive(Clone, Debug, Default)]
pub struct FaceBvh {
    nodes: Vec<Node>,
    faces: Vec<u32>,
}

impl FaceBvh {
    /// The hierarchy over `boxes` (one per face, index = face id).
    pub fn build(boxes: &[(DVec3, DVec3)]) -> FaceBvh {
        let mut faces: Vec<u32> = (0..boxes.len() as u32).collect();
        let mut bvh = FaceBvh {
            nodes: Vec::with_capacity(2 * boxes.len() / LEAF_FACES + 1),
            faces: Vec::new(),
        };
        if boxes.is_empty() {
            return bvh;
        }
        // Widen every box by a margin relative to the mesh's extent, so that the slab test
        // below never rejects a face the exact test would hit.
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for &(a, b) in boxes {
            (lo, hi) = (lo.min(a), hi.max(b));
        }
        let margin = DVec3::splat(1e-9 * (hi - lo).max_element().max(hi.abs().max_element()));
        let boxes: Vec<(DVec3, DVec3)> = boxes
            .iter()
            .map(|&(a, b)| (a - margin, b + margin))
            .collect();
        bvh.nodes.push(Node {
            lo,
            hi,
            start: 0,
            count: 0,
        });
        bvh.split(0, &boxes, &mut faces, 0);
        bvh.faces = faces;
        bvh
    }

    /// Fills node `n` with `faces[first..]`'s slice it owns (recursively).
    fn split(&mut self, n: usize, boxes: &[(DVec3, DVec3)], faces: &mut [u32], first: usize) {
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for &f in faces.iter() {
            let (a, b) = boxes[f as usize];
            (lo, hi) = (lo.min(a), hi.max(b));
        }
        self.nodes[n].lo = lo;
        self.nodes[n].hi = hi;
        if faces.len() <= LEAF_FACES {
            self.nodes[n].start = first as u32;
            self.nodes[n].count = faces.len() as u32;
            return;
        }
        let centre = |f: u32| {
            let (a, b) = boxes[f as usize];
            a + b
        };
        let (mut clo, mut chi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for &f in faces.iter() {
            (clo, chi) = (clo.min(centre(f)), chi.max(centre(f)));
        }
        let ext = chi - clo;
        let axis = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        let mid = faces.len() / 2;
        faces.select_nth_unstable_by(mid, |&a, &b| {
            centre(a)[axis].total_cmp(&centre(b)[axis]).then(a.cmp(&b))
        });
        let child = self.nodes.len();
        let empty = Node {
            lo,
            hi,
            start: 0,
            count: 0,
        };
        self.nodes.push(empty);
        self.nodes.push(empty);
        self.nodes[n].start = child as u32;
        self.nodes[n].count = 0;
        let (left, right) = faces.split_at_mut(mid);
        self.split(child, boxes, left, first);
        self.split(child + 1, boxes, right, first + mid);
    }

    /// Calls `test(face)` for every face whose box the ray `origin + t·dir`, t ≥ 0, meets,
    /// until `test` returns true; returns whether it did.
    pub(crate) fn any(&self, origin: DVec3, dir: DVec3, test: impl FnMut(u32) -> bool) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let inv = DVec3::ONE / dir;
        let hits = |n: &Node| {
            // Slabs; a zero component gives ±inf, and NaN (0·inf at a slab's plane) is
            // treated as inside by the max/min order below.
            let t0 = (n.lo - origin) * inv;
            let t1 = (n.hi - origin) * inv;
            let near = t0.min(t1);
            let far = t0.max(t1);
            let enter = near.x.max(near.y).max(near.z).max(0.0);
            let exit = far.x.min(far.y).min(far.z);
            exit.is_nan() || enter <= exit
        };
        self.walk(hits, test)
    }

    /// Calls `visit(face)` for every face whose box may meet the cone of directions within the
    /// angle θ (given by its cosine and sine) of the unit `axis` from `apex`: a superset of the
    /// faces with a point in the cone (each box is tested through its bounding sphere), and,
    /// given `front_of`, with a point not strictly behind that plane.
    pub(crate) fn for_each_in_cone(
        &self,
        apex: DVec3,
        axis: DVec3,
        cos_theta: f64,
        sin_theta: f64,
        front_of: Option<&Plane>,
        mut visit: impl FnMut(u32),
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let meets = |n: &Node| {
            let (c, r) = (0.5 * (n.lo + n.hi), 0.5 * (n.hi - n.lo).length());
            sphere_meets_cone(apex, axis, cos_theta, sin_theta, c, r)
                && front_of.is_none_or(|p| !ball_behind(p, c, r))
        };
        self.walk(meets, |f| {
            visit(f);
            false
        });
    }

    /// [`FaceBvh::for_each_in_cone`] restricted further to the pyramid from `apex` of a convex
    /// window inside the cone, given by the inward unit normals `sides` of its great circles
    /// ([`ball_meets_pyramid`]): a superset of the faces with a point seen inside the window,
    /// visited in the cone's order.
    pub(crate) fn for_each_in_window(
        &self,
        apex: DVec3,
        axis: DVec3,
        cos_theta: f64,
        sin_theta: f64,
        sides: &[DVec3],
        mut visit: impl FnMut(u32),
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let meets = |n: &Node| {
            let (c, r) = (0.5 * (n.lo + n.hi), 0.5 * (n.hi - n.lo).length());
            sphere_meets_cone(apex, axis, cos_theta, sin_theta, c, r)
                && ball_meets_pyramid(apex, sides, c, r)
        };
        self.walk(meets, |f| {
            visit(f);
            false
        });
    }

    /// Depth-first over the nodes that `enter` accepts, calling `face` on the faces of the
    /// leaves reached until it returns true; returns whether it did.
    fn walk(&self, enter: impl Fn(&Node) -> bool, mut face: impl FnMut(u32) -> bool) -> bool {
        let mut stack = [0u32; STACK];
        let mut sp = 0;
        // Bound: children come after their parent and the stack holds at most one node per level
        // (`STACK` levels: a median split halves the faces each time): each node is entered once.
        let mut cur = 0usize;
        loop {
            let node = &self.nodes[cur];
            if enter(node) {
                if node.count > 0 {
                    let s = node.start as usize;
                    for &f in &self.faces[s..s + node.count as usize] {
                        if face(f) {
                            return true;
                        }
                    }
                } else {
                    stack[sp] = node.start + 1;
                    sp += 1;
                    cur = node.start as usize;
                    continue;
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            cur = stack[sp] as usize;
        }
    }
}

/// The edges of every face (indices into `Polyhedron::edges`), for walking from faces found in
/// the hierarchy to their edges.
#[derive(Clone, Debug, Default)]
pub struct FaceEdges {
    starts: Vec<u32>,
    edges: Vec<u32>,
}

impl FaceEdges {
    /// From the edges' face adjacency.
    pub fn build(face_count: usize, edge_faces: impl Iterator<Item = [u32; 2]> + Clone) -> Self {
        let mut counts = vec![0u32; face_count + 1];
        for faces in edge_faces.clone() {
            for f in faces {
                if (f as usize) < face_count {
                    counts[f as usize + 1] += 1;
                }
            }
        }
        for i in 0..face_count {
            counts[i + 1] += counts[i];
        }
        let mut fill = counts.clone();
        let mut edges = vec![0u32; counts[face_count] as usize];
        for (e, faces) in edge_faces.enumerate() {
            for f in faces {
                if (f as usize) < face_count {
                    edges[fill[f as usize] as usize] = e as u32;
                    fill[f as usize] += 1;
                }
            }
        }
        FaceEdges {
            starts: counts,
            edges,
        }
    }

    /// The edges of face `f`.
    #[inline]
    pub(crate) fn edges_of(&self, f: usize) -> &[u32] {
        &self.edges[self.starts[f] as usize..self.starts[f + 1] as usize]
    }
}

/// Whether the ball of centre `c` and radius `r` may hold a point whose direction from `apex`
/// lies in the convex window of the inward unit normals `sides` (its great circles through
/// `apex`): false only when the ball lies wholly on the outer side of one of them, by more
/// than its radius with a relative margin of 1e-9.
#[inline]
pub(crate) fn ball_meets_pyramid(apex: DVec3, sides: &[DVec3], c: DVec3, r: f64) -> bool {
    let d = c - apex;
    let slack = r * (1.0 + 1e-9) + 1e-9 * d.length();
    sides.iter().all(|n| n.dot(d) >= -slack)
}

/// Whether the ball of centre `c` and radius `r` may meet the cone of directions within the
/// angle θ (given by its cosine and sine) of the unit `axis` from `apex` (conservative by a
/// relative 1e-9).
#[inline]
pub(crate) fn sphere_meets_cone(
    apex: DVec3,
    axis: DVec3,
    cos_theta: f64,
    sin_theta: f64,
    c: DVec3,
    r: f64,
) -> bool {
    let v = c - apex;
    let d = v.length();
    if d <= r * (1.0 + 1e-9) {
        return true;
    }
    // angle(v, axis) ≤ θ + asin(r / d)  ⇔  cos(angle) ≥ cos(θ + φ), when θ + φ < π.
    let (sin_phi, cos_phi) = (r / d, (1.0 - (r / d) * (r / d)).max(0.0).sqrt());
    let cos_sum = cos_theta * cos_phi - sin_theta * sin_phi;
    let sin_sum = sin_theta * cos_phi + cos_theta * sin_phi;
    if sin_sum < 0.0 && cos_sum < 0.0 {
        return true; // θ + φ past π: every direction
    }
    v.dot(axis) >= d * cos_sum - 1e-9 * d
}

/// Whether the ball (`c`, `r`) lies strictly behind `plane` (`eval < 0` at every point), by
/// more than the rounding of `eval` at a point of it.
#[inline]
fn ball_behind(plane: &Plane, c: DVec3, r: f64) -> bool {
    let n = plane.n.length();
    let margin = 1e-9 * (n * (c.length() + r) + plane.d.abs());
    plane.eval(c) + n * r < -margin
}
