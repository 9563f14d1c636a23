use std::process::ExitCode;

fn main() -> ExitCode {
    heliodon::cli::main()
}
