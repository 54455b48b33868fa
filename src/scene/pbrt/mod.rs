//! pbrt-v4 scene files (`.pbrt`): a second reader of the format-neutral scene
//! description. `lexer` makes tokens, `parser` reads directives, parameter
//! lists, the graphics state and transforms (with `Include`/`Import`), and
//! `map` turns each pbrt entity into its [`SceneDesc`] counterpart; the
//! scene is then built exactly like a RON scene. `write` is `rust-v convert`:
//! the same description written as RON.
//!
//! What is supported, mapped, warned about and refused is in `docs/pbrt.md`.
//! Anything not understood gives a warning (`FILE:LINE:COL: ...`, once per
//! message with a count of further uses), or with `strict` an error.

mod lexer;
mod loop_subdiv;
mod map;
mod parser;
mod write;

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::scene::check::Check;
use crate::scene::desc::{NamedMap, SceneDesc};

pub use write::convert;

/// A pbrt scene read into a description.
pub(crate) struct Imported {
    /// The scene description.
    pub(crate) desc: SceneDesc,
    /// Warnings, one line each (`FILE:LINE:COL: message`).
    pub(crate) warnings: Vec<String>,
    /// Per object: the PLY file its triangles came from, if any.
    pub(crate) mesh_files: Vec<Option<String>>,
    /// Per group member: the PLY file its triangles came from, if any.
    pub(crate) group_files: Vec<Vec<Option<String>>>,
    /// Where the description's objects and environment come from (see [`locate`]).
    pub(crate) places: Places,
}

/// A file, line and column.
type Place = (PathBuf, usize, usize);

/// Where parts of an imported description come from.
#[derive(Default)]
pub(crate) struct Places {
    /// Per object: its `Shape` directive (its `ObjectInstance` for an instance).
    objects: Vec<Place>,
    /// Per group: its name and each member's `Shape` directive.
    groups: Vec<(String, Vec<Place>)>,
    /// The infinite light's `LightSource` (its `filename` for a map).
    environment: Option<Place>,
}

/// An error of the scene built from a pbrt file about `objects[i]` (an `exterior:`
/// that disagrees with the volumes around the shape, a grid medium under `whitted`, an
/// instance's placement) or a group's member `groups."name"[j]` (a mesh with no valid
/// triangle)
/// or about the `environment` (a map that is not square, black or unreadable),
/// moved to the directive it came from, the field kept in the message; any other
/// error as it is.
pub(crate) fn locate(places: &Places, e: Error) -> Error {
    let Error::Scene { path, position: None, field, message } = e else { return e };
    let index =
        field.strip_prefix("objects[").and_then(|r| r.split_once(']')).and_then(|(i, _)| i.parse::<usize>().ok());
    let member = field
        .strip_prefix("groups.\"")
        .and_then(|r| r.split_once("\"["))
        .and_then(|(name, r)| Some((name, r.split_once(']')?.0.parse::<usize>().ok()?)));
    let place = match (index, member) {
        (Some(i), _) => places.objects.get(i),
        (None, Some((name, j))) => places.groups.iter().find(|(n, _)| n == name).and_then(|(_, p)| p.get(j)),
        (None, None) if field.starts_with("environment") => places.environment.as_ref(),
        (None, None) => None,
    };
    match place {
        Some((file, line, col)) => Error::Scene {
            path: file.clone(),
            position: Some((*line, *col)),
            field: String::new(),
            message: format!("{field} (from here): {message}"),
        },
        None => Error::Scene { path, position: None, field, message },
    }
}

/// Whether `path` names a pbrt scene (`.pbrt`, any case).
pub fn is_pbrt(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("pbrt"))
}

/// Reads the pbrt scene file at `path` into its scene description, with the
/// warnings (one line each); `strict` makes every warning an error. Geometry is in
/// rust-v's world space: mirrored `x → −x` when pbrt's camera space needs it (see
/// `docs/pbrt.md`, Handedness).
pub fn read_pbrt(path: &Path, strict: bool) -> Result<(SceneDesc, Vec<String>)> {
    let bytes = crate::io::read_input(path)?;
    let text = std::str::from_utf8(bytes.strip_prefix(&[0xef, 0xbb, 0xbf]).unwrap_or(&bytes)).map_err(|e| {
        crate::error::Error::scene_field(
            path,
            "",
            format!("byte {} is not UTF-8; expected UTF-8 text", e.valid_up_to()),
        )
    })?;
    let ctx = Check::new(path);
    let imported = import(&ctx, path, text, strict)?;
    Ok((imported.desc, imported.warnings))
}

/// Reads the pbrt scene `text` of the file `path`; files it reads are recorded in `ctx`.
pub(crate) fn import(ctx: &Check<'_>, path: &Path, text: &str, strict: bool) -> Result<Imported> {
    let mut p = parser::Parser::new(ctx, path, text.to_string(), strict);
    p.run()?;
    p.resolve_plys()?;
    p.resolve_media()?;
    let warnings = p.warning_lines();
    let b = std::mem::take(&mut p.built);
    let camera = b.camera.ok_or_else(|| crate::error::Error::scene_field(path, "", "the file has no WorldBegin"))?;
    let place = |l: &parser::Loc| (p.files[l.file].clone(), l.line, l.col);
    let places = Places {
        objects: b.object_locs.iter().map(place).collect(),
        groups: b
            .groups
            .iter()
            .zip(&b.group_locs)
            .map(|((n, _), l)| (n.clone(), l.iter().map(place).collect()))
            .collect(),
        environment: b.environment_loc.as_ref().map(place),
    };
    Ok(Imported {
        desc: SceneDesc {
            camera,
            render: b.render,
            materials: NamedMap(b.materials),
            media: NamedMap(b.media),
            objects: b.objects,
            groups: NamedMap(b.groups),
            lights: b.lights,
            environment: b.environment,
        },
        warnings,
        mesh_files: b.mesh_files,
        group_files: b.group_files,
        places,
    })
}
