//! pbrt-v4's participating media: `MakeNamedMedium` (`homogeneous` with pbrt's
//! presets, `uniformgrid`) and the media of `MediumInterface`, resolved after
//! parsing: a shape's inside becomes its `interior:`, the outside of a transition
//! its `exterior:`, and the outside medium at `Camera` the camera's `medium:`.
//!
//! A `uniformgrid`'s density is written in memory as a `.vol` file
//! (`NAME-medium-K.vol`, [`Check::provide`](crate::scene::check::Check::provide)):
//! `render` reads it from there, nothing is written beside the scene, and
//! `convert` writes it beside the output RON. pbrt's grid spans `p0..p1` in the
//! medium's space; rust-v's fills its object's bounding box: where the two boxes
//! agree (the medium's transform only scales, flips, swaps axes and moves) the
//! voxels are carried over exactly (reordered), otherwise pbrt's density is
//! resampled onto a grid over the object's bounds, with a warning.

use super::*;
use crate::medium::grid::{MAX_VOXELS, write_vol};
use crate::medium::phase::MAX_G;

/// A `MakeNamedMedium` as read.
pub(crate) struct Named {
    name: String,
    kind: Kind,
}

enum Kind {
    /// Carried over as it is.
    Homogeneous(MediumDesc),
    /// Placed per object ([`Parser::place_grid`]).
    Grid(Box<Grid>),
    /// A medium rust-v cannot render (warned about where it is defined).
    Unsupported,
}

/// A `uniformgrid` medium.
struct Grid {
    sigma_a: SpectrumDesc,
    sigma_s: SpectrumDesc,
    phase: PhaseDesc,
    n: [usize; 3],
    density: Vec<f32>,
    p0: DVec3,
    p1: DVec3,
    /// pbrt's world from the medium's space (the CTM at `MakeNamedMedium`).
    ctm: DMat4,
    /// The description's medium that holds the grid exactly, once made.
    exact: Option<String>,
}

impl Grid {
    /// pbrt-v4's density at `u` in the unit cube of `p0..p1` (`SampledGrid::Lookup`):
    /// trilinear between voxel centres, with 0 beyond the outer voxels, and 0 outside.
    fn lookup(&self, u: DVec3) -> f64 {
        if !(u.cmpge(DVec3::ZERO).all() && u.cmple(DVec3::ONE).all()) {
            return 0.0;
        }
        let s = [u.x * self.n[0] as f64 - 0.5, u.y * self.n[1] as f64 - 0.5, u.z * self.n[2] as f64 - 0.5];
        let i = s.map(|v| v.floor() as i64);
        let d = [s[0] - i[0] as f64, s[1] - i[1] as f64, s[2] - i[2] as f64];
        let at = |x: i64, y: i64, z: i64| -> f64 {
            let (n0, n1, n2) = (self.n[0] as i64, self.n[1] as i64, self.n[2] as i64);
            if x < 0 || y < 0 || z < 0 || x >= n0 || y >= n1 || z >= n2 {
                return 0.0;
            }
            self.density[((z * n1 + y) * n0 + x) as usize] as f64
        };
        let lerp = |a: f64, b: f64, t: f64| (1.0 - t) * a + t * b;
        let [x, y, z] = i;
        let c00 = lerp(at(x, y, z), at(x + 1, y, z), d[0]);
        let c10 = lerp(at(x, y + 1, z), at(x + 1, y + 1, z), d[0]);
        let c01 = lerp(at(x, y, z + 1), at(x + 1, y, z + 1), d[0]);
        let c11 = lerp(at(x, y + 1, z + 1), at(x + 1, y + 1, z + 1), d[0]);
        lerp(lerp(c00, c10, d[1]), lerp(c01, c11, d[1]), d[2])
    }
}

/// pbrt-v4's `RGBUnboundedSpectrum` of the non-negative `rgb` (the uplift of `rgb / 2m`
/// times `2m`, `m` the largest component; no illuminant) times `scale`: its 36 samples,
/// or a constant for a grey.
fn rgb_unbounded(rgb: [f32; 3], scale: f64) -> SpectrumDesc {
    let [r, g, b] = rgb;
    if r == g && g == b {
        return SpectrumDesc::Constant((r as f64 * scale) as f32);
    }
    let k = 2.0 * r.max(g).max(b);
    let shape = crate::color::rgb_reflectance(rgb.map(|v| v / k));
    SpectrumDesc::Samples((0..crate::color::N_BINS).map(|i| (shape[i] as f64 * k as f64 * scale) as f32).collect())
}

/// pbrt-v4's named media (`"string preset"`, `GetMediumScatteringProperties` in
/// `media.cpp`): name, reduced scattering σs′ and absorption σa, linear sRGB, per mm.
/// Measured by Jensen, Marschner, Levoy and Hanrahan, "A Practical Model for
/// Subsurface Light Transport", SIGGRAPH 2001 (Apple to Wholemilk), and by Narasimhan,
/// Gupta, Donner, Ramamoorthi, Nayar and Jensen, "Acquiring Scattering Properties of
/// Participating Media by Dilution", SIGGRAPH 2006 (the rest). pbrt uses σs′ as σs.
#[rustfmt::skip]
const PRESETS: [(&str, [f32; 3], [f32; 3]); 47] = [
    ("Apple", [2.29, 2.39, 1.97], [0.0030, 0.0034, 0.046]),
    ("Chicken1", [0.15, 0.21, 0.38], [0.015, 0.077, 0.19]),
    ("Chicken2", [0.19, 0.25, 0.32], [0.018, 0.088, 0.20]),
    ("Cream", [7.38, 5.47, 3.15], [0.0002, 0.0028, 0.0163]),
    ("Ketchup", [0.18, 0.07, 0.03], [0.061, 0.97, 1.45]),
    ("Marble", [2.19, 2.62, 3.00], [0.0021, 0.0041, 0.0071]),
    ("Potato", [0.68, 0.70, 0.55], [0.0024, 0.0090, 0.12]),
    ("Skimmilk", [0.70, 1.22, 1.90], [0.0014, 0.0025, 0.0142]),
    ("Skin1", [0.74, 0.88, 1.01], [0.032, 0.17, 0.48]),
    ("Skin2", [1.09, 1.59, 1.79], [0.013, 0.070, 0.145]),
    ("Spectralon", [11.6, 20.4, 14.9], [0.00, 0.00, 0.00]),
    ("Wholemilk", [2.55, 3.21, 3.77], [0.0011, 0.0024, 0.014]),
    ("Lowfat Milk", [0.89187, 1.5136, 2.532], [0.002875, 0.00575, 0.0115]),
    ("Reduced Milk", [2.4858, 3.1669, 4.5214], [0.0025556, 0.0051111, 0.012778]),
    ("Regular Milk", [4.5513, 5.8294, 7.136], [0.0015333, 0.0046, 0.019933]),
    ("Espresso", [0.72378, 0.84557, 1.0247], [4.7984, 6.5751, 8.8493]),
    ("Mint Mocha Coffee", [0.31602, 0.38538, 0.48131], [3.772, 5.8228, 7.82]),
    ("Lowfat Soy Milk", [0.30576, 0.34233, 0.61664], [0.0014375, 0.0071875, 0.035937]),
    ("Regular Soy Milk", [0.59223, 0.73866, 1.4693], [0.0019167, 0.0095833, 0.065167]),
    ("Lowfat Chocolate Milk", [0.64925, 0.83916, 1.1057], [0.0115, 0.0368, 0.1564]),
    ("Regular Chocolate Milk", [1.4585, 2.1289, 2.9527], [0.010063, 0.043125, 0.14375]),
    ("Coke", [8.9053e-05, 8.372e-05, 0.0], [0.10014, 0.16503, 0.2468]),
    ("Pepsi", [6.1697e-05, 4.2564e-05, 0.0], [0.091641, 0.14158, 0.20729]),
    ("Sprite", [6.0306e-06, 6.4139e-06, 6.5504e-06], [0.001886, 0.0018308, 0.0020025]),
    ("Gatorade", [0.0024574, 0.003007, 0.0037325], [0.024794, 0.019289, 0.008878]),
    ("Chardonnay", [1.7982e-05, 1.3758e-05, 1.2023e-05], [0.010782, 0.011855, 0.023997]),
    ("White Zinfandel", [1.7501e-05, 1.9069e-05, 1.288e-05], [0.012072, 0.016184, 0.019843]),
    ("Merlot", [2.1129e-05, 0.0, 0.0], [0.11632, 0.25191, 0.29434]),
    ("Budweiser Beer", [2.4356e-05, 2.4079e-05, 1.0564e-05], [0.011492, 0.024911, 0.057786]),
    ("Coors Light Beer", [5.0922e-05, 4.301e-05, 0.0], [0.006164, 0.013984, 0.034983]),
    ("Clorox", [0.0024035, 0.0031373, 0.003991], [0.0033542, 0.014892, 0.026297]),
    ("Apple Juice", [0.00013612, 0.00015836, 0.000227], [0.012957, 0.023741, 0.052184]),
    ("Cranberry Juice", [0.00010402, 0.00011646, 7.8139e-05], [0.039437, 0.094223, 0.12426]),
    ("Grape Juice", [5.382e-05, 0.0, 0.0], [0.10404, 0.23958, 0.29325]),
    ("Ruby Grapefruit Juice", [0.011002, 0.010927, 0.011036], [0.085867, 0.18314, 0.25262]),
    ("White Grapefruit Juice", [0.22826, 0.23998, 0.32748], [0.0138, 0.018831, 0.056781]),
    ("Shampoo", [0.0007176, 0.0008303, 0.0009016], [0.014107, 0.045693, 0.061717]),
    ("Strawberry Shampoo", [0.00015671, 0.00015947, 1.518e-05], [0.01449, 0.05796, 0.075823]),
    ("Head & Shoulders Shampoo", [0.023805, 0.028804, 0.034306], [0.084621, 0.15688, 0.20365]),
    ("Lemon Tea Powder", [0.040224, 0.045264, 0.051081], [2.4288, 4.5757, 7.2127]),
    ("Orange Powder", [0.00015617, 0.00017482, 0.0001762], [0.001449, 0.003441, 0.007863]),
    ("Pink Lemonade Powder", [0.00012103, 0.00013073, 0.00012528], [0.001165, 0.002366, 0.003195]),
    ("Cappuccino Powder", [1.8436, 2.5851, 2.1662], [35.844, 49.547, 61.084]),
    ("Salt Powder", [0.027333, 0.032451, 0.031979], [0.28415, 0.3257, 0.34148]),
    ("Sugar Powder", [0.00022272, 0.00025513, 0.000271], [0.012638, 0.031051, 0.050124]),
    ("Suisse Mocha Powder", [2.7979, 3.5452, 4.3365], [17.502, 27.004, 35.433]),
    ("Pacific Ocean Surface Water", [0.0001764, 0.00032095, 0.00019617], [0.031845, 0.031324, 0.030147]),
];

/// For a linear map whose columns each lie along one axis (a scale with flips and a
/// permutation of the axes): per column, its axis and whether it points backwards.
fn axis_permutation(l: DMat3) -> Option<[(usize, bool); 3]> {
    let mut out = [(0, false); 3];
    let mut used = [false; 3];
    for (a, slot) in out.iter_mut().enumerate() {
        let c = l.col(a);
        let len = c.length();
        if len == 0.0 {
            return None;
        }
        let axes: Vec<usize> = (0..3).filter(|&k| c[k].abs() > 1e-9 * len).collect();
        let [k] = axes[..] else { return None };
        if used[k] {
            return None;
        }
        used[k] = true;
        *slot = (k, c[k] < 0.0);
    }
    Some(out)
}

/// The axis-aligned bounds of the corners of `min..max` under `x`.
fn box_bounds(x: DMat4, min: DVec3, max: DVec3) -> (DVec3, DVec3) {
    let mut lo = DVec3::INFINITY;
    let mut hi = DVec3::NEG_INFINITY;
    for k in 0..8 {
        let p = DVec3::new(
            if k & 1 == 0 { min.x } else { max.x },
            if k & 2 == 0 { min.y } else { max.y },
            if k & 4 == 0 { min.z } else { max.z },
        );
        let q = x.transform_point3(p);
        lo = lo.min(q);
        hi = hi.max(q);
    }
    (lo, hi)
}

/// The bounding box rust-v gives a shape of the description (as `Shape::bounds`), if it has one.
fn shape_bounds(s: &ShapeDesc) -> Option<(DVec3, DVec3)> {
    let v = |p: &V3| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
    match s {
        ShapeDesc::Sphere { center, radius } => {
            let (c, r) = (glam::Vec3::from(*center), glam::Vec3::splat(radius.abs()));
            Some(((c - r).as_dvec3(), (c + r).as_dvec3()))
        }
        ShapeDesc::Triangles { positions, .. } if !positions.is_empty() => {
            let lo = positions.iter().fold(DVec3::INFINITY, |a, p| a.min(v(p)));
            let hi = positions.iter().fold(DVec3::NEG_INFINITY, |a, p| a.max(v(p)));
            Some((lo, hi))
        }
        _ => None,
    }
}

impl Parser<'_> {
    /// A medium's coefficient `name` (pbrt's default 1) times `scale`: a spectrum of
    /// non-negative values. An RGB is pbrt-v4's `RGBUnboundedSpectrum` (the uplifted
    /// colour `rgb / 2m` times `2m`, `m` its largest component; no illuminant), written
    /// as its 36 samples.
    fn coefficient(&mut self, ps: &Params, name: &str, scale: f64, what: &str) -> Result<SpectrumDesc> {
        let Some((s, rgb, loc)) = self.spectrum(ps, name, Role::Unbounded)? else {
            return Ok(SpectrumDesc::Constant(scale as f32));
        };
        let bad = |p: &Self, found: String| {
            p.err(loc, format!("{what} \"{name}\": expected non-negative coefficients per unit length, found {found}"))
        };
        if rgb {
            let SpectrumDesc::Rgb(r, g, b) = s else { unreachable!("an rgb parameter is Rgb") };
            let c = [r, g, b];
            if !c.iter().all(|v| v.is_finite() && *v >= 0.0) {
                return Err(bad(self, format!("rgb {c:?}")));
            }
            return Ok(rgb_unbounded(c, scale));
        }
        let value = self.ctx.spectrum(name, &s).map_err(|e| bad(self, e.to_string()))?;
        if value.min_value() < 0.0 {
            return Err(bad(self, value.min_value().to_string()));
        }
        Ok(if scale == 1.0 { s } else { SpectrumDesc::Scaled(scale as f32, Box::new(s)) })
    }

    /// `MakeNamedMedium NAME "string type" ...`.
    pub(crate) fn make_medium(&mut self, name: String, at: Loc, ps: &Params) -> Result<()> {
        if self.built.named_media.iter().any(|m| m.name == name) {
            return Err(self.err(at, format!("medium \"{name}\" defined twice: expected each name once")));
        }
        let Some((ty, tloc)) = self.string(ps, "type")? else {
            return Err(self.err(at, format!("MakeNamedMedium \"{name}\": expected a \"string type\" parameter")));
        };
        let what = format!("medium \"{ty}\"");
        let kind = match ty.as_str() {
            "homogeneous" | "uniformgrid" => {
                let scale = self.float(ps, "scale", 1.0)?;
                if !(scale.is_finite() && scale >= 0.0) {
                    let loc = self.param(ps, "scale").map_or(at, |p| p.loc);
                    return Err(
                        self.err(loc, format!("{what} \"scale\": expected a non-negative factor, found {scale}"))
                    );
                }
                // pbrt-v4: a known preset takes the place of "sigma_a" and "sigma_s" (both
                // still scaled); an unknown one warns and they are read.
                let preset = match self.string(ps, "preset")? {
                    Some((name, loc)) if ty == "homogeneous" => {
                        let found = PRESETS.iter().find(|p| p.0 == name);
                        if found.is_none() {
                            self.warn(loc, format!("{what} \"preset\" \"{name}\" is not among pbrt-v4's presets (Apple, Ketchup, Wholemilk, Espresso, ...): \"sigma_a\" and \"sigma_s\" are used"))?;
                        }
                        found
                    }
                    Some((_, loc)) => {
                        self.warn(loc, format!("{what}: \"preset\" applies to homogeneous media only (ignored)"))?;
                        None
                    }
                    None => None,
                };
                let (sigma_a, sigma_s) = match preset {
                    Some((_, sigma_s, sigma_a)) => {
                        for p in ["sigma_a", "sigma_s"] {
                            if let Some(q) = self.param(ps, p) {
                                let loc = q.loc;
                                self.warn(loc, format!("{what}: \"{p}\" is ignored with a preset (as in pbrt-v4)"))?;
                            }
                        }
                        (rgb_unbounded(*sigma_a, scale), rgb_unbounded(*sigma_s, scale))
                    }
                    None => {
                        (self.coefficient(ps, "sigma_a", scale, &what)?, self.coefficient(ps, "sigma_s", scale, &what)?)
                    }
                };
                let g = self.float(ps, "g", 0.0)?;
                if !(g.is_finite() && g.abs() <= MAX_G as f64) {
                    let loc = self.param(ps, "g").map_or(at, |p| p.loc);
                    return Err(self
                        .err(loc, format!("{what} \"g\": expected a mean cosine in [-{MAX_G}, {MAX_G}], found {g}")));
                }
                let phase = if g == 0.0 { PhaseDesc::Isotropic } else { PhaseDesc::HenyeyGreenstein { g: g as f32 } };
                for p in ["Le", "Lescale", "temperature", "temperaturescale", "temperatureoffset", "temperaturecutoff"]
                {
                    if let Some(q) = self.param(ps, p) {
                        let loc = q.loc;
                        self.warn(loc, format!("{what} \"{p}\": emissive media are not supported (ignored)"))?;
                    }
                }
                if ty == "homogeneous" {
                    Kind::Homogeneous(MediumDesc::Homogeneous { sigma_a, sigma_s, phase })
                } else {
                    let n = [
                        self.int(ps, "nx", 1, 1, MAX_VOXELS as i64)? as usize,
                        self.int(ps, "ny", 1, 1, MAX_VOXELS as i64)? as usize,
                        self.int(ps, "nz", 1, 1, MAX_VOXELS as i64)? as usize,
                    ];
                    let count = n[0].saturating_mul(n[1]).saturating_mul(n[2]);
                    let Some(p) = self.param(ps, "density") else {
                        return Err(self.err(at, format!("{what}: expected \"float density\" (nx·ny·nz values)")));
                    };
                    let loc = p.loc;
                    let v = self.nums_of(p, &["float"])?;
                    if count > MAX_VOXELS {
                        return Err(self.err(
                            at,
                            format!(
                                "{what}: {}x{}x{} is more than the {MAX_VOXELS} voxels a grid may have",
                                n[0], n[1], n[2]
                            ),
                        ));
                    }
                    if v.len() != count {
                        return Err(self.err(
                            loc,
                            format!(
                                "{what} \"density\": expected nx·ny·nz = {}x{}x{} = {count} values, found {}",
                                n[0],
                                n[1],
                                n[2],
                                v.len()
                            ),
                        ));
                    }
                    if let Some(k) = v.iter().position(|d| !(d.is_finite() && *d >= 0.0)) {
                        return Err(self.err(
                            loc,
                            format!(
                                "{what} \"density\": value {k} is {}: expected a finite, non-negative density",
                                v[k]
                            ),
                        ));
                    }
                    let density = v.iter().map(|&d| d as f32).collect();
                    let p0 = self.point3(ps, "p0", DVec3::ZERO)?;
                    let p1 = self.point3(ps, "p1", DVec3::ONE)?;
                    if (0..3).any(|k| p0[k] == p1[k]) {
                        return Err(self.err(at, format!("{what}: \"p0\" {p0} and \"p1\" {p1} span no volume")));
                    }
                    let ctm = self.state.ctm;
                    Kind::Grid(Box::new(Grid {
                        sigma_a,
                        sigma_s,
                        phase,
                        n,
                        density,
                        p0: p0.min(p1),
                        p1: p0.max(p1),
                        ctm,
                        exact: None,
                    }))
                }
            }
            "rgbgrid" | "cloud" | "nanovdb" => {
                self.warn(tloc, format!("MakeNamedMedium \"{name}\": medium \"{ty}\" is not supported; shapes with it inside are left clear"))?;
                for p in &ps.0 {
                    p.used.set(true);
                }
                Kind::Unsupported
            }
            other => {
                return Err(self.err(
                    tloc,
                    format!("MakeNamedMedium \"{name}\": unknown medium type \"{other}\"; expected homogeneous, uniformgrid, rgbgrid, cloud or nanovdb"),
                ));
            }
        };
        self.check_used(ps, &format!("MakeNamedMedium \"{name}\""))?;
        if let Kind::Homogeneous(d) = &kind {
            self.built.media.push((name.clone(), d.clone()));
        }
        self.built.named_media.push(Named { name, kind });
        Ok(())
    }

    /// The media of a shape's `MediumInterface`: its interior (`inside`, kept for a
    /// material that bounds a volume: a dielectric or the interface) and its
    /// exterior (`outside`, where the surface is a transition between two media, as
    /// pbrt-v4 uses it; a check in rust-v), both resolved after parsing
    /// ([`Parser::resolve_media`]).
    pub(crate) fn media_of(&mut self, rec: &ShapeRec, bounds_volume: bool) -> (Option<String>, Option<String>) {
        let exterior = (!rec.outside.is_empty() && rec.outside != rec.inside).then(|| rec.outside.clone());
        if rec.inside.is_empty() {
            return (None, exterior);
        }
        if !bounds_volume {
            self.note(
                rec.loc,
                format!(
                    "MediumInterface: medium \"{}\" inside an opaque shape is never entered (left out)",
                    rec.inside
                ),
            );
            return (None, exterior);
        }
        (Some(rec.inside.clone()), exterior)
    }

    /// Checks every medium named by a shape or the camera and places the grids:
    /// after parsing (and [`Parser::resolve_plys`]), when every object's bounds are known.
    pub(crate) fn resolve_media(&mut self) -> Result<()> {
        let interiors = std::mem::take(&mut self.built.interiors);
        for (object, name, loc) in interiors {
            let Some(k) = self.medium_index(&name, loc)? else { continue };
            let placed = match &self.built.named_media[k].kind {
                Kind::Homogeneous(_) => Some(name),
                Kind::Unsupported => None,
                Kind::Grid(_) => Some(self.place_grid(k, object, loc)?),
            };
            self.built.objects[object].interior = placed;
        }
        // Outside media are named as they are (a grid by the medium that holds it
        // voxel for voxel, if one does).
        let exteriors = std::mem::take(&mut self.built.exteriors);
        for (object, name, loc) in exteriors {
            let Some(k) = self.medium_index(&name, loc)? else { continue };
            let named = match &self.built.named_media[k].kind {
                Kind::Homogeneous(_) => Some(name.clone()),
                Kind::Grid(g) => g.exact.clone(),
                Kind::Unsupported => None,
            };
            if named.is_none() {
                self.note(loc, format!("MediumInterface: the outside medium \"{name}\" is not checked (a medium rust-v holds under another name or not at all)"));
            }
            self.built.objects[object].exterior = named;
        }
        // pbrt-v4: the camera sits in the outside medium of the MediumInterface at `Camera`.
        if let Some((name, loc)) = self.built.camera_medium.take()
            && !name.is_empty()
            && let Some(k) = self.medium_index(&name, loc)?
        {
            match &self.built.named_media[k].kind {
                Kind::Homogeneous(_) => {
                    if let Some(c) = self.built.camera.as_mut() {
                        c.medium = Some(name);
                    }
                }
                Kind::Grid(_) => self.warn(loc, format!("the camera's medium \"{name}\" is a uniformgrid: rust-v's camera medium is homogeneous (the camera sits in vacuum)"))?,
                Kind::Unsupported => {}
            }
        }
        Ok(())
    }

    /// The index of the medium `name` among those defined, or an error at `loc`.
    fn medium_index(&self, name: &str, loc: Loc) -> Result<Option<usize>> {
        match self.built.named_media.iter().position(|m| m.name == name) {
            Some(k) => Ok(Some(k)),
            None => {
                let known: Vec<&str> = self.built.named_media.iter().map(|m| m.name.as_str()).collect();
                let known = if known.is_empty() { "none".to_string() } else { known.join(", ") };
                Err(self.err(loc, format!("unknown medium \"{name}\" in MediumInterface; defined: {known}")))
            }
        }
    }

    /// The description's medium holding grid `k` for `object`: the voxels themselves
    /// where pbrt's box `p0..p1` in world space is the object's bounding box, else the
    /// density resampled over the object's bounds (with a warning).
    fn place_grid(&mut self, k: usize, object: usize, loc: Loc) -> Result<String> {
        let Kind::Grid(g) = &self.built.named_media[k].kind else { unreachable!("a grid medium") };
        let name = self.built.named_media[k].name.clone();
        let x = self.built.mirror * g.ctm;
        let (glo, ghi) = box_bounds(x, g.p0, g.p1);
        let Some((blo, bhi)) = shape_bounds(&self.built.objects[object].shape) else {
            return Err(self.err(loc, format!("medium \"{name}\" (uniformgrid): rust-v's grid fills its object's bounding box; expected a sphere or a mesh to hold it")));
        };
        let perm = axis_permutation(DMat3::from_mat4(x));
        let ext = (ghi - glo).max(bhi - blo);
        let agree =
            (0..3).all(|a| (blo[a] - glo[a]).abs() <= 1e-4 * ext[a] && (bhi[a] - ghi[a]).abs() <= 1e-4 * ext[a]);
        if let (Some(perm), true) = (perm, agree) {
            if let Some(done) = &g.exact {
                return Ok(done.clone());
            }
            let mut nw = [0; 3];
            for (a, &(w, _)) in perm.iter().enumerate() {
                nw[w] = g.n[a];
            }
            let mut data = Vec::with_capacity(g.density.len());
            for z in 0..nw[2] {
                for y in 0..nw[1] {
                    for xi in 0..nw[0] {
                        let iw = [xi, y, z];
                        let m: [usize; 3] = std::array::from_fn(|a| {
                            let (w, back) = perm[a];
                            if back { g.n[a] - 1 - iw[w] } else { iw[w] }
                        });
                        data.push(g.density[(m[2] * g.n[1] + m[1]) * g.n[0] + m[0]]);
                    }
                }
            }
            let desc = self.grid_desc(k, nw, &data);
            self.warn(loc, format!("medium \"{name}\" (uniformgrid): within half a voxel of the box's faces pbrt blends the density towards 0 and rust-v keeps the outer voxels' values"))?;
            self.built.media.push((name.clone(), desc));
            if let Kind::Grid(g) = &mut self.built.named_media[k].kind {
                g.exact = Some(name.clone());
            }
            return Ok(name);
        }
        // Resample at the finest voxel size pbrt's grid has in world space.
        let l = DMat3::from_mat4(x);
        let h = (0..3).map(|a| l.col(a).length() * (g.p1[a] - g.p0[a]) / g.n[a] as f64).fold(f64::INFINITY, f64::min);
        let bext = bhi - blo;
        let mut dims = [0usize; 3];
        let mut step = h;
        loop {
            for a in 0..3 {
                dims[a] = ((bext[a] / step).ceil() as usize).clamp(1, 1024);
            }
            if dims.iter().product::<usize>() <= 1 << 24 {
                break;
            }
            step *= 1.25;
        }
        let inv = x.inverse();
        let mut data = Vec::with_capacity(dims.iter().product());
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for xi in 0..dims[0] {
                    let f = DVec3::new(
                        (xi as f64 + 0.5) / dims[0] as f64,
                        (y as f64 + 0.5) / dims[1] as f64,
                        (z as f64 + 0.5) / dims[2] as f64,
                    );
                    let pm = inv.transform_point3(blo + f * bext);
                    data.push(g.lookup((pm - g.p0) / (g.p1 - g.p0)) as f32);
                }
            }
        }
        let desc = self.grid_desc(k, dims, &data);
        let placed = format!("{name} (object {object})");
        self.warn(
            loc,
            format!(
                "medium \"{name}\" (uniformgrid): its box p0..p1 is not this shape's bounding box, which rust-v's grid fills: pbrt's density is resampled onto {}x{}x{} voxels over the shape's bounds (medium \"{placed}\")",
                dims[0], dims[1], dims[2]
            ),
        )?;
        self.built.media.push((placed.clone(), desc));
        Ok(placed)
    }

    /// A `Grid` medium of grid medium `k`'s coefficients over `n` voxels of `data`,
    /// its `.vol` file made in memory.
    fn grid_desc(&mut self, k: usize, n: [usize; 3], data: &[f32]) -> MediumDesc {
        let Kind::Grid(g) = &self.built.named_media[k].kind else { unreachable!("a grid medium") };
        let stem = self.files[0].file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let count = self.built.media.iter().filter(|(_, m)| matches!(m, MediumDesc::Grid { .. })).count();
        let path = format!("{stem}-medium-{count}.vol");
        self.ctx.provide(&path, write_vol(n, data));
        MediumDesc::Grid {
            path,
            sigma_a: g.sigma_a.clone(),
            sigma_s: g.sigma_s.clone(),
            density_scale: 1.0,
            phase: g.phase,
        }
    }
}
