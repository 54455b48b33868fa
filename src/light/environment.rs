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

use std::f32::consts::PI;

use glam::{Mat3, Vec2, Vec3};

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
}

/// An equirectangular map of emission texels and its sampling density.
#[derive(Clone, Debug)]
struct EnvMap {
    width: usize,
    height: usize,
    texels: Vec<Texel>,
    dist: Piecewise2D,
    d65: Spectrum,
}

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
        Ok(EnvironmentLight {
            source: Source::Map(Box::new(EnvMap { width, height, texels, dist, d65 })),
            to_map: rotation.transpose(),
            from_map: rotation,
            peak,
            integral: integral as f32,
            scene_center: Vec3::ZERO,
            scene_radius: 1.0,
        })
    }

    /// The radiance arriving from world direction `wi` (pointing away from the scene).
    #[inline]
    pub fn radiance(&self, wi: Vec3) -> Spectrum {
        match &self.source {
            Source::Uniform(s) => *s,
            Source::Map(m) => m.radiance(to_uv(self.to_map * wi)),
        }
    }

    /// Total power up to the spectrum's shape: `πR² ∫ mean L dω`.
    pub fn power(&self) -> f32 {
        PI * self.scene_radius * self.scene_radius * self.integral
    }

    /// A direction towards the environment from `p`, by its density; the
    /// returned point lies beyond the scene's bounds along it.
    #[inline]
    pub fn sample_li(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        let (wi, pdf) = self.sample_direction(u)?;
        let point = p + wi * (2.0 * self.scene_radius);
        Some(LightSample { wi, point, n: -wi, pdf, scale: 1.0, is_delta: false })
    }

    /// The density per solid angle of [`Self::sample_li`] choosing world direction `wi`.
    #[inline]
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
