//! The `lobes` binary: parses the command line and runs it.
//!
//! Exit codes: [`lobes::cli::EXIT_CODES`] (0 success, 1 checks failed, 2 bad input, 3 the tool
//! could not do the work, 130 interrupted). lobes' own messages on stderr start with `lobes: `.

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    // Mesa's device-select layer prints "error: XDG_RUNTIME_DIR is invalid or not set" on every
    // headless run, which reads like lobes' own error; wgpu chooses the adapter itself, so the
    // layer is switched off unless the user set it up (NODEVICE_SELECT, MESA_VK_DEVICE_SELECT).
    // Here, before any thread or wgpu instance exists, changing the environment is sound.
    if std::env::var_os("NODEVICE_SELECT").is_none() && std::env::var_os("MESA_VK_DEVICE_SELECT").is_none() {
        // SAFETY: single-threaded at this point; nothing reads the environment concurrently.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
    // clap's usage errors get lobes' prefix and exit with 2; --help and --version print to
    // stdout and exit with 0.
    let cli = match lobes::cli::Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if e.use_stderr() => {
            // clap's rendering ends with its newline
            lobes::console::say(format_args!("lobes: {}", e.render().to_string().trim_end()));
            return ExitCode::from(lobes::cli::EXIT_USAGE);
        }
        Err(e) => e.exit(),
    };
    // on a thread with a large stack: wgpu parses a user's WGSL again, and writes it as SPIR-V,
    // recursing once per level of an expression (lobes::engine::gpu::stack)
    match lobes::engine::gpu::stack::with_big_stack(|| cli.run()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            let code = lobes::cli::exit_code(&err);
            if code == lobes::cli::EXIT_INTERRUPTED {
                lobes::console::say(format_args!("lobes: {err:#}"));
            } else {
                lobes::console::say(format_args!("lobes: error: {err:#}"));
            }
            ExitCode::from(code)
        }
    }
}
