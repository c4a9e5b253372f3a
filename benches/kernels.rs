//! Criterion micro-benchmarks of every kernel: `cargo bench` (a few minutes), or
//! `cargo bench -- --quick` (seconds). Large n × p sweeps belong to `nbody-bench sweep`.
//!
//! - `force/<scenario>/<kernel>`: one force computation over a few n, throughput in pair
//!   evaluations (the kernel's own pair-check count); for the Verlet list, a step between
//!   rebuilds (the list is kept);
//! - `step/<scenario>`: one full velocity-Verlet step of every kernel, in particle-steps;
//! - `build/<scenario>/<kernel>`: the cell-list binning, the octree and the Verlet list's build
//!   alone, in particles.
//!
//! Systems, kernels and buffers are built outside the timed loop.

mod groups;

criterion::criterion_main!(
    groups::force::benches,
    groups::step::benches,
    groups::build::benches
);
