//! The corpus the change-point detection is scored on, and the scores: 600 generated series
//! shaped like a performance history (30 to 120 points, one per commit), each from its own
//! seed, with steps of 3–20% up and down (one or two per series), isolated spikes, slow drifts
//! and flat noise. The chosen detector ([`super::changes`]) and the alternative it was chosen
//! over (Apache Otava's E-divisive means with t-tests, [`EDivisive`]) are scored side by side;
//! the table of docs/explanation/change-points.md is [`render_scores_markdown`] of them, and a
//! test keeps it so.
//!
//! How a detection counts: a change point within ±3 points of a true step is that step found
//! (one change point per step); any other is a false one. The scores for steps of 5% or more
//! count the series with such steps and the flat and spike-only series (their change points
//! are all false); the 3–5% scores count the series with steps of that size. Drifts have no
//! true step: the change points that approximate a ramp are reported, not scored. The delay
//! of a found step is how many points after its first one the detector, fed one point at a
//! time, first reports it (within the tolerance); it has settled from the point after which
//! it stays where the whole series puts it.

use super::changes::{Detector, Incremental, MIN_SEGMENT};
use crate::render::tables::{Align, Table};
use nbody_engine::stats::median;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rand_pcg::Pcg64Mcg;

/// The noise of one point is log-normal, its σ drawn per series between these two values.
/// Provenance: results/gate-study/AuthenticAMD-26-2-1-2cpu.json, `runs[].widths`, mode `ab`,
/// `raw`: the median width of the gate's A/A (unchanged code) 95% intervals of the ratio,
/// relative to the ratio, is 0.0279 with the machine quiet and 0.0391 under a spinning load. A
/// width is 2 × 1.96 standard errors of the log ratio: σ = 0.0279 / 3.92 = 0.0071 and
/// 0.0391 / 3.92 = 0.0100. Those are the spread of a ratio of two interleaved runs; a
/// history's point comes from a run of its own, on its own day and runner, so each point gets
/// the whole σ (not σ/√2), which keeps the corpus on the noisy side.
const SIGMA: [f64; 2] = [0.0071, 0.0100];

/// The first series' seed; series i has `SEED + i`.
const SEED: u64 = 20_261_205;

/// A detection within this many points of a true step finds it.
const TOLERANCE: usize = 3;

/// What a series holds besides noise.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Steps(Band),
    Spikes,
    Drift,
    Flat,
}

/// The size of a series' steps, |ratio − 1|.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Band {
    /// 5% to 20%: the steps the detector must find (F1 ≥ 0.9).
    Large,
    /// 3% to 5%: reported, no target.
    Small,
}

impl Band {
    fn sizes(self) -> std::ops::Range<f64> {
        match self {
            Band::Large => 0.05..0.20,
            Band::Small => 0.03..0.05,
        }
    }
}

/// A true step: the first point of the new level and its ratio to the old.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    pub index: usize,
    pub ratio: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub kind: Kind,
    pub values: Vec<f64>,
    pub steps: Vec<Step>,
}

/// How many series of each kind (with how many steps): 600 in all.
const PLAN: [(Kind, usize, usize); 7] = [
    (Kind::Steps(Band::Large), 1, 150),
    (Kind::Steps(Band::Large), 2, 100),
    (Kind::Steps(Band::Small), 1, 75),
    (Kind::Steps(Band::Small), 2, 25),
    (Kind::Spikes, 0, 100),
    (Kind::Drift, 0, 50),
    (Kind::Flat, 0, 100),
];

/// The corpus, the same on every call.
pub fn corpus() -> Vec<Series> {
    let mut out = Vec::new();
    for (kind, steps, count) in PLAN {
        for _ in 0..count {
            let seed = SEED + out.len() as u64;
            out.push(generate(kind, steps, &mut Pcg64Mcg::seed_from_u64(seed)));
        }
    }
    out
}

fn generate(kind: Kind, n_steps: usize, rng: &mut Pcg64Mcg) -> Series {
    let n: usize = rng.random_range(if n_steps == 2 { 40..=120 } else { 30..=120 });
    let sigma = rng.random_range(SIGMA[0]..=SIGMA[1]);
    let base = 10f64.powf(rng.random_range(-6.0..0.0));
    let mut factor = vec![1.0; n];
    let mut steps = Vec::new();
    let mut spikes = Vec::new();
    match kind {
        Kind::Steps(band) => {
            // At least 10 points on each side of a step and between two.
            let first = rng.random_range(10..=n - 10 * n_steps);
            let mut at = first;
            for i in 0..n_steps {
                if i > 0 {
                    at = rng.random_range(at + 10..=n - 10);
                }
                let size = rng.random_range(band.sizes());
                let ratio = if rng.random_bool(0.5) {
                    1.0 + size
                } else {
                    1.0 - size
                };
                steps.push(Step { index: at, ratio });
            }
            // A quarter of them also have a spike, at least 2 points from any step.
            if rng.random_bool(0.25) {
                let at = rng.random_range(0..n);
                if steps.iter().all(|s| at.abs_diff(s.index) >= 2) {
                    spikes.push(at);
                }
            }
        }
        Kind::Spikes => {
            let count = rng.random_range(1..=3);
            for _ in 0..50 {
                let at = rng.random_range(0..n);
                if spikes.len() < count && spikes.iter().all(|&s: &usize| at.abs_diff(s) >= 10) {
                    spikes.push(at);
                }
            }
        }
        Kind::Drift => {
            let size = rng.random_range(0.03..0.10);
            let total: f64 = if rng.random_bool(0.5) {
                1.0 + size
            } else {
                1.0 - size
            };
            for (i, f) in factor.iter_mut().enumerate() {
                *f = total.powf(i as f64 / (n - 1) as f64);
            }
        }
        Kind::Flat => {}
    }
    for s in &steps {
        for f in &mut factor[s.index..] {
            *f *= s.ratio;
        }
    }
    for &at in &spikes {
        // Mostly slow outliers (a busy neighbour), up to twice the time; some fast ones.
        factor[at] *= if rng.random_bool(0.8) {
            1.0 + rng.random_range(0.05..1.0)
        } else {
            1.0 - rng.random_range(0.05..0.3)
        };
    }
    let values = factor
        .iter()
        .map(|f| {
            let z: f64 = rng.sample(StandardNormal);
            base * f * (sigma * z).exp()
        })
        .collect();
    Series {
        kind,
        values,
        steps,
    }
}

/// A detector the corpus scores.
#[derive(Clone, Copy, Debug)]
pub enum Method {
    /// The chosen one ([`super::changes`]), fed one point at a time.
    Pelt(Detector),
    /// The alternative, rerun on each prefix for the delays.
    EDivisive(EDivisive),
}

impl Method {
    fn name(&self) -> String {
        match self {
            Method::Pelt(d) => format!(
                "PELT, L1 cost, min segment {}, penalty {}σ (chosen)",
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

    /// The change points' indices reported after each point, or (`every_prefix` false) after
    /// the last only.
    fn reports(&self, values: &[f64], every_prefix: bool) -> Vec<Vec<usize>> {
        match self {
            Method::Pelt(d) => {
                let mut inc = Incremental::new(*d);
                let mut out = Vec::new();
                for (i, &v) in values.iter().enumerate() {
                    inc.push(v).expect("corpus values are positive times");
                    if every_prefix || i + 1 == values.len() {
                        out.push(inc.changes().iter().map(|c| c.index).collect());
                    }
                }
                out
            }
            Method::EDivisive(e) => {
                let logs: Vec<f64> = values.iter().map(|v| v.ln()).collect();
                let from = if every_prefix { 1 } else { logs.len() };
                (from..=logs.len())
                    .map(|l| e.change_points(&logs[..l]))
                    .collect()
            }
        }
    }
}

/// The methods the corpus compares: the chosen detector, Otava's defaults, and Otava with the
/// same minimum segment.
pub fn methods() -> Vec<Method> {
    let otava = EDivisive {
        window: 50,
        max_pvalue: 0.001,
        min_segment: 1,
    };
    vec![
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
    /// Change points on the spike-only series: in the whole series, and the distinct ones
    /// reported after any point on the way.
    pub spike_changes: usize,
    pub spike_changes_any_prefix: usize,
    /// Change points on the flat series.
    pub flat_changes: usize,
    /// The median delay over the found steps of 5% or more, in points (`None`: none found).
    pub median_delay: Option<f64>,
    /// The median number of points after a found step (5% or more) from which the change
    /// point stays where the whole series puts it: the commits it names no longer move.
    pub median_settled: Option<f64>,
    /// Change points per drift series, on average.
    pub drift_changes: f64,
}

/// Every method's scores on a corpus of `series` series.
#[derive(Clone, Debug, PartialEq)]
pub struct CorpusScores {
    pub series: usize,
    pub methods: Vec<MethodScores>,
}

/// Scores `method` on `corpus`.
pub fn score(corpus: &[Series], method: &Method) -> MethodScores {
    let (mut large, mut small) = (Tally::default(), Tally::default());
    let (mut spike_changes, mut spike_any, mut flat, mut drift) = (0, 0, 0, 0);
    let (mut delays, mut settled) = (Vec::new(), Vec::new());
    for s in corpus {
        let every_prefix = matches!(s.kind, Kind::Steps(Band::Large) | Kind::Spikes);
        let reports = method.reports(&s.values, every_prefix);
        let last: &[usize] = reports.last().map_or(&[], Vec::as_slice);
        let truth: Vec<usize> = s.steps.iter().map(|t| t.index).collect();
        match s.kind {
            Kind::Steps(Band::Large) => {
                large.add(&truth, last);
                for (&k, j) in truth.iter().zip(matches(&truth, last)) {
                    if let Some(j) = j {
                        let at = last[j];
                        let moved = (0..reports.len())
                            .rev()
                            .find(|&l| !reports[l].contains(&at));
                        settled.push(moved.map_or(0, |l| l + 1).saturating_sub(k) as f64);
                    }
                    // Reports[l] is after l + 1 points; from the step's own point on.
                    let first = (k..reports.len())
                        .find(|&l| reports[l].iter().any(|&j| j.abs_diff(k) <= TOLERANCE));
                    if let Some(l) = first {
                        delays.push((l - k) as f64);
                    }
                }
            }
            Kind::Steps(Band::Small) => small.add(&truth, last),
            Kind::Spikes => {
                large.add(&[], last);
                spike_changes += last.len();
                let mut any: Vec<usize> = reports.concat();
                any.sort_unstable();
                any.dedup();
                spike_any += any.len();
            }
            Kind::Flat => {
                large.add(&[], last);
                flat += last.len();
            }
            Kind::Drift => drift += last.len(),
        }
    }
    let drifts = corpus.iter().filter(|s| s.kind == Kind::Drift).count();
    MethodScores {
        method: method.name(),
        precision: large.precision(),
        recall: large.recall(),
        f1: large.f1(),
        f1_small: small.f1(),
        spike_changes,
        spike_changes_any_prefix: spike_any,
        flat_changes: flat,
        median_delay: median(&delays),
        median_settled: median(&settled),
        drift_changes: drift as f64 / drifts.max(1) as f64,
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
    let rows: [(&str, &str, Cell); 10] = [
        ("F1, steps ≥ 5%", "≥ 0.9", |m| format!("{:.3}", m.f1)),
        ("precision, steps ≥ 5%", "", |m| {
            format!("{:.3}", m.precision)
        }),
        ("recall, steps ≥ 5%", "", |m| format!("{:.3}", m.recall)),
        ("F1, steps 3–5%", "", |m| format!("{:.3}", m.f1_small)),
        ("median delay, steps ≥ 5% (points)", "≤ 5", |m| {
            m.median_delay.map_or("–".into(), |d| format!("{d:.1}"))
        }),
        (
            "median points until it stays at its final commit",
            "",
            |m| m.median_settled.map_or("–".into(), |d| format!("{d:.1}")),
        ),
        ("change points, spike-only series", "0", |m| {
            m.spike_changes.to_string()
        }),
        (
            "change points, spike-only series, after any point",
            "0",
            |m| m.spike_changes_any_prefix.to_string(),
        ),
        ("change points, flat series", "", |m| {
            m.flat_changes.to_string()
        }),
        ("change points per drift series", "", |m| {
            format!("{:.2}", m.drift_changes)
        }),
    ];
    for (name, target, cell) in rows {
        let mut cells = vec![name.to_string(), target.to_string()];
        cells.extend(scores.methods.iter().map(cell));
        table.row(cells);
    }
    format!(
        "Scores on the {} generated series of `crates/harness/src/history/corpus.rs` (steps ≥ 5%: {} \
         series with one or two steps, with the {} flat and {} spike-only series):\n\n{}",
        scores.series,
        PLAN.iter()
            .filter(|p| p.0 == Kind::Steps(Band::Large))
            .map(|p| p.2)
            .sum::<usize>(),
        PLAN.iter()
            .filter(|p| p.0 == Kind::Flat)
            .map(|p| p.2)
            .sum::<usize>(),
        PLAN.iter()
            .filter(|p| p.0 == Kind::Spikes)
            .map(|p| p.2)
            .sum::<usize>(),
        table.markdown()
    )
}

/// Apache Otava's change-point detection (Fleming et al., ICPE 2023), here on the logarithms:
/// E-divisive means finds the split of a window that maximises the energy statistic q̂; a
/// Student's t-test between the two sides keeps it if p ≤ 10 × `max_pvalue`, and splitting
/// goes on in the pieces; windows of `window` points slide by half a window; then the merge
/// step drops, weakest first, the change points whose t-test between their neighbours' segments
/// fails `max_pvalue`. `min_segment` 1 is Otava's; more keeps q̂ and the merge off shorter
/// segments (Otava issue #150's proposal).
#[derive(Clone, Copy, Debug)]
pub struct EDivisive {
    pub window: usize,
    pub max_pvalue: f64,
    pub min_segment: usize,
}

impl EDivisive {
    /// The change points of `x` (logarithms), ascending.
    pub fn change_points(&self, x: &[f64]) -> Vec<usize> {
        let m = self.min_segment.max(1);
        // Otava's first pass: a p-value ten times as loose (for max_pvalue below 0.05).
        let weak_p = self.max_pvalue * 10.0;
        let step = (self.window / 2).max(1);
        let (mut start, mut found) = (0, Vec::new());
        while start < x.len() {
            let end = (start + self.window).min(x.len());
            let new: Vec<usize> = split(&x[start..end], weak_p, m)
                .into_iter()
                .map(|i| i + start)
                .collect();
            let last = new.last().copied().unwrap_or(0);
            for i in new {
                if !found.contains(&i) {
                    found.push(i);
                }
            }
            start = last.max(start + step);
        }
        found.sort_unstable();
        // The merge step.
        loop {
            let p: Vec<f64> = (0..found.len())
                .map(|i| {
                    let a = if i == 0 { 0 } else { found[i - 1] };
                    let b = found.get(i + 1).copied().unwrap_or(x.len());
                    if found[i] - a < m || b - found[i] < m {
                        1.0
                    } else {
                        t_test(&x[a..found[i]], &x[found[i]..b])
                    }
                })
                .collect();
            let weakest = (0..p.len()).fold(None, |w: Option<usize>, i| match w {
                Some(j) if p[j] >= p[i] => Some(j),
                _ => Some(i),
            });
            match weakest {
                Some(i) if p[i] >= self.max_pvalue => {
                    found.remove(i);
                }
                _ => return found,
            }
        }
    }
}

/// E-divisive within one window `z`: the best split by q̂ over the current pieces, kept while
/// its t-test passes `p`.
fn split(z: &[f64], p: f64, m: usize) -> Vec<usize> {
    let sums = PairSums::new(z);
    let mut cps: Vec<usize> = Vec::new();
    loop {
        let mut bounds = vec![0];
        bounds.extend_from_slice(&cps);
        bounds.push(z.len());
        let mut best: Option<(f64, usize, usize, usize)> = None;
        for w in bounds.windows(2) {
            if let Some((q, tau)) = candidate(&sums, w[0], w[1], m)
                && best.is_none_or(|b| q > b.0)
            {
                best = Some((q, tau, w[0], w[1]));
            }
        }
        match best {
            Some((_, tau, a, b)) if t_test(&z[a..tau], &z[tau..b]) <= p => {
                cps.push(tau);
                cps.sort_unstable();
            }
            _ => return cps,
        }
    }
}

/// Sums of |z_i − z_j| over the pairs i < j of [u, v), for every u ≤ v.
struct PairSums {
    width: usize,
    sums: Vec<f64>,
}

impl PairSums {
    fn new(z: &[f64]) -> Self {
        let width = z.len() + 1;
        let mut sums = vec![0.0; width * width];
        for v in 1..z.len() {
            let mut column = 0.0;
            for u in (0..v).rev() {
                column += (z[u] - z[v]).abs();
                sums[u * width + v + 1] = sums[u * width + v] + column;
            }
        }
        PairSums { width, sums }
    }

    fn get(&self, u: usize, v: usize) -> f64 {
        self.sums[u * self.width + v]
    }
}

/// The split τ of [a, b) maximising q̂ of [a, τ) against [τ, κ) over κ ≤ b (Otava's
/// candidate), each side at least `m` points.
fn candidate(s: &PairSums, a: usize, b: usize, m: usize) -> Option<(f64, usize)> {
    let mut best: Option<(f64, usize)> = None;
    if b < a + 2 * m {
        return None;
    }
    for tau in a + m..=b - m {
        for kappa in tau + m..=b {
            let (n, k, total) = ((tau - a) as f64, (kappa - tau) as f64, (kappa - a) as f64);
            let (left, right) = (s.get(a, tau), s.get(tau, kappa));
            let cross = s.get(a, kappa) - left - right;
            let mut q = 2.0 / total * cross;
            if n > 1.0 {
                q -= 2.0 * k / (total * (n - 1.0)) * left;
            }
            if k > 1.0 {
                q -= 2.0 * n / (total * (k - 1.0)) * right;
            }
            if best.is_none_or(|b| q > b.0) {
                best = Some((q, tau));
            }
        }
    }
    best
}

/// The two-sided p-value of Student's t-test (pooled variance) between `a` and `b`.
fn t_test(a: &[f64], b: &[f64]) -> f64 {
    let (na, nb) = (a.len() as f64, b.len() as f64);
    let df = na + nb - 2.0;
    if df <= 0.0 {
        return 1.0;
    }
    let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len() as f64;
    let (ma, mb) = (mean(a), mean(b));
    let ss = |x: &[f64], m: f64| x.iter().map(|v| (v - m) * (v - m)).sum::<f64>();
    let pooled = (ss(a, ma) + ss(b, mb)) / df;
    let se = (pooled * (1.0 / na + 1.0 / nb)).sqrt();
    if se == 0.0 {
        return if ma == mb { 1.0 } else { 0.0 };
    }
    let t = (ma - mb) / se;
    beta_regularized(df / 2.0, 0.5, df / (df + t * t))
}

/// The regularized incomplete beta function I_x(a, b): the gate's, which its Clopper-Pearson
/// intervals use.
fn beta_regularized(a: f64, b: f64, x: f64) -> f64 {
    crate::gate::family::incomplete_beta(x, a, b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::OnceLock;

    const PAGE: &str = "docs/explanation/change-points.md";
    const BEGIN: &str = "<!-- corpus-scores:begin -->";
    const END: &str = "<!-- corpus-scores:end -->";
    const UPDATE: &str = "NBODY_BENCH_UPDATE_DOCS";

    /// The corpus is scored once for all the tests that read the scores.
    fn scores() -> &'static CorpusScores {
        static SCORES: OnceLock<CorpusScores> = OnceLock::new();
        SCORES.get_or_init(|| score_corpus(&corpus()))
    }

    /// `page` with the region between the marks replaced by `region`.
    fn splice(page: &str, region: &str) -> Option<String> {
        let begin = page.find(BEGIN)? + BEGIN.len();
        let end = begin + page[begin..].find(END)?;
        Some(format!("{}\n{region}{}", &page[..begin], &page[end..]))
    }

    #[test]
    fn the_corpus_is_as_described() {
        let c = corpus();
        assert_eq!(c.len(), 600);
        assert_eq!(c, corpus(), "the same on every call");
        for s in &c {
            assert!((30..=120).contains(&s.values.len()));
            assert!(s.values.iter().all(|v| v.is_finite() && *v > 0.0));
            for t in &s.steps {
                let size = (t.ratio - 1.0).abs();
                assert!((0.03..=0.20).contains(&size), "{t:?}");
                assert!(t.index >= 10 && t.index + 10 <= s.values.len());
            }
        }
    }

    #[test]
    fn the_t_test_gives_the_tables_p_values() {
        // t = 2.228 with 10 degrees of freedom is the two-sided 5% point; 12.706 with 1.
        let two_sided = |t: f64, df: f64| beta_regularized(df / 2.0, 0.5, df / (df + t * t));
        assert!((two_sided(2.228, 10.0) - 0.05).abs() < 2e-4);
        assert!((two_sided(12.706, 1.0) - 0.05).abs() < 2e-4);
        assert!((two_sided(0.0, 5.0) - 1.0).abs() < 1e-12);
        assert_eq!(t_test(&[1.0, 1.0], &[2.0, 2.0]), 0.0);
    }

    #[test]
    fn the_detector_meets_its_targets_on_the_corpus() {
        let chosen = &scores().methods[0];
        assert!(chosen.f1 >= 0.9, "{chosen:?}");
        assert_eq!(chosen.spike_changes, 0, "{chosen:?}");
        assert_eq!(chosen.spike_changes_any_prefix, 0, "{chosen:?}");
        assert!(chosen.median_delay.is_some_and(|d| d <= 5.0), "{chosen:?}");
    }

    /// docs/explanation/change-points.md shows the scores this corpus gives; under
    /// `NBODY_BENCH_UPDATE_DOCS=1` the test rewrites the page's region instead.
    #[test]
    fn the_explanation_page_shows_the_corpus_scores() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../..")
            .join(PAGE);
        let page = std::fs::read_to_string(&path).unwrap();
        let generated = splice(&page, &render_scores_markdown(scores()))
            .unwrap_or_else(|| panic!("{PAGE} keeps the marks {BEGIN} and {END}"));
        if std::env::var(UPDATE).as_deref() == Ok("1") {
            std::fs::write(&path, &generated).unwrap();
            return;
        }
        assert!(
            page == generated,
            "{PAGE}'s corpus scores are stale: regenerate them with `{UPDATE}=1 cargo test \
             --release --lib -- history::corpus`, review the diff and commit it\n\
             generated:\n{}",
            render_scores_markdown(scores())
        );
    }
}
