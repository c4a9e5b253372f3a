//! Every integration test in one binary: each test file of the suite is a module here, so the
//! library's generic kernels are compiled into one test executable instead of one per file
//! (that made most of the test build's time).
//!
//! The modules that time things (`gate`, `dry_run`) are meant to run alone: `scripts/test.sh`
//! runs the suite without them, then them with one test thread, so no other test loads the
//! CPUs during their sweeps.

mod analyze;
mod bad_input;
mod bad_sizes;
mod cli;
mod config_corpus;
mod conservation;
mod dry_run;
mod export;
mod external;
mod fit_cli;
mod gate;
mod invariants;
mod kernel_parts;
mod kernels_agree;
mod layering;
mod mpi_cli;
mod parsers;
mod peers;
mod report;
mod runs;
mod sweep;
mod verlet;
