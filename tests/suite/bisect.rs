//! `bisect` on a fixture repository: 17 commits of a small C program (16 after GOOD), one of
//! which makes it do 8% more work; in some trials another commit does not compile. Each
//! commit is really checked out and compiled (`cc`, milliseconds); the program prints the work
//! it did, and a run's time is that work times seeded log-normal noise of the gate's own A/A
//! spread, with a slow common drift per round and rare spikes, so that the 20 trials are
//! reproducible. The bisection must name the commit in at least 19 of them, with at most
//! ⌈log₂ 16⌉ + 3 builds. The command line's refusals are checked through the binary.

use super::{bin, refused};
use nbody_harness::history::bisect::{self, Finding, Probe, Settings};
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rand_pcg::Pcg64Mcg;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Commits after GOOD.
const COMMITS: usize = 16;
/// The work of the fast program, and the known slowdown.
const WORK: u64 = 200_000;
const SLOWDOWN: f64 = 1.08;

fn git(repo: &Path, args: &[&str]) -> String {
    let out = Command::new("git")
        .arg("-C")
        .arg(repo)
        .args([
            "-c",
            "user.name=fixture",
            "-c",
            "user.email=fixture@example.org",
        ])
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "git {args:?}: {}",
        super::text(&out.stderr)
    );
    super::text(&out.stdout).trim().to_string()
}

fn program(work: u64, revision: usize, broken: bool) -> String {
    format!(
        "#include <stdio.h>\n\
         /* revision {revision} */\n\
         int main(void) {{\n\
         \x20   volatile unsigned long sum = 0;\n\
         \x20   unsigned long done = 0;\n\
         \x20   for (unsigned long i = 0; i < {work}UL; i++) {{ sum += i; done++; }}\n\
         \x20   printf(\"%lu\\n\", done){}\n\
         \x20   return 0;\n\
         }}\n",
        if broken { "" } else { ";" }
    )
}

/// A repository whose commit `culprit` (1..=16) raises the work by [`SLOWDOWN`] and whose
/// commit `broken` (if any) does not compile; its commits, GOOD first.
fn fixture(dir: &Path, culprit: usize, broken: Option<usize>) -> Vec<String> {
    git(dir, &["init", "-q", "-b", "main"]);
    let mut commits = Vec::new();
    for revision in 0..=COMMITS {
        let work = if revision >= culprit {
            (WORK as f64 * SLOWDOWN) as u64
        } else {
            WORK
        };
        let source = program(work, revision, broken == Some(revision));
        std::fs::write(dir.join("work.c"), source).unwrap();
        git(dir, &["add", "work.c"]);
        git(
            dir,
            &["commit", "-q", "-m", &format!("revision {revision}")],
        );
        commits.push(git(dir, &["rev-parse", "HEAD"]));
    }
    commits
}

/// Builds a commit's program with `cc`; measures by running it and drawing times from the
/// work it prints.
struct FixtureProbe {
    repo: PathBuf,
    bin: PathBuf,
    work: BTreeMap<String, f64>,
    rng: Pcg64Mcg,
    builds: usize,
}

impl Probe for FixtureProbe {
    fn build(&mut self, commit: &str) -> Result<(), String> {
        self.builds += 1;
        let source = self.bin.join(format!("{commit}.c"));
        std::fs::write(
            &source,
            git(&self.repo, &["show", &format!("{commit}:work.c")]),
        )
        .unwrap();
        let exe = self.bin.join(commit);
        let out = Command::new("cc")
            .args(["-O1", "-o"])
            .arg(&exe)
            .arg(&source)
            .output()
            .map_err(|e| format!("cannot run cc: {e}"))?;
        if !out.status.success() {
            return Err(super::text(&out.stderr));
        }
        let ran = Command::new(&exe).output().map_err(|e| e.to_string())?;
        let work: f64 = super::text(&ran.stdout)
            .trim()
            .parse()
            .map_err(|e| format!("{e}"))?;
        self.work.insert(commit.to_string(), work);
        Ok(())
    }

    fn measure(&mut self, a: &str, b: &str, rounds: usize) -> anyhow::Result<[Vec<f64>; 2]> {
        let (wa, wb) = (self.work[a], self.work[b]);
        let mut out = [Vec::new(), Vec::new()];
        for _ in 0..rounds {
            // The machine's drift: both sides of a round share it.
            let drift: f64 = 0.01 * self.rng.sample::<f64, _>(StandardNormal);
            for _ in 0..3 {
                for (side, work) in [(0, wa), (1, wb)] {
                    let z: f64 = self.rng.sample(StandardNormal);
                    let spike = if self.rng.random_bool(0.03) {
                        self.rng.random_range(1.2..1.6)
                    } else {
                        1.0
                    };
                    out[side].push(work * 1e-9 * (drift + 0.02 * z).exp() * spike);
                }
            }
        }
        Ok(out)
    }
}

#[test]
fn the_commit_is_named_in_19_of_20_seeded_trials_within_the_build_budget() {
    if Command::new("cc").arg("--version").output().is_err() {
        panic!("`cc` is needed to build the fixture repository's program (apt install gcc)");
    }
    let budget = (COMMITS as f64).log2().ceil() as usize + 3;
    let mut named = 0;
    let mut misses = Vec::new();
    for trial in 0..20u64 {
        let dir = tempfile::tempdir().unwrap();
        let repo = dir.path().join("repo");
        std::fs::create_dir(&repo).unwrap();
        let culprit = 1 + (trial as usize * 7) % COMMITS;
        // Every other trial, a commit away from the culprit does not compile.
        let broken = (trial % 2 == 1).then(|| 1 + (culprit + 4) % (COMMITS - 1));
        let commits = fixture(&repo, culprit, broken.filter(|&b| b + 1 != culprit));
        let path = bisect::first_parent_path(&repo, &commits[0], &commits[COMMITS]).unwrap();
        assert_eq!(path, commits);
        let mut probe = FixtureProbe {
            repo: repo.clone(),
            bin: dir.path().to_path_buf(),
            work: BTreeMap::new(),
            rng: Pcg64Mcg::seed_from_u64(1000 + trial),
            builds: 0,
        };
        let settings = Settings {
            direction: bisect::Direction::Slower,
            threshold: nbody_harness::gate::AB_THRESHOLD,
            rounds: nbody_harness::gate::AB_ROUNDS,
            seed: trial,
        };
        let found = bisect::bisect(&path, &mut probe, settings, &mut |_| {}).unwrap();
        assert!(
            probe.builds <= budget,
            "trial {trial}: {} builds, more than ⌈log₂ {COMMITS}⌉ + 3 = {budget}",
            probe.builds
        );
        match &found.finding {
            Finding::Named { culprit: c, .. } if c == &commits[culprit] => named += 1,
            other => misses.push(format!("trial {trial} (culprit {culprit}): {other:?}")),
        }
    }
    eprintln!("bisect fixture: named in {named} of 20 trials; missed: {misses:#?}");
    assert!(named >= 19, "named in {named} of 20 trials: {misses:#?}");
}

#[test]
fn bad_ends_and_unknown_cases_are_refused_before_any_build() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    // Skip where the checkout has no history (a source archive).
    if git(root, &["rev-list", "--count", "HEAD"])
        .parse::<usize>()
        .unwrap_or(0)
        < 3
    {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str]| {
        bin()
            .current_dir(root)
            .arg("bisect")
            .args(args)
            .args(["--runs", dir.path().to_str().unwrap()])
            .output()
            .unwrap()
    };
    let key = "lj-box/naive/n=1000/p=1/r=1/seed=1";
    refused(
        &run(&[
            "--case",
            key,
            "--config",
            "configs/backfill.toml",
            "HEAD",
            "HEAD~2",
        ]),
        "is not an ancestor of",
    );
    refused(
        &run(&[
            "--case",
            key,
            "--config",
            "configs/backfill.toml",
            "HEAD",
            "HEAD",
        ]),
        "the same commit",
    );
    refused(
        &run(&[
            "--case",
            key,
            "--config",
            "configs/backfill.toml",
            "no-such-rev",
            "HEAD",
        ]),
        "`no-such-rev` names no commit",
    );
    refused(
        &run(&[
            "--case",
            "lj-box/nope",
            "--config",
            "configs/backfill.toml",
            "HEAD~2",
            "HEAD",
        ]),
        "plans no case `lj-box/nope`",
    );
    refused(
        &run(&["--case", key, "--rounds", "0", "HEAD~2", "HEAD"]),
        "rounds",
    );
    // Nothing was measured, so nothing was kept.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}
