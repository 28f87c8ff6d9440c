//! The process's allocator (mimalloc, set in main.rs and the benchmarks): its settings.

/// mimalloc gives freed pages back to the OS only after a delay (10 ms). The recorders' threads
/// free, in bursts, what the simulation thread allocated; with the delay, freed pages pile up and a
/// 10-minute run with both recordings peaked at 60 MB, twice the 30 s run's. Purged at once, memory
/// stays flat (`cargo bench --bench scaling`: 29 MB at 30 s, 37 MB at 10 min, 35 MB at 1 h). It costs
/// time, the price of that bound: a 30 s run with both files 0.126 s against 0.116 (medians of 20,
/// +9 %), 10 min 2.19 s against 1.94 (+13 %). A 1 ms delay costs +5 % and peaks at 1.3× the 30 s run.
pub fn return_freed_memory_at_once() {
    // `mi_option_purge_delay` in mimalloc.h's `mi_option_e` (v2 and v3); libmimalloc-sys 0.1.49
    // names no constant for it
    const MI_OPTION_PURGE_DELAY: libmimalloc_sys::mi_option_t = 15;
    // SAFETY: sets a global option of the allocator; mimalloc reads it on its next purge
    unsafe { libmimalloc_sys::mi_option_set(MI_OPTION_PURGE_DELAY, 0) };
}
