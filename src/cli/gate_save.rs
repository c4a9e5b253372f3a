//! `gate --save-baseline`: keep a sweep as its machine class's baseline. The decision is the
//! library's (`nbody_harness::gate::save`, `gate::guard`); this prints the A/B run's report
//! and the refusal, records an acceptance in the history before the baseline changes, and
//! writes the file.

use crate::cli::args::GateArgs;
use nbody_engine::output::provenance::utc_now;
use nbody_harness::gate::baselines::class_name;
use nbody_harness::gate::drive::Request;
use nbody_harness::gate::formatted;
use nbody_harness::gate::guard::Acceptance;
use nbody_harness::gate::route::this_machine;
use nbody_harness::gate::save::{self, Judgement, SaveRequest};
use nbody_harness::history::verdicts::{self, GateRun};
use std::path::{Path, PathBuf};

/// Where an acceptance is recorded when `--record` names no folder: the committed history,
/// so that the acceptance is reviewed and committed with the baseline it let through.
const HISTORY: &str = "results/history";

/// Judges `results` as the new baseline of its class (A/B against the replaced baseline's
/// commit when there is one) and keeps it, or refuses: 1 for an unaccepted regression, 0
/// once saved; bad input is an error (exit 2).
pub fn save(args: &GateArgs, results: &Path, a_b: Request) -> anyhow::Result<i32> {
    let request = SaveRequest {
        folder: args.baseline.clone(),
        results: results.to_path_buf(),
        accept: Acceptance {
            cases: args.accept.clone(),
            reason: args.reason.clone(),
        },
        a_b,
    };
    let pending = match save::judge_save(&request, &mut |line| eprintln!("gate: {line}"))? {
        Judgement::Refused(refusal) => {
            out!("{}", formatted(&refusal.outcome.report, args.format));
            if let Some(dir) = &args.record {
                super::history::record_gate_run(dir, &refusal.outcome, None)?;
            }
            eprintln!("error: {}", refusal.message);
            return Ok(1);
        }
        Judgement::Ready(pending) => *pending,
    };
    if let Some(replaced) = &pending.replaced {
        out!("{}", formatted(&replaced.outcome.report, args.format));
        if let Some(reason) = &replaced.reason {
            // Recorded before the baseline changes: a baseline never holds an accepted
            // regression the history does not name.
            let dir = args
                .record
                .clone()
                .unwrap_or_else(|| PathBuf::from(HISTORY));
            let info = &pending.candidate.info;
            let run = GateRun::accepted(
                &replaced.outcome.report,
                &this_machine(),
                &class_name(info.cpu_signature.as_deref(), info.logical_cpus),
                &replaced.accepted,
                reason,
                &pending.candidate.info.git_commit,
                &utc_now(),
            );
            for (to, _) in verdicts::append(&dir, &[run])? {
                eprintln!(
                    "gate: the acceptance of {} regressed case(s) (\"{reason}\") appended to {}; \
                     commit it with the new baseline",
                    replaced.accepted.len(),
                    to.display()
                );
            }
        }
        if let Some(dir) = &args.record {
            super::history::record_gate_run(dir, &replaced.outcome, None)?;
        }
        let accepted: Vec<String> = replaced.accepted.iter().map(|r| r.describe()).collect();
        eprintln!(
            "gate: {} against the replaced baseline's commit {}",
            if accepted.is_empty() {
                "no case regressed".to_string()
            } else {
                format!("regressions accepted: {}", accepted.join("; "))
            },
            nbody_harness::gate::prefix(&replaced.commit, 12)
        );
    }
    let (target, info) = pending.keep()?;
    eprintln!(
        "gate: {} kept as the baseline of {} ({} logical CPUs): {}",
        results.display(),
        info.cpu_signature.as_deref().unwrap_or("an unknown CPU"),
        info.logical_cpus.map_or("?".into(), |n| n.to_string()),
        target.display()
    );
    Ok(0)
}
