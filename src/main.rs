fn main() {
    // before anything else, so that Ctrl-C during start-up also ends the run cleanly
    armscope::cli::install_interrupt_handler();
    std::process::exit(armscope::cli::main_with_args(std::env::args_os()));
}
