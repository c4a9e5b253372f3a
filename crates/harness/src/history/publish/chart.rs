//! One case's series on one machine class as an inline SVG chart: the medians joined by a
//! line over their 95% interval band, one x position per commit in commit order (labelled by
//! short hashes), each segment's level, and a dashed marker at every step labelled with the
//! two commits it fell between and its size. Each point carries a `<title>` (the browser's own
//! tooltip), so the chart says everything without the page's script.

use super::{Chart, esc, short};
use crate::history::series::{Metric, Series};
use crate::units::Duration;
use std::fmt::Write;

const WIDTH: f64 = 600.0;
const HEIGHT: f64 = 330.0;
const LEFT: f64 = 70.0;
const RIGHT: f64 = 14.0;
/// Two rows of change labels above the plot.
const TOP: f64 = 40.0;
/// The commit labels, the axis title and the legend below it.
const BOTTOM: f64 = 96.0;
/// At most this many commit labels; past it every k-th is written.
const MAX_LABELS: usize = 40;

/// How the values of a series are written on its axis: a factor (seconds → the axis unit)
/// and the axis title.
struct Scale {
    factor: f64,
    title: String,
}

fn scale(metric: Metric, largest: f64) -> Scale {
    match metric {
        Metric::Normalized => Scale {
            factor: 1.0,
            title: "time per step ÷ reference workload (×)".to_string(),
        },
        Metric::Seconds => {
            let (len, unit) = Duration::unit_for(largest);
            Scale {
                factor: 1.0 / len,
                title: format!("time per step ({unit})"),
            }
        }
    }
}

/// A value as the tooltip and the captions write it.
pub(super) fn value(metric: Metric, v: f64) -> String {
    match metric {
        Metric::Normalized => format!("{v:.4}×"),
        Metric::Seconds => Duration(v).to_string(),
    }
}

/// Ticks at 1, 2 or 5 × 10^k covering `[lo, hi]`, about five of them, with the decimals they
/// need.
fn ticks(lo: f64, hi: f64) -> (Vec<f64>, usize) {
    let raw = (hi - lo) / 5.0;
    let magnitude = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * magnitude)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * magnitude);
    // The decimals of the step (0.1 → 1, 0.05 → 2), safe against log10(0.1) = -0.99…
    let decimals = (-step.log10() - 1e-9).ceil().max(0.0) as usize;
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    ((first..=last).map(|i| i as f64 * step).collect(), decimals)
}

/// Where a chart's values go: the value range of the y axis (in axis units) and the plot's
/// size, with the commit count that spaces x.
struct Frame {
    /// Commits along x.
    n: usize,
    /// The y axis' ends, in axis units (padded around the intervals).
    lo: f64,
    hi: f64,
    /// Seconds → axis units.
    factor: f64,
    /// The plot's width and height.
    pw: f64,
    ph: f64,
}

impl Frame {
    /// The frame of a series whose highest interval end is `largest`: its intervals padded by
    /// 8%, or ±5% around a single value.
    fn of(s: &Series, largest: f64, sc: &Scale) -> Frame {
        let mut lo = s
            .points
            .iter()
            .map(|p| p.ci95[0])
            .fold(f64::INFINITY, f64::min)
            * sc.factor;
        let mut hi = largest * sc.factor;
        if !(lo.is_finite() && hi.is_finite() && hi > lo) {
            // One point, or every interval one value: a range around it.
            let mid = if hi.is_finite() { hi } else { 1.0 };
            (lo, hi) = (mid * 0.95, mid * 1.05);
        }
        let pad = 0.08 * (hi - lo);
        let (lo, hi) = (lo - pad, hi + pad);
        Frame {
            n: s.points.len(),
            lo,
            hi,
            factor: sc.factor,
            pw: WIDTH - LEFT - RIGHT,
            ph: HEIGHT - TOP - BOTTOM,
        }
    }

    /// The x of the i-th commit: the middle of its slot.
    fn x(&self, i: usize) -> f64 {
        LEFT + self.pw * (i as f64 + 0.5) / self.n.max(1) as f64
    }

    /// The y of a value in seconds (or a normalized ratio).
    fn y(&self, v: f64) -> f64 {
        self.y_axis(v * self.factor)
    }

    /// The y of a value already in axis units (a tick).
    fn y_axis(&self, t: f64) -> f64 {
        TOP + self.ph * (1.0 - (t - self.lo) / (self.hi - self.lo))
    }
}

/// The SVG of `chart`.
pub(super) fn svg(chart: &Chart) -> String {
    let s = &chart.series;
    let largest = s.points.iter().map(|p| p.ci95[1]).fold(0.0, f64::max);
    let sc = scale(s.metric, largest);
    let f = Frame::of(s, largest, &sc);
    let mut o = String::new();
    let _ = write!(
        o,
        r#"<svg class="chart" data-class="{class}" data-config="{config}" viewBox="0 0 {WIDTH} {HEIGHT}" width="{WIDTH}" height="{HEIGHT}" role="img" aria-label="{case} on {class}: {title} per commit">"#,
        class = esc(&s.class),
        config = esc(&s.config),
        case = esc(&s.case),
        title = esc(&sc.title),
    );
    value_axis(&mut o, &f, &sc.title);
    commit_axis(&mut o, &f, s);
    // The 95% band, the segments' levels, the medians.
    interval_band(&mut o, &f, s);
    segment_levels(&mut o, &f, chart);
    median_line(&mut o, &f, s);
    step_markers(&mut o, &f, chart);
    legend(&mut o, HEIGHT - 8.0);
    o.push_str("</svg>");
    o
}

/// The plot's frame and the y axis: grid lines at the ticks and the axis title.
fn value_axis(o: &mut String, f: &Frame, title: &str) {
    let (pw, ph) = (f.pw, f.ph);
    let _ = write!(
        o,
        r#"<rect class="frame" x="{LEFT}" y="{TOP}" width="{pw}" height="{ph}"/>"#
    );
    let (ticks, decimals) = ticks(f.lo, f.hi);
    for t in ticks {
        let ty = f.y_axis(t);
        let _ = write!(
            o,
            r#"<line class="grid" x1="{LEFT}" x2="{x2:.1}" y1="{ty:.1}" y2="{ty:.1}"/><text class="tick" x="{tx:.1}" y="{ty:.1}" text-anchor="end" dominant-baseline="middle">{t:.decimals$}</text>"#,
            x2 = LEFT + pw,
            tx = LEFT - 6.0,
        );
    }
    let _ = write!(
        o,
        r#"<text class="axis" transform="translate(14 {cy:.1}) rotate(-90)" text-anchor="middle">{}</text>"#,
        esc(title),
        cy = TOP + ph / 2.0
    );
}

/// The commits along x: short hashes (every k-th past [`MAX_LABELS`], and the last) and the
/// axis title.
fn commit_axis(o: &mut String, f: &Frame, s: &Series) {
    let n = f.n;
    let every = n.div_ceil(MAX_LABELS).max(1);
    for (i, p) in s.points.iter().enumerate() {
        if i % every != 0 && i + 1 != n {
            continue;
        }
        let _ = write!(
            o,
            r#"<text class="commit" transform="translate({:.1} {:.1}) rotate(-60)" text-anchor="end">{}</text>"#,
            f.x(i) + 3.0,
            TOP + f.ph + 8.0,
            esc(short(&p.commit))
        );
    }
    let _ = write!(
        o,
        r#"<text class="axis" x="{:.1}" y="{:.1}" text-anchor="middle">commit, oldest → newest</text>"#,
        LEFT + f.pw / 2.0,
        HEIGHT - 24.0
    );
}

/// The 95% band: along the upper ends, back along the lower ones (nothing without points).
fn interval_band(o: &mut String, f: &Frame, s: &Series) {
    if f.n > 0 {
        let mut band = String::from("M");
        for (i, p) in s.points.iter().enumerate() {
            let _ = write!(band, "{:.1},{:.1} ", f.x(i), f.y(p.ci95[1]));
        }
        for (i, p) in s.points.iter().enumerate().rev() {
            let _ = write!(band, "L{:.1},{:.1} ", f.x(i), f.y(p.ci95[0]));
        }
        let _ = write!(o, r#"<path class="band" d="{}Z"/>"#, band.trim_end());
    }
}

/// Each segment's level between the steps: the level after the step that opens it, or for
/// the first segment the level before the first step (none without steps); no level across a
/// drift (a stretch between two steps that holds one is not level), and each drift's fitted
/// trend as a sloped line.
fn segment_levels(o: &mut String, f: &Frame, chart: &Chart) {
    let mut bounds = vec![0];
    bounds.extend(chart.steps.iter().map(|st| st.index));
    bounds.push(f.n);
    for d in &chart.drifts {
        let _ = write!(
            o,
            r#"<line class="level drift" x1="{:.1}" x2="{:.1}" y1="{:.1}" y2="{:.1}"/>"#,
            f.x(d.start),
            f.x(d.end),
            f.y(d.from),
            f.y(d.to)
        );
    }
    for (k, w) in bounds.windows(2).enumerate() {
        if chart.drifts.iter().any(|d| d.start < w[1] && w[0] <= d.end) {
            continue;
        }
        let level = match (
            k.checked_sub(1).map(|j| &chart.steps[j]),
            chart.steps.get(k),
        ) {
            (Some(prev), _) => prev.after,
            (None, Some(next)) => next.before,
            (None, None) => continue,
        };
        let _ = write!(
            o,
            r#"<line class="level" x1="{:.1}" x2="{:.1}" y1="{ly:.1}" y2="{ly:.1}"/>"#,
            f.x(w[0]) - 4.0,
            f.x(w[1].saturating_sub(1)) + 4.0,
            ly = f.y(level)
        );
    }
}

/// The medians joined by a line, then a point per commit with its tooltip.
fn median_line(o: &mut String, f: &Frame, s: &Series) {
    let line: Vec<String> = s
        .points
        .iter()
        .enumerate()
        .map(|(i, p)| format!("{:.1},{:.1}", f.x(i), f.y(p.value)))
        .collect();
    let _ = write!(
        o,
        r#"<polyline class="median" points="{}"/>"#,
        line.join(" ")
    );
    for (i, p) in s.points.iter().enumerate() {
        let date = p.commit_date.as_deref().unwrap_or("no date");
        let (v, ci) = (
            value(s.metric, p.value),
            format!(
                "[{}, {}]",
                value(s.metric, p.ci95[0]),
                value(s.metric, p.ci95[1])
            ),
        );
        let _ = write!(
            o,
            r#"<circle class="point" cx="{:.1}" cy="{:.1}" r="3.2" data-commit="{c}" data-date="{d}" data-value="{v}" data-ci="{ci}"><title>{c} ({d}): {v}, 95% interval {ci}</title></circle>"#,
            f.x(i),
            f.y(p.value),
            c = esc(short(&p.commit)),
            d = esc(date),
            v = esc(&v),
            ci = esc(&ci),
        );
    }
}

/// The steps: a marker between their two commits, labels on alternating rows (anchored
/// inward near the plot's ends).
fn step_markers(o: &mut String, f: &Frame, chart: &Chart) {
    let metric = chart.series.metric;
    for (k, st) in chart.steps.iter().enumerate() {
        let mx = (f.x(st.index - 1) + f.x(st.index)) / 2.0;
        let between = format!("{}..{}", short(&st.between[0]), short(&st.between[1]));
        let size = percent(st.ratio);
        let ty = if k % 2 == 0 { TOP - 22.0 } else { TOP - 8.0 };
        let anchor = if mx < LEFT + f.pw * 0.2 {
            "start"
        } else if mx > LEFT + f.pw * 0.8 {
            "end"
        } else {
            "middle"
        };
        let _ = write!(
            o,
            r#"<g class="change {dir}" data-between="{b}" data-ratio="{ratio:.4}"><line x1="{mx:.1}" x2="{mx:.1}" y1="{y1:.1}" y2="{y2:.1}"/><text x="{mx:.1}" y="{ty:.1}" text-anchor="{anchor}">{b} {size}</text><title>step between {b}: {before} → {after} ({size}, 95% interval [{lo}, {hi}])</title></g>"#,
            dir = if st.ratio > 1.0 { "slower" } else { "faster" },
            b = esc(&between),
            ratio = st.ratio,
            y1 = ty + 3.0,
            y2 = TOP + f.ph,
            before = esc(&value(metric, st.before)),
            after = esc(&value(metric, st.after)),
            lo = percent(st.ratio_ci95[0]),
            hi = percent(st.ratio_ci95[1]),
        );
    }
}

/// The legend, one row along the bottom.
fn legend(o: &mut String, at: f64) {
    let (y, x0) = (at, LEFT);
    let _ = write!(
        o,
        r#"<g class="legend"><line class="median" x1="{x0}" x2="{x1}" y1="{ym}" y2="{ym}"/><circle class="point" cx="{xc}" cy="{ym}" r="3.2"/><text x="{xt}" y="{y}">median</text><rect class="band" x="{xb}" y="{yb}" width="18" height="10"/><text x="{xbt}" y="{y}">95% interval</text><line class="level" x1="{xl}" x2="{xl2}" y1="{ym}" y2="{ym}"/><text x="{xlt}" y="{y}">level</text><line class="change-key" x1="{xs}" x2="{xs}" y1="{ys}" y2="{y}"/><text x="{xst}" y="{y}">step (first..second commit, size)</text></g>"#,
        x1 = x0 + 18.0,
        xc = x0 + 9.0,
        ym = y - 4.0,
        xt = x0 + 24.0,
        xb = x0 + 80.0,
        yb = y - 9.0,
        xbt = x0 + 104.0,
        xl = x0 + 190.0,
        xl2 = x0 + 208.0,
        xlt = x0 + 214.0,
        xs = x0 + 260.0,
        ys = y - 11.0,
        xst = x0 + 266.0,
    );
}

/// A ratio as a signed percentage: `+44.2%`, `-17.0%`.
pub(super) fn percent(ratio: f64) -> String {
    format!("{:+.1}%", 100.0 * (ratio - 1.0))
}

#[cfg(test)]
mod tests {
    use super::ticks;

    #[test]
    fn ticks_are_round_and_inside_the_range() {
        let (t, d) = ticks(0.93, 1.41);
        assert_eq!(d, 1);
        assert_eq!(t.first().copied(), Some(1.0));
        assert!(t.iter().all(|v| (0.93..=1.41).contains(v)));
        assert!((3..=7).contains(&t.len()), "{t:?}");
        let (t, d) = ticks(120.0, 480.0);
        assert_eq!((t[0], d), (200.0, 0));
    }
}
