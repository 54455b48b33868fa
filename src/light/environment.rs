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
//! # Radiance and sampling
//! Each texel's linear sRGB colour becomes an emission spectrum as `Rgb(...)`
//! does for an emitter (`crate::color::rgb_emission`: the Jakob-Hanika sigmoid
//! times D65, fitted per texel at load, kept as three coefficients and a
//! scale). A direction's radiance is the bilinear blend of the four nearest
//! texels' spectra (wrapping in u, clamped at the poles).
//!
//! Directions are importance-sampled from a piecewise-constant density over
//! the texel grid ([`Piecewise2D`]) whose cell weights are the texel
//! neighbourhood's mean radiance (the 3x3 block around it: bilinear filtering
//! spreads a texel's radiance into its neighbours' cells, so every cell where
//! the radiance is not zero has a non-zero density: no bias) times `sin θ`
//! (the solid angle of a row). A point `(u, v)` of density `p(u, v)` is a
//! direction of density `p(u, v) / (2π² sin θ)` per solid angle. `Uniform`
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

use super::sky::SkyModel;
use super::{EmissionSample, LightSample, emit::parallel_ray};
use crate::color::{Spectrum, Uplift, d65, emission_spectrum, emission_uplift};
use crate::error::Result;
use crate::geometry::Transform;
use crate::io::image::{Pixels, decode_image};
use crate::sampler::piecewise::Piecewise2D;
use crate::sampler::warp::uniform_sphere;
use crate::scene::check::Check;
use crate::scene::desc::EnvironmentDesc;

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
}

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

/// The sky, its sun, and the ground below the horizon (see [`EnvironmentLight::sky`]).
#[derive(Clone, Debug)]
struct SkyEnv {
    model: SkyModel,
    /// Unit direction towards the sun's centre.
    sun: Vec3,
    /// `1 − cos R` of the sun's angular radius `R` (as `2 sin²(R/2)`: exact in f32).
    sun_one_minus_cos: f32,
    /// The radiance of the ground below the horizon.
    ground: Spectrum,
    /// A factor on everything.
    scale: f32,
    /// The sampling density of the sky and ground (the sun excluded), over the
    /// equirectangular grid, and the probability of sampling the sun's cone instead.
    table: Piecewise2D,
    p_sun: f32,
}

/// The sky table's size (over the whole sphere; the sky is smooth away from the
/// sun, which is sampled on its own).
const SKY_TABLE: (usize, usize) = (128, 64);

/// An equirectangular map of emission texels and its sampling density.
#[derive(Clone, Debug)]
struct EnvMap {
    width: usize,
    height: usize,
    texels: Vec<Texel>,
    /// Each texel's emission spectrum, evaluated once at load, for maps of at
    /// most [`CACHED_TEXELS`] texels (empty for larger ones, whose lookups
    /// evaluate the sigmoid of four texels each). A lookup without the cache
    /// spent 34% of `environment.ron`'s render time re-evaluating it.
    spectra: Vec<Spectrum>,
    dist: Piecewise2D,
    d65: Spectrum,
}

/// The largest map whose texel spectra are kept (512 x 512: 38 MB of spectra).
const CACHED_TEXELS: usize = 1 << 18;

/// One texel: the uplifted colour and its scale (see [`emission_uplift`]).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Texel {
    uplift: Uplift,
    scale: f32,
}

impl EnvironmentLight {
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
        }
    }

    /// A map of `width` x `height` linear sRGB texels (row 0 at the top),
    /// scaled by `scale`, turned by `rotation` (world from map). Errors (as
    /// plain messages: the caller names the field) for an empty or too large
    /// map, a negative or non-finite texel, or a map that is black everywhere.
    pub fn map(width: usize, height: usize, rgb: &[[f32; 3]], scale: f32, rotation: Mat3) -> Result<Self, String> {
        if width == 0 || height == 0 || rgb.len() != width * height {
            return Err(format!("expected a non-empty image, found {width}x{height}"));
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
        for j in 0..height {
            let (t0, t1) = (PI * j as f32 / height as f32, PI * (j + 1) as f32 / height as f32);
            let solid = (2.0 * PI / width as f32) * (t0.cos() - t1.cos());
            for i in 0..width {
                let k = j * width + i;
                integral += (mean[k] * solid) as f64;
                if mean[k] > 0.0 {
                    let s = emission_spectrum(&texels[k].uplift, texels[k].scale, &d65);
                    peak = Spectrum::from_fn(|b| peak[b].max(s[b]));
                }
            }
        }
        if !(integral > 0.0 && integral.is_finite()) {
            return Err("the map is black everywhere (or its total is not finite): it emits nothing".into());
        }
        // Sampling weights: the 3x3 neighbourhood's mean, times sin θ of the row.
        let mut weights = vec![0.0f32; width * height];
        for j in 0..height {
            let sin = (PI * (j as f32 + 0.5) / height as f32).sin();
            for i in 0..width {
                let mut sum = 0.0f32;
                for dj in -1i64..=1 {
                    let jj = (j as i64 + dj).clamp(0, height as i64 - 1) as usize;
                    for di in -1i64..=1 {
                        let ii = (i as i64 + di).rem_euclid(width as i64) as usize;
                        sum += mean[jj * width + ii];
                    }
                }
                weights[j * width + i] = sum / 9.0 * sin;
            }
        }
        let dist = Piecewise2D::new(&weights, width, height)
            .ok_or_else(|| "the map's sampling density is zero or not finite".to_string())?;
        let spectra = if texels.len() <= CACHED_TEXELS {
            texels.iter().map(|t| emission_spectrum(&t.uplift, t.scale, &d65)).collect()
        } else {
            Vec::new()
        };
        Ok(EnvironmentLight {
            source: Source::Map(Box::new(EnvMap { width, height, texels, spectra, dist, d65 })),
            to_map: rotation.transpose(),
            from_map: rotation,
            peak,
            integral: integral as f32,
            scene_center: Vec3::ZERO,
            scene_radius: 1.0,
        })
    }

    /// The Hosek-Wilkie sky (`crate::light::sky`) for a sun at `elevation`
    /// and `azimuth` (radians; azimuth 0 towards −z, π/2 towards +x, as the
    /// map's u), with the sun's disk, and below the horizon a Lambertian
    /// ground of reflectance `ground_albedo` lit by the sky and sun, `a E / π`
    /// (`E` the sky's and sun's irradiance on a horizontal plane, computed at
    /// load). Everything times `scale`. Errors name the model's parameter.
    pub fn sky(
        turbidity: f32,
        ground_albedo: f32,
        elevation: f32,
        azimuth: f32,
        scale: f32,
    ) -> Result<EnvironmentLight, String> {
        let model = SkyModel::new(turbidity, ground_albedo, elevation)?;
        let (se, ce) = elevation.sin_cos();
        let (sa, ca) = azimuth.sin_cos();
        let sun = Vec3::new(ce * sa, se, -ce * ca).normalize();
        let half = SkyModel::SUN_ANGULAR_RADIUS * 0.5;
        let sun_one_minus_cos = 2.0 * half.sin() * half.sin();
        let (w, h) = SKY_TABLE;
        // The sky (sun excluded) at texel centres: the irradiance on the ground
        // and the table's weights.
        let mut e_sky = Spectrum::ZERO;
        let mut sky_means = vec![0.0f32; w * h];
        for j in 0..h / 2 {
            let (t0, t1) = (PI * j as f32 / h as f32, PI * (j + 1) as f32 / h as f32);
            let solid = (2.0 * PI / w as f32) * (t0.cos() - t1.cos());
            for i in 0..w {
                let (d, _) = from_uv(Vec2::new((i as f32 + 0.5) / w as f32, (j as f32 + 0.5) / h as f32));
                let l = model.radiance(zenith_angle(d), angle_between(d, sun));
                e_sky += l * (solid * d.y.max(0.0));
                sky_means[j * w + i] = l.average();
            }
        }
        let e_sun = model.sun_irradiance() * se.max(0.0);
        let ground = (e_sky + e_sun) * (ground_albedo / PI);
        let ground_mean = ground.average();
        // Weights: the sky's mean at the texel and its neighbours (the Mie peak
        // is narrow), a floor of 1e-3 of the row's mean so no direction with
        // radiance has zero density, times sin θ.
        let mut weights = vec![0.0f32; w * h];
        for j in 0..h {
            let sin = (PI * (j as f32 + 0.5) / h as f32).sin();
            for i in 0..w {
                let v = if j < h / 2 {
                    let mut m = 0.0f32;
                    for dj in -1i64..=1 {
                        let jj = (j as i64 + dj).clamp(0, h as i64 / 2 - 1) as usize;
                        for di in -1i64..=1 {
                            m = m.max(sky_means[jj * w + (i as i64 + di).rem_euclid(w as i64) as usize]);
                        }
                    }
                    m
                } else {
                    ground_mean
                };
                weights[j * w + i] = v * sin;
            }
        }
        let floor = weights.iter().sum::<f32>() / weights.len() as f32 * 1e-3;
        for v in &mut weights {
            *v = v.max(floor);
        }
        let table = Piecewise2D::new(&weights, w, h).ok_or_else(|| "the sky's sampling density is zero".to_string())?;
        // ∫ L dω of each part, for the sun's share of samples and the power.
        let mut sky_int = 0.0f64;
        for j in 0..h / 2 {
            let (t0, t1) = (PI * j as f32 / h as f32, PI * (j + 1) as f32 / h as f32);
            let solid = (2.0 * PI / w as f32) * (t0.cos() - t1.cos());
            for i in 0..w {
                sky_int += (sky_means[j * w + i] * solid) as f64;
            }
        }
        let sun_int = model.sun_irradiance().average();
        let ground_int = ground_mean * 2.0 * PI;
        let total = sky_int as f32 + sun_int + ground_int;
        let p_sun = if sun_int > 0.0 { (sun_int / total).clamp(0.05, 0.95) } else { 0.0 };
        let peak = Spectrum::from_fn(|b| {
            let zenith = model.radiance(FRAC_PI_2 - elevation, FRAC_PI_2 - elevation)[b];
            let disk =
                model.sun_radiance(FRAC_PI_2 - elevation, 0.0)[b] + model.radiance(FRAC_PI_2 - elevation, 0.0)[b];
            zenith.max(disk).max(ground[b]) * scale
        });
        Ok(EnvironmentLight {
            source: Source::Sky(Box::new(SkyEnv { model, sun, sun_one_minus_cos, ground, scale, table, p_sun })),
            to_map: Mat3::IDENTITY,
            from_map: Mat3::IDENTITY,
            peak,
            integral: total * scale,
            scene_center: Vec3::ZERO,
            scene_radius: 1.0,
        })
    }

    /// The radiance arriving from world direction `wi` (pointing away from the scene).
    #[inline(never)]
    pub fn radiance(&self, wi: Vec3) -> Spectrum {
        match &self.source {
            Source::Uniform(s) => *s,
            Source::Map(m) => m.radiance(to_uv(self.to_map * wi)),
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

impl EnvMap {
    /// The bilinear blend of the four texels around `uv`.
    #[inline]
    fn radiance(&self, uv: Vec2) -> Spectrum {
        let (w, h) = (self.width as i64, self.height as i64);
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (i0, i1) = ((x0 as i64).rem_euclid(w) as usize, (x0 as i64 + 1).rem_euclid(w) as usize);
        let (j0, j1) = ((y0 as i64).clamp(0, h - 1) as usize, (y0 as i64 + 1).clamp(0, h - 1) as usize);
        if !self.spectra.is_empty() {
            let k = [j0 * self.width + i0, j0 * self.width + i1, j1 * self.width + i0, j1 * self.width + i1];
            let first = self.texels[k[0]];
            if k.iter().all(|&i| self.texels[i] == first) {
                return self.spectra[k[0]];
            }
            let wts = [(1.0 - fx) * (1.0 - fy), fx * (1.0 - fy), (1.0 - fx) * fy, fx * fy];
            let mut s = Spectrum::ZERO;
            for (k, weight) in k.into_iter().zip(wts) {
                if weight > 0.0 && self.texels[k].scale > 0.0 {
                    s += self.spectra[k] * weight;
                }
            }
            return s;
        }
        let t = [
            (self.texels[j0 * self.width + i0], (1.0 - fx) * (1.0 - fy)),
            (self.texels[j0 * self.width + i1], fx * (1.0 - fy)),
            (self.texels[j1 * self.width + i0], (1.0 - fx) * fy),
            (self.texels[j1 * self.width + i1], fx * fy),
        ];
        if t.iter().all(|(texel, _)| *texel == t[0].0) {
            // One colour all round (a constant map): exactly that texel's spectrum.
            return emission_spectrum(&t[0].0.uplift, t[0].0.scale, &self.d65);
        }
        let mut s = Spectrum::ZERO;
        for (texel, weight) in t {
            if weight > 0.0 && texel.scale > 0.0 {
                s += emission_spectrum(&texel.uplift, texel.scale, &self.d65) * weight;
            }
        }
        s
    }
}

impl SkyEnv {
    /// True when unit direction `wi` lies in the sun's disk.
    #[inline]
    fn in_sun(&self, wi: Vec3) -> bool {
        // 1 − cos γ from the chord: |wi − sun|² / 2, exact near the sun.
        (wi - self.sun).length_squared() * 0.5 <= self.sun_one_minus_cos
    }

    #[inline]
    fn radiance(&self, wi: Vec3) -> Spectrum {
        if wi.y < 0.0 {
            return self.ground * self.scale;
        }
        let (theta, gamma) = (zenith_angle(wi), angle_between(wi, self.sun));
        let mut l = self.model.radiance(theta, gamma);
        if self.in_sun(wi) {
            l += self.model.sun_radiance(theta, gamma);
        }
        l * self.scale
    }

    /// The density of the sun's cone (uniform) mixed with the table's.
    #[inline]
    fn pdf(&self, wi: Vec3) -> f32 {
        let sin = (wi.x * wi.x + wi.z * wi.z).sqrt();
        let table = if sin > 0.0 { self.table.pdf(to_uv(wi)) / (2.0 * PI * PI * sin) } else { 0.0 };
        let cone = if self.in_sun(wi) { 1.0 / (2.0 * PI * self.sun_one_minus_cos) } else { 0.0 };
        self.p_sun * cone + (1.0 - self.p_sun) * table
    }

    #[inline]
    fn sample(&self, u: Vec2) -> Option<(Vec3, f32)> {
        let wi = if u.x < self.p_sun {
            // Uniform in the sun's cone: 1 − cos γ uniform in [0, 1 − cos R].
            let ux = u.x / self.p_sun;
            let om = ux * self.sun_one_minus_cos;
            let sin_g = (om * (2.0 - om)).max(0.0).sqrt();
            let (c, s) = crate::sampler::warp::cos_sin_2pi(u.y);
            crate::geometry::Frame::from_z(self.sun).to_world(Vec3::new(sin_g * c, sin_g * s, 1.0 - om)).normalize()
        } else {
            let uu = Vec2::new((u.x - self.p_sun) / (1.0 - self.p_sun), u.y).min(Vec2::splat(1.0 - f32::EPSILON));
            let (uv, _) = self.table.sample(uu);
            from_uv(uv).0
        };
        let pdf = self.pdf(wi);
        (pdf.is_finite() && pdf > 0.0).then_some((wi, pdf))
    }
}

/// The zenith angle of unit direction `d` (from +y), accurate at the zenith.
#[inline]
fn zenith_angle(d: Vec3) -> f32 {
    (d.x * d.x + d.z * d.z).sqrt().atan2(d.y)
}

/// The angle between unit directions `a` and `b`, accurate when they are close.
#[inline]
fn angle_between(a: Vec3, b: Vec3) -> f32 {
    a.cross(b).length().atan2(a.dot(b))
}

/// The map coordinates of a unit direction `m` in the map's frame.
#[inline]
fn to_uv(m: Vec3) -> Vec2 {
    let mut u = m.x.atan2(-m.z) / (2.0 * PI);
    if u < 0.0 {
        u += 1.0;
    }
    let v = m.y.clamp(-1.0, 1.0).acos() / PI;
    Vec2::new(u.min(1.0 - f32::EPSILON), v.min(1.0 - f32::EPSILON))
}

/// The unit direction in the map's frame of map coordinates `uv`, and its `sin θ`.
#[inline]
fn from_uv(uv: Vec2) -> (Vec3, f32) {
    let (theta, phi) = (PI * uv.y, 2.0 * PI * uv.x);
    let (sin_t, cos_t) = theta.sin_cos();
    let (sin_p, cos_p) = phi.sin_cos();
    (Vec3::new(sin_t * sin_p, cos_t, -sin_t * cos_p), sin_t)
}

/// Every texel's emission uplift, `scale` folded in. Rows are fitted in
/// parallel; along a row each fit starts from the previous texel's
/// coefficients, and a texel of the same colour as the previous reuses them,
/// so a map of one colour gives exactly `Rgb(...)`'s spectrum everywhere.
fn fit_texels(width: usize, rgb: &[[f32; 3]], scale: f32) -> Vec<Texel> {
    use rayon::prelude::*;
    let rows: Vec<Vec<Texel>> = rgb
        .par_chunks(width)
        .map(|row| {
            let mut out: Vec<Texel> = Vec::with_capacity(width);
            let mut prev: Option<([f32; 3], Texel)> = None;
            for &p in row {
                let c = p.map(|v| v * scale);
                let texel = match prev {
                    Some((pc, t)) if pc == c => t,
                    _ => {
                        let near = prev.map(|(_, t)| t.uplift.coefficients());
                        let (uplift, scale) = emission_uplift(c, near);
                        Texel { uplift, scale }
                    }
                };
                prev = Some((c, texel));
                out.push(texel);
            }
            out
        })
        .collect();
    rows.concat()
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
            EnvironmentDesc::Image { path, scale, rotate_deg } => {
                let field = format!("{FIELD}.path");
                let scale = check.positive(&format!("{FIELD}.scale"), *scale)?;
                let rotation = Transform {
                    rotate_deg: check.vec(&format!("{FIELD}.rotate_deg"), *rotate_deg)?,
                    ..Transform::default()
                }
                .linear();
                let (resolved, bytes) = check.read_input(&field, path)?;
                let (w, h, pixels) = decode_image(&resolved, &bytes).map_err(|e| check.err(&field, e.to_string()))?;
                let rgb: Vec<[f32; 3]> = match pixels {
                    Pixels::Linear(p) => p.into_iter().map(|c| c.map(|v| v as f32)).collect(),
                    Pixels::Code16(p) => {
                        p.into_iter().map(|c| c.map(|v| crate::color::srgb_eotf(v as f32 / 65535.0))).collect()
                    }
                };
                EnvironmentLight::map(w as usize, h as usize, &rgb, scale, rotation)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Sampler;

    /// The orientation the module doc states: u = 0 looks to −z, 0.25 to +x,
    /// 0.5 to +z, 0.75 to −x; v = 0 up, 1 down; `to_uv` inverts `from_uv`.
    #[test]
    fn orientation_follows_the_documented_convention() {
        let dir = |u: f32, v: f32| from_uv(Vec2::new(u, v)).0;
        assert!((dir(0.0, 0.5) - Vec3::NEG_Z).length() < 1e-6);
        assert!((dir(0.25, 0.5) - Vec3::X).length() < 1e-6);
        assert!((dir(0.5, 0.5) - Vec3::Z).length() < 1e-6);
        assert!((dir(0.75, 0.5) - Vec3::NEG_X).length() < 1e-6);
        assert!((dir(0.3, 0.0) - Vec3::Y).length() < 1e-6);
        for (u, v) in [(0.1f32, 0.2f32), (0.6, 0.7), (0.95, 0.5), (0.26, 0.99)] {
            let uv = to_uv(dir(u, v));
            assert!((uv - Vec2::new(u, v)).length() < 1e-5, "{u},{v} -> {uv}");
        }
    }

    /// A 16x8 map with one bright texel, turned: the density per solid angle
    /// integrates to 1 over the sphere (midpoint rule on a fine grid of
    /// (u, v), |error| < 1e-3), `pdf_li` agrees with the density
    /// `sample_li` returned, and the estimator `L/pdf` of the irradiance-like
    /// integral ∫ mean L dω matches the map's own sum (20k samples; the
    /// estimate's spread is small because sampling follows the radiance, so 2%).
    #[test]
    fn map_density_integrates_to_one_and_matches_its_samples() {
        let (w, h) = (16usize, 8usize);
        let mut rgb = vec![[0.05f32, 0.1, 0.2]; w * h];
        rgb[2 * w + 5] = [40.0, 30.0, 10.0];
        rgb[6 * w + 12] = [0.0, 0.0, 0.0];
        let rot = Transform { rotate_deg: Vec3::new(10.0, 70.0, -20.0), ..Transform::default() }.linear();
        let env = EnvironmentLight::map(w, h, &rgb, 1.0, rot).unwrap();
        let n = 800;
        let mut integral = 0.0f64;
        for j in 0..n {
            for i in 0..n {
                let uv = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let (m, sin) = from_uv(uv);
                let wi = rot * m;
                integral += (env.pdf_li(wi) * 2.0 * PI * PI * sin) as f64 / (n * n) as f64;
            }
        }
        assert!((integral - 1.0).abs() < 1e-3, "∫pdf = {integral}");
        let mut s = Sampler::new(3, 0, 0);
        let mut est = 0.0f64;
        let samples = 20_000;
        let mut off = 0;
        for _ in 0..samples {
            let ls = env.sample_li(Vec3::ZERO, s.next_2d()).unwrap();
            let back = env.pdf_li(ls.wi);
            // A direction sampled within f32 rounding of a cell's edge may map
            // back into the neighbouring cell (rotation and normalisation round):
            // then the two densities differ by the cells' ratio. Rare.
            if (back - ls.pdf).abs() > 1e-3 * ls.pdf {
                off += 1;
            }
            est += (env.radiance(ls.wi).average() / ls.pdf) as f64;
        }
        assert!(off < samples / 200, "{off} of {samples} samples map back to another density");
        est /= samples as f64;
        // The same integral by the midpoint rule over directions (bilinear radiance).
        let mut want = 0.0f64;
        for j in 0..n {
            for i in 0..n {
                let uv = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let (m, sin) = from_uv(uv);
                want += (env.radiance(rot * m).average() * 2.0 * PI * PI * sin) as f64 / (n * n) as f64;
            }
        }
        assert!((est / want - 1.0).abs() < 0.02, "estimate {est} vs {want}");
    }

    /// A map of one colour is the same spectrum in every direction, bit for
    /// bit the emission `Rgb(...)` gives for that colour; a 1x1 map works.
    #[test]
    fn a_constant_map_is_rgb_emission_everywhere() {
        let c = [0.7f32, 0.4, 0.2];
        let want = crate::color::rgb_emission(c);
        for (w, h) in [(1usize, 1usize), (7, 3)] {
            let env = EnvironmentLight::map(w, h, &vec![c; w * h], 1.0, Mat3::IDENTITY).unwrap();
            let mut s = Sampler::new(4, 0, 0);
            for _ in 0..200 {
                let wi = uniform_sphere(s.next_2d());
                assert_eq!(env.radiance(wi), want);
            }
        }
    }

    /// The sky's density (sun cone mixed with the table) integrates to 1 over
    /// the sphere: the table part by the midpoint rule on a fine grid, the
    /// sun's part exactly (its cone density times its solid angle is 1, and
    /// the grid would miss the 0.26° disk). The irradiance of the sun and
    /// sky on a horizontal surface, estimated from `sample_li` (50k samples;
    /// the sun's part has almost no variance since its cone is sampled
    /// uniformly), matches the sun's irradiance from the model's own integral
    /// times sin(elevation) plus the sky's by the midpoint rule, within 2%.
    #[test]
    fn sky_density_integrates_to_one_and_sampling_finds_the_sun() {
        let elevation = 25f32.to_radians();
        let env = EnvironmentLight::sky(3.0, 0.3, elevation, 0.7, 1.0).unwrap();
        let Source::Sky(sky) = &env.source else { unreachable!() };
        let n = 1000;
        let mut table = 0.0f64;
        let mut sky_e = 0.0f64;
        for j in 0..n {
            for i in 0..n {
                let uv = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let (d, sin) = from_uv(uv);
                let w = (2.0 * PI * PI * sin) as f64 / (n * n) as f64;
                table += (sky.table.pdf(uv) / (2.0 * PI * PI * sin)) as f64 * w;
                if d.y > 0.0 && !sky.in_sun(d) {
                    sky_e += (env.radiance(d)[17] * d.y) as f64 * w;
                }
            }
        }
        let cone = 2.0 * PI * sky.sun_one_minus_cos * (1.0 / (2.0 * PI * sky.sun_one_minus_cos));
        let total = sky.p_sun as f64 * cone as f64 + (1.0 - sky.p_sun as f64) * table;
        assert!((total - 1.0).abs() < 2e-3, "∫pdf = {total} (table {table})");
        let mut s = Sampler::new(11, 0, 0);
        let samples = 50_000;
        let (mut e, mut hits) = (0.0f64, 0);
        for _ in 0..samples {
            let ls = env.sample_li(Vec3::ZERO, s.next_2d()).unwrap();
            assert!((env.pdf_li(ls.wi) - ls.pdf).abs() <= 1e-3 * ls.pdf);
            if ls.wi.y > 0.0 {
                e += (env.radiance(ls.wi)[17] * ls.wi.y / ls.pdf) as f64;
            }
            hits += sky.in_sun(ls.wi) as usize;
        }
        e /= samples as f64;
        let want = sky.model.sun_irradiance()[17] as f64 * elevation.sin() as f64 + sky_e;
        assert!(hits > samples / 20, "the sun's cone was sampled {hits} times");
        assert!((e / want - 1.0).abs() < 0.02, "E(550 nm) = {e}, want {want} (sky part {sky_e})");
    }

    /// Bad maps are refused with a message: NaN or negative texels, all black, empty.
    #[test]
    fn bad_maps_are_refused() {
        let id = Mat3::IDENTITY;
        assert!(
            EnvironmentLight::map(2, 1, &[[1.0, f32::NAN, 0.0], [1.0; 3]], 1.0, id).unwrap_err().contains("(0, 0)")
        );
        assert!(EnvironmentLight::map(2, 1, &[[1.0; 3], [-1.0, 0.0, 0.0]], 1.0, id).unwrap_err().contains("(1, 0)"));
        assert!(EnvironmentLight::map(2, 1, &[[0.0; 3]; 2], 1.0, id).unwrap_err().contains("black"));
        assert!(EnvironmentLight::map(0, 0, &[], 1.0, id).is_err());
    }
}
