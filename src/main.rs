fn main() {
    armscope::allocator::return_freed_memory_soon();
    // before anything else, so that Ctrl-C during start-up also ends the run cleanly
    armscope::cli::install_interrupt_handler();
    std::process::exit(armscope::cli::main_with_args(std::env::args_os()));
}

// Rerun's and MCAP's encoders allocate and free many short-lived buffers on their threads;
// glibc's per-thread arenas spend much of that in the kernel (mprotect/madvise).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;
