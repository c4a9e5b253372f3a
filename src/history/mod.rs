//! The performance history: every measurement kept per commit and machine class
//! (`results/history/<class>.jsonl`, [`store`]), the steps found in each case's series
//! ([`changes`], scored on a generated corpus in `corpus`), the series themselves
//! ([`series`]), the commit that made a case slower ([`bisect`]), a history as a tidy table
//! ([`tidy`]), and older commits measured into it ([`backfill`]).

pub mod backfill;
pub mod bisect;
pub mod changes;
#[cfg(test)]
mod corpus;
pub mod series;
pub mod store;
pub mod tidy;
