//! Scattering models (BxDFs): the closed set of materials a surface can have.
//!
//! # The contract (written once, for every model)
//! All directions are in the local shading frame, where the surface normal is
//! `+z`; `wo` points back along the path (towards the camera side), `wi` is the
//! sampled or queried direction; both point away from the surface and are unit.
//! Values come for a packet of `N` wavelengths (`Lambdas`, in the crate-internal `spectral` module).
//!
//! - [`Bxdf::eval`]`(wo, wi)` is `f(wo, wi)` without the cosine; 0 for delta
//!   models (their value lives only in `sample`).
//! - [`Bxdf::sample`]`(wo, u, uc)` draws `wi` and returns `f`, the pdf of `wi`
//!   per unit solid angle, and flags. The path weight is always
//!   `f · |cos θi| / pdf`, for delta lobes too (they return
//!   `f = weight / |cos θi|` and `pdf` = the probability of the lobe, as pbrt-v4).
//! - [`Bxdf::pdf`]`(wo, wi)` is the pdf `sample` would have used (0 for delta).
//! - A model whose sampled direction depends on wavelength is *dispersive*:
//!   [`Bxdf::dispersion`] says so and how, so the integrators can split
//!   wavelength packets there without knowing which model it is. A packet of
//!   one wavelength is sampled at that wavelength; a larger packet at the
//!   reference wavelength, 589.3 nm (only `path` and `whitted`, which do not
//!   split, let one reach a dispersive surface).
//!
//! A dielectric's outside is vacuum unless a path is inside an enclosing
//! dielectric: the `_within` forms of the verbs ([`Bxdf::sample_within`],
//! ...) take that [`Outside`] medium, and [`crate::medium::nested`] holds the stack of
//! dielectric volumes a path keeps (nested dielectrics). The plain verbs assume vacuum.
//!
//! Diffuse models, conductors and plastic are two-sided: they reflect into
//! whichever hemisphere `wo` is in; a thin sheet is symmetric. The dielectric is oriented: `+z` is outside (the side the geometric
//! normal points to), so `wo.z < 0` means the path is inside the glass.

mod conductor;
mod dielectric;
mod fresnel;
mod ior;
mod lambertian;
mod metals;
pub mod microfacet;
mod oren_nayar;
mod plastic;
mod rough_dielectric;
mod specular;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_rough;
mod thin_film;

pub use conductor::Conductor;
pub use dielectric::{Dielectric, Outside};
pub use fresnel::{fresnel_conductor, fresnel_dielectric, refract};
pub use ior::{Ior, NAMED_GLASSES, named_glass};
pub use lambertian::Lambertian;
pub use metals::{NAMED_METALS, named_metal};
pub use oren_nayar::OrenNayar;
pub use plastic::Plastic;
pub use specular::Mirror;
pub use thin_film::{ThinFilm, ThinSheet, airy};

/// The largest GGX α of a glossy lobe ([`Bxdf::is_glossy`]). At α = 0.08 (the
/// gold of `scenes/environment.ron`) the sun's reflection onto the floor was
/// about half of `caustics`' error as camera paths found it (fireflies where a
/// diffuse bounce happened to hit the gold and then the sun); light subpaths
/// aimed at the gold find it at every subpath.
pub const GLOSSY_ALPHA: f32 = 0.1;

use glam::{Vec2, Vec3};

use crate::color::{Sampled, Spectrum};
use crate::spectral::Lambdas;

/// A sampled direction with its value and pdf.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample<const N: usize> {
    /// The sampled direction (local frame).
    pub wi: Vec3,
    /// `f(wo, wi)` (for delta lobes: the lobe weight divided by |cos θi|).
    pub f: Sampled<N>,
    /// The pdf of `wi` per unit solid angle (for delta lobes: the lobe probability).
    pub pdf: f32,
    /// True when `wi` was chosen from a delta distribution (mirror, glass).
    pub is_delta: bool,
    /// The relative index of refraction crossed (`η_t / η_i`; 1 for reflection),
    /// for Russian roulette's η² factor.
    pub eta: f32,
}

/// The closed set of scattering models.
#[derive(Clone, Debug)]
pub enum Bxdf {
    /// A surface that absorbs everything (for example a light's own body).
    Black,
    /// Ideal diffuse reflection.
    Lambertian(Lambertian),
    /// Rough diffuse reflection (Oren-Nayar 1994).
    OrenNayar(OrenNayar),
    /// Perfect specular reflection.
    Mirror(Mirror),
    /// A smooth dielectric interface (glass, water): Fresnel reflection and refraction.
    Dielectric(Dielectric),
    /// A metal with a complex index, smooth or rough (GGX).
    Conductor(Conductor),
    /// A dielectric coat over a diffuse base (coated diffuse).
    Plastic(Plastic),
    /// A free-standing thin film (soap film): interference reflection, straight transmission.
    ThinSheet(ThinSheet),
    /// An index-matched boundary: light passes straight through; it only
    /// bounds a volume (and the medium inside it).
    Interface,
}

impl Bxdf {
    /// The same lobe with reflectance `r` (a texture's value at a hit) for the
    /// models whose reflectance may be textured (Lambertian, Oren-Nayar,
    /// mirror, plastic); any other model unchanged.
    pub fn with_reflectance(&self, r: Spectrum) -> Bxdf {
        match self {
            Bxdf::Lambertian(_) => Bxdf::Lambertian(Lambertian { reflectance: r }),
            Bxdf::OrenNayar(o) => {
                let mut o = *o;
                o.reflectance = r;
                Bxdf::OrenNayar(o)
            }
            Bxdf::Mirror(_) => Bxdf::Mirror(Mirror { reflectance: r }),
            Bxdf::Plastic(p) => Bxdf::Plastic(p.with_reflectance(r)),
            other => other.clone(),
        }
    }

    /// Sets the GGX α of the models with one (Conductor, Dielectric,
    /// Plastic: a roughness texture's value at a hit); others unchanged.
    pub fn set_roughness(&mut self, alpha: f32) {
        match self {
            Bxdf::Conductor(c) => c.alpha = alpha,
            Bxdf::Dielectric(d) => d.set_roughness(alpha),
            Bxdf::Plastic(p) => p.set_roughness(alpha),
            _ => {}
        }
    }

    /// Sets the thickness of the thin film of the models with one (a
    /// `ThinFilm` coating on a Conductor or Dielectric, a ThinSheet: a
    /// thickness texture's value at a hit); others unchanged.
    pub fn set_thickness_nm(&mut self, nm: f32) {
        match self {
            Bxdf::Conductor(c) => {
                if let Some(film) = &mut c.coating {
                    film.thickness_nm = nm;
                }
            }
            Bxdf::Dielectric(d) => d.set_coating_thickness_nm(nm),
            Bxdf::ThinSheet(s) => s.film.thickness_nm = nm,
            _ => {}
        }
    }

    /// `f(wo, wi)` for the packet (zero for delta models).
    #[inline]
    pub fn eval<const N: usize>(&self, wo: Vec3, wi: Vec3, lambdas: &Lambdas<N>) -> Sampled<N> {
        self.eval_within(wo, wi, lambdas, Outside::VACUUM)
    }

    /// [`Bxdf::eval`] with `outside` on a dielectric's outside (other models ignore it).
    #[inline]
    pub fn eval_within<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        lambdas: &Lambdas<N>,
        outside: Outside<'_>,
    ) -> Sampled<N> {
        match self {
            Bxdf::Lambertian(m) => m.eval(wo, wi, lambdas),
            Bxdf::OrenNayar(m) => m.eval(wo, wi, lambdas),
            Bxdf::Conductor(m) => m.eval(wo, wi, lambdas),
            Bxdf::Plastic(m) => m.eval(wo, wi, lambdas),
            Bxdf::Dielectric(m) => m.eval_packet(wo, wi, m.relative_eta_for(lambdas, outside), lambdas),
            Bxdf::Black | Bxdf::Mirror(_) | Bxdf::ThinSheet(_) | Bxdf::Interface => Sampled::splat(0.0),
        }
    }

    /// Samples `wi` given `wo`, two uniform numbers `u` and one `uc` (lobe
    /// choice), for the packet `lambdas` (see the module docs for dispersion).
    #[inline]
    pub fn sample<const N: usize>(&self, wo: Vec3, u: Vec2, uc: f32, lambdas: &Lambdas<N>) -> Option<BsdfSample<N>> {
        self.sample_within(wo, u, uc, lambdas, Outside::VACUUM)
    }

    /// [`Bxdf::sample`] with `outside` on a dielectric's outside (other models ignore it).
    #[inline]
    pub fn sample_within<const N: usize>(
        &self,
        wo: Vec3,
        u: Vec2,
        uc: f32,
        lambdas: &Lambdas<N>,
        outside: Outside<'_>,
    ) -> Option<BsdfSample<N>> {
        match self {
            Bxdf::Black => None,
            Bxdf::Lambertian(m) => m.sample(wo, u, lambdas),
            Bxdf::OrenNayar(m) => m.sample(wo, u, lambdas),
            Bxdf::Mirror(m) => m.sample(wo, lambdas),
            Bxdf::Dielectric(m) => m.sample_any(wo, u, uc, m.relative_eta_for(lambdas, outside), lambdas),
            Bxdf::Conductor(m) => m.sample(wo, u, lambdas),
            Bxdf::Plastic(m) => m.sample(wo, u, uc, lambdas),
            Bxdf::ThinSheet(m) => m.sample(wo, uc, lambdas),
            Bxdf::Interface => {
                // Straight on, weight 1: f |cos| / pdf = 1.
                let cos = wo.z.abs();
                (cos > 0.0).then(|| BsdfSample {
                    wi: -wo,
                    f: Sampled::splat(1.0 / cos),
                    pdf: 1.0,
                    is_delta: true,
                    eta: 1.0,
                })
            }
        }
    }

    /// Which of [`Bxdf::sample_within`]'s numbers this model reads: the 2D
    /// direction draw `u` and the 1D lobe choice `uc`. A draw it never reads
    /// need not be drawn (the sampler's `get_1d_if` and `get_2d_if`).
    #[inline]
    pub fn reads_draws(&self) -> (bool, bool) {
        match self {
            Bxdf::Black | Bxdf::Mirror(_) | Bxdf::Interface => (false, false),
            Bxdf::Lambertian(_) | Bxdf::OrenNayar(_) => (true, false),
            Bxdf::Conductor(m) => (!m.is_smooth(), false),
            Bxdf::Dielectric(m) => (!m.is_smooth(), true),
            Bxdf::Plastic(_) => (true, true),
            Bxdf::ThinSheet(_) => (false, true),
        }
    }

    /// The pdf of sampling `wi` given `wo` for the packet `lambdas` (zero
    /// for delta models; rough glass samples at the packet's index, as `sample`).
    #[inline]
    pub fn pdf<const N: usize>(&self, wo: Vec3, wi: Vec3, lambdas: &Lambdas<N>) -> f32 {
        self.pdf_within(wo, wi, lambdas, Outside::VACUUM)
    }

    /// [`Bxdf::pdf`] with `outside` on a dielectric's outside (other models ignore it).
    #[inline]
    pub fn pdf_within<const N: usize>(&self, wo: Vec3, wi: Vec3, lambdas: &Lambdas<N>, outside: Outside<'_>) -> f32 {
        match self {
            Bxdf::Lambertian(_) | Bxdf::OrenNayar(_) => lambertian::pdf(wo, wi),
            Bxdf::Conductor(m) => m.pdf(wo, wi),
            Bxdf::Plastic(m) => m.pdf(wo, wi, lambdas),
            Bxdf::Dielectric(m) => m.pdf_packet(wo, wi, m.relative_eta_for(lambdas, outside), lambdas),
            Bxdf::Black | Bxdf::Mirror(_) | Bxdf::ThinSheet(_) | Bxdf::Interface => 0.0,
        }
    }

    /// The dielectric, when this model is one (a medium for nested dielectrics).
    #[inline]
    pub fn as_dielectric(&self) -> Option<&Dielectric> {
        match self {
            Bxdf::Dielectric(d) => Some(d),
            _ => None,
        }
    }

    /// True for a glossy lobe: a rough conductor or rough dielectric (one
    /// microfacet lobe) with GGX α at most [`GLOSSY_ALPHA`]. `--integrator
    /// caustics` gives the caustics such a lobe casts to its light side, as
    /// those of a delta lobe (`crate::integrator::caustics`).
    #[inline]
    pub fn is_glossy(&self) -> bool {
        match self {
            Bxdf::Conductor(c) => !c.is_smooth() && c.alpha <= GLOSSY_ALPHA,
            Bxdf::Dielectric(d) => !d.is_smooth() && d.roughness() <= GLOSSY_ALPHA,
            _ => false,
        }
    }

    /// True when a hit on this material may be glossy ([`Bxdf::is_glossy`]):
    /// it is glossy, or its roughness is a texture (`textured_roughness`) on a
    /// rough conductor or dielectric, whose value at some hit may be.
    pub fn may_be_glossy(&self, textured_roughness: bool) -> bool {
        let rough = match self {
            Bxdf::Conductor(c) => !c.is_smooth(),
            Bxdf::Dielectric(d) => !d.is_smooth(),
            _ => false,
        };
        self.is_glossy() || (textured_roughness && rough)
    }

    /// True when the model's directions are all delta (no light sampling pays).
    #[inline]
    pub fn is_delta(&self) -> bool {
        match self {
            Bxdf::Mirror(_) | Bxdf::ThinSheet(_) | Bxdf::Interface => true,
            Bxdf::Dielectric(d) => d.is_smooth(),
            Bxdf::Conductor(c) => c.is_smooth(),
            Bxdf::Black | Bxdf::Lambertian(_) | Bxdf::OrenNayar(_) | Bxdf::Plastic(_) => false,
        }
    }

    /// True when `sample` may return a delta direction (`BsdfSample::is_delta`):
    /// the all-delta models and a smooth Plastic's coat. A textured roughness
    /// does not change it (a material's smoothness is decided once).
    #[inline]
    pub fn has_delta_lobe(&self) -> bool {
        match self {
            Bxdf::Plastic(p) => p.is_smooth(),
            b => b.is_delta(),
        }
    }

    /// How the model disperses, when `sample`'s direction depends on the
    /// wavelength; `None` otherwise.
    #[inline]
    pub fn dispersion(&self) -> Option<Dispersion<'_>> {
        self.dispersion_within(Outside::VACUUM)
    }

    /// [`Bxdf::dispersion`] with `outside` on a dielectric's outside: an
    /// interface disperses when either side's index varies with wavelength.
    #[inline]
    pub fn dispersion_within<'a>(&'a self, outside: Outside<'a>) -> Option<Dispersion<'a>> {
        match self {
            Bxdf::Dielectric(d) if d.ior().is_dispersive() || outside.is_dispersive() => {
                Some(Dispersion { glass: d, outside })
            }
            _ => None,
        }
    }

    /// True when `sample`'s direction depends on the wavelength.
    #[inline]
    pub fn is_dispersive(&self) -> bool {
        self.dispersion().is_some()
    }

    /// The absorption coefficient (per unit length) inside the model, for
    /// an absorbing dielectric: the integrators attenuate every segment that
    /// runs in it (as the interior [`crate::medium::Medium`] of its volume) by `exp(−σ t)`.
    #[inline]
    pub fn absorption(&self) -> Option<&Spectrum> {
        match self {
            Bxdf::Dielectric(d) => d.absorption(),
            _ => None,
        }
    }

    /// True when the model bounds a volume (a dielectric or an index-matched
    /// interface): its inside is a medium for the volume stack.
    #[inline]
    pub fn bounds_volume(&self) -> bool {
        matches!(self, Bxdf::Dielectric(_) | Bxdf::Interface)
    }

    /// True for an index-matched boundary ([`Bxdf::Interface`]).
    #[inline]
    pub fn is_interface(&self) -> bool {
        matches!(self, Bxdf::Interface)
    }

    /// True when the model absorbs everything (a path ends here).
    #[inline]
    pub fn is_black(&self) -> bool {
        matches!(self, Bxdf::Black)
    }
}

/// A dispersive model seen by an integrator that splits wavelengths there:
/// a specular reflection whose direction is the same for every wavelength,
/// and a refraction whose direction depends on it. [`Bxdf::dispersion`]
/// hands it out, so integrators never match a model by name.
#[derive(Clone, Copy, Debug)]
pub struct Dispersion<'a> {
    glass: &'a Dielectric,
    outside: Outside<'a>,
}

impl Dispersion<'_> {
    /// True for smooth glass: its reflection sends every wavelength the same
    /// way, so `auto` may keep the full spectrum there. A rough dispersive
    /// glass is instead split into single wavelengths before sampling (each
    /// then samples, and takes its light sample, at its own index).
    #[inline]
    pub fn is_smooth(&self) -> bool {
        self.glass.is_smooth()
    }

    /// The relative index (inside / outside) at the reference wavelength, 589.3 nm.
    #[inline]
    pub fn reference_eta(&self) -> f32 {
        self.glass.reference_eta() / self.outside.reference_eta()
    }

    /// The relative index at fractional bin position `pos`.
    #[inline]
    pub fn eta_at(&self, pos: f32) -> f32 {
        self.glass.eta_at(pos) / self.outside.eta_at(pos)
    }

    /// The reflectance at incidence cosine `cos` for the bin at fractional
    /// position `pos`, at that bin's relative index (the film's where the glass is coated).
    #[inline]
    pub fn reflectance_at(&self, cos: f32, pos: f32) -> f32 {
        self.glass.reflectance_at(cos, self.eta_at(pos), self.outside.eta_at(pos), pos)
    }

    /// The reflectance at the reference wavelength (589.3 nm) for incidence cosine `cos`.
    #[inline]
    pub fn reference_reflectance(&self, cos: f32) -> f32 {
        self.glass.reflectance_at(
            cos,
            self.reference_eta(),
            self.outside.reference_eta(),
            (crate::spectral::REFERENCE_LAMBDA_NM - crate::color::LAMBDA_MIN_NM) / crate::color::LAMBDA_STEP_NM,
        )
    }

    /// The reflectance at each of the packet's wavelengths for `wo`.
    #[inline]
    pub fn reflectance<const N: usize>(&self, wo: Vec3, lambdas: &Lambdas<N>) -> Sampled<N> {
        self.glass.reflectance(wo, lambdas, self.outside)
    }

    /// The refraction alone for a single wavelength, as a sample of
    /// probability 1 whose weight is the radiance scaling `1 / η²` (the
    /// integrator has already chosen refraction and weighted it); `None` on
    /// total internal reflection.
    #[inline]
    pub fn sample_refraction(&self, wo: Vec3, lambdas: &Lambdas<1>) -> Option<BsdfSample<1>> {
        self.glass.sample_refraction(wo, self.glass.relative_eta_for(lambdas, self.outside).0)
    }
}

#[cfg(test)]
pub(crate) mod test_util {
    //! Helpers shared by the models' tests.
    use super::*;
    use crate::color::Spectrum;
    use crate::sampler::Sampler;

    /// Checks, for `n` samples at `wo`, that `sample` agrees with `eval` and
    /// `pdf` for the sampled direction, and returns the albedo estimate
    /// (mean of f |cos| / pdf) for the full spectrum.
    pub fn check_sample_consistency(b: &Bxdf, wo: Vec3, n: usize) -> Spectrum {
        let l = Lambdas::full();
        let mut s = Sampler::new(3, 5, 7);
        let mut albedo = Spectrum::ZERO;
        for _ in 0..n {
            let Some(bs) = b.sample(wo, s.next_2d(), s.next_1d(), &l) else {
                continue;
            };
            assert!(bs.pdf > 0.0 && !bs.f.has_nan_or_inf(), "bad sample {bs:?}");
            assert!((bs.wi.length() - 1.0).abs() < 1e-4);
            if !bs.is_delta {
                let f = b.eval(wo, bs.wi, &l);
                for i in 0..36 {
                    assert!((f[i] - bs.f[i]).abs() <= 1e-5 * f[i].abs().max(1.0), "eval != sample at bin {i}");
                }
                assert!((b.pdf(wo, bs.wi, &l) - bs.pdf).abs() <= 1e-4 * bs.pdf);
            }
            let w = bs.f * (bs.wi.z.abs() / bs.pdf);
            albedo += w;
        }
        albedo / n as f32
    }
}
