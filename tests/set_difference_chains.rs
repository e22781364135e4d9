//! Realistic chains of subtractions, as the renderer produces them: a quad light minus the
//! silhouettes of several convex solids (boxes, prisms, icosahedra) seen from the shading point,
//! one after another, so that the subject becomes non-convex, with holes and many vertices.
//!
//! The solids are built like furniture: boxes in a common frame, placed next to each other with
//! gaps from 1e-1 down to 1e-6 of their size (or none: shared faces, edges and vertices), with
//! faces in common planes (collinear silhouette edges), some slightly rotated (nearly collinear
//! edges), some resting on the floor that contains the shading point (silhouette vertices exactly
//! on the horizon) or crossing the tangent plane (cut by the horizon).
//!
//! Every step is checked against independent oracles:
//!
//! * area: the light minus the occluders so far, as a disjoint union of convex pieces (each
//!   convex piece minus a convex occluder is the union of piece ∩ H₁ ∩ … ∩ Hᵢ₋₁ ∩ outside(Hᵢ)
//!   over the occluder's edge half-spaces, by Sutherland–Hodgman on the sphere); the error may
//!   accumulate over the chain by (`EPS_LINE` + `EPS_POINT` + `COLLAPSE_RADIUS` / 2) × the
//!   perimeters of the operands per step (what snapping to the tolerances can move);
//! * membership: at random points (uniform over the light, and clustered around the vertices at
//!   every scale down to 1e-8 rad, where the gaps are) away from every boundary, the winding number
//!   of the result (sum of angles on the sphere) must be 0 or 1 and agree with
//!   "in the light and in no occluder";
//! * validity: finite, w ≥ 0, at least three vertices per loop, no zero-length edge, and
//!   `last_traversal_consistent()` (the labels agreed everywhere, every loop closed).
//!
//! `chains_match_oracles` runs 10⁴ chains; `chains_match_oracles_stress` (ignored) runs
//! `PENUMBRA_CHAINS` chains (10⁶ by default) on every core and reports the failures by kind:
//! `PENUMBRA_CHAINS=1000000 cargo test --release --test suite set_difference_chains:: -- --ignored
//! --nocapture`. `PENUMBRA_CHAIN=i` replays chain i alone and prints it.

use crate::set_difference_common;
use set_difference_common::*;

use glam::DVec3;
use penumbra::geometry::{COLLAPSE_RADIUS, EPS_LINE, EPS_POINT};
use penumbra::geometry::{GreinerHormannSteps, PlanarPolygon, SetDifference, SphericalPolygon};
use penumbra::math::{Frame, Pcg32};
use std::f64::consts::TAU;

const SEED: u64 = 0x05e7_d1ff;

// ---------------------------------------------------------------------------------------------
// Scenes

/// The frame of the furniture, in the shading frame (the shading point at the origin, its
/// normal +z): positions are `origin + x·ex + y·ey + z·ez`.
struct Room {
    origin: DVec3,
    ex: DVec3,
    ey: DVec3,
    ez: DVec3,
}

impl Room {
    fn at(&self, x: f64, y: f64, z: f64) -> DVec3 {
        self.origin + self.ex * x + self.ey * y + self.ez * z
    }
}

/// An axis-aligned box of the room, `lo..hi` per axis, possibly rotated a little about an axis.
#[derive(Clone, Copy, Debug)]
struct Block {
    lo: [f64; 3],
    hi: [f64; 3],
}

/// 10^u for u uniform in [a, b).
fn log_uniform(rng: &mut Pcg32, a: f64, b: f64) -> f64 {
    10f64.powf(rng.range(a, b))
}

/// A gap between neighbouring solids relative to their size: none (shared faces), 1e-1 … 1e-6,
/// or a small interpenetration.
fn relative_gap(rng: &mut Pcg32) -> f64 {
    match rng.below(8) {
        0 | 1 => 0.0,
        2 => -log_uniform(rng, -6.0, -1.0),
        _ => log_uniform(rng, -6.0, -1.0),
    }
}

/// The vertices of the solids of one scene: a box next to a previous one (sharing a face
/// plane across a gap, and often the extents on the other axes), a prism sharing planes with
/// it, an icosahedron sharing a vertex with it; some rotated by a tiny angle.
fn furniture(
    rng: &mut Pcg32,
    room: &Room,
    first: Block,
    size: f64,
    count: usize,
) -> Vec<Vec<DVec3>> {
    let mut blocks = vec![first];
    let mut solids = vec![block_vertices(room, &first, None)];
    while solids.len() < count {
        let parent = blocks[rng.below(blocks.len() as u32) as usize];
        let axis = rng.below(3) as usize;
        let upward = rng.below(2) == 0;
        let gap = relative_gap(rng) * size;
        let depth = size * rng.range(0.1, 1.0);
        let mut b = parent;
        if upward {
            b.lo[axis] = parent.hi[axis] + gap;
            b.hi[axis] = b.lo[axis] + depth;
        } else {
            b.hi[axis] = parent.lo[axis] - gap;
            b.lo[axis] = b.hi[axis] - depth;
        }
        for k in 0..3 {
            if k == axis {
                continue;
            }
            let extent = parent.hi[k] - parent.lo[k];
            match rng.below(5) {
                // Same extent: faces in common planes, edges on common lines.
                0 | 1 => {}
                // One side shared, the other anywhere.
                2 => {
                    if rng.below(2) == 0 {
                        b.hi[k] = b.lo[k] + extent * rng.range(0.1, 1.5);
                    } else {
                        b.lo[k] = b.hi[k] - extent * rng.range(0.1, 1.5);
                    }
                }
                // Shifted by a tiny amount.
                3 => {
                    let d = relative_gap(rng) * size;
                    b.lo[k] += d;
                    b.hi[k] += d;
                }
                _ => {
                    let c = rng.range(parent.lo[k], parent.hi[k]);
                    let e = extent * rng.range(0.05, 0.6);
                    b.lo[k] = c - e;
                    b.hi[k] = c + e;
                }
            }
        }
        // Keep resting on the floor what rested on it.
        if first.lo[2] == 0.0 && b.lo[2] < 0.0 {
            b.lo[2] = 0.0;
            if b.hi[2] <= 0.0 {
                b.hi[2] = depth;
            }
        }
        let shape = rng.below(10);
        let rotation = (rng.below(6) == 0).then(|| {
            let angle = log_uniform(rng, -9.0, -2.0) * if rng.below(2) == 0 { 1.0 } else { -1.0 };
            (rng.below(3) as usize, angle)
        });
        let vertices = match shape {
            0 | 1 => prism_vertices(rng, room, &b),
            2 => icosahedron_vertices(rng, room, &b, &parent),
            _ => block_vertices(room, &b, rotation),
        };
        blocks.push(b);
        solids.push(vertices);
    }
    solids
}

fn block_vertices(room: &Room, b: &Block, rotation: Option<(usize, f64)>) -> Vec<DVec3> {
    let mut v = Vec::with_capacity(8);
    for k in 0..8 {
        let mut p = [
            if k & 1 == 0 { b.lo[0] } else { b.hi[0] },
            if k & 2 == 0 { b.lo[1] } else { b.hi[1] },
            if k & 4 == 0 { b.lo[2] } else { b.hi[2] },
        ];
        if let Some((axis, angle)) = rotation {
            // About the axis through the box's low corner.
            let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
            let (u, w) = (p[i] - b.lo[i], p[j] - b.lo[j]);
            let (s, c) = angle.sin_cos();
            p[i] = b.lo[i] + c * u - s * w;
            p[j] = b.lo[j] + s * u + c * w;
        }
        v.push(room.at(p[0], p[1], p[2]));
    }
    v
}

/// A triangular prism in the box: a triangle in the plane of two axes extruded along the third,
/// its faces in the box's planes.
fn prism_vertices(rng: &mut Pcg32, room: &Room, b: &Block) -> Vec<DVec3> {
    let axis = rng.below(3) as usize;
    let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
    let apex = match rng.below(3) {
        0 => b.lo[i],
        1 => b.hi[i],
        _ => rng.range(b.lo[i], b.hi[i]),
    };
    let tri = [(b.lo[i], b.lo[j]), (b.hi[i], b.lo[j]), (apex, b.hi[j])];
    let mut v = Vec::with_capacity(6);
    for &e in &[b.lo[axis], b.hi[axis]] {
        for &(u, w) in &tri {
            let mut p = [0.0; 3];
            p[axis] = e;
            p[i] = u;
            p[j] = w;
            v.push(room.at(p[0], p[1], p[2]));
        }
    }
    v
}

/// A randomly rotated icosahedron inscribed in the box, one of its vertices moved exactly onto
/// a corner of the neighbouring box (a shared vertex).
fn icosahedron_vertices(rng: &mut Pcg32, room: &Room, b: &Block, parent: &Block) -> Vec<DVec3> {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let mut base = Vec::with_capacity(12);
    for s1 in [-1.0, 1.0] {
        for s2 in [-1.0, 1.0] {
            base.push([0.0, s1, s2 * phi]);
            base.push([s1, s2 * phi, 0.0]);
            base.push([s2 * phi, 0.0, s1]);
        }
    }
    let f = Frame::from_z(rng.unit_vector());
    let r = (0..3)
        .map(|k| b.hi[k] - b.lo[k])
        .fold(f64::INFINITY, f64::min)
        * 0.5;
    let c = [0, 1, 2].map(|k| 0.5 * (b.lo[k] + b.hi[k]));
    let norm = (1.0 + phi * phi).sqrt();
    let mut v: Vec<DVec3> = base
        .iter()
        .map(|q| {
            let d = f.to_world(DVec3::new(q[0], q[1], q[2])) * (r / norm);
            room.at(c[0] + d.x, c[1] + d.y, c[2] + d.z)
        })
        .collect();
    if rng.below(2) == 0 {
        // The corner of the parent nearest to the icosahedron replaces its nearest vertex.
        let corner = block_vertices(room, parent, None)
            .into_iter()
            .min_by(|p, q| {
                let cc = room.at(c[0], c[1], c[2]);
                p.distance(cc).total_cmp(&q.distance(cc))
            })
            .unwrap();
        let k = (0..v.len())
            .min_by(|&a, &b| v[a].distance(corner).total_cmp(&v[b].distance(corner)))
            .unwrap();
        v[k] = corner;
    }
    v
}

/// One chain: the light's region and the occluders' silhouettes, all convex, counter-clockwise,
/// horizon-clipped, unit vectors.
struct Chain {
    light: Vec<DVec3>,
    occluders: Vec<Vec<DVec3>>,
}

/// The silhouette of the convex hull of 3D points seen from the origin: the spherical convex
/// hull of their directions (monotone chain in the gnomonic plane of the mean direction, turns
/// by `orient`), clipped to the upper hemisphere. `None` when the points surround the origin
/// too closely or the silhouette is degenerate.
fn silhouette(points: &[DVec3]) -> Option<Vec<DVec3>> {
    let dirs: Vec<DVec3> = points.iter().map(|p| p.normalize()).collect();
    if dirs.iter().any(|d| !d.is_finite()) {
        return None;
    }
    let c = dirs.iter().copied().sum::<DVec3>().normalize();
    if !c.is_finite() || dirs.iter().any(|p| p.dot(c) < 0.05) {
        return None;
    }
    let f = Frame::from_z(c);
    let mut pts: Vec<(f64, f64, DVec3)> = dirs
        .iter()
        .map(|&p| {
            let l = f.to_local(p);
            (l.x / l.z, l.y / l.z, p)
        })
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    pts.dedup_by(|a, b| a.2 == b.2);
    if pts.len() < 3 {
        return None;
    }
    let mut hull: Vec<DVec3> = Vec::new();
    for pass in 0..2 {
        let start = hull.len();
        let order: Vec<DVec3> = if pass == 0 {
            pts.iter().map(|p| p.2).collect()
        } else {
            pts.iter().rev().map(|p| p.2).collect()
        };
        for p in order {
            while hull.len() >= start + 2
                && orient_near(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    let hull = horizon_clip(&hull);
    let k = hull.len();
    let valid = k >= 3
        && (0..k).all(|i| orient_near(hull[i], hull[(i + 1) % k], hull[(i + 2) % k]) > 0.0)
        && (0..k).all(|i| (i + 1..k).all(|j| hull[i].cross(hull[j]).length() >= 1e-13))
        && loop_area(&hull) > 1e-9;
    valid.then_some(hull)
}

fn loop_area(lp: &[DVec3]) -> f64 {
    if lp.len() < 3 {
        return 0.0;
    }
    let mut s = SphericalPolygon::new();
    s.push_loop(lp.iter().copied());
    s.signed_solid_angle_about(DVec3::Z)
}

fn perimeter<'a>(loops: impl IntoIterator<Item = &'a [DVec3]>) -> f64 {
    loops
        .into_iter()
        .map(|lp| {
            (0..lp.len())
                .map(|i| {
                    lp[i]
                        .normalize()
                        .angle_between(lp[(i + 1) % lp.len()].normalize())
                })
                .sum::<f64>()
        })
        .sum()
}

/// A random scene: a room frame (half the time the floor is the tangent plane of the shading
/// point, so that solids resting on it reach the horizon exactly), a quad light, and 2–6 solids
/// near the line of sight from the shading point to the light.
fn random_chain(rng: &mut Pcg32) -> Chain {
    loop {
        if let Some(chain) = try_chain(rng) {
            return chain;
        }
    }
}

fn try_chain(rng: &mut Pcg32) -> Option<Chain> {
    let on_floor = rng.below(2) == 0;
    let room = if on_floor {
        let a = rng.range(0.0, TAU);
        let (s, c) = a.sin_cos();
        Room {
            origin: DVec3::ZERO,
            ex: DVec3::new(c, s, 0.0),
            ey: DVec3::new(-s, c, 0.0),
            ez: DVec3::Z,
        }
    } else {
        let f = Frame::from_z(rng.unit_vector());
        Room {
            origin: DVec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            ),
            ex: f.x,
            ey: f.y,
            ez: f.z,
        }
    };
    // Shading point in room coordinates (the origin of the shading frame).
    let eye = {
        let o = -room.origin;
        DVec3::new(o.dot(room.ex), o.dot(room.ey), o.dot(room.ez))
    };
    // The light: a rectangle of the room, horizontal (ceiling) or vertical (wall).
    let size = rng.range(0.2, 1.5);
    let (lx, ly) = (eye.x + rng.range(-2.0, 2.0), eye.y + rng.range(-2.0, 2.0));
    let lz = eye.z + rng.range(0.3, 3.0) * if on_floor { 1.0 } else { rng.range(-1.0, 1.0) };
    let (w, d) = (size * rng.range(0.3, 1.0), size * rng.range(0.3, 1.0));
    let quad: Vec<DVec3> = match rng.below(3) {
        0 => vec![
            room.at(lx, ly - w, lz - d),
            room.at(lx, ly + w, lz - d),
            room.at(lx, ly + w, lz + d),
            room.at(lx, ly - w, lz + d),
        ],
        _ => vec![
            room.at(lx - w, ly - d, lz),
            room.at(lx + w, ly - d, lz),
            room.at(lx + w, ly + d, lz),
            room.at(lx - w, ly + d, lz),
        ],
    };
    let light = silhouette(&quad)?;
    if loop_area(&light) < 1e-4 {
        return None;
    }
    // The solids: near a point on the line of sight to a random point of the light.
    let target = {
        let q =
            quad[0] + (quad[1] - quad[0]) * rng.next_f64() + (quad[3] - quad[0]) * rng.next_f64();
        let q = q - room.origin;
        DVec3::new(q.dot(room.ex), q.dot(room.ey), q.dot(room.ez))
    };
    let t = rng.range(0.15, 0.85);
    let centre = eye + (target - eye) * t;
    let scale = (target - eye).length() * t;
    let s = scale * log_uniform(rng, -1.3, -0.3);
    let extent = |rng: &mut Pcg32| s * rng.range(0.1, 1.0);
    let mut first = Block {
        lo: [0.0; 3],
        hi: [0.0; 3],
    };
    for k in 0..3 {
        let e = extent(rng);
        first.lo[k] = centre[k] - e * rng.range(0.0, 1.0);
        first.hi[k] = first.lo[k] + e;
    }
    if on_floor && rng.below(2) == 0 {
        // Resting on the floor: its bottom face in the tangent plane.
        first.lo[2] = 0.0;
        first.hi[2] = first.hi[2].max(s * 0.2);
    }
    let count = 2 + rng.below(5) as usize;
    let solids = furniture(rng, &room, first, s, count);
    let mut occluders = Vec::with_capacity(count);
    for mut sol in solids {
        // Resting solids stay exactly on the floor.
        if on_floor {
            for p in &mut sol {
                if p.z.abs() < 1e-300 {
                    p.z = 0.0;
                }
            }
        }
        let Some(c) = silhouette(&sol) else { continue };
        occluders.push(c);
    }
    // Shuffle the order of subtraction.
    for i in (1..occluders.len()).rev() {
        let j = rng.below(i as u32 + 1) as usize;
        occluders.swap(i, j);
    }
    (occluders.len() >= 2).then_some(Chain { light, occluders })
}

// ---------------------------------------------------------------------------------------------
// Oracles

/// `pieces − clip` for convex pieces and a convex clip, as convex pieces.
fn subtract_convex(pieces: &[Vec<DVec3>], clip: &[DVec3]) -> Vec<Vec<DVec3>> {
    let k = clip.len();
    let normals: Vec<DVec3> = (0..k)
        .map(|i| line_normal(clip[i], clip[(i + 1) % k]))
        .collect();
    let mut out = Vec::new();
    for piece in pieces {
        // Entirely outside one edge line: untouched.
        if normals
            .iter()
            .any(|n| piece.iter().all(|p| n.dot(*p) <= 0.0))
        {
            out.push(piece.clone());
            continue;
        }
        let mut inner = piece.clone();
        for n in &normals {
            let part = clip_halfspace(&inner, -*n);
            if part.len() >= 3 {
                out.push(part);
            }
            inner = clip_halfspace(&inner, *n);
            if inner.len() < 3 {
                break;
            }
        }
    }
    out
}

/// The smallest signed distance (sine) of p to the edge lines of a convex loop: positive inside.
fn convex_depth(lp: &[DVec3], p: DVec3) -> f64 {
    (0..lp.len())
        .map(|i| line_normal(lp[i], lp[(i + 1) % lp.len()]).dot(p))
        .fold(f64::INFINITY, f64::min)
}

/// Kinds of failure, counted separately.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Failure {
    Invalid,
    Inconsistent,
    Area,
    Membership,
}

#[derive(Default, Debug, Clone)]
struct Tally {
    chains: u64,
    steps: u64,
    failed_chains: u64,
    by_kind: [u64; 4],
    worst_area_ratio: f64,
    samples: u64,
    max_vertices: usize,
    max_loops: usize,
    /// Intersection vertices by kind (X, T subject on clip, T clip on subject, V), fragments
    /// overlapping the other boundary, occluder vertices exactly on the horizon.
    kinds: [u64; 4],
    overlaps: u64,
    horizon_vertices: u64,
    first_failures: Vec<(u64, usize, Failure, String)>,
}

impl Tally {
    fn merge(&mut self, o: &Tally) {
        self.chains += o.chains;
        self.steps += o.steps;
        self.failed_chains += o.failed_chains;
        for k in 0..4 {
            self.by_kind[k] += o.by_kind[k];
        }
        self.worst_area_ratio = self.worst_area_ratio.max(o.worst_area_ratio);
        self.samples += o.samples;
        self.max_vertices = self.max_vertices.max(o.max_vertices);
        self.max_loops = self.max_loops.max(o.max_loops);
        for k in 0..4 {
            self.kinds[k] += o.kinds[k];
        }
        self.overlaps += o.overlaps;
        self.horizon_vertices += o.horizon_vertices;
        self.first_failures.extend(o.first_failures.iter().cloned());
        self.first_failures.sort_by_key(|f| f.0);
        self.first_failures.truncate(20);
    }
}

fn planar(lp: &[DVec3]) -> PlanarPolygon {
    let mut p = PlanarPolygon::new();
    p.push_loop(lp.iter().copied());
    p
}

/// Structural validity of an output (see the module documentation).
fn valid(out: &PlanarPolygon) -> bool {
    out.loops().all(|lp| {
        lp.len() >= 3
            && (0..lp.len()).all(|i| {
                let (a, b) = (lp[i], lp[(i + 1) % lp.len()]);
                a.is_finite()
                    && a.z >= 0.0
                    && a.length_squared() > 0.0
                    && a.normalize().cross(b.normalize()).length() > 1e-14
            })
    })
}

/// Runs chain `index`, checking every step; returns the first failure.
fn run_chain(
    index: u64,
    sd: &mut SetDifference,
    tally: &mut Tally,
    verbose: bool,
) -> Option<(usize, Failure, String)> {
    let mut rng = Pcg32::new(SEED, index);
    let chain = random_chain(&mut rng);
    if verbose {
        eprintln!("light {:?}", chain.light);
        for (k, c) in chain.occluders.iter().enumerate() {
            eprintln!("occluder {k} {c:?}");
        }
    }
    let mut current = planar(&chain.light);
    let mut next = PlanarPolygon::new();
    let mut pieces = vec![chain.light.clone()];
    let mut bound = 0.0;
    let mut steps = GreinerHormannSteps::default();
    for (step, clip) in chain.occluders.iter().enumerate() {
        let clip_poly = planar(clip);
        sd.subtract(&current, &clip_poly, &mut next, Some(&mut steps));
        tally.steps += 1;
        for i in &steps.intersections {
            tally.kinds[i.kind as usize] += 1;
        }
        tally.overlaps += steps.labels.iter().filter(|l| l.after.is_overlap()).count() as u64;
        tally.horizon_vertices += clip.iter().filter(|v| v.z == 0.0).count() as u64;
        let context = |what: &str| {
            format!(
                "{what}\nsubject {:?}\nclip {:?}\nresult {:?}",
                current.0, clip, next.0
            )
        };
        if verbose {
            eprintln!("step {step}: result {:?}", next.0);
        }
        if !valid(&next) {
            return Some((step, Failure::Invalid, context("invalid output")));
        }
        if !sd.last_traversal_consistent() {
            return Some((step, Failure::Inconsistent, context("inconsistent")));
        }
        tally.max_vertices = tally.max_vertices.max(next.vertex_count());
        tally.max_loops = tally.max_loops.max(next.loop_count());
        // Area against the convex pieces of light − occluders so far.
        pieces = subtract_convex(&pieces, clip);
        let expected: f64 = pieces.iter().map(|p| loop_area(p)).sum();
        let out_loops = loops_of(&next);
        let got: f64 = out_loops.iter().map(|l| loop_area(l)).sum();
        bound += (EPS_LINE + EPS_POINT + 0.5 * COLLAPSE_RADIUS)
            * (perimeter(current.loops()) + perimeter([&clip[..]]))
            + 1e-15;
        let err = (got - expected).abs();
        tally.worst_area_ratio = tally.worst_area_ratio.max(err / bound);
        if err > bound {
            return Some((
                step,
                Failure::Area,
                context(&format!("area {got} vs {expected} (bound {bound:e})")),
            ));
        }
        // Membership at points over the light and around every vertex.
        let occluders = &chain.occluders[..=step];
        let anchors: Vec<DVec3> = chain
            .light
            .iter()
            .chain(occluders.iter().flatten())
            .copied()
            .collect();
        let (lc, lf) = {
            let c = chain.light.iter().copied().sum::<DVec3>().normalize();
            (c, Frame::from_z(c))
        };
        let reach = chain
            .light
            .iter()
            .map(|v| lc.cross(*v).length() / lc.dot(*v).max(1e-3))
            .fold(0.0, f64::max);
        for k in 0..24 {
            let p = if k % 2 == 0 {
                let (x, y) = (rng.range(-reach, reach), rng.range(-reach, reach));
                lf.to_world(DVec3::new(x, y, 1.0)).normalize()
            } else {
                let a = anchors[rng.below(anchors.len() as u32) as usize];
                let f = Frame::from_z(a);
                let r = log_uniform(&mut rng, -8.0, -1.0);
                let phi = rng.range(0.0, TAU);
                f.to_world(DVec3::new(r * phi.cos(), r * phi.sin(), 1.0))
                    .normalize()
            };
            if p.z <= 1e-9 {
                continue;
            }
            let margin = 1e-9;
            let dl = convex_depth(&chain.light, p);
            let mut ambiguous = dl.abs() < margin;
            let mut expected = dl > 0.0;
            for c in occluders {
                let d = convex_depth(c, p);
                ambiguous |= d.abs() < margin;
                expected &= d <= 0.0;
            }
            if ambiguous {
                continue;
            }
            tally.samples += 1;
            let w = winding(&out_loops, p);
            let ok = if expected {
                (w - 1.0).abs() < 1e-6
            } else {
                w.abs() < 1e-6
            };
            if !ok {
                return Some((
                    step,
                    Failure::Membership,
                    context(&format!(
                        "winding {w} at {p:?}, expected inside: {expected}"
                    )),
                ));
            }
        }
        std::mem::swap(&mut current, &mut next);
    }
    None
}

fn run_range(indices: impl Iterator<Item = u64>, keep: usize) -> Tally {
    let mut sd = SetDifference::new();
    let mut tally = Tally::default();
    for index in indices {
        tally.chains += 1;
        if let Some((step, kind, msg)) = run_chain(index, &mut sd, &mut tally, false) {
            tally.failed_chains += 1;
            tally.by_kind[kind as usize] += 1;
            if tally.first_failures.len() < keep {
                tally.first_failures.push((index, step, kind, msg));
            }
        }
    }
    tally
}

fn report(t: &Tally) {
    eprintln!(
        "chains: {} chains, {} steps, {} failed chains (invalid / inconsistent / area / \
         membership = {:?}), worst area error / bound \
         {:.2e}, {} membership samples, up to {} vertices and {} loops; intersections \
         X / T(s on c) / T(c on s) / V = {:?}, {} overlapping fragments, {} occluder vertices \
         on the horizon",
        t.chains,
        t.steps,
        t.failed_chains,
        t.by_kind,
        t.worst_area_ratio,
        t.samples,
        t.max_vertices,
        t.max_loops,
        t.kinds,
        t.overlaps,
        t.horizon_vertices
    );
    for (index, step, kind, msg) in t.first_failures.iter().take(5) {
        eprintln!("chain {index} step {step}: {kind:?}: {msg}");
    }
}

#[test]
fn chains_match_oracles() {
    if let Some(index) = std::env::var("PENUMBRA_CHAIN")
        .ok()
        .and_then(|v| v.parse().ok())
    {
        let mut tally = Tally::default();
        let r = run_chain(index, &mut SetDifference::new(), &mut tally, true);
        eprintln!("{r:?}");
        return;
    }
    let t = run_range(0..10_000, 3);
    report(&t);
    assert_eq!(t.failed_chains, 0, "{:?}", t.first_failures.first());
    assert!(t.samples > 200_000 && t.steps > 30_000, "{t:?}");
}

#[test]
#[ignore = "10⁶ chains: run by hand (see the module documentation)"]
fn chains_match_oracles_stress() {
    let n: u64 = std::env::var("PENUMBRA_CHAINS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1_000_000);
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get()) as u64;
    let start = std::time::Instant::now();
    let mut total = Tally::default();
    std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|t| s.spawn(move || run_range((t..n).step_by(threads as usize), 20)))
            .collect();
        for h in handles {
            total.merge(&h.join().unwrap());
        }
    });
    report(&total);
    eprintln!("{:.1} s", start.elapsed().as_secs_f64());
    assert_eq!(total.failed_chains, 0);
}
