//! The steps of a series as every reader of the history shows them: the change points of
//! [`super::changes`] under the default [`Detector`], each named by the two commits it fell
//! between. `history`, `publish` and its pull-request summary all come here, so that they
//! never disagree on what changed.

use super::changes::{ChangeError, Detector, change_points};
use super::series::Series;
use serde::Serialize;

/// One step of a series, between two of its commits.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Step {
    /// The index in the series of the first point of the new level.
    #[serde(skip)]
    pub index: usize,
    /// The last commit of the old level and the first of the new.
    pub between: [String; 2],
    /// The levels of the whole segments before and after, in the series' metric.
    pub before: f64,
    /// The level after, likewise.
    pub after: f64,
    /// `after / before` and its 95% interval.
    pub ratio: f64,
    /// The 95% interval of the ratio, from the series' noise and the two segments' lengths.
    pub ratio_ci95: [f64; 2],
}

/// The steps of `s`, oldest first, found by the default detector.
pub fn steps(s: &Series) -> Result<Vec<Step>, ChangeError> {
    let values: Vec<f64> = s.points.iter().map(|p| p.value).collect();
    Ok(change_points(&values, &Detector::default())?
        .into_iter()
        .map(|c| {
            let [a, b] = c.between();
            Step {
                index: c.index,
                between: [s.points[a].commit.clone(), s.points[b].commit.clone()],
                before: c.before,
                after: c.after,
                ratio: c.ratio,
                ratio_ci95: c.ratio_ci95,
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::history::series::series;

    #[test]
    fn a_step_is_named_by_the_commits_around_it() {
        let records: Vec<_> = (0..12)
            .map(|i| {
                let level = if i < 6 { 1.0 } else { 1.3 };
                // A little noise, so that the series has a scale.
                let wobble = 1.0 + 0.002 * ((i * 7 % 5) as f64 - 2.0);
                let mut r = crate::history::store::tests::record(
                    "lj-box/naive/n=1000",
                    &format!("c{i:02}"),
                    1e-3 * level * wobble,
                );
                r.commit_date = Some(format!("2026-12-{:02}T10:00:00Z", i + 1));
                r
            })
            .collect();
        let found = steps(&series(&records)[0]).unwrap();
        assert_eq!(found.len(), 1);
        assert_eq!(found[0].between, ["c05".to_string(), "c06".to_string()]);
        assert_eq!(found[0].index, 6);
        assert!((found[0].ratio - 1.3).abs() < 0.01, "{}", found[0].ratio);
    }
}
