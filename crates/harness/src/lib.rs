//! nbody-harness: what measures how N-body force kernels and other programs scale, built on
//! the simulation (`nbody_engine`), the machine's calibrated peaks (`nbody_calibrate`), the
//! files of a sweep (`nbody_records`) and the MPI drivers (`nbody_mpi`), each a crate of its
//! own named by its full path here.
//!
//! Bottom up: the [`console`], supervised [`children`], the revisions handed to [`git`] and
//! the [`fit`]s of scaling models; the [`units`] figures are written in; [`plot`]; the
//! [`experiment`] runner (rounds, external programs, launchers) and the [`analysis`] of
//! results; their [`render`]ing to tables and figures; the [`report`] and the regression
//! [`gate`]; the [`history`] of what was measured.
//! The command line is the binary crate's (`src/main.rs`, `src/cli/`), so nothing here can
//! depend on it.

// First, so that its `outln!` and `out!` macros are in scope in every module below.
#[macro_use]
pub mod console;

pub mod analysis;
pub mod children;
pub mod experiment;
pub mod fit;
pub mod gate;
pub mod git;
pub mod history;
pub mod plot;
pub mod render;
pub mod report;
pub mod units;
