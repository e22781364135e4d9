//! Scenes written the way exporters write them: Blender's OBJ exporter (`%.6f`, quads of a
//! UV sphere and cylinder planar only up to those six decimals) and `%.9g` writers (nine
//! significant digits, trailing zeros stripped). Faces planar before rounding give no warning;
//! a face bent well beyond the rounding gives one warning for its object, naming its line, the
//! count and the worst deviation.

use glam::DVec3;
use penumbra::scene::obj::load_obj_str;
use std::f64::consts::{PI, TAU};
use std::fmt::Write;

/// Blender's `%.6f`.
fn fixed6(v: f64) -> String {
    format!("{v:.6}")
}

/// `%.9g` for the magnitudes used here: nine significant digits, trailing zeros stripped.
fn sig9(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let decimals = (8 - v.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        s
    };
    if s == "-0" { "0".into() } else { s }
}

/// A UV sphere (`segments` × `rings`, quads and pole triangles), a capped cylinder of
/// `segments` sides (n-gon caps) and a cube, as one OBJ file; faces counter-clockwise from
/// outside. Returns the text and, per face, its line number.
fn blender_primitives(segments: usize, rings: usize, fmt: fn(f64) -> String) -> (String, usize) {
    let mut obj = String::from("# exporter-style primitives\n");
    let mut lines = 1;
    let mut v_count = 0;
    let mut vertex = |obj: &mut String, p: DVec3, lines: &mut usize| {
        writeln!(obj, "v {} {} {}", fmt(p.x), fmt(p.y), fmt(p.z)).unwrap();
        *lines += 1;
        v_count += 1;
        v_count
    };
    let face = |obj: &mut String, f: &[usize], lines: &mut usize| {
        let s: Vec<String> = f.iter().map(|i| i.to_string()).collect();
        writeln!(obj, "f {}", s.join(" ")).unwrap();
        *lines += 1;
        *lines
    };
    // UV sphere of radius 1.3 at (0.4, 1.1, -0.2).
    obj += "o Sphere\n";
    lines += 1;
    let c = DVec3::new(0.4, 1.1, -0.2);
    let top = vertex(&mut obj, c + DVec3::Z * 1.3, &mut lines);
    let mut ring_ids = Vec::new();
    for r in 1..rings {
        let th = PI * r as f64 / rings as f64;
        let ids: Vec<usize> = (0..segments)
            .map(|s| {
                let ph = TAU * s as f64 / segments as f64;
                let d = DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
                vertex(&mut obj, c + d * 1.3, &mut lines)
            })
            .collect();
        ring_ids.push(ids);
    }
    let bottom = vertex(&mut obj, c - DVec3::Z * 1.3, &mut lines);
    let mut first_quad_line = 0;
    for s in 0..segments {
        let t = (s + 1) % segments;
        face(&mut obj, &[top, ring_ids[0][s], ring_ids[0][t]], &mut lines);
        for r in 0..rings - 2 {
            let (a, b) = (&ring_ids[r], &ring_ids[r + 1]);
            let l = face(&mut obj, &[a[s], b[s], b[t], a[t]], &mut lines);
            if first_quad_line == 0 {
                first_quad_line = l;
            }
        }
        let last = &ring_ids[rings - 2];
        face(&mut obj, &[bottom, last[t], last[s]], &mut lines);
    }
    // Cylinder of radius 0.6, height 2, axis along z, at (-2.1, 0.3, 0.5).
    obj += "o Cylinder\n";
    lines += 1;
    let c = DVec3::new(-2.1, 0.3, 0.5);
    let mut ring = |z: f64, obj: &mut String, lines: &mut usize| -> Vec<usize> {
        (0..segments)
            .map(|s| {
                let ph = TAU * s as f64 / segments as f64;
                vertex(
                    obj,
                    c + DVec3::new(0.6 * ph.cos(), 0.6 * ph.sin(), z),
                    lines,
                )
            })
            .collect()
    };
    let lo = ring(-1.0, &mut obj, &mut lines);
    let hi = ring(1.0, &mut obj, &mut lines);
    for s in 0..segments {
        let t = (s + 1) % segments;
        face(&mut obj, &[lo[s], lo[t], hi[t], hi[s]], &mut lines);
    }
    let top_cap: Vec<usize> = hi.clone();
    let bottom_cap: Vec<usize> = lo.iter().rev().copied().collect();
    face(&mut obj, &top_cap, &mut lines);
    face(&mut obj, &bottom_cap, &mut lines);
    // A cube, turned.
    obj += "o Cube\n";
    lines += 1;
    let (sn, cs) = (0.3f64.sin(), 0.3f64.cos());
    let ids: Vec<usize> = (0..8)
        .map(|i| {
            let p = DVec3::new(
                if i & 1 == 0 { -0.5 } else { 0.5 },
                if i & 2 == 0 { -0.5 } else { 0.5 },
                if i & 4 == 0 { -0.5 } else { 0.5 },
            );
            let p = DVec3::new(cs * p.x - sn * p.y, sn * p.x + cs * p.y, p.z);
            vertex(&mut obj, p + DVec3::new(2.0, -1.0, 0.5), &mut lines)
        })
        .collect();
    for f in [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ] {
        let f: Vec<usize> = f.iter().map(|&k| ids[k]).collect();
        face(&mut obj, &f, &mut lines);
    }
    (obj, first_quad_line)
}

fn non_planar_warnings(w: &[String]) -> Vec<&String> {
    w.iter().filter(|x| x.contains("not planar")).collect()
}

#[test]
fn exporter_rounding_is_no_warning() {
    for (fmt, name) in [(fixed6 as fn(f64) -> String, "%.6f"), (sig9, "%.9g")] {
        for (segments, rings) in [(32, 16), (64, 32)] {
            let (obj, _) = blender_primitives(segments, rings, fmt);
            let s = load_obj_str(&obj, None, "blender.obj").unwrap();
            assert_eq!(s.objects.len(), 3);
            // The only warning is the missing MTL (no `mtllib`, none supplied): nothing of the
            // geometry.
            assert!(
                s.warnings
                    .iter()
                    .all(|w| !w.contains("planar") && !w.contains("convex")),
                "{name} {segments}x{rings}: {:?}",
                s.warnings
            );
            // The rounding each mesh carries is the written precision's.
            let sphere = &s.objects[0].mesh;
            let expected = if name == "%.6f" {
                3f64.sqrt() * 5e-7
            } else {
                3f64.sqrt() * 5e-9
            };
            assert!(
                sphere.rounding > 0.3 * expected && sphere.rounding <= expected * 1.0001,
                "{name}: rounding {} against {expected}",
                sphere.rounding
            );
        }
    }
    // The same quads are not planar to the old fixed 1e-6 relative test's digits in f64: the
    // rounding really is there to be explained.
    let (obj, _) = blender_primitives(32, 16, fixed6);
    let s = load_obj_str(&obj, None, "blender.obj").unwrap();
    let m = &s.objects[0].mesh;
    let worst = m
        .faces
        .iter()
        .filter(|f| f.len() == 4)
        .map(|f| {
            let p: Vec<DVec3> = f.iter().map(|&i| m.positions[i as usize]).collect();
            penumbra::scene::precision::plane_deviation(&p)
        })
        .fold(0.0, f64::max);
    assert!(worst > 1e-8, "worst quad deviation {worst:e}");
}

#[test]
fn a_face_bent_beyond_the_rounding_is_one_grouped_warning() {
    let (obj, quad_line) = blender_primitives(32, 16, fixed6);
    // Lift the first vertex of the first sphere quad by 1e-3 in z (a thousand times the
    // rounding): the two quads and the two pole triangles around it move; triangles stay planar.
    let face_line = obj.lines().nth(quad_line - 1).unwrap().to_owned();
    let first: usize = face_line
        .split_whitespace()
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    let mut lines: Vec<String> = obj.lines().map(str::to_owned).collect();
    let vline = lines
        .iter()
        .enumerate()
        .filter(|(_, l)| l.starts_with("v "))
        .nth(first - 1)
        .unwrap()
        .0;
    let xyz: Vec<f64> = lines[vline]
        .split_whitespace()
        .skip(1)
        .map(|t| t.parse().unwrap())
        .collect();
    lines[vline] = format!("v {:.6} {:.6} {:.6}", xyz[0], xyz[1], xyz[2] + 1e-3);
    let bent = lines.join("\n");
    let s = load_obj_str(&bent, None, "blender.obj").unwrap();
    let w = non_planar_warnings(&s.warnings);
    assert_eq!(w.len(), 1, "{:?}", s.warnings);
    let w = w[0];
    // The vertex is shared by the quads on both sides of it in its ring.
    assert!(w.contains("object 'Sphere': 2 faces are not planar"), "{w}");
    assert!(w.contains("6 decimals"), "{w}");
    assert!(w.starts_with("blender.obj:"), "{w}");
    let at: usize = w["blender.obj:".len()..]
        .split(':')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let face_at = &lines[at - 1];
    assert!(
        face_at.starts_with("f ")
            && face_at
                .split_whitespace()
                .any(|t| t.parse::<usize>() == Ok(first)),
        "the warning's line {at} is a face with the moved vertex: {face_at}"
    );
}

/// An L-shaped prism whose caps are written as hexagons starting at the reflex-side corner
/// (2, 1): a fan from there folds over the notch. The loader triangulates each cap inside
/// itself; the oracle is ray casting: vertical rays through the notch meet nothing, rays
/// through the L meet both caps.
#[test]
fn a_non_convex_cap_is_triangulated_inside_itself() {
    use penumbra::accel::{Bvh, Ray};
    let outline = [
        (2.0, 1.0),
        (1.0, 1.0),
        (1.0, 3.0),
        (0.0, 3.0),
        (0.0, 0.0),
        (2.0, 0.0),
    ];
    let mut obj = String::from("o L\n");
    for z in [0.0, 1.0] {
        for (x, y) in outline {
            obj += &format!("v {x:.6} {y:.6} {z:.6}\n");
        }
    }
    // Bottom cap seen from below (clockwise from above), top cap counter-clockwise, sides.
    obj += "f 6 5 4 3 2 1\nf 7 8 9 10 11 12\n";
    for k in 0..6 {
        let (a, b) = (k + 1, (k + 1) % 6 + 1);
        obj += &format!("f {a} {b} {} {}\n", b + 6, a + 6);
    }
    let s = load_obj_str(&obj, None, "l.obj").unwrap();
    let w: Vec<&String> = s
        .warnings
        .iter()
        .filter(|w| w.contains("triangulated inside itself"))
        .collect();
    assert_eq!(w.len(), 1, "{:?}", s.warnings);
    assert!(
        w[0].starts_with("l.obj:14: object 'L': 2 faces are not convex"),
        "{}",
        w[0]
    );
    let m = &s.objects[0].mesh;
    assert_eq!(
        m.faces.len(),
        2 * 4 + 6,
        "two caps of 4 triangles, six sides"
    );
    let poly = penumbra::geometry::IndexedPolyhedron::new(&m.positions, &m.faces);
    assert!(poly.diagnostics.closed_manifold);
    let bvh = Bvh::build(&s);
    let hits = |x: f64, y: f64| {
        let mut n = 0;
        let mut t0 = 0.0;
        let ray = Ray {
            origin: DVec3::new(x, y, 5.0),
            dir: -DVec3::Z,
        };
        while let Some(h) = bvh.intersect(&ray, t0, f64::INFINITY) {
            n += 1;
            t0 = h.t + 1e-9;
        }
        n
    };
    for (x, y) in [(1.5, 1.5), (1.9, 2.9), (1.1, 1.1), (1.5, 2.5)] {
        assert_eq!(hits(x, y), 0, "through the notch at ({x}, {y})");
    }
    for (x, y) in [(0.5, 2.5), (1.5, 0.5), (0.2, 0.2), (0.9, 1.9)] {
        assert_eq!(hits(x, y), 2, "through the L at ({x}, {y})");
    }
}
