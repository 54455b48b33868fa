//! rust-v: a physically based spectral path tracer.
#![forbid(unsafe_code)]

pub mod error;
pub mod geometry;
pub mod color;
pub mod bvh;

pub use error::{Error, Result};
