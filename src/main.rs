//! `nbody-bench`: the command line of the harness (its commands in `src/cli/`): parses the
//! arguments, runs the command, and exits with its code (2 after printing an error's causes).

use clap::Parser;
#[macro_use]
extern crate nbody_harness;

mod cli;

use cli::args::Cli;
use std::process::ExitCode;

fn main() -> ExitCode {
    // clap exits with code 2 on usage errors and 0 for --help/--version.
    let cli = Cli::parse();
    // An interrupted command (SIGINT, SIGTERM) leaves no temporary file and no program behind:
    // files are written under a temporary name and renamed into place, and whatever is
    // half-written when the signal comes is removed here; child programs (external programs,
    // an A/B gate's builds and sweeps) run in process groups of their own, which a terminal's
    // Ctrl-C does not reach, and are stopped here. Results saved before the signal are whole.
    let _ = ctrlc::set_handler(|| {
        // Held until the exit: no program starts after this.
        let _stopped = nbody_harness::children::stop_all();
        nbody_engine::output::remove_temporaries_and_exit(130)
    });
    let code = match cli::dispatch(cli) {
        Ok(code) => code,
        Err(err) => {
            nbody_harness::console::print_error(cli::error_chain(&err));
            2
        }
    };
    // A closed pipe on stdout ends the output quietly; any other failed write is an error.
    match nbody_harness::console::finish() {
        Err(why) => {
            nbody_harness::console::print_error(why);
            ExitCode::from(2)
        }
        Ok(()) => ExitCode::from(code as u8),
    }
}
