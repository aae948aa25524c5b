//! The `vehsim` binary: SIGINT/SIGTERM handling, a broken pipe on stdout as a clean exit, then the
//! library's [`vehsim::cli`], which maps every error to its exit code in one place.

fn main() -> std::process::ExitCode {
    vehsim::output::signals::install();
    vehsim::output::signals::quiet_broken_pipe();
    vehsim::cli::main()
}
