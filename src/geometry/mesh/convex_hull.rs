//! The convex hull of a point set, with exact orientation tests (prepare time).
//!
//! Incremental construction with outside sets, as in Quickhull (Barber, Dobkin and Huhdanpaa
//! 1996): start from a tetrahedron, give every remaining point to a face it lies strictly
//! outside of, then repeatedly take a face's farthest outside point, remove the faces it sees
//! (a connected set, found from that face through its neighbours), and join the horizon edges
//! to the point. Every "sees" is [`orient3d`] with an exact sign, and a point only ever counts as
//! outside when strictly so: points on the hull's boundary (the cap of a cylinder, the faces of
//! a box) are left out as vertices, which changes nothing of the hull as a set, and no face is
//! ever degenerate. Triangles that are exactly coplanar with a neighbour are merged back into
//! one convex polygon, so that a box's hull has six quads and a cylinder's two n-gon caps.

use crate::geometry::mesh::exact_predicates::orient3d;
use glam::DVec3;
use std::collections::HashMap;

/// A convex polyhedron: its vertices (a subset of the input points) and its faces, convex
/// polygons counter-clockwise seen from outside.
#[derive(Clone, Debug, Default)]
pub(crate) struct ConvexHull {
    pub vertices: Vec<DVec3>,
    pub faces: Vec<Vec<u32>>,
    /// Index of each hull vertex in the input.
    pub source: Vec<u32>,
}

struct Face {
    v: [u32; 3],
    outside: Vec<u32>,
    alive: bool,
}

/// The hull of `points` (non-finite points are ignored); `None` when they span no volume.
pub(crate) fn convex_hull(points: &[DVec3]) -> Option<ConvexHull> {
    let ids: Vec<u32> = (0..points.len() as u32)
        .filter(|&i| points[i as usize].is_finite())
        .collect();
    let p = |i: u32| points[i as usize];
    let simplex = initial_simplex(points, &ids)?;
    let mut faces: Vec<Face> = Vec::new();
    let mut edge_face: HashMap<(u32, u32), usize> = HashMap::new();
    let add_face =
        |faces: &mut Vec<Face>, edge_face: &mut HashMap<(u32, u32), usize>, v: [u32; 3]| {
            let id = faces.len();
            for k in 0..3 {
                edge_face.insert((v[k], v[(k + 1) % 3]), id);
            }
            faces.push(Face {
                v,
                outside: Vec::new(),
                alive: true,
            });
            id
        };
    let [a, b, c, d] = simplex;
    for (tri, opposite) in [
        ([a, b, c], d),
        ([a, b, d], c),
        ([a, c, d], b),
        ([b, c, d], a),
    ] {
        // Outward: the fourth point lies strictly behind.
        let tri = if orient3d(p(tri[0]), p(tri[1]), p(tri[2]), p(opposite)) > 0.0 {
            [tri[0], tri[2], tri[1]]
        } else {
            tri
        };
        add_face(&mut faces, &mut edge_face, tri);
    }
    let sees = |f: &Face, q: u32| orient3d(p(f.v[0]), p(f.v[1]), p(f.v[2]), p(q)) > 0.0;
    let assign = |faces: &mut Vec<Face>, candidates: &[usize], q: u32| {
        if let Some(&f) = candidates.iter().find(|&&f| sees(&faces[f], q)) {
            faces[f].outside.push(q);
        }
    };
    for &q in &ids {
        if !simplex.contains(&q) {
            assign(&mut faces, &[0, 1, 2, 3], q);
        }
    }
    let mut stack: Vec<usize> = (0..4).collect();
    let mut visible: Vec<usize> = Vec::new();
    let mut horizon: Vec<(u32, u32)> = Vec::new();
    let mut orphans: Vec<u32> = Vec::new();
    // Bound: each pop either skips a dead or empty face or adds one input point as an apex
    // (its outside set shrinks): at most `points.len()` apexes, each making O(points) faces.
    while let Some(f) = stack.pop() {
        if !faces[f].alive || faces[f].outside.is_empty() {
            continue;
        }
        // The farthest outside point of the face (by the floating-point distance: any outside
        // point would do for correctness; the farthest keeps the hull's growth balanced).
        let fv = faces[f].v;
        let n = (p(fv[1]) - p(fv[0])).cross(p(fv[2]) - p(fv[0]));
        let apex = *faces[f]
            .outside
            .iter()
            .max_by(|&&x, &&y| {
                n.dot(p(x) - p(fv[0]))
                    .total_cmp(&n.dot(p(y) - p(fv[0])))
                    .then(y.cmp(&x))
            })
            .expect("non-empty");
        // The faces the apex sees: connected, grown from `f` through shared edges.
        visible.clear();
        visible.push(f);
        faces[f].alive = false;
        let mut k = 0;
        // Bound: a face enters `visible` once (marked dead as it does).
        while k < visible.len() {
            let g = visible[k];
            k += 1;
            let v = faces[g].v;
            for e in 0..3 {
                let twin = (v[(e + 1) % 3], v[e]);
                if let Some(&h) = edge_face.get(&twin)
                    && faces[h].alive
                    && sees(&faces[h], apex)
                {
                    faces[h].alive = false;
                    visible.push(h);
                }
            }
        }
        horizon.clear();
        orphans.clear();
        for &g in &visible {
            let v = faces[g].v;
            for e in 0..3 {
                let (x, y) = (v[e], v[(e + 1) % 3]);
                let across_alive = edge_face.get(&(y, x)).is_some_and(|&h| faces[h].alive);
                if across_alive {
                    horizon.push((x, y));
                }
            }
            orphans.extend(faces[g].outside.drain(..).filter(|&q| q != apex));
        }
        for &g in &visible {
            let v = faces[g].v;
            for e in 0..3 {
                let key = (v[e], v[(e + 1) % 3]);
                if edge_face.get(&key) == Some(&g) {
                    edge_face.remove(&key);
                }
            }
        }
        let first_new = faces.len();
        for &(x, y) in &horizon {
            add_face(&mut faces, &mut edge_face, [x, y, apex]);
        }
        let new_faces: Vec<usize> = (first_new..faces.len()).collect();
        for &q in &orphans {
            assign(&mut faces, &new_faces, q);
        }
        stack.extend(new_faces);
    }
    Some(merge_coplanar(points, &faces, &edge_face))
}

/// Four input points spanning a tetrahedron: the extremes along x, then the farthest from the
/// first, from their line and from their plane (by floating point), checked exactly.
fn initial_simplex(points: &[DVec3], ids: &[u32]) -> Option<[u32; 4]> {
    let p = |i: u32| points[i as usize];
    let argmax = |f: &dyn Fn(DVec3) -> f64| {
        ids.iter()
            .copied()
            .max_by(|&a, &b| f(p(a)).total_cmp(&f(p(b))).then(b.cmp(&a)))
    };
    let a = argmax(&|v| -v.x)?;
    let b = argmax(&|v| v.distance_squared(p(a)))?;
    let u = p(b) - p(a);
    let c = argmax(&|v| u.cross(v - p(a)).length_squared())?;
    let n = u.cross(p(c) - p(a));
    let d = argmax(&|v| n.dot(v - p(a)).abs())?;
    if orient3d(p(a), p(b), p(c), p(d)) != 0.0 {
        return Some([a, b, c, d]);
    }
    // Floating point found no volume: a tetrahedron exists only if some point is exactly off
    // the plane of a, b, c (and a, b, c not collinear).
    ids.iter()
        .copied()
        .find(|&q| orient3d(p(a), p(b), p(c), p(q)) != 0.0)
        .map(|q| [a, b, c, q])
}

/// Merges the live triangles into maximal exactly coplanar regions (each a convex polygon)
/// and renumbers the vertices to the ones the hull uses.
fn merge_coplanar(
    points: &[DVec3],
    faces: &[Face],
    edge_face: &HashMap<(u32, u32), usize>,
) -> ConvexHull {
    let p = |i: u32| points[i as usize];
    let live: Vec<usize> = (0..faces.len()).filter(|&f| faces[f].alive).collect();
    let mut group: HashMap<usize, usize> = live.iter().map(|&f| (f, f)).collect();
    fn root(group: &mut HashMap<usize, usize>, mut f: usize) -> usize {
        // Bound: a parent has a smaller face index than its child (below): `f` steps at most.
        while group[&f] != f {
            let up = group[&group[&f]];
            group.insert(f, up);
            f = up;
        }
        f
    }
    for &f in &live {
        let v = faces[f].v;
        for e in 0..3 {
            let Some(&g) = edge_face.get(&(v[(e + 1) % 3], v[e])) else {
                continue;
            };
            let w = faces[g].v;
            let opposite = w
                .into_iter()
                .find(|&x| x != v[e] && x != v[(e + 1) % 3])
                .expect("a triangle has a third vertex");
            if orient3d(p(v[0]), p(v[1]), p(v[2]), p(opposite)) == 0.0 {
                let (rf, rg) = (root(&mut group, f), root(&mut group, g));
                if rf != rg {
                    group.insert(rf.max(rg), rf.min(rg));
                }
            }
        }
    }
    // Boundary of each group: its directed edges whose twin lies in another group, chained.
    let mut members: Vec<(usize, usize)> = live.iter().map(|&f| (root(&mut group, f), f)).collect();
    members.sort_unstable();
    let mut remap: HashMap<u32, u32> = HashMap::new();
    let mut hull = ConvexHull::default();
    let mut start = 0;
    // Bound: `start` moves past one group per round.
    while start < members.len() {
        let r = members[start].0;
        let end = start + members[start..].iter().take_while(|m| m.0 == r).count();
        let mut next: HashMap<u32, u32> = HashMap::new();
        for &(_, f) in &members[start..end] {
            let v = faces[f].v;
            for e in 0..3 {
                let (x, y) = (v[e], v[(e + 1) % 3]);
                let twin_group = edge_face.get(&(y, x)).map(|&g| root(&mut group, g));
                if twin_group != Some(r) {
                    next.insert(x, y);
                }
            }
        }
        let first = *next.keys().min().expect("a region has a boundary");
        let mut face = Vec::with_capacity(next.len());
        let mut x = first;
        loop {
            let id = *remap.entry(x).or_insert_with(|| {
                hull.vertices.push(p(x));
                hull.source.push(x);
                (hull.vertices.len() - 1) as u32
            });
            face.push(id);
            x = next[&x];
            if x == first || face.len() > next.len() {
                break;
            }
        }
        hull.faces.push(face);
        start = end;
    }
    hull
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Pcg32;

    /// Every input point on or behind every face plane (exactly), every face used the right
    /// way round (Euler characteristic 2 of a closed surface).
    fn check_hull(points: &[DVec3], hull: &ConvexHull) {
        for f in &hull.faces {
            let [a, b, c] = [0, 1, 2].map(|k| hull.vertices[f[k] as usize]);
            for &q in points {
                assert!(orient3d(a, b, c, q) <= 0.0, "a point outside a face");
            }
            for &v in f {
                assert_eq!(orient3d(a, b, c, hull.vertices[v as usize]), 0.0);
            }
        }
        let edges: usize = hull.faces.iter().map(Vec::len).sum::<usize>() / 2;
        assert_eq!(hull.vertices.len() + hull.faces.len(), edges + 2);
    }

    #[test]
    fn hull_of_a_cube_grid_has_six_quads() {
        // 27 points of a 3x3x3 grid: only the 8 corners are vertices; faces are coplanar with
        // grid points on them.
        let mut pts = Vec::new();
        for i in 0..27 {
            pts.push(DVec3::new((i % 3) as f64, ((i / 3) % 3) as f64, (i / 9) as f64) * 0.1);
        }
        let h = convex_hull(&pts).unwrap();
        check_hull(&pts, &h);
        assert_eq!(h.faces.len(), 6);
        assert!(h.faces.iter().all(|f| f.len() == 4));
        assert_eq!(h.vertices.len(), 8);
    }

    #[test]
    fn random_clouds_and_spheres() {
        let mut rng = Pcg32::new(3, 5);
        for n in [4usize, 5, 10, 50, 300] {
            let pts: Vec<DVec3> = (0..n)
                .map(|_| DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * 2.0 - 1.0)
                .collect();
            let h = convex_hull(&pts).unwrap();
            check_hull(&pts, &h);
            // Points on a sphere are all vertices.
            let sphere: Vec<DVec3> = pts.iter().map(|p| p.normalize()).collect();
            let h = convex_hull(&sphere).unwrap();
            check_hull(&sphere, &h);
            assert_eq!(h.vertices.len(), n);
        }
    }

    #[test]
    fn flat_and_collinear_inputs_have_no_hull() {
        let flat: Vec<DVec3> = (0..10)
            .map(|i| DVec3::new(i as f64 * 0.3, (i * i) as f64 * 0.1, 2.0))
            .collect();
        assert!(convex_hull(&flat).is_none());
        assert!(convex_hull(&[DVec3::ZERO, DVec3::X, DVec3::X * 2.0, DVec3::X * 3.0]).is_none());
        assert!(convex_hull(&[]).is_none());
    }
}
