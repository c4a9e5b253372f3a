//! Backfilling a history from the project's past: every K-th commit of a range along the
//! first parents, each built in the gate's cached worktree and measured side by side with this
//! build (the gate's interleaved A/B run), both sides recorded. This build's side, measured again
//! at every commit, is the control: a step in it is the machine's, not the code's.

use super::store::{self, CommitFacts};
use super::verdicts;
use crate::gate::base_build;
use crate::gate::drive::{self, Request};
use crate::gate::route::this_machine;
use nbody_records::results::ResultsFile;
use std::path::{Path, PathBuf};

/// What to backfill.
pub struct Backfill {
    /// `A..B`: the commits after A up to B, along the first parents.
    pub range: String,
    /// Every K-th of them, counted back from B (B always included).
    pub every: usize,
    /// The sweep config both sides run (it must be one every commit of the range reads).
    pub config: PathBuf,
    /// Interleaved rounds per case and side.
    pub rounds: usize,
    /// The history folder, and where the runs are kept.
    pub dir: PathBuf,
    /// Where the runs are kept: a folder per backfill (named by its UTC start), in it one per
    /// commit.
    pub runs: PathBuf,
    /// Build (or find cached) every commit's binary and stop: the builds need no quiet
    /// machine, the measurements do.
    pub build_only: bool,
}

/// How one commit went.
pub enum Done {
    /// Measured: the records appended.
    Recorded {
        /// Full hash of the commit.
        commit: String,
        /// History records appended, of both sides.
        records: usize,
    },
    /// Not measured (it does not build, or does not read the config): why.
    Skipped {
        /// Full hash of the commit.
        commit: String,
        /// The build's or the gate run's error.
        why: String,
    },
    /// Built (or found in the cache), not measured: `build_only`.
    Built {
        /// Full hash of the commit.
        commit: String,
    },
}

/// The commits of `range` to measure, oldest first: every `every`-th counted back from the
/// range's end, which is always included.
pub fn commits(repo: &Path, range: &str, every: usize) -> anyhow::Result<Vec<String>> {
    if every == 0 {
        anyhow::bail!("every 0th commit is none: measure every K-th commit with K at least 1");
    }
    let (from, to) = crate::git::given_range(range).map_err(anyhow::Error::msg)?;
    let range = crate::git::Rev::range(&from, &to);
    let out = crate::git::command(
        repo,
        &["rev-list", "--first-parent", "--reverse"],
        &[&range],
    )
    .output()
    .map_err(|e| anyhow::anyhow!("cannot run git: {e}"))?;
    if !out.status.success() {
        anyhow::bail!(
            "git rev-list {range}: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    let all: Vec<String> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(str::to_string)
        .collect();
    if all.is_empty() {
        anyhow::bail!("{range} holds no commit");
    }
    let last = all.len() - 1;
    Ok(all
        .into_iter()
        .enumerate()
        .filter(|(i, _)| (last - i).is_multiple_of(every))
        .map(|(_, c)| c)
        .collect())
}

/// Measures each commit of the backfill against this build and appends both sides to the
/// history; `say` hears the progress. A commit that fails is skipped with its reason.
pub fn backfill(job: &Backfill, say: &mut dyn FnMut(&str)) -> anyhow::Result<Vec<Done>> {
    // Refused before the builds, which take minutes each, as the gate refuses them.
    crate::gate::ab::check_rounds(job.rounds)?;
    let repo = base_build::repository_root(&std::env::current_dir()?)?;
    let commits = commits(&repo, &job.range, job.every)?;
    say(&format!(
        "{} commits of {} to measure, each against this build",
        commits.len(),
        job.range
    ));
    // Every build first: minutes each, and they need no quiet machine; the measurements
    // that follow then run back to back.
    let mut done = Vec::new();
    let mut built = Vec::new();
    for (i, commit) in commits.iter().enumerate() {
        say(&format!(
            "build {}/{}: {}",
            i + 1,
            commits.len(),
            crate::gate::prefix(commit, 12)
        ));
        match base_build::base_binary(&repo, commit, say) {
            Ok(_) => built.push(commit.clone()),
            Err(e) => {
                let why = e.to_string();
                say(&format!("skipped: {why}"));
                done.push(Done::Skipped {
                    commit: commit.clone(),
                    why,
                });
            }
        }
    }
    if job.build_only {
        done.extend(built.into_iter().map(|commit| Done::Built { commit }));
        return Ok(done);
    }
    let machine = this_machine();
    // Each backfill keeps its runs apart: a commit measured again is a new run, not a refusal.
    let runs = job
        .runs
        .join(nbody_engine::output::provenance::utc_now().replace(':', "-"));
    for (i, commit) in built.iter().enumerate() {
        say(&format!(
            "measure {}/{}: {}",
            i + 1,
            built.len(),
            crate::gate::prefix(commit, 12)
        ));
        let out = runs.join(crate::gate::prefix(commit, 12));
        let request = Request {
            baseline: runs.join("no-baseline"),
            current: None,
            against: Some(commit.clone()),
            config: Some(job.config.clone()),
            rounds: job.rounds,
            // The history measures every commit alike: one look, no case measured further.
            max_rounds: job.rounds,
            // Turns: the history's times are one build alone on the machine, as in CI's sweeps.
            sides: Some(crate::gate::duet::Sides::Turns),
            timeout: None,
            out: Some(out.clone()),
            threshold: None,
            normalize: crate::gate::NormalizationChoice::Auto,
            judge: None,
            force: true,
            fail_on_work_change: false,
        };
        let outcome = match drive::run(&request, say) {
            Ok(outcome) => outcome,
            Err(e) => {
                let why = format!("{e:#}");
                say(&format!("skipped: {why}"));
                done.push(Done::Skipped {
                    commit: commit.clone(),
                    why,
                });
                continue;
            }
        };
        // The run's verdicts too: the page shows the latest of them beside the series.
        verdicts::append(
            &job.dir,
            &[verdicts::GateRun::of(&outcome.report, &machine)],
        )?;
        let mut records = 0;
        for side in ["base.json", "current.json"] {
            let file = ResultsFile::load(&out.join(side))?;
            let facts = CommitFacts::of(&repo, &file.metadata.git_commit);
            let mut recs = store::records_of(&file, "backfill", &facts, &machine);
            // The base side's binary was built from the commit itself: its metadata names it.
            if side == "base.json" {
                for r in &mut recs {
                    r.commit.clone_from(commit);
                }
            }
            records += recs.len();
            store::append(&job.dir, &recs)?;
        }
        done.push(Done::Recorded {
            commit: commit.clone(),
            records,
        });
    }
    Ok(done)
}

#[cfg(test)]
mod tests {
    use super::commits;

    #[test]
    fn every_kth_commit_counted_back_from_the_end() {
        let repo = &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        // Skip where the checkout has no history (a source archive).
        let Ok(all) = commits(repo, "HEAD~6..HEAD", 1) else {
            return;
        };
        if all.len() < 6 {
            return;
        }
        let picked = commits(repo, "HEAD~6..HEAD", 3).unwrap();
        assert_eq!(picked, [all[2].clone(), all[5].clone()]);
        assert!(commits(repo, "HEAD", 1).is_err());
    }
}
