//! The `lobes` binary: parses the command line and runs it.
//!
//! Exit codes: 0 on success, 2 for bad input (clap's usage errors and
//! [`lobes::cli::UsageError`]), 1 for runtime failures.

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    // clap prints its own usage errors and exits with 2 (0 for --help/--version).
    let cli = lobes::cli::Cli::parse();
    match cli.run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err:#}");
            ExitCode::from(lobes::cli::exit_code(&err))
        }
    }
}
