//! Phases an external program times itself (`phases`): read per run, averaged per step, the
//! Amdahl serial fraction from its serial phases, its communication share, and a phase missing
//! from the output as a failed sample with the program's output.
//!
//! The programs print the times a real code would measure, computed from the thread count
//! rather than slept, so every number the tests check is exact.

use super::external::{HEAD, MEASURE, program_dir, record, sweep};
use nbody_records::external::PhaseKind;
use std::path::Path;

/// A program of `serial_ms` serial work, `parallel_ms` split over OMP_NUM_THREADS and
/// `comm_ms` of communication per extra thread, each printed as a phase over `steps` steps.
fn phased(name: &str, serial_ms: f64, parallel_ms: f64, comm_ms: f64) -> String {
    let script = format!(
        "awk -v t=\"$OMP_NUM_THREADS\" 'BEGIN {{{{ s = {serial_ms}; p = {parallel_ms} / t; c = {comm_ms} * (t - 1); \
         printf \"phase serial %g\\nphase work %g\\nphase comm %g\\ntotal %g ms\\n\", s, p, c, s + p + c }}}}'"
    );
    format!(
        r#"
[[external]]
name = "{name}"
command = ["sh", "-c", "{}"]
steps = 4
time = {{ regex = 'total ([0-9.]+) ms', unit = "ms" }}
env = {{ OMP_NUM_THREADS = "{{threads}}" }}
phases = {{ setup = {{ regex = 'phase serial ([0-9.e+-]+)', unit = "ms", kind = "serial" }}, work = {{ regex = 'phase work ([0-9.e+-]+)', unit = "ms" }}, exchange = {{ regex = 'phase comm ([0-9.e+-]+)', unit = "ms", kind = "comm" }} }}
"#,
        script.replace('\\', "\\\\").replace('"', "\\\"")
    )
}

fn strong_config(entries: &str) -> String {
    format!("{HEAD}\nthreads = [1, 2]\n{entries}{MEASURE}").replace("\"cartesian\"", "\"strong\"")
}

#[test]
fn a_programs_serial_phase_gives_the_timed_serial_fraction_it_was_built_with() {
    let dir = program_dir();
    // 2 ms serial and 6 ms parallel: a serial fraction of 1/4, which Amdahl's law fitted to
    // the two step times recovers as well (T(2) = 2 + 3 = 5 ms).
    let r = sweep(&strong_config(&phased("amdahl", 2.0, 6.0, 0.0)), dir.path());
    let one = record(&r, "lj-box/amdahl/n=50/p=1/r=1/seed=1");
    let runs = &one.rounds[0].external.as_ref().unwrap().runs;
    assert!(!runs.is_empty());
    for run in runs {
        assert!(run.error.is_none(), "{:?}", run.error);
        assert_eq!(run.phases["setup"], 2e-3);
        assert_eq!(run.phases["work"], 6e-3);
        assert_eq!(run.phases["exchange"], 0.0);
    }
    let analysis = nbody_harness::analysis::analyze(&r, Path::new("results.json")).unwrap();
    let point = analysis
        .cases
        .iter()
        .find(|c| c.key == one.key)
        .expect("the one-thread case");
    // Per step: the run's totals over its 4 steps, in the config's (sorted) order.
    let phases: Vec<(&str, PhaseKind)> = point
        .named_phases
        .iter()
        .map(|p| (p.name.as_str(), p.kind))
        .collect();
    assert_eq!(
        phases,
        [
            ("exchange", PhaseKind::Comm),
            ("setup", PhaseKind::Serial),
            ("work", PhaseKind::Parallel)
        ]
    );
    let per_step: Vec<f64> = point.named_phases.iter().map(|p| p.s_per_step).collect();
    for (got, want) in per_step.iter().zip([0.0, 0.5e-3, 1.5e-3]) {
        assert!((got - want).abs() < 1e-15, "{per_step:?}");
    }
    let strong = analysis
        .strong
        .iter()
        .find(|s| s.series.kernel.name() == "amdahl")
        .expect("a strong-scaling series");
    let timed = strong
        .timed_serial
        .as_ref()
        .expect("a timed serial fraction");
    assert!((timed.fraction - 0.25).abs() < 1e-12, "{timed:?}");
    let fitted = &strong.fit.fit.as_ref().expect("a fit").serial_fraction;
    assert!(
        (fitted.estimate - 0.25).abs() < 1e-9,
        "fitted {fitted:?} from step times 2 and 1.25 ms"
    );
}

#[test]
fn communication_phases_stand_as_the_cases_communication() {
    let dir = program_dir();
    // At 2 threads: 1 ms serial, 2 ms of work, 1 ms of communication: 25% of the step.
    let r = sweep(
        &strong_config(&phased("mpi-like", 1.0, 4.0, 1.0)),
        dir.path(),
    );
    let analysis = nbody_harness::analysis::analyze(&r, Path::new("results.json")).unwrap();
    let two = analysis
        .cases
        .iter()
        .find(|c| c.key == "lj-box/mpi-like/n=50/p=2/r=1/seed=1")
        .unwrap();
    assert_eq!(two.comm_s_per_step, Some(0.25e-3));
    assert!((two.median_s - 1e-3).abs() < 1e-15);
    // The summary's phase table names each phase with its kind and share.
    let table = nbody_harness::render::runs::external_phases(&analysis);
    let row = table
        .lines()
        .find(|l| l.contains("mpi-like") && l.contains("2 threads"))
        .unwrap_or_else(|| panic!("no row for the 2-thread case in\n{table}"));
    let quarter = nbody_harness::units::Duration(0.25e-3);
    assert!(
        row.contains(&format!("exchange (comm): {quarter} (25.0%)")),
        "{row}"
    );
    assert!(
        row.contains(&format!("setup (serial): {quarter} (25.0%)")),
        "{row}"
    );
    assert!(row.contains("| 25.0% | 25.0% |"), "{row}");
}

#[test]
fn a_phase_missing_from_the_output_fails_the_sample_with_the_output() {
    let dir = program_dir();
    let text = format!(
        r#"{HEAD}
[[external]]
name = "silent"
command = ["sh", "-c", "echo 'total 3 ms'; echo 'phase work 1'"]
steps = 1
time = {{ regex = 'total ([0-9.]+) ms', unit = "ms" }}
phases = {{ work = {{ regex = 'phase work ([0-9.]+)', unit = "ms" }}, comm = {{ regex = 'phase comm ([0-9.]+)', unit = "ms", kind = "comm" }} }}
{MEASURE}"#
    );
    let r = sweep(&text, dir.path());
    let c = record(&r, "lj-box/silent/n=50/p=1/r=1/seed=1");
    assert!(c.failed(), "no sample, no summary");
    let run = &c.rounds[0].external.as_ref().unwrap().runs[0];
    let error = run.error.as_ref().expect("an error");
    assert!(
        error.what.contains("does not match the phase `comm` regex"),
        "{}",
        error.what
    );
    assert_eq!(error.output_tail, ["total 3 ms", "phase work 1"]);
}
