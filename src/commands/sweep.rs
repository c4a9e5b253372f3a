use crate::cli::SweepArgs;
use crate::commands::fmt_ns;
use crate::experiment::config::SweepConfig;
use crate::experiment::measure::WallClock;
use crate::experiment::progress;
use crate::experiment::results::ResultsFile;
use crate::experiment::runner::{SweepOptions, run_sweep};

pub fn sweep(args: SweepArgs) -> anyhow::Result<i32> {
    let (config, text) = SweepConfig::load(&args.config)?;
    if let Some(code) = super::dry_run::before_sweep(&args, &config)? {
        return Ok(code);
    }
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
    print_speedups(&results);
    println!(
        "\n{} cases, {} rounds measured in this run; results in {}",
        report.cases,
        report.rounds_measured,
        report.path.display()
    );
    // The analysis is a convenience on top of the measurements: if it fails, the results
    // are already saved and `analyze` can be run again.
    let dir = super::analyze::default_dir(&report.path);
    match super::analyze::run(&results, &report.path, &dir) {
        Ok(written) => super::analyze::print_written(&written),
        Err(e) => eprintln!(
            "warning: analysis failed ({e:#}); the results are saved, retry with `nbody-bench analyze {}`",
            report.path.display()
        ),
    }
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

/// Speedup of every multi-thread case over its one-thread twin, raw and relative to the
/// calibrated hardware ceiling (the throughput ratio of an embarrassingly parallel loop).
fn print_speedups(results: &ResultsFile) {
    let ceiling = |p: usize| {
        results
            .calibration
            .start
            .as_ref()
            .and_then(|c| c.ceiling(p))
    };
    let mut lines = Vec::new();
    for c in results.cases.iter().filter(|c| c.case.threads > 1) {
        let mut one = c.case.clone();
        one.threads = 1;
        let base = results
            .cases
            .iter()
            .find(|o| o.case == one)
            .and_then(|o| o.summary.as_ref());
        let (Some(base), Some(s)) = (base, c.summary.as_ref()) else {
            continue;
        };
        if s.median_s <= 0.0 {
            continue;
        }
        let speedup = base.median_s / s.median_s;
        let relative = match ceiling(c.case.threads) {
            Some(h) if h > 0.0 => format!("{:>6.2}  (ceiling {h:.2}x)", speedup / h),
            _ => "     -".to_string(),
        };
        lines.push(format!(
            "{:<52} {:>7.2}x {:>6.2} {}{}",
            c.key,
            speedup,
            speedup / c.case.threads as f64,
            relative,
            if c.oversubscribed {
                "  oversubscribed: not a parallel measurement"
            } else {
                ""
            }
        ));
    }
    if !lines.is_empty() {
        println!(
            "\n{:<52} {:>8} {:>6} {:>6}",
            "speedup over the same case on 1 thread", "raw", "eff.", "/ceiling"
        );
        for l in lines {
            println!("{l}");
        }
    }
}
