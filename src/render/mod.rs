//! TODO
pub mod image_io;
