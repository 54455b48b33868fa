//! Materials: a material is built from its description once at load; `bxdf/`
//! stays the pure lobes (reflection models that know nothing of the scene
//! format).
//!
//! Data flow: `MaterialDesc` (the RON text, [`crate::scene::desc`]) →
//! `from_desc` here (checks every field, looks up named metals and glasses,
//! builds spectra and indices) → [`Bxdf`] (stored once per named material in
//! [`crate::scene::Scene::materials`]; objects refer to it by index), and,
//! where the reflectance (Lambertian, OrenNayar, Mirror and Plastic), the
//! roughness (Conductor, Dielectric, Plastic) or a thin film's thickness is
//! a texture (`Image`, `Checkerboard`), the [`MaterialTextures`] beside it,
//! which [`crate::scene::Scene::bsdf_in`] applies at each hit
//! ([`Bxdf::with_reflectance`], [`Bxdf::set_roughness`], [`Bxdf::set_thickness_nm`]).
//!
//! A `Mix` is no lobe: [`mix`] builds it once every material is named, and
//! the scene resolves it to one of its materials at each hit.
//!
//! Errors name the scene file and the field path
//! (`materials."gold".roughness`) and what was expected.

use crate::bxdf::{
    Bxdf, Conductor, Dielectric, Lambertian, Mirror, NAMED_METALS, OrenNayar, Plastic, ThinFilm, ThinSheet, named_metal,
};
use crate::color::{self, N_BINS};
use crate::error::Result;
use crate::scene::check::Check;
use crate::scene::desc::{CoatingDesc, IorDesc, MaterialDesc, ScalarDesc, SpectrumDesc};
use crate::texture::{self, MaterialTextures};

pub mod mix;
pub use mix::Mix;

/// The [`Bxdf`] of a material description at `field` (`materials."name"`), and
/// its textures if it has any.
pub(crate) fn from_desc(check: &Check, field: &str, d: &MaterialDesc) -> Result<(Bxdf, Option<MaterialTextures>)> {
    let reflectance = match d {
        MaterialDesc::Lambertian { reflectance }
        | MaterialDesc::OrenNayar { reflectance, .. }
        | MaterialDesc::Mirror { reflectance }
        | MaterialDesc::Plastic { reflectance, .. } => {
            texture::from_desc(check, &format!("{field}.reflectance"), reflectance)?
        }
        _ => None,
    };
    let roughness = match d {
        MaterialDesc::Dielectric { roughness: ScalarDesc::Texture(t), .. }
        | MaterialDesc::Conductor { roughness: ScalarDesc::Texture(t), .. }
        | MaterialDesc::Plastic { roughness: ScalarDesc::Texture(t), .. } => {
            Some(texture::scalar_from_desc(check, &format!("{field}.roughness"), t, (0.0, 1.0), "a GGX alpha")?)
        }
        _ => None,
    };
    let (film_field, thickness) = match d {
        MaterialDesc::Dielectric { coating: Some(CoatingDesc::ThinFilm { thickness_nm, .. }), .. }
        | MaterialDesc::Conductor { coating: Some(CoatingDesc::ThinFilm { thickness_nm, .. }), .. } => {
            (format!("{field}.coating.thickness_nm"), thickness_nm)
        }
        MaterialDesc::ThinSheet { thickness_nm, .. } => (format!("{field}.thickness_nm"), thickness_nm),
        _ => (String::new(), &ScalarDesc::Value(0.0)),
    };
    let thickness_nm = match thickness {
        ScalarDesc::Texture(t) => {
            Some(texture::scalar_from_desc(check, &film_field, t, (0.0, MAX_THICKNESS_NM), "a thickness in nm")?)
        }
        ScalarDesc::Value(_) => None,
    };
    // A textured material's lobe is built with a stand-in reflectance (grey
    // ½), roughness (α ½: rough, as every value of the texture is) and
    // thickness, each replaced at every hit.
    const STAND_IN: &SpectrumDesc = &SpectrumDesc::Constant(0.5);
    let textured = reflectance.is_some();
    let bxdf = bxdf_of(check, field, d, |r| if textured { STAND_IN } else { r })?;
    let textures = MaterialTextures { reflectance, roughness, thickness_nm };
    Ok((bxdf, (!textures.is_empty()).then_some(textures)))
}

/// The largest thin-film thickness, in nm.
const MAX_THICKNESS_NM: f32 = 1e7;

/// The [`Bxdf`] of a material description, its reflectance description passed through `reflectance`.
fn bxdf_of<'a>(
    check: &Check,
    field: &str,
    d: &'a MaterialDesc,
    reflectance: impl Fn(&'a SpectrumDesc) -> &'a SpectrumDesc,
) -> Result<Bxdf> {
    Ok(match d {
        MaterialDesc::Lambertian { reflectance: r } => Bxdf::Lambertian(Lambertian {
            reflectance: check.reflectance(&format!("{field}.reflectance"), reflectance(r))?,
        }),
        MaterialDesc::OrenNayar { reflectance: r, sigma_deg } => {
            if !(sigma_deg.is_finite() && (0.0..=90.0).contains(sigma_deg)) {
                return Err(
                    check.err(format!("{field}.sigma_deg"), format!("expected degrees in [0, 90], found {sigma_deg}"))
                );
            }
            Bxdf::OrenNayar(OrenNayar::new(
                check.reflectance(&format!("{field}.reflectance"), reflectance(r))?,
                *sigma_deg,
            ))
        }
        MaterialDesc::Mirror { reflectance: r } => {
            Bxdf::Mirror(Mirror { reflectance: check.reflectance(&format!("{field}.reflectance"), reflectance(r))? })
        }
        MaterialDesc::Dielectric { ior, roughness, absorption, coating } => {
            let mut d = Dielectric::new(check.ior(&format!("{field}.ior"), ior)?).with_roughness(ggx_alpha(
                check,
                &format!("{field}.roughness"),
                roughness,
            )?);
            if let Some(a) = absorption {
                d = d.with_absorption(check.spectrum(&format!("{field}.absorption"), a)?);
            }
            if let Some(CoatingDesc::ThinFilm { thickness_nm, ior }) = coating {
                d = d.with_coating(thin_film(check, &format!("{field}.coating"), thickness_nm, ior)?);
            }
            Bxdf::Dielectric(d)
        }
        MaterialDesc::Conductor { metal, eta, k, roughness, coating } => {
            let (eta, k) = match (metal, eta, k) {
                (Some(name), None, None) => named_metal(name).ok_or_else(|| {
                    let names: Vec<&str> = NAMED_METALS.iter().map(|m| m.0).collect();
                    check.err(
                        format!("{field}.metal"),
                        format!("unknown metal \"{name}\"; expected one of: {}", names.join(", ")),
                    )
                })?,
                (None, Some(eta), Some(k)) => {
                    let eta_s = check.spectrum(&format!("{field}.eta"), eta)?;
                    if eta_s.min_value() <= 0.0 {
                        return Err(check.err(format!("{field}.eta"), "expected a positive index at every wavelength"));
                    }
                    (eta_s, check.spectrum(&format!("{field}.k"), k)?)
                }
                _ => {
                    return Err(check.err(field, "expected either `metal: \"Au\"` or both `eta:` and `k:` spectra"));
                }
            };
            let coating = match coating {
                None => None,
                Some(CoatingDesc::ThinFilm { thickness_nm, ior }) => {
                    Some(thin_film(check, &format!("{field}.coating"), thickness_nm, ior)?)
                }
            };
            let alpha = ggx_alpha(check, &format!("{field}.roughness"), roughness)?;
            Bxdf::Conductor(Conductor { eta, k, alpha, coating })
        }
        MaterialDesc::Plastic { reflectance: r, ior, roughness } => {
            let ior = check.ior(&format!("{field}.ior"), ior)?;
            for b in 0..N_BINS {
                let n = ior.at(color::bin_lambda_nm(b));
                if n < 1.0 {
                    return Err(check.err(
                        format!("{field}.ior"),
                        format!("a coat's index must be at least 1, found {n} at {} nm", color::bin_lambda_nm(b)),
                    ));
                }
            }
            Bxdf::Plastic(Plastic::new(
                check.reflectance(&format!("{field}.reflectance"), reflectance(r))?,
                &ior,
                ggx_alpha(check, &format!("{field}.roughness"), roughness)?,
            ))
        }
        MaterialDesc::ThinSheet { thickness_nm, ior } => {
            Bxdf::ThinSheet(ThinSheet { film: thin_film(check, field, thickness_nm, ior)? })
        }
        MaterialDesc::Black => Bxdf::Black,
        MaterialDesc::Interface => Bxdf::Interface,
        // A placeholder: `mix::build` resolves the Mix once every material is named.
        MaterialDesc::Mix { .. } => Bxdf::Black,
    })
}

/// A thin film: a thickness in [0, 1e7] nm (a texture's stand-in: 0, its
/// values are checked with the texture) and an index of at least 1.
fn thin_film(check: &Check, field: &str, thickness_nm: &ScalarDesc, ior: &IorDesc) -> Result<ThinFilm> {
    let thickness_nm = match thickness_nm {
        ScalarDesc::Value(v) => *v,
        ScalarDesc::Texture(_) => 0.0,
    };
    if !(thickness_nm.is_finite() && (0.0..=MAX_THICKNESS_NM).contains(&thickness_nm)) {
        return Err(check.err(
            format!("{field}.thickness_nm"),
            format!("expected a thickness in nm in [0, 1e7], found {thickness_nm}"),
        ));
    }
    let ior = check.ior(&format!("{field}.ior"), ior)?;
    Ok(ThinFilm::new(thickness_nm, &ior))
}

/// A GGX α: a number in [0, 1] (0 is smooth); a texture's stand-in ½ (its
/// values are checked with the texture).
fn ggx_alpha(check: &Check, field: &str, alpha: &ScalarDesc) -> Result<f32> {
    let alpha = match alpha {
        ScalarDesc::Value(v) => *v,
        ScalarDesc::Texture(_) => 0.5,
    };
    if alpha.is_finite() && (0.0..=1.0).contains(&alpha) {
        Ok(alpha)
    } else {
        Err(check.err(field, format!("expected a GGX alpha in [0, 1], found {alpha}")))
    }
}
