//! Colour: 36-bin spectra, CIE 1931 colorimetry, sRGB conversion and named spectra.
//!
//! The renderer transports light as [`Spectrum`] values (380-730 nm, 10 nm bins; the one
//! spectral arithmetic, [`Sampled`], in `spectrum.rs`), converts to CIE XYZ with the
//! exact colour integral of the interpolated spectrum ([`color_weights`], `cie.rs`), and to sRGB with the
//! same matrix as Mitsuba 3 ([`XYZ_TO_LINEAR_SRGB`], `rgb.rs`). `named.rs` holds the spectra a
//! scene file can refer to ([`color_checker`], [`d65`], [`blackbody`]); `uplift.rs` turns linear
//! sRGB into spectra ([`rgb_reflectance`], [`rgb_emission`]); `space.rs` holds the EXR output spaces
//! ([`ColorSpace`]).

mod cie;
mod named;
mod rgb;
mod sensor;
mod space;
mod spectrum;
mod tonemap;
mod uplift;

pub use cie::{CMF, INTEGRAL_RANGE_NM, bin_xyz, cmf_at, color_weights, color_weights_f64, tent, tent_weights};
pub use named::{COLOR_CHECKER_NAMES, blackbody, color_checker, d65, equal_energy, planck, reflectance_to_xyz};
pub use rgb::{
    LINEAR_SRGB_TO_XYZ, LinearSrgb, Srgb, XYZ_TO_LINEAR_SRGB, Xyz, srgb_eotf, srgb_oetf, xyz_to_linear_srgb_f64,
};
pub use sensor::{CIE1931, Matrix3, Sensor, color_checker_pairs};
pub use space::ColorSpace;
pub use spectrum::{LAMBDA_MIN_NM, LAMBDA_STEP_NM, N_BINS, Sampled, Spectrum, bin_lambda_nm};
pub use tonemap::Tonemap;
pub use uplift::{
    Uplift, emission_spectrum, emission_uplift, fit_rows, reflectance_to_linear_srgb, rgb_emission, rgb_reflectance,
};
