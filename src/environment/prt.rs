//! Diffuse precomputed radiance transfer with shadows (Sloan et al. 2002; 002 Eq. 6): the
//! static part of the environment's irradiance, precomputed once by ray casting on the static
//! surfaces and interpolated at run time.
//!
//! For a point x with normal n and the static objects S, the transfer vector is
//!
//! ```text
//!   T_k(x) = ∫_{H(n)} V_S(x, ω) max(n·ω, 0) Y_k(ω) dω,        k = 0..8,
//! ```
//!
//! with V_S = 1 where the ray from x escapes every static occluder. For radiance
//! L(ω) = Σ_k L_k Y_k(ω) (the 3-band projection, [`super::Sh9`]) the static irradiance is the
//! dot product `E_static(x) = Σ_k L_k T_k(x)` (002 Eq. 6): rotating or rescaling the map
//! changes L_k only, never T.
//!
//! T is estimated with N cosine-weighted Hammersley rays (the samples of `rt`, rotated by a
//! hash of the node), `T_k ≈ (π/N) Σ_i V_S(ω_i) Y_k(ω_i)`, at the nodes of a regular grid laid
//! on every static receiving face (its plane, its bounding rectangle along its longest edge).
//! Nodes outside the face are moved to the nearest point of the face, so that no node starts
//! inside a neighbouring solid. At run time a point of a static face reads its face's grid
//! bilinearly ([`TransferField::transfer`]); the front side of the face only (a point seen
//! from the back, or on a dynamic object, has no transfer here and the caller computes its
//! static irradiance otherwise).
//!
//! The grid spacing is chosen so that the node count stays within a budget (at least 2×2
//! nodes per face): the precomputation is bounded by `nodes × rays` rays whatever the scene.
//! The field is cached on disk with the silhouette trees (`shading::tree_cache`), keyed by
//! the static geometry and the settings.

use super::hemisphere_samples::{HemisphereSamples, pixel_rotation};
use super::sh::{Sh9, sh_basis};
use crate::accel::{Bvh, Ray};
use crate::math::Frame;
use crate::scene::Scene;
use crate::shading::tree_cache::{self, TreeCache};
use glam::{DVec2, DVec3};
use rayon::prelude::*;

/// How the transfer is precomputed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct PrtSettings {
    /// Rays per node.
    pub rays: u32,
    /// The node budget over all static faces (the grid spacing follows from it).
    pub max_nodes: u32,
}

impl Default for PrtSettings {
    /// 256 rays (the transfer's noise is then below 1 % of the unshadowed irradiance) over at
    /// most 2¹⁶ nodes: 16.8 M rays, a few seconds on two cores, once per static scene.
    fn default() -> Self {
        PrtSettings {
            rays: 256,
            max_nodes: 1 << 16,
        }
    }
}

/// The grid of one static face: nodes `first .. first + nu·nv`, row-major in (u, v).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FaceGrid {
    /// The face's front normal (Newell) and its in-plane axes.
    pub normal: DVec3,
    pub u: DVec3,
    pub v: DVec3,
    /// The plane's offset along the normal.
    pub offset: f64,
    /// The grid's lower corner in (x·u, x·v) and the node spacing along u and v.
    pub lo: DVec2,
    pub step: DVec2,
    pub nu: u32,
    pub nv: u32,
    pub first: u32,
}

impl FaceGrid {
    /// Node (a, b) on the face's plane, before a node outside the face is moved onto it.
    pub fn node(&self, a: u32, b: u32) -> DVec3 {
        let q = self.lo + DVec2::new(a as f64, b as f64) * self.step;
        self.u * q.x + self.v * q.y + self.normal * self.offset
    }
}

/// The transfer vectors of every static receiving face.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TransferField {
    pub settings: Option<PrtSettings>,
    /// Per scene object, the index of its first face's grid in `grids` (`u32::MAX`: the
    /// object is not a static receiver).
    pub object_grids: Vec<u32>,
    /// Per face of the static receivers, its grid (`None`: the face has no area).
    pub grids: Vec<Option<FaceGrid>>,
    /// Per node, T_0..T_8.
    pub nodes: Vec<[f32; 9]>,
}

impl TransferField {
    /// Precomputes the transfer of every static receiver of `scene` (with `bvh` built from it)
    /// against its static occluders. Parallel over nodes, deterministic.
    pub fn compute(scene: &Scene, bvh: &Bvh, settings: PrtSettings) -> TransferField {
        let mut field = TransferField {
            settings: Some(settings),
            object_grids: vec![u32::MAX; scene.objects.len()],
            ..Default::default()
        };
        let faces: Vec<(usize, usize)> = scene
            .objects
            .iter()
            .enumerate()
            .filter(|(_, o)| o.flags.is_static && o.flags.receiver)
            .flat_map(|(oi, o)| (0..o.mesh.faces.len()).map(move |f| (oi, f)))
            .collect();
        let frames: Vec<Option<FacePlane>> = faces
            .iter()
            .map(|&(oi, f)| {
                FacePlane::new(
                    &scene.objects[oi].mesh.positions,
                    &scene.objects[oi].mesh.faces[f],
                )
            })
            .collect();
        let step = grid_step(&frames, settings.max_nodes);
        let mut positions: Vec<(DVec3, DVec3, u32, u32)> = Vec::new();
        for (&(oi, f), plane) in faces.iter().zip(&frames) {
            if field.object_grids[oi] == u32::MAX {
                field.object_grids[oi] = field.grids.len() as u32;
            }
            let Some(plane) = plane else {
                field.grids.push(None);
                continue;
            };
            let grid = plane.grid(step, positions.len() as u32);
            for b in 0..grid.nv {
                for a in 0..grid.nu {
                    let q = grid.lo + DVec2::new(a as f64, b as f64) * grid.step;
                    let q = plane.nearest_inside(q);
                    positions.push((plane.point(q), plane.normal, oi as u32, f as u32));
                }
            }
            field.grids.push(Some(grid));
        }
        let samples = HemisphereSamples::new(settings.rays.max(1));
        let extent = bvh
            .bounds()
            .map_or(1.0, |(lo, hi)| (hi - lo).length().max(1e-300));
        let t_min = 1e-9 * extent;
        let blocks = |o: u32, f: u32, own: (u32, u32)| {
            let obj = &scene.objects[o as usize];
            obj.flags.is_static && obj.flags.occluder && (o, f) != own
        };
        field.nodes = positions
            .par_iter()
            .enumerate()
            .map(|(i, &(p, n, o, f))| {
                let frame = Frame::from_z(n);
                let rot = pixel_rotation(PRT_SEED, i as u64);
                // A node inside a static solid (a floor running under a wall) sees the inside
                // of its faces: its transfer would darken the visible points interpolated
                // from it, so it is marked and left out of the interpolation.
                let probes = INSIDE_PROBES.min(samples.len());
                let inside = (0..probes)
                    .filter(|&k| {
                        let dir = frame.to_world(samples.rotated(k * samples.len() / probes, rot));
                        let ray = Ray { origin: p, dir };
                        bvh.intersect_accept(&ray, t_min, f64::INFINITY, |ho, hf| {
                            blocks(ho, hf, (o, f))
                        })
                        .is_some_and(|h| h.geometric_normal.dot(dir) > 0.0)
                    })
                    .count();
                if 2 * inside > probes {
                    let mut t = [0.0f32; 9];
                    t[0] = INSIDE;
                    return t;
                }
                let mut t = [0.0f64; 9];
                for s in 0..samples.len() {
                    let dir = frame.to_world(samples.rotated(s, rot));
                    let ray = Ray { origin: p, dir };
                    if !bvh.occluded(&ray, t_min, f64::INFINITY, |ho, hf| blocks(ho, hf, (o, f))) {
                        for (tk, y) in t.iter_mut().zip(sh_basis(dir)) {
                            *tk += y;
                        }
                    }
                }
                t.map(|x| (x * samples.weight()) as f32)
            })
            .collect();
        field
    }

    /// T at a point of face `face` of scene object `object` whose (two-sided) shading normal
    /// is `normal`: the bilinear interpolation of the face's grid. `None` off the static
    /// receivers, on a face without area, or on the back side of a face.
    pub fn transfer(&self, object: u32, face: u32, p: DVec3, normal: DVec3) -> Option<[f64; 9]> {
        let first = *self.object_grids.get(object as usize)?;
        if first == u32::MAX {
            return None;
        }
        let g = self.grids.get(first as usize + face as usize)?.as_ref()?;
        if g.normal.dot(normal) <= 0.0 {
            return None;
        }
        let s = ((DVec2::new(p.dot(g.u), p.dot(g.v)) - g.lo) / g.step).clamp(
            DVec2::ZERO,
            DVec2::new((g.nu - 1) as f64, (g.nv - 1) as f64),
        );
        let (a, b) = (
            (s.x.floor() as u32).min(g.nu - 2),
            (s.y.floor() as u32).min(g.nv - 2),
        );
        let (fx, fy) = (s.x - a as f64, s.y - b as f64);
        let node = |da: u32, db: u32| &self.nodes[(g.first + (b + db) * g.nu + a + da) as usize];
        let w = [
            (1.0 - fx) * (1.0 - fy),
            fx * (1.0 - fy),
            (1.0 - fx) * fy,
            fx * fy,
        ];
        let corners = [node(0, 0), node(1, 0), node(0, 1), node(1, 1)];
        let mut t = [0.0; 9];
        let mut total = 0.0;
        for (c, w) in corners.iter().zip(w) {
            if c[0] == INSIDE || w == 0.0 {
                continue;
            }
            total += w;
            for (tk, &ck) in t.iter_mut().zip(c.iter()) {
                *tk += w * ck as f64;
            }
        }
        // Renormalised over the corners outside solids; none: no transfer here.
        (total > 0.0).then(|| t.map(|x| x / total))
    }

    /// Whether every index is in range (a cached field read back from disk is checked before
    /// use) for a scene with `objects` objects whose face counts are `faces(object)`.
    pub fn is_well_formed(&self, objects: usize, faces: impl Fn(usize) -> usize) -> bool {
        if self.object_grids.len() != objects {
            return false;
        }
        let nodes = self.nodes.len() as u64;
        let grids_ok = self.grids.iter().flatten().all(|g| {
            g.nu >= 2
                && g.nv >= 2
                && u64::from(g.first) + u64::from(g.nu) * u64::from(g.nv) <= nodes
                && g.step.x > 0.0
                && g.step.y > 0.0
        });
        let objects_ok =
            self.object_grids.iter().enumerate().all(|(o, &first)| {
                first == u32::MAX || first as usize + faces(o) <= self.grids.len()
            });
        grids_ok && objects_ok && self.nodes.iter().flatten().all(|x| x.is_finite())
    }

    /// Nodes, for reports.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// The field of `scene`'s static surfaces: read from `cache` if it holds one for this
    /// static geometry and these settings, else computed (and stored).
    pub fn cached_or_computed(
        scene: &Scene,
        bvh: &Bvh,
        settings: PrtSettings,
        cache: Option<&TreeCache>,
    ) -> (TransferField, PrtReport) {
        let start = web_time::Instant::now();
        let key = transfer_key(scene, settings);
        let faces = |o: usize| scene.objects[o].mesh.faces.len();
        if let Some(field) = cache.and_then(|c| {
            c.load_data(key, |f: &TransferField| {
                f.is_well_formed(scene.objects.len(), faces)
            })
        }) {
            let report = PrtReport {
                nodes: field.node_count() as u64,
                rays: field.node_count() as u64 * u64::from(settings.rays),
                seconds: start.elapsed().as_secs_f64(),
                from_cache: true,
            };
            return (field, report);
        }
        let field = TransferField::compute(scene, bvh, settings);
        if let Some(c) = cache {
            c.store_data(key, &field);
        }
        let report = PrtReport {
            nodes: field.node_count() as u64,
            rays: field.node_count() as u64 * u64::from(settings.rays),
            seconds: start.elapsed().as_secs_f64(),
            from_cache: false,
        };
        (field, report)
    }
}

/// What obtaining a transfer field cost.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PrtReport {
    pub nodes: u64,
    /// Rays cast (or, read from the cache, that were cast when it was computed).
    pub rays: u64,
    pub seconds: f64,
    pub from_cache: bool,
}

impl std::fmt::Display for PrtReport {
    /// "60025 nodes × 256 rays, 0.60 s" (and ", read from the cache").
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} nodes × {} rays, {:.2} s{}",
            self.nodes,
            self.rays / self.nodes.max(1),
            self.seconds,
            if self.from_cache {
                ", read from the cache"
            } else {
                ""
            }
        )
    }
}

/// FNV-1a over everything the field depends on: the settings, and every static object's
/// flags, vertices and faces (dynamic objects never enter the transfer).
pub fn transfer_key(scene: &Scene, settings: PrtSettings) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |x: u64| {
        for b in x.to_le_bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    };
    eat(u64::from_le_bytes(*b"prt-v1\0\0"));
    eat(u64::from(tree_cache::FORMAT));
    eat(u64::from(settings.rays));
    eat(u64::from(settings.max_nodes));
    eat(scene.objects.len() as u64);
    for (o, obj) in scene.objects.iter().enumerate() {
        if !obj.flags.is_static {
            continue;
        }
        eat(o as u64);
        eat(u64::from(obj.flags.occluder) | u64::from(obj.flags.receiver) << 1);
        eat(obj.mesh.positions.len() as u64);
        for p in &obj.mesh.positions {
            eat(p.x.to_bits());
            eat(p.y.to_bits());
            eat(p.z.to_bits());
        }
        for f in &obj.mesh.faces {
            eat(f.len() as u64);
            for &i in f {
                eat(u64::from(i));
            }
        }
    }
    h
}

/// E_static = Σ_k L_k T_k (002 Eq. 6), per colour channel.
#[inline]
pub fn transferred_irradiance(sh: &Sh9, t: &[f64; 9]) -> DVec3 {
    sh.coeffs
        .iter()
        .zip(t)
        .fold(DVec3::ZERO, |acc, (l, &tk)| acc + *l * tk)
}

/// Marks a node inside a static solid (in T_0, which is ∫ V Y_00 cos ≥ 0 elsewhere).
pub(crate) const INSIDE: f32 = -1.0;

/// Closest-hit rays per node that decide whether it lies inside a static solid (most of them
/// meet the back of a face).
const INSIDE_PROBES: usize = 16;

/// The seed of the nodes' ray rotations (fixed: the field is a function of the scene).
const PRT_SEED: u64 = 0x5052_545f_6e6f_6465;

/// A face's plane: its normal, in-plane axes, and its outline in those axes.
struct FacePlane {
    normal: DVec3,
    u: DVec3,
    v: DVec3,
    /// The plane's offset along the normal (through the face's centroid).
    offset: f64,
    outline: Vec<DVec2>,
    lo: DVec2,
    hi: DVec2,
    area: f64,
}

impl FacePlane {
    /// The plane of a face, with u along its longest edge (a rectangle's grid then lies along
    /// its sides). `None` for a face without area.
    fn new(positions: &[DVec3], face: &[u32]) -> Option<FacePlane> {
        let normal = crate::accel::bvh::newell_normal(positions, face);
        if normal == DVec3::ZERO {
            return None;
        }
        let p = |k: usize| positions[face[k % face.len()] as usize];
        let longest = (0..face.len())
            .map(|k| p(k + 1) - p(k))
            .max_by(|a, b| a.length_squared().total_cmp(&b.length_squared()))?;
        let u = (longest - normal * normal.dot(longest)).normalize_or_zero();
        if u == DVec3::ZERO {
            return None;
        }
        let v = normal.cross(u);
        let centroid = (0..face.len()).map(p).sum::<DVec3>() / face.len() as f64;
        let outline: Vec<DVec2> = (0..face.len())
            .map(|k| DVec2::new(p(k).dot(u), p(k).dot(v)))
            .collect();
        let lo = outline.iter().fold(DVec2::INFINITY, |a, &b| a.min(b));
        let hi = outline.iter().fold(DVec2::NEG_INFINITY, |a, &b| a.max(b));
        let area = 0.5
            * (0..outline.len())
                .map(|k| outline[k].perp_dot(outline[(k + 1) % outline.len()]))
                .sum::<f64>()
                .abs();
        (area > 0.0 && (hi - lo).min_element() > 0.0 && lo.is_finite() && hi.is_finite()).then(
            || FacePlane {
                normal,
                u,
                v,
                offset: centroid.dot(normal),
                outline,
                lo,
                hi,
                area,
            },
        )
    }

    /// Nodes along u and v for spacing `step` (at least two each: the corners).
    fn counts(&self, step: f64) -> (u32, u32) {
        let n = |len: f64| ((len / step).ceil() as u32).clamp(1, 1 << 12) + 1;
        let size = self.hi - self.lo;
        (n(size.x), n(size.y))
    }

    fn grid(&self, step: f64, first: u32) -> FaceGrid {
        let (nu, nv) = self.counts(step);
        let size = self.hi - self.lo;
        FaceGrid {
            normal: self.normal,
            u: self.u,
            v: self.v,
            offset: self.offset,
            lo: self.lo,
            step: DVec2::new(size.x / (nu - 1) as f64, size.y / (nv - 1) as f64),
            nu,
            nv,
            first,
        }
    }

    fn point(&self, q: DVec2) -> DVec3 {
        self.u * q.x + self.v * q.y + self.normal * self.offset
    }

    /// `q` if it lies in the face's outline (even–odd), else the nearest point of the outline.
    fn nearest_inside(&self, q: DVec2) -> DVec2 {
        let o = &self.outline;
        let mut inside = false;
        let mut best = (f64::INFINITY, q);
        for k in 0..o.len() {
            let (a, b) = (o[k], o[(k + 1) % o.len()]);
            if (a.y > q.y) != (b.y > q.y) && q.x < a.x + (q.y - a.y) / (b.y - a.y) * (b.x - a.x) {
                inside = !inside;
            }
            let ab = b - a;
            let t = ((q - a).dot(ab) / ab.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
            let c = a + ab * t;
            let d = (q - c).length_squared();
            if d < best.0 {
                best = (d, c);
            }
        }
        if inside { q } else { best.1 }
    }
}

/// The grid spacing that keeps the node count within `max_nodes` (each face has at least
/// 2×2 nodes, so a mesh with more than max_nodes/4 faces exceeds it: then every face gets
/// its four corners). Starts from √(area / budget) and widens until the count fits.
fn grid_step(planes: &[Option<FacePlane>], max_nodes: u32) -> f64 {
    let planes: Vec<&FacePlane> = planes.iter().flatten().collect();
    let area: f64 = planes.iter().map(|p| p.area).sum();
    let largest = planes
        .iter()
        .map(|p| (p.hi - p.lo).max_element())
        .fold(0.0, f64::max);
    if planes.is_empty() || largest <= 0.0 {
        return 1.0;
    }
    let count = |step: f64| -> u64 {
        planes
            .iter()
            .map(|p| {
                let (a, b) = p.counts(step);
                u64::from(a) * u64::from(b)
            })
            .sum()
    };
    let budget = u64::from(max_nodes.max(4));
    let mut step = (area / budget as f64).sqrt().max(largest / 4096.0);
    for _ in 0..64 {
        let c = count(step);
        if c <= budget || step >= largest {
            break;
        }
        step *= (c as f64 / budget as f64).sqrt().max(1.05);
    }
    step.min(largest)
}
