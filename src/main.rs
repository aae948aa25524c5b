//! The `vehsim` binary: all work is in the library's [`vehsim::cli`].

fn main() -> std::process::ExitCode {
    vehsim::cli::main()
}
