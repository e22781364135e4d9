//! Run time against geometric complexity (000 Fig. 5 and Fig. 7).
//!
//! * Fig. 5: the 000 Fig. 4 scene with every light (or every occluder) duplicated k times at
//!   new places; the analytic method's time against the number of light (occluder) vertices,
//!   fitted with a line (slope, R²).
//! * Fig. 7: one icosahedral light over a specular floor, no occluders, subdivided repeatedly;
//!   the silhouette path against the naive per-face extension of 000 Sect. 4.3 (every front
//!   face an LTC polygon on its own: our per-triangle method, which without occluders is
//!   exactly that).
//!
//! Scenes are built in code from `scene::shapes`, so the run needs no files.

use super::fit::{LineFit, fit_line};
use crate::render::{RenderContext, RenderMethod, RenderSettings};
use crate::scene::{Camera, Material, ObjectFlags, Scene, SceneObject, shapes};
use crate::shading::PrepareConfig;
use glam::DVec3;

/// One timed render of a scaling series.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct ScalingPoint {
    pub series: String,
    pub method: String,
    /// Copies (Fig. 5) or subdivision level (Fig. 7).
    pub step: u32,
    pub light_vertices: usize,
    pub occluder_vertices: usize,
    /// Best of the repeats.
    pub seconds: f64,
}

/// A straight-line fit of one series: time against the vertex count that varies.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct ScalingFit {
    pub series: String,
    pub method: String,
    /// "light_vertices" or "occluder_vertices".
    pub x: String,
    /// Seconds per vertex.
    pub slope: f64,
    pub intercept: f64,
    pub r2: f64,
}

/// Everything the scaling run produces.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct ScalingReport {
    pub width: u32,
    pub height: u32,
    pub points: Vec<ScalingPoint>,
    pub fits: Vec<ScalingFit>,
    /// Fig. 7: slope of the naive per-face method over the silhouette method's slope.
    pub naive_over_silhouette_slope: Option<f64>,
}

fn vertices(scene: &Scene, pick: impl Fn(&SceneObject) -> bool) -> usize {
    scene
        .objects
        .iter()
        .filter(|o| pick(o))
        .map(|o| o.mesh.positions.len())
        .sum()
}

fn is_light(o: &SceneObject) -> bool {
    o.flags.light && o.material.is_emissive()
}

fn is_occluder(o: &SceneObject) -> bool {
    o.flags.occluder && !is_light(o)
}

/// `base` with every object that `pick` selects copied `copies − 1` more times, copy j moved by
/// j·`offset` (000 Fig. 5: "duplicate each light source and occluder and place them at a new
/// location").
pub(crate) fn duplicated(
    base: &Scene,
    copies: u32,
    offset: DVec3,
    pick: impl Fn(&SceneObject) -> bool,
) -> Scene {
    let mut scene = base.clone();
    for j in 1..copies {
        for o in base.objects.iter().filter(|o| pick(o)) {
            let mut c = o.clone();
            c.name = format!("{}_{j}", o.name);
            c.mesh = o.mesh.translated(offset * j as f64);
            scene.objects.push(c);
        }
    }
    scene
}

/// 000 Fig. 7's scene: an icosahedral light subdivided `level` times (12, 42, 162, 642, …
/// vertices) above a glossy floor, no occluders.
pub(crate) fn icosahedral_light_scene(level: u32) -> Scene {
    let floor = SceneObject {
        name: "floor".into(),
        mesh: shapes::quad(
            DVec3::ZERO,
            DVec3::new(6.0, 0.0, 0.0),
            DVec3::new(0.0, 0.0, -6.0),
        ),
        material: Material {
            name: "glossy_floor".into(),
            kd: DVec3::splat(0.2),
            ks: DVec3::splat(0.6),
            alpha: 0.2,
            ke: DVec3::ZERO,
        },
        flags: ObjectFlags {
            light: false,
            occluder: false,
            receiver: true,
            is_static: false,
        },
    };
    let light = SceneObject {
        name: "icosahedral_light".into(),
        mesh: shapes::icosphere(DVec3::new(0.0, 1.2, 0.0), 0.5, level),
        material: Material {
            name: "emitter".into(),
            kd: DVec3::ZERO,
            ks: DVec3::ZERO,
            alpha: 1.0,
            ke: DVec3::splat(4.0),
        },
        flags: ObjectFlags {
            light: true,
            occluder: false,
            receiver: false,
            is_static: false,
        },
    };
    Scene {
        objects: vec![floor, light],
        camera: Some(Camera {
            eye: DVec3::new(0.0, 2.5, 5.0),
            target: DVec3::new(0.0, 0.4, 0.0),
            up: DVec3::Y,
            fov_deg: 45.0,
            aspect: None,
        }),
        warnings: Vec::new(),
        environment: None,
    }
}

/// Best of `repeats` timed renders.
fn time_render(
    scene: &Scene,
    method: RenderMethod,
    width: u32,
    height: u32,
    repeats: u32,
    prepare: &PrepareConfig,
) -> crate::Result<f64> {
    let ctx = RenderContext::configured(std::sync::Arc::new(scene.clone()), prepare);
    let cam = scene.camera.ok_or("the scene has no camera")?;
    let settings = RenderSettings {
        width,
        height,
        method,
        ..RenderSettings::default()
    };
    let mut best = f64::INFINITY;
    for _ in 0..repeats.max(1) {
        let (_, stats) = ctx.render(&cam, &settings, None)?;
        best = best.min(stats.seconds);
    }
    Ok(best)
}

fn fit_series(points: &[ScalingPoint], series: &str, method: &str, x: &str) -> Option<ScalingFit> {
    let xy: Vec<(f64, f64)> = points
        .iter()
        .filter(|p| p.series == series && p.method == method)
        .map(|p| {
            let v = if x == "light_vertices" {
                p.light_vertices
            } else {
                p.occluder_vertices
            };
            (v as f64, p.seconds)
        })
        .collect();
    let LineFit {
        slope,
        intercept,
        r_squared: r2,
        ..
    } = fit_line(&xy)?;
    Some(ScalingFit {
        series: series.into(),
        method: method.into(),
        x: x.into(),
        slope,
        intercept,
        r2,
    })
}

/// What the scaling study runs.
#[derive(Clone, Debug, Default)]
pub struct ScalingConfig {
    /// Fig. 5 duplicates the lights, then the occluders, up to this many copies.
    pub max_copies: u32,
    /// Fig. 7 subdivides the light up to this level.
    pub max_level: u32,
    pub width: u32,
    pub height: u32,
    /// Each render is timed as the best of this many.
    pub repeats: u32,
    /// How the scenes are prepared (the tree cache).
    pub prepare: PrepareConfig,
}

/// Runs Fig. 5 on `fig5_base` and Fig. 7 as `config` says. `progress(message)` is called
/// before every render.
pub fn run_scaling(
    fig5_base: &Scene,
    config: &ScalingConfig,
    mut progress: impl FnMut(&str),
) -> crate::Result<ScalingReport> {
    let ScalingConfig {
        max_copies,
        max_level,
        width,
        height,
        repeats,
        ref prepare,
    } = *config;
    let mut report = ScalingReport {
        width,
        height,
        ..ScalingReport::default()
    };
    let analytic = RenderMethod::Analytic;
    // Fig. 5: copies side by side along −z, behind the originals, clear of each other.
    let offset = DVec3::new(0.0, 0.0, -1.2);
    for (series, pick) in [
        ("fig5_lights", is_light as fn(&SceneObject) -> bool),
        ("fig5_occluders", is_occluder as fn(&SceneObject) -> bool),
    ] {
        for k in 1..=max_copies {
            let scene = duplicated(fig5_base, k, offset, pick);
            progress(&format!("{series}: {k} copies"));
            report.points.push(ScalingPoint {
                series: series.into(),
                method: analytic.name().into(),
                step: k,
                light_vertices: vertices(&scene, is_light),
                occluder_vertices: vertices(&scene, is_occluder),
                seconds: time_render(&scene, analytic, width, height, repeats, prepare)?,
            });
        }
    }
    // Fig. 7.
    for level in 0..=max_level {
        let scene = icosahedral_light_scene(level);
        for method in [RenderMethod::Analytic, RenderMethod::PerTriangle] {
            progress(&format!("fig7: level {level}, {}", method.name()));
            report.points.push(ScalingPoint {
                series: "fig7".into(),
                method: method.name().into(),
                step: level,
                light_vertices: vertices(&scene, is_light),
                occluder_vertices: 0,
                seconds: time_render(&scene, method, width, height, repeats, prepare)?,
            });
        }
    }
    let pts = &report.points;
    report.fits = [
        fit_series(pts, "fig5_lights", "analytic", "light_vertices"),
        fit_series(pts, "fig5_occluders", "analytic", "occluder_vertices"),
        fit_series(pts, "fig7", "analytic", "light_vertices"),
        fit_series(pts, "fig7", "per-triangle", "light_vertices"),
    ]
    .into_iter()
    .flatten()
    .collect();
    let slope = |m: &str| {
        report
            .fits
            .iter()
            .find(|f| f.series == "fig7" && f.method == m)
            .map(|f| f.slope)
    };
    report.naive_over_silhouette_slope = match (slope("per-triangle"), slope("analytic")) {
        (Some(n), Some(s)) if s > 0.0 => Some(n / s),
        _ => None,
    };
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn icosahedral_light_vertex_counts_follow_subdivision() {
        // V = 10·4^k + 2 for an icosphere subdivided k times.
        for k in 0..4 {
            let s = icosahedral_light_scene(k);
            assert_eq!(vertices(&s, is_light), 10 * 4usize.pow(k) + 2);
        }
    }

    #[test]
    fn duplicates_multiply_the_selected_vertices_only() {
        let base = icosahedral_light_scene(1);
        let s = duplicated(&base, 3, DVec3::X * 2.0, is_light);
        assert_eq!(vertices(&s, is_light), 3 * vertices(&base, is_light));
        assert_eq!(s.objects.len(), base.objects.len() + 2);
    }
}
