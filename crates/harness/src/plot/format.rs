//! Tick labels that read like a person wrote them: `10 µs`, `1.5 ms`, `10k`, `64 KiB`, `1e-4`.
//!
//! Linear axes share one prefix and one number of decimals across all ticks (so `0.5 ms`,
//! `1.0 ms`, `1.5 ms` line up); logarithmic axes pick the prefix per tick (`100 µs`, `1 ms`).
//! Times and byte counts take their unit from `crate::units`, as the tables do.

use super::spec::Unit;
use crate::units::{Bytes, Duration};

/// Multipliers of counts and their suffixes, smallest first. The first entry also covers
/// smaller values.
const COUNTS: [(f64, &str); 5] = [(1.0, ""), (1e3, "k"), (1e6, "M"), (1e9, "G"), (1e12, "T")];

/// The size of the unit that suits `magnitude` and its suffix: the largest unit not above
/// `magnitude`, the smallest one for tiny magnitudes.
fn prefix_for(unit: Unit, magnitude: f64) -> (f64, String) {
    // A tick computed as 0.000999… s still reads 1 ms.
    let magnitude = magnitude * (1.0 + 1e-9);
    let spaced = |(size, name): (f64, &str)| (size, format!(" {name}"));
    match unit {
        Unit::Plain => (1.0, String::new()),
        Unit::Percent => (0.01, "%".into()),
        Unit::Seconds => spaced(Duration::unit_for(magnitude)),
        Unit::Bytes => spaced(Bytes::unit_for(magnitude)),
        Unit::Count => {
            let fits = |&&(m, _): &&(f64, &str)| magnitude >= m;
            let (m, suffix) = *COUNTS.iter().rev().find(fits).unwrap_or(&COUNTS[0]);
            (m, suffix.into())
        }
    }
}

/// Plain numbers this large or this small are written in scientific notation.
fn wants_scientific(unit: Unit, magnitude: f64) -> bool {
    unit == Unit::Plain && magnitude > 0.0 && !(1e-3..1e5).contains(&magnitude)
}

/// Fewest decimals (up to 6) that write `value` without visible rounding.
fn decimals_for(value: f64) -> usize {
    let value = value.abs();
    (0..6)
        .find(|&d| {
            let scaled = value * 10f64.powi(d as i32);
            (scaled - scaled.round()).abs() < 1e-6 * scaled.max(1.0)
        })
        .unwrap_or(6)
}

/// `{:e}` of `value` rounded to four significant digits: `1e-4`, `2.5e5`.
fn scientific(value: f64) -> String {
    let rounded: f64 = format!("{value:.3e}").parse().unwrap_or(value);
    format!("{rounded:e}")
}

/// Labels for the ticks of a linear axis whose ticks are multiples of `step`.
pub(crate) fn linear_labels(ticks: &[f64], step: f64, unit: Unit) -> Vec<String> {
    let magnitude = ticks.iter().fold(0.0f64, |m, t| m.max(t.abs()));
    if wants_scientific(unit, magnitude) {
        return ticks
            .iter()
            .map(|&t| {
                if t.abs() < step * 1e-9 {
                    "0".into()
                } else {
                    scientific(t)
                }
            })
            .collect();
    }
    let (mult, suffix) = prefix_for(unit, magnitude);
    let decimals = decimals_for(step / mult);
    ticks
        .iter()
        .map(|&t| {
            if t.abs() < step * 1e-9 {
                return "0".into();
            }
            format!("{:.*}{suffix}", decimals, t / mult)
        })
        .collect()
}

/// The label of one tick on a logarithmic axis, with the prefix that suits it.
pub(crate) fn log_label(value: f64, unit: Unit) -> String {
    if wants_scientific(unit, value.abs()) || (unit == Unit::Plain && value.abs() >= 1e4) {
        return scientific(value);
    }
    let (mult, suffix) = prefix_for(unit, value.abs());
    format!("{}{suffix}", significant(value / mult, 3))
}

/// `value` with at most `digits` significant digits and no trailing zeros.
fn significant(value: f64, digits: i32) -> String {
    if value == 0.0 {
        return "0".into();
    }
    let order = value.abs().log10().floor() as i32;
    let decimals = (digits - 1 - order).clamp(0, 9) as usize;
    let text = format!("{value:.decimals$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

/// Labels for the ticks of a logarithmic axis. Plain numbers switch to scientific notation
/// for every tick as soon as one needs it, so that `1e-3` does not sit next to `0.01`.
pub(crate) fn log_labels(ticks: &[f64], unit: Unit) -> Vec<String> {
    let labels: Vec<String> = ticks.iter().map(|&v| log_label(v, unit)).collect();
    if unit == Unit::Plain && labels.iter().any(|l| l.contains('e')) {
        return ticks.iter().map(|&v| scientific(v)).collect();
    }
    labels
}

/// A single value written with its unit for annotations (not ticks): `3.2 ms`, `12k`.
pub(crate) fn value_label(value: f64, unit: Unit) -> String {
    if !value.is_finite() {
        return "-".into();
    }
    log_label(value, unit)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seconds_on_a_log_axis_take_the_prefix_of_each_tick() {
        let labels: Vec<String> = [1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 2.5e-1, 3.0]
            .iter()
            .map(|&v| log_label(v, Unit::Seconds))
            .collect();
        assert_eq!(
            labels,
            ["1 µs", "10 µs", "100 µs", "1 ms", "10 ms", "250 ms", "3 s"]
        );
        assert_eq!(log_label(5e-10, Unit::Seconds), "0.5 ns");
    }

    #[test]
    fn counts_use_k_and_m_and_plain_numbers_switch_to_exponents() {
        assert_eq!(log_label(1e4, Unit::Count), "10k");
        assert_eq!(log_label(2.5e6, Unit::Count), "2.5M");
        assert_eq!(log_label(500.0, Unit::Count), "500");
        assert_eq!(log_label(1e4, Unit::Plain), "1e4");
        assert_eq!(log_label(1e-4, Unit::Plain), "1e-4");
        assert_eq!(log_label(0.05, Unit::Plain), "0.05");
        assert_eq!(log_label(2048.0, Unit::Bytes), "2 KiB");
        assert_eq!(log_label(1.5 * 1024.0 * 1024.0, Unit::Bytes), "1.5 MiB");
        assert_eq!(log_label(0.25, Unit::Percent), "25%");
    }

    #[test]
    fn plain_log_axes_use_one_notation() {
        assert_eq!(
            log_labels(&[3e-5, 1e-4, 1e-3], Unit::Plain),
            ["3e-5", "1e-4", "1e-3"]
        );
        assert_eq!(
            log_labels(&[0.01, 0.1, 1.0], Unit::Plain),
            ["0.01", "0.1", "1"]
        );
    }

    #[test]
    fn linear_ticks_share_prefix_and_decimals() {
        let ticks = [0.0, 0.5e-3, 1.0e-3, 1.5e-3];
        assert_eq!(
            linear_labels(&ticks, 0.5e-3, Unit::Seconds),
            ["0", "0.5 ms", "1.0 ms", "1.5 ms"]
        );
        assert_eq!(
            linear_labels(&[0.0, 0.25, 0.5], 0.25, Unit::Plain),
            ["0", "0.25", "0.50"]
        );
        assert_eq!(linear_labels(&[2e5, 4e5], 2e5, Unit::Plain), ["2e5", "4e5"]);
        assert_eq!(
            linear_labels(&[0.0, 20_000.0, 40_000.0], 20_000.0, Unit::Count),
            ["0", "20k", "40k"]
        );
        assert_eq!(
            linear_labels(&[0.0, 0.25, 0.5], 0.25, Unit::Percent),
            ["0", "25%", "50%"]
        );
    }

    #[test]
    fn rounding_noise_does_not_leak_into_labels() {
        let noisy = 0.1 + 0.2; // 0.30000000000000004
        assert_eq!(linear_labels(&[noisy], 0.1, Unit::Plain), ["0.3"]);
        assert_eq!(log_label(10f64.powi(-3), Unit::Seconds), "1 ms");
        assert_eq!(value_label(f64::NAN, Unit::Seconds), "-");
    }
}
