//! The nine test polyhedra of 001 Table 7.1 / Fig. 7.5: cube, cone, cylinder, icosahedron,
//! sphere, corner, extruded cube, hole and bowl.
//!
//! Table 7.1 counts *polygon* faces, some of which are non-convex (the corner's L-shaped caps)
//! or have holes (the rims of the hole and the bowl). penumbra's faces are convex polygons, so
//! such a face is built from convex pieces in its plane; `Polyhedron::feature_counts` merges
//! coplanar neighbours back and gives the table's vertex, edge and face counts (tested).
//!
//! Every shape fits in the cube [-0.5, 0.5]³ (the extruded cube in [-0.85, 0.85]³), is closed,
//! two-manifold and wound counter-clockwise seen from outside.

use super::Mesh;
use super::shapes::{cuboid, icosahedron, icosphere, l_shape, truncated_cone};
use glam::DVec3;

/// One row of 001 Table 7.1, with the shape that reproduces it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ThesisPolyhedron {
    pub name: &'static str,
    pub vertices: usize,
    pub edges: usize,
    pub faces: usize,
    pub convex: bool,
    pub star_shaped: bool,
}

/// 001 Table 7.1, in its order.
pub const TABLE_7_1: [ThesisPolyhedron; 9] = [
    row("cube", 8, 12, 6, true, true),
    row("cone", 13, 24, 13, true, true),
    row("cylinder", 24, 36, 14, true, true),
    row("icosahedron", 12, 30, 20, true, true),
    row("sphere", 42, 120, 80, true, true),
    row("corner", 12, 18, 8, false, true),
    row("extruded_cube", 32, 60, 30, false, true),
    row("hole", 16, 24, 10, false, false),
    row("bowl", 16, 24, 11, false, false),
];

const fn row(
    name: &'static str,
    vertices: usize,
    edges: usize,
    faces: usize,
    convex: bool,
    star_shaped: bool,
) -> ThesisPolyhedron {
    ThesisPolyhedron {
        name,
        vertices,
        edges,
        faces,
        convex,
        star_shaped,
    }
}

/// The mesh of a Table 7.1 polyhedron by name (`None` for other names).
pub fn thesis_polyhedron(name: &str) -> Option<Mesh> {
    let c = DVec3::ZERO;
    Some(match name {
        "cube" => cuboid(c, DVec3::splat(0.5)),
        // A 12-gon base and an apex: 12 + 1 vertices, 12 triangles and the base.
        "cone" => truncated_cone(c, 0.5, 0.0, 1.0, 12),
        "cylinder" => truncated_cone(c, 0.5, 0.5, 1.0, 12),
        "icosahedron" => icosahedron(c, 0.5),
        // The icosahedron subdivided once: 42 vertices, 80 triangles.
        "sphere" => icosphere(c, 0.5, 1),
        // An L-shaped prism: star-shaped (its kernel is the square where the legs meet).
        "corner" => l_shape(c, 1.0, 1.0, 0.4, 1.0),
        "extruded_cube" => extruded_cube(0.5, 0.3, 0.35),
        "hole" => holed_cube(0.5, 0.2, None),
        "bowl" => holed_cube(0.5, 0.3, Some(0.6)),
        _ => return None,
    })
}

/// A cube of half-size `h` with a tapered block on each face: the block's outer square has
/// half-size `s` and stands `e` out of the face, and its four sides run from the cube's edges
/// to that square. With `e > h − s` the cube's edges become valleys (non-convex), yet the centre
/// still sees every face (star-shaped): 8 + 6·4 vertices, 12 + 6·8 edges, 6·5 faces.
fn extruded_cube(h: f64, s: f64, e: f64) -> Mesh {
    let cube = cuboid(DVec3::ZERO, DVec3::splat(h));
    let mut positions = cube.positions.clone();
    let mut faces = Vec::new();
    for face in &cube.faces {
        let corners: Vec<DVec3> = face.iter().map(|&i| positions[i as usize]).collect();
        let centre = corners.iter().sum::<DVec3>() / 4.0;
        let n = centre.normalize();
        let base = positions.len() as u32;
        for p in &corners {
            positions.push(centre + n * e + (*p - centre) * (s / h));
        }
        // Outer square, same winding as the cube face.
        faces.push((0..4).map(|k| base + k).collect());
        for k in 0..4u32 {
            let j = (k + 1) % 4;
            faces.push(vec![face[k as usize], face[j as usize], base + j, base + k]);
        }
    }
    Mesh {
        positions,
        faces,
        rounding: 0.0,
    }
}

/// A cube of half-size `h` with a square shaft of half-size `r` along y: through the whole
/// cube (`depth == None`, genus one: "hole") or `depth` deep from the top ("bowl"). The top
/// (and, for the hole, the bottom) face is a square with a square hole, built from four convex
/// trapezoids.
fn holed_cube(h: f64, r: f64, depth: Option<f64>) -> Mesh {
    let mut positions = Vec::new();
    let mut p = |x: f64, y: f64, z: f64| {
        positions.push(DVec3::new(x, y, z));
        (positions.len() - 1) as u32
    };
    // Outer and inner squares, counter-clockwise seen from +y: (x, z) = (-,+), (+,+), (+,-), (-,-).
    let square = [(-1.0, 1.0), (1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)];
    let ring = |p: &mut dyn FnMut(f64, f64, f64) -> u32, half: f64, y: f64| -> [u32; 4] {
        square.map(|(sx, sz)| p(sx * half, y, sz * half))
    };
    let outer_top = ring(&mut p, h, h);
    let outer_bottom = ring(&mut p, h, -h);
    let inner_top = ring(&mut p, r, h);
    let shaft_bottom_y = depth.map_or(-h, |d| h - d);
    let inner_bottom = ring(&mut p, r, shaft_bottom_y);
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for k in 0..4 {
        let j = (k + 1) % 4;
        // Outer side walls, facing outward.
        faces.push(vec![
            outer_top[j],
            outer_top[k],
            outer_bottom[k],
            outer_bottom[j],
        ]);
        // The top rim piece between the outer and the inner square (faces +y).
        faces.push(vec![outer_top[k], outer_top[j], inner_top[j], inner_top[k]]);
        // Shaft walls, facing into the shaft.
        faces.push(vec![
            inner_top[k],
            inner_top[j],
            inner_bottom[j],
            inner_bottom[k],
        ]);
        if depth.is_none() {
            // The bottom rim piece (faces −y).
            faces.push(vec![
                outer_bottom[j],
                outer_bottom[k],
                inner_bottom[k],
                inner_bottom[j],
            ]);
        }
    }
    if depth.is_some() {
        // Bottom of the outer cube and floor of the pit (faces +y).
        faces.push(outer_bottom.iter().rev().copied().collect());
        faces.push(inner_bottom.to_vec());
    }
    Mesh {
        positions,
        faces,
        rounding: 0.0,
    }
}
