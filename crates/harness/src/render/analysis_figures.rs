//! The figures of an analysis: cost vs n with fitted curves, speedup / efficiency / Karp-Flatt
//! vs p with the Amdahl fit and the hardware ceiling, weak-scaling efficiency, phase breakdown,
//! step-time percentiles, and octree error vs cost. Each states machine, commit and sweep in
//! its caption.

use crate::analysis::forking;
use crate::analysis::groups::{Point, workers_noun};
use crate::analysis::{Analysis, ComplexityAnalysis, StrongAnalysis, ThetaAnalysis, WeakAnalysis};
use crate::fit::{GrowthReading, SharedMachine, Trend};
use crate::plot::figures::{
    self as fig, Curve, KernelSeries, Measured, Percentiles, PhaseTimes, ThetaPoint, ThetaSweep,
};
use crate::plot::{Chart, Scale, StackedBars};
use nbody_engine::kernels::Multipole;
use nbody_records::kernel_or_program::KernelOrProgram;
use serde::Serialize;
use std::path::Path;

/// A drawn figure: its file stem (the files are `<stem>.svg` and `<stem>.png`) and title.
#[derive(Clone, Debug, Serialize)]
pub struct Figure {
    /// File name without extension, e.g. `speedup-lj-box`; its prefix says the figure's kind.
    pub stem: String,
    /// The chart's title, also its alt text in Markdown.
    pub title: String,
}

/// A figure to draw; the chart is boxed, being the larger by far.
enum Drawing {
    Chart(Box<Chart>),
    Bars(StackedBars),
}

/// Renders every figure the analysis supports into `dir`. A figure that fails is reported and
/// the others are still drawn.
pub(crate) fn render_all(analysis: &Analysis, dir: &Path) -> (Vec<Figure>, Vec<String>) {
    let mut drawn = Vec::new();
    let mut errors = Vec::new();
    for (stem, drawing) in figures(analysis) {
        let (title, result) = match &drawing {
            Drawing::Chart(c) => (
                c.title.clone(),
                crate::plot::draw(c, dir, &stem).map(|_| ()),
            ),
            Drawing::Bars(b) => (
                b.title.clone(),
                crate::plot::draw_stacked(b, dir, &stem).map(|_| ()),
            ),
        };
        match result {
            Ok(()) => drawn.push(Figure { stem, title }),
            Err(e) => errors.push(format!("{stem}: {e}")),
        }
    }
    (drawn, errors)
}

/// "AMD EPYC 9R45 (2 logical CPUs) · commit 1a2b3c4 · sweep strong".
pub fn caption(analysis: &Analysis) -> String {
    let machine = match &analysis.calibration {
        Some(c) => format!("{} ({} logical CPUs)", c.cpu_model, c.logical_cpus),
        // Without a calibration the machine is not described; its host name is not shown
        // (figures are shared).
        None => "machine not calibrated".to_string(),
    };
    let commit: String = analysis.metadata.git_commit.chars().take(7).collect();
    let dirty = if analysis.metadata.git_dirty {
        "+dirty"
    } else {
        ""
    };
    format!(
        "{machine} · commit {commit}{dirty} · sweep {}",
        analysis.name
    )
}

fn slug(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect::<String>()
        .split('-')
        .filter(|p| !p.is_empty())
        .collect::<Vec<_>>()
        .join("-")
}

fn measured(
    points: &[Point],
    x: impl Fn(&Point) -> f64,
    y: impl Fn(&Point) -> (f64, [f64; 2]),
) -> Vec<Measured> {
    points
        .iter()
        .map(|p| {
            let (m, [lo, hi]) = y(p);
            Measured::with_ci(x(p), m, lo, hi).oversubscribed(p.oversubscribed)
        })
        .collect()
}

fn time_of(p: &Point) -> (f64, [f64; 2]) {
    (p.median_s, p.ci95_s)
}

/// Every figure of the analysis, in drawing order: cost vs n, strong scaling, weak scaling,
/// phases and percentiles per scenario, then octree accuracy.
fn figures(a: &Analysis) -> Vec<(String, Drawing)> {
    let cap = caption(a);
    let mut out = Vec::new();
    out.extend(cost_figures(a, &cap));
    out.extend(strong_figures(a, &cap));
    out.extend(weak_figures(a, &cap));
    out.extend(scenario_figures(a, &cap));
    out.extend(octree_accuracy_figure(a, &cap));
    out
}

/// Cost vs n: one figure per scenario, precision and parallelism.
fn cost_figures(a: &Analysis, cap: &str) -> Vec<(String, Drawing)> {
    let mut out = Vec::new();
    for same in a.cost_groups() {
        let k = &same[0].series;
        let (scenario, precision) = (k.scenario.name(), k.precision.name());
        let (threads, ranks) = (k.threads.unwrap_or(1), k.ranks.unwrap_or(1));
        let series: Vec<KernelSeries> = same.iter().map(|c| time_series(c)).collect();
        let mut chart = fig::time_per_step(&series, cap);
        chart.title = format!(
            "{scenario} ({precision}, {threads} thread{}): time per step vs n",
            if threads == 1 { "" } else { "s" }
        );
        out.push((
            format!("time-vs-n-{scenario}-{precision}-p{threads}-r{ranks}"),
            Drawing::Chart(Box::new(chart)),
        ));
    }
    out
}

/// Strong scaling: speedup, efficiency and (when fitted) Karp-Flatt, one set per scenario, n
/// and precision.
fn strong_figures(a: &Analysis, cap: &str) -> Vec<(String, Drawing)> {
    let mut out = Vec::new();
    for same in a.strong_groups() {
        let k = &same[0].series;
        let (scenario, n) = (k.scenario.name(), k.n.unwrap_or(0));
        let stem = format!("{scenario}-n{n}-{}", k.precision.name());
        let title = format!("{scenario} n={n}");
        let ceiling = hardware_ceiling(&same);
        let speed: Vec<KernelSeries> = same.iter().map(|s| speedup_series(s)).collect();
        let workers = workers_noun(
            same.iter()
                .flat_map(|s| &s.points)
                .map(|c| (c.threads, c.ranks)),
        );
        // The crossed markers' legend names the reasons the group's cases ran on one thread.
        let one_thread = forking::legend(same.iter().flat_map(|s| {
            s.measured
                .iter()
                .filter_map(|p| forking::at_workers(&s.points, p.p))
        }));
        let mut chart = fig::speedup(&speed, &ceiling, workers, cap);
        chart.title = format!("{title}: speedup vs {workers}");
        if let Some(label) = &one_thread {
            chart.crossed_label.clone_from(label);
        }
        out.push((format!("speedup-{stem}"), Drawing::Chart(Box::new(chart))));
        let eff: Vec<KernelSeries> = same.iter().map(|s| efficiency_series(s)).collect();
        let mut chart = fig::efficiency(&eff, workers, cap);
        chart.title = format!("{title}: parallel efficiency");
        if let Some(label) = one_thread {
            chart.crossed_label = label;
        }
        out.push((
            format!("efficiency-{stem}"),
            Drawing::Chart(Box::new(chart)),
        ));
        let kf: Vec<KernelSeries> = same.iter().filter_map(|s| karp_flatt_series(s)).collect();
        if kf.iter().any(|k| !k.measured.is_empty()) {
            let mut chart = fig::karp_flatt(&kf, workers, cap);
            chart.title = format!("{title}: Karp-Flatt serial fraction e(p)");
            out.push((
                format!("karp-flatt-{stem}"),
                Drawing::Chart(Box::new(chart)),
            ));
        }
    }
    out
}

/// The hardware ceiling of a strong-scaling group: one (p, ceiling) per worker count, the
/// first series that has one at that p giving it.
fn hardware_ceiling(same: &[&StrongAnalysis]) -> Vec<(f64, f64)> {
    same.iter()
        .flat_map(|s| {
            s.measured
                .iter()
                .filter_map(|p| p.ceiling.map(|c| (p.p, c)))
        })
        .fold(Vec::new(), |mut acc, pc| {
            if !acc.iter().any(|a: &(f64, f64)| a.0 == pc.0) {
                acc.push(pc);
            }
            acc
        })
}

/// A strong-scaling series' measured parallel efficiency vs p.
fn efficiency_series(s: &StrongAnalysis) -> KernelSeries {
    let m: Vec<Measured> = s
        .measured
        .iter()
        .map(|p| {
            Measured::with_ci(
                p.p,
                p.efficiency.estimate,
                p.efficiency.ci95[0],
                p.efficiency.ci95[1],
            )
            .oversubscribed(oversubscribed_at(&s.points, p.p))
            .one_thread(forking::at_workers(&s.points, p.p).is_some())
        })
        .collect();
    KernelSeries::new(s.label.clone(), m)
}

/// A strong-scaling series' Karp-Flatt serial fraction vs p, labelled with its trend's
/// verdict; `None` when the series has no fit.
fn karp_flatt_series(s: &StrongAnalysis) -> Option<KernelSeries> {
    let f = s.fit.fit.as_ref()?;
    let m = f
        .karp_flatt
        .iter()
        .map(|k| {
            Measured::with_ci(k.p, k.e.estimate, k.e.ci95[0], k.e.ci95[1])
                .oversubscribed(oversubscribed_at(&s.points, k.p))
        })
        .collect();
    let verdict = match f.karp_flatt_trend.verdict {
        Trend::Undetermined if f.karp_flatt.len() == 1 => "trend needs two p > 1",
        verdict => verdict.name(),
    };
    Some(KernelSeries::new(
        format!("{} ({verdict}{})", s.label, shared_mark(s.shared_machine)),
        m,
    ))
}

/// ", shared machine" after a label of a study measured on a shared machine, else nothing.
fn shared_mark(shared: Option<SharedMachine>) -> String {
    shared.map_or(String::new(), |_| format!(", {}", SharedMachine::MARK))
}

/// Weak scaling: one efficiency figure per scenario.
fn weak_figures(a: &Analysis, cap: &str) -> Vec<(String, Drawing)> {
    let mut out = Vec::new();
    for same in a.weak_groups() {
        let scenario = same[0].series.scenario.name();
        let series: Vec<KernelSeries> = same.iter().map(|o| weak_series(o)).collect();
        let workers = workers_noun(
            same.iter()
                .flat_map(|o| &o.points)
                .map(|c| (c.threads, c.ranks)),
        );
        let mut chart = fig::weak_efficiency(&series, workers, cap);
        chart.title = format!("{scenario}: weak-scaling efficiency T(1)/T(p)");
        let found = same.iter().flat_map(|o| {
            o.measured
                .iter()
                .filter_map(|e| forking::at_workers(&o.points, e.p))
        });
        if let Some(label) = forking::legend(found) {
            chart.crossed_label = label;
        }
        out.push((
            format!("weak-efficiency-{scenario}"),
            Drawing::Chart(Box::new(chart)),
        ));
    }
    out
}

/// A weak-scaling series' measured efficiency T(1)/T(p) vs p.
fn weak_series(o: &WeakAnalysis) -> KernelSeries {
    let m: Vec<Measured> = o
        .measured
        .iter()
        .map(|e| {
            Measured::with_ci(e.p, e.e.estimate, e.e.ci95[0], e.e.ci95[1])
                .oversubscribed(oversubscribed_at(&o.points, e.p))
                .one_thread(forking::at_workers(&o.points, e.p).is_some())
        })
        .collect();
    let shared = o
        .shared_machine
        .map_or(String::new(), |_| format!(" ({})", SharedMachine::MARK));
    KernelSeries::new(format!("{}{shared}", o.label), m)
}

/// Phase breakdown and step-time percentiles per scenario, at each case's largest n.
fn scenario_figures(a: &Analysis, cap: &str) -> Vec<(String, Drawing)> {
    let mut out = Vec::new();
    for scenario in a.scenarios() {
        let cases = a.representative_cases(scenario);
        let scen = scenario.name();
        if cases.is_empty() {
            continue;
        }
        // A case no timer covered keeps its row, named "not measured": an empty bar alone
        // would read as a step that took no time.
        let phases: Vec<PhaseTimes> = cases
            .iter()
            .map(|c| match phase_list(c) {
                Some(phases) => PhaseTimes {
                    case: case_label(c),
                    phases,
                },
                None => PhaseTimes {
                    case: format!("{} (not measured)", case_label(c)),
                    phases: Vec::new(),
                },
            })
            .collect();
        let mut bars = fig::phase_breakdown(&phases, cap);
        bars.title = format!("{scen}: time per step by phase");
        out.push((format!("phases-{}", slug(scen)), Drawing::Bars(bars)));
        if let Some(chart) = percentiles_chart(&cases, scen, cap) {
            out.push((
                format!("percentiles-{}", slug(scen)),
                Drawing::Chart(Box::new(chart)),
            ));
        }
    }
    out
}

/// The step-time percentiles of a scenario's cases; `None` when no case has step times.
/// A code timed per run (an external program) has no step times: it is left out and named
/// under the figure, never drawn at zero.
fn percentiles_chart(cases: &[&Point], scen: &str, cap: &str) -> Option<Chart> {
    let (timed, untimed): (Vec<&&Point>, Vec<&&Point>) =
        cases.iter().partition(|c| c.step_ns.is_some());
    let rows: Vec<Percentiles> = timed
        .iter()
        .filter_map(|c| {
            let s = c.step_ns.as_ref()?;
            Some(Percentiles {
                kernel: case_label(c),
                p50: s.p50 as f64 * 1e-9,
                p90: s.p90 as f64 * 1e-9,
                p99: s.p99 as f64 * 1e-9,
                max: s.max as f64 * 1e-9,
            })
        })
        .collect();
    if rows.is_empty() {
        return None;
    }
    let mut note = cap.to_string();
    if !untimed.is_empty() {
        let mut programs: Vec<&str> = untimed.iter().map(|c| c.case.kernel.name()).collect();
        programs.dedup();
        note = format!(
            "not drawn: {} (timed per run, not per step)\n{cap}",
            programs.join(", ")
        );
    }
    let mut chart = fig::step_percentiles(&rows, &note);
    chart.title = format!("{scen}: step-time percentiles at each case's largest n");
    Some(chart)
}

/// Octree accuracy vs cost: one figure of every θ sweep with points, if any.
fn octree_accuracy_figure(a: &Analysis, cap: &str) -> Option<(String, Drawing)> {
    let sweeps: Vec<ThetaSweep> = a
        .theta
        .iter()
        .map(|t| ThetaSweep {
            name: theta_sweep_name(t),
            points: t
                .points
                .iter()
                .filter_map(|p| {
                    Some(ThetaPoint {
                        setting: setting_label(p, &t.series.kernel)?,
                        seconds: p.median_s,
                        error: p.force_error?[0],
                    })
                })
                .collect(),
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    if sweeps.is_empty() {
        return None;
    }
    Some((
        "octree-accuracy".into(),
        Drawing::Chart(Box::new(fig::octree_accuracy(&sweeps, cap))),
    ))
}

/// An accuracy series' name, one series per code and expansion order:
/// "octree galaxy n=20000 quadrupole", "fmm galaxy n=20000 order 4".
fn theta_sweep_name(t: &ThetaAnalysis) -> String {
    let mut name = format!("{} ", t.series.kernel.name());
    name.push_str(&format!(
        "{} n={}",
        t.series.scenario.name(),
        t.series.n.unwrap_or(0)
    ));
    if t.series.multipole != Multipole::Monopole {
        name.push_str(&format!(" {}", t.series.multipole.name()));
    }
    if let Some(p) = t.series.order {
        name.push_str(&format!(" order {p}"));
    }
    name
}

/// What a point of an accuracy series was run at: "θ=0.5", or for a member of an external
/// family (the series named after the family) its program's name without the family's
/// prefix ("eps1e-2" of "fmm3d-eps1e-2"), after its θ when it has one ("θ=0.7 quadrupole");
/// `None` for a θ series point without a θ.
fn setting_label(p: &Point, series: &KernelOrProgram) -> Option<String> {
    let theta = p.theta.map(|t| format!("θ={t}"));
    match (p.family_setting(series.name()), theta) {
        (Some(member), Some(theta)) => Some(format!("{theta} {member}")),
        (member, theta) => member.or(theta),
    }
}

/// "octree θ=0.5 p=2 n=16384" — short enough for a category axis: the case key (whose form
/// the results file fixes) without its scenario, seed and single rank.
/// A case in a figure or a table of cases: its code with θ and expansion, n, then the workers
/// (the seed and the scenario are the figure's).
pub(crate) fn case_label(c: &Point) -> String {
    let code = crate::analysis::peers::case_label(c);
    let (code, workers) = code.split_once(", ").unwrap_or((&code, ""));
    let mut label = match code.split_once(' ') {
        Some((kernel, rest)) => format!("{kernel} n={} {rest}", c.n),
        None => format!("{code} n={}", c.n),
    };
    if !workers.is_empty() {
        label.push_str(&format!(", {workers}"));
    }
    label
}

fn oversubscribed_at(points: &[Point], p: f64) -> bool {
    points.iter().any(|c| c.has_workers(p) && c.oversubscribed)
}

fn time_series(c: &ComplexityAnalysis) -> KernelSeries {
    let mut series = KernelSeries::new(
        c.label.clone(),
        measured(&c.points, |p| p.n as f64, time_of),
    );
    if let Some(f) = &c.fit.fit {
        let lo = c.points.first().map(|p| p.n as f64).unwrap_or(1.0);
        let hi = c.points.last().map(|p| p.n as f64).unwrap_or(1.0);
        let xs = fig::grid(lo, hi, 40, Scale::Log);
        // The legend says what the curve is: a named class's model, else the free power law
        // (never a class beside an exponent that contradicts it).
        let legend = match &f.reading {
            GrowthReading::Class { class } => {
                format!(
                    "{}: {} (k = {:.2})",
                    c.label,
                    class.name(),
                    f.exponent.estimate
                )
            }
            GrowthReading::NotDistinguished { classes } => format!(
                "{}: n^{:.2} ({})",
                c.label,
                f.exponent.estimate,
                crate::fit::growth::either(classes)
            ),
            GrowthReading::ExponentOnly => format!("{}: n^{:.2}", c.label, f.exponent.estimate),
        };
        series.fit = Some(Curve::from_fn(legend, &xs, |n| f.curve(n)));
    }
    series
}

fn speedup_series(s: &StrongAnalysis) -> KernelSeries {
    let measured: Vec<Measured> = s
        .measured
        .iter()
        .map(|p| {
            Measured::with_ci(
                p.p,
                p.speedup.estimate,
                p.speedup.ci95[0],
                p.speedup.ci95[1],
            )
            .oversubscribed(oversubscribed_at(&s.points, p.p))
            .one_thread(forking::at_workers(&s.points, p.p).is_some())
        })
        .collect();
    let Some(f) = &s.fit.fit else {
        return KernelSeries::new(s.label.clone(), measured);
    };
    let hi = s.measured.iter().map(|p| p.p).fold(1.0, f64::max);
    let xs = fig::grid(1.0, hi, 30, Scale::Linear);
    let band = xs
        .iter()
        .map(|&p| {
            let (_, [lo, hi]) = f.amdahl_speedup(p);
            (p, lo, hi)
        })
        .collect();
    let curve = Curve::from_fn(
        format!(
            "{}: Amdahl f = {:.3} [{:.3}, {:.3}]{}",
            s.label,
            f.serial_fraction.estimate,
            f.serial_fraction.ci95[0],
            f.serial_fraction.ci95[1],
            shared_mark(s.shared_machine)
        ),
        &xs,
        |p| f.amdahl_speedup(p).0,
    )
    .with_band(band);
    let mut series = KernelSeries::new(s.label.clone(), measured);
    series.fit = Some(curve);
    series
}

/// A case's phases for the bars: an external program's own, else the engine's timers and the
/// MPI drivers' communication; `None` when nothing timed any (an external program that prints
/// no phase), which the bar says instead of standing empty.
fn phase_list(c: &Point) -> Option<Vec<(String, f64)>> {
    if !c.named_phases.is_empty() {
        return Some(
            c.named_phases
                .iter()
                .map(|p| (p.name.clone(), p.s_per_step))
                .collect(),
        );
    }
    let ph = c.phases.as_ref()?;
    let list = [
        ("force: build", ph.force_build),
        ("force: interact", ph.force_interact),
        ("integrate", ph.integrate),
        ("boundary", ph.boundary),
        ("communication", c.comm_s_per_step.unwrap_or(0.0)),
    ]
    .into_iter()
    .map(|(name, s)| (name.to_string(), s))
    .collect();
    Some(list)
}
