//! Naming the commit that made a case slower (or faster): a bisection of the first-parent
//! commits between an older commit (GOOD) and a newer one (BAD) that differs from it, each
//! midpoint built and measured side by side with both ends of the interval still in doubt,
//! judged with the gate's statistics ([`crate::gate::judge_pair`]). Below, "slow" and "fast"
//! are for the usual [`Direction::Slower`]; [`Direction::Faster`] swaps them.
//!
//! What can go wrong in a plain bisection, and what this one does instead:
//! - a midpoint that does not build (or cannot run the case) is skipped, and its neighbour
//!   nearest the middle is measured instead; when only such commits are left between a fast and
//!   a slow one, the answer is the range, not a guess;
//! - a midpoint faster than the fast end or slower than the slow one means the series is not
//!   monotone between the ends (two opposite steps): the bisection stops and says so, since
//!   either half could hold "the" commit;
//! - a midpoint slower than the fast end *and* faster than the slow one sits between two steps:
//!   the bisection follows the larger one and reports the other;
//! - a midpoint that differs from neither end at the gate's confidence is measured again with
//!   twice the rounds before the nearer end (in log ratio) decides;
//! - the commit is named only when it and its parent, measured side by side, differ at the
//!   gate's confidence; otherwise the slowdown is spread over commits and the answer says so.
//!
//! The measurements come from a [`Probe`]: [`probe::GateProbe`] builds this project's commits in
//! the gate's cached worktrees and runs its interleaved A/B sweeps; a test can bisect any
//! repository with a probe of its own.

pub mod probe;

use crate::gate::{Verdict, judge_pair, prefix};
use crate::git::Rev;
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Builds and measures commits for a bisection.
pub trait Probe {
    /// Builds `commit`, or finds it built; `Err(why)` when it does not build.
    fn build(&mut self, commit: &str) -> Result<(), String>;
    /// Measures the two built commits side by side, interleaved over `rounds` rounds: every
    /// sample of `a`, then of `b` (seconds per step, or any time unit both share).
    fn measure(&mut self, a: &str, b: &str, rounds: usize) -> anyhow::Result<[Vec<f64>; 2]>;
}

/// What changed between GOOD and BAD.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// BAD is slower: find the commit that made the case slower.
    Slower,
    /// BAD is faster: find the commit that made it faster.
    Faster,
}

impl Direction {
    /// The gate's verdict on a change toward BAD.
    fn toward_bad(self) -> Verdict {
        match self {
            Direction::Slower => Verdict::Regressed,
            Direction::Faster => Verdict::Improved,
        }
    }

    /// Where a change of this verdict goes.
    fn way(self, verdict: Verdict) -> Way {
        if verdict == Verdict::Unchanged {
            Way::Level
        } else if verdict == self.toward_bad() {
            Way::TowardBad
        } else {
            Way::Back
        }
    }

    /// The direction as the answer words it: "slower" or "faster".
    pub fn name(self) -> &'static str {
        match self {
            Direction::Slower => "slower",
            Direction::Faster => "faster",
        }
    }
}

/// A change between two commits, seen from the bisection's direction.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Way {
    TowardBad,
    Level,
    /// Against the direction: faster while looking for a slowdown, or the other way round.
    Back,
}

/// How a bisection judges.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    /// Whether BAD is the slower or the faster end.
    pub direction: Direction,
    /// A step smaller than this fraction is not one (the gate's A/B threshold by default).
    pub threshold: f64,
    /// Interleaved rounds of each side-by-side measurement.
    pub rounds: usize,
    /// The bootstrap's seed.
    pub seed: u64,
}

/// Two commits measured side by side: `to`'s median over `from`'s.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Comparison {
    /// Full hash of the commit measured as the reference side.
    pub from: String,
    /// Full hash of the commit measured against it.
    pub to: String,
    /// Median of `to`'s samples over median of `from`'s (above 1: `to` is slower).
    pub ratio: f64,
    /// Bootstrap 95% interval of the ratio; NaN when a side has too few samples for one.
    pub ci95: [f64; 2],
    /// The gate's verdict on `to` against `from` at the bisection's threshold.
    pub verdict: Verdict,
    /// Samples of `from` and of `to` it was judged on, over every round of the pair so far.
    pub samples: [usize; 2],
}

impl Comparison {
    /// "+8.1% [+6.0, +10.2]" (the change from `from` to `to`).
    pub fn size(&self) -> String {
        let pct = |r: f64| (r - 1.0) * 100.0;
        format!(
            "{:+.1}% [{:+.1}, {:+.1}]",
            pct(self.ratio),
            pct(self.ci95[0]),
            pct(self.ci95[1])
        )
    }
}

/// What the bisection found.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
#[serde(tag = "finding", rename_all = "snake_case")]
pub enum Finding {
    /// The first slow commit: it and its parent differ at the gate's confidence.
    Named {
        /// Full hash of the first slow commit.
        culprit: String,
        /// Its parent against it, side by side.
        step: Comparison,
    },
    /// The step is between a fast and a slow commit with only commits that do not build (or
    /// run the case) between them.
    Among {
        /// The fast commit against the slow one.
        step: Comparison,
        /// Full hashes of the commits between them that do not build or cannot run the case.
        unbuilt: Vec<String>,
    },
    /// Adjacent commits, one fast and one slow by the bisection, do not differ side by side:
    /// the slowdown is spread over several commits (a drift) rather than made by one.
    Spread {
        /// The last fast commit against the first slow one: no difference at the gate's
        /// confidence.
        step: Comparison,
    },
    /// A commit between the ends is faster than the fast end or slower than the slow one.
    NotMonotone {
        /// Full hash of the commit between the ends.
        commit: String,
        /// The measurement against the end it went past.
        against: Comparison,
    },
    /// BAD is not slower than GOOD at the gate's confidence: there is nothing to bisect.
    NoStep {
        /// GOOD against BAD, side by side.
        ends: Comparison,
    },
}

/// A bisection's answer and how it got there.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Bisection {
    /// Full hash of the GOOD end.
    pub good: String,
    /// Full hash of the BAD end.
    pub bad: String,
    /// Whether BAD was the slower or the faster end.
    pub direction: Direction,
    /// The commits after GOOD up to BAD along the first parents.
    pub commits: usize,
    /// What the bisection concluded.
    pub finding: Finding,
    /// Commits built (or found built), in order, and the ones that failed with why.
    pub builds: Vec<String>,
    /// Commits that failed to build or to run the case, each with why.
    pub skipped: Vec<(String, String)>,
    /// Every side-by-side measurement, in order (judged on the pair's samples so far).
    pub comparisons: Vec<Comparison>,
    /// Steps seen beside the one followed (a midpoint between two steps).
    pub also: Vec<Comparison>,
}

impl Bisection {
    /// 0 when a commit is named, 1 when the bisection ended without one.
    pub fn exit_code(&self) -> i32 {
        match self.finding {
            Finding::Named { .. } => 0,
            _ => 1,
        }
    }
}

/// The commits after `good` up to `bad` along the first parents, oldest first, with `good`
/// in front: index 0 is GOOD, the last is BAD. `good` must be an ancestor of `bad`.
pub fn first_parent_path(repo: &Path, good: &str, bad: &str) -> anyhow::Result<Vec<String>> {
    let git = |args: &[&str], revs: &[&Rev]| {
        crate::git::command(repo, args, revs)
            .output()
            .map_err(|e| anyhow::anyhow!("cannot run git: {e}"))
    };
    let resolve = |which: &str, rev: &str| -> anyhow::Result<Rev> {
        let given = Rev::given(rev).map_err(|why| anyhow::anyhow!("{which} {why}"))?;
        let out = git(&["rev-parse", "--verify", "--quiet"], &[&given.commit()])?;
        let full = String::from_utf8_lossy(&out.stdout).trim().to_string();
        match Rev::recorded(&full) {
            Some(full) if out.status.success() => Ok(full),
            _ => anyhow::bail!("`{rev}` names no commit of {}", repo.display()),
        }
    };
    let (g, b) = (resolve("GOOD", good)?, resolve("BAD", bad)?);
    if g == b {
        anyhow::bail!(
            "GOOD and BAD are the same commit ({}): nothing lies between them",
            prefix(g.as_str(), 12)
        );
    }
    if !git(&["merge-base", "--is-ancestor"], &[&g, &b])?
        .status
        .success()
    {
        anyhow::bail!(
            "{good} is not an ancestor of {bad}: give the older, fast commit first (GOOD) and \
             the newer, slow one second (BAD)"
        );
    }
    let out = git(
        &["rev-list", "--first-parent", "--reverse"],
        &[&Rev::range(&g, &b)],
    )?;
    let (g, b) = (g.to_string(), b.to_string());
    let mut path = vec![g.clone()];
    path.extend(
        String::from_utf8_lossy(&out.stdout)
            .lines()
            .map(str::to_string),
    );
    if path.last() != Some(&b) {
        anyhow::bail!(
            "{bad} is not on the first-parent line from {good} (it came in by a merge): give \
             the merge commit as BAD"
        );
    }
    Ok(path)
}

/// Bisects `path` (GOOD first, BAD last) with `probe`; `say` hears the progress.
pub fn bisect(
    path: &[String],
    probe: &mut dyn Probe,
    settings: Settings,
    say: &mut dyn FnMut(&str),
) -> anyhow::Result<Bisection> {
    if path.len() < 2 {
        anyhow::bail!("a bisection needs two commits, GOOD and BAD");
    }
    let mut run = Run {
        probe,
        settings,
        built: BTreeSet::new(),
        samples: BTreeMap::new(),
        builds: Vec::new(),
        skipped: Vec::new(),
        comparisons: Vec::new(),
        also: Vec::new(),
    };
    for end in [&path[0], &path[path.len() - 1]] {
        if let Err(why) = run.build(end) {
            anyhow::bail!(
                "{} does not build, so it cannot be an end: {why}",
                prefix(end, 12)
            );
        }
    }
    say(&format!(
        "{} commits after {} up to {}: the ends side by side",
        path.len() - 1,
        prefix(&path[0], 12),
        prefix(&path[path.len() - 1], 12)
    ));
    let ends = run.compare(&path[0], &path[path.len() - 1], settings.rounds)?;
    say(&format!("  {}", ends.size()));
    let dir = settings.direction;
    if dir.way(ends.verdict) != Way::TowardBad {
        return Ok(run.finish(path, Finding::NoStep { ends }));
    }
    let (mut lo, mut hi) = (0, path.len() - 1);
    let mut unbuilt: BTreeSet<usize> = BTreeSet::new();
    while let Some(mid) = midpoint(lo, hi, &unbuilt) {
        let commit = &path[mid];
        say(&format!(
            "{} commits in doubt; measuring {} against {} and {}",
            hi - lo - 1,
            prefix(commit, 12),
            prefix(&path[lo], 12),
            prefix(&path[hi], 12)
        ));
        if let Err(why) = run.build(commit) {
            say(&format!("  skipped: {why}"));
            unbuilt.insert(mid);
            continue;
        }
        let (left, right) = match run.both_sides(&path[lo], commit, &path[hi], say) {
            Ok(pair) => pair,
            Err(e) => {
                // A commit that builds but cannot run the case is as good as unbuilt.
                let why = format!("{e:#}");
                say(&format!("  skipped: {why}"));
                run.skipped.push((commit.clone(), why));
                unbuilt.insert(mid);
                continue;
            }
        };
        use Way::{Back, Level, TowardBad};
        match (dir.way(left.verdict), dir.way(right.verdict)) {
            (Back, _) | (_, Back) => {
                let against = if dir.way(left.verdict) == Back {
                    left
                } else {
                    right
                };
                let finding = Finding::NotMonotone {
                    commit: commit.clone(),
                    against,
                };
                return Ok(run.finish(path, finding));
            }
            (Level, TowardBad) => lo = mid,
            (TowardBad, Level) => hi = mid,
            (TowardBad, TowardBad) => {
                // Two steps: follow the larger, keep the other in the answer.
                if left.ratio.ln().abs() >= right.ratio.ln().abs() {
                    run.also.push(right);
                    hi = mid;
                } else {
                    run.also.push(left);
                    lo = mid;
                }
            }
            (Level, Level) => {
                // Twice the rounds could not tell either: the nearer end decides.
                if left.ratio.ln().abs() <= right.ratio.ln().abs() {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
        }
    }
    let step = run.compare(&path[lo], &path[hi], settings.rounds)?;
    let between: Vec<String> = (lo + 1..hi).map(|i| path[i].clone()).collect();
    let finding = if dir.way(step.verdict) != Way::TowardBad {
        Finding::Spread { step }
    } else if between.is_empty() {
        Finding::Named {
            culprit: path[hi].clone(),
            step,
        }
    } else {
        Finding::Among {
            step,
            unbuilt: between,
        }
    };
    Ok(run.finish(path, finding))
}

/// The commit between `lo` and `hi` to measure next: the one nearest the middle that has not
/// failed to build; `None` when none is left.
fn midpoint(lo: usize, hi: usize, unbuilt: &BTreeSet<usize>) -> Option<usize> {
    let middle = lo + (hi - lo) / 2;
    (lo + 1..hi)
        .filter(|i| !unbuilt.contains(i))
        .min_by_key(|&i| (i.abs_diff(middle), i))
}

/// A bisection under way: what is built, every sample measured so far by pair.
struct Run<'a> {
    probe: &'a mut dyn Probe,
    settings: Settings,
    built: BTreeSet<String>,
    /// Samples of (from, to) measured side by side; measuring a pair again adds to them.
    samples: BTreeMap<(String, String), [Vec<f64>; 2]>,
    builds: Vec<String>,
    skipped: Vec<(String, String)>,
    comparisons: Vec<Comparison>,
    also: Vec<Comparison>,
}

impl Run<'_> {
    fn finish(self, path: &[String], finding: Finding) -> Bisection {
        Bisection {
            good: path[0].clone(),
            bad: path[path.len() - 1].clone(),
            direction: self.settings.direction,
            commits: path.len() - 1,
            finding,
            builds: self.builds,
            skipped: self.skipped,
            comparisons: self.comparisons,
            also: self.also,
        }
    }

    fn build(&mut self, commit: &str) -> Result<(), String> {
        if self.built.contains(commit) {
            return Ok(());
        }
        self.builds.push(commit.to_string());
        match self.probe.build(commit) {
            Ok(()) => {
                self.built.insert(commit.to_string());
                Ok(())
            }
            Err(why) => {
                self.skipped.push((commit.to_string(), why.clone()));
                Err(why)
            }
        }
    }

    /// `mid` against the fast end and the slow end, measured again with twice the rounds when
    /// neither differs.
    fn both_sides(
        &mut self,
        lo: &str,
        mid: &str,
        hi: &str,
        say: &mut dyn FnMut(&str),
    ) -> anyhow::Result<(Comparison, Comparison)> {
        let rounds = self.settings.rounds;
        let mut left = self.compare(lo, mid, rounds)?;
        let mut right = self.compare(mid, hi, rounds)?;
        say(&format!(
            "  from GOOD's side {}, to BAD's side {}",
            left.size(),
            right.size()
        ));
        if left.verdict == Verdict::Unchanged && right.verdict == Verdict::Unchanged {
            say("  neither differs at the gate's confidence: measuring again");
            left = self.compare(lo, mid, 2 * rounds)?;
            right = self.compare(mid, hi, 2 * rounds)?;
            say(&format!(
                "  from GOOD's side {}, to BAD's side {}",
                left.size(),
                right.size()
            ));
        }
        Ok((left, right))
    }

    /// `to` against `from`: `rounds` more rounds side by side, judged on every sample of the
    /// pair so far (a pair already measured at these rounds is not measured again).
    fn compare(&mut self, from: &str, to: &str, rounds: usize) -> anyhow::Result<Comparison> {
        let key = (from.to_string(), to.to_string());
        let have = self.samples.get(&key).map_or(0, |s| s[0].len());
        let measure = have == 0 || rounds > self.settings.rounds;
        if measure {
            let [a, b] = self.probe.measure(from, to, rounds)?;
            let entry = self.samples.entry(key.clone()).or_default();
            entry[0].extend(a);
            entry[1].extend(b);
        }
        let [a, b] = &self.samples[&key];
        let seed =
            self.settings.seed ^ nbody_records::results::fnv1a(format!("{from}{to}").as_bytes());
        let (ratio, ci95, verdict) = judge_pair(a, b, self.settings.threshold, seed);
        let comparison = Comparison {
            from: from.to_string(),
            to: to.to_string(),
            ratio,
            ci95,
            verdict,
            samples: [a.len(), b.len()],
        };
        if measure {
            self.comparisons.push(comparison.clone());
        }
        Ok(comparison)
    }
}

#[cfg(test)]
mod tests;
