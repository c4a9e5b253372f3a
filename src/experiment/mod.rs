//! The experiment runner: sweep configs → planned cases → measured rounds → results file.

pub mod config;
pub mod config_keys;
pub mod estimate;
pub mod external;
pub mod kernel_or_program;
pub mod launcher;
pub mod locate;
pub mod lock;
pub mod measure;
pub mod plan;
pub mod progress;
pub mod reference;
pub mod results;
pub mod runner;
#[cfg(feature = "test-slowdown")]
pub mod slowdown;
pub mod vet;
