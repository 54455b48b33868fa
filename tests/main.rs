//! Integration tests, one binary organised by area (ripgrep style).
//!
//! Tests that render keep images tiny (16x16 to 32x32) and sample counts
//! small; statistical tests state their tolerance and where it comes from.

mod common;

mod auto;
mod bdpt;
mod camera;
mod caustics;
mod checkpoint;
mod cli;
mod docs;
mod emitsample;
mod environment;
mod furnace;
mod fuzz;
mod hostile;
mod instances;
mod lights;
mod media;
mod memory;
mod metrics;
mod mix;
mod output;
mod pbrt;
mod pbrt_envmap;
mod pbrt_media;
mod pbrt_real;
mod sampler;
mod scenes;
mod sensor;
mod spectra;
mod spectral;
mod stability;
mod surround;
mod textures;
