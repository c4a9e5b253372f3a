//! From an [`Axis`] and the values plotted on it to a drawable axis: the effective scale (log
//! only when every value is positive), sane bounds even for one point or all-equal values, tick
//! positions (decades on log axes) and their labels. A [`ResolvedAxis`] is a plotters
//! coordinate, so one type serves linear, log and categorical axes, and plotters' mesh draws
//! exactly these ticks.

#[cfg(feature = "plot")]
use plotters::coord::ranged1d::{
    KeyPointHint, KeyPointWeight, NoDefaultFormatting, Ranged, ValueFormatter,
};

use super::format;
use super::spec::{Axis, Scale, Unit};

/// At most this many labelled ticks on an axis.
const MAX_MAJOR: usize = 9;

/// An axis ready to draw.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ResolvedAxis {
    pub scale: Scale,
    pub lo: f64,
    pub hi: f64,
    /// Labelled ticks, each with its label.
    pub major: Vec<(f64, String)>,
    /// Unlabelled grid lines.
    pub minor: Vec<f64>,
    pub unit: Unit,
}

impl ResolvedAxis {
    /// Fits `axis` to `values` (non-finite values are ignored).
    pub fn resolve(axis: &Axis, values: impl IntoIterator<Item = f64>) -> Self {
        if !axis.categories.is_empty() {
            return Self::categorical(&axis.categories, axis.unit);
        }
        let values: Vec<f64> = values.into_iter().filter(|v| v.is_finite()).collect();
        let fixed = axis
            .range
            .filter(|&(lo, hi)| lo.is_finite() && hi.is_finite() && lo < hi);
        let all_positive = values.iter().all(|&v| v > 0.0);
        let log = axis.scale == Scale::Log && all_positive && fixed.is_none_or(|(lo, _)| lo > 0.0);
        let (lo, hi) = match fixed {
            Some(range) => range,
            None if log => log_bounds(&values),
            None => linear_bounds(&values, axis.include_zero),
        };
        let (scale, major, minor) = if log {
            let (major, minor) = log_ticks(lo, hi);
            let labels = format::log_labels(&major, axis.unit);
            (Scale::Log, major.into_iter().zip(labels).collect(), minor)
        } else {
            let whole = axis.unit == Unit::Count;
            let (major, step) = linear_ticks(lo, hi, whole);
            let labels = format::linear_labels(&major, step, axis.unit);
            let minor = if whole && step < 2.0 {
                Vec::new()
            } else {
                linear_minor(lo, hi, step, whole)
            };
            (
                Scale::Linear,
                major.into_iter().zip(labels).collect(),
                minor,
            )
        };
        ResolvedAxis {
            scale,
            lo,
            hi,
            major,
            minor,
            unit: axis.unit,
        }
    }

    fn categorical(categories: &[String], unit: Unit) -> Self {
        ResolvedAxis {
            scale: Scale::Linear,
            lo: -0.5,
            hi: categories.len().max(1) as f64 - 0.5,
            major: categories
                .iter()
                .enumerate()
                .map(|(i, c)| (i as f64, c.clone()))
                .collect(),
            minor: Vec::new(),
            unit,
        }
    }

    /// Where `value` sits between the bounds: 0 at `lo`, 1 at `hi` (outside for values beyond).
    pub fn fraction(&self, value: f64) -> f64 {
        match self.scale {
            Scale::Linear => (value - self.lo) / (self.hi - self.lo),
            Scale::Log => (value.log10() - self.lo.log10()) / (self.hi.log10() - self.lo.log10()),
        }
    }

    /// Whether `value` can be drawn on this axis (finite, inside the bounds, positive on log).
    pub fn contains(&self, value: f64) -> bool {
        let f = self.fraction(value);
        f.is_finite() && (-1e-9..=1.0 + 1e-9).contains(&f)
    }

    /// `value` pulled into the bounds (for bands and error bars that reach past them), or
    /// `None` where the axis cannot place it: not finite, or not positive on a log axis.
    pub fn clamp(&self, value: f64) -> Option<f64> {
        let f = self.fraction(value);
        f.is_finite().then_some(if f < 0.0 {
            self.lo
        } else if f > 1.0 {
            self.hi
        } else {
            value
        })
    }

    /// The label of a major tick at `value`, or a freshly formatted one for any other value.
    pub(crate) fn label(&self, value: f64) -> String {
        // On a log axis, relative to the tick: an absolute tolerance from the range would take
        // every tick decades below the top for the first one.
        let near = |v: f64| match self.scale {
            Scale::Log => (v - value).abs() <= 1e-9 * v.abs(),
            Scale::Linear => (v - value).abs() <= 1e-9 * (self.hi - self.lo).abs(),
        };
        match self.major.iter().find(|(v, _)| near(*v)) {
            Some((_, label)) => label.clone(),
            None => format::value_label(value, self.unit),
        }
    }
}

#[cfg(feature = "plot")]
impl Ranged for ResolvedAxis {
    type FormatOption = NoDefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        // Callers only pass values inside the axis; the clamp keeps a stray one from wrapping.
        let fraction = self.fraction(*value);
        let fraction = if fraction.is_finite() {
            fraction.clamp(-1.0, 2.0)
        } else {
            0.0
        };
        limit.0 + (fraction * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        match hint.weight() {
            KeyPointWeight::Bold => self.major.iter().map(|(v, _)| *v).collect(),
            KeyPointWeight::Any => self.minor.clone(),
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

#[cfg(feature = "plot")]
impl ValueFormatter<f64> for ResolvedAxis {
    fn format(value: &f64) -> String {
        value.to_string()
    }

    fn format_ext(&self, value: &f64) -> String {
        self.label(*value)
    }
}

/// Data bounds padded by 5% of the span in log space; one decade around a lone value.
fn log_bounds(values: &[f64]) -> (f64, f64) {
    let (min, max) = min_max(values).unwrap_or((1.0, 10.0));
    let (a, b) = (min.log10(), max.log10());
    let pad = if b - a < 1e-9 { 0.5 } else { 0.05 * (b - a) };
    (10f64.powf(a - pad), 10f64.powf(b + pad))
}

/// Data bounds padded by 5% of the span, or by half the value for all-equal data; a range of
/// non-negative data never starts below zero.
fn linear_bounds(values: &[f64], include_zero: bool) -> (f64, f64) {
    let Some((mut min, mut max)) = min_max(values) else {
        return (0.0, 1.0);
    };
    if include_zero {
        min = min.min(0.0);
        max = max.max(0.0);
    }
    let span = max - min;
    let pad = if span <= 1e-9 * min.abs().max(max.abs()) {
        if max == 0.0 { 1.0 } else { 0.5 * max.abs() }
    } else {
        0.05 * span
    };
    let mut lo = min - pad;
    let mut hi = max + pad;
    if min >= 0.0 && lo < 0.0 {
        lo = 0.0;
    }
    if max <= 0.0 && hi > 0.0 && min < 0.0 {
        hi = 0.0;
    }
    if lo.is_finite() && hi.is_finite() && lo < hi {
        (lo, hi)
    } else if min < max {
        (min, max)
    } else {
        (0.0, 1.0)
    }
}

fn min_max(values: &[f64]) -> Option<(f64, f64)> {
    let first = *values.first()?;
    Some(
        values
            .iter()
            .fold((first, first), |(lo, hi), &v| (lo.min(v), hi.max(v))),
    )
}

/// A step of 1, 2, 2.5 or 5 times a power of ten giving about six ticks over `span`; for
/// `whole` numbers a whole step without the 2.5.
fn nice_step(span: f64, whole: bool) -> f64 {
    let raw = span / 6.0;
    let magnitude = 10f64.powf(raw.log10().floor());
    let norm = raw / magnitude;
    let steps: &[f64] = if whole {
        &[1.0, 2.0, 5.0, 10.0]
    } else {
        &[1.0, 2.0, 2.5, 5.0, 10.0]
    };
    let nice = steps
        .iter()
        .copied()
        .find(|&n| norm <= n * 1.0001)
        .unwrap_or(10.0);
    if whole {
        (nice * magnitude).max(1.0)
    } else {
        nice * magnitude
    }
}

/// Multiples of a nice step inside `[lo, hi]`, and the step.
fn linear_ticks(lo: f64, hi: f64, whole: bool) -> (Vec<f64>, f64) {
    let step = nice_step(hi - lo, whole);
    if !(step.is_finite() && step > 0.0) {
        return (vec![lo], hi - lo);
    }
    let first = (lo / step - 1e-9).ceil() as i64;
    let last = (hi / step + 1e-9).floor() as i64;
    let ticks = (first..=last).map(|k| k as f64 * step).collect();
    (ticks, step)
}

fn linear_minor(lo: f64, hi: f64, step: f64, whole: bool) -> Vec<f64> {
    let half = step / 2.0;
    let (ticks, _) = linear_ticks(lo, hi, whole);
    let mut minor: Vec<f64> = ticks.iter().map(|t| t - half).collect();
    minor.extend(ticks.last().map(|t| t + half));
    minor.retain(|&m| m > lo && m < hi);
    minor
}

/// Ticks of a log axis: decades when the range spans several; 1-2-5 steps over one to three
/// decades; plain nice steps inside a single decade. Minor ticks fill the 2..9 multiples.
fn log_ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    let (a, b) = (lo.log10(), hi.log10());
    let first_decade = (a - 1e-9).ceil() as i32;
    let last_decade = (b + 1e-9).floor() as i32;
    let inside = |v: &f64| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9);
    let multiples = |ms: &[f64]| -> Vec<f64> {
        (first_decade - 1..=last_decade)
            .flat_map(|k| ms.iter().map(move |m| m * 10f64.powi(k)))
            .filter(inside)
            .collect()
    };
    let decades = (last_decade - first_decade + 1).max(0) as usize;
    if decades >= 4 {
        let stride = decades.div_ceil(MAX_MAJOR - 1);
        let all: Vec<f64> = (first_decade..=last_decade)
            .map(|k| 10f64.powi(k))
            .collect();
        let major: Vec<f64> = all.iter().copied().step_by(stride).collect();
        let minor = if stride > 1 {
            all.into_iter().filter(|d| !major.contains(d)).collect()
        } else if decades <= 7 {
            multiples(&[2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
        } else {
            Vec::new()
        };
        return (major, minor);
    }
    let one_two_five = multiples(&[1.0, 2.0, 5.0]);
    if one_two_five.len() >= 3 {
        let one_three = multiples(&[1.0, 3.0]);
        let major = if decades >= 2 && one_three.len() >= 3 {
            one_three
        } else {
            one_two_five
        };
        let minor = multiples(&[2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
            .into_iter()
            .filter(|m| !major.iter().any(|v| (v / m - 1.0).abs() < 1e-9))
            .collect();
        return (major, minor);
    }
    let (major, _) = linear_ticks(lo, hi, false);
    (major.into_iter().filter(|v| *v > 0.0).collect(), Vec::new())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(axis: &ResolvedAxis) -> Vec<&str> {
        axis.major.iter().map(|(_, l)| l.as_str()).collect()
    }

    #[test]
    fn wide_log_axes_tick_at_decades() {
        let axis = Axis::log("n").unit(Unit::Count);
        let r = ResolvedAxis::resolve(&axis, [100.0, 1e6]);
        assert_eq!(r.scale, Scale::Log);
        assert_eq!(labels(&r), ["100", "1k", "10k", "100k", "1M"]);
        assert!(r.minor.iter().any(|&m| (m - 2000.0).abs() < 1e-6));
    }

    #[test]
    fn very_wide_log_axes_thin_their_decades() {
        let r = ResolvedAxis::resolve(&Axis::log("e"), [1e-12, 1e3]);
        assert!(r.major.len() <= MAX_MAJOR, "{:?}", labels(&r));
        assert!(r.major.len() >= 4);
    }

    #[test]
    fn narrow_log_axes_still_get_three_or_more_ticks() {
        let time = Axis::log("t").unit(Unit::Seconds);
        for (lo, hi) in [(2e-3, 3e-2), (1.1e-3, 1.9e-3), (0.9, 1.2), (5.0, 5.0)] {
            let r = ResolvedAxis::resolve(&time, [lo, hi]);
            assert!(r.major.len() >= 2, "{lo}..{hi}: {:?}", labels(&r));
            assert!(r.major.iter().all(|(v, _)| r.contains(*v)));
        }
    }

    #[test]
    fn log_falls_back_to_linear_when_a_value_is_not_positive() {
        let r = ResolvedAxis::resolve(&Axis::log("y"), [0.0, 1.0, 10.0]);
        assert_eq!(r.scale, Scale::Linear);
        assert!(r.contains(0.0));
        let r = ResolvedAxis::resolve(&Axis::log("y"), [-3.0, 1.0]);
        assert_eq!(r.scale, Scale::Linear);
    }

    #[test]
    fn degenerate_data_gives_a_usable_range() {
        for values in [
            vec![],
            vec![0.0],
            vec![3.0],
            vec![-2.0, -2.0],
            vec![f64::NAN, f64::INFINITY],
        ] {
            for axis in [Axis::linear("x"), Axis::log("x")] {
                let r = ResolvedAxis::resolve(&axis, values.iter().copied());
                assert!(
                    r.lo.is_finite() && r.hi.is_finite() && r.lo < r.hi,
                    "{values:?} {r:?}"
                );
                assert!(!r.major.is_empty(), "{values:?} {r:?}");
                for v in values.iter().filter(|v| v.is_finite()) {
                    assert!(r.contains(*v), "{v} outside {r:?}");
                }
            }
        }
    }

    #[test]
    fn non_negative_data_does_not_get_negative_ticks() {
        let r = ResolvedAxis::resolve(&Axis::linear("s"), [0.0, 1.0, 2.0]);
        assert_eq!(r.lo, 0.0);
        assert!(r.major.iter().all(|(v, _)| *v >= 0.0));
        let r = ResolvedAxis::resolve(&Axis::linear("s").starting_at_zero(), [1.5, 2.0]);
        assert_eq!(r.lo, 0.0);
    }

    #[test]
    fn fixed_ranges_are_kept_and_bad_ones_ignored() {
        let r = ResolvedAxis::resolve(&Axis::linear("x").range(0.0, 4.0), [1.0, 9.0]);
        assert_eq!((r.lo, r.hi), (0.0, 4.0));
        assert!(!r.contains(9.0));
        let r = ResolvedAxis::resolve(&Axis::linear("x").range(4.0, 4.0), [1.0, 2.0]);
        assert!(r.contains(1.0) && r.contains(2.0));
    }

    #[test]
    fn count_axes_tick_at_whole_numbers() {
        let r = ResolvedAxis::resolve(&Axis::linear("threads").unit(Unit::Count), [2.0, 4.0]);
        assert!(
            r.major.iter().all(|(v, _)| v.fract() == 0.0),
            "{:?}",
            labels(&r)
        );
        assert!(r.major.len() >= 2);
        let r = ResolvedAxis::resolve(&Axis::linear("threads").unit(Unit::Count), [1.0, 16.0]);
        assert!(
            r.major.iter().all(|(v, _)| v.fract() == 0.0),
            "{:?}",
            labels(&r)
        );
    }

    #[test]
    fn categories_sit_at_integer_positions() {
        let axis = Axis::categorical("kernel", vec!["naive".into(), "octree".into()]);
        let r = ResolvedAxis::resolve(&axis, []);
        assert_eq!(labels(&r), ["naive", "octree"]);
        assert_eq!(r.label(1.0), "octree");
        assert!((r.fraction(0.0) - 0.25).abs() < 1e-12);
    }

    #[test]
    fn each_tick_of_a_log_axis_over_many_decades_keeps_its_own_label() {
        let r = ResolvedAxis::resolve(&Axis::log("y"), [1e-15, 0.1]);
        for (v, l) in &r.major {
            assert_eq!(&r.label(*v), l, "{:?}", labels(&r));
        }
        let distinct: std::collections::HashSet<String> =
            r.major.iter().map(|(v, _)| r.label(*v)).collect();
        assert_eq!(distinct.len(), r.major.len(), "{:?}", labels(&r));
    }
}
