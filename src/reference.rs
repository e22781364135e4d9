//! Brute-force Monte Carlo estimates by ray casting: the independent oracle the analytic
//! pipeline is tested against. Nothing here uses the polygon stages: lights are sampled
//! uniformly by area, visibility is a shadow ray through the BVH over all triangles.

use crate::accel::Ray;
use crate::ltc::ggx;
use crate::math::{Frame, Pcg32};
use crate::render::{Image, RenderContext, RenderSettings, subpixel_rays};
use crate::scene::{Camera, Material, Scene};
use crate::shading::ShadingPoint;
use glam::DVec3;
use rayon::prelude::*;

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
                let mut newell = DVec3::ZERO;
                for k in 0..p.len() {
                    newell += p[k].cross(p[(k + 1) % p.len()]);
                }
                let Some(n) = newell.try_normalize() else {
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
    pub fn sample(&self, rng: &mut Pcg32) -> (DVec3, DVec3, u32) {
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

/// BRDF value ρ(v, l) (diffuse + GGX with Schlick's Fresnel) for unit world directions.
pub fn brdf(material: &Material, frame: &Frame, v: DVec3, l: DVec3) -> DVec3 {
    let (vl, ll) = (frame.to_local(v), frame.to_local(l));
    if vl.z <= 0.0 || ll.z <= 0.0 {
        return DVec3::ZERO;
    }
    let mut f = material.kd / std::f64::consts::PI;
    if material.has_specular() {
        let h = (vl + ll).normalize();
        let w = ggx::schlick_weight(vl.dot(h));
        let spec = ggx::brdf_cos(vl, ll, material.alpha) / ll.z;
        f += material.ks.map(|f0| (f0 + (1.0 - f0) * w) * spec);
    }
    f
}

/// Monte Carlo estimate of the direct lighting at `sp` with `samples` area samples per light:
/// returns (mean, standard error of the mean) per channel.
pub fn direct_lighting(
    ctx: &RenderContext,
    lights: &LightSampler,
    sp: &ShadingPoint,
    material: &Material,
    samples: u32,
    rng: &mut Pcg32,
) -> (DVec3, DVec3) {
    let frame = Frame::from_normal_and_view(sp.normal, sp.view);
    let objects = &ctx.scene.objects;
    let mut mean = DVec3::ZERO;
    let mut var = DVec3::ZERO;
    for light in &lights.lights {
        let mut sum = DVec3::ZERO;
        let mut sum2 = DVec3::ZERO;
        for _ in 0..samples {
            let (y, ny, face) = light.sample(rng);
            let w = y - sp.position;
            let r2 = w.length_squared();
            if r2 == 0.0 {
                continue;
            }
            let dir = w / r2.sqrt();
            let cos_x = sp.normal.dot(dir);
            let cos_y = -ny.dot(dir);
            if cos_x <= 0.0 || cos_y <= 0.0 {
                continue;
            }
            let blocked = ctx.bvh.occluded(
                &Ray {
                    origin: sp.position,
                    dir: w,
                },
                1e-9,
                1.0 - 1e-9,
                |o, f| {
                    objects[o as usize].flags.occluder
                        && !(o == light.object && f == face)
                        && !(Some(o) == sp.object && Some(f) == sp.face)
                },
            );
            if blocked {
                continue;
            }
            let value = light.radiance
                * brdf(material, &frame, sp.view, dir)
                * (cos_x * cos_y / r2 * light.area);
            sum += value;
            sum2 += value * value;
        }
        let n = samples as f64;
        let m = sum / n;
        mean += m;
        // Variance of the mean from the sample variance.
        var += (sum2 / n - m * m).max(DVec3::ZERO) / (n - 1.0).max(1.0);
    }
    (mean, var.map(f64::sqrt))
}

/// A converged reference image and its per-pixel standard error, at the same stratified
/// sub-pixel positions as the analytic renderer (so both estimate the same quantity).
pub fn render_reference(
    ctx: &RenderContext,
    camera: &Camera,
    settings: &RenderSettings,
    samples_per_light: u32,
    seed: u64,
) -> Result<(Image, Image), String> {
    let basis = camera.basis()?;
    let lights = LightSampler::new(&ctx.scene);
    let (w, h, aa) = (settings.width, settings.height, settings.aa.max(1));
    let px: Vec<(DVec3, DVec3)> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let mut rng = Pcg32::new(seed, i as u64);
            let (mut mean, mut var) = (DVec3::ZERO, DVec3::ZERO);
            for ray in subpixel_rays(&basis, x, y, aa, w, h) {
                let Some(hit) = ctx.primary_hit(&ray) else {
                    continue;
                };
                mean += hit.emitted;
                if hit.receiver {
                    let mat = &ctx.prepared.materials[hit.point.object.unwrap_or(0) as usize];
                    let (m, e) =
                        direct_lighting(ctx, &lights, &hit.point, mat, samples_per_light, &mut rng);
                    mean += m;
                    var += e * e;
                }
            }
            let k = (aa * aa) as f64;
            (mean / k, var.map(f64::sqrt) / k)
        })
        .collect();
    let mut img = Image::new(w, h);
    let mut err = Image::new(w, h);
    for (i, (m, e)) in px.into_iter().enumerate() {
        img.pixels[i] = m;
        err.pixels[i] = e;
    }
    Ok((img, err))
}
