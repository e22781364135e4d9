//! Rays.

use glam::DVec3;

/// A ray `origin + t * dir`. `dir` need not be normalised: every `t` in this module (the
/// `t_min`/`t_max` of queries and the `t` of hits) is in units of `dir`, so a shadow ray
/// `Ray { origin: p, dir: q - p }` reaches `q` at `t = 1`.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub origin: DVec3,
    pub dir: DVec3,
}

impl Ray {
    pub fn new(origin: DVec3, dir: DVec3) -> Self {
        Ray { origin, dir }
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + t * self.dir
    }
}
