//! rust-v: a physically based spectral path tracer.
//!
//! Data flows one way: **scene file → [`scene::Scene`] → camera ray →
//! [`integrator`] → [`film::Film`] → image**. The [`render`] module drives it:
//! progressive passes, tiles in parallel, deterministic per-sample random numbers;
//! [`checkpoint`] saves and restores films so renders can be resumed and merged.
//!
//! # Conventions
//! - **Units**: scene units are arbitrary; wavelengths in nm; angles in the
//!   scene file in degrees (`fov_deg`, `sigma_deg`, `rotate_deg`).
//! - **Frames**: right-handed world space; the camera's `up` defaults to +y.
//!   BxDFs work in a local frame whose +z is the shading normal.
//! - **Normals**: a hit's geometric normal points out of the solid
//!   ([`geometry`]); a dielectric's inside is the side opposite the normal.
//! - **Directions**: `wo` points back along the path, `wi` towards the next
//!   vertex or the light; both away from the surface.
//! - **pdfs** are per unit solid angle unless named `_area`.
//! - **Spectra**: 36 bins, 380-730 nm every 10 nm ([`color`]), meaning the linear
//!   interpolation of the bins (flat beyond the ends); a pixel's XYZ is its exact colour
//!   integral over 360-830 nm, `Σ_b L(b) · W_b` ([`color::color_weights`]), normalised so the
//!   equal-energy spectrum of radiance 1 has `Y = 1`.
//! - **Depth**: `max_bounces` counts scattering events ([`integrator`]).
//! - **The outside** is vacuum, index 1, except inside dielectric objects,
//!   whose volumes paths track on a stack ([`medium::nested`]); a volume may
//!   hold an absorbing [`medium::Medium`].
// One module may use `unsafe`: `shape::bvh::hint` (a prefetch and `madvise`, for speed;
// see its doc). Everything else is safe Rust.
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod bxdf;
pub mod camera;
pub mod checkpoint;
pub mod color;
pub mod error;
pub mod film;
pub mod geometry;
pub mod integrator;
pub mod io;
pub mod light;
pub mod material;
pub mod medium;
pub mod render;
pub(crate) mod sampler;
pub mod scene;
pub mod settings;
pub mod shape;
pub(crate) mod spectral;
pub mod study;
pub mod texture;

pub use error::{Error, Result};
