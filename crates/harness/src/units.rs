//! Quantities as people read them: durations, wall-time plans, byte counts, percentages, plain
//! numbers and estimates with their confidence intervals. Every table, progress line and
//! summary formats through these `Display` impls, so one quantity reads the same everywhere
//! (`µs`, never `us` in one place and `µs` in another). A precision given in the format string
//! (`{:.2}`) sets the decimals; without one each type has its own default.

use std::fmt;

/// A measured time span, in seconds: `12.300 ms`, `4.560 µs`, `87.00 ns`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Duration(pub f64);

impl Duration {
    /// A span given in nanoseconds (as step timings are recorded).
    pub fn from_ns(ns: f64) -> Self {
        Duration(ns * 1e-9)
    }

    /// The unit a span of `seconds` is written in, and its length in seconds: `(1e-3, "ms")`.
    /// The figures' axes take it too, so a plot and a table name a time alike.
    pub(crate) fn unit_for(seconds: f64) -> (f64, &'static str) {
        const UNITS: [(f64, &str); 4] = [(1.0, "s"), (1e-3, "ms"), (1e-6, "µs"), (1e-9, "ns")];
        let s = seconds.abs();
        *UNITS.iter().find(|(len, _)| s >= *len).unwrap_or(&UNITS[3])
    }
}

impl fmt::Display for Duration {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (len, unit) = Self::unit_for(self.0);
        // Nanoseconds are the timer's grain: a third decimal there would be noise.
        let default = if unit == "ns" { 2 } else { 3 };
        // 1 / len is exactly 1e3, 1e6 or 1e9: the product rounds as `s * 1e3` always has.
        write!(
            f,
            "{:.d$} {unit}",
            self.0 * (1.0 / len),
            d = f.precision().unwrap_or(default)
        )
    }
}

/// A wall time for planning, coarse: `3.20 s`, `12.5 s`, `4.2 min`, `1.5 h`, `2.0 days`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallTime(pub f64);

impl fmt::Display for WallTime {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = self.0;
        let (value, unit, default) = if s < 10.0 {
            (s, "s", 2)
        } else if s < 60.0 {
            (s, "s", 1)
        } else if s < 3600.0 {
            (s / 60.0, "min", 1)
        } else if s < 86_400.0 {
            (s / 3600.0, "h", 1)
        } else {
            (s / 86_400.0, "days", 1)
        };
        write!(
            f,
            "{value:.d$} {unit}",
            d = f.precision().unwrap_or(default)
        )
    }
}

/// A byte count in binary units: `512 B`, `4.0 KiB`, `1.5 MiB`, `2.3 GiB`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bytes(pub f64);

impl Bytes {
    /// The unit a count of `bytes` is written in, and its size in bytes: `(1024.0, "KiB")`.
    /// The figures' axes take it too, so a plot and a table name a size alike.
    pub(crate) fn unit_for(bytes: f64) -> (f64, &'static str) {
        const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
        let b = bytes.abs();
        let mut size = 1.0;
        let mut unit = 0;
        while b >= 1024.0 * size && unit + 1 < UNITS.len() {
            size *= 1024.0;
            unit += 1;
        }
        (size, UNITS[unit])
    }
}

impl fmt::Display for Bytes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (size, unit) = Self::unit_for(self.0);
        // Whole bytes have no decimals; the format's precision is for the larger units.
        let d = if size == 1.0 {
            0
        } else {
            f.precision().unwrap_or(1)
        };
        write!(f, "{:.d$} {unit}", self.0 / size)
    }
}

/// A fraction shown as a percentage: `3.1%`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Percent(pub f64);

impl fmt::Display for Percent {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let d = f.precision().unwrap_or(1);
        write!(f, "{:.d$}%", 100.0 * self.0)
    }
}

/// A dimensionless number: fixed decimals (4 by default) in the readable range, scientific
/// notation (3 decimals) for magnitudes of 10⁴ and above or below 10⁻³.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Number(pub f64);

impl fmt::Display for Number {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        if !x.is_finite() {
            write!(f, "{x}")
        } else if x != 0.0 && (x.abs() >= 1e4 || x.abs() < 1e-3) {
            write!(f, "{x:.3e}")
        } else {
            write!(f, "{x:.d$}", d = f.precision().unwrap_or(4))
        }
    }
}

/// An estimate with its 95 % interval, each shown as `U`: `0.123 [0.101, 0.150]`. The format's
/// precision applies to all three.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WithCi<U> {
    /// The point estimate (a median, a fitted parameter).
    pub estimate: U,
    /// The interval's lower bound.
    pub low: U,
    /// The interval's upper bound.
    pub high: U,
}

impl<U> WithCi<U> {
    /// The estimate and interval of `e`, each in the unit `unit` makes of it.
    pub fn of(e: &crate::fit::Estimate, unit: impl Fn(f64) -> U) -> Self {
        Self::new(e.estimate, e.ci95, unit)
    }

    /// `estimate` and its interval `ci95`, each in the unit `unit` makes of it.
    pub fn new(estimate: f64, ci95: [f64; 2], unit: impl Fn(f64) -> U) -> Self {
        WithCi {
            estimate: unit(estimate),
            low: unit(ci95[0]),
            high: unit(ci95[1]),
        }
    }
}

impl<U: fmt::Display> fmt::Display for WithCi<U> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match f.precision() {
            Some(d) => write!(
                f,
                "{:.d$} [{:.d$}, {:.d$}]",
                self.estimate, self.low, self.high
            ),
            None => write!(f, "{} [{}, {}]", self.estimate, self.low, self.high),
        }
    }
}

/// A plain decimal, whose precision is the format's: for estimates of plain quantities.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plain(pub f64);

impl fmt::Display for Plain {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match f.precision() {
            Some(d) => write!(f, "{:.d$}", self.0),
            None => write!(f, "{}", self.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::Estimate;

    #[test]
    fn durations_pick_their_unit_and_honour_precision() {
        assert_eq!(Duration(2.5).to_string(), "2.500 s");
        assert_eq!(Duration(0.0123).to_string(), "12.300 ms");
        assert_eq!(Duration::from_ns(4560.0).to_string(), "4.560 µs");
        assert_eq!(Duration::from_ns(87.0).to_string(), "87.00 ns");
        assert_eq!(format!("{:.1}", Duration(0.0123)), "12.3 ms");
    }

    #[test]
    fn wall_times_are_coarse() {
        assert_eq!(WallTime(3.2).to_string(), "3.20 s");
        assert_eq!(WallTime(12.5).to_string(), "12.5 s");
        assert_eq!(WallTime(252.0).to_string(), "4.2 min");
        assert_eq!(WallTime(5400.0).to_string(), "1.5 h");
        assert_eq!(WallTime(172_800.0).to_string(), "2.0 days");
    }

    #[test]
    fn bytes_percent_and_numbers() {
        assert_eq!(Bytes(512.0).to_string(), "512 B");
        assert_eq!(Bytes(4096.0).to_string(), "4.0 KiB");
        assert_eq!(Bytes(1.5 * 1024.0 * 1024.0).to_string(), "1.5 MiB");
        assert_eq!(Percent(0.031).to_string(), "3.1%");
        assert_eq!(format!("{:.2}", Percent(0.031)), "3.10%");
        assert_eq!(Number(0.5).to_string(), "0.5000");
        assert_eq!(Number(25000.0).to_string(), "2.500e4");
        assert_eq!(Number(f64::INFINITY).to_string(), "inf");
    }

    #[test]
    fn estimates_show_their_interval_in_their_unit() {
        let e = Estimate {
            estimate: 0.123,
            ci95: [0.101, 0.15],
        };
        assert_eq!(
            format!("{:.3}", WithCi::of(&e, Plain)),
            "0.123 [0.101, 0.150]"
        );
        assert_eq!(WithCi::of(&e, Percent).to_string(), "12.3% [10.1%, 15.0%]");
        assert_eq!(
            WithCi::of(&e, Duration).to_string(),
            "123.000 ms [101.000 ms, 150.000 ms]"
        );
    }
}
