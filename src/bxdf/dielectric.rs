//! A smooth dielectric interface (glass, water, diamond): Fresnel reflection
//! (thesis eq. 2.4, unpolarised) and Snell refraction (eq. 2.3), with the
//! choice between them made stochastically with probability F, and total
//! internal reflection handled (F = 1). Refracted radiance is scaled by
//! `1 / η²` (η = η_t / η_i, pbrt-v4 §9.5.2), which cancels over a path that
//! enters and leaves. No absorption.
//!
//! The index of refraction may depend on wavelength ([`Ior`]): then the model
//! is dispersive ([`super::Dispersion`]), and the integrator asks for one
//! wavelength's direction at a time. A wavelength arrives in one form, the
//! packet's fractional bin position ([`Lambdas`]): a packet of one wavelength
//! refracts at its own index, a larger packet (which reaches a dispersive
//! surface only when dispersion is off) at the index at 589.3 nm.
//!
//! **Rough glass** (`roughness: A`, GGX α, 0 = smooth): a microfacet
//! interface with reflection and transmission ([`super::rough_dielectric`]);
//! below α = 1e-3 it is the smooth model exactly. Where the relative index
//! is 1 (glass of index 1, or inside the same glass) an uncoated rough
//! interface passes light straight through, as a smooth one does. A dispersive rough glass
//! still splits wavelengths in `auto` and `spectral` ([`super::Dispersion`]).
//!
//! **Absorption** (`absorption: SPECTRUM`, σ per scene unit per bin): light
//! travelling a distance `d` inside keeps `exp(−σ d)` (Beer-Lambert). The
//! integrators apply it to every path segment and shadow ray that runs inside
//! this object's volume while it is the path's current medium
//! ([`crate::medium::nested`]), whatever the segment ends on.
//!
//! **Outside medium**: the outside is vacuum unless the path is inside an
//! enclosing dielectric ([`crate::medium::nested`]): then every method that takes a
//! relative index `eta` is called with `n_inside / n_outside` (per
//! wavelength for one wavelength, at 589.3 nm for a larger packet), and
//! those that compute it take the [`Outside`] medium.
//!
//! **Coating** (`coating: ThinFilm(thickness_nm:, ior:)`): the film's Airy
//! reflectance per wavelength replaces Fresnel's ([`super::thin_film`]); the
//! film is thin, so the ray refracts as through the bare interface. On rough
//! glass the film lies on every microfacet: `R(λ, wo·wm)` replaces `F` per
//! wavelength in `f`, and the lobe is chosen with the packet's mean
//! reflectance, which `pdf` reproduces (for one wavelength, its own).
//!
//! ```ron
//! "glass": Dielectric(ior: Named("N-BK7")),
//! "coated_lens": Dielectric(ior: Named("N-BK7"), coating: ThinFilm(thickness_nm: 100, ior: Constant(1.38))),
//! "crown": Dielectric(ior: Constant(1.5)),
//! "flint": Dielectric(ior: Cauchy(a: 1.67, b: 0.0074)),
//! "frosted": Dielectric(ior: Constant(1.5), roughness: 0.15),
//! "coated_frost": Dielectric(ior: Constant(1.5), roughness: 0.1, coating: ThinFilm(thickness_nm: 300, ior: Constant(1.38))),
//! "green_glass": Dielectric(ior: Named("N-BK7"), absorption: Samples([...36 values per unit length...])),
//! ```

use glam::{Vec2, Vec3};

use super::microfacet::{Ggx, SMOOTH_ALPHA};
use super::thin_film::{ThinFilm, airy};
use super::{BsdfSample, Ior, fresnel_dielectric, refract, rough_dielectric};
use crate::color::{LAMBDA_MIN_NM, LAMBDA_STEP_NM, N_BINS, bin_lambda_nm};
use crate::color::{Sampled, Spectrum};
use crate::spectral::{Lambdas, REFERENCE_LAMBDA_NM};

/// The medium on the outside of a dielectric's surface: vacuum (index 1),
/// or the inside of another dielectric that encloses the path there
/// (nested dielectrics, [`crate::medium::nested`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct Outside<'a>(Option<&'a Dielectric>);

impl<'a> Outside<'a> {
    /// Vacuum, index exactly 1.
    pub const VACUUM: Outside<'static> = Outside(None);

    /// The inside of dielectric `d`.
    #[inline]
    pub fn medium(d: &'a Dielectric) -> Self {
        Outside(Some(d))
    }

    /// The outside's index at fractional bin position `pos`.
    #[inline]
    pub fn eta_at(&self, pos: f32) -> f32 {
        self.0.map_or(1.0, |d| d.eta_at(pos))
    }

    /// The outside's index for a packet (as [`Dielectric::eta_for`]).
    #[inline]
    pub fn eta_for<const N: usize>(&self, lambdas: &Lambdas<N>) -> f32 {
        self.0.map_or(1.0, |d| d.eta_for(lambdas))
    }

    /// The outside's index at the reference wavelength, 589.3 nm.
    #[inline]
    pub fn reference_eta(&self) -> f32 {
        self.0.map_or(1.0, |d| d.reference_eta())
    }

    /// True when the outside's index varies with wavelength.
    #[inline]
    pub fn is_dispersive(&self) -> bool {
        self.0.is_some_and(|d| d.ior().is_dispersive())
    }
}

/// A dielectric interface; the outside (the side the normal points to) is
/// vacuum or the enclosing medium ([`Outside`]).
#[derive(Clone, Debug)]
pub struct Dielectric {
    /// Index of refraction of the inside.
    ior: Ior,
    /// The index at each bin's wavelength (the Sellmeier equation costs
    /// three f64 divisions and a square root per wavelength).
    bin_ior: [f32; N_BINS],
    /// The index at the reference wavelength, 589.3 nm.
    reference_ior: f32,
    /// GGX α of the interface (below 1e-3: smooth).
    alpha: f32,
    /// Absorption coefficient inside, per scene unit (`None`: clear).
    absorption: Option<Spectrum>,
    /// A thin film on the outside of a smooth glass (`None`: bare).
    coating: Option<ThinFilm>,
}

impl Dielectric {
    /// A dielectric of index `ior` inside.
    pub fn new(ior: Ior) -> Self {
        let bin_ior = std::array::from_fn(|b| ior.at(bin_lambda_nm(b)));
        let reference_ior = ior.at(REFERENCE_LAMBDA_NM);
        Dielectric { ior, bin_ior, reference_ior, alpha: 0.0, absorption: None, coating: None }
    }

    /// The same glass with a rough (GGX α) interface.
    pub fn with_roughness(mut self, alpha: f32) -> Self {
        self.alpha = alpha;
        self
    }

    /// The same glass absorbing `sigma` per unit length inside (zero: clear).
    pub fn with_absorption(mut self, sigma: Spectrum) -> Self {
        self.absorption = if sigma.is_black() { None } else { Some(sigma) };
        self
    }

    /// Sets the GGX α of the interface (a roughness texture's value at a hit).
    pub fn set_roughness(&mut self, alpha: f32) {
        self.alpha = alpha;
    }

    /// Sets the coating's thickness (a texture's value at a hit; nothing
    /// without a coating).
    pub fn set_coating_thickness_nm(&mut self, nm: f32) {
        if let Some(film) = &mut self.coating {
            film.thickness_nm = nm;
        }
    }

    /// The same glass under a thin film: its reflectance (every microfacet's,
    /// on rough glass) becomes the film's Airy reflectance per wavelength.
    pub fn with_coating(mut self, film: ThinFilm) -> Self {
        self.coating = Some(film);
        self
    }

    /// The reflectance for incidence cosine `cos` (negative: from inside),
    /// relative index `eta`, outside index `n_out` (1 in vacuum) and
    /// fractional bin position `pos`: bare Fresnel, or the coating's Airy
    /// reflectance between the outside and the glass (incident medium and
    /// substrate swapped from inside; total internal reflection gives 1
    /// unless the film frustrates it).
    #[inline]
    pub fn reflectance_at(&self, cos: f32, eta: f32, n_out: f32, pos: f32) -> f32 {
        match &self.coating {
            None => fresnel_dielectric(cos, eta),
            Some(film) => {
                let lambda = LAMBDA_MIN_NM + LAMBDA_STEP_NM * pos;
                let nf = film.eta_at(pos);
                let (ni, nt) = if cos >= 0.0 { (n_out, eta * n_out) } else { (eta * n_out, n_out) };
                airy(cos.abs(), ni, nf, film.thickness_nm, nt, 0.0, lambda).0
            }
        }
    }

    /// GGX α (0 for a smooth interface).
    #[inline]
    pub fn roughness(&self) -> f32 {
        self.alpha
    }

    /// True when the interface is smooth (a delta model).
    #[inline]
    pub fn is_smooth(&self) -> bool {
        self.alpha.is_nan() || self.alpha < SMOOTH_ALPHA
    }

    /// The absorption coefficient inside, when the glass absorbs.
    #[inline]
    pub fn absorption(&self) -> Option<&Spectrum> {
        self.absorption.as_ref()
    }

    /// `f(wo, wi)` for index `eta` (0 for the smooth model).
    #[inline]
    pub fn eval(&self, wo: Vec3, wi: Vec3, eta: f32) -> f32 {
        if self.is_smooth() { 0.0 } else { rough_dielectric::eval(Ggx { alpha: self.alpha }, wo, wi, eta) }
    }

    /// The pdf of `sample` choosing `wi`, for index `eta` (0 for the smooth model).
    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3, eta: f32) -> f32 {
        if self.is_smooth() { 0.0 } else { rough_dielectric::pdf(Ggx { alpha: self.alpha }, wo, wi, eta) }
    }

    /// `f(wo, wi)` for each of the packet's wavelengths at relative index
    /// `eta` (`n_out`: the outside's index): per wavelength on coated rough
    /// glass, the same for all otherwise.
    #[inline]
    pub fn eval_packet<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        (eta, n_out): (f32, f32),
        lambdas: &Lambdas<N>,
    ) -> Sampled<N> {
        match &self.coating {
            Some(_) if !self.is_smooth() => {
                rough_dielectric::eval_coated(Ggx { alpha: self.alpha }, wo, wi, eta, |c| {
                    Sampled(std::array::from_fn(|i| self.reflectance_at(c, eta, n_out, lambdas.pos[i])))
                })
            }
            _ => Sampled::splat(self.eval(wo, wi, eta)),
        }
    }

    /// The pdf of `sample_any` choosing `wi` for the packet at relative index
    /// `eta`: coated rough glass chooses its lobe with the packet's mean film reflectance.
    #[inline]
    pub fn pdf_packet<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        (eta, n_out): (f32, f32),
        lambdas: &Lambdas<N>,
    ) -> f32 {
        match &self.coating {
            Some(_) if !self.is_smooth() => rough_dielectric::pdf_with(Ggx { alpha: self.alpha }, wo, wi, eta, |c| {
                self.mean_film(c, eta, n_out, lambdas)
            }),
            _ => self.pdf(wo, wi, eta),
        }
    }

    /// The coated reflectance at microfacet cosine `c`, averaged over the packet.
    #[inline]
    fn mean_film<const N: usize>(&self, c: f32, eta: f32, n_out: f32, lambdas: &Lambdas<N>) -> f32 {
        let sum: f32 = lambdas.pos.iter().map(|&pos| self.reflectance_at(c, eta, n_out, pos)).sum();
        (sum / N as f32).clamp(0.0, 1.0)
    }

    /// Samples the smooth or rough interface for relative index `eta`
    /// (`n_out`: the outside's index, which only a coating needs).
    #[inline]
    pub fn sample_any<const N: usize>(
        &self,
        wo: Vec3,
        u: Vec2,
        uc: f32,
        (eta, n_out): (f32, f32),
        lambdas: &Lambdas<N>,
    ) -> Option<BsdfSample<N>> {
        if self.coating.is_some() {
            if self.is_smooth() {
                return self.sample_coated(wo, uc, eta, n_out, lambdas);
            }
            let g = Ggx { alpha: self.alpha };
            let wi = rough_dielectric::sample_direction(g, wo, u, uc, eta, |c| self.mean_film(c, eta, n_out, lambdas))?;
            let f = self.eval_packet(wo, wi, (eta, n_out), lambdas);
            let pdf = self.pdf_packet(wo, wi, (eta, n_out), lambdas);
            let (_, etap) = rough_dielectric::half_vector(wo, wi, eta)?;
            if pdf.is_nan() || pdf <= 0.0 || f.is_black() {
                return None;
            }
            return Some(BsdfSample { wi, f, pdf, is_delta: false, eta: etap });
        }
        if self.is_smooth() {
            return self.sample(wo, uc, eta);
        }
        if rough_dielectric::index_matched(eta) {
            return Self::pass_through(wo);
        }
        let s = rough_dielectric::sample(Ggx { alpha: self.alpha }, wo, u, uc, eta)?;
        Some(BsdfSample { wi: s.wi, f: Sampled::splat(s.f), pdf: s.pdf, is_delta: false, eta: s.etap })
    }

    /// The index of refraction of the inside.
    #[inline]
    pub fn ior(&self) -> &Ior {
        &self.ior
    }

    /// The index at the reference wavelength, 589.3 nm (the sodium D line).
    #[inline]
    pub fn reference_eta(&self) -> f32 {
        self.reference_ior
    }

    /// The index at fractional bin position `pos` (0 = 380 nm, 35 = 730 nm):
    /// from the table at bin centres, from the formula between them.
    #[inline]
    pub fn eta_at(&self, pos: f32) -> f32 {
        if pos >= 0.0 && pos.fract() == 0.0 && (pos as usize) < N_BINS {
            self.bin_ior[pos as usize]
        } else {
            self.ior.at(LAMBDA_MIN_NM + LAMBDA_STEP_NM * pos)
        }
    }

    /// The index a packet refracts at: its wavelength's for a single
    /// wavelength, the reference wavelength's (589.3 nm) for a larger packet.
    #[inline]
    pub fn eta_for<const N: usize>(&self, lambdas: &Lambdas<N>) -> f32 {
        if N == 1 { self.eta_at(lambdas.pos[0]) } else { self.reference_ior }
    }

    /// The relative index `n_inside / n_outside` a packet refracts at, and
    /// the outside's index (both as [`Dielectric::eta_for`]).
    #[inline]
    pub fn relative_eta_for<const N: usize>(&self, lambdas: &Lambdas<N>, outside: Outside<'_>) -> (f32, f32) {
        let n_out = outside.eta_for(lambdas);
        (self.eta_for(lambdas) / n_out, n_out)
    }

    /// The Fresnel reflectance at each of the packet's wavelengths, for a
    /// direction `wo` (local frame) outside or inside, each at its own
    /// relative index against `outside`.
    #[inline]
    pub fn reflectance<const N: usize>(&self, wo: Vec3, lambdas: &Lambdas<N>, outside: Outside<'_>) -> Sampled<N> {
        Sampled(std::array::from_fn(|i| {
            let pos = lambdas.pos[i];
            let n_out = outside.eta_at(pos);
            self.reflectance_at(wo.z, self.eta_at(pos) / n_out, n_out, pos)
        }))
    }

    /// Samples a coated smooth interface: each wavelength has its own
    /// reflectance `R(λ)` (the film's), so reflection is chosen with the
    /// packet's mean `P` and weighted `R(λ) / P`, refraction (at index `eta`)
    /// with `1 − P` and weighted `(1 − R(λ)) / ((1 − P) η²)`.
    #[inline]
    fn sample_coated<const N: usize>(
        &self,
        wo: Vec3,
        uc: f32,
        eta: f32,
        n_out: f32,
        lambdas: &Lambdas<N>,
    ) -> Option<BsdfSample<N>> {
        if wo.z.abs() < f32::MIN_POSITIVE {
            return None;
        }
        let r = Sampled::<N>(std::array::from_fn(|i| self.reflectance_at(wo.z, eta, n_out, lambdas.pos[i])));
        let p = (r.0.iter().sum::<f32>() / N as f32).clamp(0.0, 1.0);
        let refracted = refract(wo, Vec3::Z, eta);
        if uc < p || p >= 1.0 || refracted.is_none() {
            if p.is_nan() || p <= 0.0 {
                return None;
            }
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            // Without a refracted direction every wavelength reflects: weight R / P with P = 1.
            let pdf = if refracted.is_none() { 1.0 } else { p };
            return Some(BsdfSample { wi, f: r / wi.z.abs(), pdf, is_delta: true, eta: 1.0 });
        }
        let (wi, etap) = refracted?;
        if wi.z.abs() < f32::MIN_POSITIVE {
            return None;
        }
        let t = Sampled(r.0.map(|x| 1.0 - x));
        Some(BsdfSample { wi, f: t / (wi.z.abs() * etap * etap), pdf: 1.0 - p, is_delta: true, eta: etap })
    }

    /// The straight pass-through of an index-matched rough interface: the
    /// delta `wi = −wo` of probability 1 and weight `f |cos θi| / pdf = 1`, as
    /// the smooth interface of index 1 refracts (see [`rough_dielectric`]).
    #[inline]
    fn pass_through<const N: usize>(wo: Vec3) -> Option<BsdfSample<N>> {
        if wo.z.abs() < f32::MIN_POSITIVE {
            return None;
        }
        Some(BsdfSample { wi: -wo, f: Sampled::splat(1.0 / wo.z.abs()), pdf: 1.0, is_delta: true, eta: 1.0 })
    }

    /// The refraction alone for index `eta`, as a sample of probability 1
    /// whose weight `f |cos θ| / pdf` is the radiance scaling `1 / η²`: the
    /// integrator has already chosen refraction and weighted it by `T`.
    /// `None` on total internal reflection or a grazing direction.
    #[inline]
    pub fn sample_refraction<const N: usize>(&self, wo: Vec3, eta: f32) -> Option<BsdfSample<N>> {
        if wo.z.abs() < f32::MIN_POSITIVE {
            return None;
        }
        let (wi, etap) = refract(wo, Vec3::Z, eta)?;
        if wi.z.abs() < f32::MIN_POSITIVE {
            return None;
        }
        let f = 1.0 / (wi.z.abs() * etap * etap);
        Some(BsdfSample { wi, f: Sampled::splat(f), pdf: 1.0, is_delta: true, eta: etap })
    }

    /// Samples reflection or refraction of the smooth interface for index `eta` (inside / outside).
    #[inline]
    pub fn sample<const N: usize>(&self, wo: Vec3, uc: f32, eta: f32) -> Option<BsdfSample<N>> {
        // Below the smallest normal f32, 1 / |cos θ| overflows to infinity.
        if wo.z.abs() < f32::MIN_POSITIVE {
            return None;
        }
        let r = fresnel_dielectric(wo.z, eta);
        let t = 1.0 - r;
        if uc < r || t <= 0.0 {
            // Specular reflection, chosen with probability R.
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            return Some(BsdfSample { wi, f: Sampled::splat(r / wi.z.abs()), pdf: r, is_delta: true, eta: 1.0 });
        }
        // Refraction, chosen with probability T = 1 - R.
        let (wi, etap) = refract(wo, Vec3::Z, eta)?;
        if wi.z.abs() < f32::MIN_POSITIVE {
            return None;
        }
        let f = t / (wi.z.abs() * etap * etap);
        Some(BsdfSample { wi, f: Sampled::splat(f), pdf: t, is_delta: true, eta: etap })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// R + T = 1 exactly: the expected weight of the stochastic choice,
    /// R·(R/R) + T·(T/T), is 1, and each branch's probability is its Fresnel
    /// term; checked with the branch probabilities themselves at several angles,
    /// both sides, for normal and total internal reflection.
    #[test]
    fn reflection_plus_transmission_is_one() {
        let d = Dielectric::new(Ior::Constant(1.5));
        for cos in [1.0f32, 0.7, 0.3, 0.05, -0.05, -0.5, -0.9, -1.0] {
            let sin = (1.0 - cos * cos).sqrt();
            let wo = Vec3::new(sin, 0.0, cos);
            let refl: BsdfSample<1> = d.sample(wo, 0.0, 1.5).unwrap();
            let r = refl.pdf;
            let weight_r = refl.f[0] * refl.wi.z.abs() / refl.pdf;
            assert!((weight_r - 1.0).abs() < 1e-5);
            if r < 1.0 {
                let tr: BsdfSample<1> = d.sample(wo, 0.999_999, 1.5).unwrap();
                assert!((r + tr.pdf - 1.0).abs() < 1e-6, "R + T at cos {cos}");
                // Transmitted weight is 1/η² in radiance units, undone on the way out.
                let w = tr.f[0] * tr.wi.z.abs() / tr.pdf;
                assert!((w * tr.eta * tr.eta - 1.0).abs() < 1e-4);
                assert!(tr.wi.z * wo.z < 0.0, "refraction crosses the surface");
            }
        }
    }

    /// Snell's law per wavelength with a dispersive glass: η_i sin θ_i =
    /// η_t(λ) sin θ_t for the index the Sellmeier equation gives at λ, and
    /// violet bends more than red.
    #[test]
    fn snell_per_wavelength() {
        let ior = crate::bxdf::named_glass("N-BK7").unwrap();
        let d = Dielectric::new(ior.clone());
        let theta = 50f32.to_radians();
        let wo = Vec3::new(theta.sin(), 0.0, theta.cos());
        let mut last_sin_t = 0.0;
        for lambda in [400.0, 550.0, 700.0] {
            let n = ior.at(lambda);
            let t: BsdfSample<1> = d.sample(wo, 0.999_999, n).unwrap();
            let sin_t = (t.wi.x * t.wi.x + t.wi.y * t.wi.y).sqrt();
            assert!((theta.sin() - n * sin_t).abs() < 1e-5, "{lambda} nm");
            assert!(sin_t > last_sin_t, "longer wavelengths bend less");
            last_sin_t = sin_t;
        }
    }

    /// The per-bin index table equals the formula at every bin's wavelength,
    /// and other wavelengths use the formula; the forced refraction is the
    /// sampled one with weight 1/η² (its branch probability taken out), and
    /// the per-wavelength reflectance is the Fresnel term at each index.
    #[test]
    fn bin_table_forced_refraction_and_reflectance_agree_with_the_formulas() {
        let ior = crate::bxdf::named_glass("N-SF11").unwrap();
        let d = Dielectric::new(ior.clone());
        for b in 0..N_BINS {
            assert_eq!(d.eta_at(b as f32), ior.at(bin_lambda_nm(b)));
        }
        assert_eq!(d.eta_at(20.93), ior.at(LAMBDA_MIN_NM + LAMBDA_STEP_NM * 20.93));
        assert_eq!(d.reference_eta(), ior.at(589.3));
        let one = Lambdas::<1> { pos: [7.0], weight: 1.0, readout: crate::spectral::Readout::Spectral };
        assert_eq!(d.eta_for(&one), ior.at(450.0));
        assert_eq!(d.eta_for(&Lambdas::full()), ior.at(589.3));
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let lambdas =
            Lambdas::<4> { pos: [0.0, 9.0, 18.0, 27.0], weight: 9.0, readout: crate::spectral::Readout::Spectral };
        let fr = d.reflectance(wo, &lambdas, Outside::VACUUM);
        for i in 0..4 {
            let eta = d.eta_at(lambdas.pos[i]);
            assert_eq!(fr[i], fresnel_dielectric(0.8, eta));
            let forced: BsdfSample<1> = d.sample_refraction(wo, eta).unwrap();
            let sampled: BsdfSample<1> = d.sample(wo, 0.999_999, eta).unwrap();
            assert!((forced.wi - sampled.wi).length() < 1e-6 && forced.eta == sampled.eta);
            let w = forced.f[0] * forced.wi.z.abs() / forced.pdf;
            assert!((w * forced.eta * forced.eta - 1.0).abs() < 1e-5);
        }
        assert!(fr[0] > fr[3], "violet reflects more than red in dense flint");
        // Total internal reflection: no refraction to force.
        let inside = Vec3::new(0.9, 0.0, -(1.0f32 - 0.81).sqrt());
        assert!(d.sample_refraction::<1>(inside, 1.8).is_none());
    }
}
