//! Exact derivatives of the analytic image with respect to the rigid motion of one object
//! (docs/derivatives.md): the visible region's integral changes by the Reynolds transport
//! theorem, a line integral along its boundary of the integrand times the boundary's normal
//! speed (`reynolds`).
//!
//! The boundary is the visible polygon the renderer computed, so the derivative is taken of
//! the very region the image integrates. Each of its edges lies on one great circle: the
//! horizon, or the plane through the shading point `x` and one edge of a mesh (a light's edge,
//! or an occluder's contour edge). That plane is the edge's *support*, found at the point
//! among the contour edges of the meshes the light piece met ([`DerivativeScratch`]); it moves
//! as its mesh moves relative to `x`, and its normal's rate is the edge's speed. The LTC lobe
//! takes the same theorem in the cosine's space, where its integrand is fixed and the map
//! `M⁻¹` (which changes only when the point's own normal turns) moves the boundary too.

mod motion;
mod reynolds;

pub use motion::{Axis, Motion, PointMotion};
pub use reynolds::{arc_rate, arc_rate_quadrature};

use crate::geometry::PolygonLoops;
use crate::ltc::LtcEntry;
use crate::math::Frame;
use crate::shading::PreparedScene;
use crate::shading::recorder::{EdgeSupport, MovingEdge, Recorder};
use glam::{DMat3, DVec3};
use std::f64::consts::PI;

/// The step of the central differences the derivative is checked against, in scene units
/// (or radians): a pixel whose camera sample hits another face within it, or whose LTC lookup
/// crosses a table node within it, is masked.
pub const FD_STEP: f64 = 1e-6;

/// A plane through the shading point that may support an edge of the visible polygon: the
/// plane through `x` and the mesh edge `p → q`, with its unit normal (world space).
#[derive(Clone, Copy, Debug)]
struct Support {
    p: DVec3,
    q: DVec3,
    normal: DVec3,
    length: f64,
    moving: bool,
    /// The prepared object whose edge it is.
    object: u32,
}

/// An edge of the visible polygon lies on its support when both endpoints are within this
/// distance of the support's plane (the set difference's vertices carry rounding of order
/// 1e-14; distinct contour edges through one plane with `x` are a measure-zero coincidence).
const ON_PLANE: f64 = 1e-8;

/// The rates of one shading point: the motion there, and the LTC entry's rate `dentry/dθ`
/// (non-zero only when the point's own normal turns).
pub(crate) struct PointRates<'a> {
    pub point: &'a PointMotion,
    pub ltc: Option<LtcEntry>,
}

/// Per-thread buffers of the derivative and what it found at the point.
#[derive(Default)]
pub struct DerivativeScratch {
    supports: Vec<Support>,
    /// Per prepared object: (stamp, first, end) of its supports at the current point.
    ranges: Vec<(u32, u32, u32)>,
    /// The supports of the light piece's own face (a light taken face by face).
    face_supports: Vec<Support>,
    relevant: Vec<u32>,
    /// Every mesh the light piece met moves (the light alone, moving): an edge on no support
    /// found cannot be taken to stay.
    only_moving: bool,
    stamp: u32,
    /// The point's derivative, summed over its lights.
    pub sum: DVec3,
    /// Edges of the visible polygon whose support was not found while they may move.
    pub unsupported: u32,
    /// The point's LTC lookup lies within the finite-difference step of a table node.
    pub near_table_node: bool,
}

impl DerivativeScratch {
    /// Starts a shading point.
    pub(crate) fn begin_point(&mut self, objects: usize) {
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 || self.ranges.len() != objects {
            self.ranges.clear();
            self.ranges.resize(objects, (0, 0, 0));
            self.supports.clear();
            self.stamp = 1;
        }
        self.supports.clear();
        self.sum = DVec3::ZERO;
        self.unsupported = 0;
        self.near_table_node = false;
    }

    /// The supports of prepared object `o` at `x`: its contour edges (between a face turned
    /// toward `x` and one turned away) and boundary edges, in every form the analytic stages
    /// may have taken it in (the mesh, the hull standing in, the fan of triangles).
    fn object_supports(
        &mut self,
        scene: &PreparedScene,
        o: u32,
        x: DVec3,
        moving: bool,
    ) -> (u32, u32) {
        let r = self.ranges[o as usize];
        if r.0 == self.stamp {
            return (r.1, r.2);
        }
        let first = self.supports.len() as u32;
        let obj = &scene.objects[o as usize];
        let meshes = [&obj.poly, obj.faces(), obj.face_pieces()];
        for (k, mesh) in meshes.iter().enumerate() {
            if meshes[..k].iter().any(|m| std::ptr::eq(*m, *mesh)) {
                continue;
            }
            let front = |f: u32| mesh.face_planes[f as usize].eval(x) > 0.0;
            for e in &mesh.edges {
                if e.is_boundary() || front(e.faces[0]) != front(e.faces[1]) {
                    let (p, q) = (
                        mesh.vertices[e.v[0] as usize],
                        mesh.vertices[e.v[1] as usize],
                    );
                    if let Some(s) = Support::new(p, q, x, moving, o) {
                        self.supports.push(s);
                    }
                }
            }
        }
        let end = self.supports.len() as u32;
        self.ranges[o as usize] = (self.stamp, first, end);
        (first, end)
    }

    /// The rate `dν/dθ` (shading frame) of the normal `ν` of the visible polygon's edge
    /// `a → b` (shading frame): zero on the horizon (the frame's own `z = 0`), from the
    /// support's motion on a mesh edge; `None` when no support was found though it may move.
    fn normal_rate(
        &mut self,
        pm: &PointMotion,
        x: DVec3,
        frame: &Frame,
        a: DVec3,
        b: DVec3,
        nu: DVec3,
    ) -> (Option<DVec3>, EdgeSupport) {
        if nu.x.abs() <= 1e-12 && nu.y.abs() <= 1e-12 {
            return (Some(DVec3::ZERO), EdgeSupport::Horizon);
        }
        let (aw, bw) = (frame.to_world(a), frame.to_world(b));
        let mid = (aw + bw).normalize_or_zero();
        let mut best: Option<(f64, Support)> = None;
        let mut consider = |s: &Support| {
            let r = s.normal.dot(aw).abs().max(s.normal.dot(bw).abs());
            if r <= ON_PLANE && s.spans(mid, x) && best.is_none_or(|(rb, _)| r < rb) {
                best = Some((r, *s));
            }
        };
        for &s in &self.face_supports {
            consider(&s);
        }
        for &o in &self.relevant {
            let (first, end) = (self.ranges[o as usize].1, self.ranges[o as usize].2);
            for s in &self.supports[first as usize..end as usize] {
                consider(s);
            }
        }
        let Some((_, s)) = best else {
            // Unfound, the edge stays only if something it could lie on stays.
            return if pm.on_moving || self.only_moving {
                (None, EdgeSupport::NotFound)
            } else {
                (Some(DVec3::ZERO), EdgeSupport::Still)
            };
        };
        let support = EdgeSupport::MeshEdge {
            object: s.object,
            p: s.p,
            q: s.q,
            moving: s.moving,
        };
        if !pm.on_moving && !s.moving {
            return (Some(DVec3::ZERO), support);
        }
        // ν = ±F m̂ with m = (p − x) × (q − x): ν̇ = ±(F dm̂ + Ḟ m̂).
        let (vp, vq) = (
            pm.relative_velocity(s.p, s.moving),
            pm.relative_velocity(s.q, s.moving),
        );
        let m_rate = vp.cross(s.q - x) + (s.p - x).cross(vq);
        let dm = (m_rate - s.normal * s.normal.dot(m_rate)) / s.length;
        let f = &pm.frame_rate;
        let local = frame.to_local(dm)
            + DVec3::new(f.x.dot(s.normal), f.y.dot(s.normal), f.z.dot(s.normal));
        let sign = if nu.dot(frame.to_local(s.normal)) >= 0.0 {
            1.0
        } else {
            -1.0
        };
        (Some(local * sign), support)
    }
}

impl Support {
    fn new(p: DVec3, q: DVec3, x: DVec3, moving: bool, object: u32) -> Option<Support> {
        let m = (p - x).cross(q - x);
        let length = m.length();
        (length > 0.0 && length.is_finite()).then(|| Support {
            p,
            q,
            normal: m / length,
            length,
            moving,
            object,
        })
    }

    /// Whether the direction `w` (on the support's plane) lies between the directions of `p`
    /// and `q` seen from `x`.
    #[inline]
    fn spans(&self, w: DVec3, x: DVec3) -> bool {
        let (p, q) = (
            (self.p - x).normalize_or_zero(),
            (self.q - x).normalize_or_zero(),
        );
        let tol = -1e-9;
        p.cross(w).dot(self.normal) >= tol && w.cross(q).dot(self.normal) >= tol
    }
}

/// The map of the LTC lobe at the point: `M⁻¹`, `M` and `dM/dθ`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LobeMap {
    pub m_inv: DMat3,
    pub m: DMat3,
    pub m_rate: DMat3,
}

impl LobeMap {
    pub(crate) fn new(entry: &LtcEntry, rate: Option<&LtcEntry>) -> LobeMap {
        let m = entry.m_inv.inverse();
        let m_rate = rate.map_or(DMat3::ZERO, |r| -(m * r.m_inv * m));
        LobeMap {
            m_inv: entry.m_inv,
            m,
            m_rate,
        }
    }
}

/// What a light piece's visible region sets up before its rates: the meshes whose edges may
/// support it (the light, the occluders it kept) and, for a light taken face by face, that
/// face's own edges.
pub(crate) fn begin_piece(
    d: &mut DerivativeScratch,
    scene: &PreparedScene,
    pm: &PointMotion,
    x: DVec3,
    objects: impl Iterator<Item = u32>,
    light_face: Option<(u32, usize)>,
) -> bool {
    d.relevant.clear();
    d.face_supports.clear();
    let (mut any_moving, mut all_moving) = (false, true);
    for o in objects {
        let moving = scene.objects[o as usize].object == pm.motion.object;
        any_moving |= moving;
        all_moving &= moving;
        if (pm.on_moving || moving) && !d.relevant.contains(&o) {
            d.object_supports(scene, o, x, moving);
            d.relevant.push(o);
        }
    }
    if let Some((o, f)) = light_face {
        let moving = scene.objects[o as usize].object == pm.motion.object;
        if pm.on_moving || moving {
            let mesh = scene.objects[o as usize].face_pieces();
            let face = mesh.face(f);
            for k in 0..face.len() {
                let (p, q) = (face[k], face[(k + 1) % face.len()]);
                let (p, q) = (mesh.vertices[p as usize], mesh.vertices[q as usize]);
                if let Some(s) = Support::new(p, q, x, moving, o) {
                    d.face_supports.push(s);
                }
            }
        }
    }
    d.only_moving = all_moving;
    pm.on_moving || any_moving
}

/// The rates of the diffuse form factor and of the LTC lobe's (before its cosine tail is
/// mixed in) over `region` less `hole` (as the stages hold them, shading frame): the sum over
/// their edges of [`arc_rate`] / π, the hole's with the opposite sign.
#[allow(clippy::too_many_arguments)]
pub(crate) fn region_rates<R: Recorder>(
    d: &mut DerivativeScratch,
    pm: &PointMotion,
    x: DVec3,
    frame: &Frame,
    region: &PolygonLoops,
    hole: &PolygonLoops,
    lobe: Option<&LobeMap>,
    rec: &mut R,
) -> (f64, f64) {
    let (mut diffuse, mut specular) = (0.0, 0.0);
    for (poly, sign) in [(region, 1.0), (hole, -1.0)] {
        for (a, b, nu) in oriented_edges(poly) {
            let (rate, support) = d.normal_rate(pm, x, frame, a, b, nu);
            let (mut e_d, mut e_s) = (0.0, 0.0);
            match rate {
                Some(rate) => {
                    e_d = sign * arc_rate(a, b, rate) / PI;
                    if let Some(l) = lobe {
                        e_s = sign * lobe_arc_rate(l, a, b, nu, rate) / PI;
                    }
                }
                None => d.unsupported += 1,
            }
            diffuse += e_d;
            specular += e_s;
            if R::ENABLED {
                rec.moving_edge(&MovingEdge {
                    a,
                    b,
                    in_hole: sign < 0.0,
                    support,
                    normal_rate: rate.unwrap_or(DVec3::ZERO),
                    diffuse: e_d,
                    lobe: e_s,
                });
            }
        }
    }
    (diffuse, specular)
}

/// The edges `a → b` of `poly`'s loops (as the form factor takes them: loops of three vertices
/// or more, zero-length edges left out) with the unit normal `ν = a × b / |a × b|` on the
/// region's side.
fn oriented_edges(poly: &PolygonLoops) -> impl Iterator<Item = (DVec3, DVec3, DVec3)> + '_ {
    poly.loops().filter(|lp| lp.len() >= 3).flat_map(|lp| {
        (0..lp.len()).filter_map(move |k| {
            let (a, b) = (lp[(k + lp.len() - 1) % lp.len()], lp[k]);
            let w = a.cross(b);
            let s = w.length();
            (s > 0.0).then(|| (a, b, w / s))
        })
    })
}

/// [`arc_rate`] of the edge `a → b` in the LTC lobe's space: the edge maps to the arc between
/// `M⁻¹a` and `M⁻¹b` (normalised), its plane's normal to `N = Mᵀν`, which turns at
/// `Ṅ = Ṁᵀν + Mᵀν̇`.
fn lobe_arc_rate(l: &LobeMap, a: DVec3, b: DVec3, nu: DVec3, nu_rate: DVec3) -> f64 {
    let n = l.m.transpose() * nu;
    let n_rate = l.m_rate.transpose() * nu + l.m.transpose() * nu_rate;
    if n_rate == DVec3::ZERO {
        return 0.0;
    }
    let len = n.length();
    let nh = n / len;
    let u = (n_rate - nh * nh.dot(n_rate)) / len;
    let (a2, b2) = (
        (l.m_inv * a).normalize_or_zero(),
        (l.m_inv * b).normalize_or_zero(),
    );
    arc_rate(a2, b2, u)
}

/// The rate of `∫_P L(ω) z dω` over the region `P` (shading frame, above the horizon) for a
/// radiance `L` of the shading frame's directions that does not depend on θ: the sum over
/// P's edges of `∫ L z (ν̇ · ω) dl` (Gauss–Legendre, [`arc_rate_quadrature`]), each edge's ν̇
/// from its support. The environment's terms (docs/derivatives.md, "The environment").
pub(crate) fn region_rate_with(
    d: &mut DerivativeScratch,
    pm: &PointMotion,
    x: DVec3,
    frame: &Frame,
    region: &PolygonLoops,
    radiance: &dyn Fn(DVec3) -> DVec3,
) -> DVec3 {
    let mut sum = DVec3::ZERO;
    for (a, b, nu) in oriented_edges(region) {
        match d.normal_rate(pm, x, frame, a, b, nu).0 {
            Some(rate) => sum += arc_rate_quadrature(a, b, rate, radiance),
            None => d.unsupported += 1,
        }
    }
    sum
}
