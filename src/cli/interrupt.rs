//! SIGINT (Ctrl-C) and SIGTERM during `lobes run` and `lobes check`: the first signal asks the
//! command to stop (`run`: after the lobe case in flight; a user's sampler case, and `check`,
//! at once: the GPU's waits see [`requested`] through
//! [`crate::engine::gpu::Gpu::stop_when`]), and the command then reports and writes what
//! finished ([`super::Interrupted`]); a second one ends the process at once with
//! [`super::EXIT_INTERRUPTED`]. Every file lobes writes is atomic ([`crate::report::atomic`])
//! and a case's `histogram.json` comes last, so a case cut short that way leaves a folder
//! without `histogram.json`: recognisably incomplete.

use signal_hook::consts::{SIGINT, SIGTERM};
use signal_hook::iterator::Signals;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

/// Whether a signal arrived since [`watch`].
static REQUESTED: AtomicBool = AtomicBool::new(false);

/// What to do before a second signal ends the process ([`before_exit`]).
static BEFORE_EXIT: Mutex<Option<Box<dyn FnOnce() + Send>>> = Mutex::new(None);

/// Sets what a second signal does before it ends the process (`lobes run` writes its summary
/// files: every exit the process survives leaves them).
pub fn before_exit(f: impl FnOnce() + Send + 'static) {
    *BEFORE_EXIT.lock().unwrap_or_else(|p| p.into_inner()) = Some(Box::new(f));
}

/// Starts watching for SIGINT and SIGTERM, on a thread of its own (where printing is safe);
/// `first` is what the first signal prints after "lobes: interrupted: ". With a `grace`, a
/// process still running that long after the first signal ends as a second signal ends it:
/// the command's own stop (seen within 50 ms of a wait on the GPU) did not come back, because a
/// thread is held in the GPU driver (a shader that never returns, a driver call that waits for
/// it), and nothing then holds the process.
pub fn watch(first: &'static str, grace: Option<std::time::Duration>) -> anyhow::Result<()> {
    let mut signals = Signals::new([SIGINT, SIGTERM]).map_err(|e| anyhow::anyhow!("cannot watch for Ctrl-C: {e}"))?;
    std::thread::spawn(move || {
        for _ in signals.forever() {
            if REQUESTED.swap(true, Ordering::SeqCst) {
                end_now("lobes: interrupted again: stopping now; the case in flight has no histogram.json");
            }
            crate::console::say(format_args!("lobes: interrupted: {first}"));
            if let Some(grace) = grace {
                std::thread::spawn(move || {
                    std::thread::sleep(grace);
                    end_now(&format!("lobes: interrupted: no report {:.0} s after the signal (a thread is held in the GPU driver): stopping now; no verdict", grace.as_secs_f64()));
                });
            }
        }
    });
    Ok(())
}

/// Says `why`, does what [`before_exit`] set and ends the process with [`super::EXIT_INTERRUPTED`].
fn end_now(why: &str) -> ! {
    crate::console::say(why);
    if let Some(f) = BEFORE_EXIT.lock().unwrap_or_else(|p| p.into_inner()).take() {
        f();
    }
    std::process::exit(super::EXIT_INTERRUPTED.into());
}

/// Whether a stop was asked for.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::SeqCst)
}
