//! The real-mesh family of `penumbra stress` (`--family real-meshes`): the meshes of the
//! scenes Blender wrote (`tests/data/blender`, OBJ and glTF) and the Stanford bunny, shaded
//! where a render shades them.
//!
//! Cases come in groups of [`GROUP`]. A group draws a mesh, a perturbation of its vertices
//! (none, or uniform in ±ε·r per coordinate for ε from 1e-7 to 1e-3 of its bounding radius r,
//! written out with 17 digits and read back through the OBJ loader, so that the faces it bends
//! are repaired as a file's would be), a role (an occluder under a random quad light, or the
//! light itself where [`RealMesh::can_be_light`]) and a floor below or through it, and prepares that scene once (without trees, without the
//! disk cache). Each case of the group then draws a camera around the mesh, an image size and a
//! pixel with a sub-pixel position, and shades the point its camera ray hits first, as the
//! renderer does ([`RenderContext::primary_hit`]). The oracle is the one of every family:
//! stratified cosine-weighted rays through the group's BVH.

use super::{Outcome, evaluate, object};
use crate::bench::realworld::{BLENDER_SCENES, source_path};
use crate::math::{Frame, Pcg32};
use crate::render::RenderContext;
use crate::scene::shapes::quad;
use crate::scene::{Camera, Mesh, Scene};
use crate::shading::{PrepareOptions, ShadingPoint, ShadingScratch};
use glam::DVec3;
use std::sync::Arc;

/// Cases per prepared scene.
pub const GROUP: u64 = 256;

/// The perturbations, relative to the mesh's bounding radius.
pub const PERTURBATIONS: [f64; 6] = [0.0, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3];

/// Camera rays tried per case before it gives up finding a surface (counted as a miss).
const TRIES: u32 = 16;

/// One mesh of the family: where it comes from and the mesh as its file gives it.
#[derive(Clone, Debug)]
pub struct RealMesh {
    /// `FILE:OBJECT`.
    pub name: String,
    pub mesh: Mesh,
    /// It may take the light's role: closed (its exact silhouette), or open with at most
    /// `MAX_OPEN_LIGHT_FACES` faces. An open light is taken face by face, each face
    /// hidden by the mesh's own faces in front of it, which costs about the product of its
    /// face count and the faces in each face's cone per point: Blender's monkey (7,872 faces)
    /// takes about 1.5 s a point that way, over the family's 1 s bound for a case.
    pub can_be_light: bool,
}

/// Open meshes with more faces than this are not lights in the family (see
/// [`RealMesh::can_be_light`]).
pub(crate) const MAX_OPEN_LIGHT_FACES: usize = 2_000;

/// Whether every edge of `mesh` is shared by exactly two faces.
fn is_closed(mesh: &Mesh) -> bool {
    let mut edges: std::collections::HashMap<(u32, u32), u32> = Default::default();
    for f in &mesh.faces {
        for k in 0..f.len() {
            let (a, b) = (f[k], f[(k + 1) % f.len()]);
            *edges.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    edges.values().all(|&n| n == 2)
}

/// Every object of the Blender scenes that is not flat (the floors and the quad lights are
/// planes), from the OBJ and from the glTF file, and the bunny. The files are
/// looked for under the working directory, then under the source tree the binary was built
/// from; an error names what is missing.
pub fn real_meshes() -> crate::Result<&'static [RealMesh]> {
    static MESHES: std::sync::OnceLock<crate::Result<Vec<RealMesh>>> = std::sync::OnceLock::new();
    MESHES
        .get_or_init(|| {
            let mut out = Vec::new();
            let mut files: Vec<String> = Vec::new();
            for (stem, _) in BLENDER_SCENES {
                files.push(format!("tests/data/blender/{stem}.toml"));
                files.push(format!("tests/data/blender/{stem}.glb"));
            }
            files.push("assets/meshes/bunny.obj".into());
            for rel in files {
                let path = source_path(&rel)
                    .ok_or_else(|| format!("{rel} not found (run from the source tree)"))?;
                let scene =
                    crate::scene::scene_file::load_scene(&path).map_err(|e| e.to_string())?;
                for o in scene.objects {
                    if !is_flat(&o.mesh) {
                        out.push(RealMesh {
                            name: format!("{rel}:{}", o.name),
                            can_be_light: is_closed(&o.mesh)
                                || o.mesh.faces.len() <= MAX_OPEN_LIGHT_FACES,
                            mesh: o.mesh,
                        });
                    }
                }
            }
            Ok(out)
        })
        .as_ref()
        .map(|v| v.as_slice())
        .map_err(Clone::clone)
}

/// Whether every vertex lies within 1e-6 of the mesh's size of one plane (a floor, a quad
/// light): the plane through the centre of the bounding box with the first face's normal.
fn is_flat(mesh: &Mesh) -> bool {
    let (c, r) = mesh.bounding_sphere();
    let Some(face) = mesh.faces.first() else {
        return true;
    };
    // Newell's normal of the first face.
    let mut n = DVec3::ZERO;
    for k in 0..face.len() {
        let (a, b) = (
            mesh.positions[face[k] as usize],
            mesh.positions[face[(k + 1) % face.len()] as usize],
        );
        n += (a - c).cross(b - c);
    }
    let Some(n) = n.try_normalize() else {
        return false;
    };
    let d = n.dot(mesh.positions[face[0] as usize]);
    mesh.positions
        .iter()
        .all(|p| (n.dot(*p) - d).abs() <= 1e-6 * r)
}

/// The scene of a group, prepared.
pub(crate) struct Group {
    pub mesh: usize,
    pub perturbation: f64,
    /// The mesh is the light (else an occluder under a quad light).
    pub mesh_is_light: bool,
    pub ctx: RenderContext,
    centre: DVec3,
    radius: f64,
}

/// `mesh` with every coordinate moved by up to ±`eps`·r, written with 17 significant digits
/// and read back through the OBJ loader (faces the move bends are split as a file's are).
fn perturbed(mesh: &Mesh, eps: f64, rng: &mut Pcg32) -> crate::Result<Mesh> {
    if eps == 0.0 {
        return Ok(mesh.clone());
    }
    let (_, r) = mesh.bounding_sphere();
    let mut text = String::new();
    for p in &mesh.positions {
        let d = DVec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        ) * eps
            * r;
        let q = *p + d;
        text += &format!("v {:.17e} {:.17e} {:.17e}\n", q.x, q.y, q.z);
    }
    for f in &mesh.faces {
        text += "f";
        for i in f {
            text += &format!(" {}", i + 1);
        }
        text += "\n";
    }
    let scene =
        crate::scene::obj::load_obj_str(&text, None, "perturbed.obj").map_err(|e| e.to_string())?;
    scene
        .objects
        .into_iter()
        .next()
        .map(|o| o.mesh)
        .ok_or_else(|| "the perturbed mesh has no face".into())
}

/// Group `g` of the run with `seed`. The light is object 0 (the oracle counts rays that reach
/// the front of its faces).
pub(crate) fn group(seed: u64, g: u64) -> crate::Result<Group> {
    let meshes = real_meshes()?;
    let mut rng = Pcg32::new(seed ^ 0x7ea1_5eed, g);
    let mesh = rng.below(meshes.len() as u32) as usize;
    let perturbation = PERTURBATIONS[rng.below(PERTURBATIONS.len() as u32) as usize];
    let m = perturbed(&meshes[mesh].mesh, perturbation, &mut rng)
        .map_err(|e| format!("{} perturbed by {perturbation:e}: {e}", meshes[mesh].name))?;
    let (centre, radius) = m.bounding_sphere();
    let mesh_is_light = rng.below(4) == 0 && meshes[mesh].can_be_light;
    // A floor below the mesh, apart from it or cutting through it; it occludes too (a mesh
    // that reaches below it is partly hidden).
    let floor_y = centre.y - radius * rng.range(0.3, 1.5);
    let span = 8.0 * radius;
    // u × v = Z × X = +Y: facing up.
    let floor = quad(
        DVec3::new(centre.x, floor_y, centre.z),
        DVec3::Z * span,
        DVec3::X * span,
    );
    let objects = if mesh_is_light {
        vec![object("mesh", m, true), object("floor", floor, false)]
    } else {
        // A quad light above the mesh, facing it: its normal (u × v) points at the centre.
        let up = DVec3::new(
            rng.range(-1.0, 1.0),
            rng.range(0.3, 1.0),
            rng.range(-1.0, 1.0),
        )
        .normalize();
        let at = centre + up * radius * rng.range(1.5, 5.0);
        let f = Frame::from_z((centre - at).normalize());
        let size = radius * rng.range(0.1, 2.0);
        let light = quad(at, f.x * size, f.y * size * rng.range(0.3, 1.0));
        // A flat light hides nothing: not an occluder.
        let mut light = object("light", light, true);
        light.flags.occluder = false;
        vec![
            light,
            object("mesh", m, false),
            object("floor", floor, false),
        ]
    };
    let scene = Scene {
        objects,
        ..Scene::default()
    };
    let options = PrepareOptions {
        share_instances: false,
        library: None,
        build_trees: false,
        expected_rays: GROUP,
        ..PrepareOptions::default()
    };
    Ok(Group {
        mesh,
        perturbation,
        mesh_is_light,
        ctx: RenderContext::with_options(Arc::new(scene), options),
        centre,
        radius,
    })
}

impl Group {
    /// The shading point of case `index`: a camera around the mesh, a random image size, pixel
    /// and sub-pixel position, and what its ray hits first (a receiver). `None` when
    /// [`TRIES`] rays all miss.
    pub(crate) fn point(&self, seed: u64, index: u64) -> Option<ShadingPoint> {
        let mut rng = Pcg32::new(seed ^ 0x00ca_5e0f_7ea1, index);
        for _ in 0..TRIES {
            let dir = DVec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-0.2, 1.0),
                rng.range(-1.0, 1.0),
            );
            let Some(dir) = dir.try_normalize() else {
                continue;
            };
            let camera = Camera {
                eye: self.centre + dir * self.radius * rng.range(1.5, 6.0),
                target: self.centre
                    + DVec3::new(
                        rng.range(-1.0, 1.0),
                        rng.range(-1.0, 1.0),
                        rng.range(-1.0, 1.0),
                    ) * 0.5
                        * self.radius,
                up: DVec3::Y,
                fov_deg: rng.range(20.0, 60.0),
                aspect: None,
            };
            let Ok(basis) = camera.basis() else {
                continue;
            };
            let (w, h) = (64 + rng.below(449), 64 + rng.below(449));
            // A pixel, and a stratum of an aa × aa grid in it, jittered as the renderer's.
            let aa = 1 + rng.below(5);
            let (px, py) = (rng.below(w), rng.below(h));
            let (sx, sy) = (rng.below(aa), rng.below(aa));
            let fx = px as f64 + (sx as f64 + rng.next_f64()) / aa as f64;
            let fy = py as f64 + (sy as f64 + rng.next_f64()) / aa as f64;
            let ray = crate::accel::Ray {
                origin: basis.eye,
                dir: basis.direction(fx, fy, w, h),
            };
            if let Some(hit) = self.ctx.primary_hit(&ray).filter(|h| h.receiver) {
                return Some(hit.point);
            }
        }
        None
    }

    /// The boundary formulation's disagreements at case `index` of this group, described.
    pub(crate) fn boundary_failures(&self, seed: u64, index: u64) -> Vec<String> {
        let Some(point) = self.point(seed, index) else {
            return Vec::new();
        };
        let mut rng = Pcg32::new(seed ^ 0x5eed, index);
        let alpha = rng.range(0.01, 1.0);
        let mut failures = Vec::new();
        super::boundary_comparison(
            &self.ctx.prepared,
            &point,
            alpha,
            &mut ShadingScratch::default(),
            |f| failures.push(f),
        );
        failures
    }

    /// Runs case `index` of this group; `None` when its camera found no surface.
    pub fn run(
        &self,
        seed: u64,
        index: u64,
        rays: u32,
        scratch: &mut ShadingScratch,
    ) -> Option<Outcome> {
        let point = self.point(seed, index)?;
        let mut rng = Pcg32::new(seed ^ 0x5eed, index);
        let alpha = rng.range(0.01, 1.0);
        Some(evaluate(
            &self.ctx.prepared,
            &self.ctx.bvh,
            &point,
            alpha,
            rays,
            &mut rng,
            scratch,
        ))
    }
}
