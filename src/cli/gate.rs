//! `gate`: compare two results files, or measure this build and judge it (against the
//! baseline file of its machine class, else A/B against the baseline's revision). The policy is
//! the library's (`nbody_harness::gate::drive`); this parses, calls it and prints.

use crate::cli::args::GateArgs;
use nbody_harness::gate::drive::{self, Request};
use nbody_harness::gate::formatted;

pub fn gate(args: GateArgs) -> anyhow::Result<i32> {
    let request = Request {
        baseline: args.baseline.clone(),
        current: args.current.clone(),
        against: args.against.clone(),
        config: args.config.clone(),
        rounds: args.rounds,
        timeout: args.timeout,
        out: args.out.clone(),
        threshold: args.threshold,
        normalize: args.normalize,
        judge: args.judge,
        force: args.force,
        fail_on_work_change: args.fail_on_work_change,
    };
    if let Some(results) = &args.save_baseline {
        return super::gate_save::save(&args, results, request);
    }
    let outcome = drive::run(&request, &mut |line| eprintln!("gate: {line}"))?;
    out!("{}", formatted(&outcome.report, args.format));
    if let Some(history) = &args.record {
        record(history, &outcome, args.current.as_deref())?;
    }
    if let Some(why) = outcome.incomplete() {
        eprintln!("error: {why}");
    }
    Ok(outcome.exit_code())
}

/// Appends what the gate measured to the history under `dir`: the A/B run's two sides (the
/// baseline's revision and this build), the fast path's sweep, or the `--current` file; and
/// the run's verdicts to the class's verdict file beside it.
pub(super) fn record(
    dir: &std::path::Path,
    outcome: &drive::Outcome,
    current: Option<&std::path::Path>,
) -> anyhow::Result<()> {
    let files: Vec<std::path::PathBuf> = match (&outcome.kept_in, current) {
        (Some(kept), _) => ["base.json", "current.json", "results.json"]
            .iter()
            .map(|f| kept.join(f))
            .filter(|p| p.is_file())
            .collect(),
        (None, Some(current)) => vec![nbody_records::locate::find_results(
            current,
            std::path::Path::new("results"),
        )?],
        (None, None) => Vec::new(),
    };
    // The verdicts beside the records: the page shows each class's latest gate run.
    let run = nbody_harness::history::verdicts::GateRun::of(
        &outcome.report,
        &nbody_harness::gate::route::this_machine(),
    );
    // A run the file already holds (a save's accepted run, appended just before) is not
    // appended again, and not reported.
    for (to, count) in nbody_harness::history::verdicts::append(dir, &[run])? {
        if count == 0 {
            continue;
        }
        eprintln!(
            "gate: the verdicts of {count} gate run(s) appended to {}",
            to.display()
        );
    }
    for path in files {
        let file = nbody_records::results::ResultsFile::load(&path)?;
        for (to, count) in super::history::append_results(dir, &file, "gate")? {
            eprintln!(
                "gate: {count} records of {} appended to {}",
                path.display(),
                to.display()
            );
        }
    }
    Ok(())
}
