//! Images of a scene: camera rays, the shading point of each hit, tiles in parallel.

pub mod compare;
pub mod image_io;

use crate::accel::{Bvh, Ray};
use crate::scene::camera::CameraBasis;
use crate::scene::{Camera, Scene};
use crate::shading::{
    Method, NoRecorder, PreparedScene, Recorder, ShadingPoint, ShadingScratch, shade,
};
use glam::DVec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// A linear-radiance image, row 0 at the top.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<DVec3>,
}

impl Image {
    pub fn new(width: u32, height: u32) -> Self {
        Image {
            width,
            height,
            pixels: vec![DVec3::ZERO; width as usize * height as usize],
        }
    }

    #[inline]
    pub fn at(&self, x: u32, y: u32) -> DVec3 {
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// Pixels as f32 triples, for the image writers.
    pub fn to_rgb32(&self) -> Vec<[f32; 3]> {
        self.pixels
            .iter()
            .map(|p| [p.x as f32, p.y as f32, p.z as f32])
            .collect()
    }

    /// Counts of (NaN, infinite, negative) pixel channels.
    pub fn invalid_counts(&self) -> (usize, usize, usize) {
        let mut c = (0, 0, 0);
        for p in &self.pixels {
            for v in p.to_array() {
                if v.is_nan() {
                    c.0 += 1;
                } else if v.is_infinite() {
                    c.1 += 1;
                } else if v < 0.0 {
                    c.2 += 1;
                }
            }
        }
        c
    }
}

/// The camera rays of pixel (x, y): `aa`×`aa` stratified positions at the centres of the
/// sub-pixel cells, averaged with a box filter by every renderer (analytic and reference alike).
pub fn subpixel_rays(
    basis: &CameraBasis,
    x: u32,
    y: u32,
    aa: u32,
    width: u32,
    height: u32,
) -> impl Iterator<Item = Ray> + '_ {
    (0..aa * aa).map(move |k| {
        let (sx, sy) = (k % aa, k / aa);
        let px = x as f64 + (sx as f64 + 0.5) / aa as f64;
        let py = y as f64 + (sy as f64 + 0.5) / aa as f64;
        Ray {
            origin: basis.eye,
            dir: basis.direction(px, py, width, height),
        }
    })
}

/// Settings of `penumbra render`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// `aa`×`aa` stratified sub-pixel positions per pixel, averaged with a box filter.
    pub aa: u32,
    pub method: Method,
}

/// Timing of a render.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RenderStats {
    pub seconds: f64,
    pub pixels_per_second: f64,
}

/// A scene ready to render: the scene, its prepared shading data and its BVH.
pub struct RenderContext<'a> {
    pub scene: &'a Scene,
    pub prepared: PreparedScene,
    pub bvh: Bvh,
}

/// What a camera ray sees first: the shading point and the radiance emitted toward the eye.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrimaryHit {
    pub point: ShadingPoint,
    pub emitted: DVec3,
    pub receiver: bool,
}

impl<'a> RenderContext<'a> {
    pub fn new(scene: &'a Scene) -> Self {
        RenderContext {
            scene,
            prepared: PreparedScene::new(scene),
            bvh: Bvh::build(scene),
        }
    }

    /// The first surface along `ray`, as a shading point with the geometric normal turned toward
    /// the viewer (two-sided shading). Shared by the renderer and the workbench's pick.
    pub fn primary_hit(&self, ray: &Ray) -> Option<PrimaryHit> {
        let hit = self.bvh.intersect(ray, 0.0, f64::INFINITY)?;
        let obj = &self.scene.objects[hit.object as usize];
        let view = (-ray.dir).normalize();
        let front = hit.geometric_normal.dot(view) > 0.0;
        let normal = if front {
            hit.geometric_normal
        } else {
            -hit.geometric_normal
        };
        // Lights emit from the front side of their faces only.
        let emitted = if obj.flags.light && front {
            obj.material.ke
        } else {
            DVec3::ZERO
        };
        Some(PrimaryHit {
            point: ShadingPoint {
                position: hit.point,
                normal,
                view,
                object: Some(hit.object),
                face: Some(hit.face),
            },
            emitted,
            receiver: obj.flags.receiver,
        })
    }

    /// Radiance toward the eye along a camera ray: emission plus direct lighting.
    pub fn radiance<R: Recorder>(
        &self,
        ray: &Ray,
        method: Method,
        scratch: &mut ShadingScratch,
        rec: &mut R,
    ) -> DVec3 {
        let Some(hit) = self.primary_hit(ray) else {
            return DVec3::ZERO;
        };
        let mut l = hit.emitted;
        if hit.receiver {
            let material = &self.prepared.materials[hit.point.object.unwrap_or(0) as usize];
            l += shade(&self.prepared, &hit.point, material, method, scratch, rec);
        }
        l
    }

    /// Renders the image seen by `camera`; tiles run in parallel. Stops early (leaving the rest
    /// black) when `cancel` becomes true.
    pub fn render(
        &self,
        camera: &Camera,
        settings: &RenderSettings,
        cancel: Option<&AtomicBool>,
    ) -> Result<(Image, RenderStats), String> {
        let basis = camera.basis()?;
        if settings.width == 0 || settings.height == 0 || settings.aa == 0 {
            return Err("image size and --aa must be positive".into());
        }
        let start = Instant::now();
        let (w, h) = (settings.width, settings.height);
        const TILE: u32 = 16;
        let tiles_x = w.div_ceil(TILE);
        let tiles_y = h.div_ceil(TILE);
        let aa = settings.aa;
        let inv = 1.0 / (aa * aa) as f64;
        let tiles: Vec<(u32, Vec<DVec3>)> = (0..tiles_x * tiles_y)
            .into_par_iter()
            .map_init(ShadingScratch::default, |scratch, t| {
                let (tx, ty) = (t % tiles_x, t / tiles_x);
                let (x0, y0) = (tx * TILE, ty * TILE);
                let (x1, y1) = ((x0 + TILE).min(w), (y0 + TILE).min(h));
                let mut out = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
                // A cancelled tile comes back empty and stays black.
                if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
                    return (t, out);
                }
                for y in y0..y1 {
                    for x in x0..x1 {
                        let mut sum = DVec3::ZERO;
                        for ray in subpixel_rays(&basis, x, y, aa, w, h) {
                            sum += self.radiance(&ray, settings.method, scratch, &mut NoRecorder);
                        }
                        out.push(sum * inv);
                    }
                }
                (t, out)
            })
            .collect();
        let mut img = Image::new(w, h);
        for (t, px) in tiles {
            let (tx, ty) = (t % tiles_x, t / tiles_x);
            let (x0, y0) = (tx * TILE, ty * TILE);
            let x1 = (x0 + TILE).min(w);
            let tw = (x1 - x0) as usize;
            for (i, p) in px.into_iter().enumerate() {
                let (x, y) = (x0 + (i % tw) as u32, y0 + (i / tw) as u32);
                img.pixels[(y * w + x) as usize] = p;
            }
        }
        let seconds = start.elapsed().as_secs_f64();
        Ok((
            img,
            RenderStats {
                seconds,
                pixels_per_second: (w * h) as f64 / seconds.max(1e-12),
            },
        ))
    }
}
