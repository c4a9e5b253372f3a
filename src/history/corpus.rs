//! The corpus of generated series the change-point detection is scored on (being written).
