//! The Slurm path of a sweep (`[scheduler]`) against stand-ins for `sbatch`, `squeue` and
//! `scontrol`, shell scripts put first on the binary's PATH, so that these tests need no Slurm:
//! what a sweep takes from a job's directory (only its own job's result, and only one that
//! answers the task), how long it waits for a queue it cannot read, and what `nbody-bench job
//! DIR` reads and checks before it measures. The real Slurm's tests are in `slurm.rs`.
//!
//! The stand-in `sbatch` keeps a count of the jobs (their ids) in the state directory and, by
//! default, runs the job script at once, before it prints the id, as a job that ran between two
//! looks at the queue; `squeue` prints nothing (the job has left) and `scontrol` says COMPLETED.

use crate::{finish, text};
use nbody_records::results::ResultsFile;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

/// The one case of [`config`].
const KEY: &str = "lj-box/naive/n=100/p=1/r=1/seed=1";

/// The job directory of round `r` of [`KEY`].
fn job_dir(out: &Path, r: usize) -> PathBuf {
    out.join(format!(
        "batch/jobs/round-{r}-lj-box-naive-n=100-p=1-r=1-seed=1"
    ))
}

/// Stand-ins for Slurm's commands in `dir/bin`; each body is a shell script's, with `$STATE`
/// the state directory (`dir/state`).
struct Slurm {
    bin: PathBuf,
    state: PathBuf,
}

/// Runs the job script (the last argument) now, its output into `--output`, and prints the id.
const RUN_AT_ONCE: &str = r#"for a; do case $a in --output=*) out=${a#--output=};; esac; script=$a; done
sh "$script" > "$out" 2>&1
echo "$id""#;

impl Slurm {
    fn new(dir: &Path, sbatch: &str, squeue: &str, scontrol: &str) -> Slurm {
        use std::os::unix::fs::PermissionsExt;
        let bin = dir.join("bin");
        let state = dir.join("state");
        std::fs::create_dir_all(&bin).unwrap();
        std::fs::create_dir_all(&state).unwrap();
        let sbatch = format!(
            "[ \"$1\" = --version ] && {{ echo 'slurm 0 (stand-in)'; exit 0; }}\n\
             id=$(( $(cat \"$STATE/count\" 2>/dev/null || echo 0) + 1 ))\n\
             echo \"$id\" > \"$STATE/count\"\n{sbatch}"
        );
        for (name, body) in [
            ("sbatch", &sbatch[..]),
            ("squeue", squeue),
            ("scontrol", scontrol),
        ] {
            let path = bin.join(name);
            std::fs::write(
                &path,
                format!("#!/bin/sh\nSTATE='{}'\n{body}\n", state.display()),
            )
            .unwrap();
            std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
        }
        Slurm { bin, state }
    }

    /// The usual stand-ins: jobs run at once and have left the queue when it is asked.
    fn at_once(dir: &Path) -> Slurm {
        Slurm::new(
            dir,
            RUN_AT_ONCE,
            "exit 0",
            "echo \"JobId=$3 JobName=x JobState=COMPLETED Reason=None\"",
        )
    }

    /// Jobs submitted so far.
    fn submitted(&self) -> usize {
        std::fs::read_to_string(self.state.join("count"))
            .map(|c| c.trim().parse().unwrap())
            .unwrap_or(0)
    }

    /// `nbody-bench ARGS` with these stand-ins first on PATH.
    fn command(&self, args: &[&str]) -> Command {
        let mut c = crate::bin();
        let path = std::env::var("PATH").unwrap_or_default();
        c.args(args)
            .env("PATH", format!("{}:{path}", self.bin.display()))
            .env_remove(nbody_engine::input::PIPE_WAIT_ENV)
            .env_remove(nbody_harness::experiment::slurm::GRACE_ENV)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        c
    }

    fn sweep(&self, config: &Path, out: &Path, more: &[&str], env: &[(&str, &str)]) -> Output {
        let mut args = vec![
            "sweep",
            "--config",
            config.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--no-calibration",
            "--yes",
        ];
        args.extend_from_slice(more);
        let mut c = self.command(&args);
        c.envs(env.iter().copied());
        finish(c.spawn().unwrap(), "sweep")
    }
}

/// A config of one case of the naive kernel at n = 100, `rounds` rounds of one sample each, its
/// `[scheduler]` with `time_limit`.
fn config(dir: &Path, rounds: usize, time_limit: &str) -> PathBuf {
    let path = dir.join("batch.toml");
    std::fs::write(
        &path,
        format!(
            "name = \"batch\"\nstudy = \"cartesian\"\nscenarios = [\"lj-box\"]\n\
             kernels = [\"naive\"]\nn = [100]\nthreads = [1]\n\
             [scheduler]\nkind = \"slurm\"\ntime_limit = \"{time_limit}\"\npoll_s = 0.05\n\
             [measure]\nwarmup_s = 0.001\nsamples = {rounds}\nrounds = {rounds}\n\
             min_sample_s = 0.001\n"
        ),
    )
    .unwrap();
    path
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", text(&o.stderr));
}

/// The rounds of [`KEY`] in the results under `out`.
fn rounds(out: &Path) -> Vec<nbody_records::round::RoundOutcome> {
    let r = ResultsFile::load(&out.join("batch/results.json")).unwrap();
    let case = r.cases.iter().find(|c| c.key == KEY).unwrap();
    case.rounds.clone()
}

/// Why round `i` has no samples, as its job record says.
fn refusal(round: &nbody_records::round::RoundOutcome) -> String {
    assert!(round.samples_s.is_empty(), "{round:?}");
    let job = round.job.as_ref().expect("the round names its job");
    job.error
        .as_ref()
        .expect("and why it has no samples")
        .what
        .clone()
}

/// A sweep without --resume submits its own jobs, whatever an earlier sweep left in their
/// directories (here a job id and a complete result); with --resume, a job the interrupted
/// sweep submitted is waited for, not submitted again, and its result taken.
#[test]
fn only_a_resumed_sweep_takes_a_job_submitted_before() {
    let dir = tempfile::tempdir().unwrap();
    let slurm = Slurm::at_once(dir.path());
    let config = config(dir.path(), 1, "5:00");
    let out = dir.path().join("out");
    ok(&slurm.sweep(&config, &out, &[], &[]));
    assert_eq!(slurm.submitted(), 1);
    let first = rounds(&out)[0].job.clone().unwrap();
    assert_eq!(first.id, "1");
    assert!(job_dir(&out, 1).join("result.json").exists());
    // A new sweep into the same place (the results file gone, the jobs left).
    std::fs::remove_file(out.join("batch/results.json")).unwrap();
    let o = slurm.sweep(&config, &out, &[], &[]);
    ok(&o);
    assert!(
        !text(&o.stderr).contains("submitted before"),
        "{}",
        text(&o.stderr)
    );
    assert_eq!(slurm.submitted(), 2, "the round was submitted again");
    let again = &rounds(&out)[0];
    assert_eq!(again.job.as_ref().unwrap().id, "2");
    assert_eq!(again.samples_s.len(), 1);

    // An interrupted sweep: its job is held until `release` exists, then `squeue` runs it.
    let held = dir.path().join("held");
    std::fs::create_dir_all(&held).unwrap();
    let slurm = Slurm::new(
        &held,
        r#"for a; do case $a in --output=*) out=${a#--output=};; esac; script=$a; done
printf '%s\n%s\n' "$script" "$out" > "$STATE/queued"
echo "$id""#,
        r#"if [ ! -e "$STATE/release" ]; then echo PENDING; exit 0; fi
if [ -e "$STATE/queued" ]; then
  { read script; read out; } < "$STATE/queued"; rm "$STATE/queued"; sh "$script" > "$out" 2>&1
fi"#,
        "echo \"JobId=$3 JobState=COMPLETED\"",
    );
    let out = held.join("out");
    let mut first = slurm
        .command(&[
            "sweep",
            "--config",
            config.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--no-calibration",
            "--yes",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let id_file = job_dir(&out, 1).join("job-id");
    let waited = std::time::Instant::now();
    while !id_file.exists() {
        assert!(first.try_wait().unwrap().is_none(), "the sweep ended early");
        assert!(
            waited.elapsed().as_secs() < crate::HANG_S,
            "no job submitted"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    first.kill().unwrap();
    first.wait().unwrap();
    std::fs::write(slurm.state.join("release"), "").unwrap();
    // Without --resume: refused, as the results file exists.
    let o = slurm.sweep(&config, &out, &[], &[]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains("--resume"), "{}", text(&o.stderr));
    let o = slurm.sweep(&config, &out, &["--resume"], &[]);
    ok(&o);
    assert!(
        text(&o.stderr).contains("job 1 was submitted before; waiting for it"),
        "{}",
        text(&o.stderr)
    );
    assert_eq!(slurm.submitted(), 1, "not submitted again");
    let round = &rounds(&out)[0];
    assert_eq!(round.job.as_ref().unwrap().id, "1");
    assert_eq!(round.samples_s.len(), 1, "{round:?}");
}

/// A result that does not answer its task is refused, and the round says why: one left by
/// another job (another token), one claiming another n, more samples than asked, or more pair
/// checks than n² pairs give. The stand-in `sbatch` writes, instead of running the job, a result
/// made from a real one (round r gets forgery r), with the task's own token where it says so.
#[test]
fn results_that_do_not_answer_their_task_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let config1 = config(dir.path(), 1, "5:00");
    let real = dir.path().join("real");
    ok(&Slurm::at_once(dir.path()).sweep(&config1, &real, &[], &[]));
    let text_of = std::fs::read_to_string(job_dir(&real, 1).join("result.json")).unwrap();
    let genuine: serde_json::Value = serde_json::from_str(&text_of).unwrap();
    let forged = dir.path().join("forged");
    std::fs::create_dir_all(&forged).unwrap();
    let forgeries: [&dyn Fn(&mut serde_json::Value); 5] = [
        // The earlier sweep's token, as it was.
        &|_| {},
        &|v| v["round"]["n"] = 1_000_000.into(),
        &|v| {
            let s = v["round"]["samples_s"][0].clone();
            v["round"]["samples_s"] = vec![s; 100_000].into();
        },
        &|v| v["round"]["work"]["pair_checks"] = u64::MAX.into(),
        // Nothing changed but the token: taken.
        &|_| {},
    ];
    for (i, forge) in forgeries.iter().enumerate() {
        let mut v = genuine.clone();
        forge(&mut v);
        if i > 0 {
            v["token"] = "@TOKEN@".into();
        }
        std::fs::write(
            forged.join(format!("forgery-{}.json", i + 1)),
            v.to_string(),
        )
        .unwrap();
    }
    let slurm = Slurm::new(
        &forged,
        &format!(
            r#"for a; do case $a in --output=*) out=${{a#--output=}};; esac; done
d=$(dirname "$out"); r=${{d##*/round-}}; r=${{r%%-*}}
token=$(sed -n 's/^  "token": "\([0-9a-f]*\)",$/\1/p' "$d/task.json")
sed "s/@TOKEN@/$token/" '{}/forgery-'$r.json > "$d/result.json"
echo "$id""#,
            forged.display()
        ),
        "exit 0",
        "echo \"JobId=$3 JobState=COMPLETED\"",
    );
    let config5 = config(&forged, 5, "5:00");
    let out = forged.join("out");
    let o = slurm.sweep(&config5, &out, &[], &[]);
    ok(&o);
    let rounds = rounds(&out);
    assert_eq!(rounds.len(), 5);
    for (round, reason) in rounds.iter().zip([
        "does not carry this job's token",
        "n = 1000000, the case has n = 100",
        "100000 samples where 1 were asked",
        "18446744073709551615 pair checks",
    ]) {
        let why = refusal(round);
        assert!(
            why.contains("result.json is refused") && why.contains(reason),
            "{why}"
        );
    }
    assert_eq!(rounds[4].samples_s.len(), 1, "{:?}", rounds[4]);
    assert!(rounds[4].job.as_ref().unwrap().error.is_none());
    assert!(
        text(&o.stderr).contains("result.json is refused"),
        "{}",
        text(&o.stderr)
    );
}

/// A result that is a named pipe nobody writes to, or a link to /dev/zero, is refused after a
/// bounded wait (or at once), never read forever; the rounds say why.
#[test]
fn a_result_that_is_a_pipe_or_a_device_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let slurm = Slurm::new(
        dir.path(),
        r#"for a; do case $a in --output=*) out=${a#--output=};; esac; done
d=$(dirname "$out")
case $d in */round-1-*) mkfifo "$d/result.json" ;; *) ln -s /dev/zero "$d/result.json" ;; esac
echo "$id""#,
        "exit 0",
        "echo \"JobId=$3 JobState=COMPLETED\"",
    );
    let config = config(dir.path(), 2, "5:00");
    let out = dir.path().join("out");
    let o = slurm.sweep(
        &config,
        &out,
        &[],
        &[(nbody_engine::input::PIPE_WAIT_ENV, "0.3")],
    );
    // No round has samples: the case failed (exit 1), no error of the sweep's own (2).
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
    let rounds = rounds(&out);
    let pipe = refusal(&rounds[0]);
    assert!(
        pipe.contains("cannot be read") && pipe.contains("no program wrote"),
        "{pipe}"
    );
    let device = refusal(&rounds[1]);
    assert!(device.contains("device"), "{device}");
}

/// `squeue` that prints a site's banner around the job's state is read for the state; one that
/// prints nothing Slurm would (nor does `scontrol`) is waited for no longer than the job's time
/// limit and the margin, from the submission; one that says RUNNING for ever, no longer than
/// that from when it was seen running. Then the sweep stops (exit 2) and says to --resume.
#[test]
fn a_queue_with_other_lines_is_read_and_the_wait_is_bounded() {
    let dir = tempfile::tempdir().unwrap();
    const BANNER: &str = "echo '*** Welcome to the cluster: maintenance on Monday ***'";
    // The job has run and left; the banner is all squeue prints, scontrol tells the state.
    let banner = Slurm::new(
        &dir.path().join("banner"),
        RUN_AT_ONCE,
        BANNER,
        &format!("{BANNER}\necho \"JobId=$3 JobState=COMPLETED\""),
    );
    let config = config(dir.path(), 1, "0:1");
    let out = dir.path().join("out-banner");
    ok(&banner.sweep(&config, &out, &[], &[]));
    let round = &rounds(&out)[0];
    assert_eq!(round.samples_s.len(), 1);
    assert_eq!(
        round.job.as_ref().unwrap().state.as_deref(),
        Some("COMPLETED")
    );

    let grace = [(nbody_harness::experiment::slurm::GRACE_ENV, "1")];
    for (name, squeue, seen) in [
        ("never-told", BANNER.to_string(), "no state"),
        (
            "running",
            format!("{BANNER}\necho RUNNING"),
            "has been running",
        ),
    ] {
        // The job never runs.
        let slurm = Slurm::new(&dir.path().join(name), "echo \"$id\"", &squeue, BANNER);
        let out = dir.path().join(format!("out-{name}"));
        let o = slurm.sweep(&config, &out, &[], &grace);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        assert!(
            err.contains(seen) && err.contains("--resume"),
            "{name}: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
}

/// `nbody-bench job DIR` reads its task with the limits of every input (a pipe nobody writes to
/// is given up, a device refused) and checks that its result can be written before it measures
/// anything: a round measured for nothing is lost. The task is a real one, of an external
/// program that leaves a mark when it runs.
#[test]
fn a_job_reads_its_task_within_limits_and_checks_its_result_can_be_written_first() {
    let dir = tempfile::tempdir().unwrap();
    let mark = dir.path().join("measured");
    let config = dir.path().join("ext.toml");
    std::fs::write(
        &config,
        format!(
            "name = \"ext\"\nstudy = \"cartesian\"\nscenarios = [\"lj-box\"]\nn = [50]\n\
             [[external]]\nname = \"x\"\nsteps = 1\ntime = \"wall\"\n\
             command = [\"sh\", \"-c\", \"touch '{}'\"]\n\
             [scheduler]\nkind = \"slurm\"\npoll_s = 0.05\n\
             [measure]\nsamples = 1\nrounds = 1\nwarmup_s = 0.0\nmin_sample_s = 0.0\n",
            mark.display()
        ),
    )
    .unwrap();
    // Submitted, never run: the job directory holds the task.
    let slurm = Slurm::new(dir.path(), "echo \"$id\"", "exit 0", "exit 0");
    let out = dir.path().join("out");
    let o = slurm.sweep(&config, &out, &[], &[]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
    let job = out.join("ext/jobs/round-1-lj-box-x-n=50-p=1-r=1-seed=1");
    let task = job.join("task.json");
    assert!(task.is_file() && !mark.exists());
    let run_job = |env: &[(&str, &str)]| {
        let mut c = slurm.command(&["job", job.to_str().unwrap()]);
        c.envs(env.iter().copied());
        finish(c.spawn().unwrap(), "job")
    };
    // Its result cannot be written: refused before measuring.
    std::fs::create_dir(job.join("result.json")).unwrap();
    let o = run_job(&[]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("result.json") && err.contains("nothing was measured"),
        "{err}"
    );
    assert!(
        !mark.exists(),
        "measured although its result could not be written"
    );
    std::fs::remove_dir(job.join("result.json")).unwrap();
    // The task is a pipe nobody writes to, then a link to a device.
    let kept = job.join("task.kept");
    std::fs::rename(&task, &kept).unwrap();
    let fifo = Command::new("mkfifo").arg(&task).status().unwrap();
    assert!(fifo.success());
    let o = run_job(&[(nbody_engine::input::PIPE_WAIT_ENV, "0.3")]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("task.json") && err.contains("no program wrote"),
        "{err}"
    );
    std::fs::remove_file(&task).unwrap();
    std::os::unix::fs::symlink("/dev/zero", &task).unwrap();
    let o = run_job(&[]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("task.json") && err.contains("device"), "{err}");
    assert!(!mark.exists());
    // The task as written: measured, and the result carries its token.
    std::fs::remove_file(&task).unwrap();
    std::fs::rename(&kept, &task).unwrap();
    ok(&run_job(&[]));
    assert!(mark.exists());
    let task: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&task).unwrap()).unwrap();
    let result: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(job.join("result.json")).unwrap()).unwrap();
    assert_eq!(result["token"], task["token"]);
    assert_eq!(result["token"].as_str().map(str::len), Some(32));
}
