//! The invariant of a shadow (docs/analytic-pipeline.md, "The invariant"): what a point sees of
//! a light is part of the light. Per light piece, the visible polygon after the set differences
//! lies inside the horizon-clipped light polygon, and so its cosine-weighted solid angle (the
//! form factor, Eq. 000-5 with a constant kernel) is between 0 and the light's. Shadowed ≤
//! unshadowed follows for every lobe, since the LTC integrands are non-negative.
//!
//! A set difference that adds area (a loop of the wrong orientation, an occluder subtracted as
//! its complement, a face folded over itself) breaks it. The renderer counts the pieces that do
//! (`ShadingStats::violations`, summed by `render`, `bench` and `stress`); a count above zero
//! is a bug, never a tolerance to widen.

use crate::geometry::SphericalPolygon;
use crate::ltc::form_factor;

/// How far (radians) a visible vertex may lie outside the light polygon: the rounding of the
/// intersections, projections and reprojections it went through, far below any feature.
const OUTSIDE_TOLERANCE: f64 = 1e-9;

/// Whether `visible` (the part of `light` left after the set differences, both clipped to the
/// horizon, in the shading frame) lies inside `light` up to f64 rounding: every vertex of it
/// inside or on `light`, and 0 ≤ F(visible) ≤ F(light) for the form factors.
pub fn visible_within_light(light: &SphericalPolygon, visible: &SphericalPolygon) -> bool {
    let f_light = form_factor(light.loops());
    let f_visible = form_factor(visible.loops());
    // The edge integrals' rounding, relative to the light's (a sum of a few terms of its size).
    let tol = 1e-10 * f_light.abs() + 1e-15;
    if !(f_visible >= -tol && f_visible <= f_light + tol) {
        return false;
    }
    visible
        .vertices()
        .iter()
        .all(|&v| light.contains_within(v, OUTSIDE_TOLERANCE))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn square(c: (f64, f64), r: f64) -> Vec<DVec3> {
        [(-r, -r), (r, -r), (r, r), (-r, r)]
            .iter()
            .map(|&(x, y)| DVec3::new(c.0 + x, c.1 + y, 1.0).normalize())
            .collect()
    }

    #[test]
    fn a_part_of_the_light_passes_and_more_than_it_does_not() {
        let mut light = SphericalPolygon::new();
        light.push_loop(square((0.0, 0.0), 0.5));
        let mut part = SphericalPolygon::new();
        part.push_loop(square((0.2, 0.0), 0.3));
        assert!(visible_within_light(&light, &part));
        assert!(visible_within_light(&light, &light));
        assert!(visible_within_light(&light, &SphericalPolygon::new()));
        // Sticking out on one side.
        let mut out = SphericalPolygon::new();
        out.push_loop(square((0.3, 0.0), 0.3));
        assert!(!visible_within_light(&light, &out));
        // Inside, but the wrong way round (negative area: a hole with no loop around it).
        let mut reversed = part.clone();
        reversed.reverse_loops();
        assert!(!visible_within_light(&light, &reversed));
        // Inside, but counted twice (more than the light).
        let mut twice = SphericalPolygon::new();
        twice.push_loop(square((0.0, 0.0), 0.45));
        twice.push_loop(square((0.0, 0.0), 0.45));
        assert!(!visible_within_light(&light, &twice));
    }
}
