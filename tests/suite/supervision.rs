//! External programs are supervised whole, and inputs may be pipes, through the binary:
//! a timed-out or interrupted run leaves no process of its group behind; an output past the
//! read-back limit is a failed sample that says so; programs are checked exactly as they will
//! be started (relative paths, the PATH an `env` sets, NUL bytes, absurd timeouts) before
//! anything runs; configs, results and CSV tables are read from pipes, and a pipe nobody
//! writes to is given up after a bounded wait. Every child has a timeout.

use crate::{finish, refused, text};
use nbody_harness::children::{alive, members_left};
use nbody_records::results::ResultsFile;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn bin() -> Command {
    let mut c = crate::bin();
    c.env_remove(nbody_engine::input::PIPE_WAIT_ENV)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    c
}

fn run(cmd: &mut Command, what: &str) -> Output {
    finish(cmd.spawn().unwrap(), what)
}

/// A config of one external program `[[external]]` body `ext`, one sample of one round.
fn config(dir: &Path, ext: &str) -> PathBuf {
    let path = dir.join("ext.toml");
    std::fs::write(
        &path,
        format!(
            "name = \"ext\"\nstudy = \"cartesian\"\nscenarios = [\"lj-box\"]\nn = [50]\n\
             [[external]]\nname = \"x\"\nsteps = 1\n{ext}\n\
             [measure]\nsamples = 1\nrounds = 1\nwarmup_s = 0.0\nmin_sample_s = 0.0\n"
        ),
    )
    .unwrap();
    path
}

fn sweep(config: &Path, out: &Path) -> Command {
    let mut c = bin();
    c.args(["sweep", "--no-calibration", "--yes", "--config"])
        .arg(config)
        .arg("--out")
        .arg(out);
    c
}

/// The work directory of the one case of [`config`].
fn workdir(out: &Path) -> PathBuf {
    out.join("ext/work/lj-box_x_n=50_p=1_r=1_seed=1")
}

/// The runs of the one case of [`config`].
fn runs(out: &Path) -> Vec<nbody_records::external::ExternalRun> {
    let r = ResultsFile::load(&out.join("ext/results.json")).unwrap();
    r.cases[0]
        .rounds
        .iter()
        .flat_map(|round| round.external.clone().unwrap().runs)
        .collect()
}

/// Waits up to 10 s for `pid` to end (signals are delivered asynchronously).
fn gone(pid: i32) -> bool {
    let deadline = Instant::now() + Duration::from_secs(10);
    while alive(pid) && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(20));
    }
    !alive(pid)
}

fn pid_in(file: &Path) -> i32 {
    std::fs::read_to_string(file)
        .unwrap()
        .trim()
        .parse()
        .unwrap()
}

/// `sh -c "<inner sh, which records its pid and becomes sleep 43>; echo"`: the issue's
/// `sh -c "sleep 43; echo"`, with the sleep's pid in `sleep.pid` of the work directory.
const SLEEPER: &str =
    r#"command = ["sh", "-c", "sh -c 'echo $$ > sleep.pid; exec sleep 43'; echo"]"#;

#[test]
fn a_timeout_stops_the_whole_process_group() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let cfg = config(
        dir.path(),
        &format!("{SLEEPER}\ntime = \"wall\"\ntimeout_s = 0.5"),
    );
    let o = run(&mut sweep(&cfg, &out), "sweep");
    assert!(!text(&o.stderr).contains("panicked"), "{}", text(&o.stderr));
    let sleeper = pid_in(&workdir(&out).join("sleep.pid"));
    assert!(
        gone(sleeper),
        "sleep 43 (pid {sleeper}) outlived its timed-out run"
    );
    let runs = runs(&out);
    assert_eq!(runs.len(), 1);
    let why = &runs[0].error.as_ref().expect("a timed-out sample").what;
    assert!(why.contains("timed out"), "{why}");
}

#[test]
fn an_interrupted_sweep_stops_the_running_program() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let cfg = config(
        dir.path(),
        &format!("{SLEEPER}\ntime = \"wall\"\ntimeout_s = 600"),
    );
    let child = sweep(&cfg, &out).spawn().unwrap();
    let pid_file = workdir(&out).join("sleep.pid");
    let deadline = Instant::now() + Duration::from_secs(60);
    while std::fs::read_to_string(&pid_file).map_or(true, |s| s.trim().is_empty())
        && Instant::now() < deadline
    {
        std::thread::sleep(Duration::from_millis(20));
    }
    let sleeper = pid_in(&pid_file);
    assert!(alive(sleeper));
    // SAFETY: kill(2) to our own child, not yet reaped.
    assert_eq!(unsafe { libc::kill(child.id() as i32, libc::SIGTERM) }, 0);
    let o = finish(child, "interrupted sweep");
    assert_eq!(o.status.code(), Some(130), "{}", text(&o.stderr));
    assert!(
        gone(sleeper),
        "sleep 43 (pid {sleeper}) outlived the interrupted sweep"
    );
}

#[test]
fn a_program_that_leaves_a_child_behind_takes_it_with_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let cfg = config(
        dir.path(),
        r#"command = ["sh", "-c", "echo $$ > group.pid; sleep 43 & echo $! > sleep.pid"]
time = "wall""#,
    );
    let o = run(&mut sweep(&cfg, &out), "sweep");
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let sleeper = pid_in(&workdir(&out).join("sleep.pid"));
    assert!(
        gone(sleeper),
        "the background sleep {sleeper} outlived its program"
    );
    assert!(members_left(pid_in(&workdir(&out).join("group.pid"))).is_empty());
}

#[test]
fn output_past_the_read_back_limit_is_a_failed_sample_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    // The real time comes after 17 MB of output; an early line would time it if only the
    // first 16 MiB were searched.
    let cfg = config(
        dir.path(),
        r#"command = ["sh", "-c", "echo 'elapsed 1 ms'; head -c 17000000 /dev/zero | tr '\\0' x; echo; echo 'elapsed 5 ms'"]
time = { regex = 'elapsed ([0-9.]+) ms', unit = "ms" }"#,
    );
    let o = run(&mut sweep(&cfg, &out), "sweep");
    assert!(!text(&o.stderr).contains("panicked"), "{}", text(&o.stderr));
    let runs = runs(&out);
    assert_eq!(runs.len(), 1);
    assert_eq!(runs[0].reported_s, None, "timed by a line before the limit");
    let e = runs[0].error.as_ref().expect("a failed sample");
    assert!(e.what.contains("16 MiB"), "{}", e.what);
    assert_eq!(
        e.output_tail.last().map(String::as_str),
        Some("elapsed 5 ms")
    );
}

#[test]
fn programs_are_checked_as_they_will_be_started() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let prog = dir.path().join("ext/run.sh");
    std::fs::create_dir_all(prog.parent().unwrap()).unwrap();
    std::fs::write(&prog, "#!/bin/sh\necho 'elapsed 2 ms'\n").unwrap();
    std::fs::set_permissions(&prog, std::fs::Permissions::from_mode(0o755)).unwrap();
    let timed = "time = { regex = 'elapsed ([0-9.]+) ms', unit = \"ms\" }";
    // A relative path is taken from the directory the sweep starts in, for the check and the
    // launch alike (the program itself runs in the case's work directory).
    let out = dir.path().join("out");
    let cfg = config(
        dir.path(),
        &format!("command = [\"./ext/run.sh\"]\n{timed}"),
    );
    let o = run(sweep(&cfg, &out).current_dir(dir.path()), "relative");
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let first = runs(&out);
    assert!(first[0].error.is_none(), "{:?}", first[0].error);
    assert_eq!(first[0].reported_s, Some(2e-3));
    // From elsewhere the same config is refused before anything runs.
    let elsewhere = tempfile::tempdir().unwrap();
    let out2 = dir.path().join("out2");
    let o = run(
        sweep(&cfg, &out2).current_dir(elsewhere.path()),
        "elsewhere",
    );
    refused(&o, "./ext/run.sh");
    refused(&o, "directory the sweep is started in");
    assert!(!out2.exists(), "something ran");
    // A bare name is found on the PATH the env sets, for the check and the launch alike.
    let out3 = dir.path().join("out3");
    let cfg = config(
        dir.path(),
        &format!(
            "command = [\"run.sh\"]\nenv = {{ PATH = \"{}\" }}\n{timed}",
            prog.parent().unwrap().display()
        ),
    );
    let o = run(&mut sweep(&cfg, &out3), "env PATH");
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_eq!(runs(&out3)[0].reported_s, Some(2e-3));
    // Refused with exit 2 before anything runs, naming the key or the reason.
    for (ext, expected) in [
        (
            "command = [\"sh\", \"-c\", \"true\"]\nenv = { PATH = \"\" }",
            "PATH its env sets is empty",
        ),
        (
            "command = [\"sh\", \"-c\", \"true\"]\nenv = { PATH = \"/no/such/dir\" }",
            "/no/such/dir",
        ),
        (
            "command = [\"sh\", \"-c\", \"a\\u0000b\"]",
            "external.x.command",
        ),
        (
            "command = [\"sh\", \"-c\", \"true\"]\nenv = { V = \"a\\u0000b\" }",
            "external.x.env.V",
        ),
        (
            "command = [\"sh\", \"-c\", \"true\"]\ntimeout_s = 1e20",
            "external.x.timeout_s",
        ),
        (
            "command = [\"sh\", \"-c\", \"true\"]\ntimeout_s = 604801",
            "7 days",
        ),
    ] {
        let out = dir.path().join("refused");
        let cfg = config(dir.path(), &format!("{ext}\ntime = \"wall\""));
        let o = run(&mut sweep(&cfg, &out), ext);
        refused(&o, expected);
        assert!(!out.exists(), "{ext}: something ran");
    }
}

/// Runs `script` with bash (for its process substitution `<(...)`), the binary as `$NB`.
fn bash(script: &str, dir: &Path) -> Output {
    run(
        Command::new("bash")
            .current_dir(dir)
            .env("NB", env!("CARGO_BIN_EXE_nbody-bench"))
            .env("ROOT", env!("CARGO_MANIFEST_DIR"))
            .env_remove("NBODY_BENCH_TEST_SLOWDOWN")
            .env_remove(nbody_engine::input::PIPE_WAIT_ENV)
            .args(["-c", script])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped()),
        script,
    )
}

#[test]
fn inputs_are_read_from_pipes() {
    let dir = tempfile::tempdir().unwrap();
    let quick = "$ROOT/results/quick/results.json";
    // analyze <(...): read; its analysis needs --out, there is no directory beside a pipe.
    let o = bash(&format!("$NB analyze <(cat {quick}) --out a"), dir.path());
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert!(dir.path().join("a/fits.json").is_file());
    let o = bash(&format!("$NB analyze <(cat {quick})"), dir.path());
    refused(&o, "is a pipe");
    refused(&o, "--out");
    // gate --current <(...): read, not "no results".
    let o = bash(
        &format!("$NB gate --baseline {quick} --current <(cat {quick})"),
        dir.path(),
    );
    let err = text(&o.stderr);
    assert!(
        !err.contains("no results") && !err.contains("panicked"),
        "{err}"
    );
    assert!(text(&o.stdout).contains("lj-box"), "{}", text(&o.stdout));
    // sweep --config <(...): read (a dry run of an external-only config runs nothing).
    let cfg = config(
        dir.path(),
        "command = [\"sh\", \"-c\", \"true\"]\ntime = \"wall\"",
    );
    let o = bash(
        &format!(
            "$NB sweep --dry-run --config <(cat {}) --out o",
            cfg.display()
        ),
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout).contains("lj-box/x/n=50"),
        "{}",
        text(&o.stdout)
    );
    // A run written back in place cannot be a pipe.
    let o = bash(
        &format!(
            "$NB sweep --config {} --resume <(cat {quick})",
            cfg.display()
        ),
        dir.path(),
    );
    refused(&o, "is a pipe");
    // fit --csv <(...): read.
    let o = bash(
        "$NB fit --model amdahl --csv <(printf 'p,time\\n1,10\\n2,5.6\\n4,3.3\\n8,2.2\\n')",
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
}

#[test]
fn a_named_pipe_nobody_writes_to_is_given_up() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("table.csv");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let o = run(
        bin()
            .env(nbody_engine::input::PIPE_WAIT_ENV, "0.5")
            .args(["fit", "--model", "amdahl", "--csv"])
            .arg(&fifo),
        "fit on a silent pipe",
    );
    refused(&o, "no program wrote to this pipe within 0.5 s");
    refused(&o, fifo.to_str().unwrap());
    // A bad wait is refused, not used.
    let o = run(
        bin()
            .env(nbody_engine::input::PIPE_WAIT_ENV, "inf")
            .args(["fit", "--model", "amdahl", "--csv"])
            .arg(&fifo),
        "bad wait",
    );
    refused(&o, nbody_engine::input::PIPE_WAIT_ENV);
    // With a writer, the table is read.
    let mut writer = Command::new("sh")
        .arg("-c")
        .arg("printf 'p,time\\n1,10\\n2,5.6\\n4,3.3\\n8,2.2\\n' > \"$0\"")
        .arg(&fifo)
        .spawn()
        .unwrap();
    let o = run(
        bin().args(["fit", "--model", "amdahl", "--csv"]).arg(&fifo),
        "fit on a pipe",
    );
    let _ = writer.kill();
    let _ = writer.wait();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
}
