//! Cases under an MPI launcher: each round of a case is one launch of this program,
//! `LAUNCHER ARGS -n R nbody-bench run --decomp D ... --json FILE`, and the run's per-step
//! times (the slowest rank's) become the round's samples. The run's `mpi` block (per-rank
//! compute, communication, waiting, traffic) is kept with the round.

use super::measure::RoundSpec;
use nbody_engine::clock::{WallClock, clock_cost};
use nbody_engine::decomp::stats::MpiReport;
use nbody_engine::engine::PhaseTimes;
use nbody_engine::kernels::{KernelKind, WorkCounters};
use nbody_records::config::MpiLaunch;
use nbody_records::plan::Case;
use nbody_records::round::RoundOutcome;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::process::Command;
use thiserror::Error;

#[derive(Debug, Error)]
pub(crate) enum LaunchError {
    #[error("`{command}`: {source}; is the MPI launcher installed and on PATH?")]
    Spawn {
        command: String,
        source: crate::children::supervised::ChildError,
    },
    #[error("`{command}` failed ({status}); its last output:\n{output}")]
    Failed {
        command: String,
        status: String,
        output: String,
    },
    #[error("cannot read the run's result {path}: {detail}")]
    Result { path: PathBuf, detail: String },
    #[error("cannot find this program to launch it: {0}")]
    Exe(std::io::Error),
    #[error(
        "cannot create a private temporary directory in {dir} for the run's result: {source}; \
         set TMPDIR to a writable directory"
    )]
    TempDir {
        dir: PathBuf,
        source: std::io::Error,
    },
}

/// The fields of a `run --json` result a round needs.
#[derive(Deserialize)]
struct RunRecord {
    n: usize,
    steps: u64,
    timing: TimingRecord,
    counters: CountersRecord,
    energy: EnergyRecord,
    mpi: MpiReport,
}

#[derive(Deserialize)]
struct TimingRecord {
    phases: PhaseTimes,
}

#[derive(Deserialize)]
struct CountersRecord {
    total: WorkCounters,
    pairs_interacting_final: u64,
}

#[derive(Deserialize)]
struct EnergyRecord {
    /// `null` when the initial energy is 0: no relative drift exists then.
    rel_drift: Option<f64>,
}

/// The launcher's arguments for one round of `case`, writing its result to `json`.
pub(crate) fn launch_args(launch: &MpiLaunch, case: &Case, exe: &Path, json: &Path) -> Vec<String> {
    let mut a: Vec<String> = launch.args.clone();
    a.push(launch.rank_flag.clone());
    a.push(case.ranks.to_string());
    a.push(exe.display().to_string());
    let decomp = case
        .decomp
        .unwrap_or(nbody_engine::decomp::Decomposition::Allgather);
    for (flag, value) in [
        ("run", None),
        ("--scenario", Some(case.scenario.name().to_string())),
        ("--kernel", Some(case.kernel.name().to_string())),
        ("-n", Some(case.n.to_string())),
        ("--seed", Some(case.seed.to_string())),
        ("--threads", Some(case.threads.to_string())),
        ("--decomp", Some(decomp.name().to_string())),
        ("--steps", Some(launch.steps.to_string())),
        ("--warmup-steps", Some(launch.warmup_steps.to_string())),
        ("--json", Some(json.display().to_string())),
        // The sweep estimated its cases before it started; a long one is not asked again.
        ("--yes", None),
    ] {
        a.push(flag.to_string());
        a.extend(value);
    }
    if let Some(theta) = case.theta {
        a.extend(["--theta".to_string(), theta.to_string()]);
    }
    // The binary's default orders are not the ones of every case.
    if case.kernel.kernel() == Some(KernelKind::Octree) {
        a.extend(["--multipole".to_string(), case.multipole.name().to_string()]);
    }
    if let Some(p) = case.order {
        a.extend(["--order".to_string(), p.to_string()]);
    }
    if let Some(s) = case.skin {
        a.extend(["--skin".to_string(), s.to_string()]);
    }
    if let Some(p) = case.precision {
        a.extend(["--precision".to_string(), p.name().to_string()]);
    }
    a
}

/// A round from a run's result: its timed steps grouped into `samples` samples.
pub(crate) fn round_from_json(
    text: &str,
    samples: usize,
    warmup: u64,
) -> Result<RoundOutcome, String> {
    let run: RunRecord = serde_json::from_str(text).map_err(|e| e.to_string())?;
    let step_ns = &run.mpi.step_ns;
    let samples = samples.max(1);
    let k = step_ns.len() / samples;
    if k == 0 {
        return Err(format!(
            "it has {} timed steps, fewer than the {samples} samples of the round",
            step_ns.len()
        ));
    }
    let used: Vec<u64> = step_ns[..k * samples].to_vec();
    let samples_s: Vec<f64> = used
        .chunks_exact(k)
        .map(|c| c.iter().sum::<u64>() as f64 * 1e-9 / k as f64)
        .collect();
    let per_step = |x: f64| x / run.steps.max(1) as f64;
    let p = &run.timing.phases;
    let median = nbody_engine::stats::median(&samples_s).unwrap_or(0.0);
    let mut mpi = run.mpi;
    mpi.step_ns.clear();
    Ok(RoundOutcome {
        steps_per_sample: k as u64,
        samples_s,
        step_ns: used,
        steps: run.steps,
        warmup_steps: warmup,
        phases: Some(PhaseTimes {
            force_build: per_step(p.force_build),
            force_interact: per_step(p.force_interact),
            integrate: per_step(p.integrate),
            boundary: per_step(p.boundary),
            output: 0.0,
        }),
        work: Some(run.counters.total),
        pairs_interacting: Some(run.counters.pairs_interacting_final),
        // A null drift (zero initial energy) is not measured: null in the results, "–" in the
        // tables, as for an external program's round.
        energy_drift: run.energy.rel_drift,
        force_error: None,
        n: run.n,
        clock_overhead: if median > 0.0 {
            2.0 * clock_cost(&WallClock::new()) / median
        } else {
            0.0
        },
        mpi: Some(mpi),
        // Launched runs time themselves; the gate's paired reference and the initial-state
        // work are measured by in-process sweeps only.
        reference_s: Vec::new(),
        initial_work: None,
        external: None,
        job: None,
    })
}

/// A new directory for the result a launched run writes back: created exclusively under a
/// random name with mode 0700 in the temporary directory, so that no other user can plant a
/// link where the run writes (a predictable name in a shared `/tmp` let one overwrite any file
/// of the user running the sweep). It and its contents are removed when dropped, after a
/// round as after a failed one, and by the interrupt handler.
pub(crate) fn private_dir() -> Result<nbody_engine::output::TemporaryDir, LaunchError> {
    nbody_engine::output::TemporaryDir::new("nbody-bench-round-").map_err(|source| {
        LaunchError::TempDir {
            dir: std::env::temp_dir(),
            source,
        }
    })
}

/// The longest one launch may take (a week): a round has no time limit of its own, but
/// nothing the sweep starts runs unsupervised.
const LAUNCH_LIMIT: std::time::Duration = std::time::Duration::from_secs(7 * 24 * 3600);

/// Launches one round of `case` and reads its result.
pub(crate) fn measure_round(
    launch: &MpiLaunch,
    case: &Case,
    spec: &RoundSpec,
    initial: Option<&Path>,
) -> Result<RoundOutcome, LaunchError> {
    let exe = std::env::current_exe().map_err(LaunchError::Exe)?;
    let dir = private_dir()?;
    let json = dir.path().join("round.json");
    let mut args = launch_args(launch, case, &exe, &json);
    if let Some(file) = initial {
        args.extend(["--initial".to_string(), file.display().to_string()]);
    }
    let command = format!("{} {}", launch.launcher, args.join(" "));
    // In a process group of its own: the launcher and its ranks are stopped together when
    // the sweep is interrupted.
    let output = crate::children::supervised::output(
        Command::new(&launch.launcher).args(&args),
        LAUNCH_LIMIT,
        &command,
        "",
    )
    .map_err(|source| LaunchError::Spawn {
        command: command.clone(),
        source,
    })?;
    let text = nbody_engine::input::read_text(&json);
    if !output.status.success() {
        let all = String::from_utf8_lossy(&output.stderr).into_owned()
            + &String::from_utf8_lossy(&output.stdout);
        let lines: Vec<&str> = all.lines().collect();
        return Err(LaunchError::Failed {
            command,
            status: output.status.to_string(),
            output: lines[lines.len().saturating_sub(20)..].join("\n"),
        });
    }
    let text = text.map_err(|e| LaunchError::Result {
        path: json.clone(),
        detail: e.to_string(),
    })?;
    round_from_json(&text, spec.samples, launch.warmup_steps as u64)
        .map_err(|detail| LaunchError::Result { path: json, detail })
}

#[cfg(test)]
mod tests;
