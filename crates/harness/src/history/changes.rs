//! Change points of a performance history: where a case's series (one value per commit, in
//! commit order) steps to a new level, between which two commits, and by how much.
//!
//! **Method.** The series is cut into segments by exact optimal partitioning, computed with
//! PELT (Killick, Fearnhead & Eckley 2012), of its logarithms under an L1 cost: a segment costs
//! the sum of its points' absolute deviations from the segment's median, and every change point
//! a penalty of `penalty × σ`, σ being the noise of one point estimated from the series itself
//! (from the median absolute difference between consecutive points, which a step or a spike
//! barely moves). No segment is shorter than `min_segment` points. What each choice is for:
//!
//! - *Logarithms*: a step is relative (a kernel 8% slower is 8% slower at any n), and the noise
//!   of a time is too, so in log space one penalty serves a 1 µs case and a 10 s one.
//! - *Medians (L1) and a minimum segment of at least 3*: one spike moves the median of a
//!   segment of three points or more by at most one rank, so it cannot pay for a change point;
//!   with a squared (mean) cost it would (a big enough spike always buys its own short
//!   segment). The default minimum segment, 5, also keeps two outliers within 5 points from
//!   making one; a step shows once 3 points of its new level are in (a majority of 5), at
//!   first up to 2 points early, and moves to its commit as the new level grows.
//! - *Penalized likelihood rather than a test per candidate*: Apache Otava's E-divisive means
//!   with t-tests in sliding windows (p 0.001, window 50) was scored on the same corpus
//!   (`corpus/`): its t-test on segment means turns isolated spikes into change points (24
//!   on the spike-only series; Otava issue #150), and with a minimum segment of 5 added it
//!   still reports some part-way through and finds fewer steps (F1 0.969 for steps of 5% or
//!   more and 0.930 for 3–5%, where this detector has 1.000 and 1.000). The table is in
//!   `docs/explanation/change-points.md`, generated from the corpus by its test.
//!
//! **Incremental.** The cost of the best segmentation of the first t points depends on those
//! points and the penalty only, so appending a point extends the dynamic programme by one step
//! ([`Incremental`]). The penalty depends on σ, which every point moves a little: σ is rounded
//! to 1/16 of an octave (±2%) so that it holds still, and when the rounded value does move the
//! programme is rerun from the start. Batch and incremental run the same steps in the same
//! order, so they agree bit for bit on every prefix.

use nbody_engine::stats::median;
use std::cmp::{Ordering, Reverse};
use std::collections::{BinaryHeap, VecDeque};
use thiserror::Error;

/// The default minimum segment length, in points: see the module documentation.
pub const MIN_SEGMENT: usize = 5;

/// The default penalty per change point, in units of one point's noise σ (log space): the
/// smallest of 6, 8, 10, 12, 14, 17 and 20 with no false change point on the corpus (below, a
/// few appear; above, steps are reported later and, at 20, some 3–5% ones missed).
pub const PENALTY: f64 = 12.0;

/// The smallest noise taken for σ (log units, 0.1%): a run of identical values (a timer's
/// grain) would otherwise make every change of a last digit a step.
const MIN_SCALE: f64 = 1e-3;

/// σ is rounded to this many steps per octave before it sets the penalty.
const SCALE_STEPS_PER_OCTAVE: f64 = 16.0;

/// The median of |x₂ − x₁| for independent normal x of σ = 1: Φ⁻¹(3/4)·√2.
const MEDIAN_ABS_DIFF: f64 = 0.953_872_552_408_939_8;

/// The mean of |x₂ − x₁| for independent normal x of σ = 1: 2/√π.
const MEAN_ABS_DIFF: f64 = std::f64::consts::FRAC_2_SQRT_PI;

/// The standard error of the median of n normal values is this × σ/√n (for large n): √(π/2).
pub(crate) const MEDIAN_SE: f64 = 1.253_314_137_315_500_1;

/// The two-sided 95% quantile of the standard normal.
pub(crate) const Z95: f64 = 1.959_963_984_540_054;

/// Why a series or a detector is refused.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum ChangeError {
    /// A value of the series is zero, negative, NaN or infinite: change points need times.
    #[error(
        "point {index} of the series is {value}: change points compare times by their ratio, \
         so every value must be positive and finite"
    )]
    NotATime {
        /// Position of the point in the series, from 0.
        index: usize,
        /// The value.
        value: f64,
    },
    /// A minimum segment below 3 points was asked for.
    #[error("a minimum segment of {0} points lets a spike become a change point: give at least 3")]
    ShortSegment(usize),
    /// A penalty that is not positive and finite was asked for.
    #[error("the penalty per change point must be positive and finite, not {0}")]
    Penalty(f64),
}

/// How change points are found: the shortest segment and the penalty per change point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detector {
    min_segment: usize,
    penalty: f64,
}

impl Default for Detector {
    fn default() -> Self {
        Detector {
            min_segment: MIN_SEGMENT,
            penalty: PENALTY,
        }
    }
}

impl Detector {
    /// A detector whose segments hold at least `min_segment` points (3 or more, so that one
    /// spike cannot make a change point) and whose change points each cost `penalty` × σ.
    pub fn new(min_segment: usize, penalty: f64) -> Result<Self, ChangeError> {
        if min_segment < 3 {
            return Err(ChangeError::ShortSegment(min_segment));
        }
        if !(penalty.is_finite() && penalty > 0.0) {
            return Err(ChangeError::Penalty(penalty));
        }
        Ok(Detector {
            min_segment,
            penalty,
        })
    }

    /// The shortest segment, in points (at least 3).
    pub fn min_segment(&self) -> usize {
        self.min_segment
    }

    /// The cost of one change point, in units of the series' noise σ (log space).
    pub fn penalty(&self) -> f64 {
        self.penalty
    }
}

/// One step of a series.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Change {
    /// The first point of the new level: the step happened between the commits of points
    /// `index - 1` and `index` ([`Change::between`]).
    pub index: usize,
    /// The level of the whole segment before (from the previous change point or the start):
    /// the median of its values, which a spike inside it barely moves.
    pub before: f64,
    /// The level of the whole segment after (to the next change point or the end).
    pub after: f64,
    /// `after / before`: above 1 the series got slower (for times), below 1 faster.
    pub ratio: f64,
    /// The 95% interval of the ratio, from the noise σ of the series and the two segments'
    /// lengths (a median of n points has a standard error of about 1.25 σ/√n). It narrows as
    /// the new level collects points.
    pub ratio_ci95: [f64; 2],
}

impl Change {
    /// The indices of the two points, hence the two commits, the step happened between: the
    /// last of the old level and the first of the new.
    pub fn between(&self) -> [usize; 2] {
        [self.index.saturating_sub(1), self.index]
    }
}

/// The change points of `values` (times, in commit order), oldest first.
pub fn change_points(values: &[f64], d: &Detector) -> Result<Vec<Change>, ChangeError> {
    let logs = values
        .iter()
        .enumerate()
        .map(|(index, &value)| log_of(index, value))
        .collect::<Result<Vec<f64>, ChangeError>>()?;
    let scale = scale_of(&logs);
    let mut fit = Fit::new(d, rounded(scale));
    while fit.points() < logs.len() {
        fit.advance(&logs);
    }
    Ok(describe(&logs, &fit.starts(), scale))
}

/// Change points kept up to date as a series grows one point at a time; after every push,
/// [`Incremental::changes`] equals [`change_points`] of the points pushed so far, bit for bit.
/// A push costs one step of the dynamic programme (about the points since the last change
/// point), or a rerun when the rounded noise level moves.
#[derive(Clone, Debug)]
pub struct Incremental {
    detector: Detector,
    logs: Vec<f64>,
    fit: Fit,
}

impl Incremental {
    /// An empty series judged by `detector`.
    pub fn new(detector: Detector) -> Self {
        Incremental {
            detector,
            logs: Vec::new(),
            fit: Fit::new(&detector, rounded(MIN_SCALE)),
        }
    }

    /// Appends the next commit's value; a value that is not a time is refused and the series
    /// left as it was.
    pub fn push(&mut self, value: f64) -> Result<(), ChangeError> {
        self.logs.push(log_of(self.logs.len(), value)?);
        let scale = rounded(scale_of(&self.logs));
        if scale.to_bits() != self.fit.scale.to_bits() {
            self.fit = Fit::new(&self.detector, scale);
        }
        while self.fit.points() < self.logs.len() {
            self.fit.advance(&self.logs);
        }
        Ok(())
    }

    /// The change points of the series so far, oldest first.
    pub fn changes(&self) -> Vec<Change> {
        describe(&self.logs, &self.fit.starts(), scale_of(&self.logs))
    }

    /// Points pushed so far.
    pub fn len(&self) -> usize {
        self.logs.len()
    }

    /// Whether no point has been pushed.
    pub fn is_empty(&self) -> bool {
        self.logs.is_empty()
    }
}

pub(crate) fn log_of(index: usize, value: f64) -> Result<f64, ChangeError> {
    if value.is_finite() && value > 0.0 {
        Ok(value.ln())
    } else {
        Err(ChangeError::NotATime { index, value })
    }
}

/// The noise σ of one point (log units) from the consecutive differences: their median over
/// its value for normal noise; their mean when more than half are zero (a coarse timer);
/// never below [`MIN_SCALE`]. A step makes one large difference, a spike two: the median
/// ignores both.
pub(crate) fn scale_of(logs: &[f64]) -> f64 {
    let diffs: Vec<f64> = logs.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
    let Some(mid) = median(&diffs) else {
        return MIN_SCALE;
    };
    let sigma = if mid > 0.0 {
        mid / MEDIAN_ABS_DIFF
    } else {
        diffs.iter().sum::<f64>() / diffs.len() as f64 / MEAN_ABS_DIFF
    };
    sigma.max(MIN_SCALE)
}

/// σ rounded to the nearest 1/16 octave, the value the penalty is made from.
pub(crate) fn rounded(scale: f64) -> f64 {
    ((scale.log2() * SCALE_STEPS_PER_OCTAVE).round() / SCALE_STEPS_PER_OCTAVE).exp2()
}

/// A growing set of values and its L1 cost, the sum of absolute deviations from its median:
/// the lower half in a max-heap, the upper half in a min-heap, and the sum of each, so that an
/// insertion costs O(log n) (the cost is the upper sum minus the lower, plus the middle value
/// when the count is odd, which the lower half holds).
#[derive(Default)]
pub(crate) struct Halves {
    lower: BinaryHeap<Key>,
    upper: BinaryHeap<Reverse<Key>>,
    lower_sum: f64,
    upper_sum: f64,
}

impl Halves {
    pub(crate) fn insert(&mut self, v: f64) {
        if self.lower.peek().is_none_or(|m| v <= m.0) {
            self.lower.push(Key(v));
            self.lower_sum += v;
        } else {
            self.upper.push(Reverse(Key(v)));
            self.upper_sum += v;
        }
        if self.lower.len() > self.upper.len() + 1 {
            if let Some(Key(m)) = self.lower.pop() {
                self.lower_sum -= m;
                self.upper.push(Reverse(Key(m)));
                self.upper_sum += m;
            }
        } else if self.upper.len() > self.lower.len()
            && let Some(Reverse(Key(m))) = self.upper.pop()
        {
            self.upper_sum -= m;
            self.lower.push(Key(m));
            self.lower_sum += m;
        }
    }

    pub(crate) fn cost(&self) -> f64 {
        let middle = match self.lower.peek() {
            Some(m) if self.lower.len() > self.upper.len() => m.0,
            _ => 0.0,
        };
        self.upper_sum - self.lower_sum + middle
    }
}

/// A value ordered by `total_cmp`, for the heaps (the logarithms of times are never NaN).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Key(f64);

impl Eq for Key {}

impl PartialOrd for Key {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Key {
    fn cmp(&self, other: &Self) -> Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// The dynamic programme of PELT under the L1 cost with a minimum segment length.
#[derive(Clone, Debug)]
struct Fit {
    min_segment: usize,
    /// The rounded σ the penalty was made from.
    scale: f64,
    penalty: f64,
    /// `best[t]`: the cost of the best segmentation of the first t points (infinite when none
    /// exists: 0 < t < min_segment); `best[0]` is `-penalty`, so a segmentation costs its
    /// segments plus a penalty per change point.
    best: Vec<f64>,
    /// `last[t]`: where the last segment of that segmentation starts.
    last: Vec<usize>,
    /// The starts a last segment may still have, ascending (PELT's pruned set).
    candidates: Vec<usize>,
    /// Starts found dominated: `(t, s)` drops s once segments may start at the point t that
    /// dominated it, min_segment points after t.
    doomed: VecDeque<(usize, usize)>,
    marked: Vec<bool>,
}

impl Fit {
    fn new(d: &Detector, scale: f64) -> Self {
        let penalty = d.penalty * scale;
        Fit {
            min_segment: d.min_segment,
            scale,
            penalty,
            best: vec![-penalty],
            last: vec![0],
            candidates: vec![0],
            doomed: VecDeque::new(),
            marked: vec![false],
        }
    }

    /// How many points the programme has taken.
    fn points(&self) -> usize {
        self.best.len() - 1
    }

    /// Takes the next point of `logs` (which holds at least `points() + 1`).
    fn advance(&mut self, logs: &[f64]) {
        let t = self.best.len();
        let m = self.min_segment;
        let mut dropped = Vec::new();
        while let Some(&(at, s)) = self.doomed.front() {
            if at > t {
                break;
            }
            self.doomed.pop_front();
            dropped.push(s);
        }
        if !dropped.is_empty() {
            self.candidates.retain(|s| !dropped.contains(s));
        }
        // The last segment x[s..t], for each candidate s from the latest back, in one set that
        // grows leftwards; values relative to the first point, for the sums' precision.
        let mut segment = Halves::default();
        let mut from = t;
        let mut costs: Vec<(usize, f64)> = Vec::new();
        let (mut best, mut start) = (f64::INFINITY, 0);
        for &s in self.candidates.iter().rev() {
            if t - s < m {
                continue;
            }
            while from > s {
                from -= 1;
                segment.insert(logs[from] - logs[0]);
            }
            let cost = segment.cost();
            costs.push((s, cost));
            let total = self.best[s] + cost + self.penalty;
            // Strictly less: of two equal costs (the L1 cost is piecewise linear, so boundaries
            // can tie), the later start, tried first, is kept.
            if total < best {
                best = total;
                start = s;
            }
        }
        self.best.push(best);
        self.last.push(start);
        self.marked.push(false);
        if best.is_finite() {
            // PELT's pruning (the L1 cost of a segment is at least that of its two halves):
            // a start whose segment to t already costs more than the best segmentation of the
            // first t points never starts a best last segment once t itself may.
            for (s, cost) in costs {
                if !self.marked[s] && self.best[s] + cost > best {
                    self.marked[s] = true;
                    self.doomed.push_back((t + m, s));
                }
            }
            self.candidates.push(t);
        }
    }

    /// The starts of the segments after the first: the change points' indices, ascending.
    fn starts(&self) -> Vec<usize> {
        let n = self.points();
        let mut out = Vec::new();
        if n == 0 || !self.best[n].is_finite() {
            return out;
        }
        let mut s = self.last[n];
        while s > 0 {
            out.push(s);
            s = self.last[s];
        }
        out.reverse();
        out
    }
}

/// Each change point with its segments' levels and ratio (`scale`: σ, unrounded).
pub(crate) fn describe(logs: &[f64], starts: &[usize], scale: f64) -> Vec<Change> {
    let mut bounds = Vec::with_capacity(starts.len() + 2);
    bounds.push(0);
    bounds.extend_from_slice(starts);
    bounds.push(logs.len());
    let levels: Vec<f64> = bounds
        .windows(2)
        .map(|w| median(&logs[w[0]..w[1]]).unwrap_or(f64::NAN))
        .collect();
    (1..bounds.len() - 1)
        .map(|i| {
            let (n_before, n_after) = (bounds[i] - bounds[i - 1], bounds[i + 1] - bounds[i]);
            let se = MEDIAN_SE * scale * (1.0 / n_before as f64 + 1.0 / n_after as f64).sqrt();
            change_of(bounds[i], [levels[i - 1], levels[i]], se)
        })
        .collect()
}

/// The change at `index` from the level `logs[0]` to `logs[1]` (logarithms), the log ratio's
/// standard error being `se`.
pub(crate) fn change_of(index: usize, logs: [f64; 2], se: f64) -> Change {
    let step = logs[1] - logs[0];
    Change {
        index,
        before: logs[0].exp(),
        after: logs[1].exp(),
        ratio: step.exp(),
        ratio_ci95: [(step - Z95 * se).exp(), (step + Z95 * se).exp()],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_distr::StandardNormal;
    use rand_pcg::Pcg64Mcg;

    /// `n` points of level 1 with log-normal noise of σ 1%, times `ratio` from `step` on.
    fn stepped(seed: u64, n: usize, step: usize, ratio: f64) -> Vec<f64> {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        (0..n)
            .map(|i| {
                let z: f64 = rng.sample(StandardNormal);
                let level = if i >= step { ratio } else { 1.0 };
                level * (0.01 * z).exp()
            })
            .collect()
    }

    fn bits(changes: &[Change]) -> Vec<[u64; 6]> {
        changes
            .iter()
            .map(|c| {
                [
                    c.index as u64,
                    c.before.to_bits(),
                    c.after.to_bits(),
                    c.ratio.to_bits(),
                    c.ratio_ci95[0].to_bits(),
                    c.ratio_ci95[1].to_bits(),
                ]
            })
            .collect()
    }

    #[test]
    fn a_step_is_found_where_it_is_with_its_size() {
        let values = stepped(7, 60, 30, 1.08);
        let changes = change_points(&values, &Detector::default()).unwrap();
        assert_eq!(changes.len(), 1, "{changes:?}");
        let c = changes[0];
        assert_eq!((c.index, c.between()), (30, [29, 30]));
        assert!((c.ratio - 1.08).abs() < 0.01, "{c:?}");
        assert!(c.ratio_ci95[0] < 1.08 && 1.08 < c.ratio_ci95[1], "{c:?}");
        assert!((c.after / c.before - c.ratio).abs() < 1e-12);
        assert!((c.before - 1.0).abs() < 0.01, "{c:?}");
    }

    #[test]
    fn no_spike_is_a_change_point_wherever_it_falls() {
        let d = Detector::default();
        for at in 0..40 {
            for spike in [0.3, 3.0, 100.0] {
                let mut values = stepped(at as u64, 40, 40, 1.0);
                values[at] *= spike;
                let mut inc = Incremental::new(d);
                for (i, &v) in values.iter().enumerate() {
                    inc.push(v).unwrap();
                    assert!(
                        inc.changes().is_empty(),
                        "spike ×{spike} at {at}, {} points: {:?}",
                        i + 1,
                        inc.changes()
                    );
                }
            }
        }
    }

    #[test]
    fn short_flat_and_constant_series_have_no_change_point() {
        let d = Detector::default();
        assert!(change_points(&[], &d).unwrap().is_empty());
        assert!(change_points(&[1.0; 9], &d).unwrap().is_empty());
        assert!(change_points(&[2.5; 200], &d).unwrap().is_empty());
        // A coarse timer: most consecutive values equal, a last digit flickering.
        let grain: Vec<f64> = (0..80)
            .map(|i| if i % 7 == 3 { 13.0 } else { 12.0 })
            .collect();
        assert!(change_points(&grain, &d).unwrap().is_empty());
        // Too short for two segments of the minimum length, however large the step.
        let mut short = vec![1.0; 5];
        short.extend([2.0; 4]);
        assert!(change_points(&short, &d).unwrap().is_empty());
    }

    #[test]
    fn values_that_are_not_times_and_bad_detectors_are_refused() {
        let d = Detector::default();
        let err = change_points(&[1.0, 0.0, 1.0], &d).unwrap_err();
        assert_eq!(
            err,
            ChangeError::NotATime {
                index: 1,
                value: 0.0
            }
        );
        assert!(change_points(&[1.0, f64::NAN], &d).is_err());
        let mut inc = Incremental::new(d);
        inc.push(1.0).unwrap();
        assert!(inc.push(-1.0).is_err());
        assert_eq!(inc.len(), 1, "a refused value is not kept");
        assert_eq!(Detector::new(2, 12.0), Err(ChangeError::ShortSegment(2)));
        assert!(Detector::new(5, 0.0).is_err());
        assert!(Detector::new(5, f64::INFINITY).is_err());
        assert!(err.to_string().contains("positive and finite"));
    }

    /// The pruned programme finds a segmentation as good as the best of all of them (optimal
    /// partitioning without pruning, each segment's cost from its sorted values).
    #[test]
    fn pruning_loses_nothing_against_every_segmentation() {
        let mut rng = Pcg64Mcg::seed_from_u64(11);
        for series in 0..200 {
            let n = rng.random_range(10..70);
            let mut level = 0.0;
            let values: Vec<f64> = (0..n)
                .map(|_| {
                    if rng.random_bool(0.08) {
                        level += rng.random_range(-0.1..0.1);
                    }
                    let z: f64 = rng.sample(StandardNormal);
                    (level + 0.01 * z).exp()
                })
                .collect();
            let logs: Vec<f64> = values.iter().map(|v| v.ln()).collect();
            let m = 3 + series % 4;
            let d = Detector::new(m, 4.0 + (series % 5) as f64 * 3.0).unwrap();
            let penalty = d.penalty * rounded(scale_of(&logs));
            let cost = |s: usize, t: usize| {
                let mut v = logs[s..t].to_vec();
                v.sort_by(f64::total_cmp);
                let mid = v[v.len() / 2];
                v.iter().map(|x| (x - mid).abs()).sum::<f64>()
            };
            let mut best = vec![f64::INFINITY; n + 1];
            let mut last = vec![0; n + 1];
            best[0] = -penalty;
            for t in m..=n {
                for s in (0..=t - m).filter(|&s| s == 0 || s >= m) {
                    let total = best[s] + cost(s, t) + penalty;
                    if total < best[t] {
                        (best[t], last[t]) = (total, s);
                    }
                }
            }
            let mut want = Vec::new();
            let mut s = last[n];
            while s > 0 {
                want.push(s);
                s = last[s];
            }
            want.reverse();
            let got: Vec<usize> = change_points(&values, &d)
                .unwrap()
                .iter()
                .map(|c| c.index)
                .collect();
            let total = |starts: &[usize]| {
                let mut b = vec![0];
                b.extend_from_slice(starts);
                b.push(n);
                b.windows(2)
                    .map(|w| cost(w[0], w[1]) + penalty)
                    .sum::<f64>()
            };
            // The L1 cost is piecewise linear: two boundaries can cost exactly the same, and
            // each search breaks ties its own way. The cost is what must agree.
            let (have, best) = (total(&got), total(&want));
            assert!(
                have <= best + 1e-12,
                "series {series}, min segment {m}: {got:?} costs {have}, {want:?} {best}"
            );
        }
    }

    /// Random series of every shape the corpus has and more (several steps, spike bursts,
    /// a coarse grain, noise levels from 0.1% to 10%): after every push the incremental
    /// change points equal the batch ones of the prefix, bit for bit.
    #[test]
    fn incremental_equals_batch_bit_for_bit_after_every_push() {
        let mut rng = Pcg64Mcg::seed_from_u64(20261205);
        for series in 0..300 {
            let n = rng.random_range(1..160);
            let sigma = 10f64.powf(rng.random_range(-3.0..-1.0));
            let mut level = 1.0;
            let grain = series % 10 == 0;
            let values: Vec<f64> = (0..n)
                .map(|_| {
                    if rng.random_bool(0.04) {
                        level *= rng.random_range(0.7..1.4);
                    }
                    let z: f64 = rng.sample(StandardNormal);
                    let spike = if rng.random_bool(0.05) {
                        rng.random_range(1.0..3.0)
                    } else {
                        1.0
                    };
                    let v = level * (sigma * z).exp() * spike;
                    if grain {
                        ((v * 50.0).round() / 50.0).max(0.02)
                    } else {
                        v
                    }
                })
                .collect();
            let d = if series % 3 == 0 {
                Detector::new(3, 6.0).unwrap()
            } else {
                Detector::default()
            };
            let mut inc = Incremental::new(d);
            for (i, &v) in values.iter().enumerate() {
                inc.push(v).unwrap();
                let batch = change_points(&values[..=i], &d).unwrap();
                assert_eq!(
                    bits(&inc.changes()),
                    bits(&batch),
                    "series {series}, prefix {}",
                    i + 1
                );
            }
        }
    }
}
