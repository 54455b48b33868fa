//! [`Check`]: the one context every `from_desc` builder takes. It knows the
//! scene file (to name it in errors), resolves and records the other files
//! the scene reads (for the scene's identity), and holds the small validation
//! helpers shared by all builders (`positive`, `vec`, `direction`, and in
//! [`super::spectra`] `spectrum`, `reflectance`, `ior`).
//!
//! Data flow: [`super::load`] parses the RON text into a
//! [`super::desc::SceneDesc`], then each model builds itself from its
//! description beside its own code (`crate::material::from_desc`,
//! `Shape::from_desc` and each shape's `from_desc` in `crate::shape`,
//! `Light::from_desc` and each light's `from_desc` in `crate::light`), all
//! through one `&Check`, so every error names the file, the field path
//! (`objects[2].shape.radius`) and what was expected.

use std::cell::RefCell;
use std::path::{Path, PathBuf};

use glam::Vec3;

use super::desc::{ScaleDesc, V3};
use crate::error::{Error, Result};
use crate::geometry::Transform;
use crate::io::{fnv1a, read_input};

/// The largest coordinate or size a scene may give: squares and products of a few
/// such numbers must stay finite in f32 (max 3.4e38), or intersections and light
/// falloff turn into NaN.
pub const MAX_MAGNITUDE: f32 = 1e15;

/// A file the scene reads besides itself.
pub(crate) struct Input {
    /// The path as written in the scene.
    pub(crate) name: String,
    /// The path it resolves to.
    pub(crate) path: PathBuf,
    /// FNV-1a of its content.
    pub(crate) hash: u64,
}

/// The loading context: the scene file, its folder, the inputs read so far,
/// and the checks every builder uses.
pub(crate) struct Check<'a> {
    pub(crate) path: &'a Path,
    pub(crate) dir: PathBuf,
    /// Every file read so far, in order (for the scene's identity).
    pub(crate) inputs: RefCell<Vec<Input>>,
    /// Files made in memory by an importer (a pbrt `uniformgrid` medium's density
    /// as a `.vol`), by the name the description uses: [`Check::read_input`] serves
    /// them instead of reading the disk. They are not inputs of their own: their
    /// content comes from the scene's files, which are.
    pub(crate) provided: RefCell<Vec<(String, Vec<u8>)>>,
}

impl<'a> Check<'a> {
    /// A context for the scene file at `path` (other files resolve relative to its folder).
    pub(crate) fn new(path: &'a Path) -> Check<'a> {
        Check {
            path,
            dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
            inputs: RefCell::default(),
            provided: RefCell::default(),
        }
    }
}

impl Check<'_> {
    /// An error at `field` of the scene file.
    pub(crate) fn err(&self, field: impl Into<String>, message: impl Into<String>) -> Error {
        Error::scene_field(self.path, field, message)
    }

    /// Reads a file the scene names (`rel`, relative to the scene file) for
    /// field `field`, and records it in the scene's identity. Only regular
    /// files are read. A file [`Check::provide`]d in memory is served from there.
    pub(crate) fn read_input(&self, field: &str, rel: &str) -> Result<(PathBuf, Vec<u8>)> {
        let path = self.dir.join(rel);
        if let Some((_, bytes)) = self.provided.borrow().iter().find(|(name, _)| name == rel) {
            return Ok((path, bytes.clone()));
        }
        let bytes = read_input(&path).map_err(|e| self.err(field, e.to_string()))?;
        self.inputs.borrow_mut().push(Input { name: rel.to_string(), path: path.clone(), hash: fnv1a(&bytes) });
        Ok((path, bytes))
    }

    /// Makes `bytes` the content of the file `rel` for [`Check::read_input`] (a file an
    /// importer makes in memory; nothing is written to disk).
    pub(crate) fn provide(&self, rel: &str, bytes: Vec<u8>) {
        self.provided.borrow_mut().push((rel.to_string(), bytes));
    }

    /// The bytes of a file made by [`Check::provide`], if `rel` is one.
    pub(crate) fn provided(&self, rel: &str) -> Option<Vec<u8>> {
        self.provided.borrow().iter().find(|(name, _)| name == rel).map(|(_, b)| b.clone())
    }

    /// Records a file read elsewhere (a mesh read ahead on the thread pool, see
    /// `Mesh::read_ahead`) in the scene's identity, as [`Check::read_input`] does.
    pub(crate) fn record_input(&self, rel: &str, path: PathBuf, hash: u64) {
        self.inputs.borrow_mut().push(Input { name: rel.to_string(), path, hash });
    }

    /// A finite number in (0, [`MAX_MAGNITUDE`]].
    pub(crate) fn positive(&self, field: &str, v: f32) -> Result<f32> {
        if v.is_finite() && v > 0.0 && v <= MAX_MAGNITUDE {
            Ok(v)
        } else {
            Err(self.err(field, format!("expected a positive number up to {MAX_MAGNITUDE:e}, found {v}")))
        }
    }

    /// A point or vector with finite coordinates up to ±[`MAX_MAGNITUDE`].
    pub(crate) fn vec(&self, field: &str, v: V3) -> Result<Vec3> {
        let v = Vec3::from(v);
        if v.is_finite() && v.abs().max_element() <= MAX_MAGNITUDE {
            Ok(v)
        } else {
            Err(self.err(field, format!("expected finite coordinates up to ±{MAX_MAGNITUDE:e}")))
        }
    }

    /// A non-zero vector, normalised.
    pub(crate) fn direction(&self, field: &str, v: V3) -> Result<Vec3> {
        let v = self.vec(field, v)?;
        v.try_normalize().ok_or_else(|| self.err(field, "expected a non-zero direction"))
    }

    /// A placement (`scale`, `rotate_deg`, `translate`, each optional) at `field`
    /// (`field.scale` etc. name the parts in errors): scales positive, angles and
    /// offsets finite.
    pub(crate) fn transform(
        &self,
        field: &str,
        scale: &Option<ScaleDesc>,
        rotate_deg: &Option<V3>,
        translate: &Option<V3>,
    ) -> Result<Transform> {
        let f = |name: &str| format!("{field}.{name}");
        let scale = match scale {
            None => Vec3::ONE,
            Some(ScaleDesc::Uniform(s)) => Vec3::splat(self.positive(&f("scale"), *s)?),
            Some(ScaleDesc::PerAxis(s)) => {
                for (axis, v) in s.iter().enumerate() {
                    self.positive(&format!("{field}.scale[{axis}]"), *v)?;
                }
                Vec3::from(*s)
            }
        };
        Ok(Transform {
            scale,
            rotate_deg: match rotate_deg {
                Some(r) => self.vec(&f("rotate_deg"), *r)?,
                None => Vec3::ZERO,
            },
            translate: match translate {
                Some(t) => self.vec(&f("translate"), *t)?,
                None => Vec3::ZERO,
            },
        })
    }
}
