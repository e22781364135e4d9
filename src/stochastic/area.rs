//! Lights prepared for area sampling, the baseline of 001 Sect. 3.6.

use crate::sampling::area_light::{AreaLight, LightSampler};
use crate::scene::Scene;
use crate::shading::PreparedScene;
use crate::shading::brdf::luminance;

use super::light_set::{LightShape, light_shape};

/// Every light with its selection weight (luminance × area) and whether its faces can hide
/// each other.
#[derive(Clone, Debug, Default)]
pub struct AreaLights {
    pub lights: Vec<AreaLight>,
    pub weights: Vec<f64>,
    pub self_occluding: Vec<bool>,
    pub total_weight: f64,
}

impl AreaLights {
    pub fn new(scene: &Scene, prepared: &PreparedScene) -> Self {
        let lights = LightSampler::new(scene).lights;
        let weights: Vec<f64> = lights
            .iter()
            .map(|l| luminance(l.radiance).max(0.0) * l.area)
            .collect();
        let self_occluding = lights
            .iter()
            .map(|l| {
                prepared
                    .objects
                    .iter()
                    .find(|p| p.object == l.object)
                    .is_some_and(|p| {
                        !matches!(light_shape(p), LightShape::Convex | LightShape::Flat)
                    })
            })
            .collect();
        AreaLights {
            total_weight: weights.iter().sum(),
            lights,
            weights,
            self_occluding,
        }
    }

    /// Draws a light with `u` uniform in [0, 1): (index, probability).
    #[inline]
    pub(crate) fn pick(&self, u: f64) -> Option<(usize, f64)> {
        if self.total_weight <= 0.0 {
            return None;
        }
        let target = u * self.total_weight;
        let mut acc = 0.0;
        let mut last = None;
        for (k, &w) in self.weights.iter().enumerate() {
            if w <= 0.0 {
                continue;
            }
            acc += w;
            last = Some((k, w / self.total_weight));
            if target < acc {
                break;
            }
        }
        last
    }
}
