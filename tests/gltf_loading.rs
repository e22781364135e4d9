//! glTF 2.0 loading (`scene::gltf`, docs/scenes.md "glTF 2.0") against independent oracles:
//! the files are written here by hand (JSON plus little-endian buffers), as `.glb`, as
//! `.gltf` with a base64 data URI and as `.gltf` with an external `.bin`. A quad light above a
//! cube above a floor, under nested translation + rotation + scale nodes:
//! * the loaded positions equal the vertices transformed here, with a rotation matrix written
//!   out from the quaternion (not glam's);
//! * the materials follow the mapping table;
//! * the same scene written as OBJ + MTL (world-space vertices, quads instead of triangle
//!   pairs) and loaded through the OBJ path shades the same at floor points;
//! * the cube, split at its faces' corners as exporters write it, is welded closed;
//! * each kind of malformed file is an error naming the file, never a panic.

use glam::DVec3;
use penumbra::accel::Ray;
use penumbra::render::RenderContext;
use penumbra::scene::gltf::{DIELECTRIC_F0, load_gltf, load_gltf_bytes};
use penumbra::scene::{Scene, SceneObject, obj, scene_file};
use penumbra::shading::{Method, NoRecorder, ShadingScratch, shade};
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

// ---------------------------------------------------------------------------------------------
// A hand-written glTF builder
// ---------------------------------------------------------------------------------------------

/// JSON arrays and one binary buffer, filled by hand.
#[derive(Default)]
struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Builder {
    fn pad(&mut self) {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
    }

    /// Positions as VEC3 floats, with `lead` padding bytes before them inside the view (the
    /// accessor's byteOffset) and `stride` bytes per vertex (None: tightly packed).
    fn positions(&mut self, pts: &[[f32; 3]], lead: usize, stride: Option<usize>) -> usize {
        self.pad();
        let start = self.bin.len();
        self.bin.extend(std::iter::repeat_n(0xAB, lead));
        let step = stride.unwrap_or(12);
        for p in pts {
            let at = self.bin.len();
            for c in p {
                self.bin.extend_from_slice(&c.to_le_bytes());
            }
            self.bin.resize(at + step, 0xCD);
        }
        let mut view =
            json!({"buffer": 0, "byteOffset": start, "byteLength": self.bin.len() - start});
        if let Some(s) = stride {
            view["byteStride"] = json!(s);
        }
        self.views.push(view);
        let lo = (0..3).map(|k| pts.iter().map(|p| p[k]).fold(f32::INFINITY, f32::min));
        let hi = (0..3).map(|k| pts.iter().map(|p| p[k]).fold(f32::NEG_INFINITY, f32::max));
        self.accessors.push(json!({
            "bufferView": self.views.len() - 1, "byteOffset": lead, "componentType": 5126,
            "count": pts.len(), "type": "VEC3",
            "min": lo.collect::<Vec<_>>(), "max": hi.collect::<Vec<_>>()
        }));
        self.accessors.len() - 1
    }

    /// Indices as u8 (5121), u16 (5123) or u32 (5125).
    fn indices(&mut self, idx: &[u32], component: u32) -> usize {
        self.pad();
        let start = self.bin.len();
        for &i in idx {
            match component {
                5121 => self.bin.push(i as u8),
                5123 => self.bin.extend_from_slice(&(i as u16).to_le_bytes()),
                _ => self.bin.extend_from_slice(&i.to_le_bytes()),
            }
        }
        self.views
            .push(json!({"buffer": 0, "byteOffset": start, "byteLength": self.bin.len() - start}));
        self.accessors.push(json!({
            "bufferView": self.views.len() - 1, "componentType": component,
            "count": idx.len(), "type": "SCALAR"
        }));
        self.accessors.len() - 1
    }
}

/// How the buffer is stored.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Form {
    Glb,
    Base64,
    ExternalBin,
}

fn base64(data: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in data.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                s.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// The GLB container: header, JSON chunk (space-padded), BIN chunk (zero-padded).
fn glb(json_text: &str, bin: &[u8]) -> Vec<u8> {
    let mut j = json_text.as_bytes().to_vec();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + 8 + b.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    out.extend_from_slice(&(b.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&b);
    out
}

/// Writes `doc` with buffer `bin` in `form` into `dir`; returns the file's path.
pub(crate) fn write(dir: &Path, stem: &str, mut doc: Value, bin: &[u8], form: Form) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    match form {
        Form::Glb => {
            doc["buffers"] = json!([{"byteLength": bin.len()}]);
            let p = dir.join(format!("{stem}.glb"));
            std::fs::write(&p, glb(&doc.to_string(), bin)).unwrap();
            p
        }
        Form::Base64 => {
            doc["buffers"] = json!([{
                "byteLength": bin.len(),
                "uri": format!("data:application/octet-stream;base64,{}", base64(bin))
            }]);
            let p = dir.join(format!("{stem}.gltf"));
            std::fs::write(&p, serde_json::to_string_pretty(&doc).unwrap()).unwrap();
            p
        }
        Form::ExternalBin => {
            let bin_name = format!("{stem} data.bin");
            std::fs::write(dir.join(&bin_name), bin).unwrap();
            doc["buffers"] = json!([{
                "byteLength": bin.len(),
                "uri": bin_name.replace(' ', "%20")
            }]);
            let p = dir.join(format!("{stem}.gltf"));
            std::fs::write(&p, serde_json::to_string_pretty(&doc).unwrap()).unwrap();
            p
        }
    }
}

pub(crate) fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("penumbra-gltf-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

// ---------------------------------------------------------------------------------------------
// The test scene and its oracle transforms
// ---------------------------------------------------------------------------------------------

/// A node's TRS, as f32 values written to the file.
#[derive(Clone, Copy)]
struct Trs {
    t: [f32; 3],
    /// x, y, z, w
    r: [f32; 4],
    s: [f32; 3],
}

impl Trs {
    fn json(&self) -> Value {
        json!({"translation": self.t, "rotation": self.r, "scale": self.s})
    }

    /// p -> T (R (S p)), in f64 from the f32 values, the quaternion normalised, the rotation
    /// matrix written out by hand.
    fn apply(&self, p: DVec3) -> DVec3 {
        let [x, y, z, w] = self.r.map(|v| v as f64);
        let n = (x * x + y * y + z * z + w * w).sqrt();
        let (x, y, z, w) = (x / n, y / n, z / n, w / n);
        let r = [
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - z * w),
                2.0 * (x * z + y * w),
            ],
            [
                2.0 * (x * y + z * w),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - x * w),
            ],
            [
                2.0 * (x * z - y * w),
                2.0 * (y * z + x * w),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ];
        let s = [
            p.x * self.s[0] as f64,
            p.y * self.s[1] as f64,
            p.z * self.s[2] as f64,
        ];
        let row = |i: usize| r[i][0] * s[0] + r[i][1] * s[1] + r[i][2] * s[2];
        DVec3::new(
            row(0) + self.t[0] as f64,
            row(1) + self.t[1] as f64,
            row(2) + self.t[2] as f64,
        )
    }
}

/// A unit quaternion (x, y, z, w) for `deg` degrees about `axis`, rounded to f32.
fn quat(axis: [f64; 3], deg: f64) -> [f32; 4] {
    let a = DVec3::from_array(axis).normalize();
    let h = deg.to_radians() / 2.0;
    let (s, c) = h.sin_cos();
    [
        (a.x * s) as f32,
        (a.y * s) as f32,
        (a.z * s) as f32,
        c as f32,
    ]
}

const LIGHT_RIG: Trs = Trs {
    t: [0.1, 3.0, -0.2],
    r: [0.0, 0.0, 0.0, 1.0],
    s: [1.0, 1.0, 1.0],
};
const GROUP: Trs = Trs {
    t: [0.0, 0.25, 0.0],
    r: [0.0, 0.0, 0.0, 1.0],
    s: [1.25, 1.25, 1.25],
};

fn light_trs() -> Trs {
    Trs {
        t: [0.0, 0.0, 0.0],
        r: quat([0.0, 1.0, 0.0], 30.0),
        s: [0.5, 1.0, 0.75],
    }
}

fn group_trs() -> Trs {
    Trs {
        r: quat([0.0, 1.0, 0.0], -20.0),
        ..GROUP
    }
}

fn cube_trs() -> Trs {
    Trs {
        t: [0.2, 0.9, 0.1],
        r: quat([1.0, 1.0, 0.0], 25.0),
        s: [0.5, 0.4, 0.6],
    }
}

/// The light: a unit square in y = 0, facing down (-y) after its transforms.
const QUAD: [[f32; 3]; 4] = [
    [-1.0, 0.0, -1.0],
    [1.0, 0.0, -1.0],
    [1.0, 0.0, 1.0],
    [-1.0, 0.0, 1.0],
];
/// Counter-clockwise seen from below (-y).
const QUAD_TRIS_DOWN: [u32; 6] = [0, 1, 2, 0, 2, 3];

/// The floor, facing up: counter-clockwise seen from above.
const FLOOR: [[f32; 3]; 4] = [
    [-4.0, 0.0, -4.0],
    [-4.0, 0.0, 4.0],
    [4.0, 0.0, 4.0],
    [4.0, 0.0, -4.0],
];

/// A cube of half-size 1 as exporters write it: 4 vertices per face (24), 2 triangles each,
/// outward (counter-clockwise seen from outside). Returns (positions, indices, quads over the
/// 8 corners for the OBJ).
fn split_cube() -> (Vec<[f32; 3]>, Vec<u32>, Vec<[usize; 4]>) {
    let corner = |i: usize| -> [f32; 3] {
        [
            if i & 1 != 0 { 1.0 } else { -1.0 },
            if i & 2 != 0 { 1.0 } else { -1.0 },
            if i & 4 != 0 { 1.0 } else { -1.0 },
        ]
    };
    // Each face's corners (bit 0 = x, 1 = y, 2 = z), counter-clockwise seen from outside.
    let faces: [[usize; 4]; 6] = [
        [0, 2, 3, 1], // -z
        [4, 5, 7, 6], // +z
        [0, 1, 5, 4], // -y
        [2, 6, 7, 3], // +y
        [0, 4, 6, 2], // -x
        [1, 3, 7, 5], // +x
    ];
    let mut pos = Vec::new();
    let mut idx = Vec::new();
    for f in &faces {
        let b = pos.len() as u32;
        pos.extend(f.iter().map(|&c| corner(c)));
        idx.extend([b, b + 1, b + 2, b, b + 2, b + 3]);
    }
    (pos, idx, faces.to_vec())
}

fn corner_of_cube(i: usize) -> DVec3 {
    DVec3::new(
        if i & 1 != 0 { 1.0 } else { -1.0 },
        if i & 2 != 0 { 1.0 } else { -1.0 },
        if i & 4 != 0 { 1.0 } else { -1.0 },
    )
}

fn light_world(p: [f32; 3]) -> DVec3 {
    LIGHT_RIG.apply(light_trs().apply(DVec3::from_array(p.map(|v| v as f64))))
}

fn cube_world(p: DVec3) -> DVec3 {
    group_trs().apply(cube_trs().apply(p))
}

fn floor_world(p: [f32; 3]) -> DVec3 {
    DVec3::from_array(p.map(|v| v as f64))
}

/// Material factors of the test scene.
const LIGHT_EMISSIVE: [f32; 3] = [1.0, 0.75, 0.5];
const LIGHT_STRENGTH: f32 = 6.0;
const CUBE_BASE: [f32; 4] = [0.25, 0.5, 0.75, 1.0];
const CUBE_METALLIC: f32 = 0.25;
const CUBE_ROUGHNESS: f32 = 0.5;
const FLOOR_BASE: [f32; 4] = [0.625, 0.5, 0.375, 1.0];
const FLOOR_ROUGHNESS: f32 = 0.75;

/// The test scene's document (without `buffers`) and its binary buffer.
pub(crate) fn test_scene() -> (Value, Vec<u8>) {
    let mut b = Builder::default();
    // The light: u16 indices, packed positions.
    let light_pos = b.positions(&QUAD, 0, None);
    let light_idx = b.indices(&QUAD_TRIS_DOWN, 5123);
    // The cube: u8 indices, positions after 8 lead bytes inside their view.
    let (cube_pos, cube_idx, _) = split_cube();
    let cube_pos = b.positions(&cube_pos, 8, None);
    let cube_idx = b.indices(&cube_idx, 5121);
    // The floor: not indexed (6 vertices), interleaved with a 20-byte stride.
    let floor_tris: Vec<[f32; 3]> = [0, 1, 2, 0, 2, 3].iter().map(|&i| FLOOR[i]).collect();
    let floor_pos = b.positions(&floor_tris, 4, Some(20));
    // A line primitive, which is skipped with a warning.
    let line_idx = b.indices(&[0, 1], 5125);
    let doc = json!({
        "asset": {"version": "2.0", "generator": "penumbra tests"},
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{"nodes": [0, 2, 4, 5]}],
        "nodes": [
            merge(json!({"name": "LightRig", "children": [1]}), LIGHT_RIG.json()),
            merge(json!({"name": "Light", "mesh": 0}), light_trs().json()),
            merge(json!({"name": "Group", "children": [3]}), group_trs().json()),
            merge(json!({"name": "Cube", "mesh": 1}), cube_trs().json()),
            {"name": "Floor", "mesh": 2},
            {"name": "Camera", "camera": 0, "translation": [0.0, 1.5, 6.0]}
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.75, "znear": 0.1}}],
        "meshes": [
            {"name": "LightMesh", "primitives": [{"attributes": {"POSITION": light_pos}, "indices": light_idx, "material": 0}]},
            {"name": "CubeMesh", "primitives": [
                {"attributes": {"POSITION": cube_pos}, "indices": cube_idx, "material": 1},
                {"attributes": {"POSITION": cube_pos}, "indices": line_idx, "mode": 1}
            ]},
            {"name": "FloorMesh", "primitives": [{"attributes": {"POSITION": floor_pos}, "material": 2}]}
        ],
        "materials": [
            {"name": "Emitter", "emissiveFactor": LIGHT_EMISSIVE,
             "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0},
             "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": LIGHT_STRENGTH}}},
            {"name": "CubeMat", "pbrMetallicRoughness": {"baseColorFactor": CUBE_BASE,
             "metallicFactor": CUBE_METALLIC, "roughnessFactor": CUBE_ROUGHNESS}},
            {"name": "FloorMat", "pbrMetallicRoughness": {"baseColorFactor": FLOOR_BASE,
             "metallicFactor": 0.0, "roughnessFactor": FLOOR_ROUGHNESS,
             "baseColorTexture": {"index": 0}}}
        ],
        "textures": [{"source": 0}],
        "images": [{"uri": "never-read.png"}],
        "bufferViews": b.views,
        "accessors": b.accessors,
    });
    (doc, b.bin)
}

fn merge(mut a: Value, b: Value) -> Value {
    for (k, v) in b.as_object().unwrap() {
        a[k] = v.clone();
    }
    a
}

/// The expected material of the table in docs/scenes.md: (Kd, Ks, alpha, Ke).
fn expected_material(base: [f32; 4], metallic: f32, roughness: f32) -> (DVec3, DVec3, f64) {
    let b = DVec3::new(base[0] as f64, base[1] as f64, base[2] as f64);
    let m = metallic as f64;
    let kd = b * (1.0 - m);
    let ks = DVec3::splat(0.04) * (1.0 - m) + b * m;
    (kd, ks, (roughness as f64).powi(2))
}

/// The same scene as OBJ + MTL, in world space, its faces as quads.
fn test_scene_as_obj() -> (String, String) {
    let mut o = String::from("mtllib scene.mtl\n");
    let v = |o: &mut String, p: DVec3| o.push_str(&format!("v {:e} {:e} {:e}\n", p.x, p.y, p.z));
    o.push_str("o Light\nusemtl Emitter\n");
    for p in QUAD {
        v(&mut o, light_world(p));
    }
    o.push_str("f 1 2 3 4\n");
    o.push_str("o Cube\nusemtl CubeMat\n");
    for c in 0..8 {
        v(&mut o, cube_world(corner_of_cube(c)));
    }
    for f in split_cube().2 {
        o.push_str(&format!(
            "f {} {} {} {}\n",
            5 + f[0],
            5 + f[1],
            5 + f[2],
            5 + f[3]
        ));
    }
    o.push_str("o Floor\nusemtl FloorMat\n");
    for p in FLOOR {
        v(&mut o, floor_world(p));
    }
    o.push_str("f 13 14 15 16\n");
    let mut m = String::new();
    let ke = DVec3::from_array(LIGHT_EMISSIVE.map(|x| x as f64)) * LIGHT_STRENGTH as f64;
    m.push_str(&format!(
        "newmtl Emitter\nKd 0 0 0\nKs {0:e} {0:e} {0:e}\nPr 1\nKe {1:e} {2:e} {3:e}\n",
        DIELECTRIC_F0, ke.x, ke.y, ke.z
    ));
    for (name, base, metallic, rough) in [
        ("CubeMat", CUBE_BASE, CUBE_METALLIC, CUBE_ROUGHNESS),
        ("FloorMat", FLOOR_BASE, 0.0, FLOOR_ROUGHNESS),
    ] {
        let (kd, ks, _) = expected_material(base, metallic, rough);
        m.push_str(&format!(
            "newmtl {name}\nKd {:e} {:e} {:e}\nKs {:e} {:e} {:e}\nPr {:e}\n",
            kd.x, kd.y, kd.z, ks.x, ks.y, ks.z, rough as f64
        ));
    }
    (o, m)
}

fn object<'a>(scene: &'a Scene, name: &str) -> &'a SceneObject {
    scene
        .object(name)
        .unwrap_or_else(|| panic!("no object '{name}'"))
}

/// Every expected point is a vertex of the object (and the object has no other vertices).
fn assert_vertices(obj: &SceneObject, expected: &[DVec3]) {
    assert_eq!(
        obj.mesh.positions.len(),
        expected.len(),
        "{}: {:?}",
        obj.name,
        obj.mesh.positions
    );
    for e in expected {
        let d = obj
            .mesh
            .positions
            .iter()
            .map(|p| p.distance(*e))
            .fold(f64::INFINITY, f64::min);
        assert!(
            d < 1e-12 * (1.0 + e.length()),
            "{}: {e} missing (nearest {d:e})",
            obj.name
        );
    }
}

fn forms() -> [Form; 3] {
    [Form::Glb, Form::Base64, Form::ExternalBin]
}

// ---------------------------------------------------------------------------------------------
// Tests
// ---------------------------------------------------------------------------------------------

#[test]
fn positions_are_the_hand_transformed_vertices_in_every_form() {
    let dir = temp_dir("positions");
    let (doc, bin) = test_scene();
    for form in forms() {
        let path = write(&dir, "scene", doc.clone(), &bin, form);
        let scene = load_gltf(&path).unwrap_or_else(|e| panic!("{form:?}: {e}"));
        let names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
        assert_eq!(names, ["Light", "Cube", "Floor"], "{form:?}");
        assert_vertices(object(&scene, "Light"), &QUAD.map(light_world));
        let corners: Vec<DVec3> = (0..8).map(|c| cube_world(corner_of_cube(c))).collect();
        assert_vertices(object(&scene, "Cube"), &corners);
        assert_vertices(object(&scene, "Floor"), &FLOOR.map(floor_world));
        for o in &scene.objects {
            assert_eq!(o.mesh.faces.len(), if o.name == "Cube" { 12 } else { 2 });
        }
        // The light faces down, the floor up: winding kept through the transforms.
        let light = &object(&scene, "Light").mesh;
        for f in 0..2 {
            assert!(light.face_normal(f).unwrap().y < -0.99);
            assert!(object(&scene, "Floor").mesh.face_normal(f).unwrap().y > 0.99);
        }
        // The line primitive and the texture are reported, once each.
        let text = scene.warnings.join("\n");
        assert!(text.contains("meshes[1].primitives[1]"), "{text}");
        assert_eq!(text.matches("textures are ignored").count(), 1, "{text}");
        assert!(
            scene
                .warnings
                .iter()
                .all(|w| w.starts_with(&path.display().to_string()))
        );
        // Through the common loader, by extension.
        let again = scene_file::load_scene(&path).unwrap();
        assert_eq!(again.objects.len(), 3);
    }
}

#[test]
fn materials_follow_the_mapping_table() {
    let dir = temp_dir("materials");
    let (doc, bin) = test_scene();
    let scene = load_gltf(&write(&dir, "scene", doc, &bin, Form::Glb)).unwrap();
    let light = object(&scene, "Light");
    let ke = DVec3::from_array(LIGHT_EMISSIVE.map(|x| x as f64)) * LIGHT_STRENGTH as f64;
    assert_eq!(light.material.ke, ke);
    assert!(light.flags.light && light.flags.occluder && light.flags.receiver);
    assert_eq!(light.material.kd, DVec3::ZERO);
    for (name, base, metallic, rough) in [
        ("Cube", CUBE_BASE, CUBE_METALLIC, CUBE_ROUGHNESS),
        ("Floor", FLOOR_BASE, 0.0, FLOOR_ROUGHNESS),
    ] {
        let o = object(&scene, name);
        let (kd, ks, alpha) = expected_material(base, metallic, rough);
        assert!((o.material.kd - kd).abs().max_element() < 1e-15, "{name}");
        assert!((o.material.ks - ks).abs().max_element() < 1e-15, "{name}");
        assert!((o.material.alpha - alpha).abs() < 1e-15, "{name}");
        assert_eq!(o.material.ke, DVec3::ZERO);
        assert!(!o.flags.light);
    }
    assert_eq!(object(&scene, "Cube").material.name, "CubeMat");
}

#[test]
fn default_material_without_one_and_defaults_of_the_factors() {
    let mut b = Builder::default();
    let pos = b.positions(
        &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        0,
        None,
    );
    let doc = json!({
        "asset": {"version": "2.0"},
        "nodes": [{"mesh": 0}, {"mesh": 1}],
        "meshes": [
            {"primitives": [{"attributes": {"POSITION": pos}}]},
            {"primitives": [{"attributes": {"POSITION": pos}, "material": 0}]}
        ],
        "materials": [{}],
        "bufferViews": b.views, "accessors": b.accessors
    });
    let dir = temp_dir("defaults");
    let scene = load_gltf(&write(&dir, "bare", doc, &b.bin, Form::Base64)).unwrap();
    assert_eq!(scene.objects.len(), 2);
    // No scene: every root node; unnamed nodes and meshes.
    assert_eq!(scene.objects[0].name, "node0");
    assert_eq!(
        scene.objects[0].material,
        penumbra::scene::Material::default()
    );
    // glTF's defaults: base colour 1, metallic 1, roughness 1 (a rough white metal).
    let m = &scene.objects[1].material;
    assert_eq!((m.kd, m.ks, m.alpha), (DVec3::ZERO, DVec3::ONE, 1.0));
    assert!(scene.camera.is_none());
}

#[test]
fn shading_equals_the_same_scene_loaded_as_obj() {
    let dir = temp_dir("shading");
    let (doc, bin) = test_scene();
    let (obj_text, mtl_text) = test_scene_as_obj();
    let oracle = obj::load_obj_str(&obj_text, Some(&mtl_text), "scene.obj").unwrap();
    assert!(oracle.warnings.is_empty(), "{:?}", oracle.warnings);
    let oracle_ctx = RenderContext::new(&oracle);
    for form in forms() {
        let scene = load_gltf(&write(&dir, "scene", doc.clone(), &bin, form)).unwrap();
        let ctx = RenderContext::new(&scene);
        let mut without = scene.clone();
        without.objects.retain(|o| o.name != "Cube");
        let no_cube = RenderContext::new(&without);
        let mut scratch = ShadingScratch::default();
        let mut shadowed = 0;
        let mut lit = 0;
        for i in 0..9 {
            for k in 0..9 {
                let (x, z) = (-3.6 + 0.9 * i as f64, -3.6 + 0.9 * k as f64);
                let ray = Ray {
                    origin: DVec3::new(x, 0.05, z),
                    dir: DVec3::NEG_Y,
                };
                let value = |ctx: &RenderContext, scratch: &mut ShadingScratch| {
                    let hit = ctx.primary_hit(&ray).expect("the floor is below");
                    let sp = hit.point;
                    let mat = &ctx.prepared.materials[sp.object.unwrap() as usize];
                    (
                        shade(
                            &ctx.prepared,
                            &sp,
                            mat,
                            Method::Analytic,
                            scratch,
                            &mut NoRecorder,
                        ),
                        ctx.scene.unshadowed_irradiance(sp.position, sp.normal),
                    )
                };
                let (a, ua) = value(&ctx, &mut scratch);
                let (b, ub) = value(&oracle_ctx, &mut scratch);
                let rel = (a - b).abs().max_element() / b.max_element().max(1e-6);
                assert!(rel < 1e-9, "{form:?} at ({x}, {z}): glTF {a} vs OBJ {b}");
                assert!((ua - ub).abs().max_element() < 1e-9 * ub.max_element());
                // Count points in (partial) shadow: the cube matters, not just the light.
                let (c, _) = value(&no_cube, &mut scratch);
                if a.max_element() < 0.99 * c.max_element() {
                    shadowed += 1;
                } else {
                    lit += 1;
                }
            }
        }
        assert!(
            shadowed > 3 && lit > 3,
            "{form:?}: {shadowed} shadowed, {lit} lit"
        );
        eprintln!("{form:?}: {shadowed} floor points in (partial) shadow of the cube, {lit} not");
    }
}

#[test]
fn split_cube_is_welded_closed_and_takes_the_silhouette_path() {
    let dir = temp_dir("closed");
    let (doc, bin) = test_scene();
    let scene = load_gltf(&write(&dir, "scene", doc, &bin, Form::Glb)).unwrap();
    let cube = object(&scene, "Cube");
    assert_eq!(cube.mesh.positions.len(), 8);
    assert!(
        cube.mesh.is_closed_manifold(),
        "{:?}",
        cube.mesh.manifold_defects()
    );
    assert!(cube.mesh.signed_volume() > 0.0);
    let ctx = RenderContext::new(&scene);
    let prepared = ctx
        .prepared
        .objects
        .iter()
        .find(|o| o.name == "Cube")
        .unwrap();
    let d = prepared.poly.diagnostics;
    assert!(d.closed_manifold && d.convex, "{d:?}");
    assert!(prepared.path.is_simple());
}

#[test]
fn camera_comes_from_the_camera_node() {
    let dir = temp_dir("camera");
    let (doc, bin) = test_scene();
    let scene = load_gltf(&write(&dir, "scene", doc, &bin, Form::Glb)).unwrap();
    let cam = scene.camera.expect("the file has a perspective camera");
    assert_eq!(cam.eye, DVec3::new(0.0, 1.5, 6.0));
    assert!(((cam.target - cam.eye).normalize() - DVec3::NEG_Z).length() < 1e-12);
    assert_eq!(cam.up, DVec3::Y);
    assert!((cam.fov_deg - (0.75f32 as f64).to_degrees()).abs() < 1e-12);
}

#[test]
fn a_scene_file_may_name_a_glb() {
    let dir = temp_dir("toml");
    let (doc, bin) = test_scene();
    write(&dir, "scene", doc, &bin, Form::Glb);
    let toml = dir.join("wrap.toml");
    std::fs::write(
        &toml,
        "[camera]\neye = [0, 2, 5]\ntarget = [0, 0, 0]\nfov = 40\n\n\
         [[object]]\nobj = \"scene.glb\"\nname = \"Cube\"\ntranslate = [1, 0, 0]\n",
    )
    .unwrap();
    let scene = scene_file::load_scene(&toml).unwrap();
    assert_eq!(scene.objects.len(), 1);
    assert_eq!(scene.camera.unwrap().fov_deg, 40.0);
}

// ---------------------------------------------------------------------------------------------
// Malformed files
// ---------------------------------------------------------------------------------------------

/// Loads `bytes` as `name` in a temporary directory; the error text, which must name the file.
fn load_error(name: &str, bytes: &[u8]) -> String {
    let dir = temp_dir("errors");
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    let label = path.display().to_string();
    let e = match load_gltf(&path) {
        Ok(s) => panic!(
            "{name}: loaded ({} objects, warnings {:?})",
            s.objects.len(),
            s.warnings
        ),
        Err(e) => e.to_string(),
    };
    assert!(
        e.starts_with(&label),
        "{name}: the error does not name the file: {e}"
    );
    e
}

fn valid_glb() -> Vec<u8> {
    let (mut doc, bin) = test_scene();
    doc["buffers"] = json!([{"byteLength": bin.len()}]);
    glb(&doc.to_string(), &bin)
}

fn scene_json(edit: impl Fn(&mut Value, &mut Vec<u8>)) -> Vec<u8> {
    let (mut doc, mut bin) = test_scene();
    edit(&mut doc, &mut bin);
    if doc.get("buffers").is_none() {
        doc["buffers"] = json!([{"byteLength": bin.len(),
            "uri": format!("data:application/octet-stream;base64,{}", base64(&bin))}]);
    }
    doc.to_string().into_bytes()
}

#[test]
fn malformed_containers_are_errors_naming_the_file() {
    let good = valid_glb();
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("empty.glb", vec![], "empty"),
        ("short.glb", b"glTF\x02\0".to_vec(), "truncated"),
        (
            "magic.glb",
            [b"gLTF".as_slice(), &good[4..]].concat(),
            "magic",
        ),
        (
            "version.glb",
            [&good[..4], &1u32.to_le_bytes(), &good[8..]].concat(),
            "version 1",
        ),
        (
            "truncated.glb",
            good[..good.len() - 10].to_vec(),
            "truncated",
        ),
        ("half.glb", good[..good.len() / 2].to_vec(), "truncated"),
        (
            "tiny-length.glb",
            [&good[..8], &3u32.to_le_bytes(), &good[12..]].concat(),
            "length",
        ),
        (
            "json-chunk.glb",
            [&good[..12], &(u32::MAX - 3).to_le_bytes(), &good[16..]].concat(),
            "JSON chunk",
        ),
        (
            "json-chunk-bad.glb",
            {
                let mut g = good.clone();
                g[20] = b'[';
                g
            },
            "JSON",
        ),
        ("text.gltf", b"{ \"asset\": ".to_vec(), "invalid glTF JSON"),
        (
            "garbage.gltf",
            b"\x00\x01\x02\x03garbage".to_vec(),
            "neither",
        ),
        (
            "version.gltf",
            br#"{"asset": {"version": "1.0"}}"#.to_vec(),
            "2.x",
        ),
    ];
    for (name, bytes, needle) in cases {
        let e = load_error(name, &bytes);
        assert!(e.contains(needle), "{name}: expected '{needle}' in: {e}");
    }
    // Every truncation of a valid file fails cleanly (or loads, for none).
    for cut in (0..good.len()).step_by(7) {
        let e = load_gltf_bytes(&good[..cut], "cut.glb", None);
        assert!(e.is_err(), "cut at {cut} loaded");
    }
}

#[test]
fn out_of_range_references_are_errors_naming_the_place() {
    type Edit = Box<dyn Fn(&mut Value, &mut Vec<u8>)>;
    let cases: Vec<(&str, Edit, &str)> = vec![
        (
            "node-mesh",
            Box::new(|d, _| d["nodes"][4]["mesh"] = json!(9)),
            "meshes[9]",
        ),
        (
            "child",
            Box::new(|d, _| d["nodes"][0]["children"] = json!([42])),
            "nodes[0].children[0]",
        ),
        (
            "cycle",
            Box::new(|d, _| d["nodes"][1]["children"] = json!([0])),
            "reached twice",
        ),
        ("scene", Box::new(|d, _| d["scene"] = json!(3)), "scenes[3]"),
        (
            "position-accessor",
            Box::new(|d, _| d["meshes"][2]["primitives"][0]["attributes"]["POSITION"] = json!(99)),
            "accessors[99]",
        ),
        (
            "index-accessor",
            Box::new(|d, _| d["meshes"][0]["primitives"][0]["indices"] = json!(77)),
            "accessors[77]",
        ),
        (
            "material",
            Box::new(|d, _| d["meshes"][0]["primitives"][0]["material"] = json!(8)),
            "materials[8]",
        ),
        (
            "view",
            Box::new(|d, _| d["accessors"][0]["bufferView"] = json!(50)),
            "bufferView 50",
        ),
        (
            "buffer",
            Box::new(|d, _| d["bufferViews"][0]["buffer"] = json!(3)),
            "buffers[3]",
        ),
        (
            "view-past-buffer",
            Box::new(|d, _| d["bufferViews"][0]["byteOffset"] = json!(1 << 20)),
            "outside buffers[0]",
        ),
        (
            "accessor-past-view",
            Box::new(|d, _| d["accessors"][0]["count"] = json!(5)),
            "do not fit",
        ),
        (
            "accessor-offset",
            Box::new(|d, _| d["accessors"][0]["byteOffset"] = json!(4)),
            "do not fit",
        ),
        (
            "huge-count",
            Box::new(|d, _| d["accessors"][0]["count"] = json!(u64::MAX / 2)),
            "accessors[0]",
        ),
        (
            "small-stride",
            Box::new(|d, _| d["bufferViews"][4]["byteStride"] = json!(8)),
            "byteStride",
        ),
        (
            "index-range",
            Box::new(|d, bin| {
                // The light's first index (u16) points past its 4 vertices.
                let at = d["bufferViews"][1]["byteOffset"].as_u64().unwrap() as usize;
                bin[at..at + 2].copy_from_slice(&9u16.to_le_bytes());
            }),
            "vertex index 9 is out of range",
        ),
        (
            "nan",
            Box::new(|d, bin| {
                let at = d["bufferViews"][0]["byteOffset"].as_u64().unwrap() as usize;
                bin[at + 4..at + 8].copy_from_slice(&f32::NAN.to_le_bytes());
            }),
            "non-finite position",
        ),
        (
            "inf",
            Box::new(|d, bin| {
                let at = d["bufferViews"][0]["byteOffset"].as_u64().unwrap() as usize;
                bin[at..at + 4].copy_from_slice(&f32::INFINITY.to_le_bytes());
            }),
            "non-finite position",
        ),
        (
            "sparse",
            Box::new(|d, _| {
                d["accessors"][0]["sparse"] = json!({"count": 1,
                "indices": {"bufferView": 1, "componentType": 5123},
                "values": {"bufferView": 0}})
            }),
            "sparse",
        ),
        (
            "position-type",
            Box::new(|d, _| d["accessors"][0]["componentType"] = json!(5123)),
            "VEC3 of FLOAT",
        ),
        (
            "index-type",
            Box::new(|d, _| d["accessors"][1]["componentType"] = json!(5126)),
            "not an index type",
        ),
        (
            "bad-enum",
            Box::new(|d, _| d["accessors"][1]["componentType"] = json!(1234)),
            "accessors[1]",
        ),
        (
            "no-position",
            Box::new(|d, _| d["meshes"][0]["primitives"][0]["attributes"] = json!({"NORMAL": 0})),
            "POSITION",
        ),
        (
            "buffer-short",
            Box::new(|d, bin| {
                d["buffers"] = json!([{"byteLength": bin.len() + 100,
                "uri": format!("data:application/octet-stream;base64,{}", base64(bin))}]);
            }),
            "byteLength",
        ),
        (
            "data-uri",
            Box::new(|d, bin| {
                d["buffers"] = json!([{"byteLength": bin.len(), "uri": "data:text/plain,hello"}]);
            }),
            "unsupported data URI",
        ),
        (
            "bad-base64",
            Box::new(|d, bin| {
                d["buffers"] = json!([{"byteLength": bin.len(), "uri": "data:application/octet-stream;base64,AB*D"}]);
            }),
            "base64",
        ),
        (
            "http",
            Box::new(|d, bin| {
                d["buffers"] =
                    json!([{"byteLength": bin.len(), "uri": "https://example.invalid/x.bin"}]);
            }),
            "URI scheme",
        ),
        (
            "missing-bin",
            Box::new(|d, bin| {
                d["buffers"] = json!([{"byteLength": bin.len(), "uri": "nowhere.bin"}]);
            }),
            "nowhere.bin",
        ),
        (
            "no-uri",
            Box::new(|d, bin| d["buffers"] = json!([{"byteLength": bin.len()}])),
            "BIN chunk",
        ),
        (
            "required-ext",
            Box::new(|d, _| d["extensionsRequired"] = json!(["KHR_draco_mesh_compression"])),
            "KHR_draco_mesh_compression",
        ),
        (
            "matrix",
            Box::new(|d, _| {
                d["nodes"][4]["matrix"] = json!([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.5, 0, 0, 0, 1])
            }),
            "nodes[4].matrix",
        ),
        (
            "zero-quat",
            Box::new(|d, _| d["nodes"][3]["rotation"] = json!([0, 0, 0, 0])),
            "nodes[3].rotation",
        ),
        (
            "not-json-type",
            Box::new(|d, _| d["nodes"] = json!("nodes")),
            "invalid glTF JSON",
        ),
    ];
    for (name, edit, needle) in cases {
        let e = load_error(&format!("{name}.gltf"), &scene_json(edit));
        assert!(e.contains(needle), "{name}: expected '{needle}' in: {e}");
    }
}

#[test]
fn degenerate_triangles_are_repaired_like_obj_faces() {
    let mut b = Builder::default();
    let pts = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 0.0, 0.0], // the same position as vertex 1
        [2.0, 0.0, 0.0],
    ];
    let pos = b.positions(&pts, 0, None);
    // A good triangle, one with a repeated position, one collinear.
    let idx = b.indices(&[0, 1, 2, 0, 1, 3, 0, 1, 4], 5123);
    let doc = json!({
        "asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}],
        "nodes": [{"name": "Bits", "mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}, "indices": idx}]}],
        "bufferViews": b.views, "accessors": b.accessors
    });
    let dir = temp_dir("degenerate");
    let scene = load_gltf(&write(&dir, "bits", doc, &b.bin, Form::Glb)).unwrap();
    assert_eq!(scene.objects.len(), 1);
    assert_eq!(scene.objects[0].mesh.faces.len(), 1);
    let text = scene.warnings.join("\n");
    assert!(
        text.contains("object 'Bits'") && text.contains("dropped"),
        "{text}"
    );
    assert!(
        text.contains("(triangle 1)") && text.contains("(triangle 2)"),
        "{text}"
    );
}

#[test]
fn random_byte_flips_never_panic() {
    let good = valid_glb();
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for _ in 0..400 {
        let mut g = good.clone();
        for _ in 0..1 + next() % 4 {
            let at = (next() % g.len() as u64) as usize;
            g[at] = next() as u8;
        }
        // Either loads soundly or fails; a panic fails the test.
        if let Ok(s) = load_gltf_bytes(&g, "flipped.glb", None) {
            for o in &s.objects {
                assert!(o.mesh.positions.iter().all(|p| p.is_finite()));
                assert!(
                    o.mesh
                        .faces
                        .iter()
                        .flatten()
                        .all(|&i| (i as usize) < o.mesh.positions.len())
                );
            }
        }
    }
}
