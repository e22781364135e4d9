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
use crate::geometry::spherical::spherical_polygon::{edges_of, near_arc_start};
use crate::ltc::form_factor;
use glam::DVec3;

/// How far (radians) a visible vertex may lie outside the light polygon: the rounding of the
/// intersections, projections and reprojections it went through, far below any feature.
const OUTSIDE_TOLERANCE: f64 = 1e-9;

/// Whether the visible region (the part of `light` left after the set differences, both
/// clipped to the horizon, in the shading frame) lies inside `light` up to f64 rounding: every
/// vertex of its polygons inside or on `light`, and 0 ≤ F(visible) ≤ F(light) for the form
/// factors. The region is `region` less `holes` (`geometry::spherical::hole_difference`; `holes` empty
/// where it is one polygon). `f_visible` is its form factor, which the diffuse lobe has
/// computed already, and `f_region` that of `region` where known. `normals` is scratch,
/// reused between calls.
///
/// When `region` is `light` itself up to the rounding of the projection (the same vertices in
/// the same order, each within 1e-14) and its form factor is known, its vertices need no test
/// and its form factor is the light's up to rounding, far within the tolerance: the check is
/// then that the holes lie in the light and integrate to at least zero.
pub fn visible_within_light(
    light: &SphericalPolygon,
    region: &SphericalPolygon,
    holes: &SphericalPolygon,
    f_visible: f64,
    f_region: Option<f64>,
    normals: &mut Vec<(DVec3, f64)>,
) -> bool {
    let region_is_light = || {
        region.loop_count() == light.loop_count()
            && region.vertex_count() == light.vertex_count()
            && region
                .loops()
                .zip(light.loops())
                .all(|(a, b)| a.len() == b.len())
            && region
                .vertices()
                .iter()
                .zip(light.vertices())
                .all(|(a, b)| a.distance_squared(*b) <= 1e-28)
    };
    let known = f_region.filter(|_| region_is_light());
    let f_light = known.unwrap_or_else(|| form_factor(light.loops()));
    // The edge integrals' rounding, relative to the light's (a sum of a few terms of its size).
    let tol = 1e-10 * f_light.abs() + 1e-15;
    if !(f_visible >= -tol && f_visible <= f_light + tol) {
        return false;
    }
    // Most visible vertices lie strictly inside the light, and most others on its boundary.
    // For a light of one positively turning (convex) loop, inside every edge's half-space is
    // inside the light, and `contains_within`'s test of the arcs is taken here with the
    // edges' normals formed once: a sign per edge, then the same products, instead of the
    // winding number's angles, which are left to the rest.
    normals.clear();
    let convex = (light.loop_count() == 1)
        .then(|| light.loop_at(0))
        .filter(|lp| {
            lp.len() >= 3
                && edges_of(lp)
                    .zip(lp.iter().cycle().skip(2))
                    .all(|((a, b), &c)| {
                        let m = a.cross(b);
                        normals.push((m, m.length().max(f64::MIN_POSITIVE)));
                        m.dot(c) > 0.0
                    })
        });
    let normals = &normals[..];
    let inside_convex = |lp: &[DVec3], v: DVec3| {
        if normals.iter().all(|(m, _)| m.dot(v) > 0.0) {
            return true;
        }
        // `SphericalPolygon::contains_within`'s boundary test, with the normals formed once.
        edges_of(lp)
            .zip(normals)
            .any(|((a, b), &(m, len))| near_arc_start(a, b, m, len, v, OUTSIDE_TOLERANCE))
    };
    let inside = |poly: &SphericalPolygon| {
        poly.vertices().iter().all(|&v| {
            convex.is_some_and(|lp| inside_convex(lp, v))
                || light.contains_within(v, OUTSIDE_TOLERANCE)
        })
    };
    (known.is_some() || inside(region)) && inside(holes)
}

#[cfg(test)]
mod tests {
    use super::*;

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
        assert!(visible_within_light(
            &light,
            &part,
            &SphericalPolygon::new(),
            form_factor(part.loops()),
            None,
            &mut Vec::new()
        ));
        assert!(visible_within_light(
            &light,
            &light,
            &SphericalPolygon::new(),
            form_factor(light.loops()),
            None,
            &mut Vec::new()
        ));
        assert!(visible_within_light(
            &light,
            &SphericalPolygon::new(),
            &SphericalPolygon::new(),
            0.0,
            None,
            &mut Vec::new()
        ));
        // Sticking out on one side.
        let mut out = SphericalPolygon::new();
        out.push_loop(square((0.3, 0.0), 0.3));
        assert!(!visible_within_light(
            &light,
            &out,
            &SphericalPolygon::new(),
            form_factor(out.loops()),
            None,
            &mut Vec::new()
        ));
        // Inside, but the wrong way round (negative area: a hole with no loop around it).
        let mut reversed = part.clone();
        reversed.reverse_loops();
        assert!(!visible_within_light(
            &light,
            &reversed,
            &SphericalPolygon::new(),
            form_factor(reversed.loops()),
            None,
            &mut Vec::new()
        ));
        // Inside, but counted twice (more than the light).
        let mut twice = SphericalPolygon::new();
        twice.push_loop(square((0.0, 0.0), 0.45));
        twice.push_loop(square((0.0, 0.0), 0.45));
        assert!(!visible_within_light(
            &light,
            &twice,
            &SphericalPolygon::new(),
            form_factor(twice.loops()),
            None,
            &mut Vec::new()
        ));
    }

    /// A region held as the light less holes: the light's own vertices (after a projection's
    /// rounding) need no test and its form factor stands for the light's; the holes are still
    /// tested, and a hole that adds area or sticks out fails.
    #[test]
    fn a_region_that_is_the_light_less_holes() {
        let mut light = SphericalPolygon::new();
        light.push_loop(square((0.0, 0.0), 0.5));
        let mut region = light.clone();
        region.map_vertices(|v| (v * (1.0 + 1e-16)).normalize());
        let f_region = form_factor(region.loops());
        let check = |holes: &SphericalPolygon, region: &SphericalPolygon| {
            let f = form_factor(region.loops()) - form_factor(holes.loops());
            visible_within_light(
                &light,
                region,
                holes,
                f,
                Some(form_factor(region.loops())),
                &mut Vec::new(),
            )
        };
        let mut hole = SphericalPolygon::new();
        hole.push_loop(square((0.1, 0.0), 0.2));
        assert!(check(&hole, &region));
        let mut out = SphericalPolygon::new();
        out.push_loop(square((0.4, 0.0), 0.2));
        assert!(!check(&out, &region));
        let mut reversed = hole.clone();
        reversed.reverse_loops();
        assert!(!check(&reversed, &region));
        // A region that is not the light is tested vertex by vertex, its form factor given or not.
        let mut bigger = SphericalPolygon::new();
        bigger.push_loop(square((0.0, 0.0), 0.6));
        assert!(!check(&hole, &bigger));
        assert!(f_region > 0.0);
    }

    /// A non-convex light (an L) takes the winding number for every vertex: a polygon in its
    /// notch is outside it, though inside the half-spaces of most of its edges.
    #[test]
    fn a_polygon_in_the_notch_of_an_l_is_not_inside_it() {
        let d = |x: f64, y: f64| DVec3::new(x, y, 1.0).normalize();
        let mut light = SphericalPolygon::new();
        light.push_loop([
            d(0.0, 0.0),
            d(0.4, 0.0),
            d(0.4, 0.2),
            d(0.2, 0.2),
            d(0.2, 0.4),
            d(0.0, 0.4),
        ]);
        let mut inside = SphericalPolygon::new();
        inside.push_loop([d(0.05, 0.05), d(0.15, 0.05), d(0.15, 0.15), d(0.05, 0.15)]);
        assert!(visible_within_light(
            &light,
            &inside,
            &SphericalPolygon::new(),
            form_factor(inside.loops()),
            None,
            &mut Vec::new()
        ));
        let mut notch = SphericalPolygon::new();
        notch.push_loop([d(0.25, 0.25), d(0.35, 0.25), d(0.35, 0.35), d(0.25, 0.35)]);
        assert!(!visible_within_light(
            &light,
            &notch,
            &SphericalPolygon::new(),
            form_factor(notch.loops()),
            None,
            &mut Vec::new()
        ));
    }
}
