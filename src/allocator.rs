//! The process's allocator (mimalloc, set in main.rs and the benchmarks): its settings.

/// mimalloc gives freed pages back to the OS only after a delay (10 ms). The recorders' threads
/// free, in bursts, what the simulation thread allocated; with the delay, freed pages pile up and a
/// 10-minute run with both recordings peaked at 60 MB, twice the 30 s run's. With a 1 ms delay memory
/// stays within 1.32× of the 30 s run's (`cargo bench --bench scaling`: 31 MB at 30 s, 41 MB at 10
/// min, 36 MB at 1 h). Purging at once (0 ms) kept it flatter (29 / 37 / 35 MB) but madvise'd and
/// faulted pages back in all the time: the tutorial batch (13 runs, two at once, with the comparison)
/// spent 1.29 s in the kernel and took 1.85 s; with 1 ms, 0.92 s and 1.51 s (medians of 7 runs, interleaved).
pub fn return_freed_memory_soon() {
    // `mi_option_purge_delay` in mimalloc.h's `mi_option_e` (v2 and v3); libmimalloc-sys 0.1.49
    // names no constant for it
    const MI_OPTION_PURGE_DELAY: libmimalloc_sys::mi_option_t = 15;
    // SAFETY: sets a global option of the allocator; mimalloc reads it on its next purge
    unsafe { libmimalloc_sys::mi_option_set(MI_OPTION_PURGE_DELAY, 1) }; // ms
}
