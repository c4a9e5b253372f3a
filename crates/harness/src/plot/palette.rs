//! Colours and marker shapes. The colours are the Okabe-Ito palette, chosen to stay
//! distinguishable under the common forms of colour blindness; each colour index also gets its
//! own marker shape so series differ in print and in greyscale too.

/// Okabe-Ito colours as RGB, most contrasting on white first (yellow, the weakest, last).
pub(crate) const PALETTE: [(u8, u8, u8); 8] = [
    (0x00, 0x72, 0xB2), // blue
    (0xD5, 0x5E, 0x00), // vermillion
    (0x00, 0x9E, 0x73), // bluish green
    (0xCC, 0x79, 0xA7), // reddish purple
    (0xE6, 0x9F, 0x00), // orange
    (0x56, 0xB4, 0xE9), // sky blue
    (0x00, 0x00, 0x00), // black
    (0xF0, 0xE4, 0x42), // yellow
];

/// Reference lines and shaded regions: dark grey, apart from the data colours.
pub(crate) const REFERENCE: (u8, u8, u8) = (0x55, 0x55, 0x55);

/// The colour index that draws in [`REFERENCE`] grey (ideal lines, hardware ceilings).
pub(crate) const REFERENCE_INDEX: usize = usize::MAX;

/// The shape drawn at a series' data points (and in its legend swatch), from [`marker`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Marker {
    /// A filled disc; palette index 0's shape.
    Circle,
    /// An axis-aligned filled square.
    Square,
    /// A filled triangle pointing up.
    Triangle,
    /// A filled square standing on a corner; also reference series' shape.
    Diamond,
}

const MARKERS: [Marker; 4] = [
    Marker::Circle,
    Marker::Square,
    Marker::Triangle,
    Marker::Diamond,
];

/// The colour for palette index `index` (wrapping), or grey for [`REFERENCE_INDEX`].
pub fn color(index: usize) -> (u8, u8, u8) {
    if index == REFERENCE_INDEX {
        return REFERENCE;
    }
    PALETTE[index % PALETTE.len()]
}

/// The marker for palette index `index`. Shapes cycle faster than colours and shift by one
/// each time the colours wrap, so no two of the first 32 indices share both.
pub fn marker(index: usize) -> Marker {
    if index == REFERENCE_INDEX {
        return Marker::Diamond;
    }
    MARKERS[(index + index / PALETTE.len()) % MARKERS.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_and_marker_pairs_stay_distinct_for_many_series() {
        let pairs: std::collections::HashSet<_> = (0..32).map(|i| (color(i), marker(i))).collect();
        assert_eq!(pairs.len(), 32);
        assert_eq!(color(REFERENCE_INDEX), REFERENCE);
    }
}
