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
        max_rounds: args.max_rounds,
        sides: args.sides,
        timeout: args.timeout,
        out: args.out.clone(),
        threshold: args.threshold,
        normalize: args.normalize,
        judge: args.judge,
        force: args.force,
        fail_on_work_change: args.fail_on_work_change,
    };
    if let Some(history) = &args.record {
        super::history::check_record_dir("--record", history)?;
    }
    if let Some(results) = &args.save_baseline {
        return super::gate_save::save(&args, results, request);
    }
    let outcome = drive::run(&request, &mut |line| eprintln!("gate: {line}"))?;
    out!("{}", formatted(&outcome.report, args.format));
    if let Some(history) = &args.record {
        super::history::record_gate_run(history, &outcome, args.current.as_deref())?;
    }
    if let Some(why) = outcome.incomplete() {
        eprintln!("error: {why}");
    }
    Ok(outcome.exit_code())
}
