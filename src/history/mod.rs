//! The performance history: every measurement kept per commit and machine class
//! (`results/history/<class>.jsonl`, [`store`]), the steps found in each case's series
//! ([`changes`], scored on a generated corpus in `corpus`), and the series themselves
//! ([`series`]).

pub mod backfill;
pub mod changes;
#[cfg(test)]
mod corpus;
pub mod publish;
pub mod series;
pub mod steps;
pub mod store;
pub mod verdicts;
