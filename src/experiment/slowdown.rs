//! A test-only knob that makes one kernel genuinely slower, so that the regression gate can be
//! tested on real sweeps: `NBODY_BENCH_TEST_SLOWDOWN=KERNEL:K` makes every timed force
//! computation of KERNEL take K times as long (the forces and work counters are those of one
//! run): the whole part of K repeats the computation, a fractional part spins for that share of
//! the last repetition's time, so `naive:1.2` is a 20 % slower force computation (the step,
//! which also integrates, slows a little less).
//!
//! Not for measurements: a sweep run with it records it in `metadata.test_slowdown`, and `gate`
//! warns about such a file. When the variable is unset the knob costs nothing: it is read once
//! per sweep, and no kernel is wrapped.

use crate::kernels::{ForceKernel, ForceReport, KernelKind};
use crate::real::Real;
use crate::state::{Field, State};
use std::fmt;

/// The environment variable the knob is read from.
pub const SLOWDOWN_ENV: &str = "NBODY_BENCH_TEST_SLOWDOWN";

/// Largest accepted factor (a mistyped one should not make a sweep run for hours).
const MAX_FACTOR: f64 = 100.0;

/// One kernel's force computation made `factor` times as long.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TestSlowdown {
    pub kernel: KernelKind,
    pub factor: f64,
}

impl fmt::Display for TestSlowdown {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.kernel.name(), self.factor)
    }
}

impl TestSlowdown {
    /// The knob from the environment: `None` when unset or empty.
    pub fn from_env() -> Result<Option<TestSlowdown>, String> {
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

    /// Wraps `kernel` if the knob names it.
    pub fn apply<T: Real, const D: usize>(
        slowdown: Option<TestSlowdown>,
        kernel: Box<dyn ForceKernel<T, D>>,
    ) -> Box<dyn ForceKernel<T, D>> {
        match slowdown {
            Some(s) if s.kernel == kernel.kind() && s.factor > 1.0 => Box::new(Repeated {
                inner: kernel,
                factor: s.factor,
            }),
            _ => kernel,
        }
    }
}

/// A kernel whose timed computations take `factor` times as long; probes (untimed) run once.
struct Repeated<T: Real, const D: usize> {
    inner: Box<dyn ForceKernel<T, D>>,
    factor: f64,
}

impl<T: Real, const D: usize> ForceKernel<T, D> for Repeated<T, D> {
    fn kind(&self) -> KernelKind {
        self.inner.kind()
    }

    fn compute(
        &mut self,
        state: &State<T, D>,
        forces: &mut Field<T, D>,
        probe: bool,
    ) -> ForceReport {
        if probe {
            return self.inner.compute(state, forces, true);
        }
        let whole = self.factor.floor();
        for _ in 1..whole as u32 {
            self.inner.compute(state, forces, false);
        }
        let start = std::time::Instant::now();
        let report = self.inner.compute(state, forces, false);
        let extra = start.elapsed().mul_f64(self.factor - whole);
        let spin = std::time::Instant::now();
        while spin.elapsed() < extra {
            std::hint::spin_loop();
        }
        report
    }

    fn spatial_order(&mut self, state: &State<T, D>) -> Option<Vec<u32>> {
        self.inner.spatial_order(state)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::KernelParams;
    use crate::physics::Gravity;
    use crate::state::zero_field;
    use crate::testing::{SEED_1, random_state};

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
    fn wraps_only_the_named_kernel_and_keeps_its_results() {
        let law = Gravity::<f64>::new(1.0, 0.05);
        let state = random_state::<f64, 3>(64, 1.0, false, SEED_1);
        let build = |k: KernelKind| k.build::<f64, _, 3>(law, &KernelParams::default()).unwrap();
        let slow = Some(TestSlowdown {
            kernel: KernelKind::Symmetric,
            factor: 3.0,
        });
        let mut plain = build(KernelKind::Symmetric);
        let mut wrapped = TestSlowdown::apply(slow, build(KernelKind::Symmetric));
        let mut other = TestSlowdown::apply(slow, build(KernelKind::Naive));
        assert_eq!(wrapped.kind(), KernelKind::Symmetric);
        assert_eq!(other.kind(), KernelKind::Naive);
        let (mut f1, mut f2) = (zero_field::<f64, 3>(64), zero_field::<f64, 3>(64));
        let a = plain.compute(&state, &mut f1, false);
        let b = wrapped.compute(&state, &mut f2, false);
        assert_eq!(a.work, b.work, "work counters of one computation");
        assert_eq!(f1, f2);
        other.compute(&state, &mut f2, false);
    }
}
