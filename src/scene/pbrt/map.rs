//! pbrt-v4 entities to the format-neutral scene description ([`crate::scene::desc`]).
//!
//! Geometry is placed in world space here (shapes carry no `transform:`): every
//! point goes through `M · CTM`, where `M` is the identity or the mirror
//! `x → −x` chosen at `WorldBegin` so that rust-v's right-handed camera sees
//! the image pbrt's left-handed camera space gives (see `begin_world`).

use std::collections::HashMap;
use std::path::PathBuf;

use rayon::prelude::*;

use glam::{DMat3, DMat4, DVec3};

use super::parser::{Loc, Param, Params, Parser, Value};
use crate::error::Result;
use crate::io::{MeshData, fnv1a, parse_mesh, read_input};
use crate::scene::desc::{
    CameraDesc, EnvironmentDesc, IorDesc, LightDesc, MaterialDesc, MediumDesc, ObjectDesc, PhaseDesc, ShapeDesc,
    SpectrumDesc, TransformDesc, V3, Wrap,
};
use crate::settings::{IntegratorKind, SettingsPatch};

mod lights;
mod materials;
mod media;
mod options;
mod shapes;

/// The material a shape gets.
#[derive(Clone, Debug)]
pub(crate) enum MatRef {
    /// pbrt's default: `diffuse` with reflectance 0.5.
    Default,
    /// A material of the description by its name.
    Name(String),
    /// `interface` (or no material): the shape only bounds a medium.
    Interface,
}

/// The current `AreaLightSource "diffuse"`.
#[derive(Clone, Debug)]
pub(crate) struct AreaLight {
    spectrum: SpectrumDesc,
    rgb: bool,
    scale: f64,
    power: Option<f64>,
    two_sided: bool,
}

impl AreaLight {
    /// The emission of a shape of `area` (pbrt's `power` is spread over it).
    fn emission(&self, area: f64) -> SpectrumDesc {
        let k = match self.power {
            Some(p) => p / ((if self.two_sided { 2.0 } else { 1.0 }) * area * std::f64::consts::PI),
            None => 1.0,
        };
        light_spectrum(&self.spectrum, self.rgb, self.scale * k)
    }
}

/// Where a placed shape goes: an object of the scene, or a member of a group.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Slot {
    /// `objects[i]`.
    Object(usize),
    /// `groups[g]`'s member `j`.
    Member(usize, usize),
}

/// A `plymesh` whose file is read after parsing ([`Parser::resolve_plys`]).
struct PendingPly {
    slot: Slot,
    file: String,
    floc: Loc,
    loc: Loc,
    x: DMat4,
    reverse: bool,
    area: Option<AreaLight>,
}

/// A `Shape` directive as read (kept for `ObjectInstance`).
#[derive(Clone, Debug)]
pub(crate) struct ShapeRec {
    pub(crate) ty: String,
    pub(crate) params: Params,
    pub(crate) ctm: DMat4,
    pub(crate) reverse: bool,
    pub(crate) material: MatRef,
    pub(crate) area: Option<AreaLight>,
    /// The `MediumInterface` names (empty: vacuum).
    pub(crate) inside: String,
    pub(crate) outside: String,
    pub(crate) loc: Loc,
}

/// A named texture.
#[derive(Clone, Debug)]
pub(crate) enum Tex {
    Spectrum(SpectrumDesc),
    Float(f64),
}

/// The camera as given, resolved at `WorldBegin` (the film's size is known then).
struct PendingCamera {
    fov: f64,
    lens_radius: f64,
    focal_distance: f64,
    camera_from_world: DMat4,
    loc: Loc,
}

/// Everything built so far.
pub(crate) struct Built {
    pub(crate) named_materials: HashMap<String, MatRef>,
    pub(crate) materials: Vec<(String, MaterialDesc)>,
    textures: HashMap<String, Tex>,
    pub(crate) objects: Vec<ObjectDesc>,
    /// Native instancing's groups (`ObjectBegin`s whose shapes are all meshes without
    /// emission or media), in order of first instance: their members in object space.
    pub(crate) groups: Vec<(String, Vec<ObjectDesc>)>,
    /// Per group member: the PLY file its triangles came from (as `mesh_files`).
    pub(crate) group_files: Vec<Vec<Option<String>>>,
    /// Per group member: where its `Shape` is (as `object_locs`).
    pub(crate) group_locs: Vec<Vec<Loc>>,
    /// Per `ObjectBegin` name instanced so far: its group, or `None` when its
    /// instances are copies (see [`Parser::native_group`]).
    pub(crate) group_index: HashMap<String, Option<usize>>,
    /// Objects placed by instances so far, against [`MAX_INSTANCED`].
    instanced: usize,
    /// Per object: the PLY file (as written in the scene) its triangles came from.
    pub(crate) mesh_files: Vec<Option<String>>,
    /// Per object: where its `Shape` is.
    pub(crate) object_locs: Vec<Loc>,
    pub(crate) lights: Vec<LightDesc>,
    pub(crate) environment: Option<EnvironmentDesc>,
    /// Where the environment comes from (the map's `filename`, or the `LightSource`).
    pub(crate) environment_loc: Option<Loc>,
    pub(crate) camera: Option<CameraDesc>,
    pending_camera: Option<PendingCamera>,
    pub(crate) render: SettingsPatch,
    resolution: (u32, u32),
    /// `M`: world space to rust-v's (identity or a mirror).
    pub(crate) mirror: DMat4,
    pending: Vec<PendingPly>,
    /// `MakeNamedMedium`s as read, in order, resolved into `media` after parsing.
    named_media: Vec<media::Named>,
    /// The media of the description (see [`Parser::resolve_media`]).
    pub(crate) media: Vec<(String, MediumDesc)>,
    /// Objects with an interior medium: the object, the medium's name and the shape's place.
    interiors: Vec<(usize, String, Loc)>,
    /// Objects with an outside medium, as `interiors`.
    exteriors: Vec<(usize, String, Loc)>,
    /// The outside medium at the `Camera` directive and its place.
    pub(crate) camera_medium: Option<(String, Loc)>,
    anonymous: usize,
    /// Triangles placed so far (copied instances included), against [`MAX_TRIANGLES`].
    triangles: usize,
}

/// The most triangles a pbrt scene may expand to (unique triangles: a group's meshes
/// count once however often it is instanced; copied instances count every copy;
/// `loopsubdiv` multiplies by 4 per level): about 1.6 GB of positions and indices at
/// most, so a small hostile file cannot exhaust memory.
pub(crate) const MAX_TRIANGLES: usize = 1 << 26;

/// The most objects a pbrt scene's native instances may place (one per member of the
/// group per `ObjectInstance`, about 200 bytes each): 200 MB at most.
pub(crate) const MAX_INSTANCED: usize = 1 << 20;

impl Default for Built {
    fn default() -> Self {
        Built {
            named_materials: HashMap::new(),
            materials: Vec::new(),
            textures: HashMap::new(),
            objects: Vec::new(),
            groups: Vec::new(),
            group_files: Vec::new(),
            group_locs: Vec::new(),
            group_index: HashMap::new(),
            instanced: 0,
            mesh_files: Vec::new(),
            object_locs: Vec::new(),
            lights: Vec::new(),
            environment: None,
            environment_loc: None,
            camera: None,
            pending_camera: None,
            // pbrt-v4's defaults when a directive is left out: a 1280x720 film, 16 samples
            // per pixel, the volumetric path tracer with maxdepth 5.
            render: SettingsPatch {
                width: Some(1280),
                height: Some(720),
                spp: Some(16),
                max_bounces: Some(5),
                integrator: Some(IntegratorKind::Path),
                ..SettingsPatch::default()
            },
            resolution: (1280, 720),
            mirror: DMat4::IDENTITY,
            pending: Vec::new(),
            named_media: Vec::new(),
            media: Vec::new(),
            interiors: Vec::new(),
            exteriors: Vec::new(),
            camera_medium: None,
            anonymous: 0,
            triangles: 0,
        }
    }
}

/// What a spectrum parameter is for.
#[derive(Clone, Copy, PartialEq)]
enum Role {
    Reflectance,
    Illuminant,
    Unbounded,
}

/// A point or vector for the description (−0 written as 0).
fn f3(v: DVec3) -> V3 {
    [v.x as f32 + 0.0, v.y as f32 + 0.0, v.z as f32 + 0.0]
}

/// The luminance-normalised light spectrum pbrt-v4 uses: `scale / Y(spectrum) · spectrum`, where
/// an RGB's Y is that of its illuminant alone (so `Rgb(r, g, b)` renders as r, g, b).
fn light_spectrum(spectrum: &SpectrumDesc, rgb: bool, factor: f64) -> SpectrumDesc {
    if rgb {
        if factor == 1.0 { spectrum.clone() } else { SpectrumDesc::Scaled(factor as f32, Box::new(spectrum.clone())) }
    } else {
        SpectrumDesc::Luminance(factor as f32, Box::new(spectrum.clone()))
    }
}

/// `s` times `k` for a reflectance (textures keep their kind).
fn scaled(s: SpectrumDesc, k: f64) -> SpectrumDesc {
    match s {
        SpectrumDesc::Image { path, uv_scale, uv_offset, wrap, scale } => {
            SpectrumDesc::Image { path, uv_scale, uv_offset, wrap, scale: scale * k as f32 }
        }
        SpectrumDesc::Checkerboard { even, odd, scale } => {
            SpectrumDesc::Checkerboard { even: Box::new(scaled(*even, k)), odd: Box::new(scaled(*odd, k)), scale }
        }
        s if k == 1.0 => s,
        s => SpectrumDesc::Scaled(k as f32, Box::new(s)),
    }
}

/// Named glasses: pbrt's name, rust-v's named glass or (refractive index n_d, source).
const GLASSES: [(&str, Option<&str>, f32); 7] = [
    ("glass-BK7", Some("N-BK7"), 1.5168),
    ("glass-BAF10", None, 1.670),
    ("glass-FK51A", None, 1.4866),
    ("glass-LASF9", None, 1.8503),
    ("glass-F5", None, 1.6034),
    ("glass-F10", None, 1.5),
    ("glass-F11", None, 1.5),
];

/// The metals rust-v knows by name (`Conductor(metal: ...)`).
const METALS: [&str; 5] = ["Ag", "Al", "Au", "Cu", "CuZn"];

impl Parser<'_> {
    // ----------------------------------------------------------------------------------
    // Parameters.

    /// The parameter `name`, marked as read.
    fn param<'p>(&self, ps: &'p Params, name: &str) -> Option<&'p Param> {
        ps.1.borrow_mut().push(name.to_string());
        let p = ps.0.iter().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }

    fn type_err(&self, p: &Param, want: &str) -> crate::error::Error {
        self.err(p.loc, format!("parameter \"{} {}\": expected type {want}", p.ty, p.name))
    }

    fn nums_of<'p>(&self, p: &'p Param, types: &[&str]) -> Result<&'p [f64]> {
        match &p.value {
            Value::Nums(v) if types.contains(&p.ty.as_str()) => Ok(v),
            _ => Err(self.type_err(p, &types.join(" or "))),
        }
    }

    fn float(&self, ps: &Params, name: &str, default: f64) -> Result<f64> {
        match self.param(ps, name) {
            None => Ok(default),
            Some(p) => Ok(self.nums_of(p, &["float", "integer"])?[0]),
        }
    }

    /// A float that may also be a float texture (only constant ones are understood).
    fn float_or_texture(&mut self, ps: &Params, name: &str, default: f64) -> Result<f64> {
        if let Some(p) = self.param(ps, name)
            && p.ty == "texture"
        {
            let Value::Strs(s) = &p.value else { return Err(self.type_err(p, "texture")) };
            return match self.built.textures.get(&s[0]) {
                Some(Tex::Float(v)) => Ok(*v),
                _ => {
                    let loc = p.loc;
                    self.warn(loc, format!("\"{name}\": only constant float textures are supported; using {default}"))?;
                    Ok(default)
                }
            };
        }
        self.float(ps, name, default)
    }

    fn int(&self, ps: &Params, name: &str, default: i64, min: i64, max: i64) -> Result<i64> {
        match self.param(ps, name) {
            None => Ok(default),
            Some(p) => {
                let v = self.nums_of(p, &["integer"])?[0];
                if v.fract() != 0.0 || v < min as f64 || v > max as f64 {
                    return Err(self.err(
                        p.loc,
                        format!("\"integer {name}\": expected a whole number from {min} to {max}, found {v}"),
                    ));
                }
                Ok(v as i64)
            }
        }
    }

    fn string(&self, ps: &Params, name: &str) -> Result<Option<(String, Loc)>> {
        match self.param(ps, name) {
            None => Ok(None),
            Some(p) => match &p.value {
                Value::Strs(s) if p.ty == "string" => Ok(Some((s[0].clone(), p.loc))),
                _ => Err(self.type_err(p, "string")),
            },
        }
    }

    fn boolean(&self, ps: &Params, name: &str, default: bool) -> Result<bool> {
        match self.param(ps, name) {
            None => Ok(default),
            Some(p) => match &p.value {
                Value::Bools(b) => Ok(b[0]),
                _ => Err(self.type_err(p, "bool")),
            },
        }
    }

    fn point3(&self, ps: &Params, name: &str, default: DVec3) -> Result<DVec3> {
        match self.param(ps, name) {
            None => Ok(default),
            Some(p) => {
                let v = self.nums_of(p, &["point3", "vector3", "normal3"])?;
                if v.len() != 3 {
                    return Err(self
                        .err(p.loc, format!("\"{} {name}\": expected one point (3 values), found {}", p.ty, v.len())));
                }
                Ok(DVec3::new(v[0], v[1], v[2]))
            }
        }
    }

    /// A spectrum parameter: the description, whether it is an RGB, and where it is.
    fn spectrum(&mut self, ps: &Params, name: &str, role: Role) -> Result<Option<(SpectrumDesc, bool, Loc)>> {
        let Some(p) = self.param(ps, name) else { return Ok(None) };
        let loc = p.loc;
        let s = match (p.ty.as_str(), &p.value) {
            ("rgb", Value::Nums(v)) => {
                return Ok(Some((SpectrumDesc::Rgb(v[0] as f32, v[1] as f32, v[2] as f32), true, loc)));
            }
            ("blackbody", Value::Nums(v)) => {
                if v.len() != 1 {
                    self.warn(loc, "\"blackbody\": pbrt-v4 takes one temperature; using the first value")?;
                }
                SpectrumDesc::Blackbody(v[0] as f32)
            }
            ("float", Value::Nums(v)) if role == Role::Unbounded || role == Role::Reflectance => {
                SpectrumDesc::Constant(v[0] as f32)
            }
            ("spectrum", Value::Nums(v)) => table(v),
            ("spectrum", Value::Strs(s)) => {
                let name = s[0].clone();
                self.named_or_file(&name, loc)?
            }
            ("texture", Value::Strs(s)) if role == Role::Reflectance => match self.built.textures.get(&s[0]) {
                Some(Tex::Spectrum(d)) => d.clone(),
                Some(Tex::Float(v)) => SpectrumDesc::Constant(*v as f32),
                None => {
                    let mut known: Vec<&str> = self.built.textures.keys().map(String::as_str).collect();
                    known.sort();
                    return Err(self.err(loc, format!("unknown texture \"{}\"; defined: {}", s[0], known.join(", "))));
                }
            },
            _ => {
                let want = match role {
                    Role::Reflectance => "rgb, spectrum, blackbody, float or texture",
                    _ => "rgb, spectrum or blackbody",
                };
                return Err(self.err(loc, format!("parameter \"{} {}\": expected type {want}", p.ty, p.name)));
            }
        };
        Ok(Some((s, false, loc)))
    }

    /// A named spectrum of pbrt-v4, or a spectrum file (`λ value` pairs).
    fn named_or_file(&mut self, name: &str, loc: Loc) -> Result<SpectrumDesc> {
        let approx = |p: &mut Self, what: &str, s: SpectrumDesc| -> Result<SpectrumDesc> {
            p.warn(loc, format!("named spectrum \"{name}\" is approximated by {what}"))?;
            Ok(s)
        };
        match name {
            "stdillum-D65" => return Ok(SpectrumDesc::D65),
            "stdillum-A" => return approx(self, "a 2856 K blackbody", SpectrumDesc::Blackbody(2856.0)),
            "stdillum-D50" => return approx(self, "a 5003 K blackbody", SpectrumDesc::Blackbody(5003.0)),
            "illum-acesD60" => return approx(self, "a 6004 K blackbody", SpectrumDesc::Blackbody(6004.0)),
            n if n.starts_with("stdillum-F") => return approx(self, "D65", SpectrumDesc::D65),
            n if n.starts_with("glass-")
                || n.starts_with("metal-")
                || n.starts_with("canon_")
                || n.starts_with("nikon_")
                || n.starts_with("sony_") =>
            {
                return Err(self.err(loc, format!("named spectrum \"{name}\" cannot be used here (it is an index of refraction or a camera's curve)")));
            }
            _ => {}
        }
        let path = self.ctx.dir.join(name);
        let bytes = read_input(&path).map_err(|e| {
            self.err(loc, format!("\"{name}\" is neither a named spectrum (stdillum-D65, glass-BK7, metal-Au-eta, ...) nor a readable spectrum file: {e}"))
        })?;
        self.ctx.record_input(name, path, fnv1a(&bytes));
        let text = String::from_utf8_lossy(&bytes);
        let mut v = Vec::new();
        for (i, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("");
            for w in line.split(|c: char| c.is_whitespace() || c == ',').filter(|w| !w.is_empty()) {
                match w.parse::<f64>() {
                    Ok(x) if x.is_finite() => v.push(x),
                    _ => {
                        return Err(self.err(
                            loc,
                            format!("spectrum file \"{name}\" line {}: expected numbers, found `{w}`", i + 1),
                        ));
                    }
                }
            }
        }
        if v.is_empty() || v.len() % 2 != 0 || v.chunks(2).zip(v.chunks(2).skip(1)).any(|(a, b)| b[0] <= a[0]) {
            return Err(self.err(
                loc,
                format!("spectrum file \"{name}\": expected (wavelength, value) pairs in increasing wavelength"),
            ));
        }
        Ok(table(&v))
    }

    /// A light's spectrum parameter `name` (default: the colour space's illuminant, D65).
    fn light_param(&mut self, ps: &Params, name: &str) -> Result<(SpectrumDesc, bool)> {
        Ok(match self.spectrum(ps, name, Role::Illuminant)? {
            Some((s, rgb, _)) => (s, rgb),
            None => (SpectrumDesc::D65, false),
        })
    }

    /// GGX α of a rough material: `roughness` or the mean of `uroughness` and `vroughness`,
    /// remapped as pbrt-v4 does (α = √r) unless `remaproughness` is false.
    fn roughness(&mut self, ps: &Params, prefix: &str, loc: Loc) -> Result<f32> {
        let n = |s: &str| format!("{prefix}{s}");
        let r = if self.param(ps, &n("roughness")).is_some() {
            self.float_or_texture(ps, &n("roughness"), 0.0)?
        } else {
            let u = self.float_or_texture(ps, &n("uroughness"), 0.0)?;
            let v = self.float_or_texture(ps, &n("vroughness"), 0.0)?;
            if u != v {
                self.warn(loc, format!("anisotropic roughness ({u}, {v}) is not supported: using their mean"))?;
            }
            0.5 * (u + v)
        };
        let remap = self.boolean(ps, "remaproughness", true)?;
        Ok(if remap { r.max(0.0).sqrt() as f32 } else { r as f32 })
    }

    /// An index of refraction: a number or a named glass.
    fn ior(&mut self, ps: &Params, name: &str) -> Result<IorDesc> {
        let Some(p) = self.param(ps, name) else { return Ok(IorDesc::Constant(1.5)) };
        let loc = p.loc;
        match (p.ty.as_str(), &p.value) {
            ("float", Value::Nums(v)) => Ok(IorDesc::Constant(v[0] as f32)),
            ("spectrum", Value::Strs(s)) if s[0].starts_with("glass-") => {
                match GLASSES.iter().find(|(n, _, _)| *n == s[0]) {
                    Some((_, Some(named), _)) => Ok(IorDesc::Named(named.to_string())),
                    Some((n, None, nd)) => {
                        self.warn(loc, format!("named glass \"{n}\" is not among rust-v's glasses: a constant index {nd} without dispersion"))?;
                        Ok(IorDesc::Constant(*nd))
                    }
                    None => Err(self.err(
                        loc,
                        format!(
                            "unknown named glass \"{}\": expected one of {}",
                            s[0],
                            GLASSES.map(|g| g.0).join(", ")
                        ),
                    )),
                }
            }
            ("spectrum", _) => {
                let s = self.spectrum(ps, name, Role::Unbounded)?;
                let v = match s {
                    Some((SpectrumDesc::Table(t), _, _)) => sample_table(&t, 587.6),
                    _ => 1.5,
                };
                self.warn(
                    loc,
                    format!(
                        "an index of refraction given as a spectrum is read as constant: {v} (its value at 587.6 nm)"
                    ),
                )?;
                Ok(IorDesc::Constant(v))
            }
            _ => Err(self.type_err(p, "float or spectrum")),
        }
    }
}

/// `(λ, value)` pairs as a `Table`.
fn table(v: &[f64]) -> SpectrumDesc {
    SpectrumDesc::Table(v.chunks(2).map(|c| (c[0] as f32, c[1] as f32)).collect())
}

/// A table's value at `nm`, linear between entries and flat beyond the ends.
fn sample_table(t: &[(f32, f32)], nm: f32) -> f32 {
    match t.iter().position(|&(l, _)| l >= nm) {
        None => t.last().map_or(1.5, |e| e.1),
        Some(0) => t[0].1,
        Some(i) => {
            let (a, b) = (t[i - 1], t[i]);
            a.1 + (b.1 - a.1) * (nm - a.0) / (b.0 - a.0)
        }
    }
}
