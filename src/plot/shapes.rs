//! Drawing primitives in pixel coordinates, shared by the plot area and the legend: markers
//! (filled or hollow), solid and dashed polylines, and translucent fills.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::palette::Marker;

pub type Px = (i32, i32);
pub type DrawResult = Result<(), String>;

pub const MARKER_RADIUS: i32 = 5;
pub const LINE_WIDTH: u32 = 2;
const DASH_ON: f64 = 9.0;
const DASH_OFF: f64 = 6.0;

fn err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

pub fn rgb((r, g, b): (u8, u8, u8)) -> RGBColor {
    RGBColor(r, g, b)
}

/// Vertices of `marker` around `c` (circles are drawn separately).
fn outline(marker: Marker, (x, y): Px, r: i32) -> Vec<Px> {
    match marker {
        Marker::Circle | Marker::Square => vec![
            (x - r, y - r),
            (x + r, y - r),
            (x + r, y + r),
            (x - r, y + r),
        ],
        Marker::Triangle => {
            let h = r + 1;
            vec![(x, y - h), (x + h, y + h - 1), (x - h, y + h - 1)]
        }
        Marker::Diamond => {
            let h = r + 1;
            vec![(x, y - h), (x + h, y), (x, y + h), (x - h, y)]
        }
    }
}

/// A marker centred at `c`. A hollow marker is the filled shape with a white inside, so the
/// ring is even and grid lines or error bars do not show through it.
pub fn marker<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    c: Px,
    marker: Marker,
    color: RGBColor,
    hollow: bool,
) -> DrawResult {
    let r = MARKER_RADIUS;
    shape(area, c, marker, r, color)?;
    if hollow {
        // Slanted edges look thinner than straight ones at the same inset.
        let inset = if matches!(marker, Marker::Triangle | Marker::Diamond) {
            3
        } else {
            2
        };
        shape(area, c, marker, r - inset, WHITE)?;
    }
    Ok(())
}

fn shape<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    c: Px,
    marker: Marker,
    r: i32,
    color: RGBColor,
) -> DrawResult {
    if marker == Marker::Circle {
        return area.draw(&Circle::new(c, r, color.filled())).map_err(err);
    }
    area.draw(&Polygon::new(outline(marker, c, r), color.filled()))
        .map_err(err)
}

/// A polyline through `points`, solid or dashed.
pub fn polyline<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    points: &[Px],
    style: ShapeStyle,
    dashed: bool,
) -> DrawResult {
    if points.len() < 2 {
        return Ok(());
    }
    if !dashed {
        return area
            .draw(&PathElement::new(points.to_vec(), style))
            .map_err(err);
    }
    for dash in dashes(points) {
        area.draw(&PathElement::new(dash, style)).map_err(err)?;
    }
    Ok(())
}

/// Cuts a polyline into dashes that continue across its vertices.
fn dashes(points: &[Px]) -> Vec<Vec<Px>> {
    let mut out = Vec::new();
    let mut current: Vec<Px> = vec![points[0]];
    let mut on = true;
    let mut left = DASH_ON;
    for pair in points.windows(2) {
        let (a, b) = (
            (pair[0].0 as f64, pair[0].1 as f64),
            (pair[1].0 as f64, pair[1].1 as f64),
        );
        let length = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
        let mut travelled = 0.0;
        while length - travelled > left {
            travelled += left;
            let t = travelled / length;
            let p = (
                (a.0 + t * (b.0 - a.0)).round() as i32,
                (a.1 + t * (b.1 - a.1)).round() as i32,
            );
            if on {
                current.push(p);
                out.push(std::mem::take(&mut current));
            } else {
                current = vec![p];
            }
            on = !on;
            left = if on { DASH_ON } else { DASH_OFF };
        }
        left -= length - travelled;
        if on {
            current.push(pair[1]);
        }
    }
    if on && current.len() >= 2 {
        out.push(current);
    }
    out
}

/// A filled polygon in `color` at opacity `alpha`.
pub fn fill<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    points: Vec<Px>,
    color: RGBColor,
    alpha: f64,
) -> DrawResult {
    if points.len() < 3 {
        return Ok(());
    }
    area.draw(&Polygon::new(points, color.mix(alpha).filled()))
        .map_err(err)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dashes_alternate_and_stay_on_the_line() {
        let d = dashes(&[(0, 0), (100, 0)]);
        assert_eq!(d.len(), 7, "{d:?}"); // 100 px = 6 × (9 + 6) + 10: seven dashes
        assert!(d.iter().all(|dash| dash.iter().all(|p| p.1 == 0)));
        assert_eq!(d[0], vec![(0, 0), (9, 0)]);
        assert_eq!(d[1][0], (15, 0));
    }
}
