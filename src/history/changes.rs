//! Change points of a performance history (being written).
