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
    CameraDesc, EnvironmentDesc, IorDesc, LightDesc, MaterialDesc, ObjectDesc, ShapeDesc, SpectrumDesc, V3, Wrap,
};
use crate::settings::{IntegratorKind, SettingsPatch};

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

/// A `plymesh` whose file is read after parsing ([`Parser::resolve_plys`]).
struct PendingPly {
    object: usize,
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
    /// Per object: the PLY file (as written in the scene) its triangles came from.
    pub(crate) mesh_files: Vec<Option<String>>,
    pub(crate) lights: Vec<LightDesc>,
    pub(crate) environment: Option<EnvironmentDesc>,
    pub(crate) camera: Option<CameraDesc>,
    pending_camera: Option<PendingCamera>,
    pub(crate) render: SettingsPatch,
    resolution: (u32, u32),
    /// `M`: world space to rust-v's (identity or a mirror).
    pub(crate) mirror: DMat4,
    pending: Vec<PendingPly>,
    anonymous: usize,
    /// Triangles placed so far (copies of instances included), against [`MAX_TRIANGLES`].
    triangles: usize,
}

/// The most triangles a pbrt scene may expand to (instances are copies, `loopsubdiv`
/// multiplies by 4 per level): about 1.6 GB of positions and indices at most, so a
/// small hostile file cannot exhaust memory.
pub(crate) const MAX_TRIANGLES: usize = 1 << 26;

impl Default for Built {
    fn default() -> Self {
        Built {
            named_materials: HashMap::new(),
            materials: Vec::new(),
            textures: HashMap::new(),
            objects: Vec::new(),
            mesh_files: Vec::new(),
            lights: Vec::new(),
            environment: None,
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

    // ----------------------------------------------------------------------------------
    // Camera and options.

    pub(crate) fn camera(&mut self, ty: &str, at: Loc, ps: &Params, ctm: DMat4) -> Result<()> {
        if ty != "perspective" {
            self.warn(at, format!("Camera \"{ty}\" is not supported: rendered as a perspective camera"))?;
        }
        let fov = self.float(ps, "fov", 90.0)?;
        if !(fov > 0.0 && fov < 180.0) {
            return Err(self.err(at, format!("Camera \"fov\": expected degrees in (0, 180), found {fov}")));
        }
        let lens_radius = self.float(ps, "lensradius", 0.0)?;
        let focal_distance = self.float(ps, "focaldistance", 1e6)?;
        if !(lens_radius >= 0.0 && focal_distance > 0.0) {
            return Err(self.err(at, format!("Camera: expected \"lensradius\" ≥ 0 and \"focaldistance\" > 0, found {lens_radius} and {focal_distance}")));
        }
        if let Some(p) = self.param(ps, "screenwindow") {
            let loc = p.loc;
            self.warn(loc, "Camera \"screenwindow\" is not supported: the full frame is rendered")?;
        }
        if let Some(p) = self.param(ps, "frameaspectratio") {
            let loc = p.loc;
            self.warn(loc, "Camera \"frameaspectratio\" is not supported: the film's aspect ratio is used")?;
        }
        for t in ["shutteropen", "shutterclose"] {
            if let Some(p) = self.param(ps, t) {
                let loc = p.loc;
                self.warn(loc, format!("Camera \"{t}\": motion blur is not supported (ignored)"))?;
            }
        }
        self.built.pending_camera =
            Some(PendingCamera { fov, lens_radius, focal_distance, camera_from_world: ctm, loc: at });
        Ok(())
    }

    pub(crate) fn film(&mut self, ty: &str, at: Loc, ps: &Params) -> Result<()> {
        if ty != "rgb" && ty != "spectral" {
            self.warn(at, format!("Film \"{ty}\" is not supported: rendered as an rgb film"))?;
        }
        let x = self.int(ps, "xresolution", 1280, 1, crate::settings::MAX_SIDE as i64)? as u32;
        let y = self.int(ps, "yresolution", 720, 1, crate::settings::MAX_SIDE as i64)? as u32;
        self.built.resolution = (x, y);
        self.built.render.width = Some(x);
        self.built.render.height = Some(y);
        if let Some((_, loc)) = self.string(ps, "filename")? {
            self.note(
                loc,
                "Film \"filename\" is ignored: the output is rust-v's -o (default: the scene's name with .png)",
            );
        }
        if let Some((s, loc)) = self.string(ps, "sensor")?
            && s != "cie1931"
        {
            self.warn(loc, format!("Film \"sensor\" \"{s}\" is not supported: rendered with the CIE 1931 observer"))?;
        }
        for ignored in ["iso", "exposuretime", "whitebalance", "maxcomponentvalue", "savefp16", "diagonal"] {
            if let Some(p) = self.param(ps, ignored) {
                let loc = p.loc;
                self.warn(loc, format!("Film \"{ignored}\" is not supported (ignored)"))?;
            }
        }
        Ok(())
    }

    pub(crate) fn sampler(&mut self, ty: &str, at: Loc, ps: &Params) -> Result<()> {
        let spp = self.int(ps, "pixelsamples", 16, 1, u32::MAX as i64)?;
        self.built.render.spp = Some(spp as u32);
        let seed = self.int(ps, "seed", 0, 0, i64::MAX)?;
        if ps.0.iter().any(|p| p.name == "seed") {
            self.built.render.seed = Some(seed as u64);
        }
        if !["zsobol", "sobol", "paddedsobol", "halton", "independent", "pmj02bn", "stratified"].contains(&ty) {
            self.warn(at, format!("Sampler \"{ty}\" is unknown: rust-v's own sampler is used"))?;
        }
        for p in ["jitter", "xsamples", "ysamples", "randomization", "dimensions"] {
            self.param(ps, p);
        }
        Ok(())
    }

    pub(crate) fn integrator(&mut self, ty: &str, at: Loc, ps: &Params) -> Result<()> {
        let depth = self.int(ps, "maxdepth", 5, 0, u32::MAX as i64)?;
        self.built.render.max_bounces = Some(depth as u32);
        let kind = match ty {
            "path" | "volpath" => IntegratorKind::Path,
            "bdpt" => IntegratorKind::Bdpt,
            "lightpath" => IntegratorKind::LightTrace,
            other => {
                self.note(at, format!("Integrator \"{other}\" is not available: rust-v's auto method is used"));
                IntegratorKind::Auto
            }
        };
        self.built.render.integrator = Some(kind);
        for p in ["regularize", "lightsampler"] {
            self.param(ps, p);
        }
        Ok(())
    }

    pub(crate) fn filter(&mut self, ty: &str, at: Loc, ps: &Params) -> Result<()> {
        if ty != "box" {
            self.warn(at, format!("PixelFilter \"{ty}\" is not supported: rust-v uses a one-pixel box filter"))?;
        }
        for p in ["xradius", "yradius", "radius", "sigma", "B", "C", "tau", "alpha"] {
            if let Some(p) = self.param(ps, p)
                && ty == "box"
            {
                let loc = p.loc;
                self.warn(loc, "PixelFilter \"box\" radius: rust-v's box is one pixel wide (ignored)")?;
            }
        }
        Ok(())
    }

    /// At `WorldBegin`: the camera, and the mirror `M` that keeps the image the right way round.
    ///
    /// pbrt's camera looks down +z with +x to the image's right and +y up: with a proper
    /// (rotation) camera transform, right = up × forward in world space. rust-v's camera
    /// puts forward × up on the right, the other way. Mirroring the whole world (x → −x)
    /// turns one into the other: for the mirror `M`, `M a × M b = −M (a × b)`, so rust-v's
    /// right in the mirrored world is `M` (pbrt's right). A camera transform that already
    /// mirrors (`Scale -1 1 1` before `LookAt`, as exporters write) needs no mirror.
    pub(crate) fn begin_world(&mut self, loc: Loc) -> Result<()> {
        let cam = self.built.pending_camera.take().unwrap_or(PendingCamera {
            fov: 90.0,
            lens_radius: 0.0,
            focal_distance: 1e6,
            camera_from_world: DMat4::IDENTITY,
            loc,
        });
        let w = cam.camera_from_world.inverse();
        let eye = w.transform_point3(DVec3::ZERO);
        let forward = w.transform_vector3(DVec3::Z);
        let up = w.transform_vector3(DVec3::Y);
        let right = w.transform_vector3(DVec3::X);
        let lens = DMat3::from_cols(right, up, forward);
        let scales = [right.length(), up.length(), forward.length()];
        if (scales[0] - scales[1]).abs() > 1e-6 * scales[0]
            || right.dot(up).abs() > 1e-6 * scales[0] * scales[1]
            || right.dot(forward).abs() > 1e-6 * scales[0] * scales[2]
            || up.dot(forward).abs() > 1e-6 * scales[1] * scales[2]
        {
            self.warn(
                cam.loc,
                "the camera transform scales or shears: rust-v's camera uses its view direction and up only",
            )?;
        }
        let mirror = lens.determinant() > 0.0;
        self.built.mirror = if mirror { DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)) } else { DMat4::IDENTITY };
        let m = self.built.mirror;
        let (xres, yres) = self.built.resolution;
        // pbrt's fov spans the shorter image side; rust-v's is vertical.
        let fov = if xres >= yres {
            cam.fov
        } else {
            2.0 * ((cam.fov.to_radians() * 0.5).tan() * yres as f64 / xres as f64).atan().to_degrees()
        };
        self.built.camera = Some(CameraDesc {
            eye: f3(m.transform_point3(eye)),
            look_at: f3(m.transform_point3(eye + forward.normalize())),
            up: f3(m.transform_vector3(up.normalize())),
            fov_deg: Some(fov as f32),
            // pbrt's thin lens: a disk of `lensradius` in scene units, focused at
            // `focaldistance` along the view direction.
            aperture_radius: cam.lens_radius as f32,
            focus_distance: (cam.lens_radius > 0.0).then_some(cam.focal_distance as f32),
            lens: None,
        });
        Ok(())
    }

    // ----------------------------------------------------------------------------------
    // Materials and textures.

    /// Adds a material to the description under `name` (or a new name) and returns its reference.
    /// An anonymous material (`Material "diffuse" ...`) is named `#K TYPE` (`#3 diffuse`),
    /// K counting them: a name a pbrt file would hardly give.
    fn add_material(&mut self, name: Option<&str>, ty: &str, m: MaterialDesc, at: Loc) -> Result<MatRef> {
        let name = match name {
            Some(n) => {
                if self.built.materials.iter().any(|(k, _)| k == n) {
                    return Err(self.err(at, format!("material \"{n}\" defined twice: expected each name once")));
                }
                n.to_string()
            }
            None => loop {
                self.built.anonymous += 1;
                let n = format!("#{} {ty}", self.built.anonymous);
                if !self.built.materials.iter().any(|(k, _)| *k == n) {
                    break n;
                }
            },
        };
        self.built.materials.push((name.clone(), m));
        Ok(MatRef::Name(name))
    }

    fn reflectance(&mut self, ps: &Params, name: &str, default: f32) -> Result<SpectrumDesc> {
        Ok(self.spectrum(ps, name, Role::Reflectance)?.map_or(SpectrumDesc::Constant(default), |s| s.0))
    }

    fn conductor(&mut self, ps: &Params, prefix: &str, at: Loc) -> Result<MaterialDesc> {
        let n = |s: &str| format!("{prefix}{s}");
        let roughness = self.roughness(ps, prefix, at)?;
        if let Some((r, _, loc)) = self.spectrum(ps, &n("reflectance"), Role::Reflectance)? {
            self.warn(
                loc,
                "a conductor given by \"reflectance\" is rendered as a Mirror of that reflectance (roughness dropped)",
            )?;
            return Ok(MaterialDesc::Mirror { reflectance: r });
        }
        let name_of = |p: Option<&Param>, suffix: &str| match p.map(|p| &p.value) {
            Some(Value::Strs(s)) => {
                s[0].strip_prefix("metal-").and_then(|m| m.strip_suffix(suffix)).map(str::to_string)
            }
            _ => None,
        };
        let eta_p = ps.0.iter().find(|p| p.name == n("eta"));
        let k_p = ps.0.iter().find(|p| p.name == n("k"));
        let (eta_m, k_m) = (name_of(eta_p, "-eta"), name_of(k_p, "-k"));
        let metal = match (eta_p, k_p) {
            (None, None) => Some("Cu".to_string()),
            _ if eta_m.is_some() && eta_m == k_m => eta_m.clone(),
            _ => None,
        };
        if let Some(m) = metal {
            self.param(ps, &n("eta"));
            self.param(ps, &n("k"));
            if METALS.contains(&m.as_str()) {
                return Ok(MaterialDesc::Conductor { metal: Some(m), eta: None, k: None, roughness, coating: None });
            }
            self.warn(
                at,
                format!("metal \"{m}\" is not among rust-v's metals ({}): rendered as Al", METALS.join(", ")),
            )?;
            return Ok(MaterialDesc::Conductor {
                metal: Some("Al".into()),
                eta: None,
                k: None,
                roughness,
                coating: None,
            });
        }
        if eta_m.is_some() || k_m.is_some() {
            self.warn(at, "a conductor's \"eta\" and \"k\" name different metals: rendered as Cu")?;
            self.param(ps, &n("eta"));
            self.param(ps, &n("k"));
            return Ok(MaterialDesc::Conductor {
                metal: Some("Cu".into()),
                eta: None,
                k: None,
                roughness,
                coating: None,
            });
        }
        let eta = self.spectrum(ps, &n("eta"), Role::Unbounded)?.map(|s| s.0).unwrap_or(SpectrumDesc::Constant(1.0));
        let k = self.spectrum(ps, &n("k"), Role::Unbounded)?.map(|s| s.0).unwrap_or(SpectrumDesc::Constant(0.0));
        Ok(MaterialDesc::Conductor { metal: None, eta: Some(eta), k: Some(k), roughness, coating: None })
    }

    /// `Material` or `MakeNamedMaterial` (then `name` is given).
    pub(crate) fn material(&mut self, name: Option<&str>, ty: &str, at: Loc, ps: &Params) -> Result<MatRef> {
        let what = format!("material \"{ty}\"");
        let m = match ty {
            "" | "none" | "interface" => {
                self.check_used(ps, &what)?;
                return Ok(MatRef::Interface);
            }
            "diffuse" => MaterialDesc::Lambertian { reflectance: self.reflectance(ps, "reflectance", 0.5)? },
            "coateddiffuse" => {
                self.warn(at, "coateddiffuse is rendered as Plastic: a dielectric coat (pbrt's eta and roughness) over a Lambertian base, without the layer's thickness, albedo and inter-reflections that pbrt simulates stochastically")?;
                let reflectance = self.reflectance(ps, "reflectance", 0.5)?;
                let roughness = self.roughness(ps, "", at)?;
                let ior = self.ior(ps, "eta")?;
                for p in ["thickness", "albedo", "g", "maxdepth", "nsamples"] {
                    self.param(ps, p);
                }
                MaterialDesc::Plastic { reflectance, ior, roughness }
            }
            "conductor" => self.conductor(ps, "", at)?,
            "coatedconductor" => {
                self.warn(at, "coatedconductor is rendered as its conductor alone (the dielectric coat is dropped)")?;
                for p in [
                    "interface.roughness",
                    "interface.uroughness",
                    "interface.vroughness",
                    "interface.eta",
                    "thickness",
                    "albedo",
                    "g",
                    "maxdepth",
                    "nsamples",
                ] {
                    self.param(ps, p);
                }
                self.conductor(ps, "conductor.", at)?
            }
            "dielectric" | "thindielectric" => {
                if ty == "thindielectric" {
                    self.warn(at, "thindielectric is rendered as a dielectric (rays bend; a thin sheet would not)")?;
                }
                let ior = self.ior(ps, "eta")?;
                let roughness = self.roughness(ps, "", at)?;
                MaterialDesc::Dielectric { ior, roughness, absorption: None, coating: None }
            }
            "diffusetransmission" => {
                self.warn(
                    at,
                    "diffusetransmission is rendered as diffuse reflection only (the transmission is dropped)",
                )?;
                self.param(ps, "transmittance");
                let r = self.reflectance(ps, "reflectance", 0.25)?;
                let s = self.float(ps, "scale", 1.0)?;
                MaterialDesc::Lambertian { reflectance: scaled(r, s) }
            }
            "mix" => {
                let amount = self.float_or_texture(ps, "amount", 0.5)?;
                let names = match self.param(ps, "materials") {
                    Some(Param { value: Value::Strs(s), .. }) if s.len() == 2 => s.clone(),
                    _ => {
                        return Err(
                            self.err(at, "material \"mix\": expected \"string materials\" with two material names")
                        );
                    }
                };
                let pick = if amount >= 0.5 { &names[1] } else { &names[0] };
                self.warn(at, format!("material \"mix\" is rendered as the material more likely chosen (\"{pick}\", amount {amount}), not a per-hit choice"))?;
                self.check_used(ps, &what)?;
                let m = self
                    .built
                    .named_materials
                    .get(pick)
                    .cloned()
                    .ok_or_else(|| self.err(at, format!("material \"mix\": unknown material \"{pick}\"")))?;
                if let Some(n) = name {
                    self.built.named_materials.insert(n.to_string(), m.clone());
                }
                return Ok(m);
            }
            other => {
                self.warn(at, format!("material \"{other}\" is not supported: rendered as diffuse 0.5"))?;
                for p in &ps.0 {
                    p.used.set(true);
                }
                MaterialDesc::Lambertian { reflectance: SpectrumDesc::Constant(0.5) }
            }
        };
        for p in ["normalmap", "displacement"] {
            if let Some(p) = self.param(ps, p) {
                let loc = p.loc;
                self.warn(loc, format!("\"{}\" (bump and normal maps) is not supported (ignored)", p.name))?;
            }
        }
        self.check_used(ps, &what)?;
        self.add_material(name, ty, m, at)
    }

    pub(crate) fn texture(&mut self, name: String, kind: &str, class: &str, at: Loc, ps: &Params) -> Result<()> {
        let what = format!("texture \"{class}\"");
        if kind != "spectrum" && kind != "float" && kind != "color" {
            return Err(self.err(
                at,
                format!("texture \"{name}\": expected the kind \"spectrum\" or \"float\", found \"{kind}\""),
            ));
        }
        let float = kind == "float";
        let tex = match class {
            "constant" => {
                if float {
                    Tex::Float(self.float(ps, "value", 1.0)?)
                } else {
                    Tex::Spectrum(self.reflectance(ps, "value", 1.0)?)
                }
            }
            "scale" => {
                let s = self.float_or_texture(ps, "scale", 1.0)?;
                if float {
                    Tex::Float(self.float_or_texture(ps, "tex", 1.0)? * s)
                } else {
                    Tex::Spectrum(scaled(self.reflectance(ps, "tex", 1.0)?, s))
                }
            }
            "imagemap" if !float => {
                let Some((file, _)) = self.string(ps, "filename")? else {
                    return Err(self.err(at, format!("texture \"{name}\": imagemap needs a \"string filename\"")));
                };
                let wrap = match self.string(ps, "wrap")? {
                    None => Wrap::Repeat,
                    Some((w, _)) if w == "repeat" => Wrap::Repeat,
                    Some((w, _)) if w == "clamp" => Wrap::Clamp,
                    Some((w, loc)) => {
                        self.warn(loc, format!("imagemap wrap \"{w}\" is not supported: repeat is used"))?;
                        Wrap::Repeat
                    }
                };
                let scale = self.float(ps, "scale", 1.0)?;
                let uv_scale = [self.float(ps, "uscale", 1.0)? as f32, self.float(ps, "vscale", 1.0)? as f32];
                let uv_offset = [self.float(ps, "udelta", 0.0)? as f32, self.float(ps, "vdelta", 0.0)? as f32];
                if self.boolean(ps, "invert", false)? {
                    self.warn(at, "imagemap \"invert\" is not supported (ignored)")?;
                }
                self.param(ps, "filter");
                self.param(ps, "maxanisotropy");
                if let Some((e, loc)) = self.string(ps, "encoding")?
                    && e != "sRGB"
                    && e != "linear"
                {
                    self.warn(loc, format!("imagemap encoding \"{e}\": PNGs are read as sRGB, EXRs as linear"))?;
                }
                Tex::Spectrum(SpectrumDesc::Image { path: file, uv_scale, uv_offset, wrap, scale: scale as f32 })
            }
            "checkerboard" if !float => {
                let even = self.reflectance(ps, "tex1", 1.0)?;
                let odd = self.reflectance(ps, "tex2", 0.0)?;
                let (u, v) = (self.float(ps, "uscale", 1.0)?, self.float(ps, "vscale", 1.0)?);
                if u != v {
                    self.warn(at, format!("checkerboard uscale {u} and vscale {v} differ: rust-v's checkerboard has one scale; using uscale"))?;
                }
                if self.int(ps, "dimension", 2, 2, 3)? != 2 {
                    self.warn(at, "a 3D checkerboard is not supported: the 2D one is used")?;
                }
                self.param(ps, "udelta");
                self.param(ps, "vdelta");
                Tex::Spectrum(SpectrumDesc::Checkerboard { even: Box::new(even), odd: Box::new(odd), scale: u as f32 })
            }
            other => {
                self.warn(at, format!("{kind} texture \"{other}\" is not supported: a constant 0.5 is used"))?;
                for p in &ps.0 {
                    p.used.set(true);
                }
                if float { Tex::Float(0.5) } else { Tex::Spectrum(SpectrumDesc::Constant(0.5)) }
            }
        };
        if let Some((m, loc)) = self.string(ps, "mapping")?
            && m != "uv"
        {
            self.warn(loc, format!("texture mapping \"{m}\" is not supported: uv is used"))?;
        }
        self.check_used(ps, &what)?;
        self.built.textures.insert(name, tex);
        Ok(())
    }

    // ----------------------------------------------------------------------------------
    // Lights.

    pub(crate) fn area_light(&mut self, ty: &str, at: Loc, ps: &Params) -> Result<Option<AreaLight>> {
        if ty != "diffuse" {
            self.warn(at, format!("AreaLightSource \"{ty}\" is not supported (ignored)"))?;
            for p in &ps.0 {
                p.used.set(true);
            }
            return Ok(None);
        }
        let (spectrum, rgb) = self.light_param(ps, "L")?;
        let scale = self.float(ps, "scale", 1.0)?;
        let two_sided = self.boolean(ps, "twosided", false)?;
        let power = self.float(ps, "power", -1.0)?;
        if let Some((_, loc)) = self.string(ps, "filename")? {
            self.warn(loc, "an area light's image (\"filename\") is not supported: \"L\" is used")?;
        }
        Ok(Some(AreaLight { spectrum, rgb, scale, power: (power > 0.0).then_some(power), two_sided }))
    }

    pub(crate) fn light(&mut self, ty: &str, at: Loc, ps: &Params, ctm: DMat4) -> Result<()> {
        let x = self.built.mirror * ctm;
        let scale = self.float(ps, "scale", 1.0)?;
        match ty {
            "point" | "spot" => {
                let (s, rgb) = self.light_param(ps, "I")?;
                let from = self.point3(ps, "from", DVec3::ZERO)?;
                let power = self.float(ps, "power", -1.0)?;
                let position = f3(x.transform_point3(from));
                if ty == "point" {
                    let k = if power > 0.0 { power / (4.0 * std::f64::consts::PI) } else { 1.0 };
                    self.built
                        .lights
                        .push(LightDesc::Point { position, intensity: light_spectrum(&s, rgb, scale * k) });
                } else {
                    let to = self.point3(ps, "to", DVec3::Z)?;
                    let cone = self.float(ps, "coneangle", 30.0)?;
                    let delta = self.float(ps, "conedeltaangle", 5.0)?;
                    let k = if power > 0.0 {
                        let (end, start) = (cone.to_radians().cos(), (cone - delta).to_radians().cos());
                        power / (2.0 * std::f64::consts::PI * ((1.0 - start) + (start - end) / 2.0))
                    } else {
                        1.0
                    };
                    self.built.lights.push(LightDesc::Spot {
                        position,
                        look_at: f3(x.transform_point3(to)),
                        cone_deg: cone as f32,
                        falloff_deg: delta.min(cone) as f32,
                        intensity: light_spectrum(&s, rgb, scale * k),
                    });
                }
            }
            "distant" => {
                let (s, rgb) = self.light_param(ps, "L")?;
                let from = self.point3(ps, "from", DVec3::ZERO)?;
                let to = self.point3(ps, "to", DVec3::Z)?;
                let e = self.float(ps, "illuminance", -1.0)?;
                let k = if e > 0.0 { e } else { 1.0 };
                let d = x.transform_vector3(to - from);
                self.built
                    .lights
                    .push(LightDesc::Distant { direction: f3(d), irradiance: light_spectrum(&s, rgb, scale * k) });
            }
            "infinite" => {
                if let Some((file, loc)) = self.string(ps, "filename")? {
                    self.warn(loc, format!("LightSource \"infinite\" image \"{file}\": pbrt-v4 maps are equal-area octahedral and rust-v reads equirectangular maps only; the environment is left out (convert the map and use environment: Image(...))"))?;
                    for p in &ps.0 {
                        p.used.set(true);
                    }
                    return Ok(());
                }
                let (s, rgb) = self.light_param(ps, "L")?;
                let e = self.float(ps, "illuminance", -1.0)?;
                let k = if e > 0.0 { e / std::f64::consts::PI } else { 1.0 };
                if let Some(p) = self.param(ps, "portal") {
                    let loc = p.loc;
                    self.warn(loc, "infinite light \"portal\" is not supported (ignored)")?;
                }
                if self.built.environment.is_some() {
                    self.warn(at, "a second infinite light: only the last one is kept")?;
                }
                self.built.environment = Some(EnvironmentDesc::Uniform(light_spectrum(&s, rgb, scale * k)));
            }
            other => {
                self.warn(at, format!("LightSource \"{other}\" is not supported (left out)"))?;
                for p in &ps.0 {
                    p.used.set(true);
                }
            }
        }
        Ok(())
    }

    // ----------------------------------------------------------------------------------
    // Shapes.

    /// A `Shape` placed by `instance · rec.ctm` (then the mirror `M`).
    pub(crate) fn shape(&mut self, rec: &ShapeRec, instance: DMat4) -> Result<()> {
        let ps = &rec.params;
        let at = rec.loc;
        let x = self.built.mirror * instance * rec.ctm;
        let lin = DMat3::from_mat4(x);
        // pbrt's own `reverseOrientation ^ transformSwapsHandedness` (without the mirror `M`),
        // which flips the normal of its quadrics at intersections.
        let quadric_flip = rec.reverse ^ (DMat3::from_mat4(instance * rec.ctm).determinant() < 0.0);
        let what = format!("Shape \"{}\"", rec.ty);
        let mut mesh_file = None;
        let mut pending = None;
        let (shape, area) = match rec.ty.as_str() {
            "sphere" | "disk" => {
                let s = self.uniform_scale(lin, at, &rec.ty)?;
                let radius = self.float(ps, "radius", 1.0)?;
                let cuts: &[(&str, Option<f64>)] = if rec.ty == "sphere" {
                    &[("zmin", None), ("zmax", None), ("phimax", Some(360.0))]
                } else {
                    &[("phimax", Some(360.0)), ("innerradius", Some(0.0))]
                };
                for &(p, full) in cuts {
                    if let Some(q) = self.param(ps, p) {
                        let v = self.nums_of(q, &["float"])?[0];
                        let partial = match (p, full) {
                            (_, Some(f)) => v != f,
                            ("zmin", _) => v > -radius,
                            _ => v < radius,
                        };
                        if partial {
                            let loc = q.loc;
                            self.warn(
                                loc,
                                format!("partial {} (\"{p}\") is not supported: the whole shape is rendered", rec.ty),
                            )?;
                        }
                    }
                }
                let r = radius * s;
                if rec.ty == "sphere" {
                    if quadric_flip && rec.area.is_some() {
                        self.warn(at, "an emitting sphere that pbrt turns inside out (ReverseOrientation, or a mirroring transform): rust-v's sphere emits outwards")?;
                    }
                    let center = x.transform_point3(DVec3::ZERO);
                    (ShapeDesc::Sphere { center: f3(center), radius: r as f32 }, 4.0 * std::f64::consts::PI * r * r)
                } else {
                    let h = self.float(ps, "height", 0.0)?;
                    let center = x.transform_point3(DVec3::new(0.0, 0.0, h));
                    let mut n = (lin.inverse().transpose() * DVec3::Z).normalize();
                    if quadric_flip {
                        n = -n;
                    }
                    (
                        ShapeDesc::Disk { center: f3(center), normal: f3(n), radius: r as f32 },
                        std::f64::consts::PI * r * r,
                    )
                }
            }
            "plymesh" => {
                let Some((file, floc)) = self.string(ps, "filename")? else {
                    return Err(self.err(at, "Shape \"plymesh\": expected a \"string filename\""));
                };
                if let Some(p) = self.param(ps, "displacement") {
                    let loc = p.loc;
                    self.warn(loc, "plymesh \"displacement\" is not supported (ignored)")?;
                }
                self.param(ps, "edgelength");
                // Read and placed after parsing, all files at once on the thread pool
                // (`resolve_plys`); the object keeps its place in the list.
                pending = Some((file.clone(), floc));
                mesh_file = Some(file);
                (ShapeDesc::Triangles { positions: Vec::new(), indices: Vec::new(), normals: None, uvs: None }, 0.0)
            }
            "trianglemesh" | "bilinearmesh" | "loopsubdiv" => {
                let (positions, tris, normals, uvs) = self.inline_mesh(&rec.ty, ps, at)?;
                let placed = place_mesh(x, rec.reverse, &positions, tris, normals.as_deref(), uvs)
                    .map_err(|m| self.err(at, format!("{what}: {m}")))?;
                self.count_triangles(&placed.0, at)?;
                placed
            }
            other => {
                self.warn(at, format!("Shape \"{other}\" is not supported (left out)"))?;
                for p in &ps.0 {
                    p.used.set(true);
                }
                return Ok(());
            }
        };
        for p in ["alpha", "emissionfilename"] {
            if let Some(p) = self.param(ps, p) {
                let loc = p.loc;
                self.warn(loc, format!("shape \"{}\" is not supported (ignored)", p.name))?;
            }
        }
        self.check_used(ps, &what)?;
        let material = match &rec.material {
            MatRef::Name(n) => Some(n.clone()),
            MatRef::Default => Some(self.default_material()),
            MatRef::Interface if rec.area.is_some() => None,
            MatRef::Interface => {
                self.warn(at, "a shape with the interface material (a medium's boundary) is left out")?;
                return Ok(());
            }
        };
        let emission = rec.area.as_ref().map(|a| a.emission(area));
        let two_sided = rec.area.as_ref().is_some_and(|a| a.two_sided);
        if let Some((file, floc)) = pending {
            let object = self.built.objects.len();
            self.built.pending.push(PendingPly {
                object,
                file,
                floc,
                loc: at,
                x,
                reverse: rec.reverse,
                area: rec.area.clone(),
            });
        }
        self.built.objects.push(ObjectDesc {
            shape,
            material,
            emission,
            two_sided,
            priority: 0,
            transform: None,
            interior: None,
        });
        self.built.mesh_files.push(mesh_file);
        Ok(())
    }

    /// Adds a placed mesh's triangles to the count, refusing more than [`MAX_TRIANGLES`].
    fn count_triangles(&mut self, shape: &ShapeDesc, at: Loc) -> Result<()> {
        if let ShapeDesc::Triangles { indices, .. } = shape {
            self.built.triangles += indices.len();
        }
        if self.built.triangles > MAX_TRIANGLES {
            return Err(self.err(
                at,
                format!(
                    "the scene expands to more than {MAX_TRIANGLES} triangles (instances are copies): expected fewer"
                ),
            ));
        }
        Ok(())
    }

    /// Reads every PLY file the `plymesh` shapes name, each once, in parallel, records
    /// them as inputs in order of first use, and places each shape's triangles (in
    /// parallel too). Errors are those of the first failing file or shape in file order.
    pub(crate) fn resolve_plys(&mut self) -> Result<()> {
        let pending = std::mem::take(&mut self.built.pending);
        let mut files: Vec<(String, Loc)> = Vec::new();
        for p in &pending {
            if !files.iter().any(|(f, _)| *f == p.file) {
                files.push((p.file.clone(), p.floc));
            }
        }
        let dir = self.ctx.dir.clone();
        let loaded: Vec<Result<(PathBuf, u64, MeshData)>> = files
            .par_iter()
            .map(|(f, _)| {
                let path = dir.join(f);
                let bytes = read_input(&path)?;
                let hash = fnv1a(&bytes);
                Ok((path.clone(), hash, parse_mesh(bytes, &path)?))
            })
            .collect();
        let mut data = HashMap::new();
        for ((f, loc), r) in files.iter().zip(loaded) {
            let (path, hash, mesh) = r.map_err(|e| self.err(*loc, format!("plymesh: {e}")))?;
            self.ctx.record_input(f, path, hash);
            data.insert(f.clone(), mesh);
        }
        let placed: Vec<std::result::Result<(ShapeDesc, f64), String>> = pending
            .par_iter()
            .map(|p| {
                let d = &data[&p.file];
                let positions: Vec<DVec3> = d.positions.iter().map(|v| v.as_dvec3()).collect();
                let normals: Option<Vec<DVec3>> = d.normals.as_ref().map(|n| n.iter().map(|v| v.as_dvec3()).collect());
                place_mesh(p.x, p.reverse, &positions, d.triangles.clone(), normals.as_deref(), d.uvs.clone())
            })
            .collect();
        for (p, r) in pending.iter().zip(placed) {
            let (shape, area) = r.map_err(|m| self.err(p.loc, format!("Shape \"plymesh\" \"{}\": {m}", p.file)))?;
            self.count_triangles(&shape, p.loc)?;
            let o = &mut self.built.objects[p.object];
            o.shape = shape;
            if let Some(a) = &p.area {
                o.emission = Some(a.emission(area));
            }
        }
        Ok(())
    }

    fn default_material(&mut self) -> String {
        let name = "pbrt-default-diffuse".to_string();
        if !self.built.materials.iter().any(|(k, _)| *k == name) {
            self.built
                .materials
                .push((name.clone(), MaterialDesc::Lambertian { reflectance: SpectrumDesc::Constant(0.5) }));
        }
        name
    }

    /// The uniform scale of a sphere's or disk's transform (a warning and the mean if it is not uniform).
    fn uniform_scale(&mut self, lin: DMat3, at: Loc, ty: &str) -> Result<f64> {
        let s = [lin.x_axis.length(), lin.y_axis.length(), lin.z_axis.length()];
        let mean = (s[0] + s[1] + s[2]) / 3.0;
        let sheared = lin.x_axis.dot(lin.y_axis).abs() > 1e-6 * s[0] * s[1]
            || lin.x_axis.dot(lin.z_axis).abs() > 1e-6 * s[0] * s[2]
            || lin.y_axis.dot(lin.z_axis).abs() > 1e-6 * s[1] * s[2];
        if sheared || s.iter().any(|v| (v - mean).abs() > 1e-6 * mean) {
            self.warn(
                at,
                format!(
                    "a {ty} under a non-uniform scale or shear is not supported: scaled uniformly by the mean ({mean})"
                ),
            )?;
        }
        Ok(mean)
    }

    /// `trianglemesh`, `bilinearmesh` and `loopsubdiv` in object space:
    /// positions, triangles, normals and uvs.
    #[allow(clippy::type_complexity)]
    fn inline_mesh(
        &mut self,
        ty: &str,
        ps: &Params,
        at: Loc,
    ) -> Result<(Vec<DVec3>, Vec<[u32; 3]>, Option<Vec<DVec3>>, Option<Vec<[f32; 2]>>)> {
        let points = |p: &Self, name: &str, types: &[&str], n: usize| -> Result<Option<Vec<f64>>> {
            match p.param(ps, name) {
                None => Ok(None),
                Some(q) => {
                    let v = p.nums_of(q, types)?;
                    if v.len() % n != 0 {
                        return Err(p.err(
                            q.loc,
                            format!("\"{} {name}\": expected a multiple of {n} values, found {}", q.ty, v.len()),
                        ));
                    }
                    Ok(Some(v.to_vec()))
                }
            }
        };
        let Some(p) = points(self, "P", &["point3"], 3)? else {
            return Err(self.err(at, format!("Shape \"{ty}\": expected \"point3 P\" (the vertices)")));
        };
        let positions: Vec<DVec3> = p.chunks(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect();
        let nv = positions.len();
        let normals = points(self, "N", &["normal3"], 3)?
            .map(|n| n.chunks(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect::<Vec<_>>());
        let uvs = match points(self, "uv", &["point2", "float"], 2)? {
            Some(v) => Some(v.chunks(2).map(|c| [c[0] as f32, c[1] as f32]).collect::<Vec<_>>()),
            None => points(self, "st", &["point2", "float"], 2)?
                .map(|v| v.chunks(2).map(|c| [c[0] as f32, c[1] as f32]).collect()),
        };
        for (name, len) in [("N", normals.as_ref().map(Vec::len)), ("uv", uvs.as_ref().map(Vec::len))] {
            if let Some(len) = len
                && len != nv
            {
                return Err(
                    self.err(at, format!("Shape \"{ty}\" \"{name}\": expected one per vertex ({nv}), found {len}"))
                );
            }
        }
        let corners = if ty == "bilinearmesh" { 4 } else { 3 };
        let indices: Vec<u32> = match self.param(ps, "indices") {
            Some(q) => {
                let v = self.nums_of(q, &["integer"])?;
                if v.len() % corners != 0 {
                    return Err(self.err(
                        q.loc,
                        format!("\"integer indices\": expected a multiple of {corners} values, found {}", v.len()),
                    ));
                }
                if let Some(bad) = v.iter().find(|&&i| i < 0.0 || i as usize >= nv || i.fract() != 0.0) {
                    return Err(self.err(
                        q.loc,
                        format!(
                            "\"integer indices\": vertex index {bad} out of range: expected 0 to {}",
                            nv as i64 - 1
                        ),
                    ));
                }
                v.iter().map(|&i| i as u32).collect()
            }
            None if nv == corners => (0..corners as u32).collect(),
            None => {
                return Err(
                    self.err(at, format!("Shape \"{ty}\": expected \"integer indices\" (there are {nv} vertices)"))
                );
            }
        };
        for p in ["S", "faceIndices"] {
            if let Some(q) = self.param(ps, p) {
                let loc = q.loc;
                self.warn(loc, format!("Shape \"{ty}\" \"{p}\" is not supported (ignored)"))?;
            }
        }
        let tris: Vec<[u32; 3]> = if corners == 4 {
            indices.chunks(4).flat_map(|q| [[q[0], q[1], q[2]], [q[2], q[1], q[3]]]).collect()
        } else {
            indices.chunks(3).map(|t| [t[0], t[1], t[2]]).collect()
        };
        if ty == "loopsubdiv" {
            let levels = self.int(ps, "levels", 3, 0, 16)?;
            let after = tris.len().saturating_mul(1 << (2 * levels));
            if after > MAX_TRIANGLES {
                return Err(self.err(
                    at,
                    format!("loopsubdiv: {} triangles at {levels} levels make {after}, more than {MAX_TRIANGLES}: expected fewer levels", tris.len()),
                ));
            }
            let (p, t, n) = super::loop_subdiv::subdivide(positions, tris, levels as u32);
            let n = n.iter().all(|v| *v != DVec3::ZERO).then_some(n);
            return Ok((p, t, n, None));
        }
        Ok((positions, tris, normals, uvs))
    }
}

/// Triangles in object space placed by `x` (the mirror included) as pbrt-v4 orients
/// them: the winding flipped by `reverse` and by a transform that swaps handedness, or,
/// with shading normals, turned towards them (pbrt's `FaceForward`); normals transformed
/// and flipped by `reverse`. Returns the shape and its area in world space.
fn place_mesh(
    x: DMat4,
    reverse: bool,
    positions: &[DVec3],
    mut tris: Vec<[u32; 3]>,
    normals: Option<&[DVec3]>,
    uvs: Option<Vec<[f32; 2]>>,
) -> std::result::Result<(ShapeDesc, f64), String> {
    let nv = positions.len();
    if let Some(k) = tris.iter().position(|t| t.iter().any(|&i| i as usize >= nv)) {
        return Err(format!("triangle {k} has a vertex index out of range (there are {nv} vertices)"));
    }
    let lin = DMat3::from_mat4(x);
    let world: Vec<DVec3> = positions.iter().map(|p| x.transform_point3(*p)).collect();
    let area: f64 = tris
        .iter()
        .map(|t| {
            0.5 * (world[t[1] as usize] - world[t[0] as usize])
                .cross(world[t[2] as usize] - world[t[0] as usize])
                .length()
        })
        .sum();
    if reverse ^ (lin.determinant() < 0.0) {
        for t in &mut tris {
            t.swap(1, 2);
        }
    }
    let nt = lin.inverse().transpose();
    let normals: Option<Vec<V3>> = normals.map(|ns| {
        ns.iter()
            .map(|n| {
                let w = (nt * *n).normalize_or_zero();
                f3(if reverse { -w } else { w })
            })
            .collect()
    });
    if let Some(ns) = &normals {
        for t in &mut tris {
            let [a, b, c] = t.map(|i| world[i as usize]);
            let s: DVec3 = t.iter().map(|&i| DVec3::from(ns[i as usize].map(f64::from))).sum();
            if (b - a).cross(c - a).dot(s) < 0.0 {
                t.swap(1, 2);
            }
        }
    }
    let positions = world.iter().map(|p| f3(*p)).collect();
    Ok((ShapeDesc::Triangles { positions, indices: tris, normals, uvs }, area))
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
