use crate::cli::SweepArgs;
use crate::commands::fmt_ns;
use crate::experiment::config::SweepConfig;
use crate::experiment::measure::WallClock;
use crate::experiment::progress;
use crate::experiment::results::ResultsFile;
use crate::experiment::runner::{SweepOptions, run_sweep};

pub fn sweep(args: SweepArgs) -> anyhow::Result<i32> {
    let (config, text) = SweepConfig::load(&args.config)?;
    let options = SweepOptions {
        resume: args.resume,
        force: args.force,
        fresh: args.fresh,
        out: args.out,
        calibrate: !args.no_calibration,
        stop_after: None,
    };
    let mut observer = progress::for_stderr();
    let report = run_sweep(
        &config,
        &text,
        &options,
        &WallClock::new(),
        observer.as_mut(),
    )?;
    let results = ResultsFile::load(&report.path)?;
    print_table(&results);
    println!(
        "\n{} cases, {} rounds measured in this run; results in {}",
        report.cases,
        report.rounds_measured,
        report.path.display()
    );
    if report.incomplete > 0 {
        println!(
            "{} cases are not complete; run `nbody-bench sweep --config {} --resume` to finish them",
            report.incomplete,
            args.config.display()
        );
    }
    Ok(0)
}

fn print_table(results: &ResultsFile) {
    println!(
        "{:<52} {:>11} {:>23} {:>11} {:>10} {:>6}",
        "case", "per step", "95% CI", "ns/p-step", "pairs/s", "sanity"
    );
    for c in &results.cases {
        let Some(s) = &c.summary else {
            println!("{:<52} {:>11}", c.key, "not measured");
            continue;
        };
        println!(
            "{:<52} {:>11} {:>23} {:>11.1} {:>10.2e} {:>6}{}",
            c.key,
            fmt_ns(s.median_s * 1e9),
            format!(
                "[{}, {}]",
                fmt_ns(s.ci95_s[0] * 1e9),
                fmt_ns(s.ci95_s[1] * 1e9)
            ),
            s.ns_per_particle_step,
            s.pair_evals_per_s,
            if s.sanity_ok { "ok" } else { "DRIFT" },
            if c.oversubscribed {
                "  (oversubscribed)"
            } else {
                ""
            }
        );
    }
}
