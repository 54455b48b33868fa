//! `rust-v convert scene.pbrt -o scene.ron`: the description a pbrt scene reads
//! into, written as a RON scene that renders the same image bit for bit.
//!
//! Paths are rewritten relative to the output file. Triangles read from a PLY file
//! (placed in world space by the importer) are written to a binary PLY beside the
//! output (`NAME-mesh-K.ply`, float32 positions, normals and uvs exactly as
//! loaded) and referenced as `Mesh(path: ...)`; inline `trianglemesh` data stays inline.
//! Instanced objects (`ObjectBegin`/`ObjectInstance`) are written as `groups:` and
//! `Instance` objects, a group's PLY triangles as `NAME-group-G-mesh-J.ply`.

use std::path::{Component, Path, PathBuf};

use serde::Serialize;

use super::Imported;
use crate::error::{Error, Result, show_path};
use crate::io::{MeshData, read_input, write_atomic};
use crate::scene::check::Check;
use crate::scene::desc::{
    CameraDesc, EnvironmentDesc, LightDesc, Materials, MediumDesc, NamedMap, ObjectDesc, ShapeDesc, SpectrumDesc,
};
use crate::settings::{IntegratorKind, SettingsPatch};

/// The `render:` block as written.
#[derive(Serialize)]
struct Render {
    #[serde(skip_serializing_if = "Option::is_none")]
    width: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    height: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    spp: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    seed: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    max_bounces: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    integrator: Option<Integrator>,
}

/// The integrators a pbrt scene maps to, spelt as in a scene file.
#[derive(Serialize)]
#[allow(non_camel_case_types)]
enum Integrator {
    auto,
    path,
    bdpt,
    lighttrace,
    caustics,
    whitted,
    spectral,
}

/// The scene file as written.
#[derive(Serialize)]
struct Out<'a> {
    camera: &'a CameraDesc,
    render: Render,
    materials: &'a Materials,
    #[serde(skip_serializing_if = "is_empty")]
    media: &'a NamedMap<MediumDesc>,
    objects: &'a [ObjectDesc],
    #[serde(skip_serializing_if = "no_groups")]
    groups: &'a NamedMap<Vec<ObjectDesc>>,
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    lights: &'a [LightDesc],
    #[serde(skip_serializing_if = "Option::is_none")]
    environment: &'a Option<EnvironmentDesc>,
}

fn is_empty(m: &&NamedMap<MediumDesc>) -> bool {
    m.0.is_empty()
}

fn no_groups(m: &&NamedMap<Vec<ObjectDesc>>) -> bool {
    m.0.is_empty()
}

/// Writes the triangles of `o` (read from a PLY file by the import) to the binary PLY
/// `name` in `out_dir` and makes `o` refer to it.
fn write_mesh(o: &mut ObjectDesc, out_dir: &Path, name: String, written: &mut Vec<PathBuf>) -> Result<()> {
    let ShapeDesc::Triangles { positions, indices, normals, uvs } = &o.shape else { return Ok(()) };
    let mesh = MeshData {
        positions: positions.iter().map(|p| glam::Vec3::from(*p)).collect(),
        triangles: indices.clone(),
        normals: normals.as_ref().map(|n| n.iter().map(|v| glam::Vec3::from(*v)).collect()),
        uvs: uvs.clone(),
    };
    let path = out_dir.join(&name);
    write_atomic(&path, &ply_bytes(&mesh))?;
    written.push(path);
    o.shape = ShapeDesc::Mesh { path: name, scale: None, rotate_deg: None, translate: None };
    Ok(())
}

fn render(p: &SettingsPatch) -> Render {
    Render {
        width: p.width,
        height: p.height,
        spp: p.spp,
        seed: p.seed,
        max_bounces: p.max_bounces,
        integrator: p.integrator.map(|k| match k {
            IntegratorKind::Auto => Integrator::auto,
            IntegratorKind::Path => Integrator::path,
            IntegratorKind::Bdpt => Integrator::bdpt,
            IntegratorKind::LightTrace => Integrator::lighttrace,
            IntegratorKind::Caustics => Integrator::caustics,
            IntegratorKind::Whitted => Integrator::whitted,
            IntegratorKind::Spectral => Integrator::spectral,
        }),
    }
}

/// `target` relative to the folder `base` (both made absolute); `target` itself if
/// they share no root.
fn relative(target: &Path, base: &Path) -> String {
    let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let norm = |p: PathBuf| {
        let mut out = PathBuf::new();
        for c in p.components() {
            match c {
                Component::CurDir => {}
                Component::ParentDir => {
                    out.pop();
                }
                c => out.push(c),
            }
        }
        out
    };
    let (t, b) = (norm(abs(target)), norm(abs(base)));
    let (tc, bc): (Vec<_>, Vec<_>) = (t.components().collect(), b.components().collect());
    let common = tc.iter().zip(&bc).take_while(|(a, b)| a == b).count();
    if common == 0 {
        return t.to_string_lossy().into_owned();
    }
    let mut out = PathBuf::new();
    for _ in common..bc.len() {
        out.push("..");
    }
    for c in &tc[common..] {
        out.push(c);
    }
    out.to_string_lossy().into_owned()
}

/// A binary little-endian PLY of `mesh`.
fn ply_bytes(mesh: &MeshData) -> Vec<u8> {
    let mut h = format!(
        "ply\nformat binary_little_endian 1.0\ncomment written by rust-v convert\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n",
        mesh.positions.len()
    );
    if mesh.normals.is_some() {
        h.push_str("property float nx\nproperty float ny\nproperty float nz\n");
    }
    if mesh.uvs.is_some() {
        h.push_str("property float u\nproperty float v\n");
    }
    h.push_str(&format!(
        "element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        mesh.triangles.len()
    ));
    let mut out = h.into_bytes();
    for (i, p) in mesh.positions.iter().enumerate() {
        let mut put = |v: f32| out.extend_from_slice(&v.to_le_bytes());
        p.to_array().into_iter().for_each(&mut put);
        if let Some(n) = &mesh.normals {
            n[i].to_array().into_iter().for_each(&mut put);
        }
        if let Some(uv) = &mesh.uvs {
            uv[i].into_iter().for_each(&mut put);
        }
    }
    for t in &mesh.triangles {
        out.push(3);
        for i in t {
            out.extend_from_slice(&i.to_le_bytes());
        }
    }
    out
}

/// Rewrites a texture's path (relative to the pbrt file's folder) relative to the output's.
fn rebase(s: &mut SpectrumDesc, from: &Path, to: &Path) {
    match s {
        SpectrumDesc::Image { path, .. } => *path = relative(&from.join(&*path), to),
        SpectrumDesc::File(path) => *path = relative(&from.join(&*path), to),
        SpectrumDesc::Scaled(_, inner) | SpectrumDesc::Luminance(_, inner) => rebase(inner, from, to),
        SpectrumDesc::Checkerboard { even, odd, .. } => {
            rebase(even, from, to);
            rebase(odd, from, to);
        }
        _ => {}
    }
}

/// Converts the pbrt scene `scene` to the RON scene `output` (and its mesh files);
/// returns the import's warnings and the files written beside it (meshes, grids, maps).
pub fn convert(scene: &Path, output: &Path, strict: bool) -> Result<(Vec<String>, Vec<PathBuf>)> {
    let bytes = read_input(scene)?;
    let text = std::str::from_utf8(bytes.strip_prefix(&[0xef, 0xbb, 0xbf]).unwrap_or(&bytes)).map_err(|e| {
        Error::scene_field(scene, "", format!("byte {} is not UTF-8; expected UTF-8 text", e.valid_up_to()))
    })?;
    let ctx = Check::new(scene);
    let Imported { mut desc, warnings, mesh_files, group_files, .. } = super::import(&ctx, scene, text, strict)?;
    let out_dir = crate::io::parent_dir(output).to_path_buf();
    let stem = output.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "scene".into());
    let mut written = Vec::new();
    for (k, (o, file)) in desc.objects.iter_mut().zip(&mesh_files).enumerate() {
        if let Some(e) = o.emission.as_mut() {
            rebase(e, &ctx.dir, &out_dir);
        }
        if file.is_some() {
            write_mesh(o, &out_dir, format!("{stem}-mesh-{k}.ply"), &mut written)?;
        }
    }
    for (g, ((_, members), files)) in desc.groups.0.iter_mut().zip(&group_files).enumerate() {
        for (j, (o, file)) in members.iter_mut().zip(files).enumerate() {
            if file.is_some() {
                write_mesh(o, &out_dir, format!("{stem}-group-{g}-mesh-{j}.ply"), &mut written)?;
            }
        }
    }
    // A `uniformgrid`'s density, made in memory by the import, as a file beside the output.
    for (k, (_, m)) in desc.media.0.iter_mut().filter(|(_, m)| matches!(m, MediumDesc::Grid { .. })).enumerate() {
        let MediumDesc::Grid { path, .. } = m else { continue };
        let Some(bytes) = ctx.provided(path) else { continue };
        let name = format!("{stem}-medium-{k}.vol");
        let at = out_dir.join(&name);
        write_atomic(&at, &bytes)?;
        written.push(at);
        *path = name;
    }
    if let Some(EnvironmentDesc::Image { path, .. }) = desc.environment.as_mut() {
        match ctx.provided(path) {
            // A map the import flipped in memory (see `map/lights.rs`).
            Some(bytes) => {
                let name = format!("{stem}-envmap.exr");
                let at = out_dir.join(&name);
                write_atomic(&at, &bytes)?;
                written.push(at);
                *path = name;
            }
            None => *path = relative(&ctx.dir.join(&*path), &out_dir),
        }
    }
    for (_, m) in desc.materials.0.iter_mut() {
        use crate::scene::desc::MaterialDesc as M;
        match m {
            M::Lambertian { reflectance } | M::Mirror { reflectance } | M::Plastic { reflectance, .. } => {
                rebase(reflectance, &ctx.dir, &out_dir)
            }
            M::OrenNayar { reflectance, .. } => rebase(reflectance, &ctx.dir, &out_dir),
            _ => {}
        }
    }
    let out = Out {
        camera: &desc.camera,
        render: render(&desc.render),
        materials: &desc.materials,
        media: &desc.media,
        objects: &desc.objects,
        groups: &desc.groups,
        lights: &desc.lights,
        environment: &desc.environment,
    };
    let config = ron::ser::PrettyConfig::new()
        .indentor("    ".to_string())
        .compact_arrays(true)
        .extensions(ron::extensions::Extensions::IMPLICIT_SOME);
    let body = ron::ser::to_string_pretty(&out, config)
        .map_err(|e| Error::Settings(format!("cannot write {} as RON: {e}", show_path(output))))?;
    let text = format!("// Converted from {} by rust-v convert (docs/pbrt.md).\n{body}\n", show_path(scene));
    write_atomic(output, text.as_bytes())?;
    Ok((warnings, written))
}
