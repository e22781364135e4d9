//! Quantitative invisibility in the exact silhouettes (`geometry::silhouettes::quantitative_invisibility`):
//! one ray per connected set of pieces, the count of faces carried from piece to piece, must
//! keep exactly the pieces one ray per piece keeps. Checked against two oracles that do not use
//! the propagation: the per-piece rays (the same silhouette bit for bit, on the bunny, a
//! displaced icosphere and the thesis polyhedra, at points around, near, far and just off
//! vertices; and in a light's window), and, piece by piece, the count of faces a ray through
//! the piece meets (scanning every face), which a wrong sign at a crossing or a vertex would
//! contradict.

use glam::DVec3;
use penumbra::geometry::IndexedPolyhedron;
use penumbra::geometry::{
    ExactSilhouetteScratch, SphericalPolygon, WindowScratch, count_ray_hits, exact_silhouette,
    exact_silhouette_in_window,
};
use penumbra::math::{Frame, Pcg32};
use penumbra::scene::thesis_polyhedra::TABLE_7_1;

use crate::silhouette_common;
use silhouette_common::{is_inside, polyhedron, triangles};

fn bunny() -> IndexedPolyhedron {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/meshes/bunny.obj");
    let scene = penumbra::scene::obj::load_obj(&path).expect("assets/meshes/bunny.obj");
    let m = &scene.objects[0].mesh;
    IndexedPolyhedron::new(&m.positions, &m.faces)
}

fn blob() -> IndexedPolyhedron {
    let m = penumbra::bench::realworld_scenes::displaced_icosphere(DVec3::ZERO, 1.0, 3, 0.15);
    IndexedPolyhedron::new(&m.positions, &m.faces)
}

/// The loops of `a` and `b`, vertex by vertex, bit for bit.
fn same_bits(a: &SphericalPolygon, b: &SphericalPolygon) -> bool {
    let bits = |p: &SphericalPolygon| -> Vec<Vec<[u64; 3]>> {
        p.loops()
            .map(|l| {
                l.iter()
                    .map(|v| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()])
                    .collect()
            })
            .collect()
    };
    bits(a) == bits(b)
}

/// Points outside `poly`: around it (1.05 to 4 radii), close to it (within a tenth of a radius
/// of its bounding sphere, and inside that sphere near vertices), far away (10 to 1000 radii),
/// and just off vertices (1e-6 to 1e-3 radii).
fn points(poly: &IndexedPolyhedron, n: usize, rng: &mut Pcg32) -> Vec<DVec3> {
    let tris = triangles(poly);
    let mut out = Vec::new();
    while out.len() < n {
        let k = out.len() % 5;
        let r = poly.radius;
        let x = match k {
            0 => poly.center + rng.unit_vector() * r * rng.range(1.05, 4.0),
            1 => poly.center + rng.unit_vector() * r * rng.range(1.0, 1.1),
            2 => poly.center + rng.unit_vector() * r * 10f64.powf(rng.range(1.0, 3.0)),
            3 => {
                let v = poly.vertices[rng.below(poly.vertices.len() as u32) as usize];
                v + rng.unit_vector() * r * 10f64.powf(rng.range(-6.0, -3.0))
            }
            _ => {
                let v = poly.vertices[rng.below(poly.vertices.len() as u32) as usize];
                v + rng.unit_vector() * r * rng.range(0.02, 0.2)
            }
        };
        if !is_inside(&tris, x) {
            out.push(x);
        }
    }
    out
}

/// What one mesh's comparison found.
#[derive(Default, Debug)]
struct Tally {
    points: u32,
    degenerate: u32,
    pieces: u32,
    rays_per_piece: u32,
    rays_qi: u32,
    components: u32,
    fallback_rays: u32,
    undecided_links: u32,
}

/// At every point: the QI silhouette equals the per-piece one bit for bit (and both fail
/// alike), with no call sent back to per-piece rays.
fn compare_exact(name: &str, poly: &IndexedPolyhedron, pts: &[DVec3]) -> Tally {
    let frame = Frame::from_z(DVec3::new(0.2, 0.9, -0.3).normalize());
    let mut qi = ExactSilhouetteScratch::default();
    qi.qi.measure = true;
    let mut per = ExactSilhouetteScratch::default();
    per.per_piece_rays = true;
    let (mut a, mut b) = (SphericalPolygon::new(), SphericalPolygon::new());
    let mut t = Tally::default();
    for (k, &x) in pts.iter().enumerate() {
        let ra = exact_silhouette(poly, x, &frame, &mut a, &mut qi);
        let rb = exact_silhouette(poly, x, &frame, &mut b, &mut per);
        assert_eq!(ra.is_ok(), rb.is_ok(), "{name}, point {k} {x}");
        assert!(same_bits(&a, &b), "{name}, point {k} {x}: QI differs");
        let (Ok(sa), Ok(sb)) = (ra, rb) else {
            t.degenerate += 1;
            continue;
        };
        assert_eq!(sa.kept, sb.kept);
        let s = qi.qi.stats;
        assert!(!s.whole_fallback, "{name}, point {k}: contradictory counts");
        t.points += 1;
        t.pieces += sa.pieces;
        t.rays_per_piece += sb.rays;
        t.rays_qi += sa.rays;
        t.components += s.components;
        t.fallback_rays += s.rays - s.components;
        t.undecided_links += s.undecided_links;
    }
    eprintln!("{name}: {t:?}");
    t
}

#[test]
fn qi_silhouettes_are_the_per_piece_ones_bit_for_bit() {
    let mut rng = Pcg32::new(31, 7);
    let bunny = bunny();
    let blob = blob();
    assert!(bunny.diagnostics.closed_manifold && blob.diagnostics.closed_manifold);
    let mut total = Tally::default();
    let mut add = |t: Tally| {
        total.points += t.points;
        total.pieces += t.pieces;
        total.rays_per_piece += t.rays_per_piece;
        total.rays_qi += t.rays_qi;
        total.components += t.components;
        total.fallback_rays += t.fallback_rays;
    };
    let pts = points(&bunny, 150, &mut rng);
    let t = compare_exact("bunny", &bunny, &pts);
    assert!(t.points >= 120, "{} points compared", t.points);
    // Far fewer rays than pieces on a mesh whose silhouette crosses itself.
    assert!(t.rays_qi * 4 < t.rays_per_piece, "{t:?}");
    add(t);
    let pts = points(&blob, 150, &mut rng);
    let t = compare_exact("blob", &blob, &pts);
    assert!(t.points >= 120, "{} points compared", t.points);
    add(t);
    for row in TABLE_7_1 {
        let poly = polyhedron(row.name);
        if !poly.diagnostics.closed_manifold {
            continue;
        }
        let pts = points(&poly, 100, &mut rng);
        add(compare_exact(row.name, &poly, &pts));
    }
    eprintln!("all: {total:?}");
    // The fallback (rays cast because a link was undecided, beyond one per connected set of
    // pieces). On the thesis polyhedra none is cast (measured: 0 of 1,200 points' pieces).
    // On the scanned bunny and the blob some links are left undecided (measured: 917 rays for
    // 93,954 pieces, about 1%, nearly all on the bunny's near and off-vertex points); each
    // such ray is still the exact per-piece test. The bound is twice that: a regression that
    // leaves many more links undecided (a tolerance too tight) fails it.
    assert!(
        total.fallback_rays * 50 <= total.pieces,
        "fallback rays {} for {} pieces",
        total.fallback_rays,
        total.pieces
    );
    assert!(total.rays_qi * 20 < total.rays_per_piece, "{total:?}");
}

/// The count carried to each piece is the count of faces (other than its edge's two) that a
/// ray through its midpoint meets, counted here by scanning every face: a wrong sign at a
/// crossing (±2) or a wrong vertex rule makes them differ at the pieces beyond it.
#[test]
fn propagated_counts_are_the_ray_counts_at_every_piece() {
    let mut rng = Pcg32::new(5, 11);
    let frame = Frame::from_z(DVec3::Z);
    let mut meshes = vec![("bunny", bunny()), ("blob", blob())];
    for row in TABLE_7_1 {
        let p = polyhedron(row.name);
        if p.diagnostics.closed_manifold {
            meshes.push((row.name, p));
        }
    }
    let mut out = SphericalPolygon::new();
    let (mut propagated, mut propagated_nonzero) = (0u32, 0u32);
    for (name, poly) in &meshes {
        let mut scratch = ExactSilhouetteScratch::default();
        for (k, x) in points(poly, 40, &mut rng).into_iter().enumerate() {
            if exact_silhouette(poly, x, &frame, &mut out, &mut scratch).is_err() {
                continue;
            }
            for (q, (mid, faces, c, from_ray)) in scratch.qi_counts().enumerate() {
                let ray = count_ray_hits(poly, x, mid, faces, true) as i32;
                assert_eq!(
                    c, ray,
                    "{name}, point {k}, piece {q} (from a ray: {from_ray})"
                );
                if !from_ray {
                    propagated += 1;
                    propagated_nonzero += u32::from(c > 0);
                }
            }
        }
    }
    // The comparison is not vacuous: most counts were carried, many of them not zero.
    assert!(
        propagated > 5000 && propagated_nonzero > 1000,
        "{propagated} carried counts, {propagated_nonzero} of them not zero"
    );
}

/// A quad light's corners seen from `x` as a positively oriented window in `frame`.
fn window(x: DVec3, centre: DVec3, u: DVec3, v: DVec3, frame: &Frame) -> Vec<DVec3> {
    let mut w: Vec<DVec3> = [-u - v, u - v, u + v, v - u]
        .iter()
        .map(|&c| frame.to_local((centre + c - x).normalize()))
        .collect();
    if w[0].cross(w[1]).dot(w[2]) < 0.0 {
        w.reverse();
    }
    w
}

/// The windowed silhouette under lights of several sizes over the bunny: QI and per-piece
/// rays give the same loops bit for bit, and the carried counts are the rays' counts.
#[test]
fn windowed_qi_silhouettes_are_the_per_piece_ones_bit_for_bit() {
    let poly = bunny();
    let lowest = poly
        .vertices
        .iter()
        .map(|p| p.y)
        .fold(f64::INFINITY, f64::min);
    let tris = triangles(&poly);
    let mut rng = Pcg32::new(8, 3);
    let mut qi = WindowScratch::default();
    qi.qi.measure = true;
    let mut per = WindowScratch::default();
    per.per_piece_rays = true;
    let (mut a, mut b) = (SphericalPolygon::new(), SphericalPolygon::new());
    let (mut ran, mut pieces, mut rays_qi, mut rays_per, mut fallback) = (0, 0, 0, 0, 0);
    for &size in &[0.1, 0.5, 1.0, 2.0, 4.0, 6.0] {
        let centre = DVec3::new(
            rng.range(-4.0, 4.0),
            lowest + rng.range(11.0, 16.0),
            rng.range(-4.0, 4.0),
        );
        let (u, v) = (DVec3::X * size, DVec3::Z * size * 0.7);
        for _ in 0..40 {
            let x = DVec3::new(rng.range(-9.0, 9.0), lowest - 1e-3, rng.range(-9.0, 9.0));
            let x = if rng.next_f64() < 0.3 {
                // Some points beside the bunny, level with it.
                x + DVec3::Y * rng.range(0.0, 8.0)
            } else {
                x
            };
            if is_inside(&tris, x) {
                continue;
            }
            let frame = Frame::from_z((centre - x).normalize());
            let w = window(x, centre, u, v, &frame);
            let ra = exact_silhouette_in_window(&poly, x, &frame, &w, false, &mut a, &mut qi).ok();
            let rb = exact_silhouette_in_window(&poly, x, &frame, &w, false, &mut b, &mut per).ok();
            assert_eq!(ra.is_some(), rb.is_some(), "at {x}, light {size}");
            assert!(same_bits(&a, &b), "at {x}, light {size}: QI differs");
            let (Some(sa), Some(sb)) = (ra, rb) else {
                continue;
            };
            ran += 1;
            pieces += sa.pieces;
            rays_qi += sa.rays;
            rays_per += sb.rays;
            let s = qi.qi.stats;
            assert!(!s.whole_fallback);
            fallback += s.rays - s.components;
            for (mid, faces, c, from_ray) in qi.qi_counts() {
                let ray = count_ray_hits(&poly, x, mid, faces, true) as i32;
                assert_eq!(c, ray, "at {x}, light {size} (from a ray: {from_ray})");
            }
        }
    }
    eprintln!(
        "windowed: {ran} points, {pieces} pieces, rays {rays_per} per piece, {rays_qi} QI, \
         fallback {fallback}"
    );
    assert!(ran >= 150, "the windowed path ran at {ran} points");
    assert!(
        rays_qi < rays_per,
        "{rays_qi} QI rays, {rays_per} per piece"
    );
    assert!(fallback * 1000 <= pieces, "fallback rays {fallback}");
}

/// The bunny with a cap cut off (every face with a vertex above `cut` of its height): an open
/// mesh with one long boundary loop.
fn cut_bunny(cut: f64) -> IndexedPolyhedron {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/meshes/bunny.obj");
    let scene = penumbra::scene::obj::load_obj(&path).expect("assets/meshes/bunny.obj");
    let m = &scene.objects[0].mesh;
    let (lo, hi) = m
        .positions
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.y), hi.max(p.y))
        });
    let limit = lo + cut * (hi - lo);
    let faces: Vec<Vec<u32>> = m
        .faces
        .iter()
        .filter(|f| f.iter().all(|&v| m.positions[v as usize].y <= limit))
        .cloned()
        .collect();
    IndexedPolyhedron::new(&m.positions, &faces)
}

/// Blender's monkey as Blender's OBJ exporter wrote it (tests/data/blender): open, with
/// eyes apart from the head. Its quads are bent by the file's rounding, so the exact paths
/// take their fan triangles (`shading::FanMesh`), as here.
fn suzanne() -> IndexedPolyhedron {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/blender/suzanne.obj");
    let scene = penumbra::scene::obj::load_obj(&path).expect("tests/data/blender/suzanne.obj");
    let m = &scene
        .objects
        .iter()
        .find(|o| o.name == "Suzanne")
        .expect("object Suzanne")
        .mesh;
    let fan: Vec<Vec<u32>> = m
        .faces
        .iter()
        .flat_map(|f| (1..f.len() - 1).map(move |k| vec![f[0], f[k], f[k + 1]]))
        .collect();
    IndexedPolyhedron::new(&m.positions, &fan)
}

/// Open meshes (docs/silhouettes.md, "Open meshes"): a boundary edge steps the count by one
/// face where a contour edge steps it by two. At points around and near the cut bunny and
/// Suzanne, the whole exact silhouette with QI equals the per-piece one bit for bit, and every
/// carried count is the scanned ray's.
#[test]
fn qi_on_open_meshes_is_the_per_piece_rays() {
    let mut rng = Pcg32::new(77, 5);
    let frame = Frame::from_z(DVec3::new(0.2, 0.9, -0.3).normalize());
    let (mut a, mut b) = (SphericalPolygon::new(), SphericalPolygon::new());
    let (mut carried, mut carried_boundary) = (0u32, 0u32);
    for (name, poly) in [("cut bunny", cut_bunny(0.7)), ("suzanne", suzanne())] {
        assert!(poly.diagnostics.boundary_edges > 0, "{name} is open");
        assert!(
            poly.index.vertex_stars.is_some(),
            "{name} has its vertex stars"
        );
        let mut qi = ExactSilhouetteScratch::default();
        qi.qi.measure = true;
        let mut per = ExactSilhouetteScratch::default();
        per.per_piece_rays = true;
        let (mut ran, mut rays_qi, mut rays_per) = (0u32, 0u32, 0u32);
        for k in 0..120 {
            let r = poly.radius;
            let x = match k % 3 {
                0 => poly.center + rng.unit_vector() * r * rng.range(1.05, 4.0),
                1 => poly.center + rng.unit_vector() * r * rng.range(0.3, 1.1),
                _ => {
                    let v = poly.vertices[rng.below(poly.vertices.len() as u32) as usize];
                    v + rng.unit_vector() * r * rng.range(0.02, 0.2)
                }
            };
            let ra = exact_silhouette(&poly, x, &frame, &mut a, &mut qi);
            let rb = exact_silhouette(&poly, x, &frame, &mut b, &mut per);
            assert_eq!(ra.is_ok(), rb.is_ok(), "{name}, point {k} {x}");
            assert!(same_bits(&a, &b), "{name}, point {k} {x}: QI differs");
            let (Ok(sa), Ok(sb)) = (ra, rb) else {
                continue;
            };
            assert!(
                !qi.qi.stats.whole_fallback,
                "{name}, point {k}: contradictory counts"
            );
            ran += 1;
            rays_qi += sa.rays;
            rays_per += sb.rays;
            for (q, (mid, faces, c, from_ray)) in qi.qi_counts().enumerate() {
                let ray = count_ray_hits(&poly, x, mid, faces, true) as i32;
                assert_eq!(
                    c, ray,
                    "{name}, point {k}, piece {q} (from a ray: {from_ray})"
                );
                if !from_ray {
                    carried += 1;
                    carried_boundary += u32::from(faces.contains(&penumbra::geometry::NO_FACE));
                }
            }
        }
        eprintln!("{name}: {ran} points, rays {rays_per} per piece, {rays_qi} QI");
        assert!(ran >= 100, "{name}: {ran} points");
        assert!(
            rays_qi * 4 < rays_per,
            "{name}: {rays_qi} QI rays, {rays_per} per piece"
        );
    }
    // Counts were carried onto boundary edges, not only between contour edges.
    assert!(
        carried > 5000 && carried_boundary > 200,
        "{carried} carried counts, {carried_boundary} on boundary edges"
    );
}

/// The windowed silhouette of Suzanne under quad lights, at points off the mesh and at points
/// on it (self-shadowing: the faces through the point are left out, and the edges next to
/// them count as boundary edges): QI gives the per-piece rays' loops bit for bit.
#[test]
fn windowed_qi_on_an_open_mesh_and_on_it_is_the_per_piece_rays() {
    let poly = suzanne();
    let mut rng = Pcg32::new(12, 9);
    let mut qi = WindowScratch::default();
    qi.qi.measure = true;
    let mut per = WindowScratch::default();
    per.per_piece_rays = true;
    let (mut a, mut b) = (SphericalPolygon::new(), SphericalPolygon::new());
    let (mut off, mut on, mut rays_qi, mut rays_per, mut kept_on) = (0, 0, 0, 0, 0);
    for k in 0..2000 {
        let on_mesh = k % 4 != 0;
        let (x, up) = if on_mesh {
            // A point inside a random face's first fan triangle, on either side of it.
            let f = rng.below(poly.face_count() as u32) as usize;
            let idx = poly.face(f);
            let (p0, p1, p2) = (
                poly.vertices[idx[0] as usize],
                poly.vertices[idx[1] as usize],
                poly.vertices[idx[2] as usize],
            );
            let (mut s, mut t) = (rng.next_f64(), rng.next_f64());
            if s + t > 1.0 {
                (s, t) = (1.0 - s, 1.0 - t);
            }
            let n = poly.face_planes[f].n.normalize();
            let side = if rng.next_f64() < 0.5 { 1.0 } else { -1.0 };
            (p0 + s * (p1 - p0) + t * (p2 - p0), n * side)
        } else {
            let x = poly.center + rng.unit_vector() * poly.radius * rng.range(1.0, 2.0);
            (x, (poly.center - x).normalize())
        };
        // A light 1 to 3 radii away, mostly far from `up` (where the mesh shadows itself).
        let dir = (up + rng.unit_vector() * 1.5).normalize();
        let centre = x + dir * poly.radius * rng.range(1.0, 3.0);
        let size = poly.radius * rng.range(0.05, 0.8);
        let frame = Frame::from_z(up);
        let u = dir.any_orthonormal_vector() * size;
        let v = dir.cross(u).normalize() * size * 0.7;
        let w = window(x, centre, u, v, &frame);
        let ra = exact_silhouette_in_window(&poly, x, &frame, &w, on_mesh, &mut a, &mut qi).ok();
        let rb = exact_silhouette_in_window(&poly, x, &frame, &w, on_mesh, &mut b, &mut per).ok();
        assert_eq!(ra.is_some(), rb.is_some(), "point {k} at {x}");
        assert!(
            same_bits(&a, &b),
            "point {k} at {x} (on the mesh: {on_mesh}): QI differs"
        );
        let (Some(sa), Some(sb)) = (ra, rb) else {
            continue;
        };
        assert!(
            !qi.qi.stats.whole_fallback,
            "point {k}: contradictory counts"
        );
        if on_mesh {
            on += 1;
            kept_on += u32::from(sa.kept > 0);
        } else {
            off += 1;
        }
        rays_qi += sa.rays;
        rays_per += sb.rays;
    }
    eprintln!(
        "windowed Suzanne: {off} points off it, {on} on it ({kept_on} with an outline), rays \
         {rays_per} per piece, {rays_qi} QI"
    );
    assert!(
        off >= 200 && on >= 150 && kept_on >= 30,
        "{off} off, {on} on, {kept_on}"
    );
    assert!(
        rays_qi * 2 < rays_per,
        "{rays_qi} QI rays, {rays_per} per piece"
    );
}
