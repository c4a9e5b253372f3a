//! The fmm on solid harmonics as a kernel: against the f64 direct sum at every accuracy
//! setting, level with the Cartesian family where both run (the same truncation), momentum
//! conserved to rounding, the same bits on 1, 2 and 3 threads, and what it refuses.

use super::*;

fn harmonic(theta: f64, order: usize) -> Fmm<Coulomb<f64>, f64, 3> {
    Fmm::harmonic(coulomb(), theta, order, 64).expect("Coulomb is 1/r")
}

#[test]
fn forces_at_every_setting_match_the_direct_sum() {
    let s = random_state::<f64, 3>(20_000, 10.0, true, SEED_1);
    let (want, _) = forces_of(&mut Naive::new(coulomb::<f64>()), &s, false);
    let settings = [(0.5, 4), (0.5, 8), (0.5, 12), (0.5, 16), (0.3, 20)];
    let mut errors = Vec::new();
    for &(theta, order) in &settings {
        let got = forces_of(&mut harmonic(theta, order), &s, false).0;
        let e = median_rel_err(&got, &want);
        // The bound `validate` holds the fmm to.
        assert!(
            e <= 0.25 * theta.powi(order as i32),
            "θ {theta} order {order}: median error {e:.2e}"
        );
        errors.push(e);
    }
    eprintln!("median errors {}", show(&errors));
    for k in 1..errors.len() {
        assert!(errors[k] < errors[k - 1] / 10.0, "{}", show(&errors));
    }
    // Measured on AMD 25/17/1: 6.7e-4, 9.9e-6, 1.9e-7, 4.3e-9, 5.9e-15.
    assert!(errors[4] < 1e-9, "{}", show(&errors));
}

#[test]
fn the_families_agree_where_both_run() {
    // Both truncate the double expansion at total order p: the same field to rounding.
    let s = random_state::<f64, 3>(3000, 10.0, true, SEED_2);
    for order in [1, 3, 6, 8] {
        let (cartesian, _) = forces_of(&mut Fmm::new(coulomb(), 0.6, order, 64), &s, false);
        let (harmonic, _) = forces_of(&mut harmonic(0.6, order), &s, false);
        let e = max_rel_diff(&harmonic, &cartesian);
        assert!(e < 1e-9, "order {order}: the families differ by {e:.2e}");
    }
}

#[test]
fn momentum_is_conserved_and_the_bits_do_not_depend_on_the_threads() {
    let s = random_state::<f64, 3>(6000, 10.0, true, SEED_1);
    let runs: Vec<_> = (1..=3)
        .map(|t| on_threads(t, || forces_of(&mut harmonic(0.5, 10), &s, false).0))
        .collect();
    for (t, run) in runs.iter().enumerate().skip(1) {
        assert!(*run == runs[0], "{} threads differ from one", t + 1);
    }
    let f = &runs[0];
    for d in 0..3 {
        let total: f64 = f[d].iter().sum();
        let scale: f64 = f[d].iter().map(|x| x.abs()).sum();
        assert!(
            total.abs() < 1e-12 * scale,
            "axis {d}: Σ F = {total:e} of {scale:e}"
        );
    }
}

#[test]
fn softened_laws_and_orders_past_each_family_are_refused() {
    let params = KernelParams {
        order: 12,
        ..KernelParams::default()
    };
    let err = KernelKind::FmmHarmonic
        .build::<f64, _, 3>(gravity::<f64>(), &params)
        .map(|_| ())
        .unwrap_err();
    assert!(matches!(err, KernelError::Incompatible { .. }), "{err}");
    assert!(Fmm::<_, f64, 3>::harmonic(gravity(), 0.5, 4, 64).is_none());
    let err = KernelKind::Fmm
        .build::<f64, _, 3>(coulomb::<f64>(), &params)
        .map(|_| ())
        .unwrap_err();
    assert!(err.to_string().contains("fmm-harmonic"), "{err}");
    assert!(
        KernelKind::FmmHarmonic
            .build::<f64, _, 3>(coulomb::<f64>(), &params)
            .is_ok()
    );
    let err = KernelKind::FmmHarmonic
        .build::<f64, _, 3>(
            coulomb::<f64>(),
            &KernelParams {
                order: 21,
                ..params
            },
        )
        .map(|_| ())
        .unwrap_err();
    assert!(err.to_string().contains("order"), "{err}");
}
