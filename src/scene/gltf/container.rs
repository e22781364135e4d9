//! The file as stored: a binary GLB container (12-byte header, a JSON chunk, an optional BIN
//! chunk) or plain JSON text, parsed into the `gltf` crate's JSON document.

use crate::Result;
use gltf::binary::{ChunkType, Error as GlbError, Glb};
use gltf::json;

/// The parsed document and the GLB's BIN chunk, if any.
pub(super) struct Parsed {
    pub root: json::Root,
    pub bin: Option<Vec<u8>>,
}

fn err(file: &str, message: impl Into<String>) -> crate::Error {
    crate::Error::File {
        file: file.to_owned(),
        message: message.into(),
    }
}

/// Parses a `.glb` (recognised by its magic `glTF`, whatever the extension) or `.gltf` file.
pub(super) fn parse(bytes: &[u8], file: &str) -> Result<Parsed> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    if bytes.iter().all(u8::is_ascii_whitespace) {
        return Err(err(file, "empty file"));
    }
    if bytes.starts_with(b"glTF") {
        parse_glb(bytes, file)
    } else if bytes.len() >= 4 && bytes[0] != b'{' && !bytes[0].is_ascii_whitespace() {
        let magic: String = bytes[..4]
            .iter()
            .map(|&b| if b.is_ascii_graphic() { b as char } else { '?' })
            .collect();
        Err(err(
            file,
            format!(
                "neither binary glTF (the magic is '{magic}', not 'glTF') nor glTF JSON \
                 (which starts with '{{')"
            ),
        ))
    } else {
        let root = parse_json(bytes).map_err(|e| crate::Error::Line {
            file: file.to_owned(),
            line: e.line(),
            message: format!("invalid glTF JSON (column {}): {e}", e.column()),
        })?;
        Ok(Parsed { root, bin: None })
    }
}

fn parse_json(bytes: &[u8]) -> Result<json::Root, json::Error> {
    json::deserialize::from_slice(bytes)
}

fn u32_at(bytes: &[u8], at: usize) -> Option<u32> {
    let b = bytes.get(at..at + 4)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

fn parse_glb(bytes: &[u8], file: &str) -> Result<Parsed> {
    // The header is checked here before the crate splits the chunks: its length field must
    // cover the header itself and lie within the file.
    let (Some(version), Some(length)) = (u32_at(bytes, 4), u32_at(bytes, 8)) else {
        return Err(err(
            file,
            format!(
                "truncated GLB: {} bytes, shorter than the 12-byte header",
                bytes.len()
            ),
        ));
    };
    if version != 2 {
        return Err(err(
            file,
            format!("GLB version {version} is not supported (glTF 2.0 only)"),
        ));
    }
    let length = length as usize;
    if length < 20 {
        return Err(err(
            file,
            format!(
                "GLB header declares a total length of {length} bytes, too short for a JSON chunk"
            ),
        ));
    }
    if length > bytes.len() {
        return Err(err(
            file,
            format!(
                "truncated GLB: the header declares {length} bytes but the file has {}",
                bytes.len()
            ),
        ));
    }
    let glb = Glb::from_slice(&bytes[..length]).map_err(|e| {
        let what = match e {
            gltf::Error::Binary(b) => describe_glb_error(&b),
            other => other.to_string(),
        };
        err(file, format!("invalid GLB container: {what}"))
    })?;
    let root = parse_json(&glb.json).map_err(|e| {
        err(
            file,
            format!(
                "invalid glTF JSON in the GLB's JSON chunk (line {}, column {}): {e}",
                e.line(),
                e.column()
            ),
        )
    })?;
    Ok(Parsed {
        root,
        bin: glb.bin.map(|b| b.into_owned()),
    })
}

fn chunk_name(ty: ChunkType) -> &'static str {
    match ty {
        ChunkType::Json => "JSON",
        ChunkType::Bin => "BIN",
    }
}

fn describe_glb_error(e: &GlbError) -> String {
    match e {
        GlbError::ChunkLength {
            ty,
            length,
            length_read,
        } => format!(
            "the {} chunk declares {length} bytes but only {length_read} follow",
            chunk_name(*ty)
        ),
        GlbError::ChunkType(ty) => format!("unexpected {} chunk", chunk_name(*ty)),
        GlbError::UnknownChunkType(t) => format!("unknown chunk type {t:?}"),
        GlbError::Length {
            length,
            length_read,
        } => format!("the header declares {length} bytes of chunks but {length_read} follow"),
        GlbError::Io(io) => format!("truncated chunk header ({io})"),
        other => other.to_string(),
    }
}
