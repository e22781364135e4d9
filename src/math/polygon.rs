//! Newell's area vector of a polygon in 3-D: the one formula every module uses for a face's
//! normal and area (meshes, the BVH's face normals, the light sampler, the loaders).

use glam::DVec3;

/// Newell's area vector of the closed polygon `points` (the last point joins the first):
/// ½ Σ (p_k − c) × (p_{k+1} − c) about the vertex centroid c. Its direction is the front
/// normal (counter-clockwise seen from the front) and its length the area of a planar polygon;
/// for a bent one it is the normal of the plane onto which its projected area is largest
/// (Newell's method). Taken about the centroid so that a polygon far from the origin loses no
/// digits to its position. Zero for fewer than three points.
#[inline]
pub fn polygon_area_vector<I>(points: I) -> DVec3
where
    I: IntoIterator<Item = DVec3>,
    I::IntoIter: Clone + ExactSizeIterator,
{
    let it = points.into_iter();
    let n = it.len();
    if n < 3 {
        return DVec3::ZERO;
    }
    let c = it.clone().sum::<DVec3>() / n as f64;
    let mut rest = it.clone();
    let first = rest.next().unwrap_or(DVec3::ZERO) - c;
    let mut prev = first;
    let mut sum = DVec3::ZERO;
    for p in rest {
        let q = p - c;
        sum += prev.cross(q);
        prev = q;
    }
    sum += prev.cross(first);
    0.5 * sum
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against the shoelace area of a planar polygon in its own plane, moved far from the
    /// origin and turned: the direction is the plane's normal and the length its area.
    #[test]
    fn the_area_vector_of_a_planar_polygon_is_its_normal_times_its_area() {
        // An L shape in the xy plane: area 3 (a 2×2 square minus a unit square).
        let l = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ];
        let shoelace: f64 = (0..l.len())
            .map(|k| {
                let (a, b) = (l[k], l[(k + 1) % l.len()]);
                a.0 * b.1 - b.0 * a.1
            })
            .sum::<f64>()
            / 2.0;
        assert_eq!(shoelace, 3.0);
        let frame = crate::math::Frame::from_z(DVec3::new(1.0, 2.0, 3.0).normalize());
        let far = DVec3::new(1e6, -2e6, 3e5);
        let pts: Vec<DVec3> = l
            .iter()
            .map(|&(u, v)| far + frame.x * u + frame.y * v)
            .collect();
        // Coordinates near 2e6 carry an absolute rounding of about 2e-10: the area and the
        // normal keep that, not the 1e6-fold more an origin-relative sum would lose.
        let a = polygon_area_vector(pts.iter().copied());
        assert!((a.length() - shoelace).abs() < 1e-8, "{}", a.length());
        assert!((a.normalize() - frame.z).length() < 1e-9, "{a}");
        // Reversed, it turns around.
        let r = polygon_area_vector(pts.iter().rev().copied());
        assert!((r + a).length() < 1e-8);
        assert_eq!(polygon_area_vector([DVec3::X, DVec3::Y]), DVec3::ZERO);
    }
}
