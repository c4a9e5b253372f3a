//! Steps and drifts: a change-point model whose segments are either level (the series holds a
//! value, as in [`super::changes`]) or sloped (a drift: the logarithm of the series moves by
//! the same amount at every commit over a range of commits, as a slow leak or a growing cache
//! footprint makes it). A drift rising 0.2% per commit for 40 commits is one drift of +8%, not
//! a step of +5% at an arbitrary commit nor a staircase of two or three steps.
//!
//! **Method.** The same penalised segmentation of the logarithms as the steps, with a second
//! kind of segment: exact optimal partitioning where a level segment costs the sum of its
//! points' absolute deviations from its median (as in `changes.rs`), a drift segment the sum
//! of their absolute deviations from a straight line plus a slope penalty of
//! `slope_penalty × σ`, and every boundary the change-point penalty `penalty × σ`; σ, the
//! penalties and the minimum level segment are the step detector's. What each choice is for:
//!
//! - *L1 for both kinds*: a drift segment and a level segment are compared on one scale, the
//!   likelihood of Laplace noise, so the better of the two fits wins by what it explains and a
//!   spike costs either its distance to the fit, never the square of it. An L2 cost on logs
//!   would let one spike tilt a line (and buy a level segment), the failure the step detector
//!   chose medians to avoid.
//! - *A robust line*: each candidate segment is fitted by the median of the slopes between
//!   points half the segment apart and the median of what remains (linear time, so the
//!   programme stays cubic in the points at worst); it is not the least-absolute-deviations
//!   line, so a drift's cost is an upper bound and a slope is never cheaper than it should be.
//!   A reported drift is then described by Theil–Sen with Sen's distribution-free interval
//!   ([`super::trend`]).
//! - *The slope penalty*: fitting a slope to noise always lowers the L1 cost a little (by
//!   about 0.4σ times a χ²₁ variable for normal noise). A drift inside a series already pays
//!   two boundaries (2 × 12σ) besides its slope, which is what keeps noise from buying one
//!   part-way; the slope penalty guards the drift over a whole series (no boundary) and the
//!   drift that replaces a single step. 4σ was chosen on the corpus (`corpus/`): at 2σ, false
//!   drifts on flat and spike-only series; at 5σ and above, some 5% drifts over 20–45 commits
//!   were reported as one or two steps (the staircase is cheaper than a drift that pays three
//!   penalties).
//! - *A minimum drift of 10 points*: a slope over fewer commits cannot be told from a step
//!   with a few outliers, and its interval would be wide.
//! - *Steps beside a drift*: a boundary between two level segments is a step, as in
//!   `changes.rs`. A boundary at a drift's end is a step only when the two fits, extrapolated
//!   to the middle of the two commits, differ by more than [`JUMP_Z`] standard errors and
//!   [`MIN_JUMP`] σ; below that it is only where the segmentation ended the ramp.
//!
//! When the best segmentation has no drift, the steps are exactly those of
//! [`super::changes::change_points`]: the model only ever adds drifts and the steps beside
//! them, it never moves a step of a series without drifts.
//!
//! **Cost.** No pruning (a drift's quick fit is not additive over halves, which PELT needs):
//! O(n³) for n points, about 1 ms for 120 points; the histories are tens of commits long.

use super::changes::{
    Change, ChangeError, Detector, Halves, MEDIAN_SE, change_of, change_points, describe, log_of,
    rounded, scale_of,
};
use super::trend::{quick_l1_cost, theil_sen};
use nbody_engine::stats::median;

/// The default slope penalty, in units of one point's noise σ: see the module documentation.
pub const SLOPE_PENALTY: f64 = 4.0;

/// The default shortest drift, in points.
pub const MIN_DRIFT: usize = 10;

/// A boundary at a drift's end is a step when the two fits differ there by more than this many
/// standard errors (two-sided p ≈ 6 × 10⁻⁵: a history has many drift ends, and a step
/// reported at every tenth would be a step inside a drift)...
pub const JUMP_Z: f64 = 4.0;

/// ...and by at least this many σ (one point's noise): the segmentation puts a drift's end
/// where it lowers the cost most, so the fits there differ by more than their standard errors
/// say, and a jump of a σ or two is where the ramp was cut, not an event of its own. The step
/// detector's own smallest steps are about 3σ; the steps beside the corpus's drifts, 5σ or more.
pub const MIN_JUMP: f64 = 4.0;

/// How steps and drifts are found: the step detector, the slope penalty and the shortest drift.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Model {
    detector: Detector,
    slope_penalty: f64,
    min_drift: usize,
}

impl Default for Model {
    fn default() -> Self {
        Model {
            detector: Detector::default(),
            slope_penalty: SLOPE_PENALTY,
            min_drift: MIN_DRIFT,
        }
    }
}

impl Model {
    /// A model with `detector`'s penalty and minimum level segment, drifts of at least
    /// `min_drift` points (no fewer than the minimum segment, nor than 4) each costing
    /// `slope_penalty` × σ besides their boundaries.
    pub fn new(
        detector: Detector,
        slope_penalty: f64,
        min_drift: usize,
    ) -> Result<Self, ChangeError> {
        if min_drift < detector.min_segment().max(4) {
            return Err(ChangeError::ShortSegment(min_drift));
        }
        if !(slope_penalty.is_finite() && slope_penalty > 0.0) {
            return Err(ChangeError::Penalty(slope_penalty));
        }
        Ok(Model {
            detector,
            slope_penalty,
            min_drift,
        })
    }

    /// The step detector whose penalty and minimum segment the model shares.
    pub fn detector(&self) -> &Detector {
        &self.detector
    }

    /// The slope's penalty, in units of σ.
    pub fn slope_penalty(&self) -> f64 {
        self.slope_penalty
    }

    /// The shortest drift, in points.
    pub fn min_drift(&self) -> usize {
        self.min_drift
    }
}

/// What a segment of the model is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// The series holds a level (its median).
    Level,
    /// The series' logarithm follows a straight line.
    Drift,
}

/// One segment of a series: the points `start..end`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Segment {
    /// Its first point.
    pub start: usize,
    /// One past its last point.
    pub end: usize,
    /// Level or drift.
    pub kind: Kind,
}

/// One drift of a series: a straight line in log space over the points `start..=end`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drift {
    /// The first point of the range.
    pub start: usize,
    /// The last point of the range.
    pub end: usize,
    /// The fitted trend's value at the first point and at the last.
    pub from: f64,
    /// The fitted trend's value at the last point.
    pub to: f64,
    /// `to / from`: the whole drift's size, above 1 slower (for times).
    pub ratio: f64,
    /// The 95% interval of the ratio: Sen's interval of the slope over the range.
    pub ratio_ci95: [f64; 2],
    /// The ratio per commit (per point): `ratio` is this to the power `end - start`.
    pub per_point: f64,
    /// The 95% interval of the ratio per point.
    pub per_point_ci95: [f64; 2],
}

/// The steps and drifts of a series, each oldest first.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Shape {
    /// The steps, as [`super::changes`] describes them.
    pub changes: Vec<Change>,
    /// The drifts.
    pub drifts: Vec<Drift>,
}

/// The steps and drifts of `values` (times, in commit order).
pub fn shape(values: &[f64], model: &Model) -> Result<Shape, ChangeError> {
    let cut = segments(values, model)?;
    describe_segments(values, &cut)
}

/// The best segmentation of `values` into level and drift segments, in order; a series too
/// short for two level segments is one. When it has no drift, its boundaries are
/// [`change_points`]'s.
pub fn segments(values: &[f64], model: &Model) -> Result<Vec<Segment>, ChangeError> {
    let logs = logs(values)?;
    let n = logs.len();
    let scale = rounded(scale_of(&logs));
    let (boundary, slope) = (
        model.detector.penalty() * scale,
        model.slope_penalty * scale,
    );
    let (min_level, min_drift) = (model.detector.min_segment(), model.min_drift);
    let mut best = vec![f64::INFINITY; n + 1];
    best[0] = -boundary;
    let mut last = vec![(0, Kind::Level); n + 1];
    let mut scratch = Vec::new();
    for t in 1..=n {
        // The last segment x[s..t], for every s from the latest back, in one set that grows
        // leftwards; values relative to the first point, for the sums' precision.
        let mut level = Halves::default();
        let (mut b, mut arg) = (f64::INFINITY, (0, Kind::Level));
        for s in (0..t).rev() {
            level.insert(logs[s] - logs[0]);
            if !best[s].is_finite() {
                continue;
            }
            // Strictly less, levels first: of equal costs the later start and the level win.
            if t - s >= min_level {
                let total = best[s] + level.cost() + boundary;
                if total < b {
                    (b, arg) = (total, (s, Kind::Level));
                }
            }
            if t - s >= min_drift
                && let Some(cost) = quick_l1_cost(&logs[s..t], &mut scratch)
            {
                let total = best[s] + cost + slope + boundary;
                if total < b {
                    (b, arg) = (total, (s, Kind::Drift));
                }
            }
        }
        best[t] = b;
        last[t] = arg;
    }
    let mut out = Vec::new();
    if n > 0 && best[n].is_finite() {
        let mut t = n;
        while t > 0 {
            let (s, kind) = last[t];
            out.push(Segment {
                start: s,
                end: t,
                kind,
            });
            t = s;
        }
        out.reverse();
    }
    if out.iter().all(|s| s.kind == Kind::Level) {
        // The same optimum as the step detector's up to ties, which it breaks its own way:
        // its boundaries, so that a series without drifts has exactly its steps.
        let starts: Vec<usize> = change_points(values, &model.detector)?
            .iter()
            .map(|c| c.index)
            .collect();
        return Ok(levels(n, &starts));
    }
    Ok(out)
}

/// Level segments of `n` points cut at `starts`.
fn levels(n: usize, starts: &[usize]) -> Vec<Segment> {
    if n == 0 {
        return Vec::new();
    }
    let mut bounds = vec![0];
    bounds.extend_from_slice(starts);
    bounds.push(n);
    bounds
        .windows(2)
        .map(|w| Segment {
            start: w[0],
            end: w[1],
            kind: Kind::Level,
        })
        .collect()
}

/// The steps and drifts of `values` cut at `segments` (found on these values or on another
/// series of the same commits): each level's median, each drift's Theil–Sen line; the steps
/// between two levels, and at a drift's end where the two fits jump by more than
/// [`JUMP_Z`] standard errors.
pub fn describe_segments(values: &[f64], segments: &[Segment]) -> Result<Shape, ChangeError> {
    let logs = logs(values)?;
    let scale = scale_of(&logs);
    if segments.iter().all(|s| s.kind == Kind::Level) {
        let starts: Vec<usize> = segments.iter().skip(1).map(|s| s.start).collect();
        return Ok(Shape {
            changes: describe(&logs, &starts, scale),
            drifts: Vec::new(),
        });
    }
    let fits: Vec<Fitted> = segments
        .iter()
        .map(|s| Fitted::of(&logs[s.start..s.end], s.kind, scale))
        .collect();
    let mut shape = Shape::default();
    for (k, s) in segments.iter().enumerate() {
        if let Fitted::Line {
            line, slope_ci95, ..
        } = fits[k]
        {
            let span = (s.end - 1 - s.start) as f64;
            shape.drifts.push(Drift {
                start: s.start,
                end: s.end - 1,
                from: line.at(0.0).exp(),
                to: line.at(span).exp(),
                ratio: (line.slope * span).exp(),
                ratio_ci95: slope_ci95.map(|b| (b * span).exp()),
                per_point: line.slope.exp(),
                per_point_ci95: slope_ci95.map(f64::exp),
            });
        }
        if k == 0 {
            continue;
        }
        let (left, right) = (&fits[k - 1], &fits[k]);
        let n_left = (s.start - segments[k - 1].start) as f64;
        let (a, se_a) = left.at(n_left - 0.5);
        let (b, se_b) = right.at(-0.5);
        let se = (se_a * se_a + se_b * se_b).sqrt();
        let both_level = matches!((left, right), (Fitted::Level { .. }, Fitted::Level { .. }));
        if both_level || (b - a).abs() > (JUMP_Z * se).max(MIN_JUMP * scale) {
            shape.changes.push(change_of(s.start, [a, b], se));
        }
    }
    Ok(shape)
}

fn logs(values: &[f64]) -> Result<Vec<f64>, ChangeError> {
    values
        .iter()
        .enumerate()
        .map(|(index, &value)| log_of(index, value))
        .collect()
}

/// A segment's fit, with what its standard errors need.
enum Fitted {
    Level {
        level: f64,
        se: f64,
    },
    Line {
        line: super::trend::Line,
        slope_ci95: [f64; 2],
        points: f64,
        scale: f64,
    },
}

impl Fitted {
    fn of(x: &[f64], kind: Kind, scale: f64) -> Fitted {
        let level = || Fitted::Level {
            level: median(x).unwrap_or(f64::NAN),
            se: MEDIAN_SE * scale / (x.len() as f64).sqrt(),
        };
        match (kind, theil_sen(x)) {
            (Kind::Drift, Some(fit)) => Fitted::Line {
                line: fit.line,
                slope_ci95: fit.slope_ci95,
                points: x.len() as f64,
                scale,
            },
            _ => level(),
        }
    }

    /// The fit's value at position `u` of its segment, and its standard error: a median's
    /// (1.25σ/√n), or a fitted line's at `u` (σ √(1/m + (u − ū)²/Σ(i − ī)²), the least-squares
    /// one, which Theil–Sen's is close to under normal noise).
    fn at(&self, u: f64) -> (f64, f64) {
        match *self {
            Fitted::Level { level, se } => (level, se),
            Fitted::Line {
                line,
                points: m,
                scale,
                ..
            } => {
                let mean = (m - 1.0) / 2.0;
                let sxx = m * (m * m - 1.0) / 12.0;
                let se = scale * (1.0 / m + (u - mean).powi(2) / sxx).sqrt();
                (line.at(u), se)
            }
        }
    }
}

#[cfg(test)]
mod tests;
