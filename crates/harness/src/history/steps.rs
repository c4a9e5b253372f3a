//! The steps and drifts of a series as every reader of the history shows them: the model of
//! [`super::drifts`] (the change points of [`super::changes`] under the default detector,
//! and the drifts beside them), each step named by the two commits it fell between and each
//! drift by the first and last commit of its range. `history`, `publish` and its pull-request
//! summary all come here, so that they never disagree on what changed.
//!
//! **Where the steps are placed.** A normalised series is a case's time over the reference
//! workload's, the control timed before each sample ([`Point::control`]). Dividing by the
//! control removes what the machine did (a slower runner, a noisy neighbour) but adds the
//! control's own noise, and on a machine whose control holds still that noise is all it adds:
//! it has moved a real step by a commit. So the segmentation is found on the raw seconds when
//! the class's control series has neither a step nor a drift, on the normalised series when it
//! moves; either way the steps' and drifts' levels and sizes are read from the series' own
//! values (its metric), cut where the segmentation cut.

use super::changes::ChangeError;
use super::drifts::{Model, Segment, describe_segments, segments, shape};
use super::series::{Metric, Point, Series};
use serde::Serialize;

/// One step of a series, between two of its commits.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Step {
    /// The index in the series of the first point of the new level.
    #[serde(skip)]
    pub index: usize,
    /// The last commit of the old level and the first of the new.
    pub between: [String; 2],
    /// The levels of the whole segments before and after, in the series' metric (beside a
    /// drift, the drift's fitted value where it meets the step).
    pub before: f64,
    /// The level after, likewise.
    pub after: f64,
    /// `after / before` and its 95% interval.
    pub ratio: f64,
    /// The 95% interval of the ratio, from the series' noise and the two segments' lengths.
    pub ratio_ci95: [f64; 2],
}

/// One drift of a series: a steady trend over a range of its commits.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Drift {
    /// The index in the series of the range's first point.
    #[serde(skip)]
    pub start: usize,
    /// The index in the series of the range's last point.
    #[serde(skip)]
    pub end: usize,
    /// The first and the last commit of the range.
    pub range: [String; 2],
    /// The fitted trend's value at the first commit, in the series' metric.
    pub from: f64,
    /// The fitted trend's value at the last commit.
    pub to: f64,
    /// `to / from`: the whole drift, above 1 slower.
    pub ratio: f64,
    /// The 95% interval of the ratio (Sen's interval of the trend's slope).
    pub ratio_ci95: [f64; 2],
    /// The ratio per commit of the range: `ratio` is this to the power of the commits
    /// between its first and last.
    pub per_commit: f64,
    /// The 95% interval of the ratio per commit.
    pub per_commit_ci95: [f64; 2],
}

impl Drift {
    /// The drift as `history` and the page write it, its first and last commit named
    /// `first` and `last`: `drift from A to B: +X% [lo%, hi%] (+r% per commit)`.
    pub fn text(&self, first: &str, last: &str) -> String {
        let pct = |r: f64| 100.0 * (r - 1.0);
        format!(
            "drift from {first} to {last}: {:+.1}% [{:+.1}%, {:+.1}%] ({:+.2}% per commit)",
            pct(self.ratio),
            pct(self.ratio_ci95[0]),
            pct(self.ratio_ci95[1]),
            pct(self.per_commit)
        )
    }
}

/// What changed in a series: its steps and its drifts, each oldest first.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Changes {
    /// The steps.
    pub steps: Vec<Step>,
    /// The drifts.
    pub drifts: Vec<Drift>,
}

/// The steps of `s`, oldest first (those of [`changes`]).
pub fn steps(s: &Series) -> Result<Vec<Step>, ChangeError> {
    Ok(changes(s)?.steps)
}

/// The steps and drifts of `s`, found by the default model on the series [`placement`] picks.
pub fn changes(s: &Series) -> Result<Changes, ChangeError> {
    let values: Vec<f64> = s.points.iter().map(|p| p.value).collect();
    let model = Model::default();
    let cut: Vec<Segment> = segments(placement(s, &model).as_deref().unwrap_or(&values), &model)?;
    let found = describe_segments(&values, &cut)?;
    let commit = |i: usize| s.points[i].commit.clone();
    Ok(Changes {
        steps: found
            .changes
            .into_iter()
            .map(|c| {
                let [a, b] = c.between();
                Step {
                    index: c.index,
                    between: [commit(a), commit(b)],
                    before: c.before,
                    after: c.after,
                    ratio: c.ratio,
                    ratio_ci95: c.ratio_ci95,
                }
            })
            .collect(),
        drifts: found
            .drifts
            .into_iter()
            .map(|d| Drift {
                start: d.start,
                end: d.end,
                range: [commit(d.start), commit(d.end)],
                from: d.from,
                to: d.to,
                ratio: d.ratio,
                ratio_ci95: d.ratio_ci95,
                per_commit: d.per_point,
                per_commit_ci95: d.per_point_ci95,
            })
            .collect(),
    })
}

/// The raw seconds of a normalised series whose control is flat (no step, no drift under
/// `model`), which the segmentation is then found on; `None` to find it on the series itself:
/// a series in seconds already, a point without a control, or a control that moves.
pub fn placement(s: &Series, model: &Model) -> Option<Vec<f64>> {
    if s.metric != Metric::Normalized {
        return None;
    }
    let control: Vec<f64> = s.points.iter().map(|p| p.control).collect::<Option<_>>()?;
    let moved =
        shape(&control, model).map_or(true, |c| !c.changes.is_empty() || !c.drifts.is_empty());
    if moved {
        return None;
    }
    let raw: Vec<f64> = s.points.iter().map(|p: &Point| p.seconds).collect();
    raw.iter().all(|v| v.is_finite() && *v > 0.0).then_some(raw)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::history::changes::{Detector, change_points};
    use crate::history::series::series;
    use crate::history::store::{Normalized, Record};

    /// Commit `i` of a case: `raw` seconds per step, the reference workload `control` seconds.
    fn record(case: &str, i: usize, raw: f64, control: Option<f64>) -> Record {
        let mut r = crate::history::store::tests::record(case, &format!("c{i:02}"), raw);
        r.commit_date = Some(format!("2026-11-{:02}T10:00:00Z", i % 28 + 1));
        r.measured = format!("2026-12-{:02}T10:00:00Z", i % 28 + 1);
        if i >= 28 {
            r.commit_date = Some(format!("2026-12-{:02}T10:00:00Z", i - 27));
        }
        r.normalized = control.map(|c| Normalized {
            median: raw / c,
            ci95: [0.99 * raw / c, 1.01 * raw / c],
        });
        r
    }

    /// Deterministic noise of about `size` (relative), different at every commit.
    fn wobble(i: usize, size: f64) -> f64 {
        1.0 + size * (((i * 37 + 11) % 17) as f64 / 8.0 - 1.0)
    }

    #[test]
    fn a_step_is_named_by_the_commits_around_it() {
        let records: Vec<_> = (0..12)
            .map(|i| {
                let level = if i < 6 { 1.0 } else { 1.3 };
                record(
                    "lj-box/naive/n=1000",
                    i,
                    1e-3 * level * wobble(i, 0.002),
                    None,
                )
            })
            .collect();
        let found = steps(&series(&records)[0]).unwrap();
        assert_eq!(found.len(), 1);
        assert_eq!(found[0].between, ["c05".to_string(), "c06".to_string()]);
        assert_eq!(found[0].index, 6);
        assert!((found[0].ratio - 1.3).abs() < 0.01, "{}", found[0].ratio);
    }

    #[test]
    fn a_drift_reads_with_its_range_size_interval_and_rate() {
        let d = Drift {
            start: 3,
            end: 43,
            range: ["c03".into(), "c43".into()],
            from: 1.0,
            to: 1.083,
            ratio: 1.083,
            ratio_ci95: [1.061, 1.105],
            per_commit: 1.002,
            per_commit_ci95: [1.0015, 1.0025],
        };
        assert_eq!(
            d.text("c03", "c43"),
            "drift from c03 to c43: +8.3% [+6.1%, +10.5%] (+0.20% per commit)"
        );
        let json = serde_json::to_value(&d).unwrap();
        assert_eq!(json["range"], serde_json::json!(["c03", "c43"]));
        assert_eq!(json["per_commit"], 1.002);
        assert!(
            json.get("start").is_none(),
            "indices stay out of JSON: {json}"
        );
    }

    #[test]
    fn a_drift_is_named_by_the_first_and_last_commits_of_its_range() {
        // Flat to c14, +0.4% per commit from c15 to c39, flat after.
        let records: Vec<_> = (0..55)
            .map(|i| {
                let trend = 1.004f64.powi(i.clamp(15, 39) as i32 - 15);
                record("k", i, 1e-3 * trend * wobble(i, 0.004), None)
            })
            .collect();
        let found = changes(&series(&records)[0]).unwrap();
        assert!(found.steps.is_empty(), "{found:?}");
        assert_eq!(found.drifts.len(), 1, "{found:?}");
        let d = &found.drifts[0];
        assert!(
            d.start.abs_diff(15) <= 3 && d.end.abs_diff(39) <= 3,
            "{d:?}"
        );
        assert_eq!(
            d.range,
            [format!("c{:02}", d.start), format!("c{:02}", d.end)]
        );
        assert!((d.ratio - 1.004f64.powi(24)).abs() < 0.02, "{d:?}");
        assert!((d.per_commit - 1.004).abs() < 0.0008, "{d:?}");
    }

    /// The control flat and noisy (a 9% dip at c11 besides), the raw series a clean 10% step
    /// at c12: divided by the control, the step sits a commit early; on the raw series, on
    /// its commit.
    #[test]
    fn with_a_flat_control_the_step_is_placed_on_the_raw_series() {
        let control = |i: usize| 0.02 * wobble(i * 3, 0.01) * if i == 11 { 0.91 } else { 1.0 };
        let raw = |i: usize| 1e-3 * wobble(i, 0.001) * if i >= 12 { 1.1 } else { 1.0 };
        let mut records: Vec<Record> = (0..24)
            .map(|i| record("k", i, raw(i), Some(control(i))))
            .collect();
        // Another case of the config, timed against the same reference.
        records
            .extend((0..24).map(|i| record("other", i, 2e-3 * wobble(i, 0.003), Some(control(i)))));
        let s = &series(&records)[0];
        assert_eq!((s.case.as_str(), s.metric), ("k", Metric::Normalized));
        // The premise: the normalised series alone puts the step a commit early.
        let normalised: Vec<f64> = s.points.iter().map(|p| p.value).collect();
        let alone = change_points(&normalised, &Detector::default()).unwrap();
        assert_eq!(alone.iter().map(|c| c.index).collect::<Vec<_>>(), [11]);
        assert!(placement(s, &Model::default()).is_some());
        let found = steps(s).unwrap();
        assert_eq!(found.len(), 1, "{found:?}");
        assert_eq!(found[0].between, ["c11".to_string(), "c12".to_string()]);
        // Its size is still the normalised series' (× the reference).
        assert!((found[0].before - 1e-3 / 0.02).abs() < 0.003, "{found:?}");
    }

    /// The machine got 20% slower at c18 (its control with it) and the code 10% slower at
    /// c8: the control moves, so the normalised series is kept, which shows the code's step
    /// only.
    #[test]
    fn with_a_moving_control_the_normalised_series_is_kept() {
        let machine = |i: usize| if i >= 18 { 1.2 } else { 1.0 };
        let control = |i: usize| 0.02 * machine(i) * wobble(i * 3, 0.002);
        let raw = |i: usize| 1e-3 * machine(i) * wobble(i, 0.002) * if i >= 8 { 1.1 } else { 1.0 };
        let records: Vec<Record> = (0..28)
            .map(|i| record("k", i, raw(i), Some(control(i))))
            .collect();
        let s = &series(&records)[0];
        assert!(placement(s, &Model::default()).is_none());
        let found = steps(s).unwrap();
        assert_eq!(found.len(), 1, "{found:?}");
        assert_eq!(found[0].between, ["c07".to_string(), "c08".to_string()]);
    }
}
