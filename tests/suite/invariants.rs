//! Physical invariants of the force kernels, over random seeded configurations (proptest):
//! Newton's third law (Σ F ≈ 0), translation invariance and permutation invariance.

use nbody_engine::kernels::{CompiledKernels, KernelKind, KernelParams};
use nbody_engine::physics::{Coulomb, Gravity, LennardJones};
use nbody_engine::state::{Field, State, zero_field};
use nbody_engine::testing::{random_state, spaced_state};
use proptest::prelude::*;

fn forces<L: CompiledKernels<f64, D>, const D: usize>(
    kind: KernelKind,
    law: L,
    s: &State<f64, D>,
) -> Field<f64, D> {
    let mut k = kind
        .build::<f64, L, D>(
            law,
            &KernelParams {
                theta: 0.0,
                leaf_size: 4,
                ..KernelParams::default()
            },
        )
        .unwrap();
    let mut f = zero_field(s.len());
    k.compute(s, &mut f, false);
    f
}

/// Largest |component| of the summed force relative to the summed magnitudes.
fn net_force_ratio<const D: usize>(f: &Field<f64, D>) -> f64 {
    let scale: f64 = (0..f[0].len())
        .map(|i| (0..D).map(|d| f[d][i].abs()).sum::<f64>())
        .sum::<f64>()
        .max(1e-300);
    (0..D)
        .map(|d| f[d].iter().sum::<f64>().abs())
        .fold(0.0, f64::max)
        / scale
}

fn check_invariants<L: CompiledKernels<f64, D>, const D: usize>(
    law: L,
    s: State<f64, D>,
    shift: f64,
    perm_seed: u64,
) {
    let n = s.len();
    for kind in KernelKind::ALL
        .into_iter()
        .filter(|k| k.supports(law.kind()))
    {
        let f = forces(kind, law, &s);
        prop_assert_lt(net_force_ratio(&f), 1e-9, &format!("{kind:?}: net force"));
        // Translation: the same forces when every particle moves by `shift`.
        let mut moved = s.clone();
        moved.pos.iter_mut().flatten().for_each(|x| *x += shift);
        let g = forces(kind, law, &moved);
        // Permutation: the same force on each particle (by id) when the arrays are shuffled.
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut x = perm_seed | 1;
        for i in (1..n).rev() {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            order.swap(i, (x % (i as u64 + 1)) as usize);
        }
        let mut shuffled = s.clone();
        shuffled.permute(&order, &mut []);
        let h = forces(kind, law, &shuffled);
        let slot = shuffled.slots_by_id();
        let scale = f
            .iter()
            .flatten()
            .map(|v| v.abs())
            .fold(0.0, f64::max)
            .max(1e-300);
        for i in 0..n {
            for d in 0..D {
                prop_assert_lt(
                    (g[d][i] - f[d][i]).abs() / scale,
                    1e-6,
                    &format!("{kind:?}: translation"),
                );
                prop_assert_lt(
                    (h[d][slot[i]] - f[d][i]).abs() / scale,
                    1e-9,
                    &format!("{kind:?}: permutation"),
                );
            }
        }
    }
}

fn prop_assert_lt(a: f64, b: f64, what: &str) {
    assert!(a < b, "{what}: {a:e} >= {b:e}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn lennard_jones_2d(n in 2usize..300, seed in any::<u64>(), shift in -5.0f64..5.0, perm in any::<u64>()) {
        let s = spaced_state::<f64, 2>(n, 0.2, 0.008, seed);
        check_invariants(LennardJones::<f64>::new(1.0, 0.01, 0.025), s, shift, perm);
    }

    #[test]
    fn gravity_3d(n in 2usize..300, seed in any::<u64>(), shift in -5.0f64..5.0, perm in any::<u64>()) {
        check_invariants(Gravity::<f64>::new(1.0, 0.01), random_state::<f64, 3>(n, 1.0, false, seed), shift, perm);
    }

    #[test]
    fn coulomb_3d(n in 2usize..300, seed in any::<u64>(), shift in -5.0f64..5.0, perm in any::<u64>()) {
        check_invariants(Coulomb::<f64>::new(1e-3), random_state::<f64, 3>(n, 1.0, true, seed), shift, perm);
    }
}
