//! The fast multipole kernel against the direct sum: exact at θ = 0, errors falling with the
//! order and with θ, momentum conserved to rounding, the multipole field of a cluster against
//! its closed form, the same bits at every thread count, and the parameters it refuses;
//! the expansion operators alone in [`operators`].

mod harmonic_kernel;
mod operators;

use super::*;
use crate::kernels::{KernelError, KernelKind, KernelParams, Naive};
use crate::physics::{Coulomb, Gravity, LennardJones};
use crate::testing::{
    SEED_1, SEED_2, forces_of, max_rel_diff, median_rel_err, norm, on_threads,
    plummer_state as plummer, random_state,
};

fn show(e: &[f64]) -> String {
    let each: Vec<String> = e.iter().map(|x| format!("{x:.2e}")).collect();
    each.join(" ")
}

fn gravity<T: Real>() -> Gravity<T> {
    Gravity::new(1.0, 0.05)
}

fn coulomb<T: Real>() -> Coulomb<T> {
    Coulomb::new(1e-3)
}

/// θ = 0 accepts no pair of cells: the near field alone is the direct sum, forces and energy.
fn exact_at_theta0<T: Real>(tol: f64) {
    for charged in [false, true] {
        for n in [1, 2, 3, 17, 500, 3000] {
            let s = random_state::<T, 3>(n, 10.0, charged, SEED_1);
            let what = format!("{} n={n} charged={charged}", T::NAME);
            if charged {
                check_exact(coulomb::<T>(), &s, tol, &what);
            } else {
                check_exact(gravity::<T>(), &s, tol, &what);
            }
        }
    }
}

fn check_exact<T: Real, L: PairLaw<T>>(law: L, s: &State<T, 3>, tol: f64, what: &str) {
    let n = s.len();
    let (want, rw) = forces_of(&mut Naive::new(law), s, true);
    for leaf in [1, 7, 64] {
        let mut k = Fmm::new(law, 0.0, 4, leaf);
        let (got, _) = on_threads(2, || forces_of(&mut k, s, false));
        let (probed, rg) = forces_of(&mut k, s, true);
        let what = format!("{what} leaf={leaf}");
        let e = max_rel_diff(&got, &want);
        assert!(e <= tol, "{what}: max diff {e:e}");
        assert!(max_rel_diff(&probed, &want) <= tol, "{what}: probe forces");
        let (ew, eg) = (rw.energy.unwrap_or(f64::NAN), rg.energy.unwrap_or(0.0));
        assert!(
            (ew - eg).abs() <= 10.0 * tol * ew.abs().max(1.0),
            "{what}: energy {eg} vs {ew}"
        );
        // Every pair once, no cell pair accepted.
        assert_eq!(
            rg.work.pair_checks,
            (n * (n.max(1) - 1) / 2) as u64,
            "{what}"
        );
        assert_eq!(rg.work.nodes_accepted, 0, "{what}");
        assert_eq!(
            rg.work.pairs_interacting, rw.work.pairs_interacting,
            "{what}"
        );
    }
}

#[test]
fn theta_zero_is_the_direct_sum() {
    exact_at_theta0::<f64>(1e-12);
    exact_at_theta0::<f32>(1e-5);
}

/// Median relative errors against the direct sum, one per (θ, order).
fn errors<L: PairLaw<f64>>(law: L, s: &State<f64, 3>, settings: &[(f64, usize)]) -> Vec<f64> {
    let (want, _) = forces_of(&mut Naive::new(law), s, false);
    settings
        .iter()
        .map(|&(theta, order)| {
            let mut k = Fmm::new(law, theta, order, 16);
            median_rel_err(&forces_of(&mut k, s, false).0, &want)
        })
        .collect()
}

#[test]
fn error_falls_with_the_order() {
    let orders: Vec<(f64, usize)> = (1..=MAX_ORDER).map(|p| (0.4, p)).collect();
    let g = errors(gravity(), &plummer(3000, SEED_1), &orders);
    let c = errors(coulomb(), &random_state(3000, 10.0, true, SEED_2), &orders);
    eprintln!("gravity {}\ncoulomb {}", show(&g), show(&c));
    for (what, e) in [("gravity", &g), ("coulomb", &c)] {
        for p in 1..MAX_ORDER {
            assert!(
                e[p] < e[p - 1],
                "{what}: errors {} not falling at order {}",
                show(e),
                p + 1
            );
        }
        // Measured at θ = 0.4: 7.9e-7 (gravity), 4.2e-6 (Coulomb).
        assert!(e[MAX_ORDER - 1] < 1e-5, "{what}: order 8 error {:e}", e[7]);
    }
}

#[test]
fn error_falls_with_theta() {
    let thetas: Vec<(f64, usize)> = [0.8, 0.6, 0.4, 0.2, 0.1].iter().map(|&t| (t, 3)).collect();
    let g = errors(gravity(), &plummer(3000, SEED_2), &thetas);
    let c = errors(coulomb(), &random_state(3000, 10.0, true, SEED_1), &thetas);
    eprintln!("gravity {}\ncoulomb {}", show(&g), show(&c));
    for (what, e) in [("gravity", &g), ("coulomb", &c)] {
        for k in 1..e.len() {
            assert!(
                e[k] < e[k - 1],
                "{what}: errors {} not falling with θ",
                show(e)
            );
        }
        // Measured at θ = 0.2 and 0.1: 1.3e-5 and 1.8e-7 (gravity), 8.8e-5 and 7.9e-7
        // (Coulomb).
        assert!(e[3] < 2e-4 && e[4] < 2e-6, "{what}: errors {}", show(e));
    }
}

/// The total force over all particles relative to Σ|F|: zero for exact mutual interactions,
/// up to the rounding of the sums.
fn momentum_residual<T: Real>(f: &Field<T, 3>) -> f64 {
    let n = f[0].len();
    let total: f64 = (0..3)
        .map(|d| f[d].iter().map(|x| x.as_f64()).sum::<f64>().powi(2))
        .sum::<f64>()
        .sqrt();
    let scale: f64 = (0..n).map(|i| norm(f, i)).sum();
    total / scale
}

#[test]
fn total_force_vanishes_to_rounding() {
    // Each cell pair acts on both cells with exactly opposite forces in exact arithmetic, so
    // the residual is rounding: measured 1.2e-17 to 1.0e-16 of Σ|F| over these orders and θ
    // (the direct sum's own: 5.5e-17 on the sphere), where the octree, whose node
    // interactions are not mutual, leaves 1.0e-4 (θ 0.4) to 3.0e-4 (θ 0.8).
    let g = plummer::<f64, 3>(5000, SEED_1);
    let c = random_state::<f64, 3>(5000, 10.0, true, SEED_2);
    for order in [1, 2, 4, 8] {
        for theta in [0.4, 0.8] {
            let mut k = Fmm::new(gravity(), theta, order, 16);
            let (f, r) = forces_of(&mut k, &g, false);
            assert!(r.work.nodes_accepted > 0);
            let e = momentum_residual(&f);
            assert!(e < 1e-14, "gravity p={order} θ={theta}: {e:e}");
            let mut k = Fmm::new(coulomb(), theta, order, 16);
            let e = momentum_residual(&forces_of(&mut k, &c, false).0);
            assert!(e < 1e-14, "coulomb p={order} θ={theta}: {e:e}");
        }
    }
}

/// The potential of sources `s` at `y` (offsets from their centre) seen from `r` (the target
/// from the centre), to quadrupole order, as the textbook writes it: with
/// `r_s² = |r|² + ε²`, `ψ = q/r_s + P·r/r_s³ + ½ (rᵀQr − ε² T)/r_s⁵`, where `P = Σ s y`,
/// `Q = Σ s (3 y yᵀ − |y|² I)` and `T = Σ s |y|²`.
fn quadrupole_potential(y: &[[f64; 3]], s: &[f64], eps2: f64, r: [f64; 3]) -> f64 {
    let rs2 = r.iter().map(|x| x * x).sum::<f64>() + eps2;
    let rs = rs2.sqrt();
    let (mut q, mut p, mut rqr, mut t) = (0.0, 0.0, 0.0, 0.0);
    for (y, &s) in y.iter().zip(s) {
        let yy: f64 = y.iter().map(|x| x * x).sum();
        let yr: f64 = (0..3).map(|d| y[d] * r[d]).sum();
        let rr: f64 = r.iter().map(|x| x * x).sum();
        q += s;
        p += s * yr;
        rqr += s * (3.0 * yr * yr - yy * rr);
        t += s * yy;
    }
    q / rs + p / (rs2 * rs) + 0.5 * (rqr - eps2 * t) / (rs2 * rs2 * rs)
}

/// A cluster of four sources and one far particle: at order 3 the cluster acts on the
/// particle through its monopole, dipole and quadrupole exactly (the particle sits at its
/// own leaf's centre, where the local expansion's gradient is the field's), so the force must
/// match the closed form above, `F = −κ s ∇ψ` by central differences, for gravity (softened
/// and not) and for Coulomb with a net dipole. The particle's own force on the cluster is the
/// opposite.
#[test]
fn a_far_particle_feels_the_clusters_multipole_field() {
    let masses = [1.0, 2.0, 0.5, 1.5];
    cluster_field("gravity", Gravity::new(1.0, 0.0), 0.0, -1.0, masses);
    cluster_field("softened", Gravity::new(1.0, 0.3), 0.09, -1.0, masses);
    cluster_field("coulomb", coulomb(), 0.0, 1.0, [1.0, -1.0, 1.0, 0.5]);
}

/// The check above for one law: `eps2` its softening squared, `kappa` its sign and scale
/// (the energy of a pair is `κ s_i s_j / r_s`).
fn cluster_field<L: PairLaw<f64>>(what: &str, law: L, eps2: f64, kappa: f64, strengths: [f64; 4]) {
    let y = [
        [0.09, 0.0, 0.02],
        [-0.05, 0.07, 0.0],
        [0.0, -0.06, 0.08],
        [-0.04, -0.01, -0.1],
    ];
    let mut s = State::<f64, 3>::new(5);
    let target = [3.1, -1.7, 2.3];
    for d in 0..3 {
        for (k, yk) in y.iter().enumerate() {
            s.pos[d][k] = yk[d];
        }
        s.pos[d][4] = target[d];
    }
    s.source[..4].copy_from_slice(&strengths);
    s.source[4] = 0.7;
    let f = forces_of(&mut Fmm::new(law, 0.5, 3, 4), &s, false).0;

    // The cluster's expansion centre (the |s|-weighted centre) and the offsets from it.
    let w: f64 = strengths.iter().map(|x| x.abs()).sum();
    let z: [f64; 3] =
        std::array::from_fn(|d| (0..4).map(|k| strengths[k].abs() * y[k][d]).sum::<f64>() / w);
    let off: Vec<[f64; 3]> = y
        .iter()
        .map(|p| std::array::from_fn(|d| p[d] - z[d]))
        .collect();
    let r: [f64; 3] = std::array::from_fn(|d| target[d] - z[d]);
    let h = 1e-5;
    for d in 0..3 {
        let (mut up, mut down) = (r, r);
        up[d] += h;
        down[d] -= h;
        let grad = (quadrupole_potential(&off, &strengths, eps2, up)
            - quadrupole_potential(&off, &strengths, eps2, down))
            / (2.0 * h);
        let want = -kappa * s.source[4] * grad;
        let got = f[d][4];
        assert!(
            (got - want).abs() <= 1e-8 * want.abs().max(1e-3),
            "{what} component {d}: {got:e} vs {want:e}"
        );
        let on_cluster: f64 = (0..4).map(|k| f[d][k]).sum::<f64>();
        // The cluster's internal forces cancel; what is left is the far particle's.
        assert!(
            (on_cluster + got).abs() <= 1e-12 * got.abs(),
            "{what}: reaction"
        );
    }
}

#[test]
fn every_thread_count_gives_the_same_bits() {
    let g = plummer::<f64, 3>(20_000, SEED_2);
    let c = random_state::<f64, 3>(20_000, 10.0, true, SEED_1);
    let f32_state = plummer::<f32, 3>(20_000, SEED_1);
    let mut kg = Fmm::new(gravity::<f64>(), 0.6, 5, 64);
    let mut kc = Fmm::new(coulomb::<f64>(), 0.5, 4, 32);
    let mut kf = Fmm::new(gravity::<f32>(), 0.5, 3, 64);
    let runs: Vec<_> = [1, 2, 3]
        .iter()
        .map(|&p| {
            on_threads(p, || {
                (
                    forces_of(&mut kg, &g, false),
                    forces_of(&mut kc, &c, false),
                    forces_of(&mut kf, &f32_state, false).0,
                )
            })
        })
        .collect();
    for (p, run) in runs.iter().enumerate().skip(1) {
        let threads = p + 1;
        assert!(run.0.0 == runs[0].0.0, "gravity, {threads} threads");
        assert_eq!(run.0.1.work, runs[0].0.1.work);
        assert!(run.1.0 == runs[0].1.0, "coulomb, {threads} threads");
        assert!(run.2 == runs[0].2, "f32, {threads} threads");
    }
    assert!(runs[0].0.1.work.nodes_accepted > 0 && runs[0].1.1.work.nodes_accepted > 0);
}

#[test]
fn bad_parameters_and_systems_are_refused() {
    let build = |params: &KernelParams| {
        KernelKind::Fmm
            .build::<f64, _, 3>(gravity::<f64>(), params)
            .map(|_| ())
    };
    let ok = KernelParams::default();
    assert!(build(&ok).is_ok());
    for order in [0, MAX_ORDER + 1] {
        let err = build(&KernelParams { order, ..ok }).unwrap_err();
        assert!(matches!(err, KernelError::BadParam(_)), "{err}");
        assert!(err.to_string().contains("order"), "{err}");
    }
    let err = build(&KernelParams { theta: 1.0, ..ok }).unwrap_err();
    assert!(err.to_string().contains("below 1"), "{err}");
    let err = build(&KernelParams {
        fmm_leaf_size: 0,
        ..ok
    })
    .unwrap_err();
    assert!(
        err.to_string().contains("--leaf-size") && err.to_string().contains("64 is its default"),
        "{err}"
    );
    // A 2-D system (checked before the kernel is built: building it for a 2-D gravity would
    // compile every kernel for a system no scenario has), and a short-range law (the 2-D LJ
    // scenarios).
    let err = ok.validate_fmm::<2>(KernelKind::Fmm).unwrap_err();
    assert!(
        matches!(err, KernelError::Dimension { dim: 2, .. }),
        "{err}"
    );
    let lj = LennardJones::<f32>::new(1.0, 0.01, 0.025);
    let err = KernelKind::Fmm
        .build::<f32, _, 2>(lj, &ok)
        .map(|_| ())
        .unwrap_err();
    assert!(matches!(err, KernelError::Incompatible { .. }), "{err}");
    assert!(err.to_string().contains("lennard-jones"), "{err}");
}

/// No particle, and one alone: nothing to compute, and no force (and no energy) at the
/// default θ and leaf size as at any.
#[test]
fn no_particle_or_one_alone_feels_nothing() {
    for n in [0, 1] {
        let s = random_state::<f64, 3>(n, 1.0, false, SEED_1);
        let c = random_state::<f64, 3>(n, 1.0, true, SEED_2);
        for leaf in [1, 64] {
            for probe in [false, true] {
                let what = format!("n={n} leaf={leaf} probe={probe}");
                let mut k = Fmm::new(gravity::<f64>(), 0.5, 4, leaf);
                let (f, r) = on_threads(2, || forces_of(&mut k, &s, probe));
                assert!(f.iter().all(|c| c.iter().all(|x| *x == 0.0)), "{what}");
                assert_eq!(r.energy, probe.then_some(0.0), "{what}");
                assert_eq!(
                    (r.work.pair_checks, r.work.nodes_accepted),
                    (0, 0),
                    "{what}"
                );
                let mut k = Fmm::new(coulomb::<f64>(), 0.5, 8, leaf);
                let (f, _) = forces_of(&mut k, &c, probe);
                assert!(
                    f.iter().all(|c| c.iter().all(|x| *x == 0.0)),
                    "coulomb {what}"
                );
            }
        }
    }
}

#[test]
fn degenerate_configurations_terminate() {
    for n in [2, 100, 3000] {
        // All particles at one point: one leaf at the deepest level, whatever the leaf size
        // (softened gravity: no force; Coulomb: every pair quenched).
        let s = State::<f64, 3>::new(n);
        let (f, r) = forces_of(&mut Fmm::new(gravity::<f64>(), 0.5, 4, 16), &s, true);
        assert!(f.iter().all(|c| c.iter().all(|x| *x == 0.0)));
        assert_eq!(r.work.pair_checks, (n * (n - 1) / 2) as u64);
        let s = random_state::<f64, 3>(n, 0.0, true, SEED_1);
        let (f, _) = forces_of(&mut Fmm::new(coulomb::<f64>(), 0.5, 4, 16), &s, false);
        assert!(f.iter().all(|c| c.iter().all(|x| *x == 0.0)));
        // On a line, half of them coincident at the origin.
        let mut s = State::<f64, 3>::new(n);
        for i in 0..n / 2 {
            s.pos[0][i] = i as f64 * 0.01;
        }
        let (want, _) = forces_of(&mut Naive::new(gravity::<f64>()), &s, false);
        let (got, _) = forces_of(&mut Fmm::new(gravity::<f64>(), 0.0, 4, 1), &s, false);
        assert!(max_rel_diff(&got, &want) < 1e-12, "line, n={n}");
        let (got, _) = forces_of(&mut Fmm::new(gravity::<f64>(), 0.5, 6, 4), &s, false);
        let e = median_rel_err(&got, &want);
        assert!(e < 1e-2, "line, n={n}: median error {e:e}");
    }
    // Cells closer than Coulomb's quench radius are never expanded: two tight clusters that
    // pass the θ test (radii 1.7e-4, 5e-4 apart) but whose every pair is quenched feel no
    // force from each other.
    let mut s = random_state::<f64, 3>(200, 2e-4, true, SEED_2);
    for i in 100..200 {
        s.pos[0][i] += 5e-4;
    }
    let (f, r) = forces_of(&mut Fmm::new(coulomb::<f64>(), 0.9, 4, 8), &s, true);
    assert!(
        f.iter().all(|c| c.iter().all(|x| *x == 0.0)),
        "quenched clusters"
    );
    assert_eq!((r.work.nodes_accepted, r.work.pairs_interacting), (0, 0));
    // Non-finite positions give non-finite forces, not a panic or an endless walk.
    let mut s = random_state::<f64, 3>(100, 1.0, false, SEED_2);
    s.pos[0][3] = f64::NAN;
    s.pos[1][7] = f64::INFINITY;
    forces_of(&mut Fmm::new(gravity::<f64>(), 0.5, 4, 4), &s, true);
}

#[test]
fn energy_matches_the_direct_sum() {
    for (what, s, tol) in [
        ("gravity", plummer::<f64, 3>(3000, SEED_1), 1e-5),
        (
            "coulomb",
            random_state::<f64, 3>(3000, 10.0, true, SEED_2),
            1e-4,
        ),
    ] {
        let (_, want) = if what == "gravity" {
            forces_of(&mut Naive::new(gravity::<f64>()), &s, true)
        } else {
            forces_of(&mut Naive::new(coulomb::<f64>()), &s, true)
        };
        let (_, got) = if what == "gravity" {
            forces_of(&mut Fmm::new(gravity::<f64>(), 0.5, 6, 16), &s, true)
        } else {
            forces_of(&mut Fmm::new(coulomb::<f64>(), 0.5, 6, 16), &s, true)
        };
        let (w, g) = (want.energy.unwrap(), got.energy.unwrap());
        assert!((w - g).abs() <= tol * w.abs(), "{what}: {g} vs {w}");
        assert!(got.work.nodes_accepted > 0);
        assert_eq!(got.work.pairs_interacting, got.work.pair_checks, "{what}");
    }
}
