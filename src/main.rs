fn main() {
    std::process::exit(armscope::cli::main_with_args(std::env::args_os()));
}
