//! Thin-film interference, per wavelength: a film of thickness `d` and index
//! `n_f` between an incident medium `n_i` and a substrate of complex index
//! `ñ_t` reflects the Airy sum of its multiple reflections (Born and Wolf,
//! *Principles of Optics*, §1.6.4), for each polarisation:
//!
//! `r = (r_if + r_ft e^{2iβ}) / (1 + r_if r_ft e^{2iβ})`, `β = 2π n_f d cos θ_f / λ`,
//!
//! with the Fresnel amplitude coefficients `r_if`, `r_ft` and complex
//! cosines (so a film thinner than the evanescent decay length frustrates
//! total internal reflection, and a metal substrate works as it is).
//! `R = (|r_s|² + |r_p|²) / 2`. The transmittance into a real substrate is
//! `T = Re(n_t cos θt) / (n_i cos θi) |t|²` (s; p uses the conjugate-cosine
//! form), `t = t_if t_ft e^{iβ} / (1 + r_if r_ft e^{2iβ})`; for a lossless
//! film `R + T = 1` (tested).
//!
//! Used by `coating: ThinFilm(thickness_nm: T, ior: ...)` on a conductor and
//! by the free-standing [`ThinSheet`] (a soap film):
//!
//! ```ron
//! "oiled_steel": Conductor(eta: Constant(2.5), k: Constant(3.3), coating: ThinFilm(thickness_nm: 350, ior: Constant(1.45))),
//! "soap": ThinSheet(thickness_nm: 400, ior: Constant(1.33)),
//! ```

use glam::Vec3;

use super::{BsdfSample, Ior};
use crate::color::{Sampled, Spectrum, bin_lambda_nm};
use crate::spectral::Lambdas;

/// A minimal complex number (f64) for the Airy sums (and the complex
/// Fresnel equations of `fresnel.rs`'s test).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct C(pub(super) f64, pub(super) f64);

impl C {
    pub(super) fn add(self, o: C) -> C {
        C(self.0 + o.0, self.1 + o.1)
    }
    pub(super) fn sub(self, o: C) -> C {
        C(self.0 - o.0, self.1 - o.1)
    }
    pub(super) fn mul(self, o: C) -> C {
        C(self.0 * o.0 - self.1 * o.1, self.0 * o.1 + self.1 * o.0)
    }
    pub(super) fn div(self, o: C) -> C {
        let d = o.0 * o.0 + o.1 * o.1;
        if d == 0.0 {
            return C(0.0, 0.0);
        }
        C((self.0 * o.0 + self.1 * o.1) / d, (self.1 * o.0 - self.0 * o.1) / d)
    }
    pub(super) fn norm2(self) -> f64 {
        self.0 * self.0 + self.1 * self.1
    }
    fn conj(self) -> C {
        C(self.0, -self.1)
    }
    /// The principal square root (non-negative real part).
    pub(super) fn sqrt(self) -> C {
        let r = self.norm2().sqrt();
        let re = ((r + self.0) / 2.0).max(0.0).sqrt();
        let im = ((r - self.0) / 2.0).max(0.0).sqrt();
        C(re, if self.1 < 0.0 { -im } else { im })
    }
    /// e^{i z}.
    fn exp_i(self) -> C {
        let m = (-self.1).exp();
        C(m * self.0.cos(), m * self.0.sin())
    }
}

/// The cosine in a medium of index `n` for a ray with `n_i sin θ_i` given:
/// `√(1 − (n_i sin θi / n)²)`, taking the branch that decays into the medium.
fn cos_in(n_sin: f64, n: C) -> C {
    let s = C(n_sin, 0.0).div(n);
    let c = C(1.0, 0.0).sub(s.mul(s)).sqrt();
    // For an absorbing medium the wave must decay: Im(n cos) ≥ 0.
    if n.mul(c).1 < 0.0 { C(-c.0, -c.1) } else { c }
}

/// Reflection and transmission amplitudes of one interface for s and p.
fn interface(n1: C, c1: C, n2: C, c2: C) -> ([C; 2], [C; 2]) {
    let (a, b) = (n1.mul(c1), n2.mul(c2));
    let rs = a.sub(b).div(a.add(b));
    let ts = C(2.0, 0.0).mul(a).div(a.add(b));
    let (a, b) = (n2.mul(c1), n1.mul(c2));
    let rp = a.sub(b).div(a.add(b));
    let tp = C(2.0, 0.0).mul(n1.mul(c1)).div(a.add(b));
    ([rs, rp], [ts, tp])
}

/// The reflectance and transmittance (unpolarised) of a film of index
/// `n_f` and thickness `d_nm` on a substrate `n_t + i k_t`, lit from a
/// medium of real index `n_i` at incidence cosine `cos_i`, at `lambda_nm`.
/// The transmittance is 0 for an absorbing substrate (`k_t > 0`: a metal).
pub fn airy(cos_i: f32, n_i: f32, n_f: f32, d_nm: f32, n_t: f32, k_t: f32, lambda_nm: f32) -> (f32, f32) {
    let ci = (cos_i.abs() as f64).min(1.0);
    let ni = C(n_i as f64, 0.0);
    let nf = C(n_f as f64, 0.0);
    let nt = C(n_t as f64, k_t as f64);
    let n_sin = n_i as f64 * (1.0 - ci * ci).max(0.0).sqrt();
    let c_i = C(ci, 0.0);
    let cf = cos_in(n_sin, nf);
    let ct = cos_in(n_sin, nt);
    let (r01, t01) = interface(ni, c_i, nf, cf);
    let (r12, t12) = interface(nf, cf, nt, ct);
    let beta = C(2.0 * std::f64::consts::PI * d_nm as f64 / lambda_nm as f64, 0.0).mul(nf.mul(cf));
    let e1 = beta.exp_i();
    let e2 = e1.mul(e1);
    let (mut r, mut t) = (0.0, 0.0);
    for p in 0..2 {
        let den = C(1.0, 0.0).add(r01[p].mul(r12[p]).mul(e2));
        r += 0.5 * r01[p].add(r12[p].mul(e2)).div(den).norm2();
        if k_t == 0.0 && ci > 0.0 {
            let amp = t01[p].mul(t12[p]).mul(e1).div(den);
            // Energy flux ratio: Re(n_t cos θt) / (n_i cos θi) for s,
            // Re(n_t cos θt*) / (n_i cos θi*) for p (real incident cosine).
            let flux = if p == 0 { nt.mul(ct).0 } else { nt.mul(ct.conj()).0 };
            t += 0.5 * amp.norm2() * flux / (n_i as f64 * ci);
        }
    }
    (r.clamp(0.0, 1.0) as f32, t.clamp(0.0, 1.0) as f32)
}

/// A thin film: thickness and index per bin.
#[derive(Clone, Debug)]
pub struct ThinFilm {
    /// Thickness in nm.
    pub thickness_nm: f32,
    /// The film's index per bin.
    pub eta: Spectrum,
}

impl ThinFilm {
    /// A film of `thickness_nm` and index `ior`.
    pub fn new(thickness_nm: f32, ior: &Ior) -> Self {
        ThinFilm { thickness_nm, eta: Spectrum::from_fn(|b| ior.at(bin_lambda_nm(b))) }
    }

    /// The film's index at fractional bin position `pos`.
    #[inline]
    pub fn eta_at(&self, pos: f32) -> f32 {
        let i0 = (pos.max(0.0) as usize).min(35);
        let frac = pos - i0 as f32;
        if frac <= 0.0 || i0 + 1 >= 36 { self.eta[i0] } else { self.eta[i0] * (1.0 - frac) + self.eta[i0 + 1] * frac }
    }

    /// Reflectance and transmittance per wavelength of the packet, from vacuum,
    /// onto a substrate of index `n_t + i k_t` (per wavelength).
    #[inline]
    pub fn airy<const N: usize>(
        &self,
        cos: f32,
        n_t: &Sampled<N>,
        k_t: &Sampled<N>,
        lambdas: &Lambdas<N>,
    ) -> (Sampled<N>, Sampled<N>) {
        let nf = lambdas.sample(&self.eta);
        let mut r = Sampled::splat(0.0);
        let mut t = Sampled::splat(0.0);
        for i in 0..N {
            (r[i], t[i]) = airy(cos, 1.0, nf[i], self.thickness_nm, n_t[i], k_t[i], lambdas.lambda_nm(i));
        }
        (r, t)
    }
}

/// A free-standing thin film in vacuum (a soap film): it reflects the Airy
/// reflectance `R(λ, θ)` and lets `T = 1 − R` through undeviated (it has no
/// thickness in the scene). Both delta lobes keep the whole packet: the
/// reflection is chosen with probability `P` = the packet's mean `R` and
/// weighted `R(λ) / P`, the transmission `(1 − R(λ)) / (1 − P)`. Put it on a
/// `Sphere` for a soap bubble.
#[derive(Clone, Debug)]
pub struct ThinSheet {
    /// The film.
    pub film: ThinFilm,
}

impl ThinSheet {
    /// Samples reflection or straight transmission.
    #[inline]
    pub fn sample<const N: usize>(&self, wo: Vec3, uc: f32, lambdas: &Lambdas<N>) -> Option<BsdfSample<N>> {
        if wo.z.abs() < f32::MIN_POSITIVE {
            return None;
        }
        let (r, _) = self.film.airy(wo.z.abs(), &Sampled::splat(1.0), &Sampled::splat(0.0), lambdas);
        let p = (r.0.iter().sum::<f32>() / N as f32).clamp(0.0, 1.0);
        if uc < p {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            return Some(BsdfSample { wi, f: r / wi.z.abs(), pdf: p, is_delta: true, eta: 1.0 });
        }
        if p >= 1.0 {
            return None;
        }
        let wi = -wo;
        let t = Sampled(r.0.map(|x| 1.0 - x));
        Some(BsdfSample { wi, f: t / wi.z.abs(), pdf: 1.0 - p, is_delta: true, eta: 1.0 })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The textbook intensity form of the Airy sum for real indices below
    /// the critical angle (Born and Wolf eq. 1.6.(58)): with real amplitude
    /// coefficients `r1 = r_if`, `r2 = r_ft` and phase `2β`,
    /// `R = (r1² + r2² + 2 r1 r2 cos 2β) / (1 + r1² r2² + 2 r1 r2 cos 2β)`,
    /// per polarisation, written here with real arithmetic only.
    fn airy_intensity(cos_i: f64, ni: f64, nf: f64, nt: f64, d: f64, lambda: f64) -> f64 {
        let s = ni * (1.0 - cos_i * cos_i).sqrt();
        let cf = (1.0 - (s / nf).powi(2)).sqrt();
        let ct = (1.0 - (s / nt).powi(2)).sqrt();
        let rs = |a: f64, ca: f64, b: f64, cb: f64| (a * ca - b * cb) / (a * ca + b * cb);
        let rp = |a: f64, ca: f64, b: f64, cb: f64| (b * ca - a * cb) / (b * ca + a * cb);
        let phase = 2.0 * (2.0 * std::f64::consts::PI * nf * d * cf / lambda);
        let one = |r1: f64, r2: f64| {
            (r1 * r1 + r2 * r2 + 2.0 * r1 * r2 * phase.cos()) / (1.0 + r1 * r1 * r2 * r2 + 2.0 * r1 * r2 * phase.cos())
        };
        0.5 * (one(rs(ni, cos_i, nf, cf), rs(nf, cf, nt, ct)) + one(rp(ni, cos_i, nf, cf), rp(nf, cf, nt, ct)))
    }

    /// Reflectance against the intensity form of the Airy formula for films
    /// of 0 (the bare interface), 100, 550 and 5000 nm at angles from normal
    /// to 80° and every bin; a lossless film transmits the rest, R + T = 1
    /// (transmittance from the amplitude sum, an independent path); and at
    /// normal incidence a quarter-wave film of index √n_t is a perfect
    /// anti-reflection coating (R = 0).
    #[test]
    fn airy_matches_the_intensity_formula_and_conserves_energy() {
        for d in [0.0f32, 100.0, 550.0, 5000.0] {
            for deg in [0.0f64, 30.0, 60.0, 80.0] {
                let c = deg.to_radians().cos();
                for b in 0..36 {
                    let lambda = bin_lambda_nm(b);
                    for (nf, nt) in [(1.33f32, 1.0f32), (1.38, 1.5), (2.0, 1.5)] {
                        let (r, t) = airy(c as f32, 1.0, nf, d, nt, 0.0, lambda);
                        let want = airy_intensity(c, 1.0, nf as f64, nt as f64, d as f64, lambda as f64);
                        assert!((r as f64 - want).abs() < 1e-5, "d {d} θ {deg} λ {lambda} nf {nf}: {r} vs {want}");
                        assert!((r + t - 1.0).abs() < 1e-5, "d {d} θ {deg} λ {lambda}: R + T = {}", r + t);
                    }
                }
            }
        }
        let (nt, lambda) = (1.5f32, 550.0f32);
        let nf = nt.sqrt();
        let (r, _) = airy(1.0, 1.0, nf, lambda / (4.0 * nf), nt, 0.0, lambda);
        assert!(r < 1e-6, "quarter-wave coating: R = {r}");
    }

    /// Extreme thicknesses: a film of 0 nm is the bare substrate (metal:
    /// the conductor's Fresnel), 1e6 nm (1 mm) stays finite and in [0, 1],
    /// and from inside a dense medium beyond the critical angle a thick gap
    /// reflects everything while a 1 nm gap lets light tunnel (frustrated
    /// total internal reflection: R < 1).
    #[test]
    fn extreme_thicknesses() {
        let (n, k) = (0.2f32, 3.0f32);
        for c in [1.0f32, 0.5, 0.1] {
            let (r, t) = airy(c, 1.0, 1.4, 0.0, n, k, 500.0);
            assert!((r - crate::bxdf::fresnel_conductor(c, n, k)).abs() < 1e-5 && t == 0.0);
            let (r, t) = airy(c, 1.0, 1.4, 1e6, 1.5, 0.0, 500.0);
            assert!(r.is_finite() && (0.0..=1.0).contains(&r) && (r + t - 1.0).abs() < 1e-4);
        }
        let c = 0.3f32; // sin θ = 0.954 in glass of 1.5: beyond the critical angle to vacuum
        let (thick, _) = airy(c, 1.5, 1.0, 5000.0, 1.5, 0.0, 500.0);
        let (thin, t) = airy(c, 1.5, 1.0, 1.0, 1.5, 0.0, 500.0);
        assert!((thick - 1.0).abs() < 1e-6, "TIR across a thick gap: {thick}");
        assert!(thin < 0.1 && (thin + t - 1.0).abs() < 1e-4, "a 1 nm gap tunnels: R {thin}, T {t}");
    }

    /// The sheet's two lobes: reflection chosen with probability P (the
    /// packet's mean R) and weighted R(λ)/P, straight transmission weighted
    /// (1 − R(λ))/(1 − P): the expected weight P·R/P + (1−P)·(1−R)/(1−P) is
    /// 1 per wavelength (lossless), at every angle including grazing, for the
    /// full spectrum and single wavelengths; and R(λ) is the Airy reflectance.
    #[test]
    fn thin_sheet_reflects_r_and_transmits_the_rest() {
        let sheet = ThinSheet { film: ThinFilm::new(400.0, &Ior::Constant(1.33)) };
        let l = Lambdas::full();
        for c in [1.0f32, 0.6, 0.1, 1e-3, -0.4] {
            let wo = Vec3::new((1.0 - c * c).sqrt(), 0.0, c);
            let refl: BsdfSample<36> = sheet.sample(wo, 0.0, &l).unwrap();
            let tr: BsdfSample<36> = sheet.sample(wo, 1.0 - 1e-7, &l).unwrap();
            assert!(refl.wi.z * wo.z > 0.0 && (tr.wi + wo).length() < 1e-6);
            assert!((refl.pdf + tr.pdf - 1.0).abs() < 1e-6);
            for b in 0..36 {
                let (r, _) = airy(c, 1.0, 1.33, 400.0, 1.0, 0.0, bin_lambda_nm(b));
                let wr = refl.f[b] * refl.wi.z.abs();
                let wt = tr.f[b] * tr.wi.z.abs();
                assert!((wr - r).abs() < 1e-5 && (wr + wt - 1.0).abs() < 1e-5, "cos {c} bin {b}");
            }
        }
    }

    /// Coated smooth glass (100 nm of n 1.38 on index 1.5, and a 1e6 nm
    /// film): per wavelength, from outside and inside, R is the Airy
    /// reflectance with the media in the right order, and R + T = 1 (the
    /// two branches' weights, refraction's 1/η² undone); beyond the critical
    /// angle from inside everything reflects.
    #[test]
    fn coated_glass_reflects_airy_and_conserves_energy() {
        use crate::bxdf::Dielectric;
        for d in [100.0f32, 1e6] {
            let glass = Dielectric::new(Ior::Constant(1.5)).with_coating(ThinFilm::new(d, &Ior::Constant(1.38)));
            let l = Lambdas::full();
            for c in [1.0f32, 0.5, 0.05, -0.9, -0.8, -0.5] {
                let wo = Vec3::new((1.0 - c * c).sqrt(), 0.0, c);
                let refl: BsdfSample<36> = glass.sample_any(wo, glam::Vec2::ZERO, 0.0, (1.5, 1.0), &l).unwrap();
                let tr: BsdfSample<36> = glass.sample_any(wo, glam::Vec2::ZERO, 1.0 - 1e-7, (1.5, 1.0), &l).unwrap();
                for b in 0..36 {
                    let (ni, nt) = if c > 0.0 { (1.0, 1.5) } else { (1.5, 1.0) };
                    let (r, _) = airy(c, ni, 1.38, d, nt, 0.0, bin_lambda_nm(b));
                    let wr = refl.f[b] * refl.wi.z.abs() / refl.pdf * refl.pdf;
                    assert!((wr - r).abs() < 1e-5, "d {d} cos {c} bin {b}: {wr} vs {r}");
                    if tr.wi.z * wo.z < 0.0 {
                        let wt = tr.f[b] * tr.wi.z.abs() * tr.eta * tr.eta;
                        assert!((wr + wt - 1.0).abs() < 1e-4, "d {d} cos {c} bin {b}: R + T = {}", wr + wt);
                    } else {
                        assert!(c < 0.0 && c > -0.75 && (r - 1.0).abs() < 1e-6, "TIR only beyond the critical angle");
                    }
                }
            }
        }
    }
}
