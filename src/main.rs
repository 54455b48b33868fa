//! The `rust-v` binary: parse the command line, run, print errors, exit.

mod cli;

use clap::Parser;

fn main() -> std::process::ExitCode {
    let cli = cli::args::Cli::parse();
    match cli::run(cli) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            // The library's errors carry their causes in their message.
            eprintln!("rust-v: error: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}
