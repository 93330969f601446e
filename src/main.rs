//! rinscope: see the errors of a rotational inertial navigation system in the Rerun viewer (the
//! command line is `rinscope::cli`).

fn main() -> std::process::ExitCode {
    rinscope::cli::main()
}
