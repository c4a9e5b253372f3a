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

/// A marker centred at `c`. Hollow markers get a white inside so grid lines do not cross them.
pub fn marker<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    c: Px,
    marker: Marker,
    color: RGBColor,
    hollow: bool,
) -> DrawResult {
    let r = MARKER_RADIUS;
    let stroke = color.stroke_width(LINE_WIDTH);
    if marker == Marker::Circle {
        if hollow {
            area.draw(&Circle::new(c, r, WHITE.filled())).map_err(err)?;
            return area.draw(&Circle::new(c, r, stroke)).map_err(err);
        }
        return area.draw(&Circle::new(c, r, color.filled())).map_err(err);
    }
    let points = outline(marker, c, r);
    if hollow {
        area.draw(&Polygon::new(points.clone(), WHITE.filled()))
            .map_err(err)?;
        let mut closed = points.clone();
        closed.push(points[0]);
        return area.draw(&PathElement::new(closed, stroke)).map_err(err);
    }
    area.draw(&Polygon::new(points, color.filled()))
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
