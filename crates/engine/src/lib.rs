//! nbody-engine: interchangeable N-body force kernels and the simulation they drive.
//!
//! Layers, bottom up: [`real`], [`simd`] and [`par`] (precision, instruction set, threads),
//! [`state`] and [`physics`] (particles and pair laws), [`kernels`] (ways of visiting the
//! pairs), [`scenario`], [`integrator`], [`boundary`] and [`engine`] (a running simulation),
//! [`run`] and [`validate`] (measured runs and force checks), [`stepper`] (a simulation of any
//! type behind one interface, for measurements that are not generic), [`decomp`] (domain
//! decompositions and what ranks exchange, without MPI), [`output`] and [`export`] (files), with
//! [`stats`], [`clock`] and [`input`] beside them. Nothing here plots, reads TOML, fits models or
//! parses a command line: that is the harness's (the `nbody-bench` crate), which depends on this
//! crate and never the other way.

pub mod boundary;
pub mod clock;
pub mod decomp;
pub mod engine;
pub mod export;
pub mod geometry;
pub mod input;
pub mod integrator;
pub mod kernels;
pub mod output;
pub mod par;
pub mod physics;
pub mod real;
pub mod run;
pub mod scenario;
pub mod simd;
pub mod state;
pub mod stats;
pub mod stepper;
/// Test fixtures: in the crate's own tests, and for other crates' tests through the `testing`
/// feature (never in a build that measures).
#[cfg(any(test, feature = "testing"))]
pub mod testing;
pub mod validate;

/// The compiler that built this crate (`rustc --version`), for the results' metadata and the
/// digest MPI ranks compare.
pub const RUSTC_VERSION: &str = env!("NBODY_BENCH_RUSTC");
