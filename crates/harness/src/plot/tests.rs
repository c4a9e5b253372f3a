//! Every figure renders, for ordinary and for awkward inputs, to an SVG that draws each series,
//! band and bar segment in the plot area in its own colour and names it in the legend, and to
//! a 1000×650 PNG with that colour in it; nothing else is left in the directory.

use super::figures::{
    self, CommTimes, Curve, KernelSeries, Measured, Percentiles, PhaseTimes, ThetaPoint, ThetaSweep,
};
use super::spec::{Band, Point, RefLine, Region};
use super::*;
use resvg::tiny_skia::Pixmap;
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
    let zeros = vec![Measured::new(0.0, 0.0), Measured::new(10.0, 1e-3)];
    let xs = figures::grid(1.0, 4.0, 8, Scale::Linear);
    let amdahl = |p: f64| 1.0 / (0.1 + 0.9 / p);
    let band = xs.iter().map(|&p| (p, 0.9 * amdahl(p), 1.1 * amdahl(p)));
    let fit = Curve::from_fn("naive: Amdahl f = 0.10", &xs, amdahl).with_band(band.collect());
    let rows = [
        (1.0, 1.0, 0.95, 1.05),
        (2.0, 1.8, 1.7, 1.9),
        (4.0, 2.1, 2.0, 2.3),
    ];
    let oversubscribed = Measured::new(4.0, 1.2).oversubscribed(true);
    let realistic = vec![
        KernelSeries::from_rows("naive", &rows).with_fit(fit),
        KernelSeries::new("per-thread", vec![Measured::new(1.0, 1.0), oversubscribed]),
    ];
    vec![
        ("no kernels", vec![]),
        ("empty series", vec![KernelSeries::new("k", vec![])]),
        ("one point", vec![KernelSeries::new("k", vec![one])]),
        ("all equal", vec![KernelSeries::new("k", equal)]),
        ("non-finite", vec![KernelSeries::new("k", non_finite)]),
        (
            "zero on log",
            vec![KernelSeries::new("k", zeros).with_fit(zero_fit)],
        ),
        ("realistic", realistic),
    ]
}

/// A drawing element of plotters' SVG (one per line) by its tag and attributes.
struct Shape<'a>(&'a str, Vec<(&'a str, &'a str)>);

impl Shape<'_> {
    fn get(&self, name: &str) -> &str {
        self.1
            .iter()
            .find(|(k, _)| *k == name)
            .map_or("", |(_, v)| v)
    }

    fn points(&self) -> Vec<i32> {
        let numbers = self
            .get("points")
            .split([' ', ','])
            .filter(|p| !p.is_empty());
        numbers.map(|n| n.parse().unwrap()).collect()
    }

    /// Its leftmost x, to tell the plot area from the legend column.
    fn x(&self) -> i32 {
        let named = ["x", "cx", "x1"]
            .iter()
            .find_map(|a| self.get(a).parse().ok());
        named.unwrap_or_else(|| self.points().into_iter().step_by(2).min().unwrap_or(0))
    }

    /// `kind` in `color`: a marker's ring, a data line, a band or a bar segment.
    fn is(&self, kind: &str, color: &str) -> bool {
        let (stroke, fill) = (self.get("stroke") == color, self.get("fill") == color);
        let width = self.get("stroke-width");
        match kind {
            "marker" => match self.0 {
                "circle" => stroke && width == "2",
                "polyline" => stroke && width == "2" && self.points().len() <= 10,
                _ => false,
            },
            "line" => self.0 == "polyline" && stroke && width == "3",
            "band" => self.0 == "polygon" && fill && self.get("opacity") == "0.18",
            "bar" => self.0 == "rect" && fill,
            _ => unreachable!("{kind}"),
        }
    }
}

fn shapes(svg: &str) -> impl Iterator<Item = Shape<'_>> {
    svg.lines().filter_map(|line| {
        let (tag, rest) = line.strip_prefix('<')?.split_once(' ')?;
        let attrs = rest.trim_end_matches(['/', '>']).split("\" ");
        let attrs = attrs.filter_map(|a| {
            a.split_once("=\"")
                .map(|(k, v)| (k, v.trim_end_matches('"')))
        });
        (tag != "text").then(|| Shape(tag, attrs.collect()))
    })
}

/// Where the legend box starts (the right edge of the figure without one).
fn legend_x(svg: &str) -> i32 {
    let legend = shapes(svg).find(|s| s.0 == "rect" && s.get("stroke") == "#BBBBBB");
    legend.map_or(1000, |s| s.x())
}

/// The SVG's elements in the plot area, left of the legend.
fn plot_shapes(svg: &str) -> Vec<Shape<'_>> {
    shapes(svg).filter(|s| s.x() < legend_x(svg)).collect()
}

fn hex(color: (u8, u8, u8)) -> String {
    format!("#{:02X}{:02X}{:02X}", color.0, color.1, color.2)
}

/// How many elements in the plot area are `kind` in palette colour `color`.
fn count(svg: &str, kind: &str, color: (u8, u8, u8)) -> usize {
    plot_shapes(svg)
        .iter()
        .filter(|s| s.is(kind, &hex(color)))
        .count()
}

/// Whether the PNG has a pixel close to `color` left of `legend_x`.
fn png_has(png: &Pixmap, color: (u8, u8, u8), legend_x: usize) -> bool {
    let near = |a: u8, b: u8| a.abs_diff(b) <= 12;
    let pixels = png.pixels().chunks(png.width() as usize);
    pixels
        .flat_map(|row| &row[..legend_x])
        .any(|p| near(p.red(), color.0) && near(p.green(), color.1) && near(p.blue(), color.2))
}

/// A kind of element, its colour, and how many the plot area must have at least.
type Drawn = (&'static str, (u8, u8, u8), usize);

/// The rendered pair exists and is well formed, the SVG carries `texts` (each word of them,
/// since legend labels wrap) and draws `drawn` (kind, colour, at least this many elements in
/// the plot area), the PNG shows those colours, and the directory holds nothing else.
fn check(rendered: &Rendered, texts: &[&str], drawn: &[Drawn]) {
    let svg = fs::read_to_string(&rendered.svg).unwrap();
    let name = rendered.svg.display();
    assert!(
        svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
        "{name}"
    );
    for word in texts
        .iter()
        .flat_map(|t| t.split([' ', '/']))
        .filter(|w| !w.is_empty())
    {
        let escaped = word
            .replace('&', "&amp;")
            .replace('<', "&lt;")
            .replace('>', "&gt;");
        let escaped = escaped.replace('"', "&quot;").replace('\'', "&apos;");
        assert!(svg.contains(&escaped), "{name} lacks {word:?}");
    }
    let png = Pixmap::decode_png(&fs::read(&rendered.png).unwrap()).unwrap();
    assert_eq!((png.width(), png.height()), (1000, 650));
    let legend_x = legend_x(&svg) as usize;
    for &(kind, color, at_least) in drawn {
        let found = count(&svg, kind, color);
        assert!(
            found >= at_least,
            "{name}: {found} {kind}s in {color:?}, want {at_least}"
        );
        if at_least > 0 && kind != "band" {
            assert!(
                png_has(&png, color, legend_x),
                "{name}: PNG lacks {color:?}"
            );
        }
    }
    let dir = rendered.svg.parent().unwrap();
    let names = fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name());
    let stray: Vec<_> = names
        .filter(|n| n.to_string_lossy().starts_with('.'))
        .collect();
    assert!(stray.is_empty(), "temporary files left: {stray:?}");
}

/// What a chart without fixed ranges must draw: each marker series one ring per finite point,
/// each line series (and reference line) at least one line, each band at least one patch,
/// all in the series' colour; and the texts it must carry, every label among them.
fn expected(chart: &Chart) -> (Vec<&str>, Vec<Drawn>) {
    let mut texts = vec![chart.title.as_str(), chart.caption.as_str()];
    texts.extend([chart.x.label.as_str(), chart.y.label.as_str()]);
    let mut drawn: Vec<Drawn> = Vec::new();
    let mut add = |kind, color, n| match drawn.iter_mut().find(|d| d.0 == kind && d.1 == color) {
        Some(d) => d.2 += n,
        None => drawn.push((kind, color, n)),
    };
    let finite = |p: &Point| p.x.is_finite() && p.y.is_finite();
    for (i, s) in chart.series.iter().enumerate() {
        texts.push(&s.label);
        let color = palette::color(s.color.unwrap_or(i));
        if matches!(s.style, SeriesStyle::Markers | SeriesStyle::LineMarkers) {
            add(
                "marker",
                color,
                s.points.iter().filter(|p| finite(p)).count(),
            );
        }
        let joined = s
            .points
            .windows(2)
            .any(|w| finite(&w[0]) && finite(&w[1]) && w[0] != w[1]);
        if s.style != SeriesStyle::Markers && joined {
            add("line", color, 1);
        }
    }
    for h in &chart.hlines {
        texts.push(&h.label);
        add(
            "line",
            palette::color(h.color.unwrap_or(palette::REFERENCE_INDEX)),
            1,
        );
    }
    for (i, b) in chart.bands.iter().enumerate() {
        texts.push(&b.label);
        let finite = |k: usize| [b.x[k], b.lo[k], b.hi[k]].iter().all(|v| v.is_finite());
        let patch =
            (1..b.x.len().min(b.lo.len()).min(b.hi.len())).any(|k| finite(k - 1) && finite(k));
        add(
            "band",
            palette::color(b.color.unwrap_or(i)),
            usize::from(patch),
        );
    }
    texts.extend(chart.regions.iter().map(|r| r.label.as_str()));
    (texts, drawn)
}

fn render_and_check(chart: &Chart, dir: &std::path::Path, stem: &str) {
    let rendered = draw(chart, dir, stem).unwrap_or_else(|e| panic!("{stem}: {e}"));
    let (texts, drawn) = expected(chart);
    check(&rendered, &texts, &drawn);
}

#[test]
fn kernel_figures_render_for_every_input() {
    let dir = tempfile::tempdir().unwrap();
    for (case, kernels) in kernel_cases() {
        let ceiling = [(1.0, 1.0), (2.0, 1.08)];
        let charts = [
            ("time", figures::time_per_step(&kernels, CAPTION)),
            (
                "speedup",
                figures::speedup(&kernels, &ceiling, "threads", CAPTION),
            ),
            (
                "speedup-no-ceiling",
                figures::speedup(&kernels, &[], "threads", CAPTION),
            ),
            (
                "efficiency",
                figures::efficiency(&kernels, "threads", CAPTION),
            ),
            ("weak", figures::weak_efficiency(&kernels, "ranks", CAPTION)),
            (
                "karp-flatt",
                figures::karp_flatt(&kernels, "threads", CAPTION),
            ),
        ];
        for (name, chart) in charts {
            let stem = format!("{name}-{}", case.replace(' ', "-"));
            render_and_check(&chart, dir.path(), &stem);
        }
    }
}

#[test]
fn a_missing_series_fails_the_check() {
    let dir = tempfile::tempdir().unwrap();
    let kernels = kernel_cases().pop().unwrap().1;
    let full = figures::speedup(&kernels, &[(1.0, 1.0), (2.0, 1.08)], "threads", CAPTION);
    for dropped in 0..full.series.len() {
        let mut partial = full.clone();
        partial.series.remove(dropped);
        let rendered = draw(&partial, dir.path(), "partial").unwrap();
        let (texts, drawn) = expected(&full);
        let checked = std::panic::catch_unwind(|| check(&rendered, &texts, &drawn));
        assert!(checked.is_err(), "series {dropped} missing went unnoticed");
    }
}

#[test]
fn bar_figures_render_for_every_input() {
    let dir = tempfile::tempdir().unwrap();
    let phase = |case: &str, v: f64| PhaseTimes {
        case: case.into(),
        phases: vec![
            ("force: build".into(), v),
            ("force: interact".into(), 10.0 * v),
            ("integrate".into(), v),
            ("boundary".into(), f64::NAN),
            ("communication".into(), -v),
        ],
    };
    let long = "lj-box/cell-list/n=100000/p=2/with/a/very/long/name/indeed";
    let bar_cases = [
        vec![],
        vec![phase("one case", 1e-4)],
        vec![phase("zero", 0.0), phase(long, 2e-3)],
        vec![phase("nan", f64::NAN)],
    ];
    for (i, cases) in bar_cases.iter().enumerate() {
        for (name, bars) in [
            ("phases", figures::phase_breakdown(cases, CAPTION)),
            ("shares", figures::phase_shares(cases, CAPTION)),
        ] {
            let rendered = draw_stacked(&bars, dir.path(), &format!("{name}-{i}")).unwrap();
            let mut texts = vec![bars.title.as_str(), bars.caption.as_str()];
            texts.push(bars.value_label.as_str());
            let mut drawn = Vec::new();
            for (k, (label, sizes)) in bars.segments.iter().enumerate() {
                let shown = sizes.iter().filter(|v| v.is_finite() && **v > 0.0).count();
                if shown > 0 {
                    texts.push(label);
                }
                drawn.push(("bar", palette::color(k), shown));
            }
            check(&rendered, &texts, &drawn);
        }
    }
}

#[test]
fn detail_figures_render_for_every_input() {
    let dir = tempfile::tempdir().unwrap();
    let pct = |kernel: &str, p50: f64| Percentiles {
        kernel: kernel.into(),
        p50,
        p90: p50,
        p99: 2.0 * p50,
        max: f64::INFINITY,
    };
    let theta = |theta: f64, seconds: f64, error: f64| ThetaPoint {
        setting: format!("θ={theta}"),
        seconds,
        error,
    };
    let sweep = |points| ThetaSweep {
        name: "galaxy".into(),
        points,
    };
    let measured = [
        Measured::with_ci(1.0, 1e-4, 9e-5, 1.2e-4),
        Measured::new(2.0, 0.0),
    ];
    let model = Curve::new("model", vec![(1.0, 1e-4), (8.0, 8e-4)])
        .with_band(vec![(1.0, 5e-5, 2e-4), (8.0, 4e-4, 1.6e-3)]);
    let comm = |x: Axis, measured: &[Measured], predicted: &Curve| {
        let (measured, predicted) = (measured.to_vec(), predicted.clone());
        figures::comm_time(
            &CommTimes {
                x,
                measured,
                predicted,
            },
            CAPTION,
        )
    };
    let three = [
        pct("naive", 1e-3),
        pct("octree", 0.0),
        pct("cell-list", f64::NAN),
    ];
    let thetas = vec![
        theta(0.0, 1e-1, 0.0),
        theta(0.5, f64::NAN, 3e-4),
        theta(1.0, 1e-3, 1e-2),
    ];
    let charts = [
        figures::step_percentiles(&[], CAPTION),
        figures::step_percentiles(&[pct("naive", 1e-3)], CAPTION),
        figures::step_percentiles(&three, CAPTION),
        figures::octree_accuracy(&[], CAPTION),
        figures::octree_accuracy(&[sweep(vec![theta(0.5, 1e-2, 3e-4)])], CAPTION),
        figures::octree_accuracy(&[sweep(thetas)], CAPTION),
        comm(Axis::linear("ranks").unit(Unit::Count), &measured, &model),
        comm(Axis::log("bytes").unit(Unit::Bytes), &measured, &model),
        comm(Axis::linear("ranks"), &[], &Curve::new("model", vec![])),
    ];
    for (i, chart) in charts.iter().enumerate() {
        render_and_check(chart, dir.path(), &format!("detail-{i}"));
    }
}

#[test]
fn a_hand_built_chart_with_every_element_renders() {
    let x = Axis::log("x axis");
    let y = Axis::linear("y axis").range(-1.0, 5.0);
    let mut chart = Chart::new("Everything & more <at once>", x, y).caption("caption line");
    // The second point is above the fixed y range: each marker series draws three markers,
    // and each line only the part after it. Series are set apart so none hides another.
    let styles = [
        SeriesStyle::Line,
        SeriesStyle::Markers,
        SeriesStyle::LineMarkers,
        SeriesStyle::Dashed,
    ];
    for (k, style) in styles.into_iter().enumerate() {
        let up = 0.25 * k as f64;
        let points = vec![
            Point::new(1.0, 1.0 + up).err(0.5 + up, 1.5 + up),
            Point::new(10.0, 9.0).hollow(true).label("off the top"),
            Point::new(100.0, 3.0 + up).label("θ=0.5").hollow(true),
            Point::new(1000.0, 4.0 - up),
        ];
        chart
            .series
            .push(Series::new(format!("{style:?}"), points, style));
    }
    chart.bands.push(Band {
        label: "band".into(),
        x: vec![1.0, 10.0, 100.0],
        lo: vec![0.0, 1.0],
        hi: vec![2.0, 8.0, 4.0],
        color: None,
    });
    for (label, y, color, dashed) in [
        ("reference", 2.0, Some(3), true),
        ("outside", 50.0, None, false),
    ] {
        let label = label.into();
        chart.hlines.push(RefLine {
            label,
            y,
            color,
            dashed,
        });
    }
    let region = Region {
        label: "region".into(),
        x_from: 50.0,
        x_to: 1e6,
    };
    chart.regions.push(region);
    let dir = tempfile::tempdir().unwrap();
    let rendered = draw(&chart, dir.path(), "everything").unwrap();
    let texts = [
        "Everything & more <at once>",
        "caption line",
        "θ=0.5",
        "hollow: oversubscribed",
        "Line",
        "LineMarkers",
        "Dashed",
        "band",
        "reference",
        "outside",
        "region",
    ];
    let drawn = [
        ("line", palette::color(0), 1),
        ("marker", palette::color(1), 3),
        ("marker", palette::color(2), 3),
        ("line", palette::color(2), 1),
        ("line", palette::color(3), 2),
        ("band", palette::color(0), 1),
    ];
    check(&rendered, &texts, &drawn);
    // The reference line above the range is listed but not drawn; the other one is.
    let svg = fs::read_to_string(&rendered.svg).unwrap();
    assert_eq!(count(&svg, "line", palette::REFERENCE), 0);
    assert_eq!(count(&svg, "marker", palette::color(1)), 3);
}

#[test]
fn rendering_replaces_files_and_makes_the_directory() {
    let dir = tempfile::tempdir().unwrap();
    let nested = dir.path().join("figures/strong");
    let chart = figures::time_per_step(&kernel_cases().pop().unwrap().1, CAPTION);
    let first = draw(&chart, &nested, "fig").unwrap();
    let second = draw(&chart, &nested, "fig").unwrap();
    assert_eq!(first, second);
    let (texts, drawn) = expected(&chart);
    check(&second, &texts, &drawn);
    assert_eq!(fs::read_dir(&nested).unwrap().count(), 2);
}

#[test]
fn bad_names_and_places_are_errors_that_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let chart = figures::efficiency(&[], "threads", CAPTION);
    for stem in ["", "../escape", "a/b", ".hidden", "spaced name"] {
        let err = draw(&chart, dir.path(), stem).unwrap_err();
        assert!(matches!(err, PlotError::BadName(_)), "{stem:?}: {err}");
    }
    let file = dir.path().join("not-a-dir");
    fs::write(&file, "x").unwrap();
    let err = draw(&chart, &file, "fig").unwrap_err();
    assert!(err.to_string().contains("not-a-dir"), "{err}");
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
}
