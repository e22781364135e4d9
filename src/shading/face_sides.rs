//! What of a mesh lies in front of a plane: before subtracting an occluder from a light face
//! (cut at that face's plane, `analytic::subtract_occluder`), an occluder wholly behind the
//! face is passed over and one wholly in front needs no cut.
//!
//! Counting every corner of the occluder's faces at every light face of every shading point
//! costs O(F) per light face, O(F²) per point where a light of F faces lights its own points
//! face by face. Two things remove that count without changing a decision:
//! - the mesh's bounding ball answers first when the plane misses it by more than rounding;
//! - a light's own mesh meets the plane of each of its faces, so the answer for its own faces is
//!   computed once, when the scene is prepared ([`FaceSides`]), by the same count.

use super::analytic::COPLANAR;
use crate::geometry::{FrontCut, IndexedPolyhedron, Plane};

/// Where light face `f` of `faces` cuts its occluders: at the face's own plane, with the
/// coplanarity tolerance, since what lies within rounding of the face's plane is not in front
/// of it (its `front_plane` is what the counts below test against).
#[inline]
pub(crate) fn light_face_cut(faces: &IndexedPolyhedron, f: usize) -> FrontCut {
    FrontCut {
        plane: faces.face_planes[f],
        tol: COPLANAR * faces.radius,
    }
}

/// Where the corners of a mesh's faces lie against a plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum InFront {
    /// None strictly in front.
    Nothing,
    /// Some in front, some not.
    Part,
    /// Every one strictly in front.
    All,
}

/// Where the corners of `mesh`'s faces lie against `plane` (in front: `plane.eval > 0`). The
/// bounding ball decides when the plane keeps it clear by far more than rounding; otherwise
/// every corner is counted.
pub(crate) fn in_front(mesh: &IndexedPolyhedron, plane: &Plane) -> InFront {
    let centre = plane.eval(mesh.center);
    let reach = plane.n.length() * mesh.radius;
    // Rounding of `eval` at a corner is far below this (relative 1e-12 of its terms).
    let margin = 1e-9 * (plane.n.length() * (mesh.center.length() + mesh.radius) + plane.d.abs());
    if centre - reach > margin {
        return InFront::All;
    }
    if centre + reach < -margin {
        return InFront::Nothing;
    }
    count_in_front(mesh, plane)
}

/// [`in_front`] by counting every corner of every face.
fn count_in_front(mesh: &IndexedPolyhedron, plane: &Plane) -> InFront {
    let total = mesh.face_indices.len();
    let front = mesh
        .face_indices
        .iter()
        .filter(|&&i| plane.eval(mesh.vertices[i as usize]) > 0.0)
        .count();
    match front {
        0 => InFront::Nothing,
        n if n == total => InFront::All,
        _ => InFront::Part,
    }
}

/// Per face of a light's face pieces: where the light's own mesh lies against the plane the
/// face cuts its occluders at (`plane_of(f)`).
#[derive(Clone, Debug)]
pub struct FaceSides(Vec<InFront>);

/// Corners × faces above this are left to the count at each point: the table would cost more
/// to prepare (tens of milliseconds at this bound, again at each move of the light in the
/// scene editor) than most renders spend on it.
pub(crate) const MAX_FACE_SIDE_TESTS: usize = 20_000_000;

impl FaceSides {
    /// The table for `mesh`, whose face `f` cuts at `plane_of(f)`; `None` over
    /// [`MAX_FACE_SIDE_TESTS`].
    pub(crate) fn of(mesh: &IndexedPolyhedron, plane_of: impl Fn(usize) -> Plane) -> Option<Self> {
        let faces = mesh.face_count();
        if faces.saturating_mul(mesh.face_indices.len()) > MAX_FACE_SIDE_TESTS {
            return None;
        }
        Some(FaceSides(
            (0..faces)
                .map(|f| count_in_front(mesh, &plane_of(f)))
                .collect(),
        ))
    }

    /// Where the mesh lies against face `f`'s cutting plane.
    #[inline]
    pub(crate) fn get(&self, f: usize) -> InFront {
        self.0[f]
    }
}
