//! The `rust-v` binary: parse the command line, run, print errors, exit.
//!
//! Exit status: 0 success (including a render stopped by SIGINT/SIGTERM
//! whose work was saved, and `--help`), 1 an error while running (bad scene,
//! unwritable output, ...), 2 a usage error (unknown flag, bad flag value),
//! 130/143 SIGINT/SIGTERM while a scene was still loading. Every error is one
//! line, `rust-v: error: ...`, on stderr.

mod cli;

use std::io::Write;
use std::process::ExitCode;

use clap::Parser;
use clap::error::ErrorKind;

fn main() -> ExitCode {
    let cli = match cli::args::Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) => {
            // Help and version go to stdout as clap formats them; a closed stdout is not an error.
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            error_line(&usage_line(&e.render().to_string()));
            return ExitCode::from(2);
        }
    };
    match cli::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // The library's errors carry their causes in their message.
            error_line(&e.to_string());
            ExitCode::FAILURE
        }
    }
}

/// Writes `rust-v: error: MESSAGE`, ignoring a closed or full stderr.
fn error_line(message: &str) {
    let _ = writeln!(std::io::stderr().lock(), "rust-v: error: {message}");
}

/// clap's multi-line usage error as one line: its paragraphs joined, the
/// `error:` prefix, the usage line and the `--help` hint dropped.
fn usage_line(rendered: &str) -> String {
    let parts: Vec<&str> = rendered
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with("Usage:") && !l.starts_with("For more information"))
        .collect();
    let joined = parts.join(" ");
    let joined = joined.strip_prefix("error: ").unwrap_or(&joined);
    format!("{joined} (see --help)")
}
