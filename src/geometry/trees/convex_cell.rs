//! Bounded convex polyhedra as lists of face polygons, split by planes: the cells of a BSP
//! build (001 Sect. 5.3 keeps each cell "as a list of edges" inside a large bounding box; face
//! loops carry the same information and close up without sorting edges) and the kernel of a
//! star-shaped mesh.

use crate::geometry::Plane;
use glam::DVec3;

/// A bounded convex polyhedron: its faces as vertex loops, counter-clockwise seen from outside.
/// Empty when the cell has no interior.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ConvexCell {
    pub faces: Vec<Vec<DVec3>>,
}

/// Which side of a plane a cell lies on, with the tolerance of `ConvexCell::side`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CellSide {
    Front,
    Back,
    /// The plane cuts the cell into two parts of non-zero thickness.
    Straddles,
}

impl ConvexCell {
    /// The axis-aligned box `[lo, hi]`.
    pub fn cuboid(lo: DVec3, hi: DVec3) -> ConvexCell {
        let corner = |i: u32| {
            DVec3::new(
                if i & 1 == 1 { hi.x } else { lo.x },
                if i & 2 == 2 { hi.y } else { lo.y },
                if i & 4 == 4 { hi.z } else { lo.z },
            )
        };
        let quads = [
            [0, 4, 6, 2], // −x
            [1, 3, 7, 5], // +x
            [0, 1, 5, 4], // −y
            [2, 6, 7, 3], // +y
            [0, 2, 3, 1], // −z
            [4, 5, 7, 6], // +z
        ];
        ConvexCell {
            faces: quads.iter().map(|q| q.map(corner).to_vec()).collect(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.faces.len() < 4
    }

    /// Every vertex (each once per face it belongs to).
    pub fn vertices(&self) -> impl Iterator<Item = DVec3> + '_ {
        self.faces.iter().flatten().copied()
    }

    /// The mean of the face vertices: strictly inside a cell with interior.
    pub fn centroid(&self) -> DVec3 {
        let (sum, n) = self
            .vertices()
            .fold((DVec3::ZERO, 0usize), |(s, n), p| (s + p, n + 1));
        if n == 0 { DVec3::ZERO } else { sum / n as f64 }
    }

    /// The axis-aligned bounding box (lo > hi for an empty cell).
    pub(crate) fn bounds(&self) -> (DVec3, DVec3) {
        self.vertices()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p), hi.max(p))
            })
    }

    /// The plane through `p` across the longest side of the bounding box (a bisector when `p`
    /// is central): how cells are split where no plane of the problem is at hand.
    pub(crate) fn longest_axis_plane(&self, p: DVec3) -> Plane {
        let (lo, hi) = self.bounds();
        let ext = hi - lo;
        let axis = if ext.x >= ext.y && ext.x >= ext.z {
            DVec3::X
        } else if ext.y >= ext.z {
            DVec3::Y
        } else {
            DVec3::Z
        };
        Plane {
            n: axis,
            d: axis.dot(p),
        }
    }

    /// Enclosed volume (divergence theorem over the faces, fanned from the centroid).
    pub fn volume(&self) -> f64 {
        let c = self.centroid();
        let mut v = 0.0;
        for f in &self.faces {
            for k in 1..f.len().saturating_sub(1) {
                v += (f[0] - c).dot((f[k] - c).cross(f[k + 1] - c));
            }
        }
        v / 6.0
    }

    /// Which side of `plane` the cell is on: every vertex within `tol` of the plane or on one
    /// side counts as that side.
    pub(crate) fn side(&self, plane: &Plane, tol: f64) -> CellSide {
        let (mut front, mut back) = (false, false);
        for p in self.vertices() {
            let s = plane.eval(p);
            front |= s > tol;
            back |= s < -tol;
        }
        match (front, back) {
            (true, true) => CellSide::Straddles,
            (true, false) => CellSide::Front,
            _ => CellSide::Back,
        }
    }

    /// The part of the cell on the back side of `plane` (`plane.eval ≤ 0`); points within `tol`
    /// of the plane count as on it. The new face lies in the plane, facing its front.
    pub(crate) fn clip_to_back(&self, plane: &Plane, tol: f64) -> ConvexCell {
        let mut faces = Vec::with_capacity(self.faces.len() + 1);
        let mut cap: Vec<DVec3> = Vec::new();
        for f in &self.faces {
            let mut out = Vec::with_capacity(f.len() + 1);
            for k in 0..f.len() {
                let (a, b) = (f[k], f[(k + 1) % f.len()]);
                let (sa, sb) = (plane.eval(a), plane.eval(b));
                if sa <= tol {
                    out.push(a);
                    if sa.abs() <= tol {
                        cap.push(a);
                    }
                }
                if (sa < -tol && sb > tol) || (sa > tol && sb < -tol) {
                    // A convex combination: stays between a and b whatever the rounding.
                    let t = sa / (sa - sb);
                    let p = a + (b - a) * t;
                    out.push(p);
                    cap.push(p);
                }
            }
            if out.len() >= 3 {
                faces.push(out);
            }
        }
        if let Some(c) = cap_polygon(&cap, plane.n, tol) {
            faces.push(c);
        }
        let cell = ConvexCell { faces };
        if cell.is_empty() {
            ConvexCell::default()
        } else {
            cell
        }
    }

    /// The polygon in which `plane` cuts the cell, counter-clockwise around the plane's
    /// normal: the face both parts of [`ConvexCell::split`] would share. `None` when the plane
    /// does not cut through the interior (it misses the cell or only touches it).
    pub(crate) fn plane_section(&self, plane: &Plane, tol: f64) -> Option<Vec<DVec3>> {
        if self.side(plane, tol) != CellSide::Straddles {
            return None;
        }
        let mut points = Vec::new();
        for f in &self.faces {
            for k in 0..f.len() {
                let (a, b) = (f[k], f[(k + 1) % f.len()]);
                let (sa, sb) = (plane.eval(a), plane.eval(b));
                if sa.abs() <= tol {
                    points.push(a);
                } else if (sa < -tol && sb > tol) || (sa > tol && sb < -tol) {
                    points.push(a + (b - a) * (sa / (sa - sb)));
                }
            }
        }
        cap_polygon(&points, plane.n, tol)
    }

    /// The two parts of the cell on either side of `plane`: (back, front).
    pub(crate) fn split(&self, plane: &Plane, tol: f64) -> (ConvexCell, ConvexCell) {
        let flipped = Plane {
            n: -plane.n,
            d: -plane.d,
        };
        (
            self.clip_to_back(plane, tol),
            self.clip_to_back(&flipped, tol),
        )
    }
}

/// The convex polygon through `points` (in a plane with unit normal `n`), counter-clockwise
/// around `n`; duplicates within `tol` removed. `None` with fewer than three distinct points.
fn cap_polygon(points: &[DVec3], n: DVec3, tol: f64) -> Option<Vec<DVec3>> {
    let mut pts: Vec<DVec3> = Vec::with_capacity(points.len());
    for &p in points {
        if !pts.iter().any(|q| q.distance(p) <= tol) {
            pts.push(p);
        }
    }
    if pts.len() < 3 {
        return None;
    }
    let c = pts.iter().sum::<DVec3>() / pts.len() as f64;
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    pts.sort_by(|a, b| {
        let (da, db) = (*a - c, *b - c);
        da.dot(v)
            .atan2(da.dot(u))
            .total_cmp(&db.dot(v).atan2(db.dot(u)))
    });
    Some(pts)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_volume_and_splits_add_up() {
        let cell = ConvexCell::cuboid(DVec3::splat(-1.0), DVec3::new(1.0, 2.0, 3.0));
        assert!((cell.volume() - 2.0 * 3.0 * 4.0).abs() < 1e-12);
        // A slanted plane through the box: the parts add up to the whole.
        let n = DVec3::new(1.0, 2.0, -0.5).normalize();
        let plane = Plane { n, d: 0.3 };
        assert_eq!(cell.side(&plane, 1e-12), CellSide::Straddles);
        let (back, front) = cell.split(&plane, 1e-12);
        assert!((back.volume() + front.volume() - cell.volume()).abs() < 1e-9);
        assert!(back.vertices().all(|p| plane.eval(p) <= 1e-9));
        assert!(front.vertices().all(|p| plane.eval(p) >= -1e-9));
        // Corner cut: the tetrahedron x + y + z ≥ 2.5 of the unit-offset box has a closed form.
        let corner = ConvexCell::cuboid(DVec3::ZERO, DVec3::ONE);
        let p = Plane {
            n: DVec3::ONE.normalize(),
            d: 2.5 / 3f64.sqrt(),
        };
        let (_, tip) = corner.split(&p, 1e-12);
        assert!((tip.volume() - 0.5f64.powi(3) / 6.0).abs() < 1e-12);
    }

    /// Twice the vector area of a closed polygon: its normal times twice its area.
    fn vector_area(poly: &[DVec3]) -> DVec3 {
        (0..poly.len())
            .map(|k| poly[k].cross(poly[(k + 1) % poly.len()]))
            .sum()
    }

    #[test]
    fn plane_sections_of_a_cube_have_their_closed_form_areas() {
        let (lo, hi) = (DVec3::new(-1.0, 0.0, 2.0), DVec3::new(1.0, 2.0, 4.0));
        let cell = ConvexCell::cuboid(lo, hi);
        let tol = 1e-12;
        let inside = |p: DVec3| p.cmpge(lo - 1e-12).all() && p.cmple(hi + 1e-12).all();
        // The plane through the centre normal to a main diagonal cuts a regular hexagon of
        // side √2·(edge/2): area (3√3/2)·s² = 3√3 for edge 2.
        let centre = (lo + hi) / 2.0;
        let n = DVec3::new(1.0, -1.0, 1.0).normalize();
        let hexagon = Plane {
            n,
            d: n.dot(centre),
        };
        // An axis-aligned plane cuts the 2 × 2 square; a slanted one through two opposite
        // edges a 2 × 2√2 rectangle.
        let square = Plane {
            n: DVec3::Y,
            d: 0.5,
        };
        let m = DVec3::new(0.0, 1.0, -1.0).normalize();
        let rectangle = Plane {
            n: m,
            d: m.dot(DVec3::new(0.0, 0.0, 2.0)),
        };
        for (plane, corners, area) in [
            (hexagon, 6, 3.0 * 3f64.sqrt()),
            (square, 4, 4.0),
            (rectangle, 4, 4.0 * 2f64.sqrt()),
        ] {
            let poly = cell
                .plane_section(&plane, tol)
                .expect("the plane cuts the box");
            assert_eq!(poly.len(), corners);
            for &p in &poly {
                assert!(plane.eval(p).abs() < 1e-12, "{p} off the plane");
                assert!(inside(p), "{p} outside the box");
            }
            // Counter-clockwise around the normal, with the closed-form area.
            let a = vector_area(&poly);
            assert!((a.dot(plane.n) / 2.0 - area).abs() < 1e-12, "{a}");
            // The same polygon as the face the split creates (an independent construction).
            let (back, _) = cell.split(&plane, tol);
            let cap = back
                .faces
                .iter()
                .find(|f| f.iter().all(|&p| plane.eval(p).abs() < 1e-12))
                .expect("the cut face");
            assert!((vector_area(cap).length() / 2.0 - area).abs() < 1e-12);
        }
        // Missing or touching the box: no section.
        let touching = Plane {
            n: DVec3::X,
            d: 1.0,
        };
        assert!(cell.plane_section(&touching, tol).is_none());
        let missing = Plane {
            n: DVec3::Z,
            d: 5.0,
        };
        assert!(cell.plane_section(&missing, tol).is_none());
    }

    #[test]
    fn a_plane_missing_the_cell_leaves_it_whole() {
        let cell = ConvexCell::cuboid(DVec3::ZERO, DVec3::ONE);
        let plane = Plane {
            n: DVec3::X,
            d: 2.0,
        };
        assert_eq!(cell.side(&plane, 1e-12), CellSide::Back);
        let (back, front) = cell.split(&plane, 1e-12);
        assert!((back.volume() - 1.0).abs() < 1e-12);
        assert!(front.is_empty());
        // Touching at a face: nothing on the far side.
        let touching = Plane {
            n: DVec3::X,
            d: 1.0,
        };
        assert_eq!(cell.side(&touching, 1e-12), CellSide::Back);
        assert!(cell.split(&touching, 1e-12).1.is_empty());
    }
}
