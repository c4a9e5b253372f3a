//! A case's series: its records of one machine class and config, one point per commit in the
//! order of the commits, on one metric for the whole series.

use super::instant::{self, Instant};
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
    /// For records that name no commit (`unknown`: measured outside a git checkout; or empty),
    /// when their measurement started: they are one point per measurement, since nothing says
    /// two such runs measured the same code. `None` (left out of JSON) for a commit's point.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub measured: Option<String>,
    /// Its committer date, ISO 8601; `None` when git did not know the commit.
    pub commit_date: Option<String>,
    /// The median of its records' medians (one record: its median), and the widest interval
    /// of them.
    pub value: f64,
    /// The lowest low and the highest high of its records' 95% intervals, in the series' metric.
    pub ci95: [f64; 2],
    /// Records of the commit the point is made from (builds with uncommitted changes left out).
    pub records: usize,
    /// The median of its records' times per step, seconds, whatever the series' metric: the
    /// raw series the steps are placed on when the control is flat ([`super::steps`]).
    #[serde(skip)]
    pub seconds: f64,
    /// The control: the time of the reference workload at this commit on this machine class
    /// and config, the median over every case's records of the commit (each record's median
    /// time over its normalised median); `None` when some record of the commit has no
    /// reference timing. What divides the raw series into the normalised one.
    #[serde(skip)]
    pub control: Option<f64>,
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
    /// One point per commit (per measurement for records that name no commit), in commit
    /// order (see [`series`]).
    pub points: Vec<Point>,
    /// Records measured on a build with uncommitted changes: not any commit's code, so not
    /// in the series.
    pub dirty: usize,
}

impl Point {
    /// Whether the point is one measurement of code that names no commit.
    pub fn outside_git(&self) -> bool {
        self.measured.is_some()
    }
}

/// The series of `records`, in the order each (class, config, case) first appears; the points
/// of a series in commit order: by the instant of the commit date, then by the order of
/// measurement (file order); a record without a date (or with one that is not a time) goes
/// right after the record measured before it. That order is total, whatever the dates.
pub fn series(records: &[Record]) -> Vec<Series> {
    let mut keys: Vec<(&str, &str, &str)> = Vec::new();
    for r in records {
        let key = (r.class.as_str(), r.config.as_str(), r.case.as_str());
        if !keys.contains(&key) {
            keys.push(key);
        }
    }
    let controls = controls(records);
    keys.into_iter()
        .map(|(class, config, case)| {
            let mine: Vec<&Record> = records
                .iter()
                .filter(|r| r.class == class && r.config == config && r.case == case)
                .collect();
            let control = |r: &Record| {
                let (commit, measured) = point_key(r);
                controls
                    .get(&(class, config, commit, measured))
                    .copied()
                    .flatten()
            };
            one(class, config, case, &mine, &control)
        })
        .collect()
}

/// A point's key within its class and config: (class, config, commit, measurement).
type ControlKey<'a> = (&'a str, &'a str, &'a str, Option<&'a str>);

/// The control of every (class, config, point): the median over the clean records of all
/// cases of the reference workload's time (median seconds over normalised median); `None`
/// when one of them has no reference timing. The reference workload is the same for every case
/// of a config (its length is the config's `measure.reference_s`), so every case's records of
/// a commit time it: the median over them is less noisy than any one case's.
fn controls(records: &[Record]) -> std::collections::BTreeMap<ControlKey<'_>, Option<f64>> {
    let mut times: std::collections::BTreeMap<ControlKey<'_>, Option<Vec<f64>>> =
        std::collections::BTreeMap::new();
    for r in records.iter().filter(|r| !r.dirty) {
        let (commit, measured) = point_key(r);
        let time = r
            .normalized
            .map(|n| r.median_s / n.median)
            .filter(|t| t.is_finite() && *t > 0.0);
        let entry = times
            .entry((&r.class, &r.config, commit, measured))
            .or_insert_with(|| Some(Vec::new()));
        match (entry.as_mut(), time) {
            (Some(v), Some(t)) => v.push(t),
            _ => *entry = None,
        }
    }
    times
        .into_iter()
        .map(|(k, v)| (k, v.and_then(|v| median(&v))))
        .collect()
}

fn one(
    class: &str,
    config: &str,
    case: &str,
    records: &[&Record],
    control: &dyn Fn(&Record) -> Option<f64>,
) -> Series {
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
    let mut points: Vec<Point> = Vec::new();
    for r in commit_order(&clean) {
        let key = point_key(r);
        if points
            .iter()
            .any(|p| (p.commit.as_str(), p.measured.as_deref()) == key)
        {
            continue;
        }
        let same: Vec<&Record> = clean
            .iter()
            .copied()
            .filter(|o| point_key(o) == key)
            .collect();
        let values: Vec<f64> = same.iter().map(|o| value(o).0).collect();
        let lo = same
            .iter()
            .map(|o| value(o).1[0])
            .fold(f64::INFINITY, f64::min);
        let hi = same.iter().map(|o| value(o).1[1]).fold(0.0, f64::max);
        let seconds: Vec<f64> = same.iter().map(|o| o.median_s).collect();
        points.push(Point {
            commit: r.commit.clone(),
            measured: key.1.map(str::to_string),
            commit_date: r.commit_date.clone(),
            value: median(&values).unwrap_or(f64::NAN),
            ci95: [lo, hi],
            records: same.len(),
            seconds: median(&seconds).unwrap_or(f64::NAN),
            control: control(r),
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

/// What makes records one point: their commit, and for records that name none, their
/// measurement too.
fn point_key(r: &Record) -> (&str, Option<&str>) {
    (
        r.commit.as_str(),
        (!r.commit_known()).then_some(r.measured.as_str()),
    )
}

/// `records` (in measurement order) in commit order. Each is keyed by (the instant of its
/// commit date, else that of the nearest record before it that has one; its position): positions
/// differ, so no two keys are equal and the order is total, and a record without a date keeps
/// its place after its neighbour. (Comparing dates only when both records have one is not an
/// order at all: the sort may then panic.)
fn commit_order<'a>(records: &[&'a Record]) -> Vec<&'a Record> {
    let mut before = None;
    let mut keyed: Vec<(Option<Instant>, usize, &Record)> = records
        .iter()
        .enumerate()
        .map(|(i, r)| {
            if let Some(t) = r.commit_date.as_deref().and_then(instant::parse) {
                before = Some(t);
            }
            (before, i, *r)
        })
        .collect();
    keyed.sort_by_key(|&(t, i, _)| (t, i));
    keyed.into_iter().map(|(_, _, r)| r).collect()
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

    #[test]
    fn commits_are_ordered_by_the_instant_of_their_dates() {
        // git's %cI keeps the committer's offset: 23:00 at -05:00 is 04:00 UTC the next day,
        // after 02:00 UTC although its text sorts first.
        let records = vec![
            record("a", "late", "2026-12-01T23:00:00-05:00", 2.0, false),
            record("a", "early", "2026-12-02T02:00:00Z", 1.0, false),
        ];
        let s = series(&records);
        let order: Vec<&str> = s[0].points.iter().map(|p| p.commit.as_str()).collect();
        assert_eq!(order, ["early", "late"]);
    }

    #[test]
    fn records_without_a_date_keep_their_place_and_the_order_is_total() {
        // Dates out of file order, every third record without one: a comparator that compares
        // dates only when both have one is no order, and sorting 30 such records panicked.
        let records: Vec<Record> = (0..30)
            .map(|i| {
                let day = (i * 7) % 28 + 1;
                let mut r = record(
                    "a",
                    &format!("c{i:02}"),
                    &format!("2026-11-{day:02}"),
                    1.0,
                    false,
                );
                if i % 3 == 1 {
                    r.commit_date = None;
                }
                r
            })
            .collect();
        let s = series(&records);
        let order: Vec<&str> = s[0].points.iter().map(|p| p.commit.as_str()).collect();
        assert_eq!(order.len(), 30);
        // Each undated record right after the record measured before it.
        for i in (1..30).filter(|i| i % 3 == 1) {
            let at = order.iter().position(|c| *c == format!("c{i:02}")).unwrap();
            assert_eq!(order[at - 1], format!("c{:02}", i - 1), "{order:?}");
        }
        // The dated ones by date.
        let days: Vec<u32> = order
            .iter()
            .filter_map(|c| {
                let i: usize = c[1..].parse().unwrap();
                (i % 3 != 1).then_some(((i * 7) % 28 + 1) as u32)
            })
            .collect();
        assert!(days.is_sorted(), "{days:?}");
    }

    #[test]
    fn records_outside_git_are_one_point_per_measurement() {
        let mut a = record("a", "unknown", "2026-12-01", 1.0, false);
        a.commit_date = None;
        let mut b = a.clone();
        b.measured = "2026-12-06T10:00:00Z".into();
        b.median_s = 2.0;
        let mut c = a.clone();
        c.commit = String::new();
        let records = vec![a.clone(), b, a, c];
        let points = &series(&records)[0].points;
        let got: Vec<(&str, Option<&str>, usize)> = points
            .iter()
            .map(|p| (p.commit.as_str(), p.measured.as_deref(), p.records))
            .collect();
        assert_eq!(
            got,
            [
                ("unknown", Some("2026-12-05T10:00:00Z"), 2),
                ("unknown", Some("2026-12-06T10:00:00Z"), 1),
                ("", Some("2026-12-05T10:00:00Z"), 1),
            ]
        );
        assert!(points.iter().all(Point::outside_git));
    }
}
