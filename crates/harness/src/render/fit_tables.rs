//! The readable tables of a fit (`nbody-bench fit`): the points with their intervals, then
//! the model's parameters, its goodness of fit and the notes, as text for a terminal.

use super::tables::{Align, Table};
use crate::fit::{CiMethod, ComplexityClass, Input, PowerFit, StrongFit, WeakFit};
use crate::units::{Duration, Number, WithCi};
use std::fmt::Write;

fn r2(r2: Option<f64>) -> String {
    r2.map_or("-".to_string(), |r| format!("{r:.4}"))
}

fn header(
    s: &mut String,
    title: &str,
    file: &str,
    inputs: &[Input],
    what: &str,
    method: CiMethod,
    n: usize,
) {
    let samples: usize = inputs.iter().map(|i| i.samples).sum();
    let _ = writeln!(
        s,
        "{title} fit of {file}: {} {what}, {samples} samples; 95% intervals from {n} bootstrap \
         replicates, {}",
        inputs.len(),
        method.describe()
    );
}

fn notes(s: &mut String, notes: &[String]) {
    for n in notes {
        let _ = writeln!(s, "note: {n}");
    }
}

/// The Amdahl fit of `file`: its points, serial fraction, T1, the Karp-Flatt trend and the
/// overhead terms tried.
pub fn strong(file: &str, fit: &StrongFit) -> String {
    let mut s = String::new();
    let s = &mut s;
    header(
        s,
        "Amdahl",
        file,
        &fit.inputs,
        "thread counts",
        fit.ci_method,
        fit.resamples,
    );
    let _ = writeln!(s, "\n{}", strong_points(fit).text().trim_end());
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "serial fraction f   {}{}",
        WithCi::of(&fit.serial_fraction, Number),
        if fit.clamped {
            " (clamped to [0, 1])"
        } else {
            ""
        }
    );
    let _ = writeln!(s, "T1                  {}", WithCi::of(&fit.t1, Duration));
    let _ = writeln!(
        s,
        "max speedup 1/f     {}",
        WithCi::of(&fit.max_speedup, Number)
    );
    let _ = writeln!(
        s,
        "fit of T(p)         r2 {}, SMAPE {:.2}%",
        r2(fit.goodness.r2),
        fit.goodness.smape_percent
    );
    let trend = &fit.karp_flatt_trend;
    let slope = trend
        .slope_per_doubling
        .as_ref()
        .map_or(String::new(), |s| {
            format!(" (slope per doubling of p {})", WithCi::of(s, Number))
        });
    let _ = writeln!(
        s,
        "Karp-Flatt trend    {}{slope}: {}",
        trend.verdict.name(),
        trend.meaning
    );
    overhead(s, fit);
    notes(s, &fit.notes);
    std::mem::take(s)
}

/// Each thread count: its median, speedup, efficiency, Karp-Flatt e(p) and the speedup over
/// the calibrated ceiling.
fn strong_points(fit: &StrongFit) -> Table {
    let r = Align::Right;
    let header = [
        "p",
        "median",
        "speedup [95% CI]",
        "efficiency",
        "Karp-Flatt e(p)",
        "of the ceiling",
    ];
    let mut t = Table::new(header).aligned([r, r, r, r, r, Align::Default]);
    for pt in &fit.points {
        let e = fit.karp_flatt.iter().find(|k| k.p == pt.p);
        let ceiling = match (pt.ceiling, pt.speedup_vs_ceiling) {
            (Some(c), Some(rel)) => format!("{} of {c:.2}x", WithCi::of(&rel, Number)),
            _ => String::new(),
        };
        t.row([
            pt.p.to_string(),
            Duration(pt.median_s).to_string(),
            WithCi::of(&pt.speedup, Number).to_string(),
            WithCi::of(&pt.efficiency, Number).to_string(),
            e.map_or("-".to_string(), |k| WithCi::of(&k.e, Number).to_string()),
            ceiling,
        ]);
    }
    t
}

/// The overhead terms tried beside Amdahl's law, and the one kept.
fn overhead(s: &mut String, fit: &StrongFit) {
    let loo: Vec<String> = fit
        .overhead
        .candidates
        .iter()
        .map(|c| {
            let name = c.term.map_or("amdahl", |t| t.name());
            let smape = c
                .loo_smape_percent
                .map_or("-".to_string(), |s| format!("{s:.2}%"));
            format!("{name} {smape}")
        })
        .collect();
    let _ = match &fit.overhead.kept {
        Some(k) => writeln!(
            s,
            "overhead term       {} kept: c = {} s, f with it {} (leave-one-out SMAPE: {})",
            k.term.name(),
            WithCi::of(&k.coefficient, Number),
            WithCi::of(&k.serial_fraction, Number),
            loo.join(", ")
        ),
        None => writeln!(
            s,
            "overhead terms      none kept (leave-one-out SMAPE: {})",
            loo.join(", ")
        ),
    };
}

/// The Gustafson fit of `file`: its points, serial fraction and cost model.
pub fn weak(file: &str, fit: &WeakFit) -> String {
    let mut s = String::new();
    let s = &mut s;
    header(
        s,
        "Gustafson",
        file,
        &fit.inputs,
        "worker counts",
        fit.ci_method,
        fit.resamples,
    );
    let r = Align::Right;
    let header = [
        "p",
        "median",
        "efficiency T1/T(p)",
        "scaled speedup",
        "n (work per worker ratio)",
    ];
    let mut table = Table::new(header).aligned([r, r, r, r, Align::Default]);
    for (i, input) in fit.inputs.iter().enumerate() {
        let work = fit.work_per_worker.as_ref();
        table.row([
            input.x.to_string(),
            Duration(input.median).to_string(),
            WithCi::of(&fit.efficiency[i].e, Number).to_string(),
            WithCi::of(&fit.scaled_speedup[i].s, Number).to_string(),
            work.map_or(String::new(), |w| format!("{} ({:.3})", w[i].n, w[i].ratio)),
        ]);
    }
    let _ = writeln!(s, "\n{}", table.text().trim_end());
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "serial fraction     alpha = {}{}  (S = p - alpha (p - 1))",
        WithCi::of(&fit.serial_fraction, Number),
        if fit.clamped {
            " (clamped to [0, 1])"
        } else {
            ""
        }
    );
    if let Some(cost) = fit.cost_model {
        let _ = writeln!(s, "cost model          g(n) = {}", cost.name());
    }
    let _ = writeln!(
        s,
        "fit of S(p)         r2 {}, SMAPE {:.2}%",
        r2(fit.goodness.r2),
        fit.goodness.smape_percent
    );
    notes(s, &fit.notes);
    std::mem::take(s)
}

/// The power-law fit of `file`: its points, exponent, the selected complexity class and every
/// candidate class's leave-one-out error.
pub fn power(file: &str, fit: &PowerFit) -> String {
    let mut s = String::new();
    let s = &mut s;
    header(
        s,
        "Power-law",
        file,
        &fit.inputs,
        "sizes",
        fit.ci_method,
        fit.resamples,
    );
    let r = Align::Right;
    let mut table = Table::new(["n", "median", "samples"]).aligned([r, r, r]);
    for input in &fit.inputs {
        let median = Duration(input.median).to_string();
        table.row([input.x.to_string(), median, input.samples.to_string()]);
    }
    let _ = writeln!(s, "\n{}", table.text().trim_end());
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "exponent k          {}  (T = c*n^k)",
        WithCi::of(&fit.exponent, Number)
    );
    let _ = writeln!(
        s,
        "c                   {} s; log-log r2 {}",
        WithCi::of(&fit.coefficient, Number),
        r2(fit.power_law_goodness.r2)
    );
    let sel = &fit.selected;
    let model = if sel.with_constant {
        format!(
            "a + c*{}, a = {} s",
            sel.class.name(),
            WithCi::of(&sel.constant, Number)
        )
    } else {
        format!("c*{}", sel.class.name())
    };
    let _ = writeln!(s, "growth              {}", fit.growth());
    let _ = writeln!(
        s,
        "best model          {model}, c = {}; leave-one-out SMAPE {:.2}%, picked by {:.0}% of \
         bootstrap replicates",
        WithCi::of(&sel.coefficient, Number),
        sel.loo_smape_percent,
        100.0 * sel.support
    );
    let header = ["class", "c*g(n)", "a + c*g(n)", "(leave-one-out SMAPE)"];
    let mut table = Table::new(header).aligned([Align::Default, r, r, Align::Default]);
    for class in ComplexityClass::ALL {
        let cell = |with_constant: bool| {
            fit.candidates
                .iter()
                .find(|c| c.class == class && c.with_constant == with_constant)
                .and_then(|c| {
                    let s = c.loo_smape_percent?;
                    Some(if c.admissible {
                        format!("{s:.2}%")
                    } else {
                        format!("({s:.2}%)")
                    })
                })
                .unwrap_or_else(|| "-".to_string())
        };
        table.row([
            class.name().to_string(),
            cell(false),
            cell(true),
            String::new(),
        ]);
    }
    let _ = writeln!(s, "\n{}", table.text().trim_end());
    let _ = writeln!(
        s,
        "(in parentheses: a negative constant or coefficient; not selectable)"
    );
    notes(s, &fit.notes);
    std::mem::take(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::synthetic::{THREADS, noisy};
    use crate::fit::{fit_power, fit_strong, fit_weak};

    /// Whether some line of `text` starts (after its padding) with `first` and a space.
    fn has_row(text: &str, first: impl std::fmt::Display) -> bool {
        let first = format!("{first} ");
        text.lines().any(|l| l.trim_start().starts_with(&first))
    }

    #[test]
    fn the_amdahl_table_has_a_row_per_thread_count_and_the_model() {
        let samples = noisy(&THREADS, 6, 0.02, 1, |p| 0.1 + 0.9 / p);
        let text = strong("strong.csv", &fit_strong(&samples, &[], 1).unwrap());
        assert!(text.starts_with("Amdahl fit of strong.csv: 5 thread counts, 30 samples"));
        assert!(THREADS.iter().all(|&p| has_row(&text, p)), "{text}");
        for line in [
            "serial fraction f",
            "max speedup 1/f",
            "Karp-Flatt trend",
            "overhead term",
        ] {
            assert!(text.contains(line), "no {line:?} in:\n{text}");
        }
    }

    #[test]
    fn the_gustafson_and_power_tables_have_their_rows() {
        let samples = noisy(&[1.0, 2.0, 4.0, 8.0], 5, 0.02, 2, |p| 1.0 + 0.05 * p);
        let text = weak("weak.csv", &fit_weak(&samples, 2).unwrap());
        assert!(
            text.starts_with("Gustafson fit of weak.csv: 4 worker counts"),
            "{text}"
        );
        assert!([1, 2, 4, 8].iter().all(|p| has_row(&text, p)), "{text}");
        assert!(text.contains("serial fraction     alpha = "), "{text}");
        let sizes = [1e3, 2e3, 4e3, 8e3, 1.6e4];
        let samples = noisy(&sizes, 4, 0.02, 3, |n| 2e-9 * n * n);
        let text = power("sizes.csv", &fit_power(&samples, 3).unwrap());
        assert!(
            text.starts_with("Power-law fit of sizes.csv: 5 sizes"),
            "{text}"
        );
        assert!(sizes.iter().all(|&n| has_row(&text, n)), "{text}");
        let classes = ComplexityClass::ALL.iter();
        assert!(classes.clone().all(|c| has_row(&text, c.name())), "{text}");
    }
}
