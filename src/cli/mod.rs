//! The binary's room: the command line ([`args`], the only user of clap),
//! one file per command family, and the console (progress, summaries,
//! the thread pool).
//!
//! - [`render`]: `render`, `resume` and `merge`; a render runs through
//!   [`session`] (signals, snapshots, checkpoints, the final outputs);
//! - [`study`]: `compare` and `converge`, the faces of [`rust_v::study`];
//! - [`convert`]: `convert`, a pbrt-v4 scene to RON;
//! - [`console`]: what the user sees on stderr while it runs.
//!
//! `main` only parses, calls [`run`], prints the error and picks the exit code.

pub mod args;
mod console;
mod convert;
mod memory;
mod render;
mod session;
mod study;

use rust_v::error::Result;

use args::{Cli, Command};

/// Runs a parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Render(args) => render::render_command(args),
        Command::Resume(args) => render::resume_command(args),
        Command::Merge(args) => render::merge_command(args),
        Command::Compare(args) => study::compare_command(args),
        Command::Converge(args) => study::converge_command(args),
        Command::Convert(args) => convert::convert_command(args),
    }
}
