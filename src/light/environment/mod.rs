//! The environment: radiance arriving from infinitely far away in every
//! direction a ray escapes to (pbrt-v4 §12.5, Mitsuba 3's `envmap` and
//! `constant` emitters).
//!
//! ```ron
//! environment: Uniform(Constant(1)),
//! environment: Image(path: "sky.exr", scale: 1, rotate_deg: (0, 90, 0)),
//! ```
//!
//! # Orientation of an `Image` map
//! The map is equirectangular (latitude-longitude) with +y up, in the same
//! convention as Mitsuba 3's `envmap`, so one file lights both renderers
//! alike: the top row looks up (+y), the bottom row down (−y), the middle row
//! at the horizon; along a row, the left edge (u = 0) looks towards −z, a
//! quarter across (u = 0.25) towards +x, the centre (u = 0.5) towards +z,
//! three quarters (u = 0.75) towards −x. For a direction `m` in the map's frame,
//! `u = atan2(m.x, −m.z) / 2π` (wrapped into [0, 1)) and `v = acos(m.y) / π`.
//! `rotate_deg: (x, y, z)` turns the map about X, then Y, then Z, as an
//! object's `transform` turns a shape (`docs/scene-format.md` has a picture).
//!
//! With `mapping: EqualArea` the image is the equal-area octahedral square of
//! pbrt-v4's image infinite lights (Clarberg 2008), square: its centre looks up
//! (+y), its corners down, u grows towards +x and v towards +z; the inner
//! diamond `|u − ½| + |v − ½| < ½` is the upper hemisphere (`map::to_square`,
//! `map::from_square`: pbrt-v4's `EqualAreaSphereToSquare` layout for the
//! direction `(x, z, y)`, pbrt's light space having +z up). Bilinear lookups
//! fold across the square's edges onto the texels that border the same
//! directions (`map::fold_square`, pbrt's `octahedralsphere` wrap).
//!
//! # Radiance and sampling
//! Each texel's linear sRGB colour becomes an emission spectrum as `Rgb(...)`
//! does for an emitter (`crate::color::rgb_emission`: the Jakob-Hanika sigmoid
//! times D65, fitted per texel at load, kept as three coefficients and a
//! scale). A direction's radiance is the bilinear blend of the four nearest
//! texels' spectra (wrapping in u, clamped at the poles).
//!
//! Directions are importance-sampled from a piecewise-constant density over
//! the texel grid ([`Piecewise2D`]) whose cell weights are the bilinear
//! lookup's mean radiance over the cell (the 3x3 block around the texel,
//! weighted 3/4 for the texel and 1/8 for each neighbour per axis: bilinear
//! filtering spreads a texel's radiance into its neighbours' cells, so every
//! cell where the radiance is not zero has a non-zero density: no bias) times
//! `sin θ` (the solid angle of a row). Until 2026-11-28 the 3x3 block's plain
//! mean: it spread a map's sun over a ring of dim texels around it, and
//! `environment.ron`'s error at 16 spp was 7% higher. A point `(u, v)` of density `p(u, v)` is a
//! direction of density `p(u, v) / (2π² sin θ)` per solid angle. An equal-area
//! map's texels all span `4π/(w·h)`: its weights have no `sin θ` and a point of
//! density `p(u, v)` is a direction of density `p(u, v) / 4π`. `Uniform`
//! samples the sphere uniformly (`1/4π`).
//!
//! Light subpaths (BDPT, light tracing) start from the environment as pbrt-v4
//! does: a direction `ω` sampled as above, then a point uniformly on the disk
//! of the scene's bounding radius `R` that faces `ω`, upstream of the scene:
//! the ray travels along `−ω` with densities `p(ω)` (direction) and `1/(πR²)`
//! (position). The emitted power, for choosing among lights, is
//! `πR² ∫ L(ω) dω` (the flux through that disk).

use std::f32::consts::{FRAC_PI_2, PI};

use glam::{Mat3, Vec2, Vec3};

use super::{EmissionSample, LightSample, emit::parallel_ray};
use crate::color::{Spectrum, d65, emission_spectrum};
use crate::error::Result;
use crate::geometry::Transform;
use crate::io::image::decode_image;
use crate::sampler::piecewise::Piecewise2D;
use crate::sampler::warp::uniform_sphere;
use crate::scene::check::Check;
use crate::scene::desc::{EnvMapping, EnvironmentDesc};

mod map;
mod sky;
#[cfg(test)]
mod tests;

use map::{CACHED_TEXELS, EnvMap, fit_texels, from_square, from_uv, to_square, to_uv};
use sky::SkyEnv;

/// The most texels an environment map may have (a 8192 x 4096 map): each
/// costs 28 bytes and a fit at load.
pub const MAX_MAP_TEXELS: usize = 1 << 25;

/// Radiance from every direction at infinity.
#[derive(Clone, Debug)]
pub struct EnvironmentLight {
    source: Source,
    /// World directions into the map's frame (`rotate_deg` inverted), and back.
    to_map: Mat3,
    from_map: Mat3,
    /// The per-bin maximum radiance over directions (for warnings about
    /// values beyond the film's range; not a direction's radiance).
    pub peak: Spectrum,
    /// `∫ mean_λ L(ω) dω` over the sphere.
    integral: f32,
    /// The centre and radius of a sphere around the scene (set by the scene).
    pub scene_center: Vec3,
    /// See `scene_center`.
    pub scene_radius: f32,
    /// A sun lights the scene: the sky's, or a map's peak ([`SUN_SHARE`]).
    sun: bool,
}

/// A map has a sun when its brightest texels that hold this share of its power
/// (`∫ mean L dω`) span at most [`SUN_SOLID_ANGLE`]: then, as under the sky's sun,
/// its caustics through specular surfaces are found by light subpaths aimed from
/// it, hardly by camera paths, and `auto` picks `caustics` (measured on
/// `scenes/environment.ron`, whose sun holds 60% of the power in 0.05 sr:
/// docs/integrators.md). A broad map (a uniform one: half its power in half the
/// sphere) keeps path tracing, where aiming from everywhere costs more than it finds.
pub const SUN_SHARE: f64 = 0.5;

/// The largest solid angle (steradians) of a map's sun: 1% of the sphere.
pub const SUN_SOLID_ANGLE: f64 = 4.0 * std::f64::consts::PI / 100.0;

/// Where the radiance comes from.
#[derive(Clone, Debug)]
enum Source {
    /// The same spectrum from every direction.
    Uniform(Spectrum),
    /// An equirectangular map.
    Map(Box<EnvMap>),
    /// The Hosek-Wilkie sky and its sun.
    Sky(Box<SkyEnv>),
}

/// The bilinear lookup's mean over a texel's cell, per axis: the texel itself
/// weighs 3/4 on average over its cell, each neighbour 1/8 (its weight falls
/// from 1/2 at the cell's edge to 0 at the centre, over half the cell).
const CELL_MEAN: [f32; 3] = [0.125, 0.75, 0.125];

/// Whether a map has a sun ([`SUN_SHARE`], [`SUN_SOLID_ANGLE`]), in one pass over its
/// texels: a histogram of their power and solid angle by radiance, in steps of a
/// quarter octave below the brightest, read from the top until it holds the share.
/// Texels within a step count together, so the solid angle found is at most one
/// step's worth more than the exact (sorted) one: a map on the edge may be called
/// sunless, never the other way by more than that step.
struct SunFinder {
    /// log2 of the brightest texel's mean radiance.
    top: f32,
    /// Power and solid angle per step.
    bins: Vec<(f64, f64)>,
}

/// Quarter-octave steps of the [`SunFinder`]'s histogram (the last takes everything dimmer).
const SUN_STEPS: usize = 4 * 40;

impl SunFinder {
    fn new(mean: &[f32]) -> SunFinder {
        let max = mean.iter().fold(0.0f32, |m, &x| m.max(x));
        SunFinder { top: max.log2(), bins: vec![(0.0, 0.0); SUN_STEPS] }
    }

    fn add(&mut self, radiance: f32, solid: f32) {
        if radiance > 0.0 {
            let step = ((self.top - radiance.log2()) * 4.0).max(0.0) as usize;
            let bin = &mut self.bins[step.min(SUN_STEPS - 1)];
            bin.0 += (radiance * solid) as f64;
            bin.1 += solid as f64;
        }
    }

    fn found(&self) -> bool {
        let total: f64 = self.bins.iter().map(|b| b.0).sum();
        let mut power = 0.0;
        let mut solid = 0.0;
        for &(p, s) in &self.bins {
            power += p;
            solid += s;
            if power >= SUN_SHARE * total {
                return solid <= SUN_SOLID_ANGLE;
            }
        }
        false
    }
}

impl EnvironmentLight {
    /// True for the Hosek-Wilkie sky, whose sun (half a degree across) lights
    /// the scene almost as a delta light does, and for a map with a sun (its
    /// brightest texels holding [`SUN_SHARE`] of its power within
    /// [`SUN_SOLID_ANGLE`]): caustics of it are found by light subpaths, hardly
    /// by camera paths.
    pub fn has_sun(&self) -> bool {
        self.sun
    }

    /// Radiance `spectrum` from every direction.
    pub fn uniform(spectrum: Spectrum) -> EnvironmentLight {
        EnvironmentLight {
            integral: 4.0 * PI * spectrum.average(),
            peak: spectrum,
            source: Source::Uniform(spectrum),
            to_map: Mat3::IDENTITY,
            from_map: Mat3::IDENTITY,
            scene_center: Vec3::ZERO,
            scene_radius: 1.0,
            sun: false,
        }
    }

    /// An equirectangular map of `width` x `height` linear sRGB texels (row 0 at
    /// the top), scaled by `scale`, turned by `rotation` (world from map). Errors
    /// (as plain messages: the caller names the field) for an empty or too large
    /// map, a negative or non-finite texel, or a map that is black everywhere.
    pub fn map(width: usize, height: usize, rgb: &[[f32; 3]], scale: f32, rotation: Mat3) -> Result<Self, String> {
        Self::map_with(width, height, rgb, scale, rotation, EnvMapping::Equirectangular)
    }

    /// [`EnvironmentLight::map`] with the given `mapping` (an equal-area map must be square).
    pub fn map_with(
        width: usize,
        height: usize,
        rgb: &[[f32; 3]],
        scale: f32,
        rotation: Mat3,
        mapping: EnvMapping,
    ) -> Result<Self, String> {
        if width == 0 || height == 0 || rgb.len() != width * height {
            return Err(format!("expected a non-empty image, found {width}x{height}"));
        }
        if mapping == EnvMapping::EqualArea && width != height {
            return Err(format!("an equal-area map is square; this one is {width}x{height}"));
        }
        if width * height > MAX_MAP_TEXELS {
            return Err(format!(
                "{width}x{height} is more than the {MAX_MAP_TEXELS} texels an environment map may have"
            ));
        }
        if let Some(k) = rgb.iter().position(|p| p.iter().any(|c| !(c.is_finite() && *c >= 0.0))) {
            let p = rgb[k];
            return Err(format!(
                "texel ({}, {}) is ({}, {}, {}): expected finite, non-negative values",
                k % width,
                k / width,
                p[0],
                p[1],
                p[2]
            ));
        }
        let d65 = d65();
        let texels = fit_texels(width, rgb, scale);
        // Each texel's mean radiance, and the peak.
        let mean: Vec<f32> = texels.iter().map(|t| emission_spectrum(&t.uplift, t.scale, &d65).average()).collect();
        let mut peak = Spectrum::ZERO;
        let mut integral = 0.0f64;
        let mut sun = SunFinder::new(&mean);
        for j in 0..height {
            let solid = match mapping {
                EnvMapping::Equirectangular => {
                    let (t0, t1) = (PI * j as f32 / height as f32, PI * (j + 1) as f32 / height as f32);
                    (2.0 * PI / width as f32) * (t0.cos() - t1.cos())
                }
                EnvMapping::EqualArea => 4.0 * PI / (width * height) as f32,
            };
            for i in 0..width {
                let k = j * width + i;
                integral += (mean[k] * solid) as f64;
                sun.add(mean[k], solid);
                if mean[k] > 0.0 {
                    let s = emission_spectrum(&texels[k].uplift, texels[k].scale, &d65);
                    peak = Spectrum::from_fn(|b| peak[b].max(s[b]));
                }
            }
        }
        if !(integral > 0.0 && integral.is_finite()) {
            return Err("the map is black everywhere (or its total is not finite): it emits nothing".into());
        }
        // Sampling weights: the bilinear lookup's mean over the cell ([`CELL_MEAN`]; across the map's edges as
        // the bilinear lookup goes), times the row's sin θ for an equirectangular map
        // (an equal-area map's texels all span the same solid angle).
        let mut env = EnvMap {
            width,
            height,
            mapping,
            texels,
            spectra: Vec::new(),
            uniform: Vec::new(),
            dist: Piecewise2D::new(&[1.0], 1, 1).expect("one cell"),
            d65,
        };
        let mut weights = vec![0.0f32; width * height];
        for j in 0..height {
            let sin = match mapping {
                EnvMapping::Equirectangular => (PI * (j as f32 + 0.5) / height as f32).sin(),
                EnvMapping::EqualArea => 1.0,
            };
            for i in 0..width {
                let mut sum = 0.0f32;
                for dj in -1i64..=1 {
                    for di in -1i64..=1 {
                        sum += CELL_MEAN[(dj + 1) as usize]
                            * CELL_MEAN[(di + 1) as usize]
                            * mean[env.texel_index(i as i64 + di, j as i64 + dj)];
                    }
                }
                weights[j * width + i] = sum * sin;
            }
        }
        env.dist = Piecewise2D::new(&weights, width, height)
            .ok_or_else(|| "the map's sampling density is zero or not finite".to_string())?;
        if env.texels.len() <= CACHED_TEXELS {
            env.cache_spectra();
        }
        Ok(EnvironmentLight {
            source: Source::Map(Box::new(env)),
            to_map: rotation.transpose(),
            from_map: rotation,
            peak,
            integral: integral as f32,
            scene_center: Vec3::ZERO,
            scene_radius: 1.0,
            sun: sun.found(),
        })
    }
    /// The radiance arriving from world direction `wi` (pointing away from the scene).
    #[inline(never)]
    pub fn radiance(&self, wi: Vec3) -> Spectrum {
        match &self.source {
            Source::Uniform(s) => *s,
            Source::Map(m) => m.radiance(m.uv_of(self.to_map * wi)),
            Source::Sky(sky) => sky.radiance(wi),
        }
    }

    /// Total power up to the spectrum's shape: `πR² ∫ mean L dω`.
    pub fn power(&self) -> f32 {
        PI * self.scene_radius * self.scene_radius * self.integral
    }

    /// A direction towards the environment from `p`, by its density; the
    /// returned point lies beyond the scene's bounds along it.
    #[inline(never)]
    pub fn sample_li(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        let (wi, pdf) = self.sample_direction(u)?;
        let point = p + wi * (2.0 * self.scene_radius);
        Some(LightSample { wi, point, n: -wi, pdf, scale: 1.0, is_delta: false })
    }

    /// The density per solid angle of [`Self::sample_li`] choosing world direction `wi`.
    #[inline(never)]
    pub fn pdf_li(&self, wi: Vec3) -> f32 {
        match &self.source {
            Source::Uniform(_) => 1.0 / (4.0 * PI),
            Source::Map(m) if m.mapping == EnvMapping::EqualArea => {
                m.dist.pdf(to_square(self.to_map * wi)) / (4.0 * PI)
            }
            Source::Map(m) => {
                let mm = self.to_map * wi;
                // sin θ from x and z: accurate near the poles, where 1 − y² is not.
                let sin = (mm.x * mm.x + mm.z * mm.z).sqrt();
                if sin <= 0.0 {
                    return 0.0;
                }
                m.dist.pdf(to_uv(mm)) / (2.0 * PI * PI * sin)
            }
            Source::Sky(sky) => sky.pdf(wi),
        }
    }

    /// A world direction towards the environment and its density per solid angle.
    #[inline]
    fn sample_direction(&self, u: Vec2) -> Option<(Vec3, f32)> {
        match &self.source {
            Source::Uniform(_) => Some((uniform_sphere(u), 1.0 / (4.0 * PI))),
            Source::Map(m) if m.mapping == EnvMapping::EqualArea => {
                let (uv, pdf_uv) = m.dist.sample(u);
                let pdf = pdf_uv / (4.0 * PI);
                (pdf.is_finite() && pdf > 0.0).then(|| ((self.from_map * from_square(uv)).normalize(), pdf))
            }
            Source::Map(m) => {
                let (uv, pdf_uv) = m.dist.sample(u);
                let (mm, sin) = from_uv(uv);
                let pdf = pdf_uv / (2.0 * PI * PI * sin);
                (pdf.is_finite() && pdf > 0.0).then(|| ((self.from_map * mm).normalize(), pdf))
            }
            Source::Sky(sky) => sky.sample(u),
        }
    }

    /// A ray leaving the environment into the scene (see the module doc).
    #[inline]
    pub(super) fn sample_le(&self, u_pos: Vec2, u_dir: Vec2) -> Option<EmissionSample> {
        let (wi, pdf_dir) = self.sample_direction(u_dir)?;
        let r = self.scene_radius;
        let mut e = parallel_ray(self.scene_center + wi * r, -wi, r, u_pos)?;
        e.pdf_dir = pdf_dir;
        Some(e)
    }

    /// The densities `(pdf_pos, pdf_dir)` of [`Self::sample_le`] for a ray travelling along `dir`.
    #[inline]
    pub(super) fn pdf_le(&self, dir: Vec3) -> (f32, f32) {
        (1.0 / (PI * self.scene_radius * self.scene_radius), self.pdf_li(-dir))
    }
}

impl EnvironmentLight {
    /// The environment of the scene description at field `environment`.
    pub(crate) fn from_desc(check: &Check, d: &EnvironmentDesc) -> Result<EnvironmentLight> {
        const FIELD: &str = "environment";
        match d {
            EnvironmentDesc::Uniform(s) => {
                let s = check.spectrum(&format!("{FIELD}.Uniform"), s)?;
                if s.average() <= 0.0 {
                    return Err(check.err(FIELD, "a Uniform environment must emit something (found black)"));
                }
                Ok(EnvironmentLight::uniform(s))
            }
            EnvironmentDesc::Image { path, scale, rotate_deg, mapping } => {
                let field = format!("{FIELD}.path");
                let scale = check.positive(&format!("{FIELD}.scale"), *scale)?;
                let rotation = Transform {
                    rotate_deg: check.vec(&format!("{FIELD}.rotate_deg"), *rotate_deg)?,
                    ..Transform::default()
                }
                .linear();
                let (resolved, bytes) = check.read_input(&field, path)?;
                let (w, h, pixels) = decode_image(&resolved, &bytes).map_err(|e| check.err(&field, e.to_string()))?;
                let rgb = pixels.linear_rgb();
                EnvironmentLight::map_with(w as usize, h as usize, &rgb, scale, rotation, *mapping)
                    .map_err(|m| check.err(&field, format!("{path}: {m}")))
            }
            EnvironmentDesc::Sky { sun_elevation_deg, sun_azimuth_deg, turbidity, ground_albedo, scale } => {
                let scale = check.positive(&format!("{FIELD}.scale"), *scale)?;
                if !sun_azimuth_deg.is_finite() {
                    return Err(check.err(
                        format!("{FIELD}.sun_azimuth_deg"),
                        format!("expected a finite angle in degrees, found {sun_azimuth_deg}"),
                    ));
                }
                if !(0.0..=90.0).contains(sun_elevation_deg) {
                    return Err(check.err(
                        format!("{FIELD}.sun_elevation_deg"),
                        format!("expected degrees in [0, 90] (the sky model's range), found {sun_elevation_deg}"),
                    ));
                }
                let elevation = (sun_elevation_deg.to_radians()).min(FRAC_PI_2);
                EnvironmentLight::sky(*turbidity, *ground_albedo, elevation, sun_azimuth_deg.to_radians(), scale)
                    .map_err(|m| {
                        // The model's message starts with the parameter's name.
                        let name = m.split_whitespace().next().unwrap_or("");
                        let field = match name {
                            "turbidity" => "turbidity",
                            "ground_albedo" => "ground_albedo",
                            _ => "sun_elevation_deg",
                        };
                        check.err(format!("{FIELD}.{field}"), m)
                    })
            }
        }
    }
}
