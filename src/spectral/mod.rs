//! Wavelength packets: which wavelengths a path carries, and the values it
//! carries for them.
//!
//! Every integrator runs one generic path loop over a packet of `N`
//! wavelengths ([`Lambdas<N>`]) whose per-wavelength values are a
//! [`Sampled<N>`] ([`crate::color::spectrum`], one arithmetic for every `N`):
//!
//! - `N = 36`, the identity packet: the full spectrum, every bin on every path
//!   (the thesis's "path" tracer, and `auto` where nothing disperses);
//! - `N = 4` (or 8): a hero packet (one bin uniform over the 36, the others at
//!   equal rotation, thesis eq. 2.7) or independent random bins;
//! - `N = 1`: one wavelength, after a packet split at a dispersive surface;
//! - `N = 3`, the RGB mode: the three wavelengths 435.8, 546.1 and 700 nm of
//!   the thesis's RGB renderer (Figure 5.8c), whose values are read as linear
//!   sRGB blue, green and red.
//!
//! A packet stores fractional bin positions (`0.0` = 380 nm, `35.0` = 730 nm):
//! spectra are sampled at integer positions exactly and linearly interpolated
//! between bins (only the RGB mode uses non-integer positions).
//!
//! # Unbiasedness
//! The pixel value is `XYZ = Σ_b L(b) · W_b` over the 36 bins, the exact colour
//! integral of the interpolated spectrum ([`color::color_weights`]). A packet that
//! includes bin `b` with probability `P(b)` contributes `L(b) · W_b / P(b)` for each of its bins, so every
//! bin's expected contribution is exactly its share of the sum, at any sample
//! count. Hero and random packets of `C` bins have `P(b) = C / 36` (hero: the
//! rotation puts each bin in the packet for exactly `C` of the 36 hero
//! choices; random: each of the `C` independent draws hits `b` with
//! probability 1/36, counted with multiplicity). Those weights live in
//! [`Lambdas::weight`], never in per-bin sample counters.
//!
//! `auto` draws bins where a full-spectrum path refracts at dispersive glass,
//! not uniformly but in proportion to the path's throughput times the bin's
//! visual importance ([`bin_importance`], [`BinDistribution`]), `C` of them
//! by stratified rotation ([`for_each_rotated`]); each carries the weight
//! `1 / (C · p(bin))`, which keeps every bin unbiased in the same way.
//!
//! # Continuous wavelengths
//! Where a path follows single wavelengths after a dispersive split or
//! collapse, 36 wavelengths would make a rainbow 36 separate images. There the
//! wavelength is continuous over 360-830 nm ([`Readout::Continuous`]): the
//! index of refraction is evaluated at λ exactly (Sellmeier, Cauchy, ...), and
//! every spectrum the path meets is linearly interpolated at λ (flat beyond
//! 380 and 730 nm: [`Lambdas::sample`] at a fractional position). A value `L`
//! at λ adds `L · cmf(λ) · weight` to the pixel, with `cmf` the 1 nm CIE table
//! linearly interpolated and divided by `∫ ȳ` ([`color::cmf_at`], the same
//! function and normalisation as the weights `W_b`), and `weight = 1 / (C · p(λ))`
//! for `C` draws of density `p` per nm.
//!
//! *The collapse draw* ([`continuous_wavelength`], any integrator may call it):
//! bin `b` is chosen with probability `P_b` in proportion to throughput ×
//! visual importance, as above; then λ is placed within bin `b`'s
//! interpolation tent `φ_b` with density `φ_b(λ) / A_b`, `A_b = ∫ φ_b` (10 nm;
//! 25 and 105 nm for the end bins, whose tents run flat to 360 and 830 nm).
//! The density of λ is the mixture
//!
//! ```text
//! p(λ) = Σ_b P_b · φ_b(λ) / A_b
//! ```
//!
//! (between 380 and 730 nm, the linear interpolation of `P_b / 10`: in
//! proportion to the interpolated throughput × importance). For any function
//! `f`, `E[f(λ) / p(λ)] = ∫_{p > 0} f(λ) dλ`. `p(λ) = 0` only where every bin
//! whose tent covers λ has `P_b = 0`, i.e. throughput 0 (the importance is
//! positive everywhere); there the interpolated throughput `β(λ) = Σ_b β_b φ_b(λ)`
//! is 0 and so is the path's radiance. Hence with `f = cmf · L`,
//! `E[L(λ) · cmf(λ) / p(λ)] = ∫ cmf(λ) · L(λ) dλ` over 360-830 nm exactly, and
//! each of `C` rotated draws (each of marginal density `p`) with weight
//! `1 / (C · p(λ))` keeps the sum unbiased, as for bins.
//!
//! *The `spectral` integrator's packets* ([`sample_packet_continuous`]): in a
//! scene with dispersive glass (and with `--wavelengths continuous`, in any
//! scene) each of the `C` wavelengths is uniform over 360-830 nm, hero (equal
//! rotation of the range) or independent: density `1/470` per nm each, weight
//! `470 / C`, so `E[Σ_k L(λ_k) · cmf(λ_k) · 470 / C] = ∫ cmf · L`. They are
//! continuous from the camera on, because a packet of `C` bins knows its
//! throughput only at those bins: jittering a wavelength at the split would
//! need the throughput between bins, which the packet never had.
//!
//! *What `L` is.* Before a collapse a full-spectrum path carries 36 bins, and
//! between bins its throughput is their linear interpolation (the convention
//! the weights `W_b` give a full-spectrum path); after it, every factor is its
//! own value at λ. So the continuous and the full-spectrum estimates of the
//! same light differ only in interpolating a product of spectra or
//! multiplying interpolated spectra, which is second order in the 10 nm bin
//! spacing (a fraction of a percent in saturated colours; docs/integrators.md's colour
//! section measures it on the Cornell box).
//!
//! *Spectral output* (`--spectral`) keeps the bin centres and the discrete
//! draws above ([`Contribution::CONTINUOUS`] is false for it), so that the 36
//! channels weighted by `W_b` reproduce the colour film exactly.

use crate::color::{self, N_BINS, Sampled, Sensor, Spectrum, Xyz};

mod continuous;

// The single-wavelength draw for a collapse, for every integrator that follows one wavelength
// (path's collapse uses it through the rotated form).
#[allow(unused_imports)]
pub use continuous::continuous_wavelength;
pub use continuous::{for_each_rotated_continuous, sample_packet_continuous, tent_area};

/// The wavelengths of the RGB mode (thesis §5.2): blue, green, red in nm.
pub const RGB_LAMBDAS_NM: [f32; 3] = [435.8, 546.1, 700.0];

/// The reference wavelength that every wavelength follows at a dispersive
/// interface in the non-spectral `path` integrator: the sodium D line.
pub const REFERENCE_LAMBDA_NM: f32 = 589.3;

/// How a packet's values become a colour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Readout {
    /// Values are spectral radiance at the packet's bins: XYZ through the colour weights.
    Spectral,
    /// Values are linear sRGB (blue, green, red), the RGB mode.
    Rgb,
    /// Values are spectral radiance at continuous wavelengths (fractional
    /// positions anywhere in 360-830 nm): each value's colour is
    /// `L · cmf(λ) · weight` ([`color::cmf_at`]), the weight holding
    /// `1 / (C · p(λ))` for the draw's density `p` per nm. See the module doc.
    Continuous,
}

/// A packet of `N` wavelengths, as fractional bin positions, with the
/// weight `1 / P(bin in packet)` that keeps every bin's estimate unbiased.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lambdas<const N: usize> {
    /// Fractional bin positions: `0.0` is 380 nm, `35.0` is 730 nm.
    pub pos: [f32; N],
    /// The weight of each wavelength's contribution (`36 / C` for a packet
    /// of `C` bins drawn as hero or random; 1 for the full spectrum;
    /// `1 / (C · p(bin))` for a wavelength `auto` drew by importance).
    pub weight: f32,
    /// How values become colour.
    pub readout: Readout,
}

impl<const N: usize> Lambdas<N> {
    /// Wavelength `i` in nm.
    #[inline]
    pub fn lambda_nm(&self, i: usize) -> f32 {
        color::LAMBDA_MIN_NM + color::LAMBDA_STEP_NM * self.pos[i]
    }

    /// A spectrum's values at the packet's wavelengths.
    #[inline]
    pub fn sample(&self, s: &Spectrum) -> Sampled<N> {
        if N == N_BINS && self.readout == Readout::Spectral {
            // The identity packet: a straight copy (positions are 0..36).
            let mut out = [0.0; N];
            out.copy_from_slice(&s.0[..N]);
            return Sampled(out);
        }
        let mut out = [0.0; N];
        for (o, &p) in out.iter_mut().zip(&self.pos) {
            let i0 = (p as usize).min(N_BINS - 1);
            let frac = p - i0 as f32;
            *o = if frac <= 0.0 || i0 + 1 >= N_BINS { s.0[i0] } else { s.0[i0] * (1.0 - frac) + s.0[i0 + 1] * frac };
        }
        Sampled(out)
    }

    /// The single-wavelength packet of wavelength `i`, carrying this packet's weight.
    #[inline]
    pub fn single(&self, i: usize) -> Lambdas<1> {
        Lambdas { pos: [self.pos[i]], weight: self.weight, readout: self.readout }
    }

    /// The colour of a packet of radiance values through the default sensor (CIE XYZ).
    pub fn xyz(&self, l: &Sampled<N>) -> Xyz {
        self.project(Sensor::cie1931(), l)
    }

    /// The film's three channels for a packet of radiance values: its projection on the
    /// sensor's curves ([`Sensor`]; XYZ for the default, `cie1931`). The curves are data, so
    /// every sensor runs the same code.
    pub fn project(&self, sensor: &Sensor, l: &Sampled<N>) -> Xyz {
        match self.readout {
            Readout::Spectral if N == N_BINS => {
                // The identity packet (the full spectrum): bin i is value i, no
                // index conversion (this runs once per camera sample).
                let (mut x, mut y, mut z) = (0.0f32, 0.0f32, 0.0f32);
                for (v, w) in l.0.iter().zip(sensor.weights()) {
                    x += v * w[0];
                    y += v * w[1];
                    z += v * w[2];
                }
                Xyz::new(x * self.weight, y * self.weight, z * self.weight)
            }
            Readout::Spectral => {
                let (mut x, mut y, mut z) = (0.0f32, 0.0f32, 0.0f32);
                for i in 0..N {
                    // Packets of sampled bins always sit on integer positions.
                    let w = sensor.weights()[self.pos[i] as usize];
                    x += l.0[i] * w[0];
                    y += l.0[i] * w[1];
                    z += l.0[i] * w[2];
                }
                Xyz::new(x * self.weight, y * self.weight, z * self.weight)
            }
            Readout::Continuous => {
                let (mut x, mut y, mut z) = (0.0f32, 0.0f32, 0.0f32);
                for i in 0..N {
                    let c = sensor.at(self.lambda_nm(i));
                    x += l.0[i] * c[0];
                    y += l.0[i] * c[1];
                    z += l.0[i] * c[2];
                }
                Xyz::new(x * self.weight, y * self.weight, z * self.weight)
            }
            Readout::Rgb => {
                // Values are (b, g, r) in wavelength order; a single wavelength
                // after a split is one channel carrying the packet weight 3.
                let mut rgb = [0.0f32; 3];
                for i in 0..N {
                    let channel = rgb_channel(self.lambda_nm(i));
                    rgb[channel] += l.0[i] * self.weight / 3.0;
                }
                match sensor.from_srgb() {
                    None => color::LinearSrgb::new(rgb[0], rgb[1], rgb[2]).to_xyz(),
                    // The RGB mode has no spectrum for a sensor to see: its linear sRGB goes to
                    // the camera RGB that the colour correction takes back to it.
                    Some(m) => {
                        let c: [f32; 3] =
                            std::array::from_fn(|k| m[k][0] * rgb[0] + m[k][1] * rgb[1] + m[k][2] * rgb[2]);
                        Xyz::new(c[0], c[1], c[2])
                    }
                }
            }
        }
    }
}

impl<const N: usize> Lambdas<N> {
    /// The per-bin radiance estimate of a packet of radiance values: each wavelength's value
    /// times the packet weight, in its bin (bins outside the packet are 0), so that
    /// `bins(l).to_xyz() == xyz(l)` up to rounding. The spectral film sums these. The RGB mode
    /// has no bins: it gives zero (the command line refuses `--spectral` with it).
    ///
    /// A continuous packet ([`Readout::Continuous`]) is never summed by the renderer (spectral
    /// output keeps the bin centres, [`Contribution::CONTINUOUS`]); here it gives each bin `b`
    /// the tent average `L(λ) · weight · φ_b(λ) / A_b`, an unbiased estimate of
    /// `∫ φ_b · L / ∫ φ_b`, whose colour is the exact one only up to second order in 10 nm.
    pub fn bins(&self, l: &Sampled<N>) -> Spectrum {
        let mut out = Spectrum::ZERO;
        match self.readout {
            Readout::Spectral => {
                for i in 0..N {
                    // Packets of sampled bins always sit on integer positions.
                    out.0[(self.pos[i] as usize).min(N_BINS - 1)] += l.0[i] * self.weight;
                }
            }
            Readout::Continuous => {
                for i in 0..N {
                    let nm = self.lambda_nm(i);
                    let b0 = (self.pos[i].max(0.0) as usize).min(N_BINS - 1);
                    for b in b0..(b0 + 2).min(N_BINS) {
                        let t = color::tent(b, nm as f64) as f32;
                        out.0[b] += l.0[i] * self.weight * t / tent_area(b);
                    }
                }
            }
            Readout::Rgb => {}
        }
        out
    }
}

/// What an integrator returns for one camera sample: its colour ([`Xyz`]) or, for spectral
/// output, its per-bin radiance estimate ([`Spectrum`], whose colour integral is that colour).
/// The integrators are generic over it, so the colour-only path pays nothing for spectral
/// output.
pub(crate) trait Contribution: Copy + Default + core::ops::AddAssign + Send + Sync + 'static {
    /// Whether single-wavelength paths may carry continuous wavelengths
    /// ([`Readout::Continuous`]): true for colour; false for spectral output, whose bins must
    /// reproduce the colour exactly, so those paths stay at the bin centres.
    const CONTINUOUS: bool;

    /// The contribution of a packet's radiance values, projected on `sensor`'s curves where it
    /// is a colour.
    fn from_packet<const N: usize>(sensor: &Sensor, lambdas: &Lambdas<N>, l: &Sampled<N>) -> Self;
}

impl Contribution for Xyz {
    const CONTINUOUS: bool = true;

    #[inline]
    fn from_packet<const N: usize>(sensor: &Sensor, lambdas: &Lambdas<N>, l: &Sampled<N>) -> Self {
        lambdas.project(sensor, l)
    }
}

impl Contribution for Spectrum {
    const CONTINUOUS: bool = false;

    #[inline]
    fn from_packet<const N: usize>(_: &Sensor, lambdas: &Lambdas<N>, l: &Sampled<N>) -> Self {
        lambdas.bins(l)
    }
}

/// Which linear sRGB channel (0 = r, 1 = g, 2 = b) an RGB-mode wavelength feeds.
fn rgb_channel(lambda_nm: f32) -> usize {
    if lambda_nm < 500.0 {
        2
    } else if lambda_nm < 650.0 {
        1
    } else {
        0
    }
}

impl Lambdas<N_BINS> {
    /// The full spectrum: all 36 bins, weight 1.
    pub fn full() -> Self {
        Lambdas { pos: std::array::from_fn(|i| i as f32), weight: 1.0, readout: Readout::Spectral }
    }
}

impl Lambdas<3> {
    /// The RGB mode's three wavelengths (thesis §5.2), each carrying weight 3
    /// so that a packet split into single wavelengths reads out the same.
    pub fn rgb() -> Self {
        let pos = RGB_LAMBDAS_NM.map(|l| (l - color::LAMBDA_MIN_NM) / color::LAMBDA_STEP_NM);
        Lambdas { pos, weight: 3.0, readout: Readout::Rgb }
    }
}

/// How a packet of `C` bins is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WavelengthSampling {
    /// One bin uniform over the 36, the others at equal rotation (thesis eq. 2.7).
    Hero,
    /// `C` independent uniform bins.
    Random,
}

/// Bin `k` of the hero packet of `c` bins whose hero is bin `hero` (thesis
/// eq. 2.7 on the bin grid): `(hero + k·36/c) mod 36`, rounded down.
#[inline]
pub fn hero_bin(hero: usize, k: usize, c: usize) -> usize {
    (hero + k * N_BINS / c) % N_BINS
}

/// Draws a packet of `C` bins. `u` supplies `C` uniform numbers in [0, 1)
/// (hero uses only the first).
pub fn sample_packet<const C: usize>(how: WavelengthSampling, u: [f32; C]) -> Lambdas<C> {
    let bin = |x: f32| ((x * N_BINS as f32) as usize).min(N_BINS - 1);
    let pos = match how {
        WavelengthSampling::Hero => {
            let h = bin(u[0]);
            std::array::from_fn(|k| hero_bin(h, k, C) as f32)
        }
        WavelengthSampling::Random => u.map(|x| bin(x) as f32),
    };
    Lambdas { pos, weight: N_BINS as f32 / C as f32, readout: Readout::Spectral }
}

/// The visual importance of each bin: the Euclidean norm of the linear sRGB
/// colour that one unit of radiance in the bin adds to a pixel
/// (`|M · W_b|`, the exact colour weights, with [`color::XYZ_TO_LINEAR_SRGB`] as `M`). A sample's
/// squared error summed over the three channels scales with it, so `auto`
/// draws its packets in proportion to it (times the path's throughput) where
/// a path meets dispersion.
pub fn bin_importance() -> &'static [f32; N_BINS] {
    static TABLE: std::sync::LazyLock<[f32; N_BINS]> = std::sync::LazyLock::new(|| {
        std::array::from_fn(|b| {
            let rgb = color::bin_xyz(b).to_linear_srgb();
            (rgb.r * rgb.r + rgb.g * rgb.g + rgb.b * rgb.b).sqrt()
        })
    });
    &TABLE
}

/// A discrete distribution over the 36 bins in proportion to non-negative
/// weights: its cumulative sums, for inversion.
#[derive(Clone, Copy, Debug)]
pub struct BinDistribution {
    cdf: [f32; N_BINS],
    total: f32,
}

impl BinDistribution {
    /// The distribution in proportion to `weight(b)`; `None` when every weight
    /// is zero (or any is negative or not finite): nothing to sample.
    #[inline]
    pub fn new(weight: impl Fn(usize) -> f32) -> Option<Self> {
        let mut cdf = [0.0; N_BINS];
        let mut total = 0.0f32;
        for (b, c) in cdf.iter_mut().enumerate() {
            let w = weight(b);
            if !(w >= 0.0 && w.is_finite()) {
                return None;
            }
            total += w;
            *c = total;
        }
        (total > 0.0 && total.is_finite()).then_some(BinDistribution { cdf, total })
    }

    /// The bin whose share of the cumulative sum holds `u` in [0, 1), and its
    /// probability. Bins of zero weight are never returned.
    #[inline]
    pub fn sample(&self, u: f32) -> (usize, f32) {
        let bin = self.find(u * self.total);
        (bin, self.prob(bin))
    }

    /// The bin [`Self::sample`] returns for `u`, and where `u` falls within
    /// that bin's share, in [0, 1]: uniform again when `u` is, so one number
    /// both picks a bin and places a wavelength in it.
    #[inline]
    pub fn sample_with_remainder(&self, u: f32) -> (usize, f32) {
        let x = u * self.total;
        let bin = self.find(x);
        let below = if bin == 0 { 0.0 } else { self.cdf[bin - 1] };
        let share = self.cdf[bin] - below;
        (bin, ((x - below) / share).clamp(0.0, 1.0))
    }

    /// The probability of bin `b` (0 for a bin of zero weight).
    #[inline]
    pub fn prob(&self, b: usize) -> f32 {
        let below = if b == 0 { 0.0 } else { self.cdf[b - 1] };
        (self.cdf[b] - below) / self.total
    }

    /// The bin whose share of the cumulative sum holds `x` in [0, total).
    #[inline]
    fn find(&self, x: f32) -> usize {
        match self.cdf.iter().position(|&c| x < c) {
            Some(b) => b,
            // `u · total` rounded up to `total`: the last bin of positive weight.
            None => self.cdf.iter().rposition(|&c| c < self.total).map_or(0, |b| b + 1),
        }
    }
}

/// Draws a packet of `c` bins from `d` by stratified rotation, the hero
/// construction in the distribution's own measure: bin `k` inverts
/// `(u + k / c) mod 1`. Each of the `c` draws is a bin `b` with probability
/// `p(b)`, so the packet's estimate `Σ_k f(b_k) / (c · p(b_k))` is unbiased for
/// `Σ_b f(b)`; a bin of probability above `1/c` may appear more than once.
/// Calls `visit(bin, 1 / (c · p(bin)))` for each draw.
#[inline]
pub fn for_each_rotated(d: &BinDistribution, c: usize, u: f32, mut visit: impl FnMut(usize, f32)) {
    for k in 0..c {
        let (bin, p) = d.sample((u + k as f32 / c as f32).fract());
        visit(bin, 1.0 / (c as f32 * p));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every bin is in exactly C of the 36 hero packets, so P(b) = C/36 and
    /// the weight 36/C is exact, for C = 4 (36/4 = 9 apart) and C = 8 (4.5
    /// apart: rounded down, still a bijection per k).
    #[test]
    fn hero_packets_cover_every_bin_equally() {
        fn check<const C: usize>() {
            let mut count = [0usize; N_BINS];
            for h in 0..N_BINS {
                let u0 = (h as f32 + 0.5) / N_BINS as f32;
                let mut u = [0.0; C];
                u[0] = u0;
                let l = sample_packet::<C>(WavelengthSampling::Hero, u);
                assert_eq!(l.pos[0], h as f32);
                for p in l.pos {
                    count[p as usize] += 1;
                }
            }
            assert!(count.iter().all(|&c| c == C), "C = {C}: {count:?}");
        }
        check::<4>();
        check::<8>();
        check::<1>();
    }

    #[test]
    fn full_packet_reads_out_the_spectrum_xyz() {
        let s = Spectrum::from_fn(|i| 0.1 + 0.02 * i as f32);
        let l = Lambdas::full();
        let a = l.xyz(&l.sample(&s));
        let b = s.to_xyz();
        assert!((a.x - b.x).abs() < 1e-5 && (a.y - b.y).abs() < 1e-5 && (a.z - b.z).abs() < 1e-5);
    }

    /// Averaging the readout over all 36 hero choices gives the full-spectrum
    /// XYZ exactly: the packet estimator is unbiased by construction.
    #[test]
    fn hero_readout_is_unbiased_over_all_choices() {
        let s = Spectrum::from_fn(|i| (i as f32 * 0.37).sin().abs() + 0.05);
        let want = s.to_xyz();
        let mut sum = [0.0f64; 3];
        for h in 0..N_BINS {
            let l = sample_packet::<4>(WavelengthSampling::Hero, [(h as f32 + 0.5) / 36.0, 0.0, 0.0, 0.0]);
            let xyz = l.xyz(&l.sample(&s));
            sum[0] += xyz.x as f64;
            sum[1] += xyz.y as f64;
            sum[2] += xyz.z as f64;
        }
        let got = sum.map(|v| v / N_BINS as f64);
        assert!((got[0] - want.x as f64).abs() < 1e-5);
        assert!((got[1] - want.y as f64).abs() < 1e-5);
        assert!((got[2] - want.z as f64).abs() < 1e-5);
    }

    #[test]
    fn rgb_packet_reads_values_as_linear_srgb() {
        let l = Lambdas::rgb();
        assert!((l.lambda_nm(0) - 435.8).abs() < 1e-3 && (l.lambda_nm(2) - 700.0).abs() < 1e-3);
        // Values (b, g, r) = (0.25, 0.5, 1.0) read back as linear sRGB (1.0, 0.5, 0.25).
        let xyz = l.xyz(&Sampled([0.25, 0.5, 1.0]));
        let rgb = xyz.to_linear_srgb();
        assert!((rgb.r - 1.0).abs() < 1e-4 && (rgb.g - 0.5).abs() < 1e-4 && (rgb.b - 0.25).abs() < 1e-4);
        // Split into single wavelengths, the three read-outs add up to the same colour.
        let mut sum = Xyz::default();
        for (i, v) in [0.25, 0.5, 1.0].into_iter().enumerate() {
            let one = l.single(i);
            let x = one.xyz(&Sampled([v]));
            sum += x;
        }
        assert!((sum.x - xyz.x).abs() < 1e-4 && (sum.y - xyz.y).abs() < 1e-4 && (sum.z - xyz.z).abs() < 1e-4);
    }

    /// The rotated draws from a throughput-times-importance distribution are
    /// unbiased: the expectation over `u` of `Σ_k f(b_k) / (c · p(b_k))`
    /// equals `Σ_b f(b)` for a coloured throughput with zero bins, for every
    /// packet size. The estimate is piecewise constant in `u`, with steps
    /// where some `u + k/c` crosses a bin boundary of the cumulative sum, so
    /// it is integrated exactly: evaluated at the midpoint of every interval
    /// between steps and weighted by the interval's length. The tolerance,
    /// 1e-5 relative, covers f32 rounding; a wrong weight (e.g. 36/c) is off
    /// by over 10%.
    #[test]
    fn rotated_importance_draws_are_unbiased() {
        let imp = bin_importance();
        let beta: [f32; N_BINS] =
            std::array::from_fn(|b| if b % 7 == 3 { 0.0 } else { 0.2 + (b as f32 * 0.41).sin().abs() });
        let f: [f32; N_BINS] = std::array::from_fn(|b| beta[b] * (0.3 + (b as f32 * 0.23).cos().abs()));
        let want: f64 = f.iter().map(|&v| v as f64).sum();
        let d = BinDistribution::new(|b| beta[b] * imp[b]).unwrap();
        for c in [1usize, 2, 4, 8] {
            let mut steps: Vec<f64> = vec![0.0, 1.0];
            for &cum in &d.cdf {
                for k in 0..c {
                    steps.push((cum as f64 / d.total as f64 - k as f64 / c as f64).rem_euclid(1.0));
                }
            }
            steps.sort_by(f64::total_cmp);
            let mut got = 0.0f64;
            for w in steps.windows(2) {
                if w[1] - w[0] < 1e-7 {
                    continue;
                }
                let mut est = 0.0f64;
                for_each_rotated(&d, c, ((w[0] + w[1]) / 2.0) as f32, |b, wt| {
                    assert!(beta[b] > 0.0, "a zero-throughput bin was drawn");
                    est += (f[b] * wt) as f64;
                });
                got += est * (w[1] - w[0]);
            }
            assert!((got - want).abs() < 1e-5 * want, "c = {c}: {got} vs {want}");
        }
        // Probabilities follow the weights, and degenerate weights give no distribution.
        let (b, p) = d.sample(0.0);
        assert_eq!(b, 0);
        assert!((p - beta[0] * imp[0] / (0..N_BINS).map(|i| beta[i] * imp[i]).sum::<f32>()).abs() < 1e-6);
        assert!(BinDistribution::new(|_| 0.0).is_none());
        assert!(BinDistribution::new(|b| if b == 5 { f32::NAN } else { 1.0 }).is_none());
        assert_eq!(BinDistribution::new(|b| (b == 35) as u8 as f32).unwrap().sample(0.999_999_9), (35, 1.0));
    }

    /// Every bin matters to the image: the importance is positive everywhere,
    /// largest in the green-yellow and smallest at the ends of the range.
    #[test]
    fn bin_importance_is_positive_and_peaks_mid_spectrum() {
        let imp = bin_importance();
        assert!(imp.iter().all(|&v| v > 0.0));
        let peak = (0..N_BINS).max_by(|&a, &b| imp[a].total_cmp(&imp[b])).unwrap();
        assert!(imp[0] < 0.05 * imp[peak] && imp[35] < 0.05 * imp[peak], "{imp:?}");
    }
}
