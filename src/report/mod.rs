//! `report`: REPORT.md generated from committed results.

pub mod keep;
