fn main() {
    std::process::exit(trum_cli::main_with_args(std::env::args_os()));
}
