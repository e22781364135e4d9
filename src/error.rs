//! The library's one error type: every fallible function of the library returns [`Result`].
//! A message names the input's file, and its line where the format has lines, worded as the
//! command line prints it. Where a caller acts on why (an edit that cannot be made, a file
//! that is not an LTC table), the error carries its kind as a value to match on
//! (`Error::Edit(EditError::NoDrag)`). Errors are cheap to clone, so that a result kept for
//! later callers (a cached load, a step of a sliced render) can be handed out again.

/// Why the library could not do what was asked.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Error {
    /// A file that cannot be read or written as what it should be.
    #[error("{file}: {message}")]
    File { file: String, message: String },
    /// An input file that cannot be read as what it should be, at a line of it.
    #[error("{file}:{line}: {message}")]
    Line {
        file: String,
        line: usize,
        message: String,
    },
    /// Anything else, in words: a request that cannot be carried out (a value out of range,
    /// an object that is not there, a method that does not apply), a render cancelled, or
    /// the error of a library the files are read with, where the caller names the file.
    #[error("{0}")]
    Request(String),
    /// An edit of a scene that cannot be made.
    #[error(transparent)]
    Edit(#[from] EditError),
    /// Bytes that are not an LTC table.
    #[error(transparent)]
    TableFormat(#[from] TableFormatError),
    /// A three.js LTC source that cannot be imported.
    #[error(transparent)]
    Import(#[from] ImportError),
}

/// Why an edit of a scene could not be made (`scene::edit`).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EditError {
    #[error("object index {index} is out of range: the scene has {count} objects")]
    ObjectOutOfRange { index: usize, count: usize },
    #[error("no object is named '{0}'")]
    NoSuchObject(String),
    #[error("{count} objects are named '{name}'; give its index instead ({indices})")]
    AmbiguousName {
        name: String,
        count: usize,
        indices: String,
    },
    #[error("no drag is in progress")]
    NoDrag,
    #[error("the transform is not finite (or its rotation axis is zero)")]
    NotFinite,
    #[error(
        "the scene does not match the edit history (object {0} has another vertex count, or the \
         object count differs)"
    )]
    SceneMismatch(usize),
}

/// Why bytes are not an LTC table (`ltc::LtcTable::from_bytes`).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum TableFormatError {
    #[error("not an LTC table (bad magic)")]
    Magic,
    #[error("unsupported LTC table version {0}")]
    Version(u32),
    #[error("bad LTC table header: {0}")]
    Header(&'static str),
    #[error("LTC table has {got} bytes, expected {expected}")]
    Length { got: usize, expected: usize },
    #[error("LTC table checksum mismatch")]
    Checksum,
    #[error(
        "LTC table record {0} holds a non-finite value, a scale <= 0 or a cosine share outside [0, 1)"
    )]
    Record(usize),
}

/// Why a three.js LTC source cannot be imported (`ltc::published::from_three_js`).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ImportError {
    #[error("array {0} not found")]
    Missing(&'static str),
    #[error("array {name}: bad number {text:?}")]
    Number { name: &'static str, text: String },
    #[error("array {name} has {got} numbers, expected {expected}")]
    Length {
        name: &'static str,
        got: usize,
        expected: usize,
    },
    #[error("texel ({x}, {y}): M⁻¹ has determinant {det} <= 0")]
    Determinant { x: usize, y: usize, det: f64 },
}

/// The library's result.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// The error of reading or writing `file`: its path and what went wrong.
    pub fn file(file: impl std::fmt::Display, message: impl std::fmt::Display) -> Self {
        Error::File {
            file: file.to_string(),
            message: message.to_string(),
        }
    }
}

/// Names the file an error concerns, and what was being done to it: `file: what: error`, the
/// words the command line prints.
pub trait InFile<T> {
    /// The error as an [`Error::File`] of `file` (`what` empty: the error's words alone).
    fn in_file(self, file: impl std::fmt::Display, what: &str) -> Result<T>;
}

impl<T, E: std::fmt::Display> InFile<T> for std::result::Result<T, E> {
    fn in_file(self, file: impl std::fmt::Display, what: &str) -> Result<T> {
        self.map_err(|e| match what {
            "" => Error::file(file, e),
            what => Error::file(file, format!("{what}: {e}")),
        })
    }
}

/// The errors of the libraries the library reads and writes files with, in their own words
/// (the caller names the file, [`InFile`], where the error does not).
macro_rules! from_foreign {
    ($($t:ty),*) => {$(
        impl From<$t> for Error {
            fn from(e: $t) -> Self {
                Error::Request(e.to_string())
            }
        }
    )*};
}
from_foreign!(
    std::io::Error,
    serde_json::Error,
    image::ImageError,
    exr::error::Error
);

impl From<String> for Error {
    fn from(message: String) -> Self {
        Error::Request(message)
    }
}

impl From<&str> for Error {
    fn from(message: &str) -> Self {
        Error::Request(message.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The words are the command line's: a file and its line before the message.
    #[test]
    fn messages_name_the_file_and_line() {
        let e = Error::Line {
            file: "a.obj".into(),
            line: 7,
            message: "bad face".into(),
        };
        assert_eq!(e.to_string(), "a.obj:7: bad face");
        assert_eq!(
            Error::file("b.toml", "no camera").to_string(),
            "b.toml: no camera"
        );
        assert_eq!(Error::from("cancelled").to_string(), "cancelled");
    }
}
