//! Inside a job (`nbody-bench job DIR`): reads the task the sweep wrote, does it and writes the
//! result, carrying the task's token, for the sweep to take.

use super::{JobResult, Task, Work};
use std::path::Path;

/// Does the task in `dir` and writes `result.json`. The task is read with the limits of every
/// input (a pipe or a device in its place is given up, not read forever), and the result's
/// place is checked before anything is measured: a round measured for nothing is a round lost.
pub fn job_main(dir: &Path) -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
    let task_path = dir.join("task.json");
    let text = nbody_engine::input::read_text(&task_path)
        .map_err(|e| format!("cannot read {}: {e}", task_path.display()))?;
    let task: Task =
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", task_path.display()))?;
    let result_path = dir.join("result.json");
    nbody_engine::output::check_writable(&result_path).map_err(|e| {
        format!(
            "{e}; nothing was measured: the job directory must be writable from the compute node \
             (on a file system it shares with the login node)"
        )
    })?;
    let node = node_name();
    let result = match &task.work {
        Work::Round { case, spec } => {
            let clock = nbody_engine::clock::WallClock::new();
            let outcome = super::super::case_round::measure_case(
                case,
                spec,
                &clock,
                &task.config,
                &task.context,
            )?;
            JobResult {
                token: task.token.clone(),
                key: Some(case.key()),
                node,
                step_ns: outcome.step_ns.clone(),
                round: Some(outcome),
                calibration: None,
            }
        }
        Work::Calibrate { threads } => JobResult {
            token: task.token.clone(),
            key: None,
            node,
            round: None,
            step_ns: Vec::new(),
            calibration: Some(nbody_calibrate::calibrate(threads)),
        },
    };
    let text = serde_json::to_vec(&result)?;
    nbody_engine::output::write_atomic(&result_path, &text)?;
    Ok(())
}

/// The node a job runs on: Slurm's name for it, else the host name.
fn node_name() -> Option<String> {
    std::env::var("SLURMD_NODENAME")
        .ok()
        .filter(|s| !s.trim().is_empty())
        .or_else(nbody_engine::output::provenance::host_name)
}
