//! The MPI entry points: `run --decomp`, `mpi-check` and `mpi-bench`. In a build without the
//! `mpi` feature they exist (in `--help` too) and refuse with exit code 2.
//!
//! Every rank runs the same command. Errors that every rank meets alike are printed by rank 0
//! only; an error of one rank (say, a particle stuck outside a wall) by that rank, and rank 0
//! points to it. Only rank 0 prints results and writes files.

use crate::cli::args::{MpiBenchArgs, MpiCheckArgs, RunArgs};
use nbody_engine::decomp::Decomposition;
use nbody_mpi::ranks::job::Job;

/// The job the ranks compare when MPI starts (`Mpi::init`): the subcommand `name` and its
/// parsed arguments (so `--steps=3` and `--steps 3` agree, and defaults count), and the
/// command line as typed for the messages.
#[cfg_attr(not(feature = "mpi"), allow(dead_code))]
fn job(name: &str, args: &dyn std::fmt::Debug) -> Job {
    let typed: Vec<String> = std::env::args_os()
        .skip(1)
        .map(|a| a.to_string_lossy().into_owned())
        .collect();
    Job {
        command: format!("{name} {args:?}"),
        typed: format!("nbody-bench {}", typed.join(" ")),
    }
}

#[cfg(not(feature = "mpi"))]
pub fn run(_args: RunArgs, _decomp: Decomposition) -> anyhow::Result<i32> {
    anyhow::bail!(nbody_engine::decomp::WITHOUT_MPI)
}

#[cfg(not(feature = "mpi"))]
pub fn check(_args: MpiCheckArgs) -> anyhow::Result<i32> {
    anyhow::bail!(nbody_engine::decomp::WITHOUT_MPI)
}

#[cfg(not(feature = "mpi"))]
pub fn bench(_args: MpiBenchArgs) -> anyhow::Result<i32> {
    anyhow::bail!(nbody_engine::decomp::WITHOUT_MPI)
}

#[cfg(feature = "mpi")]
pub use with_mpi::{bench, check, run};

#[cfg(feature = "mpi")]
mod with_mpi {
    use super::*;
    use crate::cli::args::{KernelArgs, MpiOptions};
    use crate::cli::summary::print_summary;
    use crate::cli::{error_chain, kernel_params, setup, start_setup};
    use anyhow::Context;
    use nbody_engine::decomp::check::CheckReport;
    use nbody_engine::decomp::stats::MpiReport;
    use nbody_engine::kernels::KernelKind;
    use nbody_engine::run::RunOutcome;
    use nbody_engine::scenario::Precision;
    use nbody_harness::units::Duration;
    use nbody_mpi::mpi::{BenchOptions, DomainOptions, Mpi, MpiError, MpiSpec};
    use std::path::PathBuf;

    /// Starts MPI and checks that every rank runs `job` (see `Mpi::init`, which prints a
    /// mismatch itself); on an error, prints it where it should be and gives exit code 2.
    fn start(job: &Job) -> Result<Mpi, i32> {
        // Before the check no rank knows which it is; the errors of this step say where they
        // are printed (`MpiError::printed_by` ignores the rank for them).
        Mpi::init(job).map_err(|err| fail(0, err))
    }

    /// Prints an error on the ranks that should, and gives exit code 2.
    fn fail(rank: usize, err: MpiError) -> i32 {
        if err.printed_by(rank) {
            nbody_harness::console::print_error(crate::cli::error_chain(&anyhow::Error::from(err)));
        }
        2
    }

    fn spec(
        kernel: KernelKind,
        decomp: Decomposition,
        steps: usize,
        kernel_args: &KernelArgs,
        mpi: &MpiOptions,
        dump_state: Option<PathBuf>,
        check: bool,
    ) -> Result<MpiSpec, MpiError> {
        crate::cli::no_auto_skin(kernel_args, "an MPI run")
            .map_err(|e| MpiError::Usage(e.to_string()))?;
        let params =
            kernel_params(kernel_args, Some(kernel)).map_err(|e| MpiError::Usage(e.to_string()))?;
        Ok(MpiSpec {
            kernel,
            params,
            decomp,
            steps: steps as u64,
            warmup: mpi.warmup_steps as u64,
            threads: kernel_args.threads,
            domain: DomainOptions {
                rank_grid: mpi.rank_grid.clone(),
                rebalance_above: (!mpi.no_rebalance).then_some(mpi.rebalance_above),
            },
            dump_state,
            check,
        })
    }

    /// This process's rank as the launcher tells it before MPI starts (Open MPI, MPICH,
    /// Slurm).
    fn launcher_rank() -> Option<usize> {
        ["OMPI_COMM_WORLD_RANK", "PMI_RANK", "SLURM_PROCID"]
            .iter()
            .find_map(|v| std::env::var(v).ok()?.parse().ok())
    }

    /// Refuses a job whose ranks on this machine would not fit in its memory: with allgather
    /// every rank holds all n particles, with domain about n / ranks.
    fn fits(
        setup: &nbody_engine::scenario::Setup,
        kernel: KernelKind,
        decomp: Decomposition,
        kernel_args: &KernelArgs,
        ranks: usize,
    ) -> Result<(), MpiError> {
        let local_ranks = std::env::var("OMPI_COMM_WORLD_LOCAL_SIZE")
            .ok()
            .and_then(|v| v.parse::<usize>().ok())
            .unwrap_or(ranks)
            .max(1);
        let copies = match decomp {
            Decomposition::Allgather => local_ranks,
            // Ghost layers (or imported tree nodes) aside, the ranks together hold the
            // system once.
            Decomposition::Domain | Decomposition::Octants | Decomposition::Tree => 1,
        };
        if let Err(e) = setup.validate() {
            return Err(MpiError::Usage(e.to_string()));
        }
        let params =
            kernel_params(kernel_args, Some(kernel)).map_err(|e| MpiError::Usage(e.to_string()))?;
        nbody_engine::run::check_memory(setup, kernel, &params, kernel_args.threads, copies)
            .map_err(|e| MpiError::Usage(e.to_string()))
    }

    pub fn run(args: RunArgs, decomp: Decomposition) -> anyhow::Result<i32> {
        // Rank 0 alone estimates the run, before MPI starts (a probe's timing differs between
        // ranks, and a refusal must not leave ranks waiting in a collective): its exit with
        // code 2 ends the job under the launcher.
        if !args.yes
            && launcher_rank().unwrap_or(0) == 0
            && let Ok(setup) = start_setup(args.scenario, &args.system, &args.start)
        {
            let steps = (args.steps + args.mpi.warmup_steps) as u64;
            crate::cli::dry_run::refuse_long_run(&setup, args.kernel, &args.kernel_args, steps)?;
        }
        let mut mpi = match start(&job("run", &args)) {
            Ok(mpi) => mpi,
            Err(code) => return Ok(code),
        };
        let rank = mpi.rank();
        if args.trajectory.is_some() {
            let err = MpiError::Usage(
                "--trajectory is not available with --decomp; --dump-state writes the final state"
                    .into(),
            );
            return Ok(fail(rank, err));
        }
        let setup = match start_setup(args.scenario, &args.system, &args.start) {
            Ok(setup) => setup,
            Err(e) => return Ok(fail(rank, MpiError::Usage(error_chain(&e)))),
        };
        if let Err(err) = fits(&setup, args.kernel, decomp, &args.kernel_args, mpi.size()) {
            return Ok(fail(rank, err));
        }
        let spec = spec(
            args.kernel,
            decomp,
            args.steps,
            &args.kernel_args,
            &args.mpi,
            args.dump_state.clone(),
            false,
        );
        let spec = match spec {
            Ok(spec) => spec,
            Err(err) => return Ok(fail(rank, err)),
        };
        let root = match mpi.run(&setup, &spec) {
            Ok(Some(root)) => root,
            Ok(None) => return Ok(0),
            Err(err) => return Ok(fail(rank, err)),
        };
        let outcome = root.outcome;
        if outcome.oversubscribed {
            eprintln!(
                "warning: {} ranks x {} threads on {} logical CPUs: oversubscribed; timings do not show real parallel speedup",
                mpi.size(),
                outcome.threads,
                nbody_engine::run::logical_cpus()
            );
        }
        print_summary(&outcome);
        if let Some(report) = &outcome.mpi {
            print_mpi(report);
        }
        if let Some(path) = &args.json {
            let text = serde_json::to_string_pretty(&outcome).context("serializing the result")?;
            nbody_engine::output::write_atomic(path, text.as_bytes())?;
            outln!("result written to {}", path.display());
        }
        Ok(0)
    }

    /// The MPI lines of the summary, then the Coulomb MPI tutorial's closing lines.
    fn print_mpi(r: &MpiReport) {
        let red = &r.reduced;
        let grid = r
            .rank_grid
            .as_ref()
            .map(|g| {
                let g: Vec<String> = g.iter().map(|k| k.to_string()).collect();
                format!(" on a {} grid", g.join("x"))
            })
            .unwrap_or_default();
        outln!(
            "mpi               {} ranks, {}{grid}, {} rebalance(s); {}",
            r.ranks,
            r.decomposition.name(),
            r.rebalances,
            r.library.lines().next().unwrap_or("")
        );
        let span = |m: &nbody_engine::decomp::stats::MinMeanMax| {
            format!("{:.4}/{:.4}/{:.4}", m.min, m.mean, m.max)
        };
        outln!(
            "per rank (s)      compute {}  comm {}  wait {}  (min/mean/max); comm {:.1}% of the time, compute imbalance {:.3}",
            span(&red.compute_s),
            span(&red.comm_s),
            span(&red.wait_s),
            100.0 * red.comm_fraction,
            red.compute_imbalance
        );
        outln!(
            "traffic per rank  {:.3e} bytes, {:.0} point-to-point messages, {:.0} collective calls (mean); particles {:.0}..{:.0}; ghosts received {:.0}, migrated {:.0} (mean)",
            red.bytes_sent.mean,
            red.messages_sent.mean,
            red.collectives.mean,
            red.particles.min,
            red.particles.max,
            red.ghosts_received.mean,
            red.migrated_out.mean
        );
        let s = &r.master_summary;
        outln!("Communication time {:8.5} seconds", s.communication_s);
        outln!("Computation time   {:8.5} seconds", s.computation_s);
        outln!("\tEvaluated {} interactions", s.interactions);
    }

    pub fn check(args: MpiCheckArgs) -> anyhow::Result<i32> {
        let mut mpi = match start(&job("mpi-check", &args)) {
            Ok(mpi) => mpi,
            Err(code) => return Ok(code),
        };
        let rank = mpi.rank();
        let setup = setup(args.scenario, &args.system);
        if let Err(err) = fits(
            &setup,
            args.kernel,
            args.decomp,
            &args.kernel_args,
            mpi.size(),
        ) {
            return Ok(fail(rank, err));
        }
        let spec = spec(
            args.kernel,
            args.decomp,
            args.steps,
            &args.kernel_args,
            &args.mpi,
            None,
            true,
        );
        let spec = match spec {
            Ok(spec) => spec,
            Err(err) => return Ok(fail(rank, err)),
        };
        let root = match mpi.run(&setup, &spec) {
            Ok(Some(root)) => root,
            Ok(None) => return Ok(0),
            Err(err) => return Ok(fail(rank, err)),
        };
        let Some(report) = root.check else {
            anyhow::bail!(
                "rank 0 returned no comparison with the serial run; this is a bug, please report it"
            );
        };
        let tolerance = args.tolerance.unwrap_or(match setup.precision() {
            Precision::F64 => 1e-9,
            Precision::F32 => 1e-4,
        });
        print_check(&args, &root.outcome, &report, tolerance, mpi.size());
        let ok = report.passes(tolerance) & expectations_hold(&args, &root.outcome, &report);
        outln!("{}", if ok { "MATCH" } else { "MISMATCH" });
        Ok(if ok { 0 } else { 1 })
    }

    /// How the distributed run compares with the serial one: particles, differences, the
    /// tree's forces and energy, migration.
    fn print_check(
        args: &MpiCheckArgs,
        o: &RunOutcome,
        report: &CheckReport,
        tolerance: f64,
        ranks: usize,
    ) {
        outln!(
            "{} / {} / {}: n = {}, {} steps, {} ranks",
            o.scenario,
            o.kernel,
            args.decomp.name(),
            o.n,
            args.steps + args.mpi.warmup_steps,
            ranks
        );
        outln!(
            "particles         {} distributed, {} serial, ids complete: {}, id sum {} (expected {})",
            report.n_distributed,
            report.n_serial,
            report.ids_complete,
            report.id_sum,
            report.id_sum_expected
        );
        outln!(
            "difference        positions {:.3e} of the box, velocities {:.3e} of the top speed (tolerance {tolerance:.1e})",
            report.position_error,
            report.velocity_error
        );
        if let Some(t) = &report.tree {
            outln!(
                "forces            median error {:.2e} against the direct sum (serial octree {:.2e}, bound {:.1e})",
                t.force_error,
                t.serial_force_error,
                t.force_tolerance
            );
            outln!(
                "energy drift      {:.2e} (serial {:.2e}, allowed {:.1e}); the positions are not held to rounding: the tree's nodes differ",
                t.energy_drift,
                t.serial_energy_drift,
                nbody_engine::decomp::check::DRIFT_FACTOR * t.serial_energy_drift
                    + nbody_engine::decomp::check::DRIFT_FLOOR
            );
        }
        outln!(
            "migration         {} particles changed rank, {} beyond the neighbours",
            report.migrated,
            report.far_migrated
        );
    }

    /// The `--expect-*` flags, each said when it does not hold; whether all hold.
    fn expectations_hold(args: &MpiCheckArgs, o: &RunOutcome, report: &CheckReport) -> bool {
        let (owned, rebalances): (Vec<u64>, u64) = o
            .mpi
            .as_ref()
            .map(|m| {
                (
                    m.per_rank.iter().map(|r| r.particles).collect(),
                    m.rebalances,
                )
            })
            .unwrap_or_default();
        outln!("owned at the end  {owned:?}, {rebalances} rebalance(s)");
        let mut ok = true;
        if args.expect_empty_rank && !owned.contains(&0) {
            outln!("FAIL: every rank owns particles (--expect-empty-rank)");
            ok = false;
        }
        if args.expect_rebalance && rebalances == 0 {
            outln!("FAIL: the boundaries never moved (--expect-rebalance)");
            ok = false;
        }
        if args.expect_migration && report.migrated == 0 {
            outln!("FAIL: no particle changed rank (--expect-migration)");
            ok = false;
        }
        if args.expect_far_migration && report.far_migrated == 0 {
            outln!(
                "FAIL: no particle moved beyond the neighbouring regions (--expect-far-migration)"
            );
            ok = false;
        }
        ok
    }

    pub fn bench(args: MpiBenchArgs) -> anyhow::Result<i32> {
        nbody_engine::output::check_outputs(&[("--out", &args.out)], &[])?;
        let mut mpi = match start(&job("mpi-bench", &args)) {
            Ok(mpi) => mpi,
            Err(code) => return Ok(code),
        };
        let rank = mpi.rank();
        let options = BenchOptions {
            max_bytes: args.max_bytes as u64,
            reps: args.reps,
            warmup: args.warmup,
        };
        let file = match mpi.bench(&options) {
            Ok(Some(file)) => file,
            Ok(None) => return Ok(0),
            Err(err) => return Ok(fail(rank, err)),
        };
        outln!(
            "{} ranks on {} ({}), MPI {}{}",
            file.ranks,
            file.host,
            file.mpi_library.lines().next().unwrap_or(""),
            file.mpi_standard,
            if file.oversubscribed {
                " (oversubscribed)"
            } else {
                ""
            }
        );
        outln!(
            "{:>10} {:>14} {:>14} {:>18}",
            "bytes",
            "ping-pong p50",
            "one-way GB/s",
            "allgatherv p50"
        );
        for (p, a) in file.ping_pong.points.iter().zip(&file.allgatherv.points) {
            let pp = nbody_engine::stats::median(&p.seconds).unwrap_or(0.0);
            let ag = nbody_engine::stats::median(&a.seconds).unwrap_or(0.0);
            outln!(
                "{:>10} {:>14} {:>14.3} {:>18}",
                p.bytes,
                Duration(pp),
                if pp > 0.0 {
                    p.bytes as f64 / pp * 1e-9
                } else {
                    0.0
                },
                Duration(ag)
            );
        }
        let text = serde_json::to_string_pretty(&file).context("serializing the timings")?;
        nbody_engine::output::write_atomic(&args.out, text.as_bytes())?;
        outln!("timings written to {}", args.out.display());
        Ok(0)
    }
}

#[cfg(test)]
mod tests {
    use super::job;
    use crate::cli::args::{Cli, Command};
    use clap::Parser;
    use nbody_mpi::ranks::job::{Difference, JobDigest};

    /// The digest of the MPI job of a command line, as `Mpi::init` computes it.
    fn digest(line: &str) -> JobDigest {
        let argv = std::iter::once("nbody-bench").chain(line.split_whitespace());
        let cli = Cli::try_parse_from(argv).unwrap();
        let job = match &cli.command {
            Command::Run(a) => job("run", a),
            Command::MpiCheck(a) => job("mpi-check", a),
            Command::MpiBench(a) => job("mpi-bench", a),
            other => panic!("not an MPI command: {other:?}"),
        };
        JobDigest::of(&job, "one build")
    }

    const RUN: &str =
        "run --decomp domain --scenario lj-box --kernel cell-list -n 500 --steps 3 --seed 1";

    #[test]
    fn the_same_command_line_is_the_same_job_however_spelled() {
        assert_eq!(digest(RUN), digest(RUN));
        let spelled = "run --decomp=domain --kernel=cell-list --scenario lj-box --steps=3 \
                       --seed 1 -n 500 --threads 1";
        assert_eq!(digest(RUN), digest(spelled));
    }

    #[test]
    fn any_argument_that_differs_is_another_job() {
        let base = digest(RUN);
        for other in [
            RUN.replace("--steps 3", "--steps 30"),
            RUN.replace("--decomp domain", "--decomp allgather"),
            RUN.replace("-n 500", "-n 501"),
            RUN.replace("--seed 1", "--seed 2"),
            format!("{RUN} --warmup-steps 1"),
            format!("{RUN} --json out.json"),
            "mpi-check --decomp domain --scenario lj-box --kernel cell-list -n 500 --steps 3 \
             --seed 1"
                .into(),
        ] {
            assert_eq!(
                base.differences(&digest(&other)),
                Difference::COMMAND,
                "{other}"
            );
        }
        assert_ne!(digest("mpi-bench --reps 10"), digest("mpi-bench --reps 11"));
    }
}
