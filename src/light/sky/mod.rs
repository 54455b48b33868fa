//! The spectral Hosek–Wilkie sky and its sun: a pure model of the radiance
//! of a clear sky, evaluated from the published coefficients (version 1.4a,
//! compiled in from `data.rs`, 3-clause BSD; see `docs/credits.md`).
//!
//! Written from the two papers: L. Hosek and A. Wilkie, "An Analytic Model
//! for Full Spectral Sky-Dome Radiance", ACM TOG 31(4) (SIGGRAPH 2012), and
//! "Adding a Solar Radiance Function to the Hosek Skylight Model", IEEE CG&A
//! 33(3) (2013), with the data layout of the authors' version-1.4a release.
//!
//! # Sky
//! For each of the 11 channels 320, 360, ..., 720 nm the sky radiance towards
//! a direction at zenith angle `θ` and angle `γ` to the sun is the extended
//! Perez function times a radiance scale,
//!
//! ```text
//! L(θ, γ) = (1 + A e^(B / (cos θ + 0.01))) (C + D e^(Eγ) + F cos²γ + G χ(H, γ) + I √cos θ) · L_M
//! χ(H, γ) = (1 + cos²γ) / (1 + H² − 2H cos γ)^(3/2)          (the Mie term)
//! ```
//!
//! The nine parameters and `L_M` depend on turbidity `T` ∈ [1, 10], ground
//! albedo `a` ∈ [0, 1] and sun elevation `η` ∈ [0, π/2]: each is a quintic
//! Bézier curve (6 control points) in `x = (η / (π/2))^(1/3)`, interpolated
//! linearly between the integer turbidities and between the albedos 0 and 1.
//! All of that depends on the scene only, so [`SkyModel::new`] does it once;
//! a radiance evaluation is then three `exp`/`sqrt`-class calls per channel.
//! The Mie term's denominator is evaluated as `(1 − H)² + 4H sin²(γ/2)`, the
//! same quantity without the cancellation of `1 + H² − 2H cos γ` in `f32`
//! near the sun (`H` is 0.5 to 0.9, so `(1 − H)²` can be 100 times smaller
//! than the terms it is the difference of).
//!
//! Units: W m⁻² sr⁻¹ nm⁻¹ (absolute spectral radiance; the model's output
//! since its version 1.1).
//!
//! # Sun
//! The 2013 paper adds the sun's direct radiance: per channel and integer
//! turbidity a piecewise cubic (45 pieces, breaks at `(k/45)³ π/2`) in the
//! elevation of the viewing direction, times a limb-darkening quintic
//! `Σ c_k μ^k` in the cosine `μ = √(1 − sin²γ / sin²R)` on the solar surface,
//! linear between turbidities and (both factors separately, as the authors'
//! code does) between channels. The elevation is the *view direction's*, not
//! the disk centre's: across the disk near the horizon the lower limb is
//! redder and dimmer, which is why [`SkyModel::sun_radiance`] takes `θ` as
//! well as `γ` (a change from the single-argument interface first planned).
//!
//! [`SkyModel::SUN_ANGULAR_RADIUS`] is the model's 0.255°: the radius of the
//! terrestrial sun in the authors' implementation (`TERRESTRIAL_SOLAR_RADIUS`,
//! half of 0.51°), which the limb darkening's `sin R` and the solar
//! coefficients go with; not the astronomical mean 0.2666°, which with the
//! same radiance would add about 9% to the sun's irradiance.
//! The sun's radiance is the direct part only; what the eye sees inside the
//! disk is [`SkyModel::radiance`] + [`SkyModel::sun_radiance`].
//!
//! [`SkyModel::sun_irradiance`] is the disk's total, `∫ L_sun cos γ dω` on a
//! surface facing the sun, integrated once in [`SkyModel::new`] (128 × 16
//! points over the disk, midpoint in the limb angle, trapezoid around; the
//! elevation's change across the disk matters at a low sun: taking the disk
//! at its centre's elevation would be 1.5% off at 380 nm for a sun 5° high
//! and turbidity 9).
//!
//! # Renderer bins
//! [`SkyModel::radiance`] and [`SkyModel::sun_radiance`] return the renderer's
//! 36 bins (380..730 nm): linear in wavelength between the channel centres
//! (as the authors' code interpolates), and the 720 nm value held for 730 nm,
//! beyond the model's range (the authors' code fades it linearly towards 0 at
//! 760 nm instead; holding it keeps the last bin from darkening by a quarter
//! for want of data).
//!
//! # Negative values
//! The fitted sky function dips slightly below zero in places (down to about
//! −1e-5 W m⁻² sr⁻¹ nm⁻¹ at 320 nm on the horizon 90° from a low sun, where the
//! other channels are ~1e-2); every value returned here is clamped at 0.
//!
//! # Below the horizon
//! The model is fitted for the upper hemisphere only (`θ ≤ π/2`; `√cos θ` is
//! not even real below). Every function here returns **zero** (black) for
//! `θ > π/2`: the model says nothing about the ground, and what the ground
//! shows (black or the albedo's bounce) is for the caller to decide. At the
//! horizon itself `cos θ` is clamped at 0, so `θ = π/2` in `f32` (whose cosine
//! rounds to −4e-8) gives the horizon radiance, not a NaN.

mod data;
#[cfg(test)]
mod reference;
#[cfg(test)]
mod tests;

use core::f32::consts::FRAC_PI_2;

use crate::color::{N_BINS, Spectrum};

/// Number of the model's spectral channels.
pub const N_CHANNELS: usize = 11;

/// Centre wavelengths of the model's channels, in nm: 320, 360, ..., 720.
pub const CHANNEL_NM: [f32; N_CHANNELS] = {
    let mut c = [0.0; N_CHANNELS];
    let mut i = 0;
    while i < N_CHANNELS {
        c[i] = 320.0 + 40.0 * i as f32;
        i += 1;
    }
    c
};

/// For each renderer bin (380 + 10 i nm), the lower channel and the weight
/// of the upper one: `value = (1 − t) ch[lo] + t ch[lo + 1]`. 720 nm and the
/// 730 nm beyond the model's range take channel 10 whole (`lo = 9, t = 1`).
const BIN_CHANNELS: [(usize, f32); N_BINS] = {
    let mut b = [(0, 0.0); N_BINS];
    let mut i = 0;
    while i < N_BINS {
        // Bin i is at 380 + 10 i nm, i.e. 60 + 10 i nm above the first channel.
        let above = 60 + 10 * i;
        let (lo, t) = if above >= 400 { (N_CHANNELS - 2, 1.0) } else { (above / 40, (above % 40) as f32 / 40.0) };
        b[i] = (lo, t);
        i += 1;
    }
    b
};

/// Number of elevation pieces of the solar radiance function.
const SOLAR_PIECES: usize = 45;
/// Coefficients per piece (a cubic).
const SOLAR_ORDER: usize = 4;

/// The Hosek–Wilkie sky and sun for one turbidity, ground albedo and sun
/// elevation (see the module docs).
#[derive(Clone, Debug)]
pub struct SkyModel {
    /// Per channel, the Perez parameters A B C D E F G I (the data's order);
    /// H enters only through `mie`.
    params: [[f32; 8]; N_CHANNELS],
    /// Per channel, `((1 − H)², 4H)` for the Mie term's denominator.
    mie: [[f32; 2]; N_CHANNELS],
    /// Per channel, the radiance scale `L_M` (W m⁻² sr⁻¹ nm⁻¹).
    scale: [f32; N_CHANNELS],
    /// Per channel and elevation piece, the sun's unlimbed radiance cubic
    /// (highest power first) already interpolated to the turbidity.
    solar: Box<[[[f32; SOLAR_ORDER]; SOLAR_PIECES]; N_CHANNELS]>,
    /// Per renderer bin, the limb-darkening coefficients interpolated to its wavelength.
    limb: [[f32; 6]; N_BINS],
    /// The sun's elevation in radians, as given.
    sun_elevation: f32,
    /// The sun's irradiance on a surface facing it (see [`SkyModel::sun_irradiance`]).
    sun_irradiance: Spectrum,
}

impl SkyModel {
    /// The sun's angular radius in radians: the model's 0.255° (see the module docs).
    pub const SUN_ANGULAR_RADIUS: f32 = (0.255 * core::f64::consts::PI / 180.0) as f32;

    /// The sky for `turbidity` in [1, 10], `ground_albedo` in [0, 1] and
    /// `sun_elevation` in radians in [0, π/2] (in `f32`, `FRAC_PI_2` itself is
    /// accepted). Out of range or NaN: an error that names the parameter
    /// (`turbidity`, `ground_albedo`, `sun_elevation`), the range and the value.
    pub fn new(turbidity: f32, ground_albedo: f32, sun_elevation: f32) -> Result<SkyModel, String> {
        if !(1.0..=10.0).contains(&turbidity) {
            return Err(format!("turbidity must be in [1, 10] (the model's range), got {turbidity}"));
        }
        if !(0.0..=1.0).contains(&ground_albedo) {
            return Err(format!("ground_albedo must be in [0, 1], got {ground_albedo}"));
        }
        if !(0.0..=FRAC_PI_2).contains(&sun_elevation) {
            return Err(format!(
                "sun_elevation must be in [0, 90] degrees (the sun above the horizon), got {} degrees",
                sun_elevation.to_degrees()
            ));
        }
        let (t, a) = (f64::from(turbidity), f64::from(ground_albedo));
        let x = (f64::from(sun_elevation) / core::f64::consts::FRAC_PI_2).cbrt().clamp(0.0, 1.0);
        let bernstein = bernstein5(x);
        // The (albedo, turbidity) corners and their weights: linear in both.
        let t_low = (t.floor() as usize).min(10); // 1..=10
        let t_frac = t - t_low as f64;
        let mut corners = vec![(0, t_low, (1.0 - a) * (1.0 - t_frac)), (1, t_low, a * (1.0 - t_frac))];
        if t_low < 10 {
            corners.push((0, t_low + 1, (1.0 - a) * t_frac));
            corners.push((1, t_low + 1, a * t_frac));
        }
        let mut params = [[0.0; 8]; N_CHANNELS];
        let mut mie = [[0.0; 2]; N_CHANNELS];
        let mut scale = [0.0; N_CHANNELS];
        for c in 0..N_CHANNELS {
            let mut p = [0.0f64; 9];
            let mut l = 0.0f64;
            for &(alb, turb, w) in &corners {
                let block = alb * 10 + (turb - 1);
                let sky = &data::SKY_PARAMS[c][block * 54..block * 54 + 54];
                let rad = &data::SKY_RADIANCE[c][block * 6..block * 6 + 6];
                for (k, b) in bernstein.iter().enumerate() {
                    for (j, pj) in p.iter_mut().enumerate() {
                        *pj += w * b * sky[9 * k + j];
                    }
                    l += w * b * rad[k];
                }
            }
            for j in 0..8 {
                params[c][j] = p[j] as f32;
            }
            let h = p[8];
            mie[c] = [((1.0 - h) * (1.0 - h)) as f32, (4.0 * h) as f32];
            scale[c] = l as f32;
        }
        // The solar data's turbidity index is 0-based; 10 is the top of 9..10.
        let (tl, tf) = if t >= 10.0 { (8, 1.0) } else { (t_low - 1, t_frac) };
        let solar = Box::new(core::array::from_fn(|c| {
            core::array::from_fn(|piece| {
                let at = |turb: usize, k: usize| data::SOLAR[c][SOLAR_ORDER * (SOLAR_PIECES * turb + piece) + k];
                core::array::from_fn(|k| ((1.0 - tf) * at(tl, k) + tf * at(tl + 1, k)) as f32)
            })
        }));
        let limb = core::array::from_fn(|i| {
            let (lo, w) = BIN_CHANNELS[i];
            let (w, c0, c1) = (f64::from(w), &data::LIMB_DARKENING[lo], &data::LIMB_DARKENING[lo + 1]);
            core::array::from_fn(|k| ((1.0 - w) * c0[k] + w * c1[k]) as f32)
        });
        let mut sky = SkyModel { params, mie, scale, solar, limb, sun_elevation, sun_irradiance: Spectrum::ZERO };
        sky.sun_irradiance = sky.integrate_sun();
        Ok(sky)
    }

    /// The sun's elevation in radians, as given to [`SkyModel::new`].
    pub fn sun_elevation(&self) -> f32 {
        self.sun_elevation
    }

    /// Sky radiance (W m⁻² sr⁻¹ nm⁻¹) at the 11 channels ([`CHANNEL_NM`])
    /// towards a direction at zenith angle `theta` (radians) and angle `gamma`
    /// to the sun's centre. Zero below the horizon (`theta > π/2`) and for NaN;
    /// never negative. Near the sun, `gamma` from `atan2(|d × s|, d · s)` (view
    /// and sun directions) keeps the precision that `acos(d · s)` loses in `f32`.
    pub fn channels(&self, theta: f32, gamma: f32) -> [f32; N_CHANNELS] {
        if theta.is_nan() || gamma.is_nan() || theta > FRAC_PI_2 {
            return [0.0; N_CHANNELS];
        }
        let cos_theta = theta.cos().max(0.0);
        let s = (0.5 * gamma).sin();
        let sin2_half = s * s;
        let cos_gamma = 1.0 - 2.0 * sin2_half;
        let cos2_gamma = cos_gamma * cos_gamma;
        let zenith = cos_theta.sqrt();
        let horizon = 1.0 / (cos_theta + 0.01);
        core::array::from_fn(|c| {
            let [a, b, cc, d, e, f, g, i] = self.params[c];
            let [h1, h4] = self.mie[c];
            let den = h1 + h4 * sin2_half;
            let chi = (1.0 + cos2_gamma) / (den * den.sqrt());
            let l =
                (1.0 + a * (b * horizon).exp()) * (cc + d * (e * gamma).exp() + f * cos2_gamma + g * chi + i * zenith);
            (l * self.scale[c]).max(0.0)
        })
    }

    /// [`SkyModel::channels`] at the renderer's 36 bins: linear in wavelength
    /// between the channel centres, the 720 nm value held at 730 nm.
    pub fn radiance(&self, theta: f32, gamma: f32) -> Spectrum {
        to_bins(&self.channels(theta, gamma))
    }

    /// The sun's direct radiance (W m⁻² sr⁻¹ nm⁻¹, limb-darkened) at the 36
    /// bins towards a direction at zenith angle `theta` and angle `gamma` from
    /// the sun's centre: zero outside the disk (`gamma >
    /// SUN_ANGULAR_RADIUS`) and below the horizon. The unlimbed radiance is
    /// that of the view direction's elevation `π/2 − theta` (see the module docs).
    pub fn sun_radiance(&self, theta: f32, gamma: f32) -> Spectrum {
        if theta.is_nan() || gamma.is_nan() || theta > FRAC_PI_2 || gamma > Self::SUN_ANGULAR_RADIUS {
            return Spectrum::ZERO;
        }
        let (piece, x) = solar_piece(theta);
        let direct: [f32; N_CHANNELS] = core::array::from_fn(|c| {
            let k = &self.solar[c][piece];
            ((k[0] * x + k[1]) * x + k[2]) * x + k[3]
        });
        let ratio = gamma.sin() / Self::SUN_ANGULAR_RADIUS.sin();
        let mu = (1.0 - ratio * ratio).max(0.0).sqrt();
        Spectrum::from_fn(|i| {
            let (lo, t) = BIN_CHANNELS[i];
            let l = (1.0 - t) * direct[lo] + t * direct[lo + 1];
            let c = &self.limb[i];
            let darkening = c[0] + mu * (c[1] + mu * (c[2] + mu * (c[3] + mu * (c[4] + mu * c[5]))));
            (l * darkening).max(0.0)
        })
    }

    /// The sun's spectral irradiance (W m⁻² nm⁻¹) at the 36 bins on a surface
    /// facing the sun, `∫ L_sun cos γ dω` over the disk, as computed by
    /// [`SkyModel::new`] (see the module docs): what a light standing in for
    /// the disk emits, or its weight among lights. The part of the disk below
    /// the horizon (a sun lower than [`SkyModel::SUN_ANGULAR_RADIUS`]) counts 0.
    pub fn sun_irradiance(&self) -> Spectrum {
        self.sun_irradiance
    }

    /// [`SkyModel::sun_irradiance`] by quadrature of
    /// [`SkyModel::sun_radiance`] over the disk: around the sun's direction,
    /// `sin γ = sin R sin α` (so the limb cosine is `cos α` and the integrand
    /// is smooth), `dω = tan γ sin R cos α dα dφ`, midpoint rule in `α` and `φ`.
    fn integrate_sun(&self) -> Spectrum {
        const N_ALPHA: usize = 128;
        const N_PHI: usize = 16;
        let r = f64::from(Self::SUN_ANGULAR_RADIUS);
        let theta_s = core::f64::consts::FRAC_PI_2 - f64::from(self.sun_elevation);
        let (d_alpha, d_phi) = (core::f64::consts::FRAC_PI_2 / N_ALPHA as f64, core::f64::consts::TAU / N_PHI as f64);
        let mut e = [0.0f64; N_BINS];
        for ia in 0..N_ALPHA {
            let alpha = (ia as f64 + 0.5) * d_alpha;
            let gamma = (r.sin() * alpha.sin()).asin();
            let weight = gamma.tan() * r.sin() * alpha.cos() * gamma.cos() * d_alpha * d_phi;
            for ip in 0..N_PHI {
                let phi = (ip as f64 + 0.5) * d_phi;
                let cos_theta = theta_s.cos() * gamma.cos() + theta_s.sin() * gamma.sin() * phi.cos();
                let l = self.sun_radiance(cos_theta.clamp(-1.0, 1.0).acos() as f32, gamma as f32);
                for (ei, li) in e.iter_mut().zip(l.0) {
                    *ei += f64::from(li) * weight;
                }
            }
        }
        Spectrum::from_fn(|i| e[i] as f32)
    }
}

/// Channel values to the renderer's bins (see [`BIN_CHANNELS`]).
fn to_bins(ch: &[f32; N_CHANNELS]) -> Spectrum {
    Spectrum::from_fn(|i| {
        let (lo, t) = BIN_CHANNELS[i];
        (1.0 - t) * ch[lo] + t * ch[lo + 1]
    })
}

/// The six quintic Bernstein polynomials at `x`.
fn bernstein5(x: f64) -> [f64; 6] {
    let y = 1.0 - x;
    [y.powi(5), 5.0 * y.powi(4) * x, 10.0 * y.powi(3) * x * x, 10.0 * y * y * x.powi(3), 5.0 * y * x.powi(4), x.powi(5)]
}

/// The solar function's elevation piece for a direction at zenith angle
/// `theta` (elevation `π/2 − theta`, clamped at 0): the pieces start at
/// elevations `(k/45)³ π/2`, `k = 0..45`; and the elevation above the piece's
/// start, the cubic's variable.
fn solar_piece(theta: f32) -> (usize, f32) {
    let elevation = (core::f64::consts::FRAC_PI_2 - f64::from(theta)).max(0.0);
    let u = (elevation / core::f64::consts::FRAC_PI_2).cbrt();
    let piece = ((u * SOLAR_PIECES as f64) as usize).min(SOLAR_PIECES - 1);
    let start = (piece as f64 / SOLAR_PIECES as f64).powi(3) * core::f64::consts::FRAC_PI_2;
    (piece, (elevation - start) as f32)
}
