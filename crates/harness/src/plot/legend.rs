//! Markers, legend samples and the legend. The legend is plotters' own series-label box,
//! drawn in a column right of the plot area so that it never covers data; labels too long for
//! the column wrap onto a second line.

use plotters::element::{DashedPathElement, Drawable, PointCollection};
use plotters::prelude::*;
use plotters_backend::{BackendCoord, DrawingErrorKind};

use super::palette::Marker;
use super::text::{Area, DrawResult, LEGEND_SIZE, err, style, width, wrap};

const MARKER_RADIUS: i32 = 5;
pub(crate) const LINE_WIDTH: u32 = 3;
pub(crate) const DASH: (i32, i32) = (9, 6);
const SWATCH_WIDTH: i32 = 30;
const GAP: i32 = 8;
const PADDING: i32 = 10;
/// plotters' series labels are set 1.25 font sizes apart.
const LINE_HEIGHT: f64 = 1.25 * LEGEND_SIZE;
/// The legend never takes more than this share of the figure width.
const MAX_SHARE: f64 = 0.3;

pub(crate) fn rgb((r, g, b): (u8, u8, u8)) -> RGBColor {
    RGBColor(r, g, b)
}

/// How a legend entry's sample, or a data marker, is drawn.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Swatch {
    Line {
        color: RGBColor,
        dashed: bool,
        marker: Option<Marker>,
    },
    /// Filled, or hollow: white inside, so that grid lines and error bars do not show through;
    /// crossed: a black × over it.
    Marker {
        color: RGBColor,
        marker: Marker,
        hollow: bool,
        crossed: bool,
    },
    /// A patch of `color` at the given opacity, as the band or region it stands for.
    Fill(RGBColor, f64),
}

/// A [`Swatch`] as a plotters element, drawn in pixels centred on one point. It owns nothing
/// of the backend, so plotters can box it as a legend sample.
pub(crate) struct Glyph<C>(pub C, pub Swatch);

impl<'a, C> PointCollection<'a, C> for &'a Glyph<C> {
    type Point = &'a C;
    type IntoIter = std::iter::Once<&'a C>;

    fn point_iter(self) -> Self::IntoIter {
        std::iter::once(&self.0)
    }
}

impl<C, DB: DrawingBackend> Drawable<DB> for Glyph<C> {
    fn draw<I: Iterator<Item = BackendCoord>>(
        &self,
        mut at: I,
        backend: &mut DB,
        size: (u32, u32),
    ) -> Result<(), DrawingErrorKind<DB::ErrorType>> {
        let Some((x, y)) = at.next() else {
            return Ok(());
        };
        let half = SWATCH_WIDTH / 2;
        match self.1 {
            Swatch::Line {
                color,
                dashed,
                marker,
            } => {
                let style = color.stroke_width(LINE_WIDTH);
                let ends = [(x - half, y), (x + half, y)];
                if dashed {
                    let dashes = DashedPathElement::new(ends, DASH.0, DASH.1, style);
                    dashes.draw(ends.into_iter(), backend, size)?;
                } else {
                    backend.draw_line(ends[0], ends[1], &style)?;
                }
                match marker {
                    Some(m) => draw_marker(backend, (x, y), m, color, false),
                    None => Ok(()),
                }
            }
            Swatch::Marker {
                color,
                marker,
                hollow,
                crossed,
            } => {
                draw_marker(backend, (x, y), marker, color, hollow)?;
                match crossed {
                    true => draw_cross(backend, (x, y)),
                    false => Ok(()),
                }
            }
            Swatch::Fill(color, alpha) => {
                let style = color.mix(alpha).filled();
                backend.draw_rect((x - half, y - 7), (x + half, y + 7), &style, true)
            }
        }
    }
}

/// Filled and hollow markers share one outline: a 2 px ring of radius `MARKER_RADIUS`.
fn draw_marker<DB: DrawingBackend>(
    backend: &mut DB,
    (x, y): BackendCoord,
    marker: Marker,
    color: RGBColor,
    hollow: bool,
) -> Result<(), DrawingErrorKind<DB::ErrorType>> {
    let r = MARKER_RADIUS - 1;
    let fill = if hollow { WHITE } else { color }.filled();
    let ring = color.stroke_width(2);
    let outline = match marker {
        Marker::Circle => {
            backend.draw_circle((x, y), r as u32, &fill, true)?;
            return backend.draw_circle((x, y), r as u32, &ring, false);
        }
        Marker::Square => vec![(-r, -r), (r, -r), (r, r), (-r, r)],
        Marker::Triangle => vec![(0, -r - 1), (r + 1, r), (-r - 1, r)],
        Marker::Diamond => vec![(0, -r - 1), (r + 1, 0), (0, r + 1), (-r - 1, 0)],
    };
    let outline: Vec<_> = outline.iter().map(|(dx, dy)| (x + dx, y + dy)).collect();
    backend.fill_polygon(outline.clone(), &fill)?;
    backend.draw_path(outline.iter().chain(&outline[..1]).copied(), &ring)
}

/// A black × a little wider than a marker, centred on it: it reads over any marker's colour.
fn draw_cross<DB: DrawingBackend>(
    backend: &mut DB,
    (x, y): BackendCoord,
) -> Result<(), DrawingErrorKind<DB::ErrorType>> {
    let r = MARKER_RADIUS + 3;
    let ink = BLACK.stroke_width(2);
    backend.draw_line((x - r, y - r), (x + r, y + r), &ink)?;
    backend.draw_line((x - r, y + r), (x + r, y - r), &ink)
}

/// Legend entries laid out for the page: each label in one or two lines.
pub(crate) struct Legend {
    entries: Vec<(Vec<String>, Swatch)>,
    /// The width of the legend box in pixels; 0 without entries.
    pub width: u32,
}

impl Legend {
    /// Wraps the labels to the widest legend the page allows and keeps the entries that fit
    /// into `height` pixels; entries with an empty label are left out.
    pub fn new(root: &Area, entries: Vec<(String, Swatch)>, height: u32) -> Legend {
        let chrome = (SWATCH_WIDTH + GAP + 2 * PADDING) as u32 + 2;
        let max_text = (f64::from(root.dim_in_pixel().0) * MAX_SHARE) as u32 - chrome;
        let text = style(LEGEND_SIZE);
        let mut room = ((f64::from(height) - 2.0 * f64::from(PADDING)) / LINE_HEIGHT) as usize;
        let mut laid_out = Vec::new();
        for (label, swatch) in entries.into_iter().filter(|(l, _)| !l.is_empty()) {
            let lines = wrap(root, &label, &text, max_text, 2);
            if lines.len() > room {
                break;
            }
            room -= lines.len();
            laid_out.push((lines, swatch));
        }
        let widest = laid_out.iter().flat_map(|(lines, _)| lines);
        let widest = widest.map(|l| width(root, l, &text)).max();
        Legend {
            entries: laid_out,
            width: widest.map_or(0, |w| w + chrome),
        }
    }

    /// Draws the legend in `panel`, `top` pixels below its top edge. The panel gets a chart
    /// of its own with nothing in it but series labels, which plotters lays out and boxes;
    /// each line is a label of its own, and a continued label has no sample.
    pub(crate) fn draw(&self, panel: &Area, top: i32) -> DrawResult {
        if self.entries.is_empty() {
            return Ok(());
        }
        let mut chart = ChartBuilder::on(panel)
            .build_cartesian_2d(0.0..1.0, 0.0..1.0)
            .map_err(err)?;
        for (lines, swatch) in &self.entries {
            for (i, line) in lines.iter().enumerate() {
                let none = std::iter::empty::<EmptyElement<(f64, f64), _>>();
                let label = chart.draw_series(none).map_err(err)?;
                label.label(line.as_str());
                if i == 0 {
                    let swatch = *swatch;
                    label.legend(move |(x, y)| Glyph((x + SWATCH_WIDTH / 2, y), swatch));
                }
            }
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::Coordinate(0, top))
            .label_font(style(LEGEND_SIZE))
            .legend_area_size(SWATCH_WIDTH + GAP)
            .margin(PADDING)
            .border_style(RGBColor(0xBB, 0xBB, 0xBB))
            .background_style(WHITE)
            .draw()
            .map_err(err)
    }
}
