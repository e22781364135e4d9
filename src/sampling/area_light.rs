//! Lights sampled uniformly by area: the sampling of the ray-cast reference (`reference`) and
//! of the area-sampling baseline (001 Sect. 3.6, `stochastic::area`).

use crate::math::Pcg32;
use crate::scene::Scene;
use glam::DVec3;

/// A triangle of a light, for area sampling.
#[derive(Clone, Copy, Debug)]
struct LightTriangle {
    v: [DVec3; 3],
    /// Unit normal of the face's front side.
    n: DVec3,
    face: u32,
}

/// One light sampled uniformly by area.
#[derive(Clone, Debug)]
pub struct AreaLight {
    pub object: u32,
    pub radiance: DVec3,
    pub area: f64,
    tris: Vec<LightTriangle>,
    /// Cumulative areas of `tris`.
    cdf: Vec<f64>,
}

/// All lights of a scene, prepared for area sampling.
#[derive(Clone, Debug)]
pub struct LightSampler {
    pub lights: Vec<AreaLight>,
}

impl LightSampler {
    pub fn new(scene: &Scene) -> Self {
        let mut lights = Vec::new();
        for (i, obj) in scene.objects.iter().enumerate() {
            if !(obj.flags.light && obj.material.is_emissive()) {
                continue;
            }
            let m = &obj.mesh;
            let mut tris = Vec::new();
            let mut cdf = Vec::new();
            let mut area = 0.0;
            for (f, face) in m.faces.iter().enumerate() {
                let p: Vec<DVec3> = face.iter().map(|&k| m.positions[k as usize]).collect();
                let Some(n) = crate::math::polygon_area_vector(p.iter().copied()).try_normalize()
                else {
                    continue;
                };
                for k in 1..p.len().saturating_sub(1) {
                    let a = 0.5 * (p[k] - p[0]).cross(p[k + 1] - p[0]).length();
                    if a > 0.0 {
                        area += a;
                        tris.push(LightTriangle {
                            v: [p[0], p[k], p[k + 1]],
                            n,
                            face: f as u32,
                        });
                        cdf.push(area);
                    }
                }
            }
            if area > 0.0 {
                lights.push(AreaLight {
                    object: i as u32,
                    radiance: obj.material.ke,
                    area,
                    tris,
                    cdf,
                });
            }
        }
        LightSampler { lights }
    }
}

impl AreaLight {
    /// A uniform point on the light's surface: (point, front normal, face).
    pub(crate) fn sample(&self, rng: &mut Pcg32) -> (DVec3, DVec3, u32) {
        let u = rng.next_f64() * self.area;
        let k = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.tris.len() - 1);
        let t = &self.tris[k];
        let (mut a, mut b) = (rng.next_f64(), rng.next_f64());
        if a + b > 1.0 {
            a = 1.0 - a;
            b = 1.0 - b;
        }
        (
            t.v[0] + (t.v[1] - t.v[0]) * a + (t.v[2] - t.v[0]) * b,
            t.n,
            t.face,
        )
    }
}
