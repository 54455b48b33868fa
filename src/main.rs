//! The `rust-v` binary: parse the command line, run, print errors, exit.

mod cli;
mod session;
mod study;

use clap::Parser;

fn main() -> std::process::ExitCode {
    let cli = cli::Cli::parse();
    match cli::run(cli) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            // The library's errors carry their causes in their message.
            eprintln!("rust-v: error: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}
