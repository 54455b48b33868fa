//! From a RON scene file to a [`Scene`]: read the file, deserialise it into a
//! [`SceneDesc`], call each model's builder (`crate::material::from_desc`,
//! `Shape::from_desc`, `Light::from_desc` and `Light::from_emission`, all
//! through one [`Check`]), resolve material names, and assemble the scene.
//! Mistakes are reported with the file, line:column (from the RON parser) or
//! the field path (for checks after parsing) and what was expected.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glam::Vec3;
use rayon::prelude::*;

use super::check::{Check, Input, MAX_MAGNITUDE};
use super::desc::{CameraDesc, LensDesc, ObjectDesc, SceneDesc, ShapeDesc, TransformDesc};
use super::{Object, Scene, surround};
use crate::bxdf::Bxdf;
use crate::camera::lens_system::{D_LINE_NM, LensSystem};
use crate::camera::{Camera, LensCamera};
use crate::error::{Error, Result};
use crate::geometry::Transform;
use crate::io::{Fnv1a, fnv1a, read_input};
use crate::light::{EnvironmentLight, Light};
use crate::material;
use crate::settings::{IntegratorKind, Settings, SettingsPatch};
use crate::shape::{Mesh, MeshAhead, MeshInstance, Placement, Shape, Then};

/// Loads the scene file at `path`; `overrides` (from the command line) take
/// precedence over the file's `render` settings. The file must be a regular
/// file of UTF-8 text (a byte-order mark is allowed).
pub fn load_scene(path: &Path, overrides: &SettingsPatch) -> Result<Scene> {
    load_scene_with_warnings(path, overrides, false).map(|(scene, _)| scene)
}

/// Loads the scene file at `path` as [`load_scene`] does, and returns the
/// warnings of its reader too, one line each (`FILE:LINE:COL: message`). A
/// path ending in `.pbrt` (any case) is read as a pbrt-v4 scene
/// ([`super::pbrt`]); `strict` then turns every warning into an error. RON
/// scenes have no warnings at load.
pub fn load_scene_with_warnings(path: &Path, overrides: &SettingsPatch, strict: bool) -> Result<(Scene, Vec<String>)> {
    let bytes = read_input(path)?;
    let text = decode_text(&bytes, path)?;
    if super::pbrt::is_pbrt(path) {
        let ctx = Check::new(path);
        let imported = super::pbrt::import(&ctx, path, text, strict)?;
        let scene = build(&ctx, imported.desc, overrides).map_err(|e| super::pbrt::locate(&imported.places, e))?;
        return Ok((identify(scene, ctx, &bytes), imported.warnings));
    }
    Ok((load(text, &bytes, path, overrides)?, Vec::new()))
}

/// Loads a scene from its text; `path` names it in errors and anchors
/// relative mesh paths.
pub fn load_scene_str(text: &str, path: &Path, overrides: &SettingsPatch) -> Result<Scene> {
    load(text, text.as_bytes(), path, overrides)
}

fn load(text: &str, bytes: &[u8], path: &Path, overrides: &SettingsPatch) -> Result<Scene> {
    let options = ron::Options::default().with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME);
    let desc: SceneDesc = options.from_str(text).map_err(|e| {
        let message = e.code.to_string();
        let message = match duplicate_key(&message).map(|name| key_positions(text, name)) {
            Some(at) if at.len() >= 2 => {
                format!("{message}: defined at {}:{} and again at {}:{}", at[0].0, at[0].1, at[1].0, at[1].1)
            }
            _ => message,
        };
        Error::Scene {
            path: path.to_path_buf(),
            position: Some((e.span.start.line, e.span.start.col)),
            field: String::new(),
            message,
        }
    })?;
    let ctx = Check::new(path);
    let scene = build(&ctx, desc, overrides).map_err(|e| locate(e, text))?;
    Ok(identify(scene, ctx, bytes))
}

/// The scene with its identity: the hashes of its file and of every file it read.
fn identify(mut scene: Scene, ctx: Check<'_>, bytes: &[u8]) -> Scene {
    let inputs = ctx.inputs.into_inner();
    scene.content_hash = content_hash(bytes, &inputs);
    scene.input_hashes = crate::checkpoint::InputHashes {
        scene: fnv1a(bytes),
        files: inputs.iter().map(|i| (i.name.clone(), i.hash)).collect(),
    };
    scene.inputs = inputs.into_iter().map(|i| i.path).collect();
    scene
}

/// The scene's identity for checkpoints: the FNV-1a hash of its file, and
/// when it reads other files (meshes, data), of those too, each by its name
/// as written in the scene and its content's hash. A scene that reads no
/// other file keeps the hash of its text alone, as checkpoints of format 1
/// have always recorded it.
fn content_hash(scene_bytes: &[u8], inputs: &[Input]) -> u64 {
    if inputs.is_empty() {
        return fnv1a(scene_bytes);
    }
    let mut h = Fnv1a::default();
    h.write(scene_bytes);
    for i in inputs {
        h.write(&[0xff]);
        h.write(i.name.as_bytes());
        h.write(&i.hash.to_le_bytes());
    }
    h.finish()
}

/// The scene text from the file's bytes: UTF-8, a leading byte-order mark
/// skipped; UTF-16 or other bytes are an error at the first bad byte.
fn decode_text<'a>(bytes: &'a [u8], path: &Path) -> Result<&'a str> {
    let at = |offset: usize, message: String| {
        let (line, col) = line_col(&bytes[..offset]);
        Error::Scene { path: path.to_path_buf(), position: Some((line, col)), field: String::new(), message }
    };
    if bytes.starts_with(&[0xff, 0xfe]) || bytes.starts_with(&[0xfe, 0xff]) {
        return Err(at(0, "the file is UTF-16 (it starts with a UTF-16 byte-order mark); expected UTF-8 text".into()));
    }
    let body = bytes.strip_prefix(&[0xef, 0xbb, 0xbf]).unwrap_or(bytes);
    let skipped = bytes.len() - body.len();
    let text = std::str::from_utf8(body).map_err(|e| {
        let offset = skipped + e.valid_up_to();
        at(offset, format!("byte 0x{:02x} is not UTF-8; expected UTF-8 text", bytes[offset]))
    })?;
    if let Some(offset) = text.find('\0') {
        return Err(at(skipped + offset, "a NUL byte (UTF-16 or binary data?); expected UTF-8 text".into()));
    }
    Ok(text)
}

/// Adds to a scene error found while building (a field path, no position) the
/// line and column in `text` of the place the path names
/// ([`super::position`]): `scene.ron:12:9: objects[3].shape.radius: ...`.
fn locate(e: Error, text: &str) -> Error {
    match e {
        Error::Scene { path, position: None, field, message } if !field.is_empty() => {
            let position = super::position::offset_of(text, &field).map(|o| line_col(&text.as_bytes()[..o]));
            Error::Scene { path, position, field, message }
        }
        e => e,
    }
}

/// 1-based line and column (in characters) just after `before`.
fn line_col(before: &[u8]) -> (usize, usize) {
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let last = before.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    let col = String::from_utf8_lossy(&before[last..]).chars().count() + 1;
    (line, col)
}

/// The name in a duplicate-key error of [`super::desc`].
fn duplicate_key(message: &str) -> Option<&str> {
    message.strip_prefix("duplicate material \"")?.split('"').next()
}

/// Where `"name"` stands as a map key (followed by `:`) in the text.
fn key_positions(text: &str, name: &str) -> Vec<(usize, usize)> {
    let quoted = format!("\"{name}\"");
    text.match_indices(&quoted)
        .filter(|(i, _)| text[i + quoted.len()..].trim_start().starts_with(':'))
        .map(|(i, _)| line_col(&text.as_bytes()[..i]))
        .collect()
}

fn build(ctx: &Check<'_>, desc: SceneDesc, overrides: &SettingsPatch) -> Result<Scene> {
    let settings = settings(ctx, &desc.render, overrides)?;

    // Materials by name; index 0 is the implicit black material of lights.
    let mut materials = vec![Bxdf::Black];
    let mut textures = vec![None];
    let mut by_name = BTreeMap::new();
    for (name, m) in &desc.materials.0 {
        by_name.insert(name.as_str(), materials.len() as u32);
        let (bxdf, texture) = material::from_desc(ctx, &format!("materials.\"{name}\""), m)?;
        materials.push(bxdf);
        textures.push(texture);
    }
    let mixes = material::mix::build(ctx, &desc.materials.0, &by_name, &mut materials)?;
    // Media by name.
    let mut media = BTreeMap::new();
    for (name, m) in &desc.media.0 {
        media.insert(name.as_str(), crate::medium::from_desc(ctx, &format!("media.\"{name}\""), m)?);
    }

    // Every mesh file is read, parsed and built (with its BVH) at once on the
    // thread pool; the loop below takes them in object order, so the scene,
    // its identity and the first error are those of loading one by one. A mesh
    // whose transform is invalid is left to the loop, which reports it.
    let jobs: Vec<MeshJob<usize>> = desc
        .objects
        .iter()
        .enumerate()
        .filter_map(|(i, o)| {
            let ShapeDesc::Mesh { path, scale, rotate_deg, translate } = &o.shape else { return None };
            let own = ctx.transform(&format!("objects[{i}].shape"), scale, rotate_deg, translate).ok()?;
            let then = match &o.transform {
                None => None,
                Some(t) => Some(placement(ctx, &format!("objects[{i}]"), t).ok()?.then()),
            };
            Some((i, ctx.dir.join(path), own, then))
        })
        .collect();
    let mut ahead: BTreeMap<usize, MeshAhead> =
        jobs.into_par_iter().map(|(i, path, own, then)| (i, Mesh::read_ahead(path, &own, then.as_ref()))).collect();

    let groups = groups(ctx, &desc, &by_name)?;
    let mut objects = Vec::with_capacity(desc.objects.len());
    // The second and further objects of each instance, after the file's objects (the
    // first takes the instance's place, so `objects[i]` stays the file's object `i`).
    let mut extra = Vec::new();
    let mut lights = Vec::new();
    for (i, o) in desc.objects.iter().enumerate() {
        let field = format!("objects[{i}]");
        let xf = match &o.transform {
            None => None,
            Some(t) => Some(placement(ctx, &field, t)?),
        };
        if let ShapeDesc::Instance { group } = &o.shape {
            let mut placed = instance(ctx, &field, o, group, xf.as_ref(), &groups)?.into_iter();
            objects.extend(placed.next());
            extra.extend(placed);
            continue;
        }
        let shape = match (&o.shape, ahead.remove(&i)) {
            (ShapeDesc::Mesh { path, .. }, Some(a)) => {
                Shape::Mesh(Box::new(Mesh::from_ahead(ctx, &format!("{field}.shape"), path, a, xf.as_ref())?))
            }
            (shape, _) => Shape::from_desc(ctx, &format!("{field}.shape"), shape, xf.as_ref())?,
        };
        let material = match &o.material {
            Some(name) => *by_name.get(name.as_str()).ok_or_else(|| {
                let known: Vec<&str> = by_name.keys().copied().collect();
                ctx.err(
                    format!("{field}.material"),
                    format!("unknown material \"{name}\"; defined: {}", known.join(", ")),
                )
            })?,
            None if o.emission.is_some() => 0,
            None => return Err(ctx.err(&field, "expected a `material` or an `emission`")),
        };
        let light = match &o.emission {
            None => None,
            Some(e) => {
                lights.push(Light::from_emission(ctx, &field, &shape, e, o.two_sided)?);
                Some(lights.len() as u32 - 1)
            }
        };
        let interior = match &o.interior {
            None => None,
            Some(name) => {
                let field = format!("{field}.interior");
                let m = media.get(name.as_str()).ok_or_else(|| {
                    let known: Vec<&str> = media.keys().copied().collect();
                    ctx.err(&field, format!("unknown medium \"{name}\"; defined: {}", known.join(", ")))
                })?;
                if mixes.get(material as usize).is_some_and(Option::is_some) {
                    return Err(ctx.err(
                        &field,
                        "the material is a Mix (chosen per hit): an interior needs a Dielectric or an Interface",
                    ));
                }
                let bxdf = &materials[material as usize];
                if !bxdf.bounds_volume() {
                    return Err(ctx.err(
                        &field,
                        "an interior needs a material that bounds a volume: a Dielectric or an Interface",
                    ));
                }
                if bxdf.absorption().is_some() {
                    return Err(ctx.err(
                        &field,
                        "the material has an `absorption:` (itself an interior medium); give one or the other",
                    ));
                }
                let m = if m.is_grid() {
                    let b = shape.bounds().ok_or_else(|| {
                        ctx.err(
                            &field,
                            "a Grid medium fills its object's bounds: the object must be bounded (not a Plane)",
                        )
                    })?;
                    m.placed(b.min, b.max)
                } else {
                    m.clone()
                };
                Some(Box::new(m))
            }
        };
        objects.push(Object { shape, material, light, priority: o.priority, interior, world: false });
    }
    let extras = extra.len();
    objects.append(&mut extra);
    for (i, l) in desc.lights.iter().enumerate() {
        lights.push(Light::from_desc(ctx, &format!("lights[{i}]"), l)?);
    }
    if let Some(e) = &desc.environment {
        lights.push(Light::Environment(Box::new(EnvironmentLight::from_desc(ctx, e)?)));
    }
    if objects.is_empty() {
        return Err(ctx.err("objects", "expected at least one object"));
    }
    // The camera's medium: a volume around the whole scene (`surround`).
    let mut names: Vec<Option<&str>> = desc.objects.iter().map(|o| o.interior.as_deref()).collect();
    names.extend(std::iter::repeat_n(None, extras));
    if let Some(name) = &desc.camera.medium {
        let m = media.get(name.as_str()).ok_or_else(|| {
            let known: Vec<&str> = media.keys().copied().collect();
            ctx.err("camera.medium", format!("unknown medium \"{name}\"; defined: {}", known.join(", ")))
        })?;
        let eye = ctx.vec("camera.eye", desc.camera.eye)?;
        materials.push(Bxdf::Interface);
        textures.push(None);
        let aperture = if desc.camera.aperture_radius.is_finite() { desc.camera.aperture_radius.max(0.0) } else { 0.0 };
        objects.push(surround::world_volume(ctx, &objects, (eye, aperture), m, materials.len() as u32 - 1)?);
        names.push(Some(name.as_str()));
    }
    let known: Vec<&str> = media.keys().copied().collect();
    surround::check_exteriors(ctx, &desc.objects, &objects, &materials, &names, &known)?;
    if let Some(i) = objects.iter().position(|o| o.interior.as_ref().is_some_and(|m| m.is_grid()))
        && settings.integrator == IntegratorKind::Whitted
    {
        let field = if i < desc.objects.len() { format!("objects[{i}].interior") } else { "camera.medium".into() };
        return Err(ctx.err(field, "a Grid medium: whitted does not track media; use auto, path or spectral"));
    }
    if let Some(i) = objects.iter().position(|o| o.interior.as_ref().is_some_and(|m| m.scatters() || m.is_grid()))
        && settings.integrator == IntegratorKind::Caustics
    {
        let field = if i < desc.objects.len() { format!("objects[{i}].interior") } else { "camera.medium".into() };
        return Err(ctx.err(
            field,
            "--integrator caustics: scenes with media are not supported yet (an absorbing dielectric is); use bdpt",
        ));
    }

    let c = &desc.camera;
    let eye = ctx.vec("camera.eye", c.eye)?;
    let look_at = ctx.vec("camera.look_at", c.look_at)?;
    let up = ctx.direction("camera.up", c.up)?;
    let forward =
        (look_at - eye).try_normalize().ok_or_else(|| ctx.err("camera.look_at", "must differ from camera.eye"))?;
    if forward.cross(up).length() < 1e-4 {
        return Err(ctx.err("camera.up", "must not be parallel to the view direction"));
    }
    let camera = match &c.lens {
        None => {
            let fov = match c.fov_deg {
                Some(f) if f > 0.0 && f < 180.0 => f,
                Some(f) => return Err(ctx.err("camera.fov_deg", format!("expected degrees in (0, 180), found {f}"))),
                None => {
                    return Err(
                        ctx.err("camera.fov_deg", "expected the vertical field of view in degrees, in (0, 180)")
                    );
                }
            };
            if !(c.aperture_radius >= 0.0 && c.aperture_radius <= MAX_MAGNITUDE) {
                return Err(ctx.err(
                    "camera.aperture_radius",
                    format!(
                        "expected a radius from 0 (a pinhole) up to {MAX_MAGNITUDE:e}, found {}",
                        c.aperture_radius
                    ),
                ));
            }
            let focus = match c.focus_distance {
                Some(f) => ctx.positive("camera.focus_distance", f)?,
                None => (look_at - eye).length(),
            };
            Camera::new(eye, look_at, up, fov, settings.width, settings.height).with_thin_lens(c.aperture_radius, focus)
        }
        Some(lens) => lens_camera(ctx, c, lens, (eye, look_at, up), &settings)?,
    };
    let mut scene = Scene::new(objects, materials, textures, lights, camera, settings, 0);
    scene.mixes = mixes;
    Ok(scene)
}

/// An object's `transform:` (`field`: `objects[i]`), checked: scale, rotation and
/// translation, or a general `matrix:` (exclusive with them, finite, invertible).
fn placement(ctx: &Check<'_>, field: &str, t: &TransformDesc) -> Result<Placement> {
    let tf = format!("{field}.transform");
    let Some(rows) = &t.matrix else {
        return Ok(Placement {
            t: ctx.transform(&tf, &t.scale, &t.rotate_deg, &t.translate)?,
            matrix: None,
            field: tf,
        });
    };
    let mf = format!("{tf}.matrix");
    if t.scale.is_some() || t.rotate_deg.is_some() || t.translate.is_some() {
        return Err(ctx.err(
            &mf,
            "not with `scale`, `rotate_deg` or `translate`: a matrix is the whole placement; expected one or the other",
        ));
    }
    for (r, row) in rows.iter().enumerate() {
        if let Some(c) = row.iter().position(|v| !(v.is_finite() && v.abs() <= MAX_MAGNITUDE)) {
            return Err(ctx.err(
                &mf,
                format!("row {r}, column {c} is {}: expected finite numbers up to ±{MAX_MAGNITUDE:e}", row[c]),
            ));
        }
    }
    let col = |c: usize| Vec3::new(rows[0][c], rows[1][c], rows[2][c]);
    let m = glam::Mat3::from_cols(col(0), col(1), col(2));
    let det = m.determinant();
    // Singular relative to the size of its columns (a matrix of tiny entries is fine).
    let size = col(0).length() * col(1).length() * col(2).length();
    let inverse = m.inverse();
    if !(det.abs() > 1e-6 * size && det.is_finite() && inverse.is_finite()) {
        return Err(ctx.err(
            &mf,
            format!(
                "the matrix is singular (its linear part's determinant is {det:e}): expected an invertible placement"
            ),
        ));
    }
    Ok(Placement { t: Transform::default(), matrix: Some((m, col(3))), field: tf })
}

/// A mesh file to read ahead: its key, path, own transform and its object's placement.
type MeshJob<K> = (K, PathBuf, Transform, Option<Then>);

/// A group's members, built once in group space: the shared mesh, material and priority.
type Group = Vec<(std::sync::Arc<Mesh>, u32, u32)>;

/// The scene's `groups:`, each member checked (a mesh with a material; no emission,
/// `interior` or `exterior`) and built once.
fn groups(ctx: &Check<'_>, desc: &SceneDesc, materials: &BTreeMap<&str, u32>) -> Result<BTreeMap<String, Group>> {
    // The groups' mesh files are read and built at once on the thread pool, as the
    // objects' are (see `build`); the loop takes them in order.
    let jobs: Vec<MeshJob<(usize, usize)>> = desc
        .groups
        .0
        .iter()
        .enumerate()
        .flat_map(|(g, (name, members))| members.iter().enumerate().map(move |(j, o)| (g, name, j, o)))
        .filter_map(|(g, name, j, o)| {
            let ShapeDesc::Mesh { path, scale, rotate_deg, translate } = &o.shape else { return None };
            let field = format!("groups.\"{name}\"[{j}]");
            let own = ctx.transform(&format!("{field}.shape"), scale, rotate_deg, translate).ok()?;
            let then = match &o.transform {
                None => None,
                Some(t) => Some(placement(ctx, &field, t).ok()?.then()),
            };
            Some(((g, j), ctx.dir.join(path), own, then))
        })
        .collect();
    let mut ahead: BTreeMap<(usize, usize), MeshAhead> =
        jobs.into_par_iter().map(|(k, path, own, then)| (k, Mesh::read_ahead(path, &own, then.as_ref()))).collect();
    let mut out = BTreeMap::new();
    for (g, (name, members)) in desc.groups.0.iter().enumerate() {
        let gf = format!("groups.\"{name}\"");
        if members.is_empty() {
            return Err(ctx.err(&gf, "an empty group: expected at least one object"));
        }
        let mut group = Vec::with_capacity(members.len());
        for (j, o) in members.iter().enumerate() {
            let field = format!("{gf}[{j}]");
            for (given, what) in [
                (o.emission.is_some(), "emission"),
                (o.interior.is_some(), "interior"),
                (o.exterior.is_some(), "exterior"),
            ] {
                if given {
                    return Err(ctx.err(
                        format!("{field}.{what}"),
                        format!("a group's object takes no `{what}:` (an instance is only a surface with a material, as in pbrt-v4); expected the object outside `groups`"),
                    ));
                }
            }
            let xf = match &o.transform {
                None => None,
                Some(t) => Some(placement(ctx, &field, t)?),
            };
            let shape = match (&o.shape, ahead.remove(&(g, j))) {
                (ShapeDesc::Mesh { path, .. }, Some(a)) => {
                    Shape::Mesh(Box::new(Mesh::from_ahead(ctx, &format!("{field}.shape"), path, a, xf.as_ref())?))
                }
                (ShapeDesc::Mesh { .. } | ShapeDesc::Triangles { .. }, _) => {
                    Shape::from_desc(ctx, &format!("{field}.shape"), &o.shape, xf.as_ref())?
                }
                (ShapeDesc::Instance { .. }, _) => {
                    return Err(ctx.err(
                        format!("{field}.shape"),
                        "groups do not nest: expected a Mesh or Triangles, not an Instance",
                    ));
                }
                (_, _) => {
                    return Err(ctx.err(
                        format!("{field}.shape"),
                        "a group holds meshes: expected a Mesh or Triangles (place spheres, disks, quads, cuboids and planes as objects)",
                    ));
                }
            };
            let Shape::Mesh(mesh) = shape else {
                return Err(ctx.err(format!("{field}.shape"), "expected a Mesh or Triangles"));
            };
            let Some(mat) = &o.material else {
                return Err(ctx.err(&field, "expected a `material` (a group's objects do not emit)"));
            };
            let material = *materials.get(mat.as_str()).ok_or_else(|| {
                let known: Vec<&str> = materials.keys().copied().collect();
                ctx.err(
                    format!("{field}.material"),
                    format!("unknown material \"{mat}\"; defined: {}", known.join(", ")),
                )
            })?;
            group.push((std::sync::Arc::new(*mesh), material, o.priority));
        }
        out.insert(name.clone(), group);
    }
    Ok(out)
}

/// The objects of an `Instance(group: ...)` object at `field`: one per member of the
/// group, sharing its mesh, placed by the object's transform `xf`; a placement that
/// cancels large coordinates places a copy instead ([`MeshInstance::cancels`]).
fn instance(
    ctx: &Check<'_>,
    field: &str,
    o: &ObjectDesc,
    name: &str,
    xf: Option<&Placement>,
    groups: &BTreeMap<String, Group>,
) -> Result<Vec<Object>> {
    for (given, what, why) in [
        (o.material.is_some(), "material", "the group's objects carry their own materials"),
        (
            o.emission.is_some(),
            "emission",
            "an instance is only a surface (pbrt-v4 refuses area lights in instances too)",
        ),
        (o.interior.is_some(), "interior", "an instance bounds no medium"),
        (o.exterior.is_some(), "exterior", "an instance bounds no medium"),
        (o.priority != 0, "priority", "the group's objects carry their own priorities"),
    ] {
        if given {
            return Err(ctx.err(format!("{field}.{what}"), format!("an Instance takes no `{what}:`: {why}")));
        }
    }
    let group = groups.get(name).ok_or_else(|| {
        let known: Vec<&str> = groups.keys().map(String::as_str).collect();
        let known = if known.is_empty() { "none".to_string() } else { known.join(", ") };
        ctx.err(format!("{field}.shape.group"), format!("unknown group \"{name}\"; defined: {known}"))
    })?;
    let (m, t) = xf.map_or((glam::Mat3::IDENTITY, Vec3::ZERO), Placement::affine);
    let mut out = Vec::with_capacity(group.len());
    for (j, (mesh, material, priority)) in group.iter().enumerate() {
        let shape = if MeshInstance::cancels(mesh, m, t) {
            let copy = mesh.placed_copy(m, t).map_err(|e| {
                let at = xf.map_or(field.to_string(), |x| x.field.clone());
                ctx.err(at, format!("placing groups.\"{name}\"[{j}]: {e}"))
            })?;
            Shape::Mesh(Box::new(copy))
        } else {
            let inst = MeshInstance::new(mesh.clone(), m, t);
            let b = inst.bounds();
            if ctx.vec(field, b.min.into()).is_err() || ctx.vec(field, b.max.into()).is_err() {
                let at = xf.map_or(field.to_string(), |x| x.field.clone());
                return Err(ctx.err(
                    at,
                    format!("the placement moves groups.\"{name}\"[{j}] out of range: expected coordinates up to ±{MAX_MAGNITUDE:e}"),
                ));
            }
            Shape::Instance(Box::new(inst))
        };
        out.push(Object { shape, material: *material, light: None, priority: *priority, interior: None, world: false });
    }
    Ok(out)
}

/// The camera looking through the lens system `lens` of camera block `c`.
fn lens_camera(
    ctx: &Check<'_>,
    c: &CameraDesc,
    lens: &LensDesc,
    (eye, look_at, up): (Vec3, Vec3, Vec3),
    settings: &Settings,
) -> Result<Camera> {
    for (given, field) in [
        (c.fov_deg.is_some(), "camera.fov_deg"),
        (c.aperture_radius != 0.0, "camera.aperture_radius"),
        (c.focus_distance.is_some(), "camera.focus_distance"),
    ] {
        if given {
            return Err(ctx.err(field, "not with a `lens`: the lens's own fields set the view, aperture and focus"));
        }
    }
    if settings.integrator == IntegratorKind::Caustics {
        return Err(ctx.err(
            "camera.lens",
            "caustics splats light subpaths to the camera, which needs the camera's importance, which a lens system does not define; use auto, path, spectral or whitted",
        ));
    }
    if matches!(settings.integrator, IntegratorKind::Bdpt | IntegratorKind::LightTrace) {
        return Err(ctx.err(
            "camera.lens",
            "bdpt and lighttrace need the camera's importance, which a lens system does not define (as in pbrt-v4); use auto, path, spectral or whitted",
        ));
    }
    let aperture = ctx.positive("camera.lens.aperture_diameter_mm", lens.aperture_diameter_mm)?;
    let focus = ctx.positive("camera.lens.focus_distance", lens.focus_distance)?;
    let diagonal = ctx.positive("camera.lens.film_diagonal_mm", lens.film_diagonal_mm)?;
    let (path, bytes) = ctx.read_input("camera.lens.file", &lens.file)?;
    let text = String::from_utf8(bytes)
        .map_err(|_| ctx.err("camera.lens.file", format!("{}: expected UTF-8 text", path.display())))?;
    let system = LensSystem::parse(&text, &path)?;
    let camera =
        LensCamera::new(&system, aperture as f64, focus as f64 * 1e3, diagonal as f64, settings.width, settings.height)
            .map_err(|m| ctx.err("camera.lens", format!("{}: {m}", lens.file)))?;
    // The pinhole methods get the lens's field of view (nothing renders with them).
    let efl = camera.lens().effective_focal_length(D_LINE_NM).unwrap_or(50.0);
    let fov = (2.0 * (camera.film_size().1 / 2.0).atan2(efl)).to_degrees().clamp(1e-3, 179.0) as f32;
    Ok(Camera::new(eye, look_at, up, fov, settings.width, settings.height).with_lens_system(camera))
}

/// Combines defaults, the file's `render` block and the command line, and checks the result.
fn settings(ctx: &Check<'_>, file: &SettingsPatch, cli: &SettingsPatch) -> Result<Settings> {
    let s = Settings::combine(file, cli);
    if let Err(Error::Setting { name, message }) = s.check() {
        return Err(ctx.err(format!("render.{name}"), message));
    }
    Ok(s)
}
