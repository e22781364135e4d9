//! Wavefront OBJ/MTL loading (docs/scenes.md, "OBJ and MTL").
//!
//! The text goes through two passes:
//!
//! 1. A validating pre-scan of our own, which knows line numbers (tobj does not report them):
//!    it parses every vertex in f64, rejects malformed or non-finite numbers and out-of-range
//!    face indices with `file:line` errors, drops faces with fewer than 3 vertices, and writes a
//!    sanitized copy of the file that contains only what tobj needs (`v`, `f` with position
//!    indices, `o`, `g`, `usemtl`, `mtllib`). MTL files get the same treatment.
//! 2. tobj (no triangulation, single index) parses the sanitized copy and splits it into
//!    objects: one model per `o`/`g` statement and per material change within it.
//!
//! The models are then rebuilt from the pre-scan's f64 data (tobj is compiled with f32
//! numbers): the k-th face tobj reports is the k-th face of the pre-scan, the k-th material
//! the k-th material definition met through the `mtllib` statements. Faces are repaired (see
//! `repair_face`) and each object keeps only the vertices it uses.

use super::face_triangulation::{FaceSurface, Split, face_surface};
use super::precision::{PrecisionSurvey, WrittenPrecision, written_number};
use super::{Material, Mesh, ObjectFlags, Scene, SceneObject};
use crate::Result;
use glam::DVec3;
use std::collections::HashSet;
use std::path::Path;

/// At most this many warnings are kept per loaded file; the rest are counted.
const MAX_WARNINGS: usize = 40;

/// Smallest and largest GGX alpha (docs/scenes.md).
pub const ALPHA_MIN: f64 = 1e-4;
pub const ALPHA_MAX: f64 = 1.0;

/// Loads an OBJ file (and the MTL files its `mtllib` statements name, relative to the OBJ's
/// directory) with the default flags: light = (Ke > 0), occluder = true, receiver = true.
pub fn load_obj(path: &Path) -> Result<Scene> {
    let label = path.display().to_string();
    let text = read_text(path, &label)?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    load_obj_with(&text, &label, &|name: &str| {
        let p = dir.join(name);
        let label = p.display().to_string();
        match std::fs::read(&p) {
            Ok(bytes) => MtlSource::Found {
                label,
                text: String::from_utf8_lossy(&bytes).into_owned(),
            },
            Err(e) => MtlSource::Missing {
                label,
                reason: e.to_string(),
            },
        }
    })
}

/// Loads OBJ text from memory. `mtl`, if given, is used for every `mtllib` statement (and also
/// when the OBJ has none); without it materials fall back to the default with a warning.
/// `name_for_errors` names the OBJ in errors and warnings.
pub fn load_obj_str(obj: &str, mtl: Option<&str>, name_for_errors: &str) -> Result<Scene> {
    let dir = Path::new(name_for_errors)
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    let resolve = |name: &str| {
        let label = dir.join(name).display().to_string();
        match mtl {
            Some(text) => MtlSource::Found {
                label,
                text: text.to_owned(),
            },
            None => MtlSource::Missing {
                label,
                reason: "no MTL text was supplied".into(),
            },
        }
    };
    let inline = mtl.is_some().then(|| {
        let stem = Path::new(name_for_errors)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "inline".into());
        format!("{stem}.mtl")
    });
    load_obj_impl(obj, name_for_errors, &resolve, inline.as_deref())
}

/// Reads a whole file as text (invalid UTF-8 is replaced, not rejected).
pub(crate) fn read_text(path: &Path, label: &str) -> Result<String> {
    match std::fs::read(path) {
        Ok(bytes) => Ok(String::from_utf8_lossy(&bytes).into_owned()),
        Err(e) => Err(crate::Error::File {
            file: label.to_owned(),
            message: format!("cannot read file: {e}"),
        }),
    }
}

/// Result of looking up the file named by an `mtllib` statement.
pub(crate) enum MtlSource {
    Found { label: String, text: String },
    Missing { label: String, reason: String },
}

/// Loads OBJ text whose `mtllib` files are provided by `resolve` (file system, embedded table).
pub(crate) fn load_obj_with(
    obj: &str,
    label: &str,
    resolve: &dyn Fn(&str) -> MtlSource,
) -> Result<Scene> {
    load_obj_impl(obj, label, resolve, None)
}

/// The GGX alpha for an MTL material (docs/scenes.md): `Pr`^2 if `Pr` is given, else
/// sqrt(2 / (Ns + 2)) if `Ns` is given (the Blinn-Phong / Beckmann correspondence, Ns < 0
/// taken as 0), else 1; always clamped to [1e-4, 1].
pub(crate) fn alpha_from_mtl(pr: Option<f64>, ns: Option<f64>) -> f64 {
    let a = match (pr, ns) {
        (Some(pr), _) => pr * pr,
        (None, Some(ns)) => (2.0 / (ns.max(0.0) + 2.0)).sqrt(),
        (None, None) => 1.0,
    };
    if a.is_finite() {
        a.clamp(ALPHA_MIN, ALPHA_MAX)
    } else {
        ALPHA_MAX
    }
}

// ---------------------------------------------------------------------------------------------
// Warnings
// ---------------------------------------------------------------------------------------------

/// The warnings of one loaded file, at most [`MAX_WARNINGS`] of them listed.
#[derive(Default)]
pub(crate) struct Warnings {
    list: Vec<String>,
    suppressed: usize,
}

impl Warnings {
    fn at(&mut self, file: &str, line: usize, msg: impl std::fmt::Display) {
        self.push(format!("{file}:{line}: {msg}"));
    }
    pub(crate) fn push(&mut self, w: String) {
        if self.list.len() < MAX_WARNINGS {
            self.list.push(w);
        } else {
            self.suppressed += 1;
        }
    }
    pub(crate) fn finish(mut self, file: &str) -> Vec<String> {
        if self.suppressed > 0 {
            self.list.push(format!(
                "{file}: {} more warnings not shown",
                self.suppressed
            ));
        }
        self.list
    }
}

fn line_err(file: &str, line: usize, message: impl std::fmt::Display) -> crate::Error {
    crate::Error::Line {
        file: file.to_owned(),
        line,
        message: message.to_string(),
    }
}

// ---------------------------------------------------------------------------------------------
// Pre-scan of the OBJ text
// ---------------------------------------------------------------------------------------------

/// Logical lines of an OBJ/MTL file: comments (`#` to end of line) removed, `\` continuations
/// joined; each with the 1-based number of its first physical line.
fn logical_lines(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut pending: Option<(usize, String)> = None;
    for (i, raw) in text.lines().enumerate() {
        let content = raw.split('#').next().unwrap_or("");
        let (start, mut acc) = pending.take().unwrap_or((i + 1, String::new()));
        let trimmed = content.trim_end();
        if let Some(body) = trimmed.strip_suffix('\\') {
            acc.push_str(body);
            acc.push(' ');
            pending = Some((start, acc));
        } else {
            acc.push_str(content);
            out.push((start, acc));
        }
    }
    if let Some(p) = pending {
        out.push(p);
    }
    out
}

/// The statement keyword and the rest of the line after it (trimmed).
fn split_statement(content: &str) -> Option<(&str, &str)> {
    let t = content.trim();
    let kw = t.split_whitespace().next()?;
    Some((kw, t[kw.len()..].trim()))
}

fn parse_number(tok: &str) -> Option<f64> {
    tok.parse::<f64>().ok()
}

struct ObjScan {
    /// Sanitized OBJ text for tobj.
    sanitized: String,
    positions: Vec<DVec3>,
    /// (line, 0-based vertex indices) of every face with at least 3 vertices, in file order.
    faces: Vec<(usize, Vec<u32>)>,
    /// (line, file name) of every `mtllib` statement, in file order.
    mtllibs: Vec<(usize, String)>,
    /// (line, material name) of every `usemtl` statement.
    usemtls: Vec<(usize, String)>,
    /// How precisely the vertex coordinates were written.
    precision: WrittenPrecision,
}

fn scan_obj(text: &str, file: &str, warn: &mut Warnings) -> Result<ObjScan> {
    let mut scan = ObjScan {
        sanitized: String::with_capacity(text.len()),
        positions: Vec::new(),
        faces: Vec::new(),
        mtllibs: Vec::new(),
        usemtls: Vec::new(),
        precision: WrittenPrecision::default(),
    };
    let mut survey = PrecisionSurvey::new();
    // Unknown statements by keyword: (count, first line), in the order first met.
    let mut unknown: Vec<(String, usize, usize)> = Vec::new();
    let mut ignored_elements = 0usize;
    let mut first_ignored_element = 0usize;
    let mut free_form = 0usize;
    for (line, content) in logical_lines(text) {
        let Some((kw, rest)) = split_statement(&content) else {
            continue;
        };
        let toks: Vec<&str> = rest.split_whitespace().collect();
        match kw {
            "v" => {
                let p = parse_vertex(&toks).map_err(|m| line_err(file, line, m))?;
                for t in &toks[..3] {
                    if let Some(n) = written_number(t) {
                        survey.add(n);
                    }
                }
                if scan.positions.len() >= u32::MAX as usize {
                    return Err(line_err(file, line, "too many vertices"));
                }
                scan.positions.push(p);
                scan.sanitized += &format!("v {} {} {}\n", p.x, p.y, p.z);
            }
            "vt" | "vn" | "vp" => {
                // Texture coordinates and normals are not used (normals come from the
                // geometry), but their numbers must still be numbers.
                if toks.is_empty() {
                    return Err(line_err(file, line, format!("'{kw}' without values")));
                }
                for t in &toks {
                    if parse_number(t).is_none() {
                        return Err(line_err(file, line, format!("malformed number '{t}'")));
                    }
                }
            }
            "f" | "fo" => {
                let n = scan.positions.len();
                let mut face = Vec::with_capacity(toks.len());
                for t in &toks {
                    face.push(parse_face_index(t, n).map_err(|m| line_err(file, line, m))?);
                }
                if face.len() < 3 {
                    warn.at(
                        file,
                        line,
                        format!(
                            "face with {} vertices dropped (a face needs at least 3)",
                            face.len()
                        ),
                    );
                    continue;
                }
                scan.sanitized.push('f');
                for &i in &face {
                    scan.sanitized += &format!(" {}", i + 1);
                }
                scan.sanitized.push('\n');
                scan.faces.push((line, face));
            }
            "l" | "p" => {
                if ignored_elements == 0 {
                    first_ignored_element = line;
                }
                ignored_elements += 1;
            }
            "o" | "g" => {
                scan.sanitized += &format!("{kw} {rest}\n");
            }
            "usemtl" => {
                if rest.is_empty() {
                    warn.at(file, line, "'usemtl' without a material name ignored");
                } else {
                    scan.usemtls.push((line, rest.to_owned()));
                    scan.sanitized += &format!("usemtl {rest}\n");
                }
            }
            "mtllib" => {
                if rest.is_empty() {
                    warn.at(file, line, "'mtllib' without a file name ignored");
                } else {
                    scan.mtllibs.push((line, rest.to_owned()));
                    scan.sanitized += &format!("mtllib {rest}\n");
                }
            }
            // Smoothing, merging groups, level of detail, display attributes: irrelevant.
            "s" | "mg" | "lod" | "bevel" | "c_interp" | "d_interp" | "shadow_obj" | "trace_obj"
            | "usemap" | "maplib" | "ctech" | "stech" => {}
            "cstype" | "deg" | "bmat" | "step" | "curv" | "curv2" | "surf" | "parm" | "trim"
            | "hole" | "scrv" | "sp" | "end" | "con" => free_form += 1,
            other => {
                let shown: String = other.chars().take(24).collect();
                match unknown.iter_mut().find(|u| u.0 == shown) {
                    Some(u) => u.1 += 1,
                    None => unknown.push((shown, 1, line)),
                }
            }
        }
    }
    for (kw, count, first) in unknown {
        let times = if count == 1 {
            String::new()
        } else {
            format!(" ({count} times, first here)")
        };
        warn.at(
            file,
            first,
            format!("unknown statement '{kw}' ignored{times}"),
        );
    }
    scan.precision = survey.finish();
    if ignored_elements > 0 {
        warn.at(
            file,
            first_ignored_element,
            format!("{ignored_elements} line/point elements ('l', 'p') ignored"),
        );
    }
    if free_form > 0 {
        warn.push(format!(
            "{file}: {free_form} free-form geometry statements ignored"
        ));
    }
    Ok(scan)
}

/// `v x y z [w]` or `v x y z r g b`; the coordinates must be finite, w finite and nonzero.
fn parse_vertex(toks: &[&str]) -> crate::Result<DVec3> {
    if toks.len() < 3 {
        return Err(crate::Error::from(format!(
            "vertex needs 3 coordinates, found {}",
            toks.len()
        )));
    }
    let mut vals = Vec::with_capacity(toks.len());
    for t in toks {
        vals.push(parse_number(t).ok_or_else(|| format!("malformed number '{t}'"))?);
    }
    for (t, v) in toks.iter().zip(&vals).take(3) {
        if !v.is_finite() {
            return Err(crate::Error::from(format!(
                "non-finite vertex coordinate '{t}'"
            )));
        }
    }
    let mut p = DVec3::new(vals[0], vals[1], vals[2]);
    match vals.len() {
        3 | 6 => {}
        4 => {
            let w = vals[3];
            if !w.is_finite() || w == 0.0 {
                return Err(crate::Error::from(format!(
                    "invalid homogeneous weight w = '{}'",
                    toks[3]
                )));
            }
            p /= w;
            if !p.is_finite() {
                return Err("vertex coordinate overflows after division by w".into());
            }
        }
        n => {
            return Err(crate::Error::from(format!(
                "vertex has {n} values; expected 3 (x y z), 4 (x y z w) or 6 (x y z r g b)"
            )));
        }
    }
    Ok(p)
}

/// One `v`, `v/vt`, `v//vn` or `v/vt/vn` token of a face; returns the 0-based vertex index.
/// Negative indices are relative to the `defined` vertices seen so far.
fn parse_face_index(tok: &str, defined: usize) -> crate::Result<u32> {
    let v = tok.split('/').next().unwrap_or("");
    let idx: i64 = v
        .parse()
        .map_err(|_| format!("malformed face vertex index '{tok}'"))?;
    let abs = if idx > 0 {
        idx - 1
    } else if idx < 0 {
        (defined as i64).saturating_add(idx)
    } else {
        return Err("face vertex index 0 is invalid (OBJ indices start at 1)".into());
    };
    if abs < 0 || abs >= defined as i64 {
        return Err(crate::Error::from(format!(
            "face vertex index {idx} is out of range: {defined} vertices are defined before this line"
        )));
    }
    Ok(abs as u32)
}

// ---------------------------------------------------------------------------------------------
// MTL
// ---------------------------------------------------------------------------------------------

/// One `newmtl` block with the values penumbra uses, parsed in f64.
#[derive(Clone, Debug, Default)]
struct MtlEntry {
    name: String,
    kd: Option<DVec3>,
    ks: Option<DVec3>,
    ke: Option<DVec3>,
    ns: Option<f64>,
    pr: Option<f64>,
    pm: Option<f64>,
    ni: Option<f64>,
    /// Written by Blender's OBJ exporter (its MTL's first line says so): `Ks` is the
    /// Principled BSDF's specular level and `Ns` its roughness (docs/scenes.md, "Materials
    /// written by Blender").
    blender: bool,
}

impl MtlEntry {
    fn material(&self) -> Material {
        let kd = self.kd.unwrap_or(Material::default().kd);
        let ks = self.ks.unwrap_or(DVec3::ZERO);
        let ke = self.ke.unwrap_or(DVec3::ZERO);
        let name = self.name.clone();
        if !self.blender {
            let alpha = alpha_from_mtl(self.pr, self.ns);
            return match self.pm {
                // The metal/dielectric split of glTF (and of the PBR extension): a metal
                // reflects its base colour.
                Some(m) => Material {
                    name,
                    kd: kd * (1.0 - m),
                    ks: ks * (1.0 - m) + kd * m,
                    alpha,
                    ke,
                },
                None => Material {
                    name,
                    kd,
                    ks,
                    alpha,
                    ke,
                },
            };
        }
        // Blender: F0 = ((Ni − 1)/(Ni + 1))² · 2·Ks for a dielectric (Ks the specular level,
        // 0.5 meaning the IOR's own reflectance), roughness from Pr, else from
        // Ns = 1000 (1 − roughness)²; alpha = roughness²; metallic Pm splits like glTF.
        let ior = self
            .ni
            .filter(|n| n.is_finite() && *n >= 1.0)
            .unwrap_or(1.5);
        let f0 = ((ior - 1.0) / (ior + 1.0)).powi(2);
        let dielectric = (ks * 2.0 * f0).min(DVec3::ONE);
        let roughness = match (self.pr, self.ns) {
            (Some(r), _) => r,
            (None, Some(ns)) => 1.0 - (ns / 1000.0).clamp(0.0, 1.0).sqrt(),
            (None, None) => 0.5,
        };
        let alpha = (roughness * roughness).clamp(ALPHA_MIN, ALPHA_MAX);
        let m = self.pm.unwrap_or(0.0).clamp(0.0, 1.0);
        Material {
            name,
            kd: kd * (1.0 - m),
            ks: dielectric * (1.0 - m) + kd * m,
            alpha,
            ke,
        }
    }
}

/// Validates an MTL file; returns its sanitized text (for tobj) and its entries in order.
fn scan_mtl(text: &str, file: &str, warn: &mut Warnings) -> Result<(String, Vec<MtlEntry>)> {
    let mut sanitized = String::new();
    let mut entries: Vec<MtlEntry> = Vec::new();
    let mut outside_warned = false;
    let blender = text.starts_with("# Blender");
    for (line, content) in logical_lines(text) {
        let Some((kw, rest)) = split_statement(&content) else {
            continue;
        };
        if kw == "newmtl" {
            if rest.is_empty() {
                return Err(line_err(file, line, "'newmtl' without a material name"));
            }
            entries.push(MtlEntry {
                name: rest.to_owned(),
                blender,
                ..MtlEntry::default()
            });
            sanitized += &format!("newmtl {rest}\n");
            continue;
        }
        let toks: Vec<&str> = rest.split_whitespace().collect();
        let used = matches!(kw, "Kd" | "Ks" | "Ke" | "Ns" | "Pr" | "Pm" | "Ni");
        let Some(cur) = entries.last_mut() else {
            if used && !outside_warned {
                warn.at(file, line, format!("'{kw}' before any 'newmtl' ignored"));
                outside_warned = true;
            }
            continue;
        };
        match kw {
            "Kd" | "Ks" | "Ke" => {
                let c = parse_color(kw, &toks).map_err(|m| line_err(file, line, m))?;
                let clamped = c.max(DVec3::ZERO);
                if clamped != c {
                    warn.at(file, line, format!("negative {kw} clamped to 0"));
                }
                if kw == "Kd" && clamped.max_element() > 1.0 {
                    warn.at(
                        file,
                        line,
                        "Kd above 1 reflects more light than it receives",
                    );
                }
                if kw == "Ks" && clamped.max_element() > 1.0 {
                    warn.at(file, line, "Ks (F0) above 1 is not physical");
                }
                sanitized += &format!("{kw} {} {} {}\n", clamped.x, clamped.y, clamped.z);
                match kw {
                    "Kd" => cur.kd = Some(clamped),
                    "Ks" => cur.ks = Some(clamped),
                    _ => cur.ke = Some(clamped),
                }
            }
            "Ns" | "Pr" | "Pm" | "Ni" => {
                let [t] = toks[..] else {
                    return Err(line_err(
                        file,
                        line,
                        format!("'{kw}' needs exactly one number, found {}", toks.len()),
                    ));
                };
                let v = parse_number(t)
                    .ok_or_else(|| line_err(file, line, format!("malformed number '{t}'")))?;
                if !v.is_finite() {
                    return Err(line_err(file, line, format!("non-finite {kw} '{t}'")));
                }
                let v = if v < 0.0 {
                    warn.at(file, line, format!("negative {kw} clamped to 0"));
                    0.0
                } else {
                    v
                };
                sanitized += &format!("{kw} {v}\n");
                match kw {
                    "Ns" => cur.ns = Some(v),
                    "Pr" => cur.pr = Some(v),
                    "Pm" => cur.pm = Some(v.min(1.0)),
                    _ => cur.ni = Some(v),
                }
            }
            // Known but unused by penumbra (ambient, transparency, refraction, textures,
            // PBR extensions other than Pr, ...).
            "Ka" | "Tf" | "d" | "Tr" | "illum" | "sharpness" | "Ps" | "Pc" | "Pcr" | "aniso"
            | "anisor" | "bump" | "disp" | "decal" | "refl" | "norm" => {}
            other if other.starts_with("map_") => {}
            other => {
                let shown: String = other.chars().take(24).collect();
                warn.at(
                    file,
                    line,
                    format!("unknown MTL statement '{shown}' ignored"),
                );
            }
        }
    }
    Ok((sanitized, entries))
}

/// `Kd r [g b]`: one number means grey; three numbers r g b; all finite.
fn parse_color(kw: &str, toks: &[&str]) -> crate::Result<DVec3> {
    if let Some(&first) = toks.first()
        && (first == "spectral" || first == "xyz")
    {
        return Err(crate::Error::from(format!(
            "'{kw} {first}' is not supported; give r g b"
        )));
    }
    let mut vals = Vec::with_capacity(3);
    for t in toks {
        let v = parse_number(t).ok_or_else(|| format!("malformed number '{t}'"))?;
        if !v.is_finite() {
            return Err(crate::Error::from(format!("non-finite {kw} value '{t}'")));
        }
        vals.push(v);
    }
    match vals[..] {
        [g] => Ok(DVec3::splat(g)),
        [r, g, b] => Ok(DVec3::new(r, g, b)),
        _ => Err(crate::Error::from(format!(
            "'{kw}' needs 1 or 3 numbers, found {}",
            vals.len()
        ))),
    }
}

// ---------------------------------------------------------------------------------------------
// Face repair
// ---------------------------------------------------------------------------------------------

/// Outcome of [`repair_face`].
#[derive(Debug, PartialEq)]
pub(crate) enum FaceRepair {
    /// The face is fine as it is.
    Kept(Vec<u32>),
    /// Repeated consecutive vertices were removed; the rest is a valid face.
    Repaired(Vec<u32>, String),
    /// The face is dropped, for the given reason.
    Dropped(String),
}

/// Repairs one face (docs/scenes.md, "Repairs"):
/// * consecutive repeats (same index, or a different index at the identical position,
///   including the last vertex repeating the first) are removed;
/// * a face left with fewer than 3 vertices, or a face of (numerically) zero area, is dropped.
///
/// A face that revisits a vertex non-consecutively (a keyhole around a hole) is kept here;
/// [`face_surface`] splits it into triangles.
///
/// Zero area means |area| <= 1e-12 * (longest edge)^2, i.e. all vertices collinear to
/// ~1e-12 relative precision.
pub(crate) fn repair_face(face: &[u32], positions: &[DVec3]) -> FaceRepair {
    let pos = |i: u32| positions.get(i as usize).copied();
    if face.iter().any(|&i| pos(i).is_none()) {
        return FaceRepair::Dropped("vertex index out of range".into());
    }
    let same = |a: u32, b: u32| a == b || pos(a) == pos(b);
    let mut out: Vec<u32> = Vec::with_capacity(face.len());
    for &v in face {
        if out.last().is_none_or(|&l| !same(l, v)) {
            out.push(v);
        }
    }
    while out.len() > 1 && same(out[0], out[out.len() - 1]) {
        out.pop();
    }
    let removed = face.len() - out.len();
    if out.len() < 3 {
        return FaceRepair::Dropped(format!(
            "degenerate face dropped: fewer than 3 distinct vertices ({} of {})",
            out.len(),
            face.len()
        ));
    }
    let pts: Vec<DVec3> = out.iter().filter_map(|&i| pos(i)).collect();
    let area = crate::math::polygon_area_vector(pts.iter().copied()).length();
    let longest = (0..pts.len())
        .map(|k| pts[k].distance(pts[(k + 1) % pts.len()]))
        .fold(0.0, f64::max);
    if area.is_nan() || area <= 1e-12 * longest * longest {
        return FaceRepair::Dropped("degenerate face dropped: zero area".into());
    }
    if removed > 0 {
        FaceRepair::Repaired(
            out,
            format!(
                "repeated vertex removed from face ({removed} of {})",
                face.len()
            ),
        )
    } else {
        FaceRepair::Kept(out)
    }
}

/// The faces of one object that one kind of repair or note applies to: one warning for all of
/// them, with their count, their first lines and the worst case.
#[derive(Default)]
struct Tally {
    lines: Vec<usize>,
    count: usize,
    worst: f64,
    worst_line: usize,
    worst_tolerance: f64,
}

/// How many lines a grouped warning lists.
const LISTED_LINES: usize = 6;

impl Tally {
    fn add(&mut self, line: usize, worst: f64, tolerance: f64) {
        self.count += 1;
        if self.lines.len() < LISTED_LINES {
            self.lines.push(line);
        }
        if self.count == 1 || worst > self.worst {
            (self.worst, self.worst_line, self.worst_tolerance) = (worst, line, tolerance);
        }
    }

    /// "line 12" or "lines 8, 12, 13" or "lines 8, 12, ... (96 faces)" (with `unit` "line";
    /// glTF objects number their triangles instead).
    fn where_(&self, unit: &str) -> String {
        let list: Vec<String> = self.lines.iter().map(|l| l.to_string()).collect();
        match self.count {
            1 => format!("{unit} {}", list[0]),
            n if n <= LISTED_LINES => format!("{unit}s {}", list.join(", ")),
            n => format!("{unit}s {}, ... ({n} faces)", list.join(", ")),
        }
    }
}

/// The repairs and notes of one object's faces, by kind.
#[derive(Default)]
struct FaceTallies {
    repeated: Tally,
    /// Dropped faces, by reason, in the order first met.
    dropped: Vec<(String, Tally)>,
    /// Not planar: split into triangles.
    non_planar: Tally,
    /// Not planar, and not simple in the plane of their normal either: fanned.
    non_planar_fanned: Tally,
    /// Planar, not convex, triangulated inside themselves.
    triangulated: Tally,
    /// Planar, not convex, and not simple either (no ear): fanned.
    non_convex: Tally,
    /// Touching themselves (keyholes), triangulated inside themselves.
    keyhole: Tally,
    /// Touching themselves with no triangulation: dropped.
    no_surface: Tally,
    /// The same face (or triangle of a split face) as an earlier one: dropped.
    duplicate: Tally,
}

impl FaceTallies {
    fn emit(self, src: &FaceSource, object: &str, warn: &mut Warnings) {
        let unit = src.origin.unit();
        let t = &self.repeated;
        if t.count > 0 {
            src.origin.warn(
                warn,
                src.file,
                t.lines[0],
                format!(
                    "object '{object}': repeated vertices removed from {} ({})",
                    count_faces(t.count),
                    t.where_(unit)
                ),
            );
        }
        for (reason, t) in &self.dropped {
            src.origin.warn(
                warn,
                src.file,
                t.lines[0],
                format!(
                    "object '{object}': {} dropped: {reason} ({})",
                    count_faces(t.count),
                    t.where_(unit)
                ),
            );
        }
        let t = &self.non_planar;
        if t.count > 0 {
            src.origin.warn(
                warn,
                src.file,
                t.worst_line,
                format!(
                    "object '{object}': {} not planar beyond the precision the file was \
                     written with ({}); the worst, on this line, has a vertex {:.2e} off its \
                     plane where rounding explains {:.1e} ({}); each split into triangles \
                     (docs/scenes.md, \"The surface of a face\")",
                    faces(t.count),
                    src.precision,
                    t.worst,
                    t.worst_tolerance,
                    t.where_(unit)
                ),
            );
        }
        let notes = [
            (
                &self.triangulated,
                "not convex, each triangulated inside itself (a fan from its first vertex \
                 would fold outside it)",
            ),
            (
                &self.keyhole,
                "touching themselves (a hole bridged by a keyhole slit), each triangulated \
                 inside itself",
            ),
            (
                &self.non_planar_fanned,
                "not planar and crossing themselves in the plane of their normal; each fanned \
                 from its first vertex",
            ),
            (
                &self.non_convex,
                "neither convex nor simple (the outline crosses itself); each fanned from its \
                 first vertex, which covers area the outline does not",
            ),
            (
                &self.no_surface,
                "touching themselves with no triangulation inside themselves: dropped",
            ),
            (
                &self.duplicate,
                "the same as an earlier face (same vertices, same winding): dropped",
            ),
        ];
        for (t, what) in notes {
            if t.count > 0 {
                src.origin.warn(
                    warn,
                    src.file,
                    t.lines[0],
                    format!(
                        "object '{object}': {} {what} ({})",
                        faces(t.count),
                        t.where_(unit)
                    ),
                );
            }
        }
    }
}

/// "1 face" / "3 faces".
fn count_faces(n: usize) -> String {
    if n == 1 {
        "1 face".into()
    } else {
        format!("{n} faces")
    }
}

/// "1 face is" / "3 faces are".
fn faces(n: usize) -> String {
    let verb = if n == 1 { "is" } else { "are" };
    format!("{} {verb}", count_faces(n))
}

// ---------------------------------------------------------------------------------------------
// Assembly
// ---------------------------------------------------------------------------------------------

fn load_obj_impl(
    obj: &str,
    file: &str,
    resolve: &dyn Fn(&str) -> MtlSource,
    inline_mtl: Option<&str>,
) -> Result<Scene> {
    let mut warn = Warnings::default();
    let mut scan = scan_obj(obj, file, &mut warn)?;

    // Material libraries, in the order tobj will request them.
    let mut requests: Vec<(usize, String)> = Vec::new();
    if let Some(name) = inline_mtl
        && scan.mtllibs.is_empty()
    {
        requests.push((0, name.to_owned()));
        scan.sanitized = format!("mtllib {name}\n{}", scan.sanitized);
    }
    requests.extend(scan.mtllibs.iter().cloned());
    let mut libs: Vec<(String, String, Vec<MtlEntry>)> = Vec::new(); // (request, text, entries)
    let mut all_entries: Vec<MtlEntry> = Vec::new();
    for (line, name) in &requests {
        let (text, entries) = match resolve(name) {
            MtlSource::Found { label, text } => {
                let mut mw = Warnings::default();
                let r = scan_mtl(&text, &label, &mut mw)?;
                for w in mw.finish(&label) {
                    warn.push(w);
                }
                r
            }
            MtlSource::Missing { label, reason } => {
                let msg = format!(
                    "material library '{label}' not loaded ({reason}); its materials fall back to the default"
                );
                if *line > 0 {
                    warn.at(file, *line, msg);
                } else {
                    warn.push(format!("{file}: {msg}"));
                }
                (String::new(), Vec::new())
            }
        };
        all_entries.extend(entries.iter().cloned());
        libs.push((name.clone(), text, entries));
    }
    let known: HashSet<&str> = all_entries.iter().map(|e| e.name.as_str()).collect();
    let mut reported = HashSet::new();
    for (line, name) in &scan.usemtls {
        if !known.contains(name.as_str()) && reported.insert(name.clone()) {
            warn.at(
                file,
                *line,
                format!("material '{name}' is not defined; using the default material"),
            );
        }
    }

    // Object splitting by tobj. (`..Default::default()` covers tobj's optional-feature fields.)
    #[allow(clippy::needless_update)]
    let opts = tobj::LoadOptions {
        single_index: true,
        triangulate: false,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let internal = |what: &str| crate::Error::File {
        file: file.to_owned(),
        message: format!("internal error while splitting objects: {what}"),
    };
    let (models, materials) =
        tobj::load_obj_buf(&mut scan.sanitized.as_bytes(), &opts, |p: &Path| {
            let key = p.to_string_lossy();
            match libs.iter().find(|(name, _, _)| *name == key) {
                Some((_, text, _)) => tobj::load_mtl_buf(&mut text.as_bytes()),
                None => Ok(Default::default()),
            }
        })
        .map_err(|e| internal(&e.to_string()))?;
    let materials = materials.unwrap_or_default();
    if materials.len() != all_entries.len()
        || materials
            .iter()
            .zip(&all_entries)
            .any(|(m, e)| m.name != e.name)
    {
        return Err(internal("material lists disagree"));
    }

    let mut scene = Scene::default();
    let mut next_face = 0usize;
    for model in &models {
        let m = &model.mesh;
        let arities: Vec<u32> = if m.face_arities.is_empty() {
            vec![3; m.indices.len() / 3]
        } else {
            m.face_arities.clone()
        };
        let total: usize = arities.iter().map(|&a| a as usize).sum();
        let end = next_face + arities.len();
        if total != m.indices.len() || end > scan.faces.len() {
            return Err(internal("face counts disagree"));
        }
        let faces = &scan.faces[next_face..end];
        next_face = end;
        if faces
            .iter()
            .zip(&arities)
            .any(|((_, f), &a)| f.len() != a as usize)
        {
            return Err(internal("face sizes disagree"));
        }
        if faces.is_empty() {
            continue;
        }
        let material = match m.material_id.and_then(|i| all_entries.get(i)) {
            Some(e) => e.material(),
            None => Material::default(),
        };
        let precision = scan.precision;
        let rounding = |g: u32| {
            scan.positions
                .get(g as usize)
                .map_or(0.0, |&p| precision.vertex_rounding(p))
        };
        let src = FaceSource {
            file,
            origin: FaceOrigin::Lines,
            positions: &scan.positions,
            rounding: &rounding,
            precision: precision.describe(),
        };
        if let Some(obj) = build_object(&model.name, faces, &src, material, &mut warn) {
            scene.objects.push(obj);
        }
    }
    if next_face != scan.faces.len() {
        return Err(internal("faces left over"));
    }
    if scene.objects.is_empty() {
        warn.push(format!("{file}: no faces found; the scene is empty"));
    }
    scene.warnings = warn.finish(file);
    Ok(scene)
}

/// How the warnings of [`build_object`] name the faces they are about.
pub(crate) enum FaceOrigin<'a> {
    /// OBJ faces, each numbered by its line.
    Lines,
    /// glTF triangles, numbered from 0 in the order read; `context` names where they come
    /// from (node, mesh, primitives).
    Triangles { context: &'a str },
}

impl FaceOrigin<'_> {
    fn unit(&self) -> &'static str {
        match self {
            FaceOrigin::Lines => "line",
            FaceOrigin::Triangles { .. } => "triangle",
        }
    }

    /// A warning about the face numbered `n`.
    fn warn(&self, warn: &mut Warnings, file: &str, n: usize, msg: impl std::fmt::Display) {
        match self {
            FaceOrigin::Lines => warn.at(file, n, msg),
            FaceOrigin::Triangles { context } => warn.push(format!("{file}: {context}: {msg}")),
        }
    }
}

/// The vertices that the faces given to [`build_object`] index, and how they were written.
pub(crate) struct FaceSource<'a> {
    /// The file, for warnings.
    pub file: &'a str,
    pub origin: FaceOrigin<'a>,
    pub positions: &'a [DVec3],
    /// The rounding radius of each vertex (`Mesh::rounding`, docs/scenes.md "Precision").
    pub rounding: &'a dyn Fn(u32) -> f64,
    /// The precision in words, for the note on non-planar faces.
    pub precision: String,
}

/// Repairs the faces of one object and keeps only the vertices it uses; its repairs and notes
/// are grouped by kind (one warning each, with a count and the worst case). Each face comes
/// with its number for the warnings (its line, or its triangle: `src.origin`).
pub(crate) fn build_object(
    name: &str,
    faces: &[(usize, Vec<u32>)],
    src: &FaceSource,
    material: Material,
    warn: &mut Warnings,
) -> Option<SceneObject> {
    let positions = src.positions;
    let mut mesh = Mesh::default();
    let mut local = std::collections::HashMap::<u32, u32>::new();
    let mut tallies = FaceTallies::default();
    let mut seen: HashSet<Vec<u32>> = HashSet::new();
    // Every edge of the object, with the diagonals added by splitting quads: a quad is split
    // along a diagonal that is not an edge yet, so that two quads sharing two edges (at a
    // vertex of valence two) do not both cut that vertex off into one triangle twice, a fin
    // of two coincident faces that leaves the mesh non-manifold.
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let mut edges: HashSet<(u32, u32)> = faces
        .iter()
        .flat_map(|(_, f)| (0..f.len()).map(move |k| key(f[k], f[(k + 1) % f.len()])))
        .collect();
    for (line, face) in faces {
        let kept = match repair_face(face, positions) {
            FaceRepair::Kept(f) => f,
            FaceRepair::Repaired(f, _) => {
                tallies.repeated.add(*line, 0.0, 0.0);
                f
            }
            FaceRepair::Dropped(reason) => {
                let reason = reason
                    .trim_start_matches("degenerate face dropped: ")
                    .to_owned();
                match tallies.dropped.iter_mut().find(|(r, _)| *r == reason) {
                    Some((_, t)) => t.add(*line, 0.0, 0.0),
                    None => {
                        let mut t = Tally::default();
                        t.add(*line, 0.0, 0.0);
                        tallies.dropped.push((reason, t));
                    }
                }
                continue;
            }
        };
        let pts: Vec<DVec3> = kept.iter().map(|&i| positions[i as usize]).collect();
        let rounding = kept.iter().map(|&g| (src.rounding)(g)).fold(0.0, f64::max);
        mesh.rounding = mesh.rounding.max(rounding);
        let mut pieces = vec![kept.clone()];
        match face_surface(&pts, rounding) {
            FaceSurface::Polygon => {}
            FaceSurface::NoSurface => {
                tallies.no_surface.add(*line, 0.0, 0.0);
                continue;
            }
            FaceSurface::Triangles { tris, why, fanned } => {
                // One note per face: why it was split, and whether only a fan was left.
                match (why, fanned) {
                    (Split::NonPlanar { off, tolerance }, _) => {
                        tallies.non_planar.add(*line, off, tolerance);
                        if fanned {
                            tallies.non_planar_fanned.add(*line, 0.0, 0.0);
                        }
                    }
                    (Split::NonConvex, false) => tallies.triangulated.add(*line, 0.0, 0.0),
                    (Split::NonConvex, true) => tallies.non_convex.add(*line, 0.0, 0.0),
                    // `face_surface` never fans a keyhole (it has no surface then).
                    (Split::Keyhole, _) => tallies.keyhole.add(*line, 0.0, 0.0),
                }
                let tris = if kept.len() == 4 {
                    // The diagonal the two triangles share, from corner 0 or from corner 1.
                    let from_0 = tris.iter().all(|t| t.contains(&0) && t.contains(&2));
                    let (d, other, other_d) = if from_0 {
                        ((0, 2), [[1, 2, 3], [1, 3, 0]], (1, 3))
                    } else {
                        ((1, 3), [[0, 1, 2], [0, 2, 3]], (0, 2))
                    };
                    let taken = edges.contains(&key(kept[d.0], kept[d.1]));
                    let (tris, d) = if taken {
                        (other.to_vec(), other_d)
                    } else {
                        (tris, d)
                    };
                    edges.insert(key(kept[d.0], kept[d.1]));
                    tris
                } else {
                    tris
                };
                pieces = tris
                    .iter()
                    .map(|t| t.iter().map(|&k| kept[k]).collect())
                    .collect();
            }
        }
        for piece in pieces {
            // The same face twice (same vertices, same winding) would make every edge of it
            // non-manifold; the copy is dropped. The same face wound the other way is kept: the
            // two are the sides of a sheet.
            let start = (0..piece.len()).min_by_key(|&k| piece[k]).unwrap_or(0);
            let key: Vec<u32> = (0..piece.len())
                .map(|k| piece[(start + k) % piece.len()])
                .collect();
            if !seen.insert(key) {
                tallies.duplicate.add(*line, 0.0, 0.0);
                continue;
            }
            let f = piece
                .iter()
                .map(|&g| {
                    *local.entry(g).or_insert_with(|| {
                        mesh.positions.push(positions[g as usize]);
                        mesh.positions.len() as u32 - 1
                    })
                })
                .collect();
            mesh.faces.push(f);
        }
    }
    tallies.emit(src, name, warn);
    if mesh.faces.is_empty() {
        let line = faces.first().map_or(0, |f| f.0);
        src.origin.warn(
            warn,
            src.file,
            line,
            format!("object '{name}' has no valid faces and is skipped"),
        );
        return None;
    }
    let flags = ObjectFlags {
        light: material.is_emissive(),
        occluder: true,
        receiver: true,
        is_static: false,
    };
    Some(SceneObject {
        name: name.to_owned(),
        mesh,
        material,
        flags,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn alpha_fallbacks() {
        assert_eq!(alpha_from_mtl(Some(0.5), Some(10.0)), 0.25);
        assert!((alpha_from_mtl(None, Some(98.0)) - (0.02f64).sqrt()).abs() < 1e-15);
        assert_eq!(alpha_from_mtl(None, Some(0.0)), 1.0);
        assert_eq!(alpha_from_mtl(None, None), 1.0);
        assert_eq!(alpha_from_mtl(Some(0.0), None), ALPHA_MIN);
        assert_eq!(alpha_from_mtl(Some(3.0), None), 1.0);
        assert_eq!(alpha_from_mtl(None, Some(1e30)), ALPHA_MIN);
        assert_eq!(alpha_from_mtl(Some(f64::NAN), None), 1.0);
    }

    #[test]
    fn logical_lines_strip_comments_and_join_continuations() {
        let l = logical_lines("v 1 2 3 # c\nf 1 \\\n 2 3\n# only\n\\");
        assert_eq!(l[0], (1, "v 1 2 3 ".to_owned()));
        assert_eq!(l[1].0, 2);
        assert_eq!(
            l[1].1.split_whitespace().collect::<Vec<_>>(),
            ["f", "1", "2", "3"]
        );
        assert_eq!(l[2], (4, String::new()));
        assert_eq!(l.len(), 4);
    }

    /// A face written twice is kept once (its edges stay manifold), with a warning naming the
    /// line of the copy; the same face wound the other way is kept (a two-sided sheet).
    #[test]
    fn a_duplicate_face_is_dropped_and_a_reversed_one_kept() {
        let obj = "v 0.000000 0.000000 0.000000\nv 1.000000 0.000000 0.000000\n\
                   v 1.000000 1.000000 0.000000\nv 0.000000 1.000000 0.000000\n\
                   f 1 2 3 4\nf 2 3 4 1\nf 4 3 2 1\n";
        let scene = load_obj_str(obj, None, "twice.obj").unwrap();
        let m = &scene.objects[0].mesh;
        assert_eq!(m.faces.len(), 2, "{:?}", m.faces);
        assert!(
            scene
                .warnings
                .iter()
                .any(|w| w.starts_with("twice.obj:6:") && w.contains("same as an earlier face")),
            "{:?}",
            scene.warnings
        );
        let poly = crate::geometry::Polyhedron::new(&m.positions, &m.faces);
        assert_eq!(poly.diagnostics.nonmanifold_edges, 0);
        assert!(poly.diagnostics.closed_manifold);
    }

    /// The keyhole face of an n-gon cap with a hole (OBJ indices repeating the slit's ends)
    /// loads as triangles around the hole: their area is the ring's, and none covers the hole.
    #[test]
    fn a_keyhole_face_loads_as_triangles_around_its_hole() {
        // Written with 6 decimals, as Blender writes (integers would say a rounding of 0.5).
        let v = [
            (0, 0),
            (4, 0),
            (4, 4),
            (0, 4),
            (1, 1),
            (1, 3),
            (3, 3),
            (3, 1),
        ];
        let mut obj: String = v
            .iter()
            .map(|(x, y)| format!("v {x}.000000 {y}.000000 0.000000\n"))
            .collect();
        obj += "f 1 2 3 4 1 5 6 7 8 5\n";
        let scene = load_obj_str(&obj, None, "keyhole.obj").unwrap();
        let m = &scene
            .objects
            .first()
            .unwrap_or_else(|| panic!("{:?}", scene.warnings))
            .mesh;
        assert!(m.faces.iter().all(|f| f.len() == 3), "{:?}", m.faces);
        let area: f64 = m
            .faces
            .iter()
            .map(|f| {
                let p: Vec<DVec3> = f.iter().map(|&i| m.positions[i as usize]).collect();
                crate::math::polygon_area_vector(p.iter().copied()).z
            })
            .sum();
        assert!((area - 12.0).abs() < 1e-12, "{area}");
        let centre = DVec3::new(2.0, 2.0, 0.0);
        for f in &m.faces {
            let p: Vec<DVec3> = f.iter().map(|&i| m.positions[i as usize]).collect();
            let inside = (0..3).all(|k| (p[(k + 1) % 3] - p[k]).cross(centre - p[k]).z > 0.0);
            assert!(!inside, "a triangle covers the hole: {p:?}");
        }
    }

    #[test]
    fn face_repairs() {
        let p = [
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::X, // same position as 1
            DVec3::new(2.0, 0.0, 0.0),
        ];
        assert_eq!(repair_face(&[0, 1, 2], &p), FaceRepair::Kept(vec![0, 1, 2]));
        assert!(
            matches!(repair_face(&[0, 1, 1, 2, 0], &p), FaceRepair::Repaired(f, _) if f == [0, 1, 2])
        );
        assert!(
            matches!(repair_face(&[0, 1, 3, 2], &p), FaceRepair::Repaired(f, _) if f == [0, 1, 2])
        );
        assert!(matches!(
            repair_face(&[0, 1, 0], &p),
            FaceRepair::Dropped(_)
        ));
        assert!(
            matches!(repair_face(&[0, 1, 4], &p), FaceRepair::Dropped(r) if r.contains("zero area"))
        );
        // Folded back onto itself: no area.
        assert!(
            matches!(repair_face(&[0, 1, 2, 3], &p), FaceRepair::Dropped(r) if r.contains("zero area"))
        );
        // A keyhole (a square around a square hole, the slit's two ends visited twice) is
        // kept here; `face_surface` splits it.
        let q = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let ring = [
            q(0.0, 0.0),
            q(4.0, 0.0),
            q(4.0, 4.0),
            q(0.0, 4.0),
            q(1.0, 1.0),
            q(1.0, 3.0),
            q(3.0, 3.0),
            q(3.0, 1.0),
        ];
        let keyhole = [0, 1, 2, 3, 0, 4, 5, 6, 7, 4];
        assert_eq!(
            repair_face(&keyhole, &ring),
            FaceRepair::Kept(keyhole.to_vec())
        );
        assert!(matches!(
            repair_face(&[0, 9, 2], &p),
            FaceRepair::Dropped(_)
        ));
    }
}
