//! The page around a plot, shared by charts and bars: white background, title on top, caption
//! at the bottom, plotters' mesh with the ticks [`ResolvedAxis`] chose, and the legend column
//! on the right. Also the text sizes, and fitting text to a width measured with the embedded
//! font.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::axis::ResolvedAxis;
use super::font::FAMILY;
use super::legend::{Legend, Swatch};
use super::text::{AXIS_LABEL_SIZE, CAPTION_SIZE, DrawResult, TEXT_COLOR, TITLE_SIZE, err};
pub(crate) use super::text::{Area, LEGEND_SIZE, MUTED_COLOR, NOTE_SIZE, TICK_SIZE, shorten};
pub use super::text::{anchored, style, width};

pub(crate) type Plot<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<ResolvedAxis, ResolvedAxis>>;

const SIDE: u32 = 20;
const CAPTION_ROOM: u32 = 24;
/// The plot area, and the legend with it, starts this far below the title.
const PLOT_TOP: i32 = 8;

/// The page of one figure: where the plot goes, and whether a legend is beside it.
pub(crate) struct Page<'a> {
    pub plot: Area<'a>,
    legend: bool,
}

impl<'a> Page<'a> {
    /// Clears `root`, writes the title and the caption, and draws the legend in a column on
    /// the right, level with the top of the plot area.
    pub fn new(
        root: &Area<'a>,
        title: &str,
        caption: &str,
        legend: Vec<(String, Swatch)>,
    ) -> Result<Self, String> {
        root.fill(&WHITE).map_err(err)?;
        let width = root.dim_in_pixel().0;
        let max_text = width - 2 * SIDE;
        let mut area = root.margin(8, 8, 0, 0);
        if !title.trim().is_empty() {
            let bold = (FAMILY, TITLE_SIZE, FontStyle::Bold).into_font();
            let bold = bold.color(&TEXT_COLOR);
            // Measured in the regular face: a real bold is up to ~15% wider.
            let title = shorten(root, title, &bold, max_text * 85 / 100);
            area = area.titled(&title, bold).map_err(err)?;
        }
        // One line per line of the caption (a note on what is not drawn goes above the
        // machine line).
        let lines: Vec<&str> = caption.lines().filter(|l| !l.trim().is_empty()).collect();
        if !lines.is_empty() {
            let room = CAPTION_ROOM * lines.len() as u32;
            let (rest, bottom) = area.split_vertically(area.dim_in_pixel().1 - room);
            let muted = anchored(CAPTION_SIZE, HPos::Center, VPos::Bottom).color(&MUTED_COLOR);
            for (i, line) in lines.iter().enumerate() {
                let line = shorten(root, line, &muted, max_text);
                let at = (width as i32 / 2, (CAPTION_ROOM * (i as u32 + 1)) as i32);
                bottom.draw_text(&line, &muted, at).map_err(err)?;
            }
            area = rest;
        }
        let legend = Legend::new(root, legend, area.dim_in_pixel().1 - PLOT_TOP as u32);
        if legend.width == 0 {
            return Ok(Page {
                plot: area,
                legend: false,
            });
        }
        let (plot, panel) = area.split_horizontally(width - legend.width - SIDE / 2);
        legend.draw(&panel, PLOT_TOP)?;
        Ok(Page { plot, legend: true })
    }

    /// Builds the plot on the page and draws plotters' mesh: grid lines at the major and
    /// minor ticks (none across y without `y_grid`), tick labels, and the axis descriptions.
    /// `y_size` is the size of the y tick labels.
    pub fn plot(
        &self,
        (x, y): (ResolvedAxis, ResolvedAxis),
        (x_desc, y_desc): (&str, &str),
        y_size: f64,
        y_grid: bool,
    ) -> Result<Plot<'_, 'a>, String> {
        let y_style = style(y_size);
        let widest = y
            .major
            .iter()
            .map(|(_, l)| width(&self.plot, l, &y_style))
            .max();
        let mut plot = ChartBuilder::on(&self.plot)
            .margin_top(PLOT_TOP)
            .margin_left(10)
            .margin_right(if self.legend { 12 } else { 24 })
            .x_label_area_size((TICK_SIZE + AXIS_LABEL_SIZE) as u32 + 16)
            .y_label_area_size(widest.unwrap_or(0) + AXIS_LABEL_SIZE as u32 + 26)
            .build_cartesian_2d(x, y)
            .map_err(err)?;
        let mut mesh = plot.configure_mesh();
        mesh.x_desc(x_desc)
            .x_label_style(style(TICK_SIZE))
            .y_label_style(y_style)
            .axis_desc_style(style(AXIS_LABEL_SIZE))
            .bold_line_style(BLACK.mix(0.14))
            .light_line_style(BLACK.mix(0.05));
        if !y_desc.is_empty() {
            mesh.y_desc(y_desc);
        }
        if !y_grid {
            mesh.disable_y_mesh();
        }
        mesh.draw().map_err(err)?;
        Ok(plot)
    }
}

/// Writes "no data to show" in the middle of the plot area.
pub(crate) fn note_no_data(root: &Area, plot: &Plot) -> DrawResult {
    let (xs, ys) = plot.plotting_area().get_pixel_range();
    let style = anchored(LEGEND_SIZE, HPos::Center, VPos::Center).color(&MUTED_COLOR);
    let centre = ((xs.start + xs.end) / 2, (ys.start + ys.end) / 2);
    root.draw_text("no data to show", &style, centre)
        .map_err(err)
}
