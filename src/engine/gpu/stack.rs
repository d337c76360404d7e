//! A thread with a large stack for work that recurses once per level of a user's WGSL: naga's
//! WGSL front end lowers, and its validator and back ends walk, an expression recursively, so a
//! pdf returning a sum of 20 000 terms (20 000 levels deep) overflows an ordinary thread's stack
//! and aborts the process (exit 134). Every parse, validation and composition of WGSL that
//! lobes did not write itself runs through [`with_big_stack`], and so does the `lobes` command
//! line as a whole (wgpu parses a shader module again, and its back end writes SPIR-V, on the
//! calling thread).

/// The stack of [`with_big_stack`]'s thread: 1 GiB of address space, reserved rather than used
/// (only the pages the recursion reaches are touched), enough for expressions about 200 000
/// levels deep (naga needs 2–5 KiB a level).
pub const BIG_STACK: usize = 1 << 30;

/// Runs `f` on a thread of its own with a [`BIG_STACK`] stack and returns what it returns (a
/// panic in `f` is resumed here).
///
/// ```
/// let sum = lobes::engine::gpu::stack::with_big_stack(|| (1..=10u32).sum::<u32>());
/// assert_eq!(sum, 55);
/// ```
pub fn with_big_stack<T: Send>(f: impl FnOnce() -> T + Send) -> T {
    std::thread::scope(|s| {
        let thread = std::thread::Builder::new().name("lobes-big-stack".into()).stack_size(BIG_STACK);
        match thread.spawn_scoped(s, f) {
            Ok(handle) => handle.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)),
            // no thread to be had (a limit on threads or address space): nothing else to try
            Err(e) => panic!("lobes: cannot start a thread with a {} MiB stack to parse WGSL on: {e}", BIG_STACK >> 20),
        }
    })
}
