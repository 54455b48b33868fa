//! From a RON scene file to a [`Scene`]: parse, check every name and size,
//! load meshes, and report mistakes with the file, line:column (from the RON
//! parser) or the field path (for checks after parsing) and what was expected.

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glam::Vec3;

use super::desc::{CoatingDesc, IorDesc, LightDesc, MaterialDesc, ScaleDesc, SceneDesc, ShapeDesc, V3};
use super::{Object, Scene};
use crate::bxdf::{
    Bxdf, Conductor, Dielectric, Lambertian, Mirror, NAMED_METALS, OrenNayar, Plastic, ThinFilm, ThinSheet, named_metal,
};
use crate::camera::Camera;
use crate::color::{self, N_BINS};
use crate::error::{Error, Result};
use crate::io::{Fnv1a, fnv1a, parse_mesh, read_input};
use crate::light::{AreaLight, BeamLight, DiskLight, DistantLight, Light, PointLight, SphereLight, SpotLight};
use crate::settings::{Settings, SettingsPatch};
use crate::shape::{Bubble, Cuboid, Disk, Mesh, Plane, Quad, Shape, Sphere, Transform};

/// The largest coordinate or size a scene may give: squares and products of a few
/// such numbers must stay finite in f32 (max 3.4e38), or intersections and light
/// falloff turn into NaN.
pub const MAX_MAGNITUDE: f32 = 1e15;

/// Loads the scene file at `path`; `overrides` (from the command line) take
/// precedence over the file's `render` settings. The file must be a regular
/// file of UTF-8 text (a byte-order mark is allowed).
pub fn load_scene(path: &Path, overrides: &SettingsPatch) -> Result<Scene> {
    let bytes = read_input(path)?;
    let text = decode_text(&bytes, path)?;
    load(text, &bytes, path, overrides)
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
    let ctx = Ctx { path, dir: path.parent().map(Path::to_path_buf).unwrap_or_default(), inputs: RefCell::default() };
    let mut scene = build(&ctx, desc, overrides)?;
    let inputs = ctx.inputs.into_inner();
    scene.content_hash = content_hash(bytes, &inputs);
    scene.inputs = inputs.into_iter().map(|i| i.path).collect();
    Ok(scene)
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

/// A file the scene reads besides itself.
pub(super) struct Input {
    /// The path as written in the scene.
    name: String,
    /// The path it resolves to.
    path: PathBuf,
    /// FNV-1a of its content.
    hash: u64,
}

pub(super) struct Ctx<'a> {
    pub(super) path: &'a Path,
    pub(super) dir: PathBuf,
    /// Every file read so far, in order (for the scene's identity).
    inputs: RefCell<Vec<Input>>,
}

impl Ctx<'_> {
    pub(super) fn err(&self, field: impl Into<String>, message: impl Into<String>) -> Error {
        Error::scene_field(self.path, field, message)
    }

    /// Reads a file the scene names (`rel`, relative to the scene file) for
    /// field `field`, and records it in the scene's identity. Only regular
    /// files are read.
    pub(super) fn read_input(&self, field: &str, rel: &str) -> Result<(PathBuf, Vec<u8>)> {
        let path = self.dir.join(rel);
        let bytes = read_input(&path).map_err(|e| self.err(field, e.to_string()))?;
        self.inputs.borrow_mut().push(Input { name: rel.to_string(), path: path.clone(), hash: fnv1a(&bytes) });
        Ok((path, bytes))
    }

    pub(super) fn positive(&self, field: &str, v: f32) -> Result<f32> {
        if v.is_finite() && v > 0.0 && v <= MAX_MAGNITUDE {
            Ok(v)
        } else {
            Err(self.err(field, format!("expected a positive number up to {MAX_MAGNITUDE:e}, found {v}")))
        }
    }

    fn vec(&self, field: &str, v: V3) -> Result<Vec3> {
        let v = Vec3::from(v);
        if v.is_finite() && v.abs().max_element() <= MAX_MAGNITUDE {
            Ok(v)
        } else {
            Err(self.err(field, format!("expected finite coordinates up to ±{MAX_MAGNITUDE:e}")))
        }
    }

    fn direction(&self, field: &str, v: V3) -> Result<Vec3> {
        let v = self.vec(field, v)?;
        v.try_normalize().ok_or_else(|| self.err(field, "expected a non-zero direction"))
    }

    fn material(&self, field: &str, d: &MaterialDesc) -> Result<Bxdf> {
        Ok(match d {
            MaterialDesc::Lambertian { reflectance } => Bxdf::Lambertian(Lambertian {
                reflectance: self.reflectance(&format!("{field}.reflectance"), reflectance)?,
            }),
            MaterialDesc::OrenNayar { reflectance, sigma_deg } => {
                if !(sigma_deg.is_finite() && (0.0..=90.0).contains(sigma_deg)) {
                    return Err(self
                        .err(format!("{field}.sigma_deg"), format!("expected degrees in [0, 90], found {sigma_deg}")));
                }
                Bxdf::OrenNayar(OrenNayar::new(
                    self.reflectance(&format!("{field}.reflectance"), reflectance)?,
                    *sigma_deg,
                ))
            }
            MaterialDesc::Mirror { reflectance } => {
                Bxdf::Mirror(Mirror { reflectance: self.reflectance(&format!("{field}.reflectance"), reflectance)? })
            }
            MaterialDesc::Dielectric { ior, roughness, absorption, coating } => {
                let mut d = Dielectric::new(self.ior(&format!("{field}.ior"), ior)?)
                    .with_roughness(self.roughness(&format!("{field}.roughness"), *roughness)?);
                if let Some(a) = absorption {
                    d = d.with_absorption(self.spectrum(&format!("{field}.absorption"), a)?);
                }
                if let Some(CoatingDesc::ThinFilm { thickness_nm, ior }) = coating {
                    d = d.with_coating(self.thin_film(&format!("{field}.coating"), *thickness_nm, ior)?);
                }
                Bxdf::Dielectric(d)
            }
            MaterialDesc::Conductor { metal, eta, k, roughness, coating } => {
                let (eta, k) = match (metal, eta, k) {
                    (Some(name), None, None) => named_metal(name).ok_or_else(|| {
                        let names: Vec<&str> = NAMED_METALS.iter().map(|m| m.0).collect();
                        self.err(
                            format!("{field}.metal"),
                            format!("unknown metal \"{name}\"; expected one of: {}", names.join(", ")),
                        )
                    })?,
                    (None, Some(eta), Some(k)) => {
                        let eta_s = self.spectrum(&format!("{field}.eta"), eta)?;
                        if eta_s.min_value() <= 0.0 {
                            return Err(
                                self.err(format!("{field}.eta"), "expected a positive index at every wavelength")
                            );
                        }
                        (eta_s, self.spectrum(&format!("{field}.k"), k)?)
                    }
                    _ => {
                        return Err(self.err(field, "expected either `metal: \"Au\"` or both `eta:` and `k:` spectra"));
                    }
                };
                let coating = match coating {
                    None => None,
                    Some(CoatingDesc::ThinFilm { thickness_nm, ior }) => {
                        Some(self.thin_film(&format!("{field}.coating"), *thickness_nm, ior)?)
                    }
                };
                let alpha = self.roughness(&format!("{field}.roughness"), *roughness)?;
                Bxdf::Conductor(Conductor { eta, k, alpha, coating })
            }
            MaterialDesc::Plastic { reflectance, ior, roughness } => {
                let ior = self.ior(&format!("{field}.ior"), ior)?;
                for b in 0..N_BINS {
                    let n = ior.at(color::bin_lambda_nm(b));
                    if n < 1.0 {
                        return Err(self.err(
                            format!("{field}.ior"),
                            format!("a coat's index must be at least 1, found {n} at {} nm", color::bin_lambda_nm(b)),
                        ));
                    }
                }
                Bxdf::Plastic(Plastic::new(
                    self.reflectance(&format!("{field}.reflectance"), reflectance)?,
                    &ior,
                    self.roughness(&format!("{field}.roughness"), *roughness)?,
                ))
            }
            MaterialDesc::ThinSheet { thickness_nm, ior } => {
                Bxdf::ThinSheet(ThinSheet { film: self.thin_film(field, *thickness_nm, ior)? })
            }
            MaterialDesc::Black => Bxdf::Black,
        })
    }

    /// A thin film: a thickness in [0, 1e7] nm and an index of at least 1.
    fn thin_film(&self, field: &str, thickness_nm: f32, ior: &IorDesc) -> Result<ThinFilm> {
        if !(thickness_nm.is_finite() && (0.0..=1e7).contains(&thickness_nm)) {
            return Err(self.err(
                format!("{field}.thickness_nm"),
                format!("expected a thickness in nm in [0, 1e7], found {thickness_nm}"),
            ));
        }
        let ior = self.ior(&format!("{field}.ior"), ior)?;
        Ok(ThinFilm::new(thickness_nm, &ior))
    }

    /// A GGX α: a number in [0, 1] (0 is smooth).
    fn roughness(&self, field: &str, alpha: f32) -> Result<f32> {
        if alpha.is_finite() && (0.0..=1.0).contains(&alpha) {
            Ok(alpha)
        } else {
            Err(self.err(field, format!("expected a GGX alpha in [0, 1], found {alpha}")))
        }
    }

    fn shape(&self, field: &str, d: &ShapeDesc) -> Result<Shape> {
        let f = |name: &str| format!("{field}.{name}");
        Ok(match d {
            ShapeDesc::Sphere { center, radius } => {
                Shape::Sphere(Sphere::new(self.vec(&f("center"), *center)?, self.positive(&f("radius"), *radius)?))
            }
            ShapeDesc::Bubble { center, outer_radius, inner_radius } => {
                let outer = self.positive(&f("outer_radius"), *outer_radius)?;
                let inner = self.positive(&f("inner_radius"), *inner_radius)?;
                if inner >= outer {
                    return Err(self
                        .err(f("inner_radius"), format!("expected less than outer_radius ({outer}), found {inner}")));
                }
                Shape::Bubble(Bubble {
                    center: self.vec(&f("center"), *center)?,
                    outer_radius: outer,
                    inner_radius: inner,
                })
            }
            ShapeDesc::Plane { point, normal } => Shape::Plane(Plane {
                point: self.vec(&f("point"), *point)?,
                normal: self.direction(&f("normal"), *normal)?,
            }),
            ShapeDesc::Disk { center, normal, radius } => Shape::Disk(Disk {
                center: self.vec(&f("center"), *center)?,
                normal: self.direction(&f("normal"), *normal)?,
                radius: self.positive(&f("radius"), *radius)?,
            }),
            ShapeDesc::Cuboid { min, max } => {
                let (lo, hi) = (self.vec(&f("min"), *min)?, self.vec(&f("max"), *max)?);
                if !lo.cmplt(hi).all() {
                    return Err(self.err(field, "expected min < max on every axis"));
                }
                Shape::Cuboid(Cuboid { min: lo, max: hi })
            }
            ShapeDesc::Quad { origin, edge_u, edge_v } => {
                let (u, v) = (self.vec(&f("edge_u"), *edge_u)?, self.vec(&f("edge_v"), *edge_v)?);
                if u.cross(v).length_squared() <= f32::MIN_POSITIVE {
                    return Err(self.err(field, "edge_u and edge_v must be non-zero and not parallel"));
                }
                Shape::Quad(Quad::new(self.vec(&f("origin"), *origin)?, u, v))
            }
            ShapeDesc::Mesh { path, scale, rotate_deg, translate } => {
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
                let transform = Transform {
                    scale,
                    rotate_deg: match rotate_deg {
                        Some(r) => self.vec(&f("rotate_deg"), *r)?,
                        None => Vec3::ZERO,
                    },
                    translate: match translate {
                        Some(t) => self.vec(&f("translate"), *t)?,
                        None => Vec3::ZERO,
                    },
                };
                let (file, bytes) = self.read_input(&f("path"), path)?;
                let data = parse_mesh(bytes, &file).map_err(|e| self.err(f("path"), e.to_string()))?;
                let mesh = Mesh::from_data(data, &file, &transform).map_err(|e| match e {
                    Error::Setting { name, message } => self.err(f(name), message),
                    e => self.err(f("path"), e.to_string()),
                })?;
                Shape::Mesh(Box::new(mesh))
            }
        })
    }
}

fn build(ctx: &Ctx<'_>, desc: SceneDesc, overrides: &SettingsPatch) -> Result<Scene> {
    let settings = settings(ctx, &desc.render, overrides)?;

    // Materials by name; index 0 is the implicit black material of lights.
    let mut materials = vec![Bxdf::Black];
    let mut by_name = BTreeMap::new();
    for (name, m) in &desc.materials.0 {
        by_name.insert(name.as_str(), materials.len() as u32);
        materials.push(ctx.material(&format!("materials.\"{name}\""), m)?);
    }

    let mut objects = Vec::with_capacity(desc.objects.len());
    let mut lights = Vec::new();
    for (i, o) in desc.objects.iter().enumerate() {
        let field = format!("objects[{i}]");
        let shape = ctx.shape(&format!("{field}.shape"), &o.shape)?;
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
                let radiance = ctx.spectrum(&format!("{field}.emission"), e)?;
                let two = o.two_sided;
                let flat = |l: Option<AreaLight>| {
                    l.map(Light::Area)
                        .ok_or_else(|| ctx.err(format!("{field}.shape"), "an emitter needs a non-zero area"))
                };
                let l = match &shape {
                    Shape::Sphere(s) => Light::Sphere(SphereLight { sphere: *s, radiance, two_sided: two }),
                    Shape::Disk(d) => Light::Disk(DiskLight { disk: *d, radiance, two_sided: two }),
                    Shape::Quad(q) => flat(AreaLight::quad(q, radiance, two))?,
                    Shape::Cuboid(c) => flat(AreaLight::cuboid(c, radiance, two))?,
                    Shape::Mesh(m) => flat(AreaLight::mesh(m, radiance, two))?,
                    Shape::Plane(_) | Shape::Bubble(_) => {
                        return Err(ctx.err(
                            format!("{field}.emission"),
                            "a Plane (infinite) or Bubble cannot emit; expected a Sphere, Disk, Quad, Cuboid or Mesh",
                        ));
                    }
                };
                lights.push(l);
                Some(lights.len() as u32 - 1)
            }
        };
        objects.push(Object { shape, material, light, priority: o.priority });
    }
    for (i, l) in desc.lights.iter().enumerate() {
        match l {
            LightDesc::Point { position, intensity } => lights.push(Light::Point(PointLight {
                position: ctx.vec(&format!("lights[{i}].position"), *position)?,
                intensity: ctx.spectrum(&format!("lights[{i}].intensity"), intensity)?,
            })),
            LightDesc::Spot { position, look_at, cone_deg, falloff_deg, intensity } => {
                let f = |name: &str| format!("lights[{i}].{name}");
                let position = ctx.vec(&f("position"), *position)?;
                let target = ctx.vec(&f("look_at"), *look_at)?;
                let axis = (target - position)
                    .try_normalize()
                    .ok_or_else(|| ctx.err(f("look_at"), "must differ from position"))?;
                if !(cone_deg.is_finite() && *cone_deg > 0.0 && *cone_deg <= 90.0) {
                    return Err(ctx.err(f("cone_deg"), format!("expected degrees in (0, 90], found {cone_deg}")));
                }
                if !(falloff_deg.is_finite() && (0.0..=*cone_deg).contains(falloff_deg)) {
                    return Err(ctx.err(
                        f("falloff_deg"),
                        format!("expected degrees from 0 to cone_deg ({cone_deg}), found {falloff_deg}"),
                    ));
                }
                let intensity = ctx.spectrum(&f("intensity"), intensity)?;
                lights.push(Light::Spot(SpotLight::new(position, axis, *cone_deg, *falloff_deg, intensity)));
            }
            LightDesc::Distant { direction, irradiance } => lights.push(Light::Distant(DistantLight {
                direction: ctx.direction(&format!("lights[{i}].direction"), *direction)?,
                irradiance: ctx.spectrum(&format!("lights[{i}].irradiance"), irradiance)?,
                scene_radius: 1.0,
                scene_center: glam::Vec3::ZERO,
            })),
            LightDesc::Beam { origin, direction, radius, irradiance } => lights.push(Light::Beam(BeamLight {
                origin: ctx.vec(&format!("lights[{i}].origin"), *origin)?,
                direction: ctx.direction(&format!("lights[{i}].direction"), *direction)?,
                radius: ctx.positive(&format!("lights[{i}].radius"), *radius)?,
                irradiance: ctx.spectrum(&format!("lights[{i}].irradiance"), irradiance)?,
            })),
        }
    }
    if objects.is_empty() {
        return Err(ctx.err("objects", "expected at least one object"));
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
    if !(c.fov_deg > 0.0 && c.fov_deg < 180.0) {
        return Err(ctx.err("camera.fov_deg", format!("expected degrees in (0, 180), found {}", c.fov_deg)));
    }
    let camera = Camera::new(eye, look_at, up, c.fov_deg, settings.width, settings.height);
    Ok(Scene::new(objects, materials, lights, camera, settings, 0))
}

/// Combines defaults, the file's `render` block and the command line, and checks the result.
fn settings(ctx: &Ctx<'_>, file: &SettingsPatch, cli: &SettingsPatch) -> Result<Settings> {
    let s = Settings::combine(file, cli);
    if let Err(Error::Setting { name, message }) = s.check() {
        return Err(ctx.err(format!("render.{name}"), message));
    }
    Ok(s)
}
