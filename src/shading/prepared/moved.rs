//! A prepared scene after one object moved rigidly, without preparing it again.

use super::instances::instance_map;
use super::mesh_forms::{FanMesh, StandIn};
use super::mesh_path::MeshPath;
use super::report::PrepareNote;
use super::{PreparedScene, scene_box, unseparated, without_vertex_rule};
use crate::EditError;
use crate::geometry::{IndexedPolyhedron, separating_plane, star_centre};
use crate::scene::Scene;
use glam::DVec3;
use std::sync::Arc;

/// What [`PreparedScene::with_moved_object`] reused.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MoveReuse {
    /// The object is neither a light nor an occluder: nothing of it is prepared.
    #[default]
    NotPrepared,
    /// Its trees (and hull, star centre, triangulations) were kept, under a new map into
    /// the trees' frame.
    Trees,
    /// It had no tree; its mesh data were prepared again (`Polyhedron::new`).
    NoTree,
    /// Its new vertices are not an affine image (positive determinant) of its old ones: it
    /// was prepared alone, without trees (its silhouette is computed at each point).
    Alone,
}

impl PreparedScene {
    /// The prepared scene of `scene`, a copy of the scene `self` was prepared from in which
    /// object `index` moved rigidly (any affine map of positive determinant will do), without
    /// preparing it again: every other object's data are copied (their trees, triangulations
    /// and mesh hierarchies are `Arc`-shared), and the moved object keeps its trees, which
    /// work in their own frame: its `to_tree` becomes the old map after the inverse motion
    /// (001 Sect. 5.4, as for instances), its star centre moves with it, and a convex hull
    /// standing in for it is moved, not recomputed. Only its `Polyhedron` (face planes,
    /// adjacency, face hierarchy: world-frame data) is built again from its new vertices,
    /// and the separating planes of its light–occluder pairs are found again.
    ///
    /// The trees stay valid wherever the moved object goes, but they cover the box they were
    /// built over (the old scene's bounds in the object's old frame): shading points outside
    /// it take the silhouette computed at the point (same result, slower). Re-prepare the
    /// scene ([`PreparedScene::prepare`]) when an edit is done to give it trees over its new
    /// bounds.
    ///
    /// Falls back to preparing the object alone, without trees, when its new vertices are
    /// not an affine image of its old ones (another mesh, a mirror image, or a flat mesh,
    /// which has no tree anyway). An error when `index` is out of range or the scene has
    /// another object count.
    pub fn with_moved_object(
        &self,
        scene: &Scene,
        index: usize,
    ) -> crate::Result<(PreparedScene, MoveReuse)> {
        let count = scene.objects.len();
        if index >= count {
            return Err(EditError::ObjectOutOfRange { index, count }.into());
        }
        if count != self.materials.len() {
            return Err(crate::Error::from(format!(
                "the scene has {count} objects, the prepared scene {}",
                self.materials.len()
            )));
        }
        let mut out = self.clone();
        out.materials = scene.objects.iter().map(|o| o.material.clone()).collect();
        out.bounds = scene_box(scene);
        out.trees_built = 0;
        let Some(p) = self.objects.iter().position(|o| o.object == index as u32) else {
            return Ok((out, MoveReuse::NotPrepared));
        };
        let obj = &scene.objects[index];
        let old = &self.objects[p];
        // The mesh's topology is kept when the move leaves it alone (the usual case).
        let mesh = old
            .faces()
            .moved(&obj.mesh.positions)
            .unwrap_or_else(|| IndexedPolyhedron::new(&obj.mesh.positions, &obj.mesh.faces));
        if mesh.face_count() == 0 {
            return Err(crate::Error::from(format!(
                "object '{}' has no usable face after the move",
                obj.name
            )));
        }
        let had_tree = old.path.tree().is_some();
        let map = instance_map(old.faces(), &mesh);
        // The fan keeps its triangles under the move too (no new adjacency per drag frame).
        let fan = match &old.fan {
            Some(f) => f
                .poly
                .moved(&obj.mesh.positions)
                .map(|poly| FanMesh {
                    poly: Arc::new(poly),
                    face_of: f.face_of.clone(),
                })
                .or_else(|| FanMesh::of(&obj.mesh)),
            None => FanMesh::of(&obj.mesh),
        };
        let reuse;
        {
            let o = &mut out.objects[p];
            o.fan = fan;
            match map {
                Some(m) => {
                    // The trees work in their own frame: only the map into it changes, and a
                    // hull standing in is moved with the mesh, not computed again.
                    let (poly, stand_in) = match old.stand_in() {
                        None => (mesh, None),
                        Some(s) => {
                            let vertices: Vec<DVec3> = old
                                .poly
                                .vertices
                                .iter()
                                .map(|&v| m.transform_point3(v))
                                .collect();
                            let faces: Vec<Vec<u32>> = (0..old.poly.face_count())
                                .map(|f| old.poly.face(f).to_vec())
                                .collect();
                            let stand_in = StandIn {
                                mesh: Arc::new(mesh),
                                ..s.clone()
                            };
                            (IndexedPolyhedron::new(&vertices, &faces), Some(stand_in))
                        }
                    };
                    o.path = MeshPath::decide(&poly, stand_in, old.path.tree().cloned());
                    o.poly = poly;
                    let back = m.inverse();
                    o.to_tree = Some(match old.to_tree {
                        Some(t) => t * back,
                        None => back,
                    });
                    o.star_centre = old.star_centre.map(|c| m.transform_point3(c));
                    reuse = if had_tree {
                        MoveReuse::Trees
                    } else {
                        MoveReuse::NoTree
                    };
                }
                None => {
                    let (poly, stand_in) = StandIn::of(mesh, obj.mesh.rounding);
                    let d = poly.diagnostics;
                    o.star_centre = (old.star_centre.is_some() && !d.convex && d.closed_manifold)
                        .then(|| star_centre(&poly))
                        .flatten();
                    o.path = MeshPath::decide(&poly, stand_in, None);
                    o.poly = poly;
                    o.to_tree = None;
                    o.triangulation = None;
                    reuse = MoveReuse::Alone;
                    if had_tree {
                        out.report.push(PrepareNote::TreesDroppedByMove {
                            object: o.name.clone(),
                        });
                    }
                }
            }
            if self.one_ray_per_piece {
                without_vertex_rule(&mut o.poly);
            }
            if out.lights.iter().any(|&(l, _)| l as usize == p) {
                o.face_sides = o.light_face_sides();
            }
        }
        // The separating planes of the moved object's pairs, and the notes of every pair.
        let n_occ = out.occluders.len();
        for (li, &(l, _)) in out.lights.iter().enumerate() {
            for (oi, &oc) in out.occluders.iter().enumerate() {
                if (l as usize != p && oc as usize != p) || l == oc {
                    continue;
                }
                out.separations[li * n_occ + oi] = separating_plane(
                    &out.objects[oc as usize].poly,
                    &out.objects[l as usize].poly,
                );
            }
        }
        out.report
            .notes
            .retain(|n| !matches!(n, PrepareNote::NotSeparated { .. }));
        let pairs: Vec<(u32, u32)> =
            unseparated(&out.lights, &out.occluders, &out.separations).collect();
        for (l, oc) in pairs {
            out.report.push(PrepareNote::NotSeparated {
                light: out.objects[l as usize].name.clone(),
                occluder: out.objects[oc as usize].name.clone(),
            });
        }
        Ok((out, reuse))
    }
}
