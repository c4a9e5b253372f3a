use clap::Parser;
use nbody_bench::cli::Cli;
use std::process::ExitCode;

fn main() -> ExitCode {
    // clap exits with code 2 on usage errors and 0 for --help/--version.
    let cli = Cli::parse();
    match nbody_bench::commands::dispatch(cli) {
        Ok(code) => ExitCode::from(code as u8),
        Err(err) => {
            eprintln!("error: {}", nbody_bench::commands::error_chain(&err));
            ExitCode::from(2)
        }
    }
}
