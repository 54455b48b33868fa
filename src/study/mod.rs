//! Analysis: image metrics, convergence studies and their charts.
//!
//! These tools read images (or a film's current mean) and never reach into
//! the render core: [`metrics`] measures an image against a reference (the
//! thesis's MSE, PSNR and SSIM, windowed SSIM, linear errors), [`converge`]
//! renders progressively with several methods and records error against time
//! and samples, and [`chart`] draws the records. The `compare` and
//! `converge` subcommands are their command-line faces.

pub mod chart;
pub mod converge;
pub mod metrics;
