//! Scaling figures: cost against n, and speedup, efficiency and Karp-Flatt against the workers
//! p (`workers` names what p counts: "threads", "ranks", …).

use super::{KernelSeries, extent, kernel_chart};
use crate::plot::palette::REFERENCE_INDEX;
use crate::plot::spec::{Axis, Chart, RefLine, Series, SeriesStyle, Unit};

/// Time per step against n on log-log axes, one colour per kernel, fits dashed.
pub fn time_per_step(kernels: &[KernelSeries], caption: &str) -> Chart {
    let x = Axis::log("particles n").unit(Unit::Count);
    let y = Axis::log("time per step").unit(Unit::Seconds);
    kernel_chart("Time per step vs particle count", x, y, kernels, caption)
}

/// Speedup T(1)/T(p) against threads with the ideal line S = p, the hardware ceiling measured
/// by calibration as `(p, ceiling)` points, and each kernel's fit (e.g. Amdahl) with its band.
pub fn speedup(
    kernels: &[KernelSeries],
    ceiling: &[(f64, f64)],
    workers: &str,
    caption: &str,
) -> Chart {
    let x = Axis::linear(format!("{workers} p")).unit(Unit::Count);
    let y = Axis::linear("speedup T(1) / T(p)").starting_at_zero();
    let title = format!("Strong scaling: speedup vs {workers}");
    let mut chart = kernel_chart(&title, x, y, kernels, caption);
    let measured = kernels.iter().flat_map(|k| k.measured.iter().map(|m| m.x));
    let fits = kernels.iter().flat_map(|k| &k.fit);
    if let Some((lo, hi)) = extent(measured.chain(fits.flat_map(|f| f.points.iter().map(|p| p.0))))
    {
        let ideal = Series::from_xy("ideal S = p", [(lo, lo), (hi, hi)], SeriesStyle::Dashed)
            .color(REFERENCE_INDEX);
        chart.series.insert(0, ideal);
    }
    if !ceiling.is_empty() {
        let series = Series::from_xy(
            "hardware ceiling (calibrated)",
            ceiling.iter().copied(),
            SeriesStyle::LineMarkers,
        );
        chart.series.insert(0, series.color(REFERENCE_INDEX));
    }
    chart
}

fn ideal_at_one() -> RefLine {
    RefLine {
        label: "ideal".into(),
        y: 1.0,
        color: None,
        dashed: true,
    }
}

/// Parallel efficiency S(p)/p against threads, with the ideal 1.
pub fn efficiency(kernels: &[KernelSeries], workers: &str, caption: &str) -> Chart {
    let x = Axis::linear(format!("{workers} p")).unit(Unit::Count);
    let y = Axis::linear("parallel efficiency S(p) / p").starting_at_zero();
    let title = format!("Strong scaling: parallel efficiency vs {workers}");
    let mut chart = kernel_chart(&title, x, y, kernels, caption);
    chart.hlines.push(ideal_at_one());
    chart
}

/// Weak-scaling efficiency T(1)/T(p) against the workers (n grows with p), with the ideal 1.
pub fn weak_efficiency(kernels: &[KernelSeries], workers: &str, caption: &str) -> Chart {
    let one = match workers {
        "threads" => "thread",
        "ranks" => "rank",
        _ => "worker",
    };
    let x = Axis::linear(format!("{workers} p (work per {one} held constant)")).unit(Unit::Count);
    let y = Axis::linear("weak-scaling efficiency T(1) / T(p)").starting_at_zero();
    let title = format!("Weak scaling: efficiency vs {workers}");
    let mut chart = kernel_chart(&title, x, y, kernels, caption);
    chart.hlines.push(ideal_at_one());
    chart
}

/// The Karp-Flatt experimentally determined serial fraction e(p) against threads (p ≥ 2).
/// A rising e(p) points to parallel overhead, a flat one to inherently serial work.
pub fn karp_flatt(kernels: &[KernelSeries], workers: &str, caption: &str) -> Chart {
    let x = Axis::linear(format!("{workers} p")).unit(Unit::Count);
    let y = Axis::linear("serial fraction e(p)");
    let title = format!("Karp-Flatt serial fraction vs {workers}");
    let mut chart = kernel_chart(&title, x, y, kernels, caption);
    chart.hlines.push(RefLine {
        label: String::new(),
        y: 0.0,
        color: None,
        dashed: false,
    });
    chart
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::figures::{Curve, Measured};

    #[test]
    fn speedup_has_ideal_ceiling_and_fit() {
        let amdahl = Curve::new("Amdahl f = 0.1", vec![(1.0, 1.0), (4.0, 3.1)]);
        let kernels = [KernelSeries::new(
            "per-thread",
            vec![Measured::new(1.0, 1.0), Measured::new(4.0, 2.0)],
        )
        .with_fit(amdahl)];
        let chart = speedup(&kernels, &[(1.0, 1.0), (2.0, 1.1)], "threads", "m");
        let labels: Vec<&str> = chart.series.iter().map(|s| s.label.as_str()).collect();
        assert_eq!(
            labels,
            [
                "hardware ceiling (calibrated)",
                "ideal S = p",
                "per-thread",
                "Amdahl f = 0.1"
            ]
        );
        assert_eq!(chart.series[1].points.len(), 2);
        assert_eq!(chart.series[1].points[1].y, 4.0);
    }

    #[test]
    fn no_measurements_means_no_ideal_line() {
        assert!(speedup(&[], &[], "threads", "").series.is_empty());
        assert_eq!(efficiency(&[], "threads", "").hlines[0].y, 1.0);
    }

    #[test]
    fn axes_and_titles_name_the_workers() {
        let weak = weak_efficiency(&[], "ranks", "");
        assert_eq!(weak.x.label, "ranks p (work per rank held constant)");
        assert_eq!(weak.title, "Weak scaling: efficiency vs ranks");
        let mixed = weak_efficiency(&[], "workers (threads × ranks)", "");
        assert_eq!(
            mixed.x.label,
            "workers (threads × ranks) p (work per worker held constant)"
        );
        assert_eq!(speedup(&[], &[], "ranks", "").x.label, "ranks p");
        assert_eq!(karp_flatt(&[], "threads", "").x.label, "threads p");
    }
}
