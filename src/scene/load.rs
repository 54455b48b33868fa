//! From a RON scene file to a [`Scene`]: parse, check every name and size,
//! load meshes, and report mistakes with the file, line:column (from the RON
//! parser) or the field path (for checks after parsing) and what was expected.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glam::Vec3;

use super::desc::{CoatingDesc, IorDesc, LightDesc, MaterialDesc, ScaleDesc, SceneDesc, ShapeDesc, SpectrumDesc, V3};
use super::{Object, Scene};
use crate::bxdf::{
    Bxdf, Conductor, Dielectric, Ior, Lambertian, Mirror, NAMED_GLASSES, NAMED_METALS, OrenNayar, Plastic, ThinFilm,
    ThinSheet, named_glass, named_metal,
};
use crate::camera::Camera;
use crate::color::{self, N_BINS, Spectrum};
use crate::error::{Error, Result};
use crate::light::{DiskLight, Light, PointLight, SphereLight};
use crate::settings::{Settings, SettingsPatch};
use crate::shape::{Bubble, Cuboid, Disk, Mesh, Plane, Quad, Shape, Sphere, Transform};

/// The largest coordinate or size a scene may give: squares and products of a few
/// such numbers must stay finite in f32 (max 3.4e38), or intersections and light
/// falloff turn into NaN.
pub const MAX_MAGNITUDE: f32 = 1e15;

/// Loads the scene file at `path`; `overrides` (from the command line) take
/// precedence over the file's `render` settings.
pub fn load_scene(path: &Path, overrides: &SettingsPatch) -> Result<Scene> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    load_scene_str(&text, path, overrides)
}

/// Loads a scene from its text; `path` names it in errors and anchors
/// relative mesh paths.
pub fn load_scene_str(text: &str, path: &Path, overrides: &SettingsPatch) -> Result<Scene> {
    let options = ron::Options::default().with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME);
    let desc: SceneDesc = options.from_str(text).map_err(|e| Error::Scene {
        path: path.to_path_buf(),
        position: Some((e.span.start.line, e.span.start.col)),
        field: String::new(),
        message: e.code.to_string(),
    })?;
    let ctx = Ctx { path, dir: path.parent().map(Path::to_path_buf).unwrap_or_default() };
    build(&ctx, desc, overrides, fnv1a(text.as_bytes()))
}

/// FNV-1a 64-bit hash, for recognising a scene's content in checkpoints.
fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for &b in bytes {
        h = (h ^ b as u64).wrapping_mul(0x0100_0000_01b3);
    }
    h
}

struct Ctx<'a> {
    path: &'a Path,
    dir: PathBuf,
}

impl Ctx<'_> {
    fn err(&self, field: impl Into<String>, message: impl Into<String>) -> Error {
        Error::scene_field(self.path, field, message)
    }

    fn positive(&self, field: &str, v: f32) -> Result<f32> {
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

    fn spectrum(&self, field: &str, s: &SpectrumDesc) -> Result<Spectrum> {
        let out = match s {
            SpectrumDesc::Constant(v) => Spectrum::splat(*v),
            SpectrumDesc::Samples(v) => {
                if v.len() != N_BINS {
                    return Err(
                        self.err(field, format!("expected 36 samples (380 to 730 nm every 10 nm), found {}", v.len()))
                    );
                }
                Spectrum::from_fn(|i| v[i])
            }
            SpectrumDesc::ColorChecker(name) => color::color_checker(name).ok_or_else(|| {
                self.err(
                    field,
                    format!(
                        "unknown ColorChecker patch \"{name}\"; expected one of: {}",
                        color::COLOR_CHECKER_NAMES.join(", ")
                    ),
                )
            })?,
            SpectrumDesc::D65 => color::d65(),
            SpectrumDesc::EqualEnergy => color::equal_energy(),
            SpectrumDesc::Blackbody(t) => color::blackbody(*t)
                .ok_or_else(|| self.err(field, format!("expected a positive temperature in kelvin, found {t}")))?,
            SpectrumDesc::Scaled(k, inner) => self.spectrum(field, inner)? * *k,
        };
        if out.has_nan_or_inf() || out.min_value() < 0.0 || out.max_value() > MAX_MAGNITUDE {
            return Err(self.err(field, format!("expected finite, non-negative values up to {MAX_MAGNITUDE:e}")));
        }
        Ok(out)
    }

    fn reflectance(&self, field: &str, s: &SpectrumDesc) -> Result<Spectrum> {
        let r = self.spectrum(field, s)?;
        if r.max_value() > 1.0 {
            return Err(self.err(field, format!("a reflectance must lie in [0, 1], found {}", r.max_value())));
        }
        Ok(r)
    }

    fn ior(&self, field: &str, d: &IorDesc) -> Result<Ior> {
        let ior = match d {
            IorDesc::Constant(n) => Ior::Constant(*n),
            IorDesc::Cauchy { a, b } => Ior::Cauchy { a: *a, b: *b },
            IorDesc::Sellmeier { b, c } => Ior::Sellmeier { b: [b[0], b[1], b[2], 0.0], c: [c[0], c[1], c[2], 0.0] },
            IorDesc::Named(name) => named_glass(name).ok_or_else(|| {
                let names: Vec<&str> = NAMED_GLASSES.iter().map(|g| g.0).collect();
                self.err(field, format!("unknown glass \"{name}\"; expected one of: {}", names.join(", ")))
            })?,
        };
        for lambda in [color::LAMBDA_MIN_NM, 550.0, color::bin_lambda_nm(N_BINS - 1)] {
            let n = ior.at(lambda);
            if !(n.is_finite() && n > 0.0) {
                return Err(self
                    .err(field, format!("the index of refraction at {lambda} nm is {n}; expected a positive number")));
            }
        }
        Ok(ior)
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
                    if !d.is_smooth() {
                        return Err(self.err(
                            format!("{field}.coating"),
                            "a coating is supported on smooth glass only (roughness below 0.001)",
                        ));
                    }
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
                    rotate_deg: rotate_deg.map(Vec3::from).unwrap_or(Vec3::ZERO),
                    translate: translate.map(Vec3::from).unwrap_or(Vec3::ZERO),
                };
                let file = self.dir.join(path);
                let mesh = Mesh::load(&file, &transform).map_err(|e| self.err(f("path"), e.to_string()))?;
                Shape::Mesh(Box::new(mesh))
            }
        })
    }
}

fn build(ctx: &Ctx<'_>, desc: SceneDesc, overrides: &SettingsPatch, content_hash: u64) -> Result<Scene> {
    let settings = settings(ctx, &desc.render, overrides)?;

    // Materials by name; index 0 is the implicit black material of lights.
    let mut materials = vec![Bxdf::Black];
    let mut by_name = BTreeMap::new();
    for (name, m) in &desc.materials {
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
                let l = match &shape {
                    Shape::Sphere(s) => Light::Sphere(SphereLight { sphere: *s, radiance, two_sided: o.two_sided }),
                    Shape::Disk(d) => Light::Disk(DiskLight { disk: *d, radiance, two_sided: o.two_sided }),
                    _ => return Err(ctx.err(format!("{field}.emission"), "only Sphere and Disk shapes can emit")),
                };
                lights.push(l);
                Some(lights.len() as u32 - 1)
            }
        };
        objects.push(Object { shape, material, light });
    }
    for (i, l) in desc.lights.iter().enumerate() {
        match l {
            LightDesc::Point { position, intensity } => lights.push(Light::Point(PointLight {
                position: ctx.vec(&format!("lights[{i}].position"), *position)?,
                intensity: ctx.spectrum(&format!("lights[{i}].intensity"), intensity)?,
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
    Ok(Scene::new(objects, materials, lights, camera, settings, content_hash))
}

/// Combines defaults, the file's `render` block and the command line, and checks the result.
fn settings(ctx: &Ctx<'_>, file: &SettingsPatch, cli: &SettingsPatch) -> Result<Settings> {
    let s = Settings::combine(file, cli);
    s.check().map_err(|(field, message)| ctx.err(format!("render.{field}"), message))?;
    Ok(s)
}
