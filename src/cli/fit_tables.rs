//! The readable tables `fit` prints.

use nbody_harness::fit::{CiMethod, ComplexityClass, Input, PowerFit, StrongFit, WeakFit};
use nbody_harness::units::{Duration, Number, WithCi};

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
            .map_or("-".to_string(), |k| WithCi::of(&k.e, Number).to_string());
        let ceiling = match (pt.ceiling, pt.speedup_vs_ceiling) {
            (Some(c), Some(rel)) => format!("  {} of ceiling {c:.2}x", WithCi::of(&rel, Number)),
            _ => String::new(),
        };
        let line = format!(
            "{:>6} {:>11}  {:<28} {:<28} {:<28}{ceiling}",
            pt.p,
            Duration(pt.median_s),
            WithCi::of(&pt.speedup, Number),
            WithCi::of(&pt.efficiency, Number),
            e
        );
        outln!("{}", line.trim_end());
    }
    outln!();
    outln!(
        "serial fraction f   {}{}",
        WithCi::of(&fit.serial_fraction, Number),
        if fit.clamped {
            " (clamped to [0, 1])"
        } else {
            ""
        }
    );
    outln!("T1                  {}", WithCi::of(&fit.t1, Duration));
    outln!(
        "max speedup 1/f     {}",
        WithCi::of(&fit.max_speedup, Number)
    );
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
            format!(" (slope per doubling of p {})", WithCi::of(s, Number))
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
            WithCi::of(&k.coefficient, Number),
            WithCi::of(&k.serial_fraction, Number),
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
            Duration(input.median),
            WithCi::of(&fit.efficiency[i].e, Number),
            WithCi::of(&fit.scaled_speedup[i].s, Number),
        );
        outln!("{}", line.trim_end());
    }
    outln!();
    outln!(
        "serial fraction     alpha = {}{}  (S = p - alpha (p - 1))",
        WithCi::of(&fit.serial_fraction, Number),
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
            Duration(input.median),
            input.samples
        );
    }
    outln!();
    outln!(
        "exponent k          {}  (T = c*n^k)",
        WithCi::of(&fit.exponent, Number)
    );
    outln!(
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
    outln!(
        "complexity class    {} ({model}, c = {}); leave-one-out SMAPE {:.2}%, chosen by {:.0}% \
         of bootstrap replicates",
        sel.class.name(),
        WithCi::of(&sel.coefficient, Number),
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
