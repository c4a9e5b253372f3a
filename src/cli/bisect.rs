//! `nbody-bench bisect`: the commit between a fast and a slow one that made a case slower (or,
//! with `--faster`, faster), found by building midpoints and measuring each side by side with
//! both ends in doubt.

use clap::Args;
use nbody_harness::gate::{AB_ROUNDS, AB_THRESHOLD, prefix};
use nbody_harness::history::bisect::probe::GateProbe;
use nbody_harness::history::bisect::{self, Bisection, Direction, Finding, Settings};
use std::path::PathBuf;

#[derive(Debug, Args)]
#[command(after_help = "Examples:\n  \
    nbody-bench bisect --case 'galaxy/symmetric/n=4000/p=1/r=1/seed=1' --config configs/backfill.toml cc46656 db62323\n  \
    nbody-bench history --case 'galaxy/*'     # find the two commits first\n\n\
    Every commit is built once in the gate's cached worktrees (target/gate-base/; minutes \
    each the first time) and measured on a quiet machine, side by side with the fast and the \
    slow end still in doubt (the gate's interleaved A/B sweeps and its statistics). A commit \
    that does not build or cannot run the case is skipped. The commit is named only when it \
    and its parent differ at the gate's confidence; otherwise the answer says why not: the \
    slowdown is spread over several commits, lies among commits that do not build, or the \
    series is not monotone between the ends (two opposite steps).\n\n\
    With --faster it names the commit that made the case faster instead (BAD the newer, faster \
    end).\n\n\
    Exit codes: 0 a commit named, 1 none named (the answer says why), 2 bad input.")]
pub struct BisectArgs {
    /// The last commit known fast (an ancestor of BAD).
    #[arg(value_name = "GOOD")]
    pub good: String,
    /// The first commit known slow.
    #[arg(value_name = "BAD")]
    pub bad: String,
    /// The case to bisect: its key as `history` and the results files name it.
    #[arg(long, value_name = "KEY")]
    pub case: String,
    /// The sweep config that plans the case (every commit between must read it).
    #[arg(long, value_name = "CONFIG", default_value = "configs/ci.toml")]
    pub config: PathBuf,
    /// Interleaved rounds of each side-by-side measurement (a midpoint that differs from
    /// neither end is measured again with twice as many): even, from 2 to 100, as the gate's
    /// --rounds.
    #[arg(long, default_value_t = AB_ROUNDS, value_parser = crate::cli::values::parse_ab_rounds)]
    pub rounds: usize,
    /// The smallest change taken for a step, as a fraction (the gate's A/B threshold).
    #[arg(long, default_value_t = AB_THRESHOLD)]
    pub threshold: f64,
    /// Where each side-by-side run and the answer (bisect.json) are kept, in a folder of
    /// their own per bisection.
    #[arg(long, value_name = "DIR", default_value = "results/runs/bisect")]
    pub runs: PathBuf,
    /// Find the commit that made the case faster (BAD is then the faster, newer end).
    #[arg(long)]
    pub faster: bool,
    /// Print the answer as JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

pub fn bisect(args: BisectArgs) -> anyhow::Result<i32> {
    nbody_harness::gate::check_threshold(args.threshold)?;
    nbody_harness::gate::ab::check_rounds(args.rounds)?;
    let repo = nbody_harness::gate::base_build::repository_root(&std::env::current_dir()?)?;
    let config = nbody_records::locate::find_config(&args.config)?;
    let path = bisect::first_parent_path(&repo, &args.good, &args.bad)?;
    let runs = args.runs.join(format!(
        "{}-{}",
        nbody_engine::output::provenance::utc_now().replace(':', "-"),
        prefix(&path[path.len() - 1], 12)
    ));
    let mut probe = GateProbe::new(
        &repo,
        &config,
        &args.case,
        &runs,
        Box::new(|line: &str| eprintln!("bisect: {line}")),
    )?;
    let settings = Settings {
        direction: if args.faster {
            Direction::Faster
        } else {
            Direction::Slower
        },
        threshold: args.threshold,
        rounds: args.rounds,
        seed: 0xb15ec7,
    };
    let found = bisect::bisect(&path, &mut probe, settings, &mut |line| {
        eprintln!("bisect: {line}")
    })?;
    let json = serde_json::to_string_pretty(&found)?;
    let kept = runs.join("bisect.json");
    nbody_engine::output::write_atomic(&kept, format!("{json}\n").as_bytes())?;
    if args.json {
        outln!("{json}");
    } else {
        outln!("{}", describe(&found, &args.case));
    }
    eprintln!("bisect: every measurement is kept in {}", runs.display());
    Ok(found.exit_code())
}

/// The answer in words.
fn describe(found: &Bisection, case: &str) -> String {
    let p = |c: &str| prefix(c, 12).to_string();
    let way = found.direction.name();
    let (good, bad) = match found.direction {
        Direction::Slower => ("fast", "slow"),
        Direction::Faster => ("slow", "fast"),
    };
    let mut text = match &found.finding {
        Finding::Named { culprit, step } => format!(
            "{case}: {} made it {way}: {} against its parent {}",
            p(culprit),
            step.size(),
            p(&step.from)
        ),
        Finding::Among { step, unbuilt } => format!(
            "{case}: the step ({}) is in {}, or in the commits between that do not build or \
             run the case: {}",
            step.size(),
            p(&step.to),
            unbuilt.iter().map(|c| p(c)).collect::<Vec<_>>().join(", ")
        ),
        Finding::Spread { step } => format!(
            "{case}: no single commit: {} ({good}) and {} ({bad}) differ by {}, less than the \
             gate can tell; the change is spread over several commits (a drift)",
            p(&step.from),
            p(&step.to),
            step.size()
        ),
        Finding::NotMonotone { commit, against } => {
            format!(
                "{case}: not monotone between the ends: {} against {} is {} — a step up and one \
             down lie between them; bisect each half with its own ends",
                p(&against.to),
                p(&against.from),
                against.size()
            ) + &format!(" (at {})", p(commit))
        }
        Finding::NoStep { ends } => format!(
            "{case}: {} is not {way} than {} at the gate's confidence ({}): nothing to bisect{}",
            p(&ends.to),
            p(&ends.from),
            ends.size(),
            match found.direction {
                Direction::Slower => " (--faster looks for a speed-up)",
                Direction::Faster => "",
            }
        ),
    };
    for other in &found.also {
        text.push_str(&format!(
            "\nanother step, not followed: {} from {} to {}",
            other.size(),
            p(&other.from),
            p(&other.to)
        ));
    }
    text.push_str(&format!(
        "\n{} commits between the ends; {} built or found built, {} skipped, {} side-by-side \
         measurements",
        found.commits,
        found.builds.len(),
        found.skipped.len(),
        found.comparisons.len()
    ));
    for (commit, why) in &found.skipped {
        let first = why.lines().next().unwrap_or_default();
        text.push_str(&format!("\n  skipped {}: {first}", p(commit)));
    }
    text
}
