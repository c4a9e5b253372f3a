//! A [`ResolvedAxis`] as a plotters coordinate, so one coordinate type serves linear, log and
//! categorical axes and the grid and tick labels are exactly the ticks [`ResolvedAxis`] chose.

use plotters::coord::ranged1d::{
    KeyPointHint, KeyPointWeight, NoDefaultFormatting, Ranged, ValueFormatter,
};
use std::ops::Range;

use super::axis::ResolvedAxis;

pub struct AxisCoord(pub ResolvedAxis);

impl Ranged for AxisCoord {
    type FormatOption = NoDefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        // Callers only pass values inside the axis; the clamp keeps a stray one from wrapping.
        let fraction = self.0.fraction(*value);
        let fraction = if fraction.is_finite() {
            fraction.clamp(-1.0, 2.0)
        } else {
            0.0
        };
        limit.0 + (fraction * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        match hint.weight() {
            KeyPointWeight::Bold => self.0.major.iter().map(|(v, _)| *v).collect(),
            KeyPointWeight::Any => self.0.minor.clone(),
        }
    }

    fn range(&self) -> Range<f64> {
        self.0.lo..self.0.hi
    }
}

impl ValueFormatter<f64> for AxisCoord {
    fn format(value: &f64) -> String {
        value.to_string()
    }

    fn format_ext(&self, value: &f64) -> String {
        self.0.label(*value)
    }
}
