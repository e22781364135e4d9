//! The node hierarchy: which nodes are drawn (the default scene, else scene 0, else every root
//! node), each with its world transform composed in f64 from the nodes' TRS or matrices; and
//! the first perspective camera as penumbra's [`Camera`].

use super::super::Camera;
use crate::Result;
use glam::{DAffine3, DMat4, DQuat, DVec3, DVec4};
use gltf::json;
use gltf::json::validation::Checked;

/// A node reached from the scene, with its world transform.
pub(super) struct Placed {
    pub node: usize,
    pub world: DAffine3,
}

fn err(file: &str, message: String) -> crate::Error {
    crate::Error::File {
        file: file.to_owned(),
        message,
    }
}

fn finite(v: &[f32]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// The local transform of node `i`: its `matrix` (column-major, affine), or T * R * S with the
/// rotation quaternion normalised.
pub(super) fn local_transform(node: &json::Node, i: usize, file: &str) -> Result<DAffine3> {
    if let Some(m) = &node.matrix {
        if !finite(m) {
            return Err(err(
                file,
                format!("nodes[{i}].matrix has a non-finite entry"),
            ));
        }
        let m = DMat4::from_cols_array(&m.map(|x| x as f64));
        if m.row(3) != DVec4::new(0.0, 0.0, 0.0, 1.0) {
            return Err(err(
                file,
                format!("nodes[{i}].matrix is not affine (its last row is not 0 0 0 1)"),
            ));
        }
        return Ok(DAffine3::from_mat4(m));
    }
    let t = node.translation.unwrap_or([0.0; 3]);
    let s = node.scale.unwrap_or([1.0; 3]);
    let r = node.rotation.as_ref().map_or([0.0, 0.0, 0.0, 1.0], |q| q.0);
    if !finite(&t) || !finite(&s) || !finite(&r) {
        return Err(err(
            file,
            format!("nodes[{i}] has a non-finite translation, rotation or scale"),
        ));
    }
    let q = DQuat::from_array(r.map(|x| x as f64));
    let len = q.length();
    if len <= 1e-6 {
        return Err(err(
            file,
            format!("nodes[{i}].rotation is a zero quaternion"),
        ));
    }
    Ok(DAffine3::from_scale_rotation_translation(
        DVec3::from_array(s.map(|x| x as f64)),
        q / len,
        DVec3::from_array(t.map(|x| x as f64)),
    ))
}

/// The nodes drawn, in depth-first order, with their world transforms. A node reached twice
/// (a cycle, or a node with two parents) is an error, as the specification says.
pub(super) fn placed_nodes(
    root: &json::Root,
    file: &str,
    notes: &mut Vec<String>,
) -> Result<Vec<Placed>> {
    let n = root.nodes.len();
    let check = |idx: usize, path: String| -> Result<usize> {
        if idx < n {
            Ok(idx)
        } else {
            Err(err(
                file,
                format!("{path}: node {idx} does not exist ({n} nodes)"),
            ))
        }
    };
    let chosen = match (&root.scene, root.scenes.is_empty()) {
        (Some(s), _) => Some(s.value()),
        (None, false) => Some(0),
        (None, true) => None,
    };
    let roots: Vec<usize> = match chosen {
        Some(si) => {
            let scene = root.scenes.get(si).ok_or_else(|| {
                err(
                    file,
                    format!(
                        "scene: scenes[{si}] does not exist ({} scenes)",
                        root.scenes.len()
                    ),
                )
            })?;
            if root.scene.is_none() && root.scenes.len() > 1 {
                notes.push(format!(
                    "no default scene: scenes[0] of {} is loaded",
                    root.scenes.len()
                ));
            }
            scene
                .nodes
                .iter()
                .enumerate()
                .map(|(k, x)| check(x.value(), format!("scenes[{si}].nodes[{k}]")))
                .collect::<Result<_, _>>()?
        }
        None => {
            // No scene: every node that is nobody's child.
            let mut is_child = vec![false; n];
            for (p, node) in root.nodes.iter().enumerate() {
                for (k, c) in node.children.iter().flatten().enumerate() {
                    is_child[check(c.value(), format!("nodes[{p}].children[{k}]"))?] = true;
                }
            }
            (0..n).filter(|&i| !is_child[i]).collect()
        }
    };
    let mut visited = vec![false; n];
    let mut out = Vec::new();
    // Depth first, children in order: a stack of (node, parent's world transform).
    let mut stack: Vec<(usize, DAffine3)> = roots
        .iter()
        .rev()
        .map(|&r| (r, DAffine3::IDENTITY))
        .collect();
    while let Some((i, parent)) = stack.pop() {
        if std::mem::replace(&mut visited[i], true) {
            return Err(err(
                file,
                format!(
                    "nodes[{i}] is reached twice from the scene (a cycle, or a node with two \
                     parents)"
                ),
            ));
        }
        let node = &root.nodes[i];
        let world = parent * local_transform(node, i, file)?;
        if let Some(children) = &node.children {
            for (k, c) in children.iter().enumerate().rev() {
                let c = check(c.value(), format!("nodes[{i}].children[{k}]"))?;
                stack.push((c, world));
            }
        }
        out.push(Placed { node: i, world });
    }
    Ok(out)
}

/// The camera of the first node (in drawing order) that has a perspective camera: eye at the
/// node's origin, looking down its -z axis with +y up, vertical field of view `yfov`. The
/// target is placed at `target_distance` along the view direction.
pub(super) fn first_camera(
    root: &json::Root,
    placed: &[Placed],
    target_distance: impl Fn(DVec3, DVec3) -> f64,
    notes: &mut Vec<String>,
) -> Option<Camera> {
    for p in placed {
        let Some(ci) = root.nodes[p.node].camera.as_ref().map(|c| c.value()) else {
            continue;
        };
        let Some(cam) = root.cameras.get(ci) else {
            notes.push(format!(
                "nodes[{}].camera: cameras[{ci}] does not exist; ignored",
                p.node
            ));
            continue;
        };
        let perspective = match (&cam.type_, &cam.perspective) {
            (Checked::Valid(json::camera::Type::Perspective), Some(persp)) => persp,
            _ => {
                notes.push(format!(
                    "cameras[{ci}] is not a perspective camera; ignored"
                ));
                continue;
            }
        };
        let eye = p.world.transform_point3(DVec3::ZERO);
        let forward = p.world.transform_vector3(DVec3::NEG_Z).try_normalize();
        let up = p.world.transform_vector3(DVec3::Y).try_normalize();
        let (Some(forward), Some(up)) = (forward, up) else {
            notes.push(format!(
                "nodes[{}]: the camera's transform is degenerate; camera ignored",
                p.node
            ));
            continue;
        };
        let d = target_distance(eye, forward);
        let camera = Camera {
            eye,
            target: eye + forward * d,
            up,
            fov_deg: (perspective.yfov as f64).to_degrees(),
            aspect: perspective.aspect_ratio.map(f64::from),
        };
        match camera.basis() {
            Ok(_) => return Some(camera),
            Err(m) => notes.push(format!("cameras[{ci}] (nodes[{}]): {m}; ignored", p.node)),
        }
    }
    None
}
