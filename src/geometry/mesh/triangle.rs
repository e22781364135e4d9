//! Watertight ray–triangle intersection (Woop, Benthin and Wald 2013, "Watertight
//! Ray/Triangle Intersection", JCGT 2(1)), in f64.
//!
//! The ray is made the +z axis of a sheared frame: translate by the origin, rotate the
//! axes so that the dominant direction component is z, shear so that the direction becomes
//! (0, 0, 1). A vertex's 2-D image `(x, y)` in that frame is a function of the vertex and the
//! ray only, not of the triangle, so every triangle sharing an edge evaluates that edge's
//! 2-D cross product from the *same* two floating-point points. With `cross(p, q)` computed
//! as `p.x*q.y - p.y*q.x`, the neighbour's value is the exact negation (IEEE multiplication
//! commutes and `a - b == -(b - a)`), so the edge can never be missed by both triangles: the
//! test is watertight for rays through edges and vertices.
//!
//! Rounding is monotone, so a computed edge value has the sign of the exact value of the
//! rounded inputs or is zero. Zeros are re-evaluated exactly with FMA error terms (the
//! paper falls back to double precision from single; f64 has no wider type, but the sign of
//! `a*b - c*d` is exact from `fl(a*b) == fl(c*d)` plus the two products' rounding errors), so
//! a ray through a vertex is claimed by exactly the triangles of its fan that contain it.
//!
//! Both sides of a triangle are hit (no culling). The paper swaps the x and y axes when the
//! dominant direction component is negative to keep the sign of the determinant tied to the
//! winding; without culling only the ratios `U/det`, `V/det`, `W/det`, `T/det` are used, which
//! do not depend on that sign, so the swap is omitted.

use glam::DVec3;

use crate::geometry::mesh::ray::Ray;

/// A hit on one triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    /// Ray parameter of the hit, in units of the ray direction.
    pub t: f64,
    /// Barycentric weights of `v0`, `v1`, `v2`: each in [0, 1], summing to 1 up to rounding.
    /// The hit point is `bary.x * v0 + bary.y * v1 + bary.z * v2`.
    pub bary: DVec3,
}

impl TriangleHit {
    /// The hit point interpolated from the vertices: it lies on the triangle to within the
    /// rounding of its coordinates, which `origin + t * dir` far from the origin does not.
    #[inline]
    pub fn point(&self, v0: DVec3, v1: DVec3, v2: DVec3) -> DVec3 {
        self.bary.x * v0 + self.bary.y * v1 + self.bary.z * v2
    }
}

/// True if the triangle has (numerically) zero area: `|e1 x e2| <= 16 eps |e1| |e2|`, i.e.
/// the sine of its widest corner angle is below about 4e-15. This catches coincident and
/// collinear vertices whatever the rounding of the edge vectors, independently of scale.
/// Such triangles are never hit.
pub fn is_degenerate(v0: DVec3, v1: DVec3, v2: DVec3) -> bool {
    let e1 = v1 - v0;
    let e2 = v2 - v0;
    let n2 = e1.cross(e2).length_squared();
    let tol = 16.0 * f64::EPSILON;
    let bound = tol * tol * e1.length_squared() * e2.length_squared();
    // NaN (from overflow of huge coordinates) counts as degenerate.
    n2.is_nan() || bound.is_nan() || n2 <= bound
}

/// Intersects `ray` with the triangle `(v0, v1, v2)` and returns the hit with
/// `t_min < t < t_max`, if any. Degenerate triangles ([`is_degenerate`]) and rays with a zero
/// direction are never hit. Never returns NaN for finite input.
///
/// For many triangles against one ray, build a [`PreparedRay`] once instead.
pub fn intersect_triangle(
    ray: &Ray,
    v0: DVec3,
    v1: DVec3,
    v2: DVec3,
    t_min: f64,
    t_max: f64,
) -> Option<TriangleHit> {
    if is_degenerate(v0, v1, v2) {
        return None;
    }
    PreparedRay::new(ray).intersect(v0, v1, v2, t_min, t_max)
}

/// The per-ray part of the watertight test: axis permutation and shear.
#[derive(Clone, Copy, Debug)]
pub struct PreparedRay {
    origin: DVec3,
    /// Index of the dominant axis of the direction (the sheared frame's z).
    kz: u8,
    sx: f64,
    sy: f64,
    sz: f64,
    valid: bool,
}

/// Raw result of the edge tests: `t` and the unnormalised barycentrics `(U, V, W)` with
/// their sum `det` (all of one sign).
#[derive(Clone, Copy, Debug)]
pub(crate) struct RawHit {
    pub t: f64,
    pub uvw: DVec3,
    pub det: f64,
}

impl RawHit {
    #[inline]
    pub(crate) fn finish(&self) -> TriangleHit {
        TriangleHit {
            t: self.t,
            bary: self.uvw / self.det,
        }
    }
}

/// Rotates `v` so that axis `kz` comes last; the other two keep their cyclic order.
#[inline(always)]
fn permute(v: DVec3, kz: u8) -> DVec3 {
    match kz {
        0 => DVec3::new(v.y, v.z, v.x),
        1 => DVec3::new(v.z, v.x, v.y),
        _ => v,
    }
}

/// `p.x * q.y - p.y * q.x`: the edge function. `cross2(q, p)` is exactly `-cross2(p, q)`.
#[inline(always)]
fn cross2(px: f64, py: f64, qx: f64, qy: f64) -> f64 {
    px * qy - py * qx
}

/// `cross2` with an exact sign, for when the plain evaluation gave zero: then the two
/// rounded products are equal and the sign is that of the difference of their rounding
/// errors, which FMA yields exactly (barring underflow). Antisymmetric like `cross2`.
#[cold]
#[inline(never)]
fn cross2_exact(px: f64, py: f64, qx: f64, qy: f64) -> f64 {
    let a = px * qy;
    let b = py * qx;
    let ea = px.mul_add(qy, -a);
    let eb = py.mul_add(qx, -b);
    (a - b) + (ea - eb)
}

impl PreparedRay {
    pub fn new(ray: &Ray) -> Self {
        let d = ray.dir;
        let a = d.abs();
        let kz: u8 = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let pd = permute(d, kz);
        let valid = pd.z != 0.0 && d.is_finite() && ray.origin.is_finite();
        // |sx|, |sy| <= 1 since z is the dominant component; sz is finite unless the
        // direction is subnormal (then t is NaN or infinite and every test rejects it).
        let (sx, sy, sz) = if valid {
            (pd.x / pd.z, pd.y / pd.z, 1.0 / pd.z)
        } else {
            (0.0, 0.0, 0.0)
        };
        PreparedRay {
            origin: ray.origin,
            kz,
            sx,
            sy,
            sz,
            valid,
        }
    }

    /// False for a zero or non-finite direction: such rays hit nothing.
    #[inline]
    pub(crate) fn is_valid(&self) -> bool {
        self.valid
    }

    /// [`intersect_triangle`] with this ray, without the degeneracy pre-test: a triangle
    /// whose image in the ray's frame has zero area is still rejected, but nearly collinear
    /// vertices may produce a hit (callers filter with [`is_degenerate`] once per triangle).
    #[inline]
    pub fn intersect(
        &self,
        v0: DVec3,
        v1: DVec3,
        v2: DVec3,
        t_min: f64,
        t_max: f64,
    ) -> Option<TriangleHit> {
        let raw = self.intersect_raw(v0, v1, v2)?;
        (raw.t > t_min && raw.t < t_max).then(|| raw.finish())
    }

    /// Edge tests and `t`, without the range test. `t` may be negative, infinite or NaN
    /// (for absurd inputs); callers test it with comparisons that reject NaN.
    #[inline(always)]
    pub(crate) fn intersect_raw(&self, v0: DVec3, v1: DVec3, v2: DVec3) -> Option<RawHit> {
        if !self.valid {
            return None;
        }
        // Vertices relative to the origin, dominant axis last.
        let a = permute(v0 - self.origin, self.kz);
        let b = permute(v1 - self.origin, self.kz);
        let c = permute(v2 - self.origin, self.kz);
        // Shear into the ray frame (x, y only; z is scaled later, only when needed).
        let ax = a.x - self.sx * a.z;
        let ay = a.y - self.sy * a.z;
        let bx = b.x - self.sx * b.z;
        let by = b.y - self.sy * b.z;
        let cx = c.x - self.sx * c.z;
        let cy = c.y - self.sy * c.z;
        // Scaled barycentrics: U opposite A (weight of v0), V of v1, W of v2.
        let mut u = cross2(cx, cy, bx, by);
        let mut v = cross2(ax, ay, cx, cy);
        let mut w = cross2(bx, by, ax, ay);
        if u == 0.0 || v == 0.0 || w == 0.0 {
            if u == 0.0 {
                u = cross2_exact(cx, cy, bx, by);
            }
            if v == 0.0 {
                v = cross2_exact(ax, ay, cx, cy);
            }
            if w == 0.0 {
                w = cross2_exact(bx, by, ax, ay);
            }
        }
        // Inside iff the three have one sign (zeros are on an edge and count as inside).
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 || !det.is_finite() {
            // Zero: the triangle's image is degenerate (the ray lies in its plane, or the
            // triangle has zero area). Not finite: overflow from absurd coordinates.
            return None;
        }
        let az = self.sz * a.z;
        let bz = self.sz * b.z;
        let cz = self.sz * c.z;
        let t = (u * az + v * bz + w * cz) / det;
        Some(RawHit {
            t,
            uvw: DVec3::new(u, v, w),
            det,
        })
    }
}
