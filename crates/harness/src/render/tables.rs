//! Markdown tables: the one [`Table`] builder that every table of the harness is made with
//! (REPORT.md, `summary.md`, the gate's report), and the tables of an analysis: cost vs n,
//! strong scaling, weak scaling, octree accuracy and the energy checks. `summary.md` and
//! REPORT.md both print these, so a number, a marker or a word reads the same in both: an
//! oversubscribed case is marked `*`, an unbounded speedup is `∞`, a missing value `–`.

use crate::analysis::groups::Point;
use crate::analysis::{Analysis, Fitted};
use crate::analysis::{crossover, forking};
use crate::fit::{SharedMachine, StrongFit, Trend};
use crate::units::{Duration, Percent, Plain, WithCi};
use nbody_engine::output::neutral::control::visible;
use nbody_engine::physics::LawKind;
use std::fmt::Write;

/// How the cells of a column sit, as the delimiter row says it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Align {
    /// `---`: the renderer's default, left in every one we know.
    #[default]
    Default,
    /// `---:`: for numbers that should line up on their last digit.
    Right,
}

/// A Markdown table: a header, an alignment per column, rows of cells already formatted
/// (through `crate::units`). Cells are written as they are: `|` in a cell is the caller's
/// to escape.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Table {
    header: Vec<String>,
    align: Vec<Align>,
    rows: Vec<Vec<String>>,
}

impl Table {
    /// A table with these column headers, every column default-aligned, and no rows.
    pub fn new<S: Into<String>>(header: impl IntoIterator<Item = S>) -> Self {
        let header: Vec<String> = header.into_iter().map(Into::into).collect();
        let align = vec![Align::Default; header.len()];
        Table {
            header,
            align,
            rows: Vec::new(),
        }
    }

    /// The same table with one alignment per column, in order.
    pub fn aligned(mut self, align: impl IntoIterator<Item = Align>) -> Self {
        self.align = align.into_iter().collect();
        assert_eq!(
            self.align.len(),
            self.header.len(),
            "one alignment per column"
        );
        self
    }

    /// Adds a row; it has one cell per column.
    pub fn row<S: Into<String>>(&mut self, cells: impl IntoIterator<Item = S>) -> &mut Self {
        let cells: Vec<String> = cells.into_iter().map(Into::into).collect();
        // A short or long row silently shifts every cell after it into the wrong column.
        debug_assert_eq!(cells.len(), self.header.len(), "one cell per column");
        self.rows.push(cells);
        self
    }

    /// The header, the delimiter row and the rows, each line ending in a newline.
    pub fn markdown(&self) -> String {
        let mut md = line(&self.header);
        md.push('|');
        for a in &self.align {
            md.push_str(match a {
                Align::Default => "---|",
                Align::Right => "---:|",
            });
        }
        md.push('\n');
        for r in &self.rows {
            md.push_str(&line(r));
        }
        md
    }
}

impl Table {
    /// The header and the rows as aligned text for a terminal: each column as wide as its
    /// widest cell (in characters), right-aligned columns padded on the left, one space between
    /// columns, no trailing spaces. A cell's control characters (a case key from someone
    /// else's file may hold ESC sequences) are shown escaped.
    pub fn text(&self) -> String {
        let shown: Vec<Vec<String>> = std::iter::once(&self.header)
            .chain(&self.rows)
            .map(|r| r.iter().map(|c| visible(c).into_owned()).collect())
            .collect();
        let mut widths = vec![0; self.header.len()];
        for r in &shown {
            for (w, c) in widths.iter_mut().zip(r) {
                *w = (*w).max(c.chars().count());
            }
        }
        let mut out = String::new();
        for r in &shown {
            let mut line = String::new();
            for ((c, w), a) in r.iter().zip(&widths).zip(&self.align) {
                let pad = " ".repeat(w - c.chars().count());
                match a {
                    Align::Default => line += &format!("{c}{pad} "),
                    Align::Right => line += &format!("{pad}{c} "),
                }
            }
            out += line.trim_end();
            out.push('\n');
        }
        out
    }
}

/// One line of cells: `| a | b |`, an empty cell as `| |`.
fn line(cells: &[String]) -> String {
    let mut md = String::new();
    for c in cells {
        md.push_str("| ");
        if !c.is_empty() {
            md.push_str(c);
            md.push(' ');
        }
    }
    md.push_str("|\n");
    md
}

/// What a cell shows when there is no value.
pub(crate) const NONE: &str = "–";

/// The marker of a case that ran more workers (threads or ranks) than logical CPUs.
pub fn over(oversubscribed: bool) -> &'static str {
    if oversubscribed { "*" } else { "" }
}

fn not_fitted<T>(f: &Fitted<T>) -> String {
    format!("not fitted: {}", f.error.as_deref().unwrap_or("unknown"))
}

/// The sentence that explains the peak column.
pub(crate) fn peak_note() -> String {
    format!(
        "\"Peak\" is the pair rate as a share of the calibrated FMA peak of the threads used, at a nominal \
         {} / {} / {} flops per LJ / gravity / Coulomb pair (f64 at half the f32 rate).",
        LawKind::LennardJones.flops_per_pair(),
        LawKind::Gravity.flops_per_pair(),
        LawKind::Coulomb.flops_per_pair()
    )
}

/// Cost vs n: per series, the n range, the time and rates at the largest n (a column of its
/// own, so that no value reads as if it were the whole range's), the fitted exponent and what
/// it lets be said of the growth ([`crate::fit::GrowthReading`]).
pub fn complexity(a: &Analysis) -> String {
    let mut table = Table::new([
        "scenario",
        "kernel",
        "n measured",
        "at n",
        "time/step",
        "ns/particle-step",
        "pair-evals/s",
        "peak",
        "k [95% CI]",
        "growth",
    ]);
    for c in &a.complexity {
        let (Some(first), Some(last)) = (c.points.first(), c.points.last()) else {
            continue;
        };
        let (k, growth) = match &c.fit.fit {
            Some(f) => (
                format!("{:.2}", WithCi::of(&f.exponent, Plain)),
                match f.reading.class() {
                    Some(_) => format!(
                        "{} (LOO SMAPE {:.1}%)",
                        f.growth(),
                        f.selected.loo_smape_percent
                    ),
                    None => f.growth(),
                },
            ),
            None => (NONE.into(), not_fitted(&c.fit)),
        };
        let peak = a
            .peak_share(last, c.series.scenario.law(), c.series.precision)
            .map_or(NONE.to_string(), |s| format!("{:.0}", Percent(s)));
        table.row([
            c.series.scenario.name().to_string(),
            c.label.clone(),
            format!("{}–{}", first.n, last.n),
            last.n.to_string(),
            Duration(last.median_s).to_string(),
            format!("{:.1}", last.ns_per_particle_step),
            // An external program counts no pairs: none, rather than a rate of zero.
            last.pair_evals_per_s
                .map_or(NONE.to_string(), |r| format!("{r:.2e}")),
            peak,
            k,
            growth,
        ]);
    }
    table.markdown()
}

/// The sentence that says how to read the cost-vs-n table's columns.
pub(crate) fn complexity_note() -> String {
    "Time per step, its rates and the peak share are at the largest n measured (\"at n\"); k is \
     the exponent of the free power law `T = c·n^k` with its bootstrap 95% CI. A growth class \
     is named only where the class picked by leave-one-out cross-validation (SMAPE) grows with \
     an exponent inside k's CI over the measured n; otherwise two classes the data do not tell \
     apart, or the measured exponent alone."
        .to_string()
}

/// The pairs of codes whose measured order changes over n or is not resolved somewhere, one
/// line each, then how many pairs keep one order throughout.
pub(crate) fn crossovers(a: &Analysis) -> String {
    let mut md = String::new();
    let (told, settled): (Vec<_>, Vec<_>) = a.crossovers.iter().partition(|x| !x.settled());
    for x in told {
        let _ = writeln!(md, "- {}", crossover::sentence(x));
    }
    if !settled.is_empty() {
        let _ = writeln!(
            md,
            "- {} other pair{} of codes measured at the same sizes: no crossover (one is \
             faster at every size where either is, or the two are level).",
            settled.len(),
            if settled.len() == 1 { "" } else { "s" },
        );
    }
    md
}

fn oversubscribed_at(points: &[Point], p: f64) -> bool {
    points.iter().any(|c| c.has_workers(p) && c.oversubscribed)
}

/// Strong scaling: the speedup at each p (and over the calibrated ceiling), the Amdahl fit, its
/// bound, the Karp-Flatt trend and the serial fraction the phase timers measured.
pub fn strong(a: &Analysis) -> String {
    let mut table = Table::new([
        "scenario",
        "kernel",
        "n",
        "speedup by p (÷ ceiling)",
        "Amdahl f [95% CI]",
        "1/f",
        "Karp-Flatt",
        "f from phase timers",
    ]);
    for st in &a.strong {
        let head = [
            st.series.scenario.name().to_string(),
            st.label.clone(),
            st.series.n.unwrap_or(0).to_string(),
        ];
        let Some(f) = &st.fit.fit else {
            let blank = std::iter::repeat_n(String::new(), 4);
            table.row(head.into_iter().chain([not_fitted(&st.fit)]).chain(blank));
            continue;
        };
        let cells: Vec<String> = st
            .measured
            .iter()
            .filter(|p| p.p > 1.0)
            .map(|p| {
                let rel = p
                    .speedup_vs_ceiling
                    .as_ref()
                    .map(|e| format!(" (÷ {:.2})", e.estimate))
                    .unwrap_or_default();
                format!(
                    "{}{}{}: {:.2}{rel}",
                    p.p,
                    over(oversubscribed_at(&st.points, p.p)),
                    forking::at_workers(&st.points, p.p).map_or("", |o| o.marker()),
                    WithCi::of(&p.speedup, Plain)
                )
            })
            .collect();
        let bound = if f.max_speedup.estimate.is_finite() {
            format!("{:.1}", f.max_speedup.estimate)
        } else {
            "∞".into()
        };
        let timed = st
            .timed_serial
            .as_ref()
            .map_or(NONE.to_string(), |t| format!("{:.2}", Percent(t.fraction)));
        let shared = shared_mark(st.shared_machine.as_ref());
        table.row(head.into_iter().chain([
            cells.join("<br>"),
            format!("{}{shared}", WithCi::of(&f.serial_fraction, Percent)),
            bound,
            format!("{}{shared}", karp_flatt_cell(f)),
            timed,
        ]));
    }
    table.markdown()
}

/// `" (shared machine)"` after a reading of a study measured on a shared machine, else
/// nothing ([`SharedMachine::note`] under the table says what it means).
fn shared_mark(shared: Option<&SharedMachine>) -> String {
    shared.map_or(String::new(), |_| format!(" ({})", SharedMachine::MARK))
}

/// The Karp-Flatt column: e(p) at each p > 1 with its interval, then the trend's verdict, or
/// with one p > 1 that a trend needs two (its one value is a measurement all the same).
fn karp_flatt_cell(f: &StrongFit) -> String {
    let mut lines: Vec<String> = f
        .karp_flatt
        .iter()
        .map(|k| format!("e({}) = {:.1}", k.p, WithCi::of(&k.e, Percent)))
        .collect();
    lines.push(match f.karp_flatt_trend.verdict {
        Trend::Undetermined if f.karp_flatt.len() == 1 => "trend: needs two p > 1".to_string(),
        verdict => format!("trend: {}", verdict.name()),
    });
    lines.join("<br>")
}

/// The notes that follow the strong table of `a`, each a paragraph: the one-thread markers
/// ([`forking::OneThread::marker`]) it shows, and the machine shared with other processes;
/// empty when there is none.
pub(crate) fn strong_notes(a: &Analysis) -> String {
    let found = a
        .strong
        .iter()
        .filter(|st| st.fit.fit.is_some())
        .flat_map(|st| {
            st.measured
                .iter()
                .filter(|p| p.p > 1.0)
                .filter_map(|p| forking::at_workers(&st.points, p.p))
        });
    let shared = a.strong.iter().find_map(|st| st.shared_machine);
    forking::notes(found) + &shared_note(shared)
}

/// The paragraph of [`SharedMachine::note`], or nothing on a quiet machine.
fn shared_note(shared: Option<SharedMachine>) -> String {
    shared.map_or(String::new(), |s| format!("{}\n\n", s.note()))
}

/// `notes` to follow a table: after a blank line, ending in one newline; empty without notes,
/// so that a table without a marked case is followed as before.
pub(crate) fn after_table(notes: &str) -> String {
    match notes.trim_end() {
        "" => String::new(),
        notes => format!("\n{notes}\n"),
    }
}

/// [`strong_notes`] for the weak table of `a`.
pub(crate) fn weak_notes(a: &Analysis) -> String {
    let found = a.weak.iter().filter(|w| w.fit.fit.is_some()).flat_map(|w| {
        w.measured
            .iter()
            .filter_map(|e| w.points.iter().find(|c| c.has_workers(e.p)))
            .filter_map(forking::of_point)
    });
    let shared = a.weak.iter().find_map(|w| w.shared_machine);
    forking::notes(found) + &shared_note(shared)
}

/// The notes of each complexity fit (a class not firmly determined, a range of n too short to
/// tell two classes apart), one line each.
pub(crate) fn complexity_notes(a: &Analysis) -> String {
    let mut md = String::new();
    for c in &a.complexity {
        for note in c.fit.fit.iter().flat_map(|f| &f.notes) {
            let _ = writeln!(md, "- {} {}: {note}", c.series.scenario.name(), c.label);
        }
    }
    md
}

/// Each strong series' timed serial fraction next to the fitted one, one line each.
pub(crate) fn serial_comparisons(a: &Analysis) -> String {
    let mut md = String::new();
    for st in &a.strong {
        if let Some(c) = &st.serial_comparison {
            let _ = writeln!(
                md,
                "- {} {} n={}: {}",
                st.series.scenario.name(),
                st.label,
                st.series.n.unwrap_or(0),
                c.explanation
            );
        }
    }
    md
}

/// Weak scaling: n and the efficiency at each p, and Gustafson's serial fraction.
pub fn weak(a: &Analysis) -> String {
    let mut table = Table::new(["scenario", "kernel", "p: n, efficiency", "Gustafson α"]);
    for w in &a.weak {
        let head = [w.series.scenario.name().to_string(), w.label.clone()];
        let Some(f) = &w.fit.fit else {
            table.row(head.into_iter().chain([not_fitted(&w.fit), String::new()]));
            continue;
        };
        let cells: Vec<String> = w
            .measured
            .iter()
            .map(|e| {
                let c = w.points.iter().find(|c| c.has_workers(e.p));
                format!(
                    "{}{}{}: n={}, {:.2}",
                    e.p,
                    over(c.is_some_and(|c| c.oversubscribed)),
                    c.and_then(forking::of_point).map_or("", |o| o.marker()),
                    c.map_or(0, |c| c.n),
                    WithCi::of(&e.e, Plain)
                )
            })
            .collect();
        let shared = shared_mark(w.shared_machine.as_ref());
        table.row(head.into_iter().chain([
            format!("{}{shared}", cells.join("<br>")),
            format!("{}{shared}", WithCi::of(&f.serial_fraction, Percent)),
        ]));
    }
    table.markdown()
}

/// θ of an octree or fmm case, with the expansion order when it is not the octree's
/// default monopole (the fmm's order always).
fn theta_cell(p: &crate::analysis::groups::Point) -> String {
    let theta = p.theta.map_or(NONE.to_string(), |t| t.to_string());
    match (p.case.multipole, p.case.order) {
        (_, Some(order)) => format!("{theta} (order {order})"),
        (nbody_engine::kernels::Multipole::Monopole, None) => theta,
        (m, None) => format!("{theta} ({})", m.name()),
    }
}

/// The octree over θ (one series per expansion order): time and the force error against an
/// f64 direct sum.
pub fn theta(a: &Analysis) -> String {
    let mut table = Table::new([
        "scenario",
        "code",
        "n",
        "θ",
        "time/step",
        "µs/particle-step",
        "median / max relative force error",
    ]);
    for t in &a.theta {
        for p in &t.points {
            let error = p.force_error.map_or("not measured".to_string(), |[m, x]| {
                format!("{m:.2e} / {x:.2e}")
            });
            table.row([
                t.series.scenario.name().to_string(),
                p.case.kernel.name().to_string(),
                p.n.to_string(),
                theta_cell(p),
                Duration(p.median_s).to_string(),
                format!("{:.2}", p.ns_per_particle_step * 1e-3),
                error,
            ]);
        }
    }
    table.markdown()
}

/// The energy check per scenario and kernel of each analysis: cases, the largest drift, the
/// cases flagged. With `by_sweep`, a first column names each analysis's sweep (REPORT.md
/// gathers every sweep into one table).
pub fn sanity<'a>(analyses: impl IntoIterator<Item = &'a Analysis>, by_sweep: bool) -> String {
    let columns = ["scenario", "kernel", "cases", "largest drift", "flagged"];
    let mut table = Table::new(by_sweep.then_some("sweep").into_iter().chain(columns));
    for a in analyses {
        sanity_rows(&mut table, a, by_sweep.then_some(a.name.as_str()));
    }
    table.markdown()
}

/// The rows of `a` in the energy-check table, led by `sweep` when given.
fn sanity_rows(table: &mut Table, a: &Analysis, sweep: Option<&str>) {
    // Per scenario and code: its cases, the largest drift and the cases over the limit among
    // those that measured one (none for an external program: "–", not a drift of zero).
    let mut rows: Vec<(&Point, usize, Option<f64>, usize)> = Vec::new();
    for c in &a.cases {
        let same = |r: &&mut (&Point, usize, Option<f64>, usize)| {
            r.0.case.scenario == c.case.scenario && r.0.case.kernel == c.case.kernel
        };
        let flagged = usize::from(c.sanity_ok == Some(false));
        match rows.iter_mut().find(same) {
            Some(r) => {
                r.1 += 1;
                r.2 = match (r.2, c.max_energy_drift) {
                    (Some(a), Some(b)) => Some(a.max(b)),
                    (a, b) => a.or(b),
                };
                r.3 += flagged;
            }
            None => rows.push((c, 1, c.max_energy_drift, flagged)),
        }
    }
    for (c, cases, drift, flagged) in rows {
        table.row(sweep.map(str::to_string).into_iter().chain([
            c.case.scenario.name().to_string(),
            c.case.kernel.name().to_string(),
            cases.to_string(),
            drift.map_or(NONE.to_string(), |d| format!("{d:.1e}")),
            drift.map_or(NONE.to_string(), |_| flagged.to_string()),
        ]));
    }
}

fn error_cell(e: Option<f64>) -> String {
    e.map_or(NONE.to_string(), |e| format!("{e:.2e}"))
}

/// Our kernels next to the external programs of the sweep: each of our cases against the
/// fastest external case of the same system and workers, time per particle-step of each with
/// its CI, the ratio theirs ÷ ours with its CI (above 1: ours is faster), the force errors where
/// measured and, when a peer ran in several ways, the slower runs beside it. Empty when the
/// sweep ran no external program next to a kernel.
pub fn peers(a: &Analysis) -> String {
    if a.peers.is_empty() {
        return String::new();
    }
    let errors = a
        .peers
        .iter()
        .any(|r| r.ours_error.is_some() || r.theirs_error.is_some());
    let others = a.peers.iter().any(|r| !r.others.is_empty());
    let mut header = vec![
        "scenario",
        "n",
        "workers",
        "ours",
        "ns/particle-step [95% CI]",
        if others {
            "theirs (the fastest run)"
        } else {
            "theirs"
        },
        "ns/particle-step [95% CI]",
        "theirs ÷ ours [95% CI]",
    ];
    if errors {
        header.push("median force error (ours / theirs)");
    }
    if others {
        header.push("their other runs: ns/particle-step (theirs ÷ ours)");
    }
    let mut table = Table::new(header);
    for r in &a.peers {
        let ratio = match r.speedup_ci {
            Some(ci) => format!("{:.2}", WithCi::new(r.speedup, ci, Plain)),
            None => format!("{:.2}", r.speedup),
        };
        let mut row = vec![
            r.scenario.to_string(),
            r.n.to_string(),
            format!("{}{}", r.workers, over(r.oversubscribed)),
            r.ours.to_string(),
            format!("{:.1}", WithCi::new(r.ours_ns, r.ours_ci_ns, Plain)),
            r.theirs.to_string(),
            format!("{:.1}", WithCi::new(r.theirs_ns, r.theirs_ci_ns, Plain)),
            ratio,
        ];
        if errors {
            row.push(format!(
                "{} / {}",
                error_cell(r.ours_error),
                error_cell(r.theirs_error)
            ));
        }
        if others {
            let cell: Vec<String> = r
                .others
                .iter()
                .map(|o| {
                    format!(
                        "{}{}: {:.1} ({:.2})",
                        o.theirs,
                        over(o.oversubscribed),
                        o.theirs_ns,
                        o.speedup
                    )
                })
                .collect();
            let cell = if cell.is_empty() {
                NONE.to_string()
            } else {
                cell.join("; ")
            };
            row.push(cell);
        }
        table.row(row);
    }
    table.markdown()
}

/// Tree codes at equal median force error: each code's time per step interpolated to it on
/// its sweep over θ, and the ratio. Empty when the sweep has no such pair of series.
pub(crate) fn peers_equal_error(a: &Analysis) -> String {
    if a.peers_equal_error.is_empty() {
        return String::new();
    }
    let mut table = Table::new([
        "scenario",
        "n",
        "workers",
        "median error",
        "ours",
        "time/step",
        "theirs",
        "time/step",
        "theirs ÷ ours",
    ]);
    let cost = |s: Option<f64>, range: [f64; 2]| match s {
        Some(s) => Duration(s).to_string(),
        None => format!("outside the measured {:.1e}–{:.1e}", range[0], range[1]),
    };
    // "fmm (θ=0.5 order 4 – θ=0.4 order 6)": the settings the time lies between.
    let code = |name: &str, between: &Option<[String; 2]>| match between {
        Some([a, b]) if a == b => format!("{name} ({a})"),
        Some([a, b]) => format!("{name} ({a} – {b})"),
        None => name.to_string(),
    };
    for r in &a.peers_equal_error {
        table.row([
            r.scenario.to_string(),
            r.n.to_string(),
            r.workers.to_string(),
            format!("{:.0e}", r.error),
            code(&r.ours, &r.ours_between),
            cost(r.ours_s, r.ours_errors),
            code(&r.theirs, &r.theirs_between),
            cost(r.theirs_s, r.theirs_errors),
            r.speedup.map_or(NONE.to_string(), |s| format!("{s:.2}")),
        ]);
    }
    table.markdown()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_table_is_its_header_a_delimiter_row_and_its_rows() {
        let mut t = Table::new(["case", "time"]).aligned([Align::Default, Align::Right]);
        t.row(["`a`", "1.000 ms"])
            .row(["`b`".to_string(), "–".to_string()]);
        assert_eq!(
            t.markdown(),
            "| case | time |\n|---|---:|\n| `a` | 1.000 ms |\n| `b` | – |\n"
        );
    }

    #[test]
    fn as_text_each_column_is_as_wide_as_its_widest_cell() {
        let mut t = Table::new(["case", "time"]).aligned([Align::Default, Align::Right]);
        t.row(["lj-box/naive", "1.000 ms"]).row(["a", "–"]);
        assert_eq!(
            t.text(),
            "case             time\nlj-box/naive 1.000 ms\na                   –\n"
        );
    }

    #[test]
    fn empty_cells_are_one_space_wide() {
        let mut t = Table::new(["", ""]);
        t.row(["CPU", ""]);
        assert_eq!(t.markdown(), "| | |\n|---|---|\n| CPU | |\n");
        assert_eq!(Table::new(["n"]).markdown(), "| n |\n|---|\n");
    }
}
