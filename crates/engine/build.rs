//! Records the compiler version (`nbody_engine::RUSTC_VERSION`) for the results metadata and
//! the digest MPI ranks compare.
use std::process::Command;

fn main() {
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let version = Command::new(rustc)
        .arg("--version")
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "unknown".into());
    println!("cargo:rustc-env=NBODY_BENCH_RUSTC={version}");
    println!("cargo:rerun-if-changed=build.rs");
}
