//! Every figure renders, for ordinary and for awkward inputs, to a non-empty SVG that carries
//! its texts and a 1000×650 PNG, and nothing else is left in the directory.

use super::figures::{
    self, CommTimes, Curve, KernelSeries, Measured, Percentiles, PhaseTimes, ThetaPoint, ThetaSweep,
};
use super::*;
use std::fs;

const CAPTION: &str = "test machine, commit 0000000";

/// Kernel sets that have broken plotting code before: nothing, an empty series, one point,
/// all-equal values, non-finite values, zero (and a negative band) where a log axis wants
/// positives, and a realistic set with fits and bands.
fn kernel_cases() -> Vec<(&'static str, Vec<KernelSeries>)> {
    let one = Measured::with_ci(1000.0, 1e-3, 9e-4, 1.1e-3);
    let equal = (1..5).map(|i| Measured::new(i as f64, 2e-3)).collect();
    let non_finite = vec![
        Measured::new(f64::NAN, 1.0),
        Measured::new(2.0, f64::NAN),
        Measured::new(4.0, f64::INFINITY),
        Measured::with_ci(8.0, 1.0, f64::NAN, 2.0),
        Measured::new(16.0, 1.5),
    ];
    let zero_fit = Curve::new("fit", vec![(0.0, 0.0), (10.0, 1e-3)])
        .with_band(vec![(0.0, -1.0, 1.0), (10.0, 0.0, 2e-3)]);
    let xs = figures::grid(1.0, 4.0, 8, Scale::Linear);
    let amdahl = |p: f64| 1.0 / (0.1 + 0.9 / p);
    let band = xs
        .iter()
        .map(|&p| (p, 0.9 * amdahl(p), 1.1 * amdahl(p)))
        .collect();
    let realistic = vec![
        KernelSeries::from_rows(
            "naive",
            &[
                (1.0, 1.0, 0.95, 1.05),
                (2.0, 1.8, 1.7, 1.9),
                (4.0, 2.1, 2.0, 2.3),
            ],
        )
        .with_fit(Curve::from_fn("naive: Amdahl f = 0.10", &xs, amdahl).with_band(band)),
        KernelSeries::new(
            "per-thread",
            vec![
                Measured::new(1.0, 1.0),
                Measured::new(4.0, 1.2).oversubscribed(true),
            ],
        ),
    ];
    vec![
        ("no kernels", vec![]),
        ("empty series", vec![KernelSeries::new("k", vec![])]),
        ("one point", vec![KernelSeries::new("k", vec![one])]),
        ("all equal", vec![KernelSeries::new("k", equal)]),
        ("non-finite", vec![KernelSeries::new("k", non_finite)]),
        (
            "zero on log",
            vec![
                KernelSeries::new(
                    "k",
                    vec![Measured::new(0.0, 0.0), Measured::new(10.0, 1e-3)],
                )
                .with_fit(zero_fit),
            ],
        ),
        ("realistic", realistic),
    ]
}

/// The rendered pair exists, is well formed, carries `texts`, and has no company.
fn check(rendered: &Rendered, texts: &[&str]) {
    let svg = fs::read_to_string(&rendered.svg).unwrap();
    assert!(
        svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
        "{}",
        rendered.svg.display()
    );
    for text in texts.iter().filter(|t| !t.is_empty()) {
        let escaped = text
            .replace('&', "&amp;")
            .replace('<', "&lt;")
            .replace('>', "&gt;")
            .replace('"', "&quot;")
            .replace('\'', "&apos;");
        assert!(
            svg.contains(&escaped),
            "{} lacks {text:?}",
            rendered.svg.display()
        );
    }
    let png = fs::read(&rendered.png).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let size = |at: usize| u32::from_be_bytes(png[at..at + 4].try_into().unwrap());
    assert_eq!((size(16), size(20)), (1000, 650));
    let dir = rendered.svg.parent().unwrap();
    let stray: Vec<_> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.starts_with('.') || name.ends_with(".tmp"))
        .collect();
    assert!(stray.is_empty(), "temporary files left: {stray:?}");
}

fn texts(chart: &Chart) -> Vec<&str> {
    vec![
        chart.title.as_str(),
        chart.caption.as_str(),
        chart.x.label.as_str(),
        chart.y.label.as_str(),
    ]
}

#[test]
fn kernel_figures_render_for_every_input() {
    let dir = tempfile::tempdir().unwrap();
    for (case, kernels) in kernel_cases() {
        let charts = [
            ("time", figures::time_per_step(&kernels, CAPTION)),
            (
                "speedup",
                figures::speedup(&kernels, &[(1.0, 1.0), (2.0, 1.08)], CAPTION),
            ),
            (
                "speedup-no-ceiling",
                figures::speedup(&kernels, &[], CAPTION),
            ),
            ("efficiency", figures::efficiency(&kernels, CAPTION)),
            ("weak", figures::weak_efficiency(&kernels, CAPTION)),
            ("karp-flatt", figures::karp_flatt(&kernels, CAPTION)),
        ];
        for (name, chart) in charts {
            let stem = format!("{name}-{}", case.replace(' ', "-"));
            let rendered =
                render(&chart, dir.path(), &stem).unwrap_or_else(|e| panic!("{stem}: {e}"));
            check(&rendered, &texts(&chart));
        }
    }
}

#[test]
fn detail_figures_render_for_every_input() {
    let dir = tempfile::tempdir().unwrap();
    let phase = |case: &str, v: f64| PhaseTimes {
        case: case.into(),
        build: v,
        interact: 10.0 * v,
        integrate: v,
        boundary: f64::NAN,
        communication: -v,
    };
    let pct = |kernel: &str, p50: f64| Percentiles {
        kernel: kernel.into(),
        p50,
        p90: p50,
        p99: 2.0 * p50,
        max: f64::INFINITY,
    };
    let theta = |theta: f64, seconds: f64, error: f64| ThetaPoint {
        theta,
        seconds,
        error,
    };
    let measured = vec![
        Measured::with_ci(1.0, 1e-4, 9e-5, 1.2e-4),
        Measured::new(2.0, 0.0),
    ];
    let predicted = Curve::new("model", vec![(1.0, 1e-4), (8.0, 8e-4)])
        .with_band(vec![(1.0, 5e-5, 2e-4), (8.0, 4e-4, 1.6e-3)]);

    let bar_cases: Vec<Vec<PhaseTimes>> = vec![
        vec![],
        vec![phase("one case", 1e-4)],
        vec![
            phase("zero", 0.0),
            phase(
                "lj-box/cell-list/n=100000/p=2/with/a/very/long/name/indeed",
                2e-3,
            ),
        ],
        vec![phase("nan", f64::NAN)],
    ];
    for (i, cases) in bar_cases.iter().enumerate() {
        for (name, bars) in [
            ("phases", figures::phase_breakdown(cases, CAPTION)),
            ("shares", figures::phase_shares(cases, CAPTION)),
        ] {
            let rendered = render_stacked(&bars, dir.path(), &format!("{name}-{i}")).unwrap();
            check(
                &rendered,
                &[
                    bars.title.as_str(),
                    bars.caption.as_str(),
                    bars.value_label.as_str(),
                ],
            );
        }
    }

    let charts = [
        figures::step_percentiles(&[], CAPTION),
        figures::step_percentiles(&[pct("naive", 1e-3)], CAPTION),
        figures::step_percentiles(
            &[
                pct("naive", 1e-3),
                pct("octree", 0.0),
                pct("cell-list", f64::NAN),
            ],
            CAPTION,
        ),
        figures::octree_accuracy(&[], CAPTION),
        figures::octree_accuracy(
            &[ThetaSweep {
                name: "galaxy".into(),
                points: vec![theta(0.5, 1e-2, 3e-4)],
            }],
            CAPTION,
        ),
        figures::octree_accuracy(
            &[ThetaSweep {
                name: "galaxy".into(),
                points: vec![
                    theta(0.0, 1e-1, 0.0),
                    theta(0.5, f64::NAN, 3e-4),
                    theta(1.0, 1e-3, 1e-2),
                ],
            }],
            CAPTION,
        ),
        figures::comm_time(
            &CommTimes {
                x: Axis::linear("ranks").unit(Unit::Count),
                measured: measured.clone(),
                predicted: predicted.clone(),
            },
            CAPTION,
        ),
        figures::comm_time(
            &CommTimes {
                x: Axis::log("bytes").unit(Unit::Bytes),
                measured,
                predicted,
            },
            CAPTION,
        ),
        figures::comm_time(
            &CommTimes {
                x: Axis::linear("ranks"),
                measured: vec![],
                predicted: Curve::new("model", vec![]),
            },
            CAPTION,
        ),
    ];
    for (i, chart) in charts.iter().enumerate() {
        let rendered = render(chart, dir.path(), &format!("detail-{i}")).unwrap();
        check(&rendered, &texts(chart));
    }
}

#[test]
fn a_hand_built_chart_with_every_element_renders() {
    let mut chart = Chart::new(
        "Everything & more <at once>",
        Axis::log("x axis"),
        Axis::linear("y axis").range(-1.0, 5.0),
    )
    .caption("caption line");
    let points = vec![
        Point::new(1.0, 1.0).err(0.5, 1.5),
        Point::new(10.0, 9.0).hollow(true).label("off the top"),
        Point::new(100.0, 3.0).label("θ=0.5"),
    ];
    for style in [
        SeriesStyle::Line,
        SeriesStyle::Markers,
        SeriesStyle::LineMarkers,
        SeriesStyle::Dashed,
    ] {
        chart
            .series
            .push(Series::new(format!("{style:?}"), points.clone(), style));
    }
    chart.bands.push(Band {
        label: "band".into(),
        x: vec![1.0, 10.0, 100.0],
        lo: vec![0.0, 1.0],
        hi: vec![2.0, 8.0, 4.0],
        color: None,
    });
    chart.hlines.push(RefLine {
        label: "reference".into(),
        y: 2.0,
        color: Some(3),
        dashed: true,
    });
    chart.hlines.push(RefLine {
        label: "outside".into(),
        y: 50.0,
        color: None,
        dashed: false,
    });
    chart.regions.push(Region {
        label: "region".into(),
        x_from: 50.0,
        x_to: 1e6,
    });
    let dir = tempfile::tempdir().unwrap();
    let rendered = render(&chart, dir.path(), "everything").unwrap();
    check(
        &rendered,
        &[
            "Everything & more <at once>",
            "caption line",
            "x axis",
            "y axis",
            "θ=0.5",
            "hollow: oversubscribed",
        ],
    );
}

#[test]
fn rendering_replaces_files_and_makes_the_directory() {
    let dir = tempfile::tempdir().unwrap();
    let nested = dir.path().join("figures/strong");
    let chart = figures::time_per_step(&kernel_cases().pop().unwrap().1, CAPTION);
    let first = render(&chart, &nested, "fig").unwrap();
    let second = render(&chart, &nested, "fig").unwrap();
    assert_eq!(first, second);
    check(&second, &texts(&chart));
    assert_eq!(fs::read_dir(&nested).unwrap().count(), 2);
}

#[test]
fn bad_names_and_places_are_errors_that_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let chart = figures::efficiency(&[], CAPTION);
    for stem in ["", "../escape", "a/b", ".hidden", "spaced name"] {
        let err = render(&chart, dir.path(), stem).unwrap_err();
        assert!(matches!(err, PlotError::BadName(_)), "{stem:?}: {err}");
    }
    let file = dir.path().join("not-a-dir");
    fs::write(&file, "x").unwrap();
    let err = render(&chart, &file, "fig").unwrap_err();
    assert!(err.to_string().contains("not-a-dir"), "{err}");
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
}
