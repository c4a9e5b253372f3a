//! The tables of docs/explanation/gate.md, generated from the committed study files: the
//! gate's false alarms and power as it is configured, and the measurements its rule,
//! thresholds and mode were chosen from.

use super::decide::Mode;
use super::{Load, Method, SLOWDOWNS, StudyFile, StudyRun};
use crate::gate::{AB_JUDGE, AB_THRESHOLD, FILE_JUDGE, FILE_THRESHOLD, Judged};
use crate::render::tables::{Align, Table};

/// Marks of the generated region in docs/explanation/gate.md.
pub const BEGIN: &str =
    "<!-- generated from results/gate-study/ by `nbody-bench gate-study --docs`: do not edit -->";
/// End mark of the generated region in docs/explanation/gate.md.
pub const END: &str = "<!-- end of generated region -->";

/// The threshold a run's decisions were configured with: today's defaults, or for a run
/// judged before paired decisions the defaults of that rule (A/B 3%, fast path 10%).
fn threshold(run: &StudyRun, mode: Mode) -> f64 {
    match (run.method, mode) {
        (Method::PairedSequential, Mode::Ab | Mode::AbMedians) => AB_THRESHOLD,
        (Method::PairedSequential, Mode::Fast) => FILE_THRESHOLD,
        (Method::BootstrapMedians, Mode::Ab | Mode::AbMedians) => 0.03,
        (Method::BootstrapMedians, Mode::Fast) => 0.10,
    }
}

/// The rule a mode judges on (the same before and since paired decisions).
fn rule(mode: Mode) -> Judged {
    match mode {
        Mode::Ab | Mode::AbMedians => AB_JUDGE,
        Mode::Fast => FILE_JUDGE,
    }
}

fn condition(run: &StudyRun) -> String {
    let load = match (run.duet, run.load) {
        (true, Load::Quiet) => "quiet, duet (both sides at once, one per CPU)",
        (true, Load::Spin) => "a process spinning on one CPU, duet",
        (false, Load::Quiet) => "quiet, sides in turns",
        (false, Load::Spin) => "a process spinning on one CPU, sides in turns",
    };
    match run.method {
        Method::PairedSequential => load.to_string(),
        Method::BootstrapMedians => format!("{load}, before paired decisions"),
    }
}

/// The thresholds a run judged `mode` at under `rule`, in increasing order.
fn thresholds(run: &StudyRun, mode: Mode, rule: Judged) -> Vec<f64> {
    let mut t: Vec<f64> = run
        .tallies
        .iter()
        .filter(|t| t.mode == mode && t.rule == rule && t.slowdown == 1.0)
        .map(|t| t.threshold)
        .collect();
    t.sort_by(f64::total_cmp);
    t.dedup();
    t
}

fn percent(x: f64) -> String {
    format!("{:.1}%", 100.0 * x)
}

/// "k/n (r%, 95% CI a–b%)", or "–" when the study made no such decision.
fn cell(run: &StudyRun, mode: Mode, rule: Judged, threshold: f64, slowdown: f64) -> String {
    match run.tally(mode, rule, threshold, slowdown) {
        Some(t) if t.decisions > 0 => {
            let (rate, [lo, hi]) = t.rate();
            let k = if slowdown == 1.0 {
                t.any_flagged
            } else {
                t.exactly_slowed
            };
            format!(
                "{k}/{} ({}, {}–{})",
                t.decisions,
                percent(rate),
                percent(lo),
                percent(hi)
            )
        }
        _ => "–".into(),
    }
}

/// The generated region: for every study file (machine class), the gate as configured, the
/// three rules side by side, the thresholds, and the interval widths of each mode.
pub fn markdown(files: &[StudyFile]) -> String {
    let mut s = String::new();
    if files.is_empty() {
        s += "No study file is committed yet: `nbody-bench gate-study` measures one.\n";
    }
    for file in files {
        s += &format!(
            "\n#### {} ({}, {} logical CPUs, SIMD {})\n\n",
            file.class(),
            file.cpu_model,
            file.logical_cpus,
            file.simd
        );
        s += &format!(
            "Config `{}`; fast-path decisions against {}.\n\n",
            file.config_name,
            file.baseline
                .as_deref()
                .map_or("no baseline (none was committed)".into(), |b| format!(
                    "`{b}`"
                ))
        );
        s += &format!(
            "**The gate as configured** (A/B: the `{}` ratio above {}, paired rounds in looks of \
             {} up to {} rounds; fast path: `{}` above {}; runs before paired decisions at their \
             own defaults, 1.03 and 1.1): decisions that flagged any case on unchanged code \
             (false alarms), and that flagged exactly the slowed kernel's cases (power), with \
             95% Clopper–Pearson intervals; decisions that left some case unknown, and the mean \
             rounds per case of an A/A decision.\n\n",
            rule_name(AB_JUDGE),
            1.0 + AB_THRESHOLD,
            crate::gate::AB_ROUNDS,
            crate::gate::AB_MAX_ROUNDS,
            rule_name(FILE_JUDGE),
            1.0 + FILE_THRESHOLD
        );
        let mut header = vec![
            "condition".to_string(),
            "mode".into(),
            "decisions measured in".into(),
            "false alarms (A/A)".into(),
            "unknown (A/A)".into(),
            "rounds per case (A/A)".into(),
        ];
        // The knob slows the force computation; the step the gate times also builds,
        // integrates and applies the walls, so its own ratio is shown beside.
        header.extend(SLOWDOWNS.iter().map(|&f| {
            let step = file
                .runs
                .iter()
                .find_map(|r| r.step_ratio(f))
                .map_or(String::new(), |r| format!(" (step ×{r:.3})"));
            format!("force {:.0}% slower{step}", (f - 1.0) * 100.0)
        }));
        let columns = header.len();
        let mut t = Table::new(header).aligned(
            [Align::Default, Align::Default]
                .into_iter()
                .chain(std::iter::repeat_n(Align::Right, columns - 2)),
        );
        for run in &file.runs {
            for mode in super::decide::MODES {
                let th = threshold(run, mode);
                let Some(aa) = run.tally(mode, rule(mode), th, 1.0) else {
                    continue;
                };
                let (unknown, rounds) = match (run.method, mode) {
                    (Method::BootstrapMedians, _) | (_, Mode::AbMedians) => {
                        ("–".to_string(), format!("{}", run.rounds))
                    }
                    (Method::PairedSequential, _) => (
                        format!("{}/{}", aa.undecided, aa.decisions),
                        format!(
                            "{:.1}",
                            aa.case_rounds as f64 / (aa.decisions * run.cases.max(1)).max(1) as f64
                        ),
                    ),
                };
                let mut row = vec![
                    condition(run),
                    mode.name().to_string(),
                    if mode == Mode::AbMedians {
                        "(the A/B's first look)".to_string()
                    } else {
                        format!("{:.1} s", run.decision_measure_s)
                    },
                    cell(run, mode, rule(mode), th, 1.0),
                    unknown,
                    rounds,
                ];
                row.extend(
                    SLOWDOWNS
                        .iter()
                        .map(|&f| cell(run, mode, rule(mode), th, f)),
                );
                t.row(row);
            }
        }
        s += &t.markdown();
        s += &rules_table(file);
        s += &thresholds_table(file);
        s += &widths_table(file);
        for run in &file.runs {
            let rounds = match run.method {
                Method::PairedSequential => format!("{} to {}", run.rounds, run.max_rounds),
                Method::BootstrapMedians => run.rounds.to_string(),
            };
            s += &format!(
                "\n- {}: {} blocks of {rounds} rounds x {} samples per side, slowed kernel `{}`, \
                 measured {} (commit {}{}), {:.0} s per block.\n",
                condition(run),
                run.blocks,
                run.samples_per_round,
                run.slowed_kernel.name(),
                run.started,
                crate::gate::prefix(&run.git_commit, 10),
                if run.git_dirty {
                    ", uncommitted changes"
                } else {
                    ""
                },
                run.block_wall_s
            );
        }
    }
    s
}

fn rule_name(rule: Judged) -> &'static str {
    match rule {
        Judged::Normalized => "normalized",
        Judged::Raw => "raw",
        Judged::Both => "both",
    }
}

/// Each rule at the configured thresholds: false alarms and power, every condition.
fn rules_table(file: &StudyFile) -> String {
    let mut t = Table::new([
        "condition",
        "mode",
        "rule",
        "false alarms (A/A)",
        "force 10% slower",
        "force 25% slower",
    ])
    .aligned([
        Align::Default,
        Align::Default,
        Align::Default,
        Align::Right,
        Align::Right,
        Align::Right,
    ]);
    let mut any = false;
    for run in &file.runs {
        for mode in super::decide::MODES {
            let th = threshold(run, mode);
            for rule in super::decide::RULES {
                if run.tally(mode, rule, th, 1.0).is_none() {
                    continue;
                }
                any = true;
                t.row([
                    condition(run),
                    mode.name().to_string(),
                    rule_name(rule).to_string(),
                    cell(run, mode, rule, th, 1.0),
                    cell(run, mode, rule, th, 1.10),
                    cell(run, mode, rule, th, 1.25),
                ]);
            }
        }
    }
    if !any {
        return String::new();
    }
    format!(
        "\n**The rules compared** (normalised ratio, raw ratio, both), at the configured \
         thresholds:\n\n{}",
        t.markdown()
    )
}

/// Each candidate threshold under each mode's configured rule.
fn thresholds_table(file: &StudyFile) -> String {
    let mut t = Table::new([
        "condition",
        "mode",
        "rule",
        "threshold",
        "false alarms (A/A)",
        "force 5% slower",
        "force 10% slower",
        "force 25% slower",
    ])
    .aligned([
        Align::Default,
        Align::Default,
        Align::Default,
        Align::Right,
        Align::Right,
        Align::Right,
        Align::Right,
        Align::Right,
    ]);
    let mut any = false;
    for run in &file.runs {
        for mode in super::decide::MODES {
            let rule = rule(mode);
            for th in thresholds(run, mode, rule) {
                if run.tally(mode, rule, th, 1.0).is_none() {
                    continue;
                }
                any = true;
                t.row([
                    condition(run),
                    mode.name().to_string(),
                    rule_name(rule).to_string(),
                    format!("{th}"),
                    cell(run, mode, rule, th, 1.0),
                    cell(run, mode, rule, th, 1.05),
                    cell(run, mode, rule, th, 1.10),
                    cell(run, mode, rule, th, 1.25),
                ]);
            }
        }
    }
    if !any {
        return String::new();
    }
    format!(
        "\n**The thresholds compared** (each mode's rule):\n\n{}",
        t.markdown()
    )
}

/// Median relative width of A/A decisions' per-case 95% intervals, each condition and mode.
fn widths_table(file: &StudyFile) -> String {
    let mut t = Table::new(["condition", "mode", "normalised ratio", "raw ratio"]).aligned([
        Align::Default,
        Align::Default,
        Align::Right,
        Align::Right,
    ]);
    let mut any = false;
    for run in &file.runs {
        for w in &run.widths {
            any = true;
            t.row([
                condition(run),
                w.mode.name().to_string(),
                percent(w.normalized),
                percent(w.raw),
            ]);
        }
    }
    if !any {
        return String::new();
    }
    format!(
        "\n**Interval widths on unchanged code** (median over cases and decisions of the 95% \
         interval's width over the ratio):\n\n{}",
        t.markdown()
    )
}

/// `page` with its generated region replaced by `region`; `None` when the page has no
/// region marks.
pub fn splice(page: &str, region: &str) -> Option<String> {
    let start = page.find(BEGIN)? + BEGIN.len();
    let end = start + page[start..].find(END)?;
    Some(format!(
        "{}\n{}\n{}",
        &page[..start],
        region.trim(),
        &page[end..]
    ))
}
