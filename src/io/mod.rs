//! Files in and out: atomic writes, mesh files (OBJ, PLY, optionally
//! gzip-compressed), spectrum files (two-column CSV), image files, and the crate's one hash.
//!
//! Everything here turns bytes on disk into the renderer's types or back,
//! and reports failures as [`crate::Error`]s that name the file (and the
//! line, where the format has lines). Nothing here renders.

mod atomic_file;
mod hash;
pub mod image;
mod mesh_file;
mod ply;
mod spectrum_file;

pub use atomic_file::{temp_path, write_atomic};
pub use hash::{Fnv1a, fnv1a};
pub use mesh_file::{MeshData, read_mesh_file};
pub use spectrum_file::{SpectrumFileError, parse_spectrum_file};
