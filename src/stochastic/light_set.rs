//! The lights seen from one shading point as sets of spherical triangles to sample by solid
//! angle (001 Sect. 3.6 and 6.1).
//!
//! * A convex closed light: its silhouette (the same [`silhouette`] stage as the analytic
//!   path), clipped to the horizon with [`clip_to_horizon`], triangulated as a fan. A convex
//!   polygon clipped to a hemisphere stays convex, so the fan around any vertex is valid.
//! * A flat light: its front faces, each clipped and fanned (faces are convex). Faces in one
//!   plane never overlap in direction.
//! * A star-shaped closed light (001 Sect. 6.1): its exact silhouette (the analytic path's,
//!   from the BSP tree or on the fly) fanned from the direction of a kernel point c. Every
//!   segment from c to the surface lies in the mesh, so every arc from c's direction to the
//!   silhouette lies in its projection: the fan covers it exactly once. Each fan triangle is
//!   clipped to the horizon (a triangle cut by a half-space stays convex) and fanned again.
//!   Where the fan would hold a triangle that is not positively oriented (degenerate points),
//!   the light takes the face path below.
//! * A closed light that is neither (001 Sect. 6.2): the triangles precomputed for the cell of
//!   the shading point ([`crate::geometry::SilhouetteTriangulation`], proved to cover the
//!   silhouette exactly once everywhere in the cell), each clipped to the horizon and fanned.
//! * Any other light, and the cells where no triangulation was proved: its front faces, each
//!   clipped and fanned. Faces may overlap in direction; a sample on a face that another face
//!   of the same light hides is rejected by a ray test ([`LightRun::self_occluding`]).
//!
//! Each light's triangles share one density 1/Ω, Ω the sum of their solid angles, so that the
//! multiple-importance weights need only Ω (see `estimator.rs`).

use crate::geometry::{ExactSilhouetteScratch, SilhouettePoint};
use crate::geometry::{
    HorizonScratch, Sidedness, SilhouetteScratch, SphericalPolygon, clip_to_horizon, face_polygon,
    orient, silhouette,
};
use crate::math::Frame;
use crate::sampling::SphericalTriangle;
use crate::shading::{PreparedObject, PreparedScene, ShadingPoint};
use glam::DVec3;

/// Face index of a triangle that belongs to the silhouette fan of a convex light.
pub(crate) const SILHOUETTE: u32 = u32::MAX;

/// The triangles of one light at the current shading point.
#[derive(Clone, Copy, Debug, Default)]
pub struct LightRun {
    /// Index into `PreparedScene::lights`.
    pub light: usize,
    /// Index of the light object in the scene.
    pub object: u32,
    pub radiance: DVec3,
    /// `tris[start..end]` of the [`LightSet`].
    pub start: usize,
    pub end: usize,
    /// Ω: total solid angle of the triangles (each direction counted once per face it lies in).
    pub solid_angle: f64,
    /// Faces of the light may hide each other (a non-convex, non-flat light sampled by faces).
    pub self_occluding: bool,
    /// Probability of choosing this light for a light sample.
    pub probability: f64,
}

/// Reused buffers of the triangulation.
#[derive(Default)]
pub(crate) struct LightSetScratch {
    silhouette: SilhouetteScratch,
    exact: ExactSilhouetteScratch,
    triangle: SphericalPolygon,
    horizon: HorizonScratch,
    sph: SphericalPolygon,
    clipped: SphericalPolygon,
    face_buf: Vec<DVec3>,
}

/// Spherical triangles of every light seen from one shading point, in the shading frame.
#[derive(Default)]
pub struct LightSet {
    pub runs: Vec<LightRun>,
    pub tris: Vec<SphericalTriangle>,
    /// Vertices of `tris` (for containment tests), in the same order.
    pub corners: Vec<[DVec3; 3]>,
    /// The light face each triangle comes from, or `SILHOUETTE`.
    pub faces: Vec<u32>,
    /// Cumulative solid angle within each run (ends at the run's Ω).
    pub cdf: Vec<f64>,
    scratch: LightSetScratch,
}

/// How a light mesh is triangulated for sampling.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightShape {
    Convex,
    Flat,
    StarShaped,
    /// Closed, neither convex nor star-shaped, with precomputed triangulations.
    Triangulated,
    General,
}

pub fn light_shape(obj: &PreparedObject) -> LightShape {
    let d = &obj.poly.diagnostics;
    if d.planar {
        LightShape::Flat
    } else if d.convex {
        LightShape::Convex
    } else if obj.star_centre.is_some() {
        LightShape::StarShaped
    } else if obj.triangulation.is_some() {
        LightShape::Triangulated
    } else {
        LightShape::General
    }
}

/// Relative distance below which a face is taken to contain the shading point (as in the
/// analytic path).
const COPLANAR: f64 = 1e-9;

impl LightSet {
    /// Triangulates every light seen from `sp` (shading frame `frame`) and sets the light
    /// selection probabilities proportional to luminance × Ω.
    pub fn build(&mut self, scene: &PreparedScene, sp: &ShadingPoint, frame: &Frame) {
        self.build_with(scene, sp, frame, false)
    }

    /// [`LightSet::build`]; with `faces_only`, every light is triangulated face by face (the
    /// baseline of 001 Table 7.3: triangulated faces instead of triangulated silhouettes).
    pub fn build_with(
        &mut self,
        scene: &PreparedScene,
        sp: &ShadingPoint,
        frame: &Frame,
        faces_only: bool,
    ) {
        self.runs.clear();
        self.tris.clear();
        self.corners.clear();
        self.faces.clear();
        self.cdf.clear();
        let x = sp.position;
        for (l, &(light_id, radiance)) in scene.lights.iter().enumerate() {
            let light = &scene.objects[light_id as usize];
            let on_light = sp.object == Some(light.object);
            let shape = if faces_only {
                LightShape::General
            } else {
                light_shape(light)
            };
            let start = self.tris.len();
            let mut total = 0.0;
            let mut shape = shape;
            if shape == LightShape::StarShaped {
                match (!on_light)
                    .then(|| self.star_fan(light, x, frame))
                    .flatten()
                {
                    Some(t) => total = t,
                    None => {
                        self.truncate(start);
                        shape = LightShape::General;
                    }
                }
            }
            if shape == LightShape::Triangulated {
                match (!on_light)
                    .then(|| self.cell_triangles(light, x, frame))
                    .flatten()
                {
                    Some(t) => total = t,
                    None => {
                        self.truncate(start);
                        shape = LightShape::General;
                    }
                }
            }
            match shape {
                LightShape::StarShaped | LightShape::Triangulated => {}
                LightShape::Convex => {
                    if on_light {
                        continue; // a convex light does not light itself
                    }
                    let s = &mut self.scratch;
                    silhouette(
                        &light.poly,
                        x,
                        frame,
                        Sidedness::FrontOnly,
                        &mut s.sph,
                        &mut s.silhouette,
                    );
                    clip_to_horizon(&s.sph, &mut s.clipped, &mut s.horizon);
                    total += push_fans(
                        &s.clipped,
                        SILHOUETTE,
                        &mut self.tris,
                        &mut self.corners,
                        &mut self.faces,
                        &mut self.cdf,
                        total,
                    );
                }
                LightShape::Flat | LightShape::General => {
                    for f in 0..light.poly.face_count() {
                        let plane = light.poly.face_planes[f];
                        let s = plane.eval(x);
                        if s <= COPLANAR * light.poly.radius
                            || (on_light && sp.face == Some(f as u32))
                        {
                            continue; // behind the face, in its plane, or the face itself
                        }
                        let sc = &mut self.scratch;
                        face_polygon(
                            &light.poly,
                            f,
                            x,
                            frame,
                            Sidedness::FrontOnly,
                            None,
                            &mut sc.sph,
                            &mut sc.face_buf,
                        );
                        clip_to_horizon(&sc.sph, &mut sc.clipped, &mut sc.horizon);
                        total += push_fans(
                            &sc.clipped,
                            f as u32,
                            &mut self.tris,
                            &mut self.corners,
                            &mut self.faces,
                            &mut self.cdf,
                            total,
                        );
                    }
                }
            }
            if total > 0.0 {
                self.runs.push(LightRun {
                    light: l,
                    object: light.object,
                    radiance,
                    start,
                    end: self.tris.len(),
                    solid_angle: total,
                    self_occluding: shape == LightShape::General,
                    probability: 0.0,
                });
            } else {
                self.truncate(start);
            }
        }
        let weight =
            |r: &LightRun| crate::shading::brdf::luminance(r.radiance).max(0.0) * r.solid_angle;
        let sum: f64 = self.runs.iter().map(weight).sum();
        if sum > 0.0 {
            for r in &mut self.runs {
                r.probability = weight(r) / sum;
            }
        }
    }

    fn truncate(&mut self, start: usize) {
        self.tris.truncate(start);
        self.corners.truncate(start);
        self.faces.truncate(start);
        self.cdf.truncate(start);
    }

    /// The fan of a star-shaped light's silhouette from its centre's direction, each triangle
    /// clipped to the horizon and fanned; its total solid angle, or `None` (degenerate point:
    /// no single silhouette loop, or a fan triangle not positively oriented).
    fn star_fan(&mut self, light: &PreparedObject, x: DVec3, frame: &Frame) -> Option<f64> {
        let centre = light.star_centre?;
        let c = frame.to_local(centre - x).try_normalize()?;
        let LightSetScratch {
            exact,
            triangle,
            horizon,
            sph,
            clipped,
            ..
        } = &mut self.scratch;
        light.exact_silhouette(x, frame, sph, exact).ok()?;
        let mut loops = sph.loops();
        let (Some(lp), None) = (loops.next(), loops.next()) else {
            return None; // a star-shaped mesh's silhouette is one loop
        };
        let mut total = 0.0;
        for k in 0..lp.len() {
            let (a, b) = (lp[k], lp[(k + 1) % lp.len()]);
            if let Some(part) = clip_triangle([c, a, b], triangle, clipped, horizon)? {
                total += push_fans(
                    part,
                    SILHOUETTE,
                    &mut self.tris,
                    &mut self.corners,
                    &mut self.faces,
                    &mut self.cdf,
                    total,
                );
            }
        }
        Some(total)
    }

    /// The precomputed triangles of the cell of `x` (001 Sect. 6.2), each clipped to the
    /// horizon and fanned; their total solid angle, or `None` (no proved triangulation there,
    /// or a triangle that rounding left not positively oriented).
    fn cell_triangles(&mut self, light: &PreparedObject, x: DVec3, frame: &Frame) -> Option<f64> {
        let cells = light.triangulation.as_ref()?;
        let tris = cells.triangles(light.tree_point(x))?;
        let LightSetScratch {
            triangle,
            horizon,
            clipped,
            ..
        } = &mut self.scratch;
        let mut total = 0.0;
        for t in tris {
            let mut d = [DVec3::ZERO; 3];
            for (dk, &p) in d.iter_mut().zip(t) {
                *dk = frame.to_local(SilhouettePoint::unpack(p).direction(&light.poly, x)?);
            }
            // A triangle degenerate on the cell's boundary has no area.
            if let Some(part) = clip_triangle(d, triangle, clipped, horizon)? {
                total += push_fans(
                    part,
                    SILHOUETTE,
                    &mut self.tris,
                    &mut self.corners,
                    &mut self.faces,
                    &mut self.cdf,
                    total,
                );
            }
        }
        Some(total)
    }

    /// True when no light can be sampled.
    pub fn is_empty(&self) -> bool {
        self.runs.iter().all(|r| r.probability <= 0.0)
    }

    /// Draws a light run with `u` uniform in [0, 1); `None` when the set is empty.
    #[inline]
    pub(crate) fn pick_run(&self, u: f64) -> Option<usize> {
        let mut acc = 0.0;
        let mut last = None;
        for (i, r) in self.runs.iter().enumerate() {
            if r.probability <= 0.0 {
                continue;
            }
            acc += r.probability;
            last = Some(i);
            if u < acc {
                return last;
            }
        }
        last
    }

    /// A direction uniform in the solid angle of run `r` (each face counted separately):
    /// returns (direction in the shading frame, face index or [`SILHOUETTE`]).
    #[inline]
    pub(crate) fn sample(&self, r: usize, u0: f64, u1: f64, u2: f64) -> (DVec3, u32) {
        let run = &self.runs[r];
        let target = u0 * run.solid_angle;
        let cdf = &self.cdf[run.start..run.end];
        let k = run.start + cdf.partition_point(|&c| c <= target).min(cdf.len() - 1);
        (self.tris[k].sample(u1, u2), self.faces[k])
    }

    /// Does run `r` cover direction `w` (shading frame)? A triangle (a, b, c), counter-
    /// clockwise and smaller than a hemisphere, contains `w` exactly when `w` is on the inner
    /// side of its three great circles.
    #[inline]
    pub fn covers(&self, r: usize, w: DVec3) -> bool {
        let run = &self.runs[r];
        self.corners[run.start..run.end].iter().any(|&[a, b, c]| {
            orient(a, b, w) >= 0.0 && orient(b, c, w) >= 0.0 && orient(c, a, w) >= 0.0
        })
    }
}

/// The part of triangle `d` above the horizon, in `clipped`: `Some(None)` for a degenerate
/// triangle (no area), `None` for one that is not positively oriented (the caller's
/// triangulation does not hold at this point).
fn clip_triangle<'a>(
    d: [DVec3; 3],
    triangle: &mut SphericalPolygon,
    clipped: &'a mut SphericalPolygon,
    horizon: &mut HorizonScratch,
) -> Option<Option<&'a SphericalPolygon>> {
    let o = orient(d[0], d[1], d[2]);
    if o < 0.0 {
        return None;
    }
    if o == 0.0 {
        return Some(None);
    }
    triangle.clear();
    triangle.push_loop(d);
    clip_to_horizon(triangle, clipped, horizon);
    Some(Some(clipped))
}

/// Appends the fan of every loop of `poly` (convex loops, positively oriented) and returns
/// their total solid angle. Triangles without positive area are dropped: they hold no
/// direction (and a negative one would be a rounding artefact of nearly collinear vertices).
fn push_fans(
    poly: &SphericalPolygon,
    face: u32,
    tris: &mut Vec<SphericalTriangle>,
    corners: &mut Vec<[DVec3; 3]>,
    faces: &mut Vec<u32>,
    cdf: &mut Vec<f64>,
    mut acc: f64,
) -> f64 {
    let start = acc;
    for lp in poly.loops() {
        for k in 1..lp.len().saturating_sub(1) {
            let (a, b, c) = (lp[0], lp[k], lp[k + 1]);
            if orient(a, b, c) <= 0.0 {
                continue;
            }
            if let Some(t) = SphericalTriangle::new(a, b, c) {
                acc += t.solid_angle();
                tris.push(t);
                corners.push([a, b, c]);
                faces.push(face);
                cdf.push(acc);
            }
        }
    }
    acc - start
}
