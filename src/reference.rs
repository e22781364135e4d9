//! Brute-force Monte Carlo estimates by ray casting: the independent oracle the analytic
//! pipeline is tested against. Nothing here uses the polygon stages: lights are sampled
//! uniformly by area, visibility is a shadow ray through the BVH over all triangles.

use crate::accel::Ray;
use crate::ltc::ggx;
use crate::math::{Frame, Pcg32};
use crate::render::{Image, RenderContext, RenderSettings, subpixel_rays};
use crate::scene::{Camera, Material};
use crate::shading::ShadingPoint;
use glam::DVec3;
use rayon::prelude::*;

// Lights sampled uniformly by area: `sampling::area_light` (the stochastic baseline samples them
// the same way).
pub(crate) use crate::sampling::area_light::LightSampler;

/// BRDF value ρ(v, l) (diffuse + GGX with Schlick's Fresnel) for unit world directions.
pub(crate) fn brdf(material: &Material, frame: &Frame, v: DVec3, l: DVec3) -> DVec3 {
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
) -> crate::Result<(Image, Image)> {
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
