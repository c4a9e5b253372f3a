//! The experiment runner: the cases of a sweep config ([`nbody_records`]) measured round by
//! round (`runner`; one round of any case in `case_round`, of a kernel in `measure`, with the
//! `reference` workload and `progress` lines) into its results file, held by one writer
//! (`lock`); external programs run (`external`) and rounds under an MPI launcher (`launcher`)
//! or as batch jobs (`slurm`), a program that keeps failing the same way stopped
//! (`repeated_failure`); the length estimate of a sweep (`estimate`).

mod case_round;
pub mod estimate;
pub mod external;
pub mod launcher;
pub mod lock;
pub mod measure;
pub mod progress;
pub mod reference;
mod repeated_failure;
pub mod runner;
pub mod skin;
pub mod slowdown;
pub mod slurm;

// The gate study's measuring loop sets cases up as sweeps do.
pub(crate) use case_round::case_setup;

/// The cargo features of this build that change what it measures, as results files record
/// them: `mpi` (the MPI drivers) and `test-slowdown` (a build for the gate's tests only).
pub fn cargo_features() -> Vec<&'static str> {
    [
        ("mpi", cfg!(feature = "mpi")),
        ("test-slowdown", slowdown::ENABLED),
    ]
    .into_iter()
    .filter_map(|(name, on)| on.then_some(name))
    .collect()
}
