//! Mesh files: OBJ (through tobj, triangulated) and PLY (ASCII or binary,
//! [`super::ply`]), either optionally gzip-compressed (`.obj.gz`, `.ply.gz`),
//! read into positions, triangles and optional normals in file order.
//! Placing and intersecting a mesh is [`crate::shape::Mesh`]'s work.

use std::io::Read;
use std::path::Path;

use glam::Vec3;

use super::ply;
use crate::error::{Error, Result};

/// Reads and decompresses a mesh file into positions, triangles and optional normals.
pub fn read_mesh_file(path: &Path) -> Result<MeshData> {
    parse_mesh(super::read_input(path)?, path)
}

/// Parses a mesh file's bytes (`path`'s name picks the format; errors name it).
pub fn parse_mesh(raw: impl AsRef<[u8]>, path: &Path) -> Result<MeshData> {
    let raw = raw.as_ref();
    let name = path.file_name().map(|n| n.to_string_lossy().to_lowercase()).unwrap_or_default();
    // A big gzip-compressed PLY: parsed while it inflates where it can (an ASCII body).
    if name.ends_with(".ply.gz")
        && raw.len() >= STREAM_GZ_BYTES
        && let Some(d) = ply::parse_gz(raw, path)
    {
        return Ok(MeshData { positions: d.positions, triangles: d.triangles, normals: d.normals, uvs: d.uvs });
    }
    let (data, name) = if let Some(stem) = name.strip_suffix(".gz") {
        let mut out = Vec::with_capacity(raw.len() * 4);
        flate2::read::MultiGzDecoder::new(raw)
            .read_to_end(&mut out)
            .map_err(|e| Error::mesh(path, format!("gzip decompression failed: {e}")))?;
        (std::borrow::Cow::Owned(out), stem.to_string())
    } else {
        (std::borrow::Cow::Borrowed(raw), name)
    };
    if name.ends_with(".ply") {
        let d = ply::parse(&data, path)?;
        Ok(MeshData { positions: d.positions, triangles: d.triangles, normals: d.normals, uvs: d.uvs })
    } else if name.ends_with(".obj") {
        load_obj(&data, path)
    } else {
        Err(Error::mesh(path, "unknown mesh format: expected a name ending in .obj, .ply, .obj.gz or .ply.gz"))
    }
}

/// Gzip-compressed PLY files of at least this many bytes are parsed while they
/// inflate ([`ply::parse_gz`]); smaller ones are not worth a second thread.
const STREAM_GZ_BYTES: usize = 1 << 18;

/// A mesh file's contents in file order, before any transform or filtering.
#[derive(Debug)]
pub struct MeshData {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles as vertex indices (polygons fan-triangulated).
    pub triangles: Vec<[u32; 3]>,
    /// Per-vertex normals, when the file has one for every vertex.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates, when the file has them for every vertex
    /// (OBJ `vt`; PLY `u v`, `s t`, `texture_u texture_v` or `texture_s texture_t`),
    /// as the file gives them (no flip).
    pub uvs: Option<Vec<[f32; 2]>>,
}

/// Reads an OBJ file (all its objects and groups merged) with tobj, triangulated, with
/// one index per vertex so that normals line up with positions.
fn load_obj(data: &[u8], path: &Path) -> Result<MeshData> {
    let opts = tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() };
    let mut reader = std::io::BufReader::new(data);
    // tobj multiplies face indices without overflow checks: a huge index (e.g. a
    // relative -2147483649) panics in builds with overflow checks. Turn that into an error.
    let parsed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        tobj::load_obj_buf(&mut reader, &opts, |_| Ok((Vec::new(), Default::default())))
    }))
    .map_err(|_| Error::mesh(path, "OBJ parse error: index out of range (the OBJ parser panicked)"))?;
    let (models, _materials) = parsed.map_err(|e| Error::mesh(path, format!("OBJ parse error: {e}")))?;
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    let mut normals = Vec::new();
    let mut all_normals = true;
    let mut uvs = Vec::new();
    let mut all_uvs = true;
    for model in &models {
        let m = &model.mesh;
        let base = positions.len() as u32;
        let nv = m.positions.len() / 3;
        positions.extend(m.positions.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])));
        if m.normals.len() == m.positions.len() {
            normals.extend(m.normals.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])));
        } else {
            all_normals = false;
        }
        if m.texcoords.len() == 2 * nv {
            uvs.extend(m.texcoords.chunks_exact(2).map(|c| [c[0], c[1]]));
        } else {
            all_uvs = false;
        }
        if m.indices.len() % 3 != 0 {
            return Err(Error::mesh(
                path,
                format!("object '{}': {} indices is not a multiple of 3", model.name, m.indices.len()),
            ));
        }
        for c in m.indices.chunks_exact(3) {
            if let Some(&bad) = c.iter().find(|&&i| i as usize >= nv) {
                return Err(Error::mesh(
                    path,
                    format!("object '{}': vertex index {} out of range ({nv} vertices)", model.name, bad + 1),
                ));
            }
            indices.push([base + c[0], base + c[1], base + c[2]]);
        }
    }
    let normals = (all_normals && !normals.is_empty()).then_some(normals);
    let uvs = (all_uvs && !uvs.is_empty()).then_some(uvs);
    Ok(MeshData { positions, triangles: indices, normals, uvs })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::gzip;

    /// An ASCII PLY of `n` vertices in a strip of `n - 2` triangles.
    fn strip(n: usize) -> String {
        let mut t = format!(
            "ply\nformat ascii 1.0\nelement vertex {n}\nproperty float x\nproperty float y\nproperty float z\n\
             element face {}\nproperty list uchar int vertex_indices\nend_header\n",
            n - 2
        );
        for i in 0..n {
            let f = i as f32;
            t += &format!("{} {} {}\n", f * 0.37, (f * 0.11).sin(), 1.0 / (f + 1.0));
        }
        for i in 0..n - 2 {
            t += &format!("3 {} {} {}\n", i, i + 1, i + 2);
        }
        t
    }

    /// A gzip file big enough to be parsed while it inflates gives the data of
    /// its inflated text parsed on its own; a truncated or corrupt stream (data,
    /// CRC) is one error naming the file and the gzip failure, a bad line the
    /// line's error exactly as in the uncompressed file.
    #[test]
    fn big_gzip_ply_streams_and_fails_cleanly() {
        let text = strip(40_000);
        let gz = gzip(text.as_bytes());
        assert!(gz.len() >= STREAM_GZ_BYTES, "{} bytes: too small to stream", gz.len());
        let (zipped, plain) = (Path::new("dir/big.ply.gz"), Path::new("dir/big.ply"));
        let a = parse_mesh(gz.clone(), zipped).unwrap();
        let b = parse_mesh(text.clone().into_bytes(), plain).unwrap();
        assert_eq!(a.positions.len(), 40_000);
        assert_eq!(a.triangles.len(), 39_998);
        assert!(a.positions == b.positions && a.triangles == b.triangles && a.normals.is_none());
        let mut corrupt = gz.clone();
        for k in (corrupt.len() / 2..corrupt.len() / 2 + 64).step_by(3) {
            corrupt[k] ^= 0x5a;
        }
        let mut bad_crc = gz.clone();
        let n = bad_crc.len();
        bad_crc[n - 8] ^= 1;
        for (what, bytes) in [("truncated", gz[..gz.len() / 2].to_vec()), ("corrupt", corrupt), ("crc", bad_crc)] {
            let e = parse_mesh(bytes, zipped).err().unwrap_or_else(|| panic!("{what}: an error")).to_string();
            assert!(e.contains("big.ply.gz") && e.contains("gzip decompression failed"), "{what}: {e}");
        }
        let bad = text.replacen("\n3 30000 30001 30002\n", "\n3 30000 x 30002\n", 1);
        assert_ne!(bad, text);
        let want = parse_mesh(bad.clone().into_bytes(), plain).expect_err("an error").to_string();
        let want = want.replace("big.ply:", "big.ply.gz:");
        assert!(want.contains("big.ply.gz: line "), "{want}");
        let line = want.split("line ").nth(1).unwrap().split(':').next().unwrap().to_string();
        let got = parse_mesh(gzip(bad.as_bytes()), zipped).expect_err("an error").to_string();
        assert_eq!(got, want);
        // The line number, counted independently: header 9 lines, 40000 vertices, 30000 faces before it.
        assert_eq!(line, (9 + 40_000 + 30_000 + 1).to_string());
    }
}
