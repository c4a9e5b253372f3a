//! Renders every figure of `nbody_harness::plot::figures` from made-up but realistic numbers into
//! `target/plot-preview/` (or the directory given as the first argument), to look at them.
//!
//!     cargo run --release --example plot_preview

use nbody_harness::plot::figures::{
    self, CommTimes, Curve, KernelSeries, Measured, Percentiles, PhaseTimes, ThetaPoint, ThetaSweep,
};
use nbody_harness::plot::{self, Axis, Chart, Scale, Unit};
use std::path::PathBuf;

const CAPTION: &str =
    "AMD EPYC 9R14 (2 logical CPUs), rustc 1.95.0, commit bd7a039 (dirty), release, 2026-11-22";

/// A deterministic wobble of a few percent, so the points do not sit exactly on the fits.
fn wobble(i: usize) -> f64 {
    1.0 + 0.04 * ((i as f64 * 2.3).sin())
}

fn with_ci(x: f64, median: f64) -> Measured {
    Measured::with_ci(x, median, median * 0.97, median * 1.04)
}

fn cost_series(name: &str, ns: &[f64], cost: impl Fn(f64) -> f64, exponent: f64) -> KernelSeries {
    let measured = ns
        .iter()
        .enumerate()
        .map(|(i, &n)| with_ci(n, cost(n) * wobble(i)))
        .collect();
    let xs = figures::grid(ns[0], ns[ns.len() - 1], 24, Scale::Log);
    let fit = Curve::from_fn(format!("{name}: T ∝ n^{exponent:.2}"), &xs, cost);
    KernelSeries::new(name, measured).with_fit(fit)
}

fn scaling_kernels() -> Vec<KernelSeries> {
    let ps: [f64; 4] = [1.0, 2.0, 3.0, 4.0];
    let amdahl = |f: f64| move |p: f64| 1.0 / (f + (1.0 - f) / p);
    let series = |name: &str, f: f64, cap: f64| {
        let measured = ps
            .iter()
            .enumerate()
            .map(|(i, &p)| {
                let s = amdahl(f)(p.min(2.0)) * cap.powf((p.min(2.0) - 1.0).min(1.0)) * wobble(i);
                Measured::with_ci(p, s, s * 0.96, s * 1.03).oversubscribed(p > 2.0)
            })
            .collect();
        let xs = figures::grid(1.0, 4.0, 16, Scale::Linear);
        let band = xs
            .iter()
            .map(|&p| (p, amdahl(f + 0.05)(p), amdahl((f - 0.05).max(0.0))(p)))
            .collect();
        let fit =
            Curve::from_fn(format!("{name}: Amdahl f = {f:.2}"), &xs, amdahl(f)).with_band(band);
        KernelSeries::new(name, measured).with_fit(fit)
    };
    vec![
        series("per-thread", 0.08, 0.6),
        series("cell-list", 0.25, 0.55),
    ]
}

fn ratio_series(kernels: &[KernelSeries], f: impl Fn(f64, f64) -> f64) -> Vec<KernelSeries> {
    kernels
        .iter()
        .map(|k| {
            let measured = k
                .measured
                .iter()
                .map(|m| {
                    let (lo, hi) = m.ci.unwrap_or((m.median, m.median));
                    Measured::with_ci(m.x, f(m.x, m.median), f(m.x, lo), f(m.x, hi))
                        .oversubscribed(m.oversubscribed)
                })
                .collect();
            KernelSeries::new(k.name.as_str(), measured)
        })
        .collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("target/plot-preview"));
    let small = [500.0, 1000.0, 2000.0, 4000.0, 8000.0, 16000.0];
    let large = [1e3, 1e4, 1e5, 1e6];
    let cost = vec![
        cost_series("naive", &small, |n| 2.1e-10 * n * n, 2.0),
        cost_series("symmetric", &small, |n| 1.3e-10 * n * n, 2.0),
        cost_series("cell-list", &large, |n| 1.4e-8 * n, 1.0),
        cost_series("octree", &large, |n| 9e-8 * n * n.log2() / 10.0, 1.08),
    ];
    let mut rendered = vec![plot::draw(
        &figures::time_per_step(&cost, CAPTION),
        &dir,
        "time-per-step",
    )?];

    let kernels = scaling_kernels();
    let ceiling = [(1.0, 1.0), (2.0, 1.08)];
    rendered.push(plot::draw(
        &figures::speedup(&kernels, &ceiling, "threads", CAPTION),
        &dir,
        "speedup",
    )?);
    let efficiency = ratio_series(&kernels, |p, s| s / p);
    rendered.push(plot::draw(
        &figures::efficiency(&efficiency, "threads", CAPTION),
        &dir,
        "efficiency",
    )?);
    let weak = ratio_series(&kernels, |p, s| (s / p).powf(0.7));
    rendered.push(plot::draw(
        &figures::weak_efficiency(&weak, "threads", CAPTION),
        &dir,
        "weak-efficiency",
    )?);
    let karp: Vec<KernelSeries> =
        ratio_series(&kernels, |p, s| (1.0 / s - 1.0 / p) / (1.0 - 1.0 / p))
            .into_iter()
            .map(|mut k| {
                k.measured.retain(|m| m.x >= 2.0);
                k
            })
            .collect();
    rendered.push(plot::draw(
        &figures::karp_flatt(&karp, "threads", CAPTION),
        &dir,
        "karp-flatt",
    )?);

    let phase = |case: &str, build, interact, integrate, boundary, communication| PhaseTimes {
        case: case.into(),
        phases: [
            ("force: build", build),
            ("force: interact", interact),
            ("integrate", integrate),
            ("boundary", boundary),
            ("communication", communication),
        ]
        .into_iter()
        .map(|(name, s): (&str, f64)| (name.to_string(), s))
        .collect(),
    };
    let phases = [
        phase(
            "lj-box/cell-list/n=100000/p=1",
            1.1e-4,
            1.2e-3,
            2.0e-4,
            6e-5,
            0.0,
        ),
        phase(
            "lj-box/cell-list/n=100000/p=2",
            1.0e-4,
            6.9e-4,
            1.1e-4,
            6e-5,
            0.0,
        ),
        phase(
            "galaxy/octree/n=100000/p=2/θ=0.5",
            6.0e-3,
            2.4e-2,
            1.5e-4,
            0.0,
            0.0,
        ),
        phase(
            "coulomb/naive/n=4000/ranks=4",
            0.0,
            8.1e-3,
            4.0e-5,
            0.0,
            1.9e-3,
        ),
    ];
    rendered.push(plot::draw_stacked(
        &figures::phase_breakdown(&phases, CAPTION),
        &dir,
        "phases",
    )?);
    rendered.push(plot::draw_stacked(
        &figures::phase_shares(&phases, CAPTION),
        &dir,
        "phase-shares",
    )?);
    let many: Vec<PhaseTimes> = (0..30)
        .map(|i| {
            phase(
                &format!("lj-box/cell-list/n={}/p=2", 1000 * (i + 1)),
                1e-5 * i as f64,
                1e-4 * i as f64,
                2e-5,
                1e-5,
                0.0,
            )
        })
        .collect();
    rendered.push(plot::draw_stacked(
        &figures::phase_breakdown(&many, CAPTION),
        &dir,
        "phases-many",
    )?);

    let pct = |kernel: &str, p50: f64| Percentiles {
        kernel: kernel.into(),
        p50,
        p90: p50 * 1.08,
        p99: p50 * 1.6,
        max: p50 * 4.5,
    };
    let rows = [
        pct("naive", 3.2e-3),
        pct("symmetric", 1.9e-3),
        pct("per-thread", 1.1e-3),
        pct("cell-list", 4.1e-5),
        pct("octree", 2.2e-4),
    ];
    rendered.push(plot::draw(
        &figures::step_percentiles(&rows, CAPTION),
        &dir,
        "percentiles",
    )?);

    let sweep = |name: &str, scale: f64| ThetaSweep {
        name: name.into(),
        points: [0.2, 0.3, 0.5, 0.7, 1.0]
            .iter()
            .map(|&theta: &f64| ThetaPoint {
                setting: format!("θ={theta}"),
                seconds: scale * 0.02 / theta.powf(1.6),
                error: 2e-3 * theta.powf(3.0),
            })
            .collect(),
    };
    let sweeps = [sweep("galaxy n=100k", 1.0), sweep("coulomb n=100k", 1.7)];
    rendered.push(plot::draw(
        &figures::octree_accuracy(&sweeps, CAPTION),
        &dir,
        "octree-accuracy",
    )?);

    let model = |r: f64| 2e-5 + 1.5e-5 * r.log2() + 4e-6 * r;
    let xs = figures::grid(1.0, 16.0, 31, Scale::Linear);
    let band = xs
        .iter()
        .map(|&r| (r, model(r) * 0.8, model(r) * 1.25))
        .collect();
    let comm = CommTimes {
        x: Axis::linear("MPI ranks"),
        measured: [1.0, 2.0, 3.0, 4.0]
            .iter()
            .enumerate()
            .map(|(i, &r)| with_ci(r, model(r) * wobble(i)))
            .collect(),
        predicted: Curve::from_fn("model: α log₂ r + β r", &xs, model).with_band(band),
    };
    rendered.push(plot::draw(
        &figures::comm_time(&comm, CAPTION),
        &dir,
        "comm",
    )?);

    let mut edge = Chart::new(
        "One point, a NaN and a zero on a log axis",
        Axis::log("n").unit(Unit::Count),
        Axis::log("time").unit(Unit::Seconds),
    );
    edge.series.push(plot::Series::from_xy(
        "kernel",
        [(1000.0, 0.0), (2000.0, f64::NAN), (4000.0, 1e-3)],
        plot::SeriesStyle::LineMarkers,
    ));
    rendered.push(plot::draw(&edge.caption(CAPTION), &dir, "edge")?);

    let bytes = CommTimes {
        x: Axis::log("message size").unit(Unit::Bytes),
        measured: [1e3, 1e4, 1e5]
            .iter()
            .enumerate()
            .map(|(i, &b)| with_ci(b, (2e-6 + b / 5e9) * wobble(i)))
            .collect(),
        predicted: Curve::from_fn(
            "model: α + b / bandwidth",
            &figures::grid(1e2, 1e7, 30, Scale::Log),
            |b| 2e-6 + b / 5e9,
        ),
    };
    rendered.push(plot::draw(
        &figures::comm_time(&bytes, CAPTION),
        &dir,
        "comm-bytes",
    )?);
    rendered.push(plot::draw(&figures::time_per_step(&[], ""), &dir, "empty")?);

    for r in rendered {
        println!("{}  {}", r.svg.display(), r.png.display());
    }
    Ok(())
}
