//! One round of any case, wherever it runs: a built-in kernel in this process or under the
//! config's MPI launcher, or an external program. The runner calls it for each round, and a
//! batch job (`slurm`) for the round it was given.

use super::measure::{RoundSpec, measure_round};
use nbody_engine::clock::Clock;
use nbody_engine::scenario::Setup;
use nbody_engine::scenario::initial::InitialBodies;
use nbody_records::config::SweepConfig;
use nbody_records::kernel_or_program::KernelOrProgram;
use nbody_records::plan::Case;
use std::sync::Arc;

/// Measures one round of `case`.
pub(super) fn measure_case<C: Clock>(
    case: &Case,
    spec: &RoundSpec,
    clock: &C,
    config: &SweepConfig,
    context: &super::external::Context,
) -> Result<nbody_records::round::RoundOutcome, Box<dyn std::error::Error + Send + Sync>> {
    let kernel = match &case.kernel {
        KernelOrProgram::Kernel(k) => *k,
        KernelOrProgram::External(name) => {
            let ext = config
                .external
                .iter()
                .find(|e| &e.name == name)
                .ok_or_else(|| format!("the config has no [[external]] entry named `{name}`"))?;
            return Ok(super::external::run::measure_round(
                ext,
                case,
                spec,
                config.mpi.as_ref(),
                context,
            )?);
        }
    };
    if let Some(launch) = &config.mpi {
        return Ok(super::launcher::measure_round(
            launch,
            case,
            spec,
            context.initial.as_deref(),
        )?);
    }
    Ok(measure_round(
        &case_setup(case, context.bodies.clone()),
        case,
        kernel,
        spec,
        clock,
    )??)
}

/// The system a case measures: the seeded placement, or the config's file of bodies.
pub(crate) fn case_setup(case: &Case, bodies: Option<Arc<InitialBodies>>) -> Setup {
    let mut setup = Setup::new(case.scenario);
    setup.n = Some(case.n);
    setup.seed = case.seed;
    setup.precision = case.precision;
    setup.initial = bodies;
    setup
}
