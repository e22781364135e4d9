//! The bytes of glTF buffers: the GLB's BIN chunk, `data:` URIs with base64 payloads, and
//! external files relative to the glTF file. Each buffer is read when first used.

use crate::Result;
use gltf::json;
use std::path::{Path, PathBuf};

/// The buffers of one file, read on demand.
pub(super) struct Buffers<'a> {
    root: &'a json::Root,
    bin: Option<&'a [u8]>,
    /// Where external buffers are looked up; `None` when the file was given as bytes only.
    dir: Option<PathBuf>,
    file: &'a str,
    loaded: Vec<Option<Vec<u8>>>,
}

impl<'a> Buffers<'a> {
    pub(super) fn new(
        root: &'a json::Root,
        bin: Option<&'a [u8]>,
        dir: Option<&Path>,
        file: &'a str,
    ) -> Self {
        Buffers {
            root,
            bin,
            dir: dir.map(Path::to_path_buf),
            file,
            loaded: vec![None; root.buffers.len()],
        }
    }

    fn err(&self, message: String) -> crate::Error {
        crate::Error::File {
            file: self.file.to_owned(),
            message,
        }
    }

    /// The bytes of buffer `index` (at most its declared `byteLength`).
    pub(super) fn get(&mut self, index: usize) -> Result<&[u8]> {
        let Some(buffer) = self.root.buffers.get(index) else {
            return Err(self.err(format!(
                "buffers[{index}] does not exist ({} buffers)",
                self.root.buffers.len()
            )));
        };
        if self.loaded[index].is_none() {
            let mut data = self.read(index, buffer)?;
            let declared = buffer.byte_length.0;
            if (data.len() as u64) < declared {
                return Err(self.err(format!(
                    "buffers[{index}]: byteLength is {declared} but its data has only {} bytes",
                    data.len()
                )));
            }
            data.truncate(declared as usize);
            self.loaded[index] = Some(data);
        }
        Ok(self.loaded[index].as_deref().unwrap_or(&[]))
    }

    fn read(&self, index: usize, buffer: &json::Buffer) -> Result<Vec<u8>> {
        let Some(uri) = &buffer.uri else {
            return match (index, self.bin) {
                (0, Some(bin)) => Ok(bin.to_vec()),
                (0, None) => {
                    Err(self
                        .err("buffers[0] has no uri and the file has no GLB BIN chunk".to_owned()))
                }
                _ => Err(self.err(format!(
                    "buffers[{index}] has no uri (only buffers[0] may be the GLB BIN chunk)"
                ))),
            };
        };
        if let Some(rest) = uri.strip_prefix("data:") {
            let Some((header, payload)) = rest.split_once(',') else {
                return Err(self.err(format!("buffers[{index}].uri: malformed data URI (no ',')")));
            };
            if !header.ends_with(";base64") {
                return Err(self.err(format!(
                    "buffers[{index}].uri: unsupported data URI '{}': only base64 data URIs are read",
                    shorten(header)
                )));
            }
            return decode_base64(payload)
                .map_err(|m| self.err(format!("buffers[{index}].uri: invalid base64 data: {m}")));
        }
        if has_scheme(uri) {
            return Err(self.err(format!(
                "buffers[{index}].uri '{}': unsupported URI scheme (only data: URIs and \
                 relative file paths are read)",
                shorten(uri)
            )));
        }
        let rel = percent_decode(uri)
            .map_err(|m| self.err(format!("buffers[{index}].uri '{}': {m}", shorten(uri))))?;
        let Some(dir) = &self.dir else {
            return Err(self.err(format!(
                "buffers[{index}] is the external file '{rel}', which cannot be read when the \
                 glTF is given without its directory"
            )));
        };
        let path = dir.join(&rel);
        std::fs::read(&path).map_err(|e| {
            self.err(format!(
                "buffers[{index}]: cannot read the external buffer '{}': {e}",
                path.display()
            ))
        })
    }
}

/// The first characters of a long text, for messages.
fn shorten(s: &str) -> String {
    if s.chars().count() <= 48 {
        s.to_owned()
    } else {
        format!("{}...", s.chars().take(48).collect::<String>())
    }
}

/// Whether `uri` starts with a URI scheme (`http:`, `file:`): letters, then digits, `+`, `-`,
/// `.`, then a colon, at least two characters long (so a Windows drive `C:` is not a scheme).
fn has_scheme(uri: &str) -> bool {
    let Some((scheme, _)) = uri.split_once(':') else {
        return false;
    };
    scheme.len() >= 2
        && scheme.starts_with(|c: char| c.is_ascii_alphabetic())
        && scheme
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'))
}

/// Decodes `%XX` escapes of a relative URI reference (the path is UTF-8).
fn percent_decode(uri: &str) -> crate::Result<String> {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = b
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or("malformed percent escape")?;
            out.push(hex);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| "the decoded path is not UTF-8".into())
}

/// Standard base64 (RFC 4648, `+` and `/`), with or without `=` padding; whitespace is
/// skipped.
fn decode_base64(text: &str) -> crate::Result<Vec<u8>> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3);
    let mut acc: u32 = 0;
    let mut bits = 0u32;
    let mut padding = 0usize;
    for (pos, c) in text.bytes().enumerate() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            b'=' => {
                padding += 1;
                continue;
            }
            c if c.is_ascii_whitespace() => continue,
            _ => return Err(crate::Error::from(format!("character {pos} is not base64"))),
        };
        if padding > 0 {
            return Err(crate::Error::from(format!(
                "data after '=' padding at character {pos}"
            )));
        }
        acc = (acc << 6) | v as u32;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    if bits >= 6 || padding > 2 {
        return Err(crate::Error::from("truncated base64 data".to_owned()));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trips() {
        assert_eq!(decode_base64("").unwrap(), b"");
        assert_eq!(decode_base64("TQ==").unwrap(), b"M");
        assert_eq!(decode_base64("TWE=").unwrap(), b"Ma");
        assert_eq!(decode_base64("TWFu").unwrap(), b"Man");
        assert_eq!(decode_base64("TWFuTQ").unwrap(), b"ManM");
        assert_eq!(decode_base64("AAEC/w==").unwrap(), [0, 1, 2, 255]);
        assert!(decode_base64("TW!u").is_err());
        assert!(decode_base64("T").is_err());
        assert!(decode_base64("TQ==TQ==").is_err());
    }

    #[test]
    fn uris() {
        assert!(has_scheme("http://x/y.bin"));
        assert!(has_scheme("file:///y.bin"));
        assert!(!has_scheme("y.bin"));
        assert!(!has_scheme("C:/y.bin"));
        assert_eq!(percent_decode("a%20b.bin").unwrap(), "a b.bin");
        assert!(percent_decode("a%2").is_err());
    }
}
