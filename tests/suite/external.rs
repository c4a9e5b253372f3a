//! External programs in sweeps, with a tiny program written by the test (a shell script whose
//! run time, printed time and failure are chosen by its arguments): wall and regex timing,
//! placeholders and environment, a threads study read as strong scaling, failing samples kept
//! as errors, resume, arguments passed literally, bad configs refused.

use nbody_engine::clock::MockClock;
use nbody_harness::experiment::runner::{Silent, SweepError, SweepOptions, run_sweep};
use nbody_records::config::SweepConfig;
use nbody_records::results::ResultsFile;
use std::path::Path;
use std::time::Duration;

/// `prog MODE SLEEP_S PRINTED_MS [ARGS...]`: writes its other arguments (one a line) and its
/// environment into its working directory, then per MODE: `ok` sleeps and prints the time and
/// the check word, `scaled` prints PRINTED_MS / OMP_NUM_THREADS, `nocheck` prints the time
/// only, `notime` the check word only, `crash` writes to stderr and exits 3, `hang` sleeps 30 s.
const PROGRAM: &str = r#"#!/bin/sh
mode=$1; sleep_s=$2; printed=$3; shift 3
printf '%s\n' "$@" > args.txt
env > env.txt
case $mode in
  ok) sleep "$sleep_s"; echo "elapsed $printed ms"; echo "check OK" ;;
  scaled) echo "elapsed $(awk "BEGIN { print $printed / $OMP_NUM_THREADS }") ms"; echo "check OK" ;;
  nocheck) echo "elapsed $printed ms" ;;
  notime) echo "check OK" ;;
  crash) echo "step 3: out of particles" >&2; exit 3 ;;
  hang) exec sleep 30 ;;
esac
"#;

/// A temporary directory holding the program (`{config_dir}/prog`).
pub(crate) fn program_dir() -> tempfile::TempDir {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let prog = dir.path().join("prog");
    std::fs::write(&prog, PROGRAM).unwrap();
    std::fs::set_permissions(&prog, std::fs::Permissions::from_mode(0o755)).unwrap();
    dir
}

pub(crate) fn options(dir: &Path) -> SweepOptions {
    SweepOptions {
        out: Some(dir.join("out")),
        config_dir: Some(dir.to_path_buf()),
        nbody_bench: Some(env!("CARGO_BIN_EXE_nbody-bench").into()),
        ..Default::default()
    }
}

pub(crate) fn sweep(text: &str, dir: &Path) -> ResultsFile {
    let config = SweepConfig::parse(text, Path::new("ext.toml")).unwrap();
    let clock = MockClock::new(Duration::from_millis(1));
    let report = run_sweep(&config, text, &options(dir), &clock, &mut Silent).unwrap();
    ResultsFile::load(&report.path).unwrap()
}

pub(crate) const HEAD: &str = r#"
name = "ext"
study = "cartesian"
scenarios = ["lj-box"]
n = [50]
"#;

/// The `[measure]` table, after the `[[external]]` entries.
pub(crate) const MEASURE: &str = r#"
[measure]
warmup_s = 0.002
samples = 3
rounds = 2
min_sample_s = 0.002
"#;

pub(crate) fn record<'a>(r: &'a ResultsFile, key: &str) -> &'a nbody_records::results::CaseRecord {
    r.cases.iter().find(|c| c.key == key).unwrap_or_else(|| {
        panic!(
            "no case {key} in {:?}",
            r.cases.iter().map(|c| &c.key).collect::<Vec<_>>()
        )
    })
}

#[test]
fn regex_and_wall_timing_next_to_a_built_in_kernel() {
    let dir = program_dir();
    let text = format!(
        r#"{HEAD}
kernels = ["naive"]
[[external]]
name = "printed"
command = ["{{config_dir}}/prog", "ok", "0", "7.5"]
steps = 5
time = {{ regex = 'elapsed ([0-9.]+) ms', unit = "ms" }}
check = 'check OK'
version = ["sh", "-c", "echo printed 2.1; echo second line"]

[[external]]
name = "walled"
command = ["{{config_dir}}/prog", "ok", "0.05", "1"]
steps = 10
time = "wall"
{MEASURE}"#
    );
    let r = sweep(&text, dir.path());
    assert_eq!(r.cases.len(), 3);
    assert!(r.cases.iter().all(|c| c.is_complete()));
    assert!(
        record(&r, "lj-box/naive/n=50/p=1/r=1/seed=1")
            .summary
            .is_some()
    );
    // The printed 7.5 ms over 5 steps, exactly, in every sample of both rounds.
    let printed = record(&r, "lj-box/printed/n=50/p=1/r=1/seed=1");
    let s = printed.summary.as_ref().unwrap();
    assert_eq!(s.samples, 3);
    for round in &printed.rounds {
        assert!(round.samples_s.iter().all(|&t| (t - 1.5e-3).abs() < 1e-15));
        let ext = round.external.as_ref().unwrap();
        assert!(ext.runs.iter().all(|run| run.reported_s == Some(7.5e-3)));
        assert!(
            ext.launch_overhead_s.is_none(),
            "regex timing has no empty run"
        );
    }
    assert!((s.ns_per_particle_step - 1.5e-3 * 1e9 / 50.0).abs() < 1e-6);
    // Wall timing: at least the program's sleep, and the empty run measured.
    let walled = record(&r, "lj-box/walled/n=50/p=1/r=1/seed=1");
    for round in &walled.rounds {
        assert_eq!(
            round.samples_s.len(),
            round.external.as_ref().unwrap().runs.len()
        );
        assert!(
            round.samples_s.iter().all(|&t| t * 10.0 >= 0.05),
            "{:?}",
            round.samples_s
        );
        let ext = round.external.as_ref().unwrap();
        assert!(ext.launch_overhead_s.is_some_and(|o| o > 0.0));
        assert!(ext.overhead_share.is_some());
    }
    let versions: Vec<(&str, &str)> = r
        .metadata
        .externals
        .iter()
        .map(|v| (v.name.as_str(), v.version.as_str()))
        .collect();
    assert_eq!(
        versions,
        vec![
            ("printed", "printed 2.1"),
            ("walled", "(no version command)")
        ]
    );
    // The analysis sets the kernel against the faster program of the same case, with the ratio
    // of the medians and an interval around it, and the slower one beside it.
    let a = nbody_harness::analysis::analyze(&r, Path::new("results.json")).unwrap();
    let naive = record(&r, "lj-box/naive/n=50/p=1/r=1/seed=1")
        .summary
        .as_ref()
        .unwrap()
        .median_s;
    let pairs: Vec<(&str, &str, Vec<&str>)> = a
        .peers
        .iter()
        .map(|p| {
            let others = p.others.iter().map(|o| o.theirs.as_str()).collect();
            (p.ours.as_str(), p.theirs.as_str(), others)
        })
        .collect();
    assert_eq!(pairs, vec![("naive", "printed", vec!["walled"])]);
    let row = &a.peers[0];
    assert!((row.speedup - 1.5e-3 / naive).abs() <= 1e-12 * row.speedup);
    let ci = row.speedup_ci.unwrap();
    assert!(ci[0] <= row.speedup && row.speedup <= ci[1], "{ci:?}");
    assert!((row.theirs_ns - 1.5e-3 * 1e9 / 50.0).abs() < 1e-6);
    let table = nbody_harness::render::tables::peers(&a);
    assert!(table.contains("| lj-box | 50 | 1 | naive |"), "{table}");
    assert!(
        table.contains("| printed |") && table.contains("walled: "),
        "{table}"
    );
    // How each program ran comes from the config the results file holds.
    let runs = nbody_harness::render::runs::external_runs(&a);
    assert!(runs.contains("- `printed` (printed 2.1): `"), "{runs}");
    assert!(
        runs.contains("`walled`") && runs.contains("wall time"),
        "{runs}"
    );
}

#[test]
fn placeholders_and_environment_reach_the_program() {
    let dir = program_dir();
    let text = format!(
        r#"{HEAD}
seeds = [7]
[[external]]
name = "args"
command = ["{{config_dir}}/prog", "ok", "0", "1", "{{n}}", "t={{threads}},r={{ranks}}", "{{steps}}", "{{seed}}", "{{scenario}}", "{{workdir}}", "{{config_dir}}", "{{nbody_bench}}", "{{{{n}}}}"]
steps = 4
time = {{ regex = 'elapsed ([0-9.]+) ms', unit = "ms" }}
env = {{ BENCH_VAR = "threads-{{threads}}-seed-{{seed}}" }}
{MEASURE}"#
    );
    let r = sweep(&text, dir.path());
    let key = "lj-box/args/n=50/p=1/r=1/seed=7";
    assert!(record(&r, key).is_complete());
    let work =
        std::path::absolute(dir.path().join("out/ext/work").join(key.replace('/', "_"))).unwrap();
    let args = std::fs::read_to_string(work.join("args.txt")).unwrap();
    let config_dir = std::path::absolute(dir.path()).unwrap();
    let exe = std::path::absolute(env!("CARGO_BIN_EXE_nbody-bench")).unwrap();
    let expected = [
        "50".to_string(),
        "t=1,r=1".into(),
        "4".into(),
        "7".into(),
        "lj-box".into(),
        work.display().to_string(),
        config_dir.display().to_string(),
        exe.display().to_string(),
        "{n}".into(),
    ];
    assert_eq!(args.lines().collect::<Vec<_>>(), expected);
    let env = std::fs::read_to_string(work.join("env.txt")).unwrap();
    assert!(
        env.lines().any(|l| l == "BENCH_VAR=threads-1-seed-7"),
        "{env}"
    );
}

#[test]
fn an_argument_with_shell_metacharacters_is_passed_literally() {
    let dir = program_dir();
    let odd = "x; touch pwned && echo $(id) | cat > out `id` * 'q' \"r\" \\";
    let quoted = toml::Value::String(odd.into()).to_string();
    let text = format!(
        r#"{HEAD}
[[external]]
name = "odd"
command = ["{{config_dir}}/prog", "ok", "0", "1", {quoted}]
steps = 1
time = {{ regex = 'elapsed ([0-9.]+) ms', unit = "ms" }}
{MEASURE}"#
    );
    let r = sweep(&text, dir.path());
    let key = "lj-box/odd/n=50/p=1/r=1/seed=1";
    assert_eq!(record(&r, key).summary.as_ref().unwrap().samples, 3);
    let work = dir.path().join("out/ext/work").join(key.replace('/', "_"));
    assert_eq!(
        std::fs::read_to_string(work.join("args.txt")).unwrap(),
        format!("{odd}\n")
    );
    assert!(!work.join("pwned").exists() && !work.join("out").exists());
}

#[test]
fn a_threads_study_reads_as_strong_scaling() {
    let dir = program_dir();
    let text = format!(
        r#"{HEAD}
threads = [1, 2]
[[external]]
name = "scaled"
command = ["{{config_dir}}/prog", "scaled", "0", "8"]
steps = 2
time = {{ regex = 'elapsed ([0-9.]+) ms', unit = "ms" }}
env = {{ OMP_NUM_THREADS = "{{threads}}" }}
{MEASURE}"#
    )
    .replace("\"cartesian\"", "\"strong\"");
    let r = sweep(&text, dir.path());
    let one = record(&r, "lj-box/scaled/n=50/p=1/r=1/seed=1");
    let two = record(&r, "lj-box/scaled/n=50/p=2/r=1/seed=1");
    assert_eq!(one.summary.as_ref().unwrap().median_s, 4e-3);
    assert_eq!(two.summary.as_ref().unwrap().median_s, 2e-3);
    let analysis = nbody_harness::analysis::analyze(&r, Path::new("results.json")).unwrap();
    let strong = analysis
        .strong
        .iter()
        .find(|s| s.series.kernel.name() == "scaled")
        .expect("a strong-scaling series of the external");
    let at_two = strong.measured.iter().find(|p| p.p == 2.0).unwrap();
    assert!(
        (at_two.speedup.estimate - 2.0).abs() < 1e-12,
        "{:?}",
        at_two.speedup
    );
}

#[test]
fn a_family_of_settings_reads_as_one_accuracy_series() {
    let dir = program_dir();
    // One code at three requested precisions (each its own entry) and a program of no family.
    let entry = |name: &str, family: &str, ms: f64, error: f64| {
        format!(
            r#"
[[external]]
name = "{name}"
command = ["sh", "-c", "echo 'elapsed {ms} ms'; echo 'error {error:e}'"]
steps = 1
time = {{ regex = 'elapsed ([0-9.]+) ms', unit = "ms" }}
force_error = 'error (\S+)'
{family}
"#
        )
    };
    let text = format!(
        "{HEAD}{}{}{}{}{MEASURE}",
        entry("code-eps1e-2", "family = \"code\"", 2.0, 1e-2),
        entry("code-eps1e-4", "family = \"code\"", 8.0, 1e-4),
        entry("code-eps1e-3", "family = \"code\"", 4.0, 1e-3),
        entry("alone", "", 3.0, 5e-3),
    );
    let r = sweep(&text, dir.path());
    let groups = nbody_harness::analysis::groups::group(&r);
    let names: Vec<&str> = groups.theta.iter().map(|s| s.key.kernel.name()).collect();
    // The program of no family has one setting: no series.
    assert_eq!(names, ["code"]);
    let series = &groups.theta[0];
    let members: Vec<&str> = series.points.iter().map(|p| p.case.kernel.name()).collect();
    // In order of error, most accurate first.
    assert_eq!(members, ["code-eps1e-4", "code-eps1e-3", "code-eps1e-2"]);
    let errors: Vec<f64> = series
        .points
        .iter()
        .map(|p| p.force_error.unwrap()[0])
        .collect();
    assert_eq!(errors, [1e-4, 1e-3, 1e-2]);
    // Their cases keep their own names everywhere else.
    assert!(
        r.cases
            .iter()
            .any(|c| c.key == "lj-box/code-eps1e-3/n=50/p=1/r=1/seed=1")
    );
}

#[test]
fn failing_samples_are_errors_with_the_programs_output_and_the_sweep_goes_on() {
    let dir = program_dir();
    let mut text = format!("{HEAD}\nkernels = [\"naive\"]\n");
    for (name, mode, extra) in [
        ("nocheck", "nocheck", ""),
        ("crash", "crash", ""),
        ("notime", "notime", ""),
        ("hang", "hang", "timeout_s = 0.3"),
    ] {
        text.push_str(&format!(
            r#"
[[external]]
name = "{name}"
command = ["{{config_dir}}/prog", "{mode}", "0", "1"]
steps = 1
time = {{ regex = 'elapsed ([0-9.]+) ms', unit = "ms" }}
check = 'check OK'
{extra}
"#
        ));
    }
    text.push_str(MEASURE);
    let text = text.replace("samples = 3\nrounds = 2", "samples = 2\nrounds = 1");
    let r = sweep(&text, dir.path());
    assert!(r.cases.iter().all(|c| c.is_complete()));
    assert_eq!(
        record(&r, "lj-box/naive/n=50/p=1/r=1/seed=1")
            .summary
            .as_ref()
            .unwrap()
            .samples,
        2
    );
    let errors = |name: &str| {
        let c = record(&r, &format!("lj-box/{name}/n=50/p=1/r=1/seed=1"));
        assert!(
            c.summary.is_none() && c.failed(),
            "{name}: no sample, no summary"
        );
        let runs = &c.rounds[0].external.as_ref().unwrap().runs;
        assert_eq!(runs.len(), 2, "{name}");
        runs.iter()
            .map(|run| run.error.clone().expect("an error"))
            .collect::<Vec<_>>()
    };
    assert!(
        errors("nocheck")[0]
            .what
            .contains("does not match the check")
    );
    let crash = errors("crash");
    assert!(
        crash[0].what.contains("failed") && crash[0].what.contains('3'),
        "{}",
        crash[0].what
    );
    assert_eq!(crash[0].output_tail, vec!["step 3: out of particles"]);
    assert!(errors("notime")[0].what.contains("time regex"));
    let hang = errors("hang");
    assert!(
        hang[0].what.contains("timed out after 0.3 s"),
        "{}",
        hang[0].what
    );
    // A failed case is left out of the analysis, not read as a zero time.
    let analysis = nbody_harness::analysis::analyze(&r, Path::new("results.json")).unwrap();
    assert_eq!(analysis.cases.len(), 1);
}

#[test]
fn resume_keeps_the_external_rounds_and_repeats_none() {
    let dir = program_dir();
    let text = format!(
        r#"{HEAD}
kernels = ["naive"]
threads = [1, 2]
[[external]]
name = "printed"
command = ["{{config_dir}}/prog", "ok", "0", "{{threads}}"]
steps = 1
time = {{ regex = 'elapsed ([0-9.]+) ms', unit = "ms" }}
env = {{ OMP_NUM_THREADS = "{{threads}}" }}
{MEASURE}"#
    );
    let config = SweepConfig::parse(&text, Path::new("ext.toml")).unwrap();
    let clock = MockClock::new(Duration::from_millis(1));
    let mut opts = options(dir.path());
    let first = run_sweep(&config, &text, &opts, &clock, &mut crate::StopAfter(3)).unwrap();
    assert_eq!((first.rounds_measured, first.incomplete), (3, 4));
    let partial = ResultsFile::load(&first.path).unwrap();
    opts.resume = true;
    let second = run_sweep(&config, &text, &opts, &clock, &mut Silent).unwrap();
    assert_eq!((second.rounds_measured, second.incomplete), (8 - 3, 0));
    let done = ResultsFile::load(&second.path).unwrap();
    for c in &done.cases {
        assert_eq!(c.rounds.len(), 2, "{}", c.key);
        let old = partial.cases.iter().find(|o| o.key == c.key).unwrap();
        assert_eq!(&c.rounds[..old.rounds.len()], &old.rounds[..], "{}", c.key);
    }
    let p2 = record(&done, "lj-box/printed/n=50/p=2/r=1/seed=1");
    assert_eq!(p2.summary.as_ref().unwrap().median_s, 2e-3);
}

#[test]
fn bad_external_configs_are_refused_before_anything_runs() {
    let parse = |ext: &str| {
        let text = format!("{HEAD}\n[[external]]\n{ext}\n{MEASURE}");
        SweepConfig::parse(&text, Path::new("bad.toml"))
            .map(|_| ())
            .unwrap_err()
            .to_string()
    };
    let base = "name = \"x\"\nsteps = 1\ntime = \"wall\"\n";
    for (ext, expected) in [
        (format!("{base}command = [\"prog\", \"{{nn}}\"]"), "unknown placeholder `{nn}`"),
        (format!("{base}command = [\"prog\", \"{{n\"]"), "unclosed"),
        (format!("{base}command = []"), "must name a program"),
        (
            "name = \"naive\"\nsteps = 1\ntime = \"wall\"\ncommand = [\"p\"]".into(),
            "built-in kernel",
        ),
        (
            "name = \"x\"\nsteps = 1\ncommand = [\"p\"]\ntime = { regex = 'no group', unit = \"s\" }".into(),
            "needs a group",
        ),
        (
            "name = \"x\"\nsteps = 1\ncommand = [\"p\"]\ntime = \"cpu\"".into(),
            "must be \"wall\" or",
        ),
        (format!("{base}command = [\"p\"]\nthreads = [1, 2]"), "uses {threads}"),
        (format!("{base}command = [\"p\"]\nranks = [2]"), "no [mpi] launcher"),
        (format!("{base}command = [\"p\"]\nversion = [\"p\", \"{{n}}\"]"), "unknown placeholder `{n}`"),
        (format!("{base}command = [\"p\"]\nshell = \"sh\""), "shell"),
        (
            "name = \"x\"\nsteps = 0\ntime = \"wall\"\ncommand = [\"p\"]".into(),
            "at least 1",
        ),
        (format!("{base}command = [\"p\"]\nfamily = \"f\""), "give `force_error` too"),
        (
            format!("{base}command = [\"p\"]\nphases = {{ comm = {{ regex = 'comm', unit = \"s\" }} }}"),
            "`external.x.phases.comm.regex` needs a group",
        ),
        (
            format!("{base}command = [\"p\"]\nphases = {{ c = {{ regex = 'c (.+)', unit = \"s\", kind = \"io\" }} }}"),
            "unknown variant `io`",
        ),
        (
            format!("{base}command = [\"p\"]\nphases = {{ \"a b\" = {{ regex = 'c (.+)', unit = \"s\" }} }}"),
            "phase named `a b`",
        ),
        (
            format!("{base}command = [\"p\"]\nforce_error = 'e (.+)'\nfamily = \"a b\""),
            "it must be letters",
        ),
    ] {
        let message = parse(&ext);
        assert!(message.contains(expected), "{ext}\n→ {message}");
    }
    // A program that does not exist: refused before the first case, nothing measured.
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        "{HEAD}\nkernels = [\"naive\"]\n[[external]]\n{base}command = [\"no-such-peer-program\"]\n{MEASURE}"
    );
    let config = SweepConfig::parse(&text, Path::new("ext.toml")).unwrap();
    let clock = MockClock::new(Duration::from_millis(1));
    let err = run_sweep(&config, &text, &options(dir.path()), &clock, &mut Silent).unwrap_err();
    assert!(matches!(err, SweepError::External(_)), "{err}");
    assert!(
        err.to_string().contains("`no-such-peer-program` not found"),
        "{err}"
    );
    assert!(!dir.path().join("out/ext/results.json").exists());
    // Through the command line: exit code 2 and the message.
    let path = dir.path().join("ext.toml");
    std::fs::write(&path, &text).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_nbody-bench"))
        .args(["sweep", "--config", path.to_str().unwrap(), "--out"])
        .arg(dir.path().join("cli"))
        .args(["--no-calibration", "--yes"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("not found") && !stderr.contains("panicked"),
        "{stderr}"
    );
}
