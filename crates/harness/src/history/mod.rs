//! The performance history: every measurement kept per commit and machine class
//! (`results/history/<class>.jsonl`, [`store`], read by one line reader, `lines`, with
//! dates compared as [`instant`]s), the steps found in each case's series
//! ([`changes`]) and the drifts beside them ([`drifts`], lines fitted by [`trend`]), scored on a
//! generated corpus in `corpus`, the series themselves ([`series`]) and their steps and drifts
//! ([`steps`]), the gate's verdicts kept beside them
//! ([`verdicts`]), the commit that made a case slower ([`bisect`]), a history as a tidy table
//! ([`tidy`]) and as a page and a pull-request summary ([`publish`]), and older commits
//! measured into it ([`backfill`]).

pub mod backfill;
pub mod bisect;
pub mod changes;
#[cfg(test)]
mod corpus;
pub mod drifts;
pub mod instant;
mod lines;
pub mod publish;
pub mod series;
pub mod steps;
pub mod store;
pub mod tidy;
pub mod trend;
pub mod verdicts;
