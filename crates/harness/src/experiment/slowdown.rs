//! A test-only knob that makes one kernel genuinely slower, so that the regression gate can be
//! tested on real sweeps: `NBODY_BENCH_TEST_SLOWDOWN=KERNEL:K` makes every timed force
//! computation of KERNEL take K times as long, with the forces and work counters of one
//! computation (the engine's `kernels::repeated`), so `naive:1.2` is a 20 % slower force
//! computation.
//!
//! Not for measurements: it is read only in a build with the `test-slowdown` feature (CI's, for
//! the gate's tests), where a sweep that applies it says so; this module is the one place that
//! feature is looked at in the harness. When the variable is unset it costs nothing: it is read
//! once per sweep, and no kernel is wrapped.

use nbody_engine::kernels::{KernelKind, KernelParams};
use nbody_engine::run::RunError;
use nbody_engine::scenario::{Setup, SetupError};
use nbody_engine::stepper::Stepper;
use std::fmt;

/// Whether this build has the knob (the `test-slowdown` feature): without it the variable is
/// never read and no kernel is slowed.
pub const ENABLED: bool = cfg!(feature = "test-slowdown");

/// Why a command that slows a kernel on purpose refuses in a build without the knob.
pub const NOT_ENABLED: &str = "this slows a kernel on purpose and needs a build with the \
    test-slowdown feature: cargo build --release --features test-slowdown (never measure \
    anything else with that build)";

/// The environment variable the knob is read from.
pub(crate) const SLOWDOWN_ENV: &str = "NBODY_BENCH_TEST_SLOWDOWN";

/// Largest accepted factor (a mistyped one should not make a sweep run for hours).
const MAX_FACTOR: f64 = 100.0;

/// One kernel's force computation made `factor` times as long.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct TestSlowdown {
    pub kernel: KernelKind,
    pub factor: f64,
}

impl fmt::Display for TestSlowdown {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.kernel.name(), self.factor)
    }
}

impl TestSlowdown {
    /// The knob from the environment: `None` when unset or empty, and in a build without it.
    pub(crate) fn from_env() -> Result<Option<TestSlowdown>, String> {
        if !ENABLED {
            return Ok(None);
        }
        match std::env::var(SLOWDOWN_ENV) {
            Ok(v) if !v.trim().is_empty() => Self::parse(&v).map(Some),
            _ => Ok(None),
        }
    }

    /// Parses `KERNEL:K`, e.g. `symmetric:3`.
    pub fn parse(text: &str) -> Result<TestSlowdown, String> {
        let bad = |why: String| {
            format!("{SLOWDOWN_ENV}=`{text}`: {why}; expected KERNEL:K such as symmetric:3")
        };
        let (name, factor) = text
            .trim()
            .split_once(':')
            .ok_or_else(|| bad("no `:`".into()))?;
        let kernel = KernelKind::ALL
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or_else(|| bad(format!("unknown kernel `{name}`")))?;
        let factor = factor
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|k| (1.0..=MAX_FACTOR).contains(k))
            .ok_or_else(|| bad(format!("K must be a number from 1 to {MAX_FACTOR}")))?;
        Ok(TestSlowdown { kernel, factor })
    }

    /// How many times as long `kernel`'s timed force computations are to take (1 for a
    /// kernel the knob does not name); the engine's `kernels::repeated` does it.
    #[cfg_attr(not(feature = "test-slowdown"), allow(dead_code))]
    pub(crate) fn factor_for(&self, kernel: KernelKind) -> f64 {
        if self.kernel == kernel {
            self.factor
        } else {
            1.0
        }
    }
}

/// The stepper of `kernel` on the system of `setup`, its force computations slowed when
/// `knob` names it (the engine's `kernels::repeated`, compiled with the feature only).
pub(crate) fn stepper(
    knob: Option<TestSlowdown>,
    setup: &Setup,
    kernel: KernelKind,
    params: &KernelParams,
) -> Result<Result<Box<dyn Stepper>, RunError>, SetupError> {
    #[cfg(feature = "test-slowdown")]
    if let Some(knob) = knob {
        let repeat = nbody_engine::kernels::repeated::Repeat(knob.factor_for(kernel));
        return nbody_engine::stepper::decorated_stepper(setup, kernel, params, repeat);
    }
    let _ = knob;
    nbody_engine::stepper::stepper(setup, kernel, params)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_refuses() {
        assert_eq!(
            TestSlowdown::parse("symmetric:3"),
            Ok(TestSlowdown {
                kernel: KernelKind::Symmetric,
                factor: 3.0
            })
        );
        assert_eq!(TestSlowdown::parse("naive:1.2").unwrap().factor, 1.2);
        assert_eq!(
            TestSlowdown::parse("per-thread:1").unwrap().to_string(),
            "per-thread:1"
        );
        for bad in [
            "symmetric",
            "fast:2",
            "naive:0",
            "naive:0.5",
            "naive:x",
            "naive:1000",
            "naive:NaN",
        ] {
            let e = TestSlowdown::parse(bad).unwrap_err();
            assert!(e.contains(SLOWDOWN_ENV) && e.contains(bad), "{e}");
        }
    }

    #[test]
    fn slows_only_the_named_kernel() {
        let knob = TestSlowdown::parse("symmetric:3").unwrap();
        assert_eq!(knob.factor_for(KernelKind::Symmetric), 3.0);
        assert_eq!(knob.factor_for(KernelKind::Naive), 1.0);
    }
}
