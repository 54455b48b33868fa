//! Files in and out: inputs checked to be regular files, outputs checked
//! up front and written atomically, mesh files (OBJ, PLY, optionally
//! gzip-compressed), spectrum files (two-column CSV), image files, and the
//! crate's one hash.
//!
//! Everything here turns bytes on disk into the renderer's types or back,
//! and reports failures as [`crate::Error`]s that name the file (and the
//! line, where the format has lines). Nothing here renders.

mod atomic_file;
mod files;
mod hash;
pub mod image;
mod mesh_file;
mod ply;
mod spectrum_file;

pub use atomic_file::{NAME_MAX, temp_path, write_atomic};
pub use files::{check_aliasing, check_output, check_regular, is_snapshot_name, parent_dir, read_input};
pub use hash::{Fnv1a, fnv1a};
pub use mesh_file::{MeshData, parse_mesh, read_mesh_file};

/// `data` gzip-compressed (for tests of the readers of `.gz` files).
#[cfg(test)]
pub(crate) fn gzip(data: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(data).unwrap();
    e.finish().unwrap()
}
pub use spectrum_file::{
    SpectrumFileError, SpectrumRow, TableRow, parse_spectrum_file, parse_spectrum_rows, parse_table,
};
