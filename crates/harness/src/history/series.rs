//! A case's series: its records of one machine class and config, one point per commit in the
//! order of the commits, on one metric for the whole series.

use super::store::Record;
use nbody_engine::stats::median;
use serde::Serialize;

/// What a series' values are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Metric {
    /// The time per step over the reference workload timed before each sample: what the
    /// machine's speed of the moment does not move.
    Normalized,
    /// Seconds per step, where some record has no reference timing.
    Seconds,
}

/// One commit's measurement of a case.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Point {
    /// The commit measured, as its records name it.
    pub commit: String,
    /// Its committer date, ISO 8601; `None` when git did not know the commit.
    pub commit_date: Option<String>,
    /// The median of its records' medians (one record: its median), and the widest interval
    /// of them.
    pub value: f64,
    /// The lowest low and the highest high of its records' 95% intervals, in the series' metric.
    pub ci95: [f64; 2],
    /// Records of the commit the point is made from (builds with uncommitted changes left out).
    pub records: usize,
}

/// A case's series on one machine class and config: one point per commit, in commit order.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Series {
    /// The machine class, as its history file names it.
    pub class: String,
    /// The sweep config's name the records came from.
    pub config: String,
    /// The case key.
    pub case: String,
    /// What the values are, one metric for the whole series.
    pub metric: Metric,
    /// One point per commit, ordered by commit date, then by order of measurement.
    pub points: Vec<Point>,
    /// Records measured on a build with uncommitted changes: not any commit's code, so not
    /// in the series.
    pub dirty: usize,
}

/// The series of `records`, in the order each (class, config, case) first appears; the points
/// of a series in commit order (the commit date, then the order of measurement; a record
/// without a date goes where it was measured).
pub fn series(records: &[Record]) -> Vec<Series> {
    let mut keys: Vec<(&str, &str, &str)> = Vec::new();
    for r in records {
        let key = (r.class.as_str(), r.config.as_str(), r.case.as_str());
        if !keys.contains(&key) {
            keys.push(key);
        }
    }
    keys.into_iter()
        .map(|(class, config, case)| {
            let mine: Vec<&Record> = records
                .iter()
                .filter(|r| r.class == class && r.config == config && r.case == case)
                .collect();
            one(class, config, case, &mine)
        })
        .collect()
}

fn one(class: &str, config: &str, case: &str, records: &[&Record]) -> Series {
    let clean: Vec<&Record> = records.iter().copied().filter(|r| !r.dirty).collect();
    let metric = if !clean.is_empty() && clean.iter().all(|r| r.normalized.is_some()) {
        Metric::Normalized
    } else {
        Metric::Seconds
    };
    let value = |r: &Record| match (metric, r.normalized) {
        (Metric::Normalized, Some(n)) => (n.median, n.ci95),
        _ => (r.median_s, r.ci95_s),
    };
    // The commits in order of their dates; the measurement order breaks ties and places a
    // commit without a date.
    let mut order: Vec<(usize, &Record)> = clean.iter().copied().enumerate().collect();
    order.sort_by(|(i, a), (j, b)| match (&a.commit_date, &b.commit_date) {
        (Some(x), Some(y)) => x.cmp(y).then(i.cmp(j)),
        _ => i.cmp(j),
    });
    let mut points: Vec<Point> = Vec::new();
    for (_, r) in order {
        if points.iter().any(|p| p.commit == r.commit) {
            continue;
        }
        let same: Vec<&Record> = clean
            .iter()
            .copied()
            .filter(|o| o.commit == r.commit)
            .collect();
        let values: Vec<f64> = same.iter().map(|o| value(o).0).collect();
        let lo = same
            .iter()
            .map(|o| value(o).1[0])
            .fold(f64::INFINITY, f64::min);
        let hi = same.iter().map(|o| value(o).1[1]).fold(0.0, f64::max);
        points.push(Point {
            commit: r.commit.clone(),
            commit_date: r.commit_date.clone(),
            value: median(&values).unwrap_or(f64::NAN),
            ci95: [lo, hi],
            records: same.len(),
        });
    }
    Series {
        class: class.to_string(),
        config: config.to_string(),
        case: case.to_string(),
        metric,
        points,
        dirty: records.len() - clean.len(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::history::store::Normalized;

    fn record(case: &str, commit: &str, date: &str, median_s: f64, norm: bool) -> Record {
        let mut r = crate::history::store::tests::record(case, commit, median_s);
        r.commit_date = Some(date.into());
        r.ci95_s = [median_s * 0.9, median_s * 1.1];
        r.normalized = norm.then_some(Normalized {
            median: median_s * 10.0,
            ci95: [median_s * 9.0, median_s * 11.0],
        });
        r
    }

    #[test]
    fn points_follow_the_commits_one_per_commit_on_one_metric() {
        let mut dirty = record("a", "c3", "2026-12-03", 9.0, true);
        dirty.dirty = true;
        let records = vec![
            record("a", "c2", "2026-12-02", 2.0, true),
            record("a", "c1", "2026-12-01", 1.0, true),
            record("b", "c1", "2026-12-01", 5.0, false),
            record("a", "c2", "2026-12-02", 4.0, true),
            dirty,
        ];
        let s = series(&records);
        assert_eq!(s.len(), 2);
        let a = &s[0];
        assert_eq!(
            (a.case.as_str(), a.metric, a.dirty),
            ("a", Metric::Normalized, 1)
        );
        let values: Vec<(&str, f64, usize)> = a
            .points
            .iter()
            .map(|p| (p.commit.as_str(), p.value, p.records))
            .collect();
        assert_eq!(values, [("c1", 10.0, 1), ("c2", 30.0, 2)]);
        assert_eq!(a.points[1].ci95, [18.0, 44.0]);
        // A series with a record lacking the reference timing is in seconds throughout.
        assert_eq!(s[1].metric, Metric::Seconds);
        assert_eq!(s[1].points[0].value, 5.0);
    }
}
