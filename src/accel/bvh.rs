//! A bounding volume hierarchy over every triangle of a [`Scene`] (docs/accel.md).
//!
//! * Build: binned SAH (Wald 2007) on triangle-box centroids, 16 bins per axis, all three
//!   axes binned in one pass; subtrees of at least `PAR_GRAIN` triangles are built in
//!   parallel with `rayon::join`. Below depth `DEPTH_CAP` splits are SAH; past it (and when
//!   all centroids coincide) they are object medians, which bounds the depth by
//!   `DEPTH_CAP + log2(n) < STACK_SIZE`.
//! * Layout: nodes in one array, 32 bytes each (box rounded outwards to f32, two `u32`),
//!   the two children of an inner node adjacent in one 64-byte cache line; triangles
//!   copied in leaf order with their three f64 vertices (the watertight test needs the
//!   vertices themselves, not an edge form) and their (object, face). Face normals
//!   (Newell) are kept per face, not per triangle.
//! * Traversal: fixed-size stack on the program stack, both children's boxes tested, the
//!   nearer visited first and the farther pushed with its entry distance so that it is
//!   skipped if a closer hit has been found by the time it is popped. No allocation.
//! * Robustness: boxes are slab-tested against a ray whose origin is widened by
//!   `eta = 16 eps (max |vertex coordinate| + max |origin coordinate|)` on every axis. The
//!   watertight triangle test decides exactly for vertices moved by the rounding of the
//!   translation and shear, at most about `6 eps |v - o|_inf` per axis, and the slab
//!   arithmetic rounds by about `3 eps |b - o|`; `eta` covers both, so the box test never
//!   rejects a triangle that the triangle test accepts, and the BVH is exactly as
//!   watertight as the triangle test. Zero direction components (infinite reciprocals)
//!   are handled by NaN-ignoring min/max: a ray parallel to a slab and inside it sees
//!   (-inf, inf).

use glam::{DVec3, Vec3};
use std::mem::MaybeUninit;

use super::ray::Ray;
use super::triangle::{PreparedRay, RawHit, is_degenerate};
use crate::scene::Scene;

/// Closest hit of a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter, in units of the ray direction.
    pub t: f64,
    /// Index into `scene.objects`.
    pub object: u32,
    /// Index into that object's `mesh.faces`.
    pub face: u32,
    /// The hit point, interpolated from the triangle's vertices (on the triangle to within
    /// the rounding of its coordinates).
    pub point: DVec3,
    /// Unit normal of the front side of the face (counter-clockwise winding seen from the
    /// front): the normalised Newell normal of the whole polygon.
    pub geometric_normal: DVec3,
}

/// Bins per axis of the SAH build.
const BINS: usize = 16;
/// Leaves hold at most this many triangles (unless all centroids coincide past the depth
/// budget, which the median split still halves).
const MAX_LEAF: usize = 8;
/// SAH cost of one traversal step (two box tests) relative to one triangle test. Measured
/// throughput is flat between 1 and 3 (docs/accel.md); 2 gives about 0.7 nodes per
/// triangle.
const C_TRAV: f64 = 2.0;
/// Past this depth, splits are object medians (guaranteeing logarithmic depth below).
const DEPTH_CAP: u32 = 30;
/// Traversal stack entries; the depth is at most `DEPTH_CAP + 31` for `n < 2^31`.
const STACK_SIZE: usize = 64;
/// Subtrees with at least this many triangles are built in parallel.
const PAR_GRAIN: usize = 4096;
/// Relative widening of the ray origin in the box test (see the module docs).
const BOX_SLACK: f64 = 16.0 * f64::EPSILON;

/// 32 bytes: the two children of an inner node share one 64-byte cache line.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
struct Node {
    /// The box, rounded outwards to f32 (half the memory traffic of f64; the box only
    /// grows, so the test stays conservative).
    bmin: Vec3,
    bmax: Vec3,
    /// Inner node: index of the first child (the second follows it). Leaf: first triangle.
    start: u32,
    /// Number of triangles; 0 for an inner node.
    count: u32,
}

/// Largest f32 <= x (or -inf).
fn f32_down(x: f64) -> f32 {
    let f = x as f32;
    if f as f64 > x { f.next_down() } else { f }
}

/// Smallest f32 >= x (or +inf).
fn f32_up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x { f.next_up() } else { f }
}

impl Node {
    fn new(bmin: DVec3, bmax: DVec3, start: u32, count: u32) -> Node {
        Node {
            bmin: Vec3::new(f32_down(bmin.x), f32_down(bmin.y), f32_down(bmin.z)),
            bmax: Vec3::new(f32_up(bmax.x), f32_up(bmax.y), f32_up(bmax.z)),
            start,
            count,
        }
    }
}

#[derive(Clone, Copy, Debug)]
struct Tri {
    v0: DVec3,
    v1: DVec3,
    v2: DVec3,
    object: u32,
    face: u32,
}

impl Tri {
    /// Tie-break for hits at exactly the same `t` (an edge shared by two faces): the
    /// smallest (object, face) wins, whatever the traversal order, as in a brute-force loop.
    #[inline]
    fn key(&self) -> u64 {
        ((self.object as u64) << 32) | self.face as u64
    }
}

/// BVH over all triangles (fan triangulation of every face) of all objects of a scene,
/// whatever their flags. Zero-area triangles are left out.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
    tris: Vec<Tri>,
    /// Unit Newell normal per face (zero for a face without area), at
    /// `face_base[object] + face`.
    face_normals: Vec<DVec3>,
    face_base: Vec<usize>,
    /// Largest |coordinate| of any stored vertex, for the box-test slack.
    max_abs: f64,
    /// The SAH cost (relative to the root's area) of the tree as last built, which a refit
    /// may let grow to [`REFIT_MAX_COST`] times before [`Bvh::with_moved_object`] rebuilds.
    built_cost: f64,
    /// Refits since the last build.
    refits: u32,
}

/// A refit tree whose SAH cost grew beyond this factor of the built tree's is rebuilt.
pub(crate) const REFIT_MAX_COST: f64 = 1.25;

/// The normalised Newell normal of a polygon (front side = counter-clockwise), or zero if
/// the polygon has no area or an index is out of range. For a planar polygon it is the
/// normal of its plane whatever its shape; for a non-planar one, the normal of the best
/// plane in the sense of its projected area.
pub fn newell_normal(positions: &[DVec3], face: &[u32]) -> DVec3 {
    if face.len() < 3 || face.iter().any(|&i| i as usize >= positions.len()) {
        return DVec3::ZERO;
    }
    crate::math::polygon_area_vector(face.iter().map(|&i| positions[i as usize]))
        .normalize_or_zero()
}

#[derive(Clone, Copy)]
struct Prim {
    bmin: DVec3,
    bmax: DVec3,
    centroid: DVec3,
}

#[derive(Clone, Copy)]
struct Bin {
    bmin: DVec3,
    bmax: DVec3,
    count: usize,
}

impl Bin {
    const EMPTY: Bin = Bin {
        bmin: DVec3::INFINITY,
        bmax: DVec3::NEG_INFINITY,
        count: 0,
    };
    #[inline]
    fn grow(&mut self, bmin: DVec3, bmax: DVec3, count: usize) {
        self.bmin = self.bmin.min(bmin);
        self.bmax = self.bmax.max(bmax);
        self.count += count;
    }
}

/// Half the surface area of a box (the SAH only needs ratios).
#[inline]
fn half_area(bmin: DVec3, bmax: DVec3) -> f64 {
    let d = (bmax - bmin).max(DVec3::ZERO);
    d.x * d.y + d.y * d.z + d.z * d.x
}

#[inline]
fn bin_of(c: f64, cmin: f64, scale: f64) -> usize {
    // `as` saturates (and maps NaN to 0), so the index is always in range.
    (((c - cmin) * scale) as usize).min(BINS - 1)
}

enum BuildNode {
    Leaf {
        bmin: DVec3,
        bmax: DVec3,
        start: u32,
        count: u32,
    },
    Inner {
        bmin: DVec3,
        bmax: DVec3,
        children: Box<[BuildNode; 2]>,
    },
}

/// Splits `idx` in place so that the first part satisfies `pred`; returns its length.
fn partition(idx: &mut [u32], mut pred: impl FnMut(u32) -> bool) -> usize {
    let (mut i, mut j) = (0, idx.len());
    while i < j {
        if pred(idx[i]) {
            i += 1;
        } else {
            j -= 1;
            idx.swap(i, j);
        }
    }
    i
}

fn build_node(prims: &[Prim], idx: &mut [u32], offset: usize, depth: u32) -> BuildNode {
    let n = idx.len();
    let (mut bmin, mut bmax) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    let (mut cmin, mut cmax) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for &i in idx.iter() {
        let p = &prims[i as usize];
        bmin = bmin.min(p.bmin);
        bmax = bmax.max(p.bmax);
        cmin = cmin.min(p.centroid);
        cmax = cmax.max(p.centroid);
    }
    let leaf = || BuildNode::Leaf {
        bmin,
        bmax,
        start: offset as u32,
        count: n as u32,
    };
    if n == 1 {
        return leaf();
    }

    let extent = cmax - cmin;
    let mid = if depth < DEPTH_CAP && extent.max_element() > 0.0 {
        match sah_split(prims, idx, bmin, bmax, cmin, extent) {
            Some((axis, k)) => {
                let scale = BINS as f64 / extent[axis];
                partition(idx, |i| {
                    bin_of(prims[i as usize].centroid[axis], cmin[axis], scale) < k
                })
            }
            None if n <= MAX_LEAF => return leaf(),
            None => median_split(prims, idx, extent),
        }
    } else if n <= MAX_LEAF {
        return leaf();
    } else {
        median_split(prims, idx, extent)
    };
    debug_assert!(mid > 0 && mid < n);

    let (left, right) = idx.split_at_mut(mid);
    let (a, b) = if n >= PAR_GRAIN {
        rayon::join(
            || build_node(prims, left, offset, depth + 1),
            || build_node(prims, right, offset + mid, depth + 1),
        )
    } else {
        (
            build_node(prims, left, offset, depth + 1),
            build_node(prims, right, offset + mid, depth + 1),
        )
    };
    BuildNode::Inner {
        bmin,
        bmax,
        children: Box::new([a, b]),
    }
}

/// Object median along the axis of largest centroid extent (any halving if all coincide).
fn median_split(prims: &[Prim], idx: &mut [u32], extent: DVec3) -> usize {
    let axis = extent.max_position();
    let mid = idx.len() / 2;
    idx.select_nth_unstable_by(mid, |&a, &b| {
        let ca = prims[a as usize].centroid[axis];
        let cb = prims[b as usize].centroid[axis];
        ca.total_cmp(&cb)
    });
    mid
}

/// Best binned-SAH split `(axis, k)` (bins `< k` go left), or `None` if a leaf is cheaper
/// (only when `idx` fits in a leaf) or no bin boundary separates the centroids.
fn sah_split(
    prims: &[Prim],
    idx: &[u32],
    bmin: DVec3,
    bmax: DVec3,
    cmin: DVec3,
    extent: DVec3,
) -> Option<(usize, usize)> {
    let n = idx.len();
    let mut bins = [[Bin::EMPTY; BINS]; 3];
    let scale = DVec3::splat(BINS as f64) / extent; // inf on flat axes, which are skipped
    for &i in idx {
        let p = &prims[i as usize];
        for axis in 0..3 {
            if extent[axis] > 0.0 {
                let b = bin_of(p.centroid[axis], cmin[axis], scale[axis]);
                bins[axis][b].grow(p.bmin, p.bmax, 1);
            }
        }
    }

    let mut best: Option<(usize, usize)> = None;
    let mut best_cost = f64::INFINITY;
    for (axis, bins) in bins.iter().enumerate() {
        if extent[axis] <= 0.0 {
            continue;
        }
        // right[k] = union of bins k.. (for k in 1..BINS)
        let mut right_area = [0.0; BINS];
        let mut right_count = [0usize; BINS];
        let mut acc = Bin::EMPTY;
        for k in (1..BINS).rev() {
            acc.grow(bins[k].bmin, bins[k].bmax, bins[k].count);
            right_area[k] = half_area(acc.bmin, acc.bmax);
            right_count[k] = acc.count;
        }
        let mut acc = Bin::EMPTY;
        for k in 1..BINS {
            acc.grow(bins[k - 1].bmin, bins[k - 1].bmax, bins[k - 1].count);
            if acc.count == 0 || right_count[k] == 0 {
                continue;
            }
            let cost = half_area(acc.bmin, acc.bmax) * acc.count as f64
                + right_area[k] * right_count[k] as f64;
            if cost < best_cost {
                best_cost = cost;
                best = Some((axis, k));
            }
        }
    }

    // Leaf cost n * A versus split cost C_TRAV * A + sum(A_child * n_child), both scaled
    // by the parent's area A (which may be zero for a degenerate cluster).
    let area = half_area(bmin, bmax);
    if n <= MAX_LEAF && n as f64 * area <= C_TRAV * area + best_cost {
        return None;
    }
    best
}

fn flatten(node: BuildNode, slot: usize, nodes: &mut Vec<Node>) {
    match node {
        BuildNode::Leaf {
            bmin,
            bmax,
            start,
            count,
        } => nodes[slot] = Node::new(bmin, bmax, start, count),
        BuildNode::Inner {
            bmin,
            bmax,
            children,
        } => {
            let first = nodes.len();
            debug_assert!(first.is_multiple_of(2));
            nodes[slot] = Node::new(bmin, bmax, first as u32, 0);
            let placeholder = nodes[slot];
            nodes.push(placeholder);
            nodes.push(placeholder);
            let [a, b] = *children;
            flatten(a, first, nodes);
            flatten(b, first + 1, nodes);
        }
    }
}

/// Per-ray data of the traversal: the watertight test's frame and the box test's
/// reciprocal direction and widened origin.
struct TraversalRay {
    tri: PreparedRay,
    inv: DVec3,
    o_lo: DVec3,
    o_hi: DVec3,
}

impl TraversalRay {
    fn new(ray: &Ray, max_abs: f64) -> Option<Self> {
        let tri = PreparedRay::new(ray);
        if !tri.is_valid() {
            return None;
        }
        // `+ 0.0` turns -0 into +0, so zero components give +inf reciprocals (never -inf):
        // the NaN cases of the slab test are then exactly the ones `box_entries` ignores.
        let inv = DVec3::ONE / (ray.dir + DVec3::ZERO);
        let m = max_abs + ray.origin.abs().max_element();
        let eta = DVec3::splat(BOX_SLACK * m + f64::MIN_POSITIVE);
        Some(TraversalRay {
            tri,
            inv,
            o_lo: ray.origin - eta,
            o_hi: ray.origin + eta,
        })
    }

    /// Entry distances of the ray into the boxes of two sibling nodes within
    /// `[t_min, t_max]`, `f64::INFINITY` for a miss. Written lane-wise so that the two boxes
    /// are tested together (SSE2 on x86-64).
    #[inline(always)]
    fn box_entries(&self, pair: &[Node], t_min: f64, t_max: f64) -> [f64; 2] {
        let (n0, n1) = (&pair[0], &pair[1]);
        let mut entry = [t_min; 2];
        let mut exit = [t_max; 2];
        // Slab distances of the boxes widened by eta: (bmin - eta - o) / d and
        // (bmax + eta - o) / d. NaN arises only as 0 * inf: the origin on a widened slab
        // plane of an axis the ray is parallel to. The comparisons are arranged so that a
        // NaN never narrows the interval (`x > y` and `x < y` are false for NaN).
        macro_rules! axis {
            ($c:ident) => {{
                let lo = [n0.bmin.$c as f64, n1.bmin.$c as f64];
                let hi = [n0.bmax.$c as f64, n1.bmax.$c as f64];
                for k in 0..2 {
                    let a = (lo[k] - self.o_hi.$c) * self.inv.$c;
                    let b = (hi[k] - self.o_lo.$c) * self.inv.$c;
                    let near = if a > b { b } else { a };
                    let far = if a > b { a } else { b };
                    entry[k] = if near > entry[k] { near } else { entry[k] };
                    exit[k] = if far < exit[k] { far } else { exit[k] };
                }
            }};
        }
        axis!(x);
        axis!(y);
        axis!(z);
        let mut out = [f64::INFINITY; 2];
        for k in 0..2 {
            if entry[k] <= exit[k] {
                out[k] = entry[k];
            }
        }
        out
    }

    /// Entry distance of the ray into one node's box, if any (the root).
    fn box_entry(&self, node: &Node, t_min: f64, t_max: f64) -> Option<f64> {
        let e = self.box_entries(&[*node, *node], t_min, t_max)[0];
        (e < f64::INFINITY).then_some(e)
    }
}

impl Bvh {
    /// Builds the BVH over all triangles of all objects. Faces with fewer than three
    /// vertices or with out-of-range indices contribute no triangles.
    pub fn build(scene: &Scene) -> Bvh {
        let mut tris = Vec::new();
        let mut face_normals = Vec::new();
        let mut face_base = Vec::with_capacity(scene.objects.len());
        let mut max_abs: f64 = 0.0;
        for (object, obj) in scene.objects.iter().enumerate() {
            face_base.push(face_normals.len());
            let pos = &obj.mesh.positions;
            for (face, f) in obj.mesh.faces.iter().enumerate() {
                let normal = newell_normal(pos, f);
                face_normals.push(normal);
                if f.len() < 3 || f.iter().any(|&i| i as usize >= pos.len()) {
                    continue;
                }
                for k in 1..f.len() - 1 {
                    let (v0, v1, v2) = (
                        pos[f[0] as usize],
                        pos[f[k] as usize],
                        pos[f[k + 1] as usize],
                    );
                    if is_degenerate(v0, v1, v2) {
                        continue;
                    }
                    for v in [v0, v1, v2] {
                        max_abs = max_abs.max(v.abs().max_element());
                    }
                    tris.push(Tri {
                        v0,
                        v1,
                        v2,
                        object: object as u32,
                        face: face as u32,
                    });
                }
            }
        }
        assert!(
            tris.len() < (1 << 31),
            "BVH: too many triangles ({})",
            tris.len()
        );

        let mut bvh = Bvh {
            nodes: Vec::new(),
            tris: Vec::new(),
            face_normals,
            face_base,
            max_abs,
            built_cost: 0.0,
            refits: 0,
        };
        if tris.is_empty() {
            return bvh;
        }

        let prims: Vec<Prim> = tris
            .iter()
            .map(|t| {
                let bmin = t.v0.min(t.v1).min(t.v2);
                let bmax = t.v0.max(t.v1).max(t.v2);
                Prim {
                    bmin,
                    bmax,
                    centroid: 0.5 * (bmin + bmax),
                }
            })
            .collect();
        let mut order: Vec<u32> = (0..tris.len() as u32).collect();
        let root = build_node(&prims, &mut order, 0, 0);
        // Root at 0, an unused node at 1, so that sibling pairs start at even indices and
        // each pair fills one aligned cache line.
        let placeholder = Node::new(DVec3::ZERO, DVec3::ZERO, 0, 0);
        let mut nodes = Vec::with_capacity(2 * tris.len());
        nodes.push(placeholder);
        nodes.push(placeholder);
        flatten(root, 0, &mut nodes);
        bvh.nodes = nodes;
        bvh.tris = order.iter().map(|&i| tris[i as usize]).collect();
        bvh.built_cost = bvh.sah_cost();
        bvh
    }

    /// The SAH cost of the tree relative to its root's area: `C_TRAV` per inner node and one
    /// per triangle of a leaf, each weighted by its box's area.
    fn sah_cost(&self) -> f64 {
        let Some(root) = self.nodes.first() else {
            return 0.0;
        };
        let area = |n: &Node| half_area(n.bmin.as_dvec3(), n.bmax.as_dvec3());
        let root_area = area(root).max(f64::MIN_POSITIVE);
        let mut cost = 0.0;
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let n = &self.nodes[i];
            if n.count > 0 {
                cost += area(n) * n.count as f64;
            } else {
                cost += C_TRAV * area(n);
                stack.push(n.start as usize);
                stack.push(n.start as usize + 1);
            }
        }
        cost / root_area
    }

    /// Refits since the last full build (0 for a tree just built).
    pub fn refits(&self) -> u32 {
        self.refits
    }

    /// The BVH of `new`, a copy of `old` (the scene this BVH was built from) in which object
    /// `object` moved (any change of its positions, its faces unchanged): the object's
    /// triangles are replaced in place and the boxes refit bottom-up, which hits exactly what
    /// a rebuild would (the closest hit and its tie rule do not depend on the tree's shape).
    /// Rebuilt instead when the object's faces or non-degenerate triangles changed, when the
    /// scenes do not match, or when the refit tree's SAH cost exceeds [`REFIT_MAX_COST`]
    /// times that of the last build.
    pub fn with_moved_object(&self, old: &Scene, new: &Scene, object: usize) -> Bvh {
        self.refit(old, new, object)
            .unwrap_or_else(|| Bvh::build(new))
    }

    fn refit(&self, old: &Scene, new: &Scene, object: usize) -> Option<Bvh> {
        let (o, n) = (old.objects.get(object)?, new.objects.get(object)?);
        if old.objects.len() != new.objects.len()
            || self.face_base.len() != new.objects.len()
            || o.mesh.faces != n.mesh.faces
            || o.mesh.positions.len() != n.mesh.positions.len()
            || self.nodes.is_empty()
        {
            return None;
        }
        let (old_pos, pos) = (&o.mesh.positions, &n.mesh.positions);
        let mut bvh = self.clone();
        let base = self.face_base[object];
        for (face, f) in n.mesh.faces.iter().enumerate() {
            bvh.face_normals[base + face] = newell_normal(pos, f);
        }
        // Every stored triangle of the object, found by its old vertices; the counts of
        // non-degenerate triangles must agree.
        let mut stored = 0usize;
        for t in bvh.tris.iter_mut().filter(|t| t.object == object as u32) {
            let f = n.mesh.faces.get(t.face as usize)?;
            if f.iter().any(|&i| i as usize >= pos.len()) {
                return None;
            }
            let k = (1..f.len().saturating_sub(1)).find(|&k| {
                old_pos[f[0] as usize] == t.v0
                    && old_pos[f[k] as usize] == t.v1
                    && old_pos[f[k + 1] as usize] == t.v2
            })?;
            let (v0, v1, v2) = (
                pos[f[0] as usize],
                pos[f[k] as usize],
                pos[f[k + 1] as usize],
            );
            if is_degenerate(v0, v1, v2) {
                return None;
            }
            (t.v0, t.v1, t.v2) = (v0, v1, v2);
            stored += 1;
        }
        let fresh = n
            .mesh
            .faces
            .iter()
            .filter(|f| f.len() >= 3 && f.iter().all(|&i| (i as usize) < pos.len()))
            .flat_map(|f| {
                (1..f.len() - 1).filter(move |&k| {
                    !is_degenerate(
                        pos[f[0] as usize],
                        pos[f[k] as usize],
                        pos[f[k + 1] as usize],
                    )
                })
            })
            .count();
        if fresh != stored {
            return None;
        }
        bvh.max_abs = bvh
            .tris
            .iter()
            .map(|t| t.v0.abs().max(t.v1.abs()).max(t.v2.abs()).max_element())
            .fold(0.0, f64::max);
        bvh.refit_node(0);
        bvh.refits += 1;
        (bvh.sah_cost() <= REFIT_MAX_COST * self.built_cost).then_some(bvh)
    }

    /// Recomputes the box of node `i` and its subtree from the triangles (f64 boxes rounded
    /// outwards, as the build does: rounding is monotone, so an unchanged subtree gets its
    /// box back bit for bit).
    fn refit_node(&mut self, i: usize) -> (DVec3, DVec3) {
        let n = self.nodes[i];
        let (lo, hi) = if n.count > 0 {
            self.tris[n.start as usize..(n.start + n.count) as usize]
                .iter()
                .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), t| {
                    (
                        lo.min(t.v0).min(t.v1).min(t.v2),
                        hi.max(t.v0).max(t.v1).max(t.v2),
                    )
                })
        } else {
            let a = self.refit_node(n.start as usize);
            let b = self.refit_node(n.start as usize + 1);
            (a.0.min(b.0), a.1.max(b.1))
        };
        self.nodes[i] = Node::new(lo, hi, n.start, n.count);
        (lo, hi)
    }

    /// Number of (non-degenerate) triangles stored.
    pub fn triangle_count(&self) -> usize {
        self.tris.len()
    }

    /// Number of nodes (inner and leaves).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Box of everything (rounded outwards to f32), or `None` for an empty BVH.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        self.nodes
            .first()
            .map(|n| (n.bmin.as_dvec3(), n.bmax.as_dvec3()))
    }

    /// Unit Newell normal of a face (zero if it has no area). Panics if `object` or `face`
    /// is out of range for the scene the BVH was built from.
    pub fn face_normal(&self, object: u32, face: u32) -> DVec3 {
        self.face_normals[self.face_base[object as usize] + face as usize]
    }

    /// Closest hit with `t_min < t < t_max`. Ties in `t` (a ray through an edge shared by
    /// two faces) go to the smallest (object, face). Rays with a zero direction hit nothing.
    pub fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<Hit> {
        self.intersect_accept(ray, t_min, t_max, |_, _| true)
    }

    /// Closest hit among the triangles whose (object, face) `accept` returns true for (the
    /// others are transparent), with the tie rule of [`Bvh::intersect`]. `accept` is called
    /// only for triangles the ray hits.
    pub fn intersect_accept(
        &self,
        ray: &Ray,
        t_min: f64,
        t_max: f64,
        mut accept: impl FnMut(u32, u32) -> bool,
    ) -> Option<Hit> {
        if self.nodes.is_empty() {
            return None;
        }
        let tr = TraversalRay::new(ray, self.max_abs)?;
        let mut best: Option<(usize, RawHit)> = None;
        let mut best_t = t_max;
        let mut best_key = u64::MAX;
        self.traverse(&tr, t_min, t_max, |start, count, limit| {
            for i in start as usize..(start + count) as usize {
                let tri = &self.tris[i];
                let Some(raw) = tr.tri.intersect_raw(tri.v0, tri.v1, tri.v2) else {
                    continue;
                };
                if raw.t > t_min && raw.t <= best_t && accept(tri.object, tri.face) {
                    let key = tri.key();
                    if raw.t < best_t || (best.is_some() && key < best_key) {
                        best = Some((i, raw));
                        best_t = raw.t;
                        best_key = key;
                    }
                }
            }
            *limit = best_t;
            false
        });
        let (i, raw) = best?;
        let tri = &self.tris[i];
        let th = raw.finish();
        let mut n = self.face_normal(tri.object, tri.face);
        if n == DVec3::ZERO {
            // A face whose Newell normal vanishes (e.g. a self-overlapping polygon) still
            // has triangles with area: fall back to the triangle's own normal.
            n = (tri.v1 - tri.v0).cross(tri.v2 - tri.v0).normalize_or_zero();
        }
        Some(Hit {
            t: th.t,
            object: tri.object,
            face: tri.face,
            point: th.point(tri.v0, tri.v1, tri.v2),
            geometric_normal: n,
        })
    }

    /// True if the ray hits, with `t_min < t < t_max`, any triangle whose (object, face)
    /// `accept` returns true for. `accept` is called only for triangles the ray hits, and
    /// traversal stops at the first accepted one.
    pub fn occluded(
        &self,
        ray: &Ray,
        t_min: f64,
        t_max: f64,
        mut accept: impl FnMut(u32, u32) -> bool,
    ) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let Some(tr) = TraversalRay::new(ray, self.max_abs) else {
            return false;
        };
        let mut found = false;
        self.traverse(&tr, t_min, t_max, |start, count, _| {
            for tri in &self.tris[start as usize..(start + count) as usize] {
                if let Some(raw) = tr.tri.intersect_raw(tri.v0, tri.v1, tri.v2)
                    && raw.t > t_min
                    && raw.t < t_max
                    && accept(tri.object, tri.face)
                {
                    found = true;
                    return true;
                }
            }
            false
        });
        found
    }

    /// Visits the leaves the ray may reach within `[t_min, limit]`, nearest child first.
    /// `leaf(start, count, &mut limit)` may lower `limit` (closest hit) and returns true to
    /// stop (any hit).
    #[inline(always)]
    fn traverse(
        &self,
        tr: &TraversalRay,
        t_min: f64,
        t_max: f64,
        mut leaf: impl FnMut(u32, u32, &mut f64) -> bool,
    ) {
        let mut limit = t_max;
        if tr.box_entry(&self.nodes[0], t_min, limit).is_none() {
            return;
        }
        // Deferred subtrees and their entry distances. Left uninitialised: zeroing 1 KiB per
        // ray cost more than the traversal of a small scene, and only entries below `sp`,
        // each written before it is counted, are ever read.
        let mut stack = [const { MaybeUninit::<(u32, f64)>::uninit() }; STACK_SIZE];
        let mut sp = 0usize;
        let mut cur = 0usize;
        loop {
            let node = &self.nodes[cur];
            if node.count > 0 {
                if leaf(node.start, node.count, &mut limit) {
                    return;
                }
            } else {
                let l = node.start as usize;
                let [a, b] = tr.box_entries(&self.nodes[l..l + 2], t_min, limit);
                match (a < f64::INFINITY, b < f64::INFINITY) {
                    (true, true) => {
                        let (near, far, t_far) = if b < a { (l + 1, l, a) } else { (l, l + 1, b) };
                        stack[sp].write((far as u32, t_far));
                        sp += 1;
                        cur = near;
                        continue;
                    }
                    (true, false) => {
                        cur = l;
                        continue;
                    }
                    (false, true) => {
                        cur = l + 1;
                        continue;
                    }
                    (false, false) => {}
                }
            }
            // Pop the most recently deferred subtree that may still hold a hit.
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                // SAFETY: `stack[sp]` was written when `sp` was last raised past it.
                let (node, t_entry) = unsafe { stack[sp].assume_init() };
                if t_entry <= limit {
                    cur = node as usize;
                    break;
                }
            }
        }
    }
}
