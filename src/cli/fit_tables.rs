//! The readable tables `fit` prints.

use nbody_harness::fit::{CiMethod, ComplexityClass, Input, PowerFit, StrongFit, WeakFit};
use nbody_harness::render::tables::{Align, Table};
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
    outln!("\n{}", strong_points(fit).text().trim_end());
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
    print_overhead(fit);
    print_notes(&fit.notes);
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
fn print_overhead(fit: &StrongFit) {
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
    outln!("\n{}", table.text().trim_end());
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
    let r = Align::Right;
    let mut table = Table::new(["n", "median", "samples"]).aligned([r, r, r]);
    for input in &fit.inputs {
        let median = Duration(input.median).to_string();
        table.row([input.x.to_string(), median, input.samples.to_string()]);
    }
    outln!("\n{}", table.text().trim_end());
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
    outln!("\n{}", table.text().trim_end());
    outln!("(in parentheses: a negative constant or coefficient; not selectable)");
    print_notes(&fit.notes);
}
