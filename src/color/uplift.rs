//! RGB to spectrum: the smooth sigmoid uplift of Jakob and Hanika 2019 ("A Low-Dimensional
//! Function Space for Efficient Spectral Upsampling").
//!
//! A scene may give a colour as linear sRGB, `Rgb(0.8, 0.2, 0.1)`. The renderer needs a spectrum;
//! following Jakob and Hanika, it is the sigmoid of a quadratic,
//!
//! ```text
//! ρ(λ) = S(c0 t² + c1 t + c2),   S(x) = 1/2 + x / (2 √(1 + x²)),   t = (λ − 380 nm) / 350 nm,
//! ```
//!
//! which is smooth and always inside (0, 1), so a reflectance can never exceed 1 or go negative.
//! The three coefficients are fitted when the scene loads, by Levenberg-Marquardt on the three
//! equations "the exact colour integral ([`super::color_weights`]) of the 36-bin spectrum under
//! D65 gives back the linear sRGB colour", started from grey (`c = 0`, ρ = 1/2) and walked to the
//! target in a few steps (continuation), as the paper does when it builds its tables. Greys
//! (r = g = b) are not fitted: they are the constant spectrum of that value, so `Rgb(1, 1, 1)` is
//! exactly 1 everywhere (the failure of pbrt-v4 issue #54 cannot happen).
//!
//! As an emission (`emission: Rgb(4, 3, 2)`) the colour is split, like pbrt-v4's
//! `RGBIlluminantSpectrum`, into a scale `s = 2 · max(r, g, b)` and the uplifted reflectance of
//! `rgb / s` (at most 1/2, far from the sigmoid's asymptotes), times D65 normalised to Y = 1: an
//! emitter seen directly renders `(r, g, b)`.
//!
//! ```ron
//! "red": Lambertian(reflectance: Rgb(0.6, 0.05, 0.04)),
//! (shape: Disk(center: (0, 1.99, 0), normal: (0, -1, 0), radius: 0.3), emission: Rgb(12, 10, 8)),
//! ```

use super::cie::color_weights_f64;
use super::named::d65;
use super::rgb::xyz_to_linear_srgb_f64;
use super::spectrum::{N_BINS, Spectrum};

/// The sigmoid `S(x) = 1/2 + x / (2 √(1 + x²))`, in (0, 1) for every finite `x`.
fn sigmoid(x: f64) -> f64 {
    if x.is_infinite() {
        return if x > 0.0 { 1.0 } else { 0.0 };
    }
    0.5 + x / (2.0 * (1.0 + x * x).sqrt())
}

/// The spectrum of coefficients `c` at the 36 bin centres.
fn eval(c: [f64; 3]) -> [f64; N_BINS] {
    std::array::from_fn(|b| {
        let t = b as f64 / (N_BINS - 1) as f64;
        sigmoid((c[0] * t + c[1]) * t + c[2])
    })
}

/// D65 at the bins times the colour weights, divided by D65's Y: `Σ_b K_b ρ_b` is the XYZ of
/// reflectance `ρ` under D65 with the white at Y = 1.
fn d65_weights() -> [[f64; 3]; N_BINS] {
    let w = color_weights_f64();
    let d = d65();
    let y: f64 = (0..N_BINS).map(|b| w[b][1] * d[b] as f64).sum();
    std::array::from_fn(|b| w[b].map(|v| v * d[b] as f64 / y))
}

/// Linear sRGB of reflectance `rho` under D65 (white at Y = 1), through the exact colour integral.
pub fn reflectance_to_linear_srgb(rho: &[f64; N_BINS]) -> [f64; 3] {
    let k = d65_weights();
    let mut xyz = [0.0f64; 3];
    for (kb, &r) in k.iter().zip(rho) {
        for c in 0..3 {
            xyz[c] += kb[c] * r;
        }
    }
    xyz_to_linear_srgb_f64(xyz)
}

/// Solves the 3x3 system `a x = b` by Gaussian elimination with partial pivoting; `None` if
/// singular.
fn solve3(mut a: [[f64; 3]; 3], mut b: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let p = (col..3).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[p][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, p);
        b.swap(col, p);
        for row in col + 1..3 {
            let f = a[row][col] / a[col][col];
            let pivot = a[col];
            for (x, p) in a[row][col..].iter_mut().zip(&pivot[col..]) {
                *x -= f * p;
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 3];
    for row in (0..3).rev() {
        let s: f64 = (row + 1..3).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// The largest coefficient magnitude the fit may reach: beyond it the sigmoid is within 1e-9
/// of 0 or 1 over whole stretches, and the colour no longer changes.
const MAX_COEFF: f64 = 1e4;

/// Levenberg-Marquardt steps from `c` towards the coefficients whose colour is `target`.
fn refine(mut c: [f64; 3], target: [f64; 3], iterations: usize) -> [f64; 3] {
    let k = d65_weights();
    let residual = |c: [f64; 3]| {
        let rho = eval(c);
        let mut xyz = [0.0f64; 3];
        for (kb, &r) in k.iter().zip(&rho) {
            for i in 0..3 {
                xyz[i] += kb[i] * r;
            }
        }
        let rgb = xyz_to_linear_srgb_f64(xyz);
        [rgb[0] - target[0], rgb[1] - target[1], rgb[2] - target[2]]
    };
    let norm2 = |r: [f64; 3]| r.iter().map(|v| v * v).sum::<f64>();
    let mut r = residual(c);
    let mut mu = 1e-3;
    for _ in 0..iterations {
        if norm2(r) < 1e-20 {
            break;
        }
        // Jacobian by central differences.
        let mut j = [[0.0f64; 3]; 3];
        for p in 0..3 {
            let h = 1e-6 * (1.0 + c[p].abs());
            let (mut cp, mut cm) = (c, c);
            cp[p] += h;
            cm[p] -= h;
            let (rp, rm) = (residual(cp), residual(cm));
            for i in 0..3 {
                j[i][p] = (rp[i] - rm[i]) / (2.0 * h);
            }
        }
        // Normal equations (JᵀJ + μ diag(JᵀJ)) δ = −Jᵀr.
        let mut jtj = [[0.0f64; 3]; 3];
        let mut jtr = [0.0f64; 3];
        for p in 0..3 {
            for q in 0..3 {
                jtj[p][q] = (0..3).map(|i| j[i][p] * j[i][q]).sum();
            }
            jtr[p] = -(0..3).map(|i| j[i][p] * r[i]).sum::<f64>();
        }
        let mut improved = false;
        for _ in 0..8 {
            let mut a = jtj;
            for p in 0..3 {
                a[p][p] += mu * jtj[p][p].max(1e-12);
            }
            let Some(d) = solve3(a, jtr) else {
                mu *= 10.0;
                continue;
            };
            let next = std::array::from_fn(|p| (c[p] + d[p]).clamp(-MAX_COEFF, MAX_COEFF));
            let rn = residual(next);
            if norm2(rn) < norm2(r) {
                (c, r) = (next, rn);
                mu = (mu / 3.0).max(1e-12);
                improved = true;
                break;
            }
            mu *= 4.0;
        }
        if !improved {
            break;
        }
    }
    c
}

/// The sigmoid coefficients whose reflectance under D65 has linear sRGB colour `rgb` (each
/// component in [0, 1]), or the nearest the model reaches. Greys give `[0, 0, x]` with
/// `S(x)` equal to the grey.
pub fn fit_coefficients(rgb: [f64; 3]) -> [f64; 3] {
    // Continuation: from mid grey, the target in 8 steps, a few iterations each, then polish.
    let start = [0.5; 3];
    let mut c = [0.0; 3];
    const STEPS: usize = 8;
    for s in 1..=STEPS {
        let f = s as f64 / STEPS as f64;
        let t = std::array::from_fn(|i| start[i] + (rgb[i] - start[i]) * f);
        c = refine(c, t, if s == STEPS { 60 } else { 15 });
    }
    c
}

/// The reflectance spectrum of linear sRGB `rgb` under D65 (components in [0, 1]; out-of-range
/// values are clamped): exactly `r` everywhere for a grey, else the fitted sigmoid, in [0, 1].
pub fn rgb_reflectance(rgb: [f32; 3]) -> Spectrum {
    Uplift::reflectance(rgb, None).spectrum()
}

/// A colour uplifted but not yet evaluated: what a texel keeps (a grey, or the sigmoid's three
/// coefficients: 24 bytes instead of a 144-byte spectrum). [`Uplift::spectrum`] gives exactly
/// what [`rgb_reflectance`] gives for the same colour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Uplift {
    /// The constant spectrum of this value.
    Grey(f32),
    /// The sigmoid of a quadratic with these coefficients.
    Sigmoid([f64; 3]),
}

impl Uplift {
    /// The reflectance of linear sRGB `rgb` (clamped into [0, 1]). With `near`, the
    /// coefficients of a similar colour (the previous texel of an image row), the fit starts
    /// there and takes a few Levenberg-Marquardt steps; only if they leave a colour error
    /// above 1e-6 does it fall back to the full fit from grey. Equal colours give equal
    /// coefficients either way when the caller reuses them (see `crate::texture`).
    pub fn reflectance(rgb: [f32; 3], near: Option<[f64; 3]>) -> Uplift {
        let [r, g, b] = rgb.map(|v| if v.is_finite() { v.clamp(0.0, 1.0) } else { 0.0 });
        if r == g && g == b {
            return Uplift::Grey(r);
        }
        let target = [r as f64, g as f64, b as f64];
        if let Some(start) = near {
            let c = refine(start, target, 12);
            if colour_error2(c, target) < 1e-12 {
                return Uplift::Sigmoid(c);
            }
        }
        Uplift::Sigmoid(fit_coefficients(target))
    }

    /// The coefficients, for warm-starting the next fit (grey: the sigmoid's constant).
    pub fn coefficients(&self) -> [f64; 3] {
        match *self {
            Uplift::Grey(v) => {
                // S(x) = v  ⇔  x = (2v − 1) / (2 √(v (1 − v))), finite inside (0, 1).
                let v = (v as f64).clamp(1e-6, 1.0 - 1e-6);
                [0.0, 0.0, (2.0 * v - 1.0) / (2.0 * (v * (1.0 - v)).sqrt())]
            }
            Uplift::Sigmoid(c) => c,
        }
    }

    /// The reflectance spectrum at the 36 bins, in [0, 1].
    #[inline]
    pub fn spectrum(&self) -> Spectrum {
        match *self {
            Uplift::Grey(v) => Spectrum::splat(v),
            Uplift::Sigmoid(c) => {
                let rho = eval(c);
                Spectrum::from_fn(|i| rho[i].clamp(0.0, 1.0) as f32)
            }
        }
    }
}

/// Uplifts an image of rows of `width` linear sRGB texels, each times `scale`,
/// with `fit` (a colour and, where there is one, the previous texel's
/// coefficients to start from: see [`Uplift::reflectance`]). Rows are fitted
/// in parallel; along a row a texel of the same colour as the previous reuses
/// its result, so an image of one colour gives every texel exactly what
/// `fit` gives that colour alone. `coefficients` gives a result's coefficients.
pub fn fit_rows<T: Copy + Send>(
    width: usize,
    rgb: &[[f32; 3]],
    scale: f32,
    fit: impl Fn([f32; 3], Option<[f64; 3]>) -> T + Sync,
    coefficients: impl Fn(&T) -> [f64; 3] + Sync,
) -> Vec<T> {
    use rayon::prelude::*;
    let rows: Vec<Vec<T>> = rgb
        .par_chunks(width)
        .map(|row| {
            let mut out = Vec::with_capacity(width);
            let mut prev: Option<([f32; 3], T)> = None;
            for &p in row {
                let c = p.map(|v| v * scale);
                let texel = match prev {
                    Some((pc, t)) if pc == c => t,
                    _ => fit(c, prev.map(|(_, t)| coefficients(&t))),
                };
                prev = Some((c, texel));
                out.push(texel);
            }
            out
        })
        .collect();
    rows.concat()
}

/// The squared colour error of coefficients `c` against `target`.
fn colour_error2(c: [f64; 3], target: [f64; 3]) -> f64 {
    let rgb = reflectance_to_linear_srgb(&eval(c));
    (0..3).map(|i| (rgb[i] - target[i]).powi(2)).sum()
}

/// An emission colour as a texel keeps it: [`rgb_emission`] is `scale · uplift · D65` with
/// these two (the scale folds in `1 / Y(D65)`); black is a zero scale.
pub fn emission_uplift(rgb: [f32; 3], near: Option<[f64; 3]>) -> (Uplift, f32) {
    let rgb = rgb.map(|v| if v.is_finite() { v.max(0.0) } else { 0.0 });
    let m = rgb[0].max(rgb[1]).max(rgb[2]);
    if m == 0.0 {
        return (Uplift::Grey(0.0), 0.0);
    }
    let s = 2.0 * m;
    (Uplift::reflectance(rgb.map(|v| v / s), near), s / d65().to_xyz().y)
}

/// The emission spectrum of a texel from [`emission_uplift`]: bit for bit what
/// [`rgb_emission`] gives for the same colour.
#[inline]
pub fn emission_spectrum(uplift: &Uplift, scale: f32, d65: &Spectrum) -> Spectrum {
    if scale == 0.0 {
        return Spectrum::ZERO;
    }
    uplift.spectrum() * *d65 * scale
}

/// The emission spectrum of linear sRGB `rgb` (non-negative components; negative or non-finite
/// ones count as 0): `s · ρ(rgb / s) · D65 / Y(D65)` with `s = 2 · max(r, g, b)`, so that the
/// emitter seen directly renders `(r, g, b)`.
pub fn rgb_emission(rgb: [f32; 3]) -> Spectrum {
    let rgb = rgb.map(|v| if v.is_finite() { v.max(0.0) } else { 0.0 });
    let m = rgb[0].max(rgb[1]).max(rgb[2]);
    if m == 0.0 {
        return Spectrum::ZERO;
    }
    let (uplift, scale) = emission_uplift(rgb, None);
    emission_spectrum(&uplift, scale, &d65())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::Xyz;

    /// Linear sRGB of a 36-bin radiance through the renderer's own read-out (f32).
    fn seen(l: &Spectrum) -> [f32; 3] {
        let x: Xyz = l.to_xyz();
        let c = x.to_linear_srgb();
        [c.r, c.g, c.b]
    }

    /// The round trip (uplift, then the exact integral under D65) gives the colour back within
    /// 2e-3 per channel over a 6x6x6 grid of the sRGB cube, faces and corners included (measured
    /// worst: about 6e-5); the reflectance stays in [0, 1].
    #[test]
    fn reflectance_round_trip_over_the_gamut() {
        let grid = [0.0f32, 0.2, 0.4, 0.6, 0.8, 1.0];
        let white = d65();
        let mut worst = 0.0f32;
        for &r in &grid {
            for &g in &grid {
                for &b in &grid {
                    let s = rgb_reflectance([r, g, b]);
                    assert!(s.min_value() >= 0.0 && s.max_value() <= 1.0);
                    let got = seen(&(s * white * (1.0 / white.to_xyz().y)));
                    for (gv, want) in got.into_iter().zip([r, g, b]) {
                        worst = worst.max((gv - want).abs());
                    }
                }
            }
        }
        eprintln!("worst: {worst}");
        assert!(worst < 2e-3, "worst {worst}");
    }

    #[test]
    fn greys_are_constant_and_white_is_exactly_one() {
        assert_eq!(rgb_reflectance([1.0, 1.0, 1.0]), Spectrum::ONE);
        assert_eq!(rgb_reflectance([0.0, 0.0, 0.0]), Spectrum::ZERO);
        assert_eq!(rgb_reflectance([0.3, 0.3, 0.3]), Spectrum::splat(0.3));
        // Out-of-range input is clamped, never NaN.
        assert_eq!(rgb_reflectance([2.0, f32::NAN, -1.0]), rgb_reflectance([1.0, 0.0, 0.0]));
    }

    /// An emitter's spectrum seen directly renders its (r, g, b) within 2e-3 relative to the
    /// brightest channel, for dim, bright, saturated and grey colours.
    #[test]
    fn emission_renders_its_rgb() {
        for rgb in [[1.0f32, 1.0, 1.0], [12.0, 10.0, 8.0], [0.2, 0.5, 0.9], [5.0, 0.1, 0.0], [0.0, 0.0, 3.0]] {
            let l = rgb_emission(rgb);
            assert!(l.min_value() >= 0.0 && !l.has_nan_or_inf());
            let got = seen(&l);
            let m = rgb[0].max(rgb[1]).max(rgb[2]);
            for (g, w) in got.into_iter().zip(rgb) {
                assert!((g - w).abs() < 2e-3 * m, "{rgb:?}: {got:?}");
            }
        }
        assert_eq!(rgb_emission([0.0, -1.0, f32::NAN]), Spectrum::ZERO);
    }

    #[test]
    fn solve3_inverts() {
        let a = [[2.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 4.0]];
        let x = solve3(a, [3.0, 5.0, 5.0]).unwrap();
        for (got, want) in x.iter().zip([1.0, 1.0, 1.0]) {
            assert!((got - want).abs() < 1e-12);
        }
        assert!(solve3([[0.0; 3]; 3], [1.0; 3]).is_none());
    }
}
