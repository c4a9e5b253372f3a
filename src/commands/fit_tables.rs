//! The readable tables `fit` prints.

use super::fmt_ns;
use crate::fit::{CiMethod, ComplexityClass, Estimate, Input, PowerFit, StrongFit, WeakFit};

/// A number in a width-friendly form: fixed below 1e4, scientific far from 1.
fn num(x: f64) -> String {
    if x.is_infinite() {
        if x > 0.0 { "inf" } else { "-inf" }.to_string()
    } else if x != 0.0 && (x.abs() >= 1e4 || x.abs() < 1e-3) {
        format!("{x:.3e}")
    } else {
        format!("{x:.4}")
    }
}

fn est(e: &Estimate) -> String {
    format!(
        "{} [{}, {}]",
        num(e.estimate),
        num(e.ci95[0]),
        num(e.ci95[1])
    )
}

fn est_s(e: &Estimate) -> String {
    let s = |t: f64| fmt_ns(t * 1e9);
    format!("{} [{}, {}]", s(e.estimate), s(e.ci95[0]), s(e.ci95[1]))
}

fn r2(r2: Option<f64>) -> String {
    r2.map_or("-".to_string(), |r| format!("{r:.4}"))
}

fn header(title: &str, file: &str, inputs: &[Input], what: &str, method: CiMethod, n: usize) {
    let samples: usize = inputs.iter().map(|i| i.samples).sum();
    outln!(
        "{title} fit of {file}: {} {what}, {samples} samples; 95% intervals from {n} bootstrap \
         replicates, {}",
        inputs.len(),
        method.describe()
    );
}

fn print_notes(notes: &[String]) {
    for n in notes {
        outln!("note: {n}");
    }
}

pub fn print_strong(file: &str, fit: &StrongFit) {
    header(
        "Amdahl",
        file,
        &fit.inputs,
        "thread counts",
        fit.ci_method,
        fit.resamples,
    );
    outln!(
        "\n{:>6} {:>11}  {:<28} {:<28} Karp-Flatt e(p)",
        "p",
        "median",
        "speedup [95% CI]",
        "efficiency"
    );
    for pt in &fit.points {
        let e = fit
            .karp_flatt
            .iter()
            .find(|k| k.p == pt.p)
            .map_or("-".to_string(), |k| est(&k.e));
        let ceiling = match (pt.ceiling, pt.speedup_vs_ceiling) {
            (Some(c), Some(rel)) => format!("  {} of ceiling {c:.2}x", est(&rel)),
            _ => String::new(),
        };
        let line = format!(
            "{:>6} {:>11}  {:<28} {:<28} {:<28}{ceiling}",
            pt.p,
            fmt_ns(pt.median_s * 1e9),
            est(&pt.speedup),
            est(&pt.efficiency),
            e
        );
        outln!("{}", line.trim_end());
    }
    outln!();
    outln!(
        "serial fraction f   {}{}",
        est(&fit.serial_fraction),
        if fit.clamped {
            " (clamped to [0, 1])"
        } else {
            ""
        }
    );
    outln!("T1                  {}", est_s(&fit.t1));
    outln!("max speedup 1/f     {}", est(&fit.max_speedup));
    outln!(
        "fit of T(p)         r2 {}, SMAPE {:.2}%",
        r2(fit.goodness.r2),
        fit.goodness.smape_percent
    );
    let trend = &fit.karp_flatt_trend;
    let slope = trend
        .slope_per_doubling
        .as_ref()
        .map_or(String::new(), |s| {
            format!(" (slope per doubling of p {})", est(s))
        });
    outln!(
        "Karp-Flatt trend    {}{slope}: {}",
        trend.verdict.name(),
        trend.meaning
    );
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
    match &fit.overhead.kept {
        Some(k) => outln!(
            "overhead term       {} kept: c = {} s, f with it {} (leave-one-out SMAPE: {})",
            k.term.name(),
            est(&k.coefficient),
            est(&k.serial_fraction),
            loo.join(", ")
        ),
        None => outln!(
            "overhead terms      none kept (leave-one-out SMAPE: {})",
            loo.join(", ")
        ),
    }
    print_notes(&fit.notes);
}

pub fn print_weak(file: &str, fit: &WeakFit) {
    header(
        "Gustafson",
        file,
        &fit.inputs,
        "worker counts",
        fit.ci_method,
        fit.resamples,
    );
    outln!(
        "\n{:>6} {:>11}  {:<28} {:<28} n (work per worker ratio)",
        "p",
        "median",
        "efficiency T1/T(p)",
        "scaled speedup"
    );
    for (i, input) in fit.inputs.iter().enumerate() {
        let work = fit
            .work_per_worker
            .as_ref()
            .map_or(String::new(), |w| format!("{} ({:.3})", w[i].n, w[i].ratio));
        let line = format!(
            "{:>6} {:>11}  {:<28} {:<28} {work}",
            input.x,
            fmt_ns(input.median * 1e9),
            est(&fit.efficiency[i].e),
            est(&fit.scaled_speedup[i].s),
        );
        outln!("{}", line.trim_end());
    }
    outln!();
    outln!(
        "serial fraction     alpha = {}{}  (S = p - alpha (p - 1))",
        est(&fit.serial_fraction),
        if fit.clamped {
            " (clamped to [0, 1])"
        } else {
            ""
        }
    );
    if let Some(cost) = fit.cost_model {
        outln!("cost model          g(n) = {}", cost.name());
    }
    outln!(
        "fit of S(p)         r2 {}, SMAPE {:.2}%",
        r2(fit.goodness.r2),
        fit.goodness.smape_percent
    );
    print_notes(&fit.notes);
}

pub fn print_power(file: &str, fit: &PowerFit) {
    header(
        "Power-law",
        file,
        &fit.inputs,
        "sizes",
        fit.ci_method,
        fit.resamples,
    );
    outln!("\n{:>12} {:>11} {:>8}", "n", "median", "samples");
    for input in &fit.inputs {
        outln!(
            "{:>12} {:>11} {:>8}",
            input.x,
            fmt_ns(input.median * 1e9),
            input.samples
        );
    }
    outln!();
    outln!("exponent k          {}  (T = c*n^k)", est(&fit.exponent));
    outln!(
        "c                   {} s; log-log r2 {}",
        est(&fit.coefficient),
        r2(fit.power_law_goodness.r2)
    );
    let sel = &fit.selected;
    let model = if sel.with_constant {
        format!("a + c*{}, a = {} s", sel.class.name(), est(&sel.constant))
    } else {
        format!("c*{}", sel.class.name())
    };
    outln!(
        "complexity class    {} ({model}, c = {}); leave-one-out SMAPE {:.2}%, chosen by {:.0}% \
         of bootstrap replicates",
        sel.class.name(),
        est(&sel.coefficient),
        sel.loo_smape_percent,
        100.0 * sel.support
    );
    outln!(
        "\n{:<12} {:>16} {:>16}   (leave-one-out SMAPE)",
        "class",
        "c*g(n)",
        "a + c*g(n)"
    );
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
        outln!(
            "{:<12} {:>16} {:>16}",
            class.name(),
            cell(false),
            cell(true)
        );
    }
    outln!("(in parentheses: a negative constant or coefficient; not selectable)");
    print_notes(&fit.notes);
}
