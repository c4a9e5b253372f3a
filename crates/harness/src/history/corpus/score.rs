//! How each method is scored on the corpus, and the table of the scores.

use super::{Band, EDivisive, Kind, Series, TOLERANCE, planned};
use crate::history::changes::{Detector, Incremental, MIN_SEGMENT};
use crate::history::drifts::{self, Model};
use crate::render::tables::{Align, Table};
use nbody_engine::stats::median;

/// A detector the corpus scores.
#[derive(Clone, Copy, Debug)]
pub enum Method {
    /// Steps and drifts ([`crate::history::drifts`]), on each whole series.
    Drifts(Model),
    /// Steps alone ([`crate::history::changes`]), fed one point at a time.
    Pelt(Detector),
    /// The alternative, rerun on each prefix for the delays.
    EDivisive(EDivisive),
}

/// What a method reports on a series: its steps' indices, and its drifts.
#[derive(Clone, Debug, Default)]
struct Report {
    steps: Vec<usize>,
    drifts: Vec<drifts::Drift>,
}

impl Method {
    fn name(&self) -> String {
        match self {
            Method::Drifts(m) => format!(
                "level or drift segments, slope penalty {}σ, min drift {} (chosen)",
                m.slope_penalty(),
                m.min_drift()
            ),
            Method::Pelt(d) => format!(
                "PELT, L1 cost, min segment {}, penalty {}σ (steps alone)",
                d.min_segment(),
                d.penalty()
            ),
            Method::EDivisive(e) if e.min_segment <= 1 => format!(
                "E-divisive + t-test (Otava: p {}, window {})",
                e.max_pvalue, e.window
            ),
            Method::EDivisive(e) => format!(
                "E-divisive + t-test, min segment {} (p {}, window {})",
                e.min_segment, e.max_pvalue, e.window
            ),
        }
    }

    /// Whether the method is scored after every point (delays, spikes part-way): the drift
    /// model is scored on whole series only (see the module documentation of `drifts`: with
    /// no drift its steps are the step detector's, point for point).
    fn every_prefix(&self) -> bool {
        !matches!(self, Method::Drifts(_))
    }

    /// What is reported after each point, or (`every_prefix` false) after the last only.
    fn reports(&self, values: &[f64], every_prefix: bool) -> Vec<Report> {
        let steps = |steps: Vec<usize>| Report {
            steps,
            drifts: Vec::new(),
        };
        match self {
            Method::Drifts(m) => {
                let s = drifts::shape(values, m).expect("corpus values are positive times");
                vec![Report {
                    steps: s.changes.iter().map(|c| c.index).collect(),
                    drifts: s.drifts,
                }]
            }
            Method::Pelt(d) => {
                let mut inc = Incremental::new(*d);
                let mut out = Vec::new();
                for (i, &v) in values.iter().enumerate() {
                    inc.push(v).expect("corpus values are positive times");
                    if every_prefix || i + 1 == values.len() {
                        out.push(steps(inc.changes().iter().map(|c| c.index).collect()));
                    }
                }
                out
            }
            Method::EDivisive(e) => {
                let logs: Vec<f64> = values.iter().map(|v| v.ln()).collect();
                let from = if every_prefix { 1 } else { logs.len() };
                (from..=logs.len())
                    .map(|l| steps(e.change_points(&logs[..l])))
                    .collect()
            }
        }
    }
}

/// The methods the corpus compares: the chosen model, the step detector alone, Otava's
/// defaults, and Otava with the same minimum segment.
pub fn methods() -> Vec<Method> {
    let otava = EDivisive {
        window: 50,
        max_pvalue: 0.001,
        min_segment: 1,
    };
    vec![
        Method::Drifts(Model::default()),
        Method::Pelt(Detector::default()),
        Method::EDivisive(otava),
        Method::EDivisive(EDivisive {
            min_segment: MIN_SEGMENT,
            ..otava
        }),
    ]
}

/// True, false and missed detections.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Tally {
    found: usize,
    false_: usize,
    missed: usize,
}

impl Tally {
    fn add(&mut self, truth: &[usize], reported: &[usize]) {
        let matched = matches(truth, reported);
        let found = matched.iter().flatten().count();
        self.found += found;
        self.missed += truth.len() - found;
        self.false_ += reported.len() - found;
    }

    fn precision(&self) -> f64 {
        ratio(self.found, self.found + self.false_)
    }

    fn recall(&self) -> f64 {
        ratio(self.found, self.found + self.missed)
    }

    fn f1(&self) -> f64 {
        let (p, r) = (self.precision(), self.recall());
        if p + r > 0.0 {
            2.0 * p * r / (p + r)
        } else {
            0.0
        }
    }
}

/// For each true step in order, the index in `reported` of the change point that finds it: the
/// nearest within [`TOLERANCE`] that no earlier step took.
fn matches(truth: &[usize], reported: &[usize]) -> Vec<Option<usize>> {
    let mut used = vec![false; reported.len()];
    truth
        .iter()
        .map(|&k| {
            let nearest = (0..reported.len())
                .filter(|&j| !used[j] && reported[j].abs_diff(k) <= TOLERANCE)
                .min_by_key(|&j| reported[j].abs_diff(k));
            if let Some(j) = nearest {
                used[j] = true;
            }
            nearest
        })
        .collect()
}

/// `a / b`, 1 when there is nothing to count (no detection is never an imprecise one).
fn ratio(a: usize, b: usize) -> f64 {
    if b == 0 { 1.0 } else { a as f64 / b as f64 }
}

/// One method's scores on the corpus.
#[derive(Clone, Debug, PartialEq)]
pub struct MethodScores {
    pub method: String,
    /// Steps of 5% or more (with the flat and spike-only series' false change points).
    pub precision: f64,
    pub recall: f64,
    pub f1: f64,
    /// Steps of 3% to 5%.
    pub f1_small: f64,
    /// Steps of 5% or more beside a ramp (the ramp-and-step series).
    pub f1_beside_drifts: f64,
    /// Steps on the spike-only series: in the whole series, and (`None`: not scored part-way)
    /// the distinct ones reported after any point on the way.
    pub spike_changes: usize,
    pub spike_changes_any_prefix: Option<usize>,
    /// Drifts on the spike-only series.
    pub spike_drifts: usize,
    /// Steps and drifts on the flat series.
    pub flat_changes: usize,
    /// Two-state series with a step or a drift.
    pub two_state_changed: usize,
    /// The median delay over the found steps of 5% or more, in points (`None`: none found, or
    /// not scored part-way).
    pub median_delay: Option<f64>,
    /// The median number of points after a found step (5% or more) from which the change
    /// point stays where the whole series puts it: the commits it names no longer move.
    pub median_settled: Option<f64>,
    /// True drifts of 5% or more over 20 points or more, and the share of them reported as a
    /// drift.
    pub drifts: usize,
    pub drift_recall: f64,
    /// Steps reported inside a true drift's range, over every series with a drift.
    pub steps_in_drifts: usize,
    /// Series with a true drift (of any size) reported with exactly one step inside it.
    pub drifts_as_one_step: usize,
    /// Of the drifts found, the share whose per-commit interval holds the true rate.
    pub drift_rate_covered: Option<f64>,
    /// Drifts on the series without one (steps, spikes, flat, two-state).
    pub false_drifts: usize,
}

/// Every method's scores on a corpus of `series` series.
#[derive(Clone, Debug, PartialEq)]
pub struct CorpusScores {
    pub series: usize,
    pub methods: Vec<MethodScores>,
}

/// Scores `method` on `corpus`.
pub fn score(corpus: &[Series], method: &Method) -> MethodScores {
    let (mut large, mut small, mut beside) = (Tally::default(), Tally::default(), Tally::default());
    let (mut spike_changes, mut spike_any, mut spike_drifts, mut flat, mut two_state) =
        (0, 0, 0, 0, 0);
    let (mut delays, mut settled) = (Vec::new(), Vec::new());
    let (mut drifts, mut drifts_found, mut in_drifts, mut as_one, mut false_drifts) =
        (0, 0, 0, 0, 0);
    let mut covered = Vec::new();
    for s in corpus {
        let every_prefix =
            method.every_prefix() && matches!(s.kind, Kind::Steps(Band::Large) | Kind::Spikes);
        let reports = method.reports(&s.values, every_prefix);
        let last = reports.last().cloned().unwrap_or_default();
        let steps: &[usize] = &last.steps;
        let truth: Vec<usize> = s.steps.iter().map(|t| t.index).collect();
        match (s.drift, s.kind) {
            (Some(d), _) => {
                let inside = steps
                    .iter()
                    .filter(|&&i| (d.start..=d.end).contains(&i))
                    .count();
                in_drifts += inside;
                as_one += usize::from(inside == 1);
                let span = d.end - d.start;
                let size = (d.ratio().ln()).abs();
                let found = last.drifts.iter().find(|r| {
                    let overlap = (r.end.min(d.end) + 1).saturating_sub(r.start.max(d.start));
                    2 * overlap > span && (r.ratio.ln() * d.ratio().ln()) > 0.0
                });
                if span + 1 >= 20 && size >= 1.05f64.ln() {
                    drifts += 1;
                    drifts_found += usize::from(found.is_some());
                }
                if let Some(r) = found {
                    let [lo, hi] = r.per_point_ci95;
                    covered.push(lo <= d.per_point && d.per_point <= hi);
                }
                false_drifts += last.drifts.len() - usize::from(found.is_some());
            }
            (None, _) => false_drifts += last.drifts.len(),
        }
        match s.kind {
            Kind::Steps(Band::Large) => {
                large.add(&truth, steps);
                if every_prefix {
                    let prefixes: Vec<&[usize]> =
                        reports.iter().map(|r| r.steps.as_slice()).collect();
                    prefix_scores(&truth, &prefixes, &mut delays, &mut settled);
                }
            }
            Kind::Steps(Band::Small) => small.add(&truth, steps),
            Kind::RampAndStep => beside.add(&truth, steps),
            Kind::Spikes => {
                large.add(&[], steps);
                spike_changes += steps.len();
                spike_drifts += last.drifts.len();
                let mut any: Vec<usize> = reports.iter().flat_map(|r| r.steps.clone()).collect();
                any.sort_unstable();
                any.dedup();
                spike_any += any.len();
            }
            Kind::Flat => {
                large.add(&[], steps);
                flat += steps.len() + last.drifts.len();
            }
            Kind::TwoState => {
                two_state += usize::from(!steps.is_empty() || !last.drifts.is_empty());
            }
            Kind::Drift | Kind::Ramp => {}
        }
    }
    let prefixed = method.every_prefix();
    MethodScores {
        method: method.name(),
        precision: large.precision(),
        recall: large.recall(),
        f1: large.f1(),
        f1_small: small.f1(),
        f1_beside_drifts: beside.f1(),
        spike_changes,
        spike_changes_any_prefix: prefixed.then_some(spike_any),
        spike_drifts,
        flat_changes: flat,
        two_state_changed: two_state,
        median_delay: median(&delays),
        median_settled: median(&settled),
        drifts,
        drift_recall: ratio(drifts_found, drifts),
        steps_in_drifts: in_drifts,
        drifts_as_one_step: as_one,
        drift_rate_covered: (!covered.is_empty())
            .then(|| covered.iter().filter(|&&c| c).count() as f64 / covered.len() as f64),
        false_drifts,
    }
}

/// The delays and settling points of the true steps `truth` found in the `reports` made after
/// each point of a series.
fn prefix_scores(
    truth: &[usize],
    reports: &[&[usize]],
    delays: &mut Vec<f64>,
    settled: &mut Vec<f64>,
) {
    let last: &[usize] = reports.last().copied().unwrap_or(&[]);
    for (&k, j) in truth.iter().zip(matches(truth, last)) {
        if let Some(j) = j {
            let at = last[j];
            let moved = (0..reports.len())
                .rev()
                .find(|&l| !reports[l].contains(&at));
            settled.push(moved.map_or(0, |l| l + 1).saturating_sub(k) as f64);
        }
        // Reports[l] is after l + 1 points; from the step's own point on.
        let first =
            (k..reports.len()).find(|&l| reports[l].iter().any(|&j| j.abs_diff(k) <= TOLERANCE));
        if let Some(l) = first {
            delays.push((l - k) as f64);
        }
    }
}

/// Every method of [`methods`] scored on `corpus`.
pub fn score_corpus(corpus: &[Series]) -> CorpusScores {
    CorpusScores {
        series: corpus.len(),
        methods: methods().iter().map(|m| score(corpus, m)).collect(),
    }
}

/// The scores as a Markdown table, one column per method, one row per score with its target.
pub fn render_scores_markdown(scores: &CorpusScores) -> String {
    let mut header = vec!["Score".to_string(), "Target".to_string()];
    header.extend(scores.methods.iter().map(|m| m.method.clone()));
    let mut align = vec![Align::Default, Align::Default];
    align.extend(scores.methods.iter().map(|_| Align::Right));
    let mut table = Table::new(header).aligned(align);
    type Cell = fn(&MethodScores) -> String;
    let rows: [(&str, &str, Cell); 17] = [
        ("F1, steps ≥ 5%", "≥ 0.95", |m| format!("{:.3}", m.f1)),
        ("precision, steps ≥ 5%", "", |m| {
            format!("{:.3}", m.precision)
        }),
        ("recall, steps ≥ 5%", "", |m| format!("{:.3}", m.recall)),
        ("F1, steps 3–5%", "≥ 0.95", |m| {
            format!("{:.3}", m.f1_small)
        }),
        ("F1, steps ≥ 5% beside a drift", "", |m| {
            format!("{:.3}", m.f1_beside_drifts)
        }),
        ("median delay, steps ≥ 5% (points)", "≤ 5", |m| {
            m.median_delay.map_or("–".into(), |d| format!("{d:.1}"))
        }),
        (
            "median points until it stays at its final commit",
            "",
            |m| m.median_settled.map_or("–".into(), |d| format!("{d:.1}")),
        ),
        ("steps, spike-only series", "0", |m| {
            m.spike_changes.to_string()
        }),
        ("steps, spike-only series, after any point", "0", |m| {
            m.spike_changes_any_prefix
                .map_or("–".into(), |c| c.to_string())
        }),
        ("drifts, spike-only series", "0", |m| {
            m.spike_drifts.to_string()
        }),
        ("steps and drifts, flat series", "", |m| {
            m.flat_changes.to_string()
        }),
        ("two-state series with a step or drift", "0", |m| {
            m.two_state_changed.to_string()
        }),
        (
            "drifts ≥ 5% over ≥ 20 points reported as drifts",
            "1.000",
            |m| format!("{:.3} of {}", m.drift_recall, m.drifts),
        ),
        ("steps inside a true drift", "0", |m| {
            m.steps_in_drifts.to_string()
        }),
        ("drifts reported as one step", "0", |m| {
            m.drifts_as_one_step.to_string()
        }),
        (
            "drifts found whose rate interval holds the true rate",
            "",
            |m| {
                m.drift_rate_covered
                    .map_or("–".into(), |c| format!("{c:.3}"))
            },
        ),
        ("drifts on series without one", "", |m| {
            m.false_drifts.to_string()
        }),
    ];
    for (name, target, cell) in rows {
        let mut cells = vec![name.to_string(), target.to_string()];
        cells.extend(scores.methods.iter().map(cell));
        table.row(cells);
    }
    let drifting = planned(Kind::Drift) + planned(Kind::Ramp) + planned(Kind::RampAndStep);
    format!(
        "Scores on the {} generated series of `crates/harness/src/history/corpus/` (steps ≥ 5%: \
         {} series with one or two steps, with the {} flat and {} spike-only series; drifts: the \
         {} series with one, {} of them with a step beside it; {} two-state series):\n\n{}",
        scores.series,
        planned(Kind::Steps(Band::Large)),
        planned(Kind::Flat),
        planned(Kind::Spikes),
        drifting,
        planned(Kind::RampAndStep),
        planned(Kind::TwoState),
        table.markdown()
    )
}
