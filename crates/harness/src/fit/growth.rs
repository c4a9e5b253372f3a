//! The growth classes a complexity fit chooses among ([`ComplexityClass`]), and what the fit
//! lets a reader say about growth in n ([`GrowthReading`]). Cross-validation always picks
//! some class, and on a short range of n, or with cache effects bending the curve, the pick
//! changes between identical runs; the free exponent k, with its interval, does not. So a class
//! is named only where both agree: its own exponent over the measured n lies in k's 95%
//! interval, and no other class's does unless cross-validation picks it firmly. Where two
//! classes remain, both are named; where none does, the measured exponent stands alone. A
//! class is never printed beside an exponent interval that excludes it.

use super::Estimate;
use serde::{Serialize, Serializer};

/// A candidate growth class `g(n)`; models are `c·g(n)` or `a + c·g(n)`. Logarithms are base 2
/// (any base is absorbed by `c`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ComplexityClass {
    /// Linear, `g(n) = n`.
    N,
    /// `g(n) = n·log2 n` (tree codes such as Barnes-Hut).
    NLogN,
    /// `g(n) = n^1.5`.
    NSqrtN,
    /// Quadratic, `g(n) = n²` (direct all-pairs summation).
    N2,
    /// `g(n) = n²·log2 n`.
    N2LogN,
    /// Cubic, `g(n) = n³`.
    N3,
}

impl ComplexityClass {
    /// Every class, in increasing order of growth: the hypotheses the selection tries.
    pub const ALL: [ComplexityClass; 6] = [
        ComplexityClass::N,
        ComplexityClass::NLogN,
        ComplexityClass::NSqrtN,
        ComplexityClass::N2,
        ComplexityClass::N2LogN,
        ComplexityClass::N3,
    ];

    /// How the class is written in tables, messages and JSON, e.g. `n log n` or `n^2`.
    pub fn name(self) -> &'static str {
        match self {
            ComplexityClass::N => "n",
            ComplexityClass::NLogN => "n log n",
            ComplexityClass::NSqrtN => "n^1.5",
            ComplexityClass::N2 => "n^2",
            ComplexityClass::N2LogN => "n^2 log n",
            ComplexityClass::N3 => "n^3",
        }
    }

    /// The growth function, `g(n)`.
    pub fn g(self, n: f64) -> f64 {
        match self {
            ComplexityClass::N => n,
            ComplexityClass::NLogN => n * n.log2(),
            ComplexityClass::NSqrtN => n * n.sqrt(),
            ComplexityClass::N2 => n * n,
            ComplexityClass::N2LogN => n * n * n.log2(),
            ComplexityClass::N3 => n * n * n,
        }
    }
}

impl Serialize for ComplexityClass {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// What may be said about how time grows with n.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum GrowthReading {
    /// One class: the cross-validated one, whose exponent over the measured n lies in k's
    /// interval, with no other class's there (or cross-validation picking it firmly).
    Class {
        /// The class named.
        class: ComplexityClass,
    },
    /// Classes (two or more) whose exponents all lie in k's interval and that
    /// cross-validation does not firmly tell apart, the cross-validated one among them.
    NotDistinguished {
        /// The classes, in increasing order of growth.
        classes: Vec<ComplexityClass>,
    },
    /// No class: none has its exponent in k's interval, or the one that has is not the one
    /// cross-validation picks. The measured exponent is all that is said.
    ExponentOnly,
}

/// The share of bootstrap replicates whose own cross-validation must pick the class for it to
/// be named over another class whose exponent also lies in k's interval: at 95% the pick is as
/// firm as the interval itself.
pub(crate) const FIRM_SUPPORT: f64 = 0.95;

/// The exponents `class` takes over n in `[lo, hi]`, `[smallest, largest]`: its local slope
/// `d ln g / d ln n`. Exactly k for `n^k`; the log classes run from `k + 1/ln hi` to
/// `k + 1/ln lo` (n log n over n = 1000–16000: 1.10 to 1.14), unbounded when `lo <= 1`.
pub fn nominal_exponents(class: ComplexityClass, lo: f64, hi: f64) -> [f64; 2] {
    let (k, log) = match class {
        ComplexityClass::N => (1.0, false),
        ComplexityClass::NLogN => (1.0, true),
        ComplexityClass::NSqrtN => (1.5, false),
        ComplexityClass::N2 => (2.0, false),
        ComplexityClass::N2LogN => (2.0, true),
        ComplexityClass::N3 => (3.0, false),
    };
    if !log {
        return [k, k];
    }
    let slope = |n: f64| {
        if n > 1.0 {
            k + 1.0 / n.ln()
        } else {
            f64::INFINITY
        }
    };
    [slope(hi), slope(lo)]
}

/// The classes whose exponents over `[lo, hi]` meet k's 95% interval, slowest-growing first.
fn consistent(exponent: &Estimate, lo: f64, hi: f64) -> Vec<ComplexityClass> {
    ComplexityClass::ALL
        .into_iter()
        .filter(|&c| {
            let [a, b] = nominal_exponents(c, lo, hi);
            a <= exponent.ci95[1] && exponent.ci95[0] <= b
        })
        .collect()
}

/// The reading of a fit over n in `[lo, hi]`: `exponent` is the free power law's k,
/// `selected` the class cross-validation picked and `support` the share of bootstrap
/// replicates that picked it too.
pub(crate) fn read(
    exponent: &Estimate,
    selected: ComplexityClass,
    support: f64,
    lo: f64,
    hi: f64,
) -> GrowthReading {
    let fits = consistent(exponent, lo, hi);
    if !fits.contains(&selected) {
        // No class fits k, or cross-validation prefers one that k excludes: the two
        // disagree, and naming either would contradict the other.
        return GrowthReading::ExponentOnly;
    }
    if fits.len() == 1 || support >= FIRM_SUPPORT {
        return GrowthReading::Class { class: selected };
    }
    GrowthReading::NotDistinguished { classes: fits }
}

/// The note that says why `reading` names fewer than one class, for the fit's notes; `None`
/// when it names one.
pub(crate) fn note(
    reading: &GrowthReading,
    exponent: &Estimate,
    lo: f64,
    hi: f64,
) -> Option<String> {
    let [a, b] = exponent.ci95;
    let names = |classes: &[ComplexityClass]| listed(classes, "and");
    match reading {
        GrowthReading::Class { .. } => None,
        GrowthReading::NotDistinguished { classes } => Some(format!(
            "k's 95% CI [{a:.3}, {b:.3}] holds the exponents of {} over n = {lo}–{hi}, \
             and cross-validation does not pick one firmly: widen the range of n to tell \
             them apart",
            names(classes)
        )),
        GrowthReading::ExponentOnly => Some(match consistent(exponent, lo, hi).as_slice() {
            [] => format!(
                "no complexity class grows over n = {lo}–{hi} with an exponent in k's 95% CI \
                 [{a:.3}, {b:.3}]: the growth is the measured exponent alone"
            ),
            fits => format!(
                "k's 95% CI [{a:.3}, {b:.3}] holds the exponent of {} over n = {lo}–{hi}, but \
                 cross-validation prefers another class: the two disagree, so no class is \
                 named and the growth is the measured exponent alone",
                names(fits)
            ),
        }),
    }
}

/// "n or n log n", "n^1.5, n^2 or n^2 log n".
pub(crate) fn either(classes: &[ComplexityClass]) -> String {
    listed(classes, "or")
}

/// The classes' names as a list whose last two `word` joins.
fn listed(classes: &[ComplexityClass], word: &str) -> String {
    let names: Vec<&str> = classes.iter().map(|c| c.name()).collect();
    match names.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} {word} {last}", rest.join(", ")),
        _ => names.concat(),
    }
}

impl GrowthReading {
    /// The class named, if exactly one is.
    pub fn class(&self) -> Option<ComplexityClass> {
        match self {
            GrowthReading::Class { class } => Some(*class),
            _ => None,
        }
    }

    /// How a table or legend says it, with `k` the measured exponent: "n^2", "n or n log n
    /// (not distinguished at these n)", "n^1.98 (no class within its CI)".
    pub fn text(&self, k: f64) -> String {
        match self {
            GrowthReading::Class { class } => class.name().to_string(),
            GrowthReading::NotDistinguished { classes } => {
                format!("{} (not distinguished at these n)", either(classes))
            }
            GrowthReading::ExponentOnly => format!("n^{k:.2} (no class within its CI)"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ComplexityClass::*;

    fn k(lo: f64, hi: f64) -> Estimate {
        Estimate {
            estimate: 0.5 * (lo + hi),
            ci95: [lo, hi],
        }
    }

    #[test]
    fn a_log_class_spans_its_local_exponents_over_the_range() {
        let [a, b] = nominal_exponents(NLogN, 1000.0, 16000.0);
        assert!((a - (1.0 + 1.0 / 16000f64.ln())).abs() < 1e-12);
        assert!((b - (1.0 + 1.0 / 1000f64.ln())).abs() < 1e-12);
        assert_eq!(nominal_exponents(N2, 10.0, 1e6), [2.0, 2.0]);
        assert_eq!(nominal_exponents(N2LogN, 1.0, 10.0)[1], f64::INFINITY);
    }

    #[test]
    fn a_class_outside_the_exponent_interval_is_never_named() {
        // "n log n (n^0.79)": cross-validation picked n log n, k says 0.79.
        let r = read(&k(0.75, 0.83), NLogN, 1.0, 1000.0, 16000.0);
        assert_eq!(r, GrowthReading::ExponentOnly);
        assert_eq!(r.text(0.79), "n^0.79 (no class within its CI)");
        // k = 1.98 [1.978, 1.984]: n² has exactly 2, outside; nothing else fits either.
        let r = read(&k(1.978, 1.984), N2, 1.0, 250.0, 32000.0);
        assert_eq!(r, GrowthReading::ExponentOnly);
        // The exponent fits n log n only, but cross-validation prefers n: they disagree.
        let r = read(&k(1.10, 1.12), N, 0.6, 1000.0, 16000.0);
        assert_eq!(r, GrowthReading::ExponentOnly);
    }

    #[test]
    fn one_class_is_named_where_the_exponent_and_cross_validation_agree() {
        let r = read(&k(1.99, 2.01), N2, 0.8, 250.0, 32000.0);
        assert_eq!(r, GrowthReading::Class { class: N2 });
        assert_eq!(r.text(2.0), "n^2");
        let r = read(&k(1.11, 1.13), NLogN, 0.9, 1000.0, 16000.0);
        assert_eq!(r.class(), Some(NLogN));
    }

    #[test]
    fn two_classes_in_the_interval_are_both_named_unless_the_pick_is_firm() {
        let wide = k(0.95, 1.2);
        let r = read(&wide, NLogN, 0.6, 1000.0, 16000.0);
        assert_eq!(
            r,
            GrowthReading::NotDistinguished {
                classes: vec![N, NLogN]
            }
        );
        assert_eq!(r.text(1.05), "n or n log n (not distinguished at these n)");
        assert_eq!(r.class(), None);
        let r = read(&wide, N, 0.97, 1000.0, 16000.0);
        assert_eq!(r, GrowthReading::Class { class: N });
        // Three classes in a wide interval: all three are named.
        let r = read(&k(1.38, 2.14), N2, 0.7, 500.0, 4000.0);
        assert_eq!(
            r.text(1.85),
            "n^1.5, n^2 or n^2 log n (not distinguished at these n)"
        );
        let json = serde_json::to_value(&r).unwrap();
        assert_eq!(json["kind"], "not-distinguished");
        assert_eq!(json["classes"][2], "n^2 log n");
    }
}
