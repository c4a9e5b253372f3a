//! Where two codes' costs cross over n, read from the measurements: at each size both
//! measured, which one is faster, by more than [`LEVEL`] and with their 95% intervals apart.
//! A crossover is the span of sizes in which that order changes, with the size where the
//! measured ratio crosses 1 interpolated between its ends. Fitted curves are not used: they
//! cross or not depending on which class the fits pick, so a crossover read from them came and
//! went between identical runs; the measured order does not flip unless the data do.

use super::ComplexityAnalysis;
use super::groups::Point;
use serde::Serialize;

/// Two codes whose medians differ by less than this at a size are level there: the gate's
/// threshold for builds measured in interleaved rounds, as a sweep measures its codes
/// (`gate::AB_THRESHOLD`, from its noise study), below which a difference is not evidence.
const LEVEL: f64 = 0.03;

/// How two codes measured at the same sizes compare over n.
#[derive(Clone, Debug, Serialize)]
pub(crate) struct Crossover {
    pub scenario: String,
    pub precision: String,
    pub threads: usize,
    /// The code faster at the largest size where one is, and the other one.
    pub(crate) faster_above: String,
    pub(crate) faster_below: String,
    /// Where the measured order changes: the size at which the ratio of the two medians
    /// crosses 1, interpolated (log-log) within `between`; `None` when it does not change.
    pub n: Option<f64>,
    /// The sizes the change lies between: the largest at which `faster_below` is faster and
    /// the smallest above it at which `faster_above` is; `None` when the order does not change.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub between: Option<[usize; 2]>,
    /// Sizes at which neither is faster (level, or the intervals overlap): the order is not
    /// resolved there.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub unresolved: Vec<usize>,
    /// The smallest and largest size both were measured at.
    pub(crate) range: [usize; 2],
    /// The sizes both were measured at, in increasing order.
    #[serde(skip)]
    sizes: Vec<usize>,
}

impl Crossover {
    /// Where a crossover may lie outside what was resolved: the sizes at one end of the
    /// range at which neither code is faster, while one is at every other size. `Below` when
    /// they are the smallest sizes (the order could change below the first resolved one).
    fn open_end(&self) -> Option<End> {
        let (u, all) = (self.unresolved.len(), self.sizes.len());
        if self.between.is_some() || u == 0 || u == all {
            return None;
        }
        if self.unresolved[..] == self.sizes[..u] {
            Some(End::Below(self.sizes[u]))
        } else if self.unresolved[..] == self.sizes[all - u..] {
            Some(End::Above(self.sizes[all - u - 1]))
        } else {
            None
        }
    }

    /// Whether the pair shows no crossover: no change of order, and none left open at an end
    /// of the range (one faster wherever either is, or the two level).
    pub(crate) fn settled(&self) -> bool {
        self.between.is_none() && self.open_end().is_none()
    }
}

/// The end of the range where a crossover is not resolved, with the last size resolved.
#[derive(Clone, Copy, Debug, PartialEq)]
enum End {
    Below(usize),
    Above(usize),
}

/// Which of two codes is faster at one size, if either is.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Order {
    A,
    B,
    Level,
}

fn order(a: &Point, b: &Point) -> Order {
    let apart_by = |fast: &Point, slow: &Point| {
        fast.ci95_s[1] < slow.ci95_s[0] && slow.median_s > fast.median_s * (1.0 + LEVEL)
    };
    if apart_by(a, b) {
        Order::A
    } else if apart_by(b, a) {
        Order::B
    } else {
        Order::Level
    }
}

/// Every pair of series of the same scenario, precision and workers measured at two or more
/// common sizes, each pair once: the same pairs whatever the data, so that a crossover is
/// never in one run's list and missing from the next.
pub(crate) fn crossovers(all: &[ComplexityAnalysis]) -> Vec<Crossover> {
    let mut out = Vec::new();
    for (i, a) in all.iter().enumerate() {
        for b in &all[i + 1..] {
            let same = a.series.scenario == b.series.scenario
                && a.series.precision == b.series.precision
                && a.series.threads == b.series.threads
                && a.series.ranks == b.series.ranks;
            let Some(m) = same.then(|| measured_order(&a.points, &b.points)).flatten() else {
                continue;
            };
            let (above, below) = if m.a_above { (a, b) } else { (b, a) };
            out.push(Crossover {
                scenario: a.series.scenario.name().into(),
                precision: a.series.precision.name().into(),
                threads: a.series.threads.unwrap_or(1),
                faster_above: above.label.clone(),
                faster_below: below.label.clone(),
                n: m.n,
                between: m.between,
                unresolved: m.unresolved,
                range: [m.sizes[0], m.sizes[m.sizes.len() - 1]],
                sizes: m.sizes,
            });
        }
    }
    out
}

/// How two series compare at the sizes both were measured at.
#[derive(Debug, PartialEq)]
struct MeasuredOrder {
    /// Whether the first series is the one faster at the largest size where one is.
    a_above: bool,
    /// See [`Crossover::n`].
    n: Option<f64>,
    /// See [`Crossover::between`].
    between: Option<[usize; 2]>,
    /// See [`Crossover::unresolved`].
    unresolved: Vec<usize>,
    /// The sizes both were measured at, increasing.
    sizes: Vec<usize>,
}

/// The order of `a` and `b` (each in increasing n) at the sizes both were measured at;
/// `None` with fewer than two.
fn measured_order(a: &[Point], b: &[Point]) -> Option<MeasuredOrder> {
    let pairs: Vec<(&Point, &Point)> = a
        .iter()
        .filter_map(|pa| Some((pa, b.iter().find(|pb| pb.n == pa.n)?)))
        .collect();
    if pairs.len() < 2 {
        return None;
    }
    let orders: Vec<Order> = pairs.iter().map(|(pa, pb)| order(pa, pb)).collect();
    // The faster above is the one faster at the largest size where one is; with no size
    // resolved, the one with the smaller median at the largest size.
    let top = match orders.iter().rev().find(|o| **o != Order::Level) {
        Some(o) => *o,
        None => {
            let (pa, pb) = pairs[pairs.len() - 1];
            if pa.median_s <= pb.median_s {
                Order::A
            } else {
                Order::B
            }
        }
    };
    let other = if top == Order::A { Order::B } else { Order::A };
    let between = orders.iter().rposition(|o| *o == other).map(|i| {
        let j = (i + 1..orders.len())
            .find(|&j| orders[j] == top)
            .expect("the faster above is faster at a larger size");
        (i, j)
    });
    // ln(T_above / T_below) at the k-th common size: positive where the other is faster.
    let log_ratio = |k: usize| {
        let (pa, pb) = pairs[k];
        let ratio = pa.median_s / pb.median_s;
        if top == Order::A { ratio } else { 1.0 / ratio }.ln()
    };
    let n = between.map(|(i, j)| {
        let (ri, rj) = (log_ratio(i), log_ratio(j));
        let (ni, nj) = ((pairs[i].0.n as f64).ln(), (pairs[j].0.n as f64).ln());
        (ni + (nj - ni) * ri / (ri - rj)).exp()
    });
    Some(MeasuredOrder {
        a_above: top == Order::A,
        n,
        between: between.map(|(i, j)| [pairs[i].0.n, pairs[j].0.n]),
        unresolved: pairs
            .iter()
            .zip(&orders)
            .filter(|(_, o)| **o == Order::Level)
            .map(|((pa, _), _)| pa.n)
            .collect(),
        sizes: pairs.iter().map(|(pa, _)| pa.n).collect(),
    })
}

/// "galaxy (f64, 1 thread): octree θ=0.5 is faster from n = 4000 on, naive up to n = 2000; the
/// order changes between them (n ≈ 2239 where the measured ratio crosses 1)."
pub(crate) fn sentence(x: &Crossover) -> String {
    let head = format!(
        "{} ({}, {} thread{})",
        x.scenario,
        x.precision,
        x.threads,
        if x.threads == 1 { "" } else { "s" }
    );
    let sizes = |ns: &[usize]| {
        ns.iter()
            .map(usize::to_string)
            .collect::<Vec<_>>()
            .join(", ")
    };
    let level = if x.unresolved.is_empty() {
        String::new()
    } else {
        format!(
            " At n = {} the two are level (within {:.0}% of each other or of each other's 95% \
             CI).",
            sizes(&x.unresolved),
            100.0 * LEVEL
        )
    };
    let [lo, hi] = x.range;
    let (above, below) = (&x.faster_above, &x.faster_below);
    if let (Some([from, to]), Some(n)) = (x.between, x.n) {
        return format!(
            "{head}: {above} is faster from n = {to} on, {below} up to n = {from}; the order \
             changes between them (n ≈ {n:.0} where the measured ratio crosses 1).{level}"
        );
    }
    match x.open_end() {
        Some(End::Below(first)) => format!(
            "{head}: {above} is faster than {below} from n = {first} on.{level} Whether they \
             cross below n = {first} is not resolved at these n."
        ),
        Some(End::Above(last)) => format!(
            "{head}: {above} is faster than {below} up to n = {last}.{level} Whether they \
             cross above n = {last} is not resolved at these n."
        ),
        None if x.unresolved.len() == x.sizes.len() => format!(
            "{head}: neither {above} nor {below} is faster at any measured n (n = {lo}–{hi})."
        ),
        None if x.unresolved.is_empty() => {
            format!("{head}: {above} is faster than {below} at every measured n (n = {lo}–{hi}).")
        }
        None => format!(
            "{head}: {above} is faster than {below} wherever either is (n = {lo}–{hi}).{level}"
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::family::tests::point;
    use nbody_engine::kernels::KernelKind;

    const NS: [usize; 6] = [500, 1000, 2000, 4000, 8000, 16000];

    /// A series of `kernel` at [`NS`] taking `t(n)` per step, each median times the factor
    /// `wobble` gives its index (the noise of one run), its interval ±1%.
    fn series(kernel: KernelKind, t: impl Fn(f64) -> f64, wobble: &[f64]) -> Vec<Point> {
        NS.iter()
            .zip(wobble)
            .map(|(&n, w)| point(kernel, n, 1, t(n as f64) * w))
            .collect()
    }

    fn crossover(m: MeasuredOrder) -> Crossover {
        let (above, below) = if m.a_above { ("a", "b") } else { ("b", "a") };
        Crossover {
            scenario: "lj-box".into(),
            precision: "f32".into(),
            threads: 1,
            faster_above: above.into(),
            faster_below: below.into(),
            n: m.n,
            between: m.between,
            unresolved: m.unresolved,
            range: [m.sizes[0], m.sizes[m.sizes.len() - 1]],
            sizes: m.sizes,
        }
    }

    #[test]
    fn a_crossover_is_the_span_where_the_measured_order_changes() {
        // 1e-9 n² = 2e-6 n at n = 2000: level there, the quadratic one faster below.
        let quiet = [1.0; 6];
        let a = series(KernelKind::Naive, |n| 1e-9 * n * n, &quiet);
        let b = series(KernelKind::CellList, |n| 2e-6 * n, &quiet);
        let m = measured_order(&a, &b).unwrap();
        assert!(!m.a_above);
        assert_eq!(m.between, Some([1000, 4000]));
        assert_eq!(m.unresolved, vec![2000]);
        let n = m.n.unwrap();
        assert!((n / 2000.0 - 1.0).abs() < 1e-9, "{n}");
        let x = crossover(m);
        assert!(!x.settled());
        let s = sentence(&x);
        assert!(
            s.contains("b is faster from n = 4000 on, a up to n = 1000"),
            "{s}"
        );
        assert!(s.contains("n ≈ 2000"), "{s}");
    }

    #[test]
    fn runs_with_other_noise_read_the_same_crossover() {
        // Each run's medians off by up to 2.5% (more than their ±1% intervals), in
        // different patterns: the span and the faster codes stay, n moves within the span.
        let runs = [
            [1.0, 1.0, 1.0, 1.0, 1.0, 1.0],
            [1.025, 0.975, 1.02, 0.98, 1.01, 0.99],
            [0.975, 1.025, 0.98, 1.02, 0.99, 1.01],
            [1.02, 1.02, 0.975, 0.975, 1.02, 1.02],
        ];
        let quiet = [1.0; 6];
        let b = series(KernelKind::CellList, |n| 2e-6 * n, &quiet);
        let readings: Vec<(bool, Option<[usize; 2]>)> = runs
            .iter()
            .map(|w| {
                let a = series(KernelKind::Naive, |n| 1e-9 * n * n, w);
                let m = measured_order(&a, &b).unwrap();
                let n = m.n.expect("the order changes in every run");
                assert!((1000.0..=4000.0).contains(&n), "{n}");
                (m.a_above, m.between)
            })
            .collect();
        assert!(readings.iter().all(|r| *r == readings[0]), "{readings:?}");
    }

    #[test]
    fn codes_level_at_every_size_or_faster_throughout_show_no_crossover() {
        let a = series(KernelKind::Symmetric, |n| 1e-9 * n * n, &[1.0; 6]);
        let wobble = [1.02, 0.98, 1.01, 0.99, 1.02, 0.98];
        let b = series(KernelKind::PerThread, |n| 1e-9 * n * n, &wobble);
        let level = crossover(measured_order(&a, &b).unwrap());
        assert_eq!(level.unresolved.len(), NS.len());
        assert!(level.settled() && level.n.is_none());
        assert!(sentence(&level).contains("neither"), "{}", sentence(&level));
        let c = series(KernelKind::CellList, |n| 1e-7 * n, &[1.0; 6]);
        let faster = crossover(measured_order(&a, &c).unwrap());
        assert!(faster.settled() && faster.between.is_none() && faster.n.is_none());
        let s = sentence(&faster);
        assert!(
            s.contains("b is faster than a at every measured n (n = 500–16000)"),
            "{s}"
        );
    }

    #[test]
    fn a_crossover_that_may_lie_below_the_first_size_is_said_to_be_unresolved() {
        // Level at n = 500, the linear code faster from 1000 on: no change of order is
        // measured, but one below 1000 is not ruled out.
        let a = series(KernelKind::Naive, |n| 2e-9 * n * n, &[1.0; 6]);
        let b = series(KernelKind::CellList, |n| 1e-6 * n, &[1.0; 6]);
        let x = crossover(measured_order(&a, &b).unwrap());
        assert_eq!((x.between, x.unresolved.clone()), (None, vec![500]));
        assert!(!x.settled());
        let s = sentence(&x);
        assert!(s.contains("b is faster than a from n = 1000 on"), "{s}");
        assert!(s.contains("not resolved at these n"), "{s}");
        // Fewer than two common sizes: nothing to compare.
        assert!(measured_order(&a[..1], &b[..1]).is_none());
    }
}
