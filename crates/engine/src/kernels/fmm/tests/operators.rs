//! The expansion operators one at a time, at every order: M2M and L2L are exact polynomial
//! identities (the shifted expansion is the same polynomial, so only rounding may differ), and
//! M2L then L2P matches the direct sum with an error that falls with the order.

use super::super::expansion::{self, Batch, Expansion, Lanes, MAX_ORDER, terms};
use super::super::m2l;
use crate::kernels::lanes::isas_here;
use crate::kernels::rows::LANES;
use crate::physics::{Gravity, PairLaw};
use crate::testing::{SEED_1, SEED_2};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// A point uniform in the ball of radius `r` about `z`.
fn in_ball(rng: &mut Pcg64Mcg, z: [f64; 3], r: f64) -> [f64; 3] {
    loop {
        let v: [f64; 3] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
        if v.iter().map(|x| x * x).sum::<f64>() <= 1.0 {
            return std::array::from_fn(|d| z[d] + r * v[d]);
        }
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|d| a[d] - b[d])
}

/// The multipole of `sources` (position, strength) about `z`.
fn p2m_about(exp: &Expansion, sources: &[([f64; 3], f64)], z: [f64; 3]) -> Vec<f64> {
    let (mut m, mut mono) = (vec![0.0; exp.len], vec![0.0; exp.len]);
    for &(x, s) in sources {
        exp.p2m(sub(z, x), s, &mut m, &mut mono);
    }
    m
}

/// The M2L's terms, which the fork decision counts: the pairs `(n, m)` with `|n| + |m| ≤ p`.
#[test]
fn m2l_terms_count_the_pairs_of_indices() {
    for p in 1..=MAX_ORDER {
        let want: usize = (1..=6).map(|k| p + k).product::<usize>() / 720;
        assert_eq!(Expansion::new(p).m2l_terms(), want, "order {p}");
    }
}

#[test]
fn m2m_of_the_childrens_p2m_is_the_parents_p2m() {
    let mut rng = Pcg64Mcg::seed_from_u64(SEED_1);
    for p in 1..=MAX_ORDER {
        let exp = Expansion::new(p);
        let parent_z = [0.3, -0.2, 0.1];
        let mut all = Vec::new();
        let mut shifted = vec![0.0; exp.len];
        let mut mono = vec![0.0; exp.len];
        // Two children with their own centres, as M2M adds them up the tree.
        for child_z in [[0.5, 0.1, -0.2], [0.0, -0.6, 0.4]] {
            let sources: Vec<([f64; 3], f64)> = (0..12)
                .map(|_| (in_ball(&mut rng, child_z, 0.4), rng.random_range(-1.0..1.0)))
                .collect();
            let m = p2m_about(&exp, &sources, child_z);
            exp.m2m(sub(parent_z, child_z), &m, &mut shifted, &mut mono);
            all.extend(sources);
        }
        let want = p2m_about(&exp, &all, parent_z);
        let scale = want.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        for (n, (got, want)) in shifted.iter().zip(&want).enumerate() {
            assert!(
                (got - want).abs() <= 1e-13 * scale,
                "order {p}, coefficient {n}: {got:e} vs {want:e}"
            );
        }
    }
}

#[test]
fn l2l_moves_the_local_expansion_without_changing_it() {
    let mut rng = Pcg64Mcg::seed_from_u64(SEED_2);
    for p in 1..=MAX_ORDER {
        let exp = Expansion::new(p);
        let mut mono = vec![0.0; exp.len];
        for _ in 0..20 {
            let parent: Vec<f64> = (0..exp.len).map(|_| rng.random_range(-1.0..1.0)).collect();
            let d = in_ball(&mut rng, [0.0; 3], 1.0);
            let r = in_ball(&mut rng, [0.0; 3], 1.0);
            let mut child = vec![0.0; exp.len];
            exp.l2l(d, &parent, &mut child, &mut mono);
            // The point r from the child's centre is r + d from the parent's.
            let at = std::array::from_fn(|k| r[k] + d[k]);
            let (got_grad, got) = exp.l2p(r, &child, true, &mut mono);
            let (want_grad, want) = exp.l2p(at, &parent, true, &mut mono);
            // The size of the sum's terms, which its rounding scales with.
            exp.monomials(at.map(f64::abs), &mut mono);
            let scale: f64 = parent.iter().zip(&mono).map(|(l, m)| l.abs() * m).sum();
            assert!(
                (got - want).abs() <= 1e-13 * scale,
                "order {p}: potential {got:e} vs {want:e}"
            );
            for k in 0..3 {
                assert!(
                    (got_grad[k] - want_grad[k]).abs() <= 1e-13 * scale,
                    "order {p}: gradient {k}: {:e} vs {:e}",
                    got_grad[k],
                    want_grad[k]
                );
            }
        }
    }
}

/// The local expansion about `z_a` of the multipole `m` about `z_b`, by the kernel's M2L with
/// the source in lane 0 and zero multipoles in the other lanes (as a cell's last batch of
/// partners is padded).
fn m2l_one<L: PairLaw<f64>>(exp: &Expansion, law: &L, r: [f64; 3], m: &[f64]) -> Vec<f64> {
    let mut b = Batch::new(exp.len);
    b.r = std::array::from_fn(|d| [r[d]; LANES]);
    for (row, &v) in b.mb.iter_mut().zip(m) {
        row[0] = v;
    }
    let r2: f64 = r.iter().map(|x| x * x).sum();
    let coeff = [law.coeff(r2, 1.0, 1.0); LANES];
    let soft = [r2 + law.softening2(); LANES];
    expansion::scaled_derivatives(&coeff, &soft, exp.p, &mut b.dj);
    exp.m2l_lanes(&mut b, 0);
    b.la.iter().map(|row| row[0]).collect()
}

/// Sources within 0.5 of one centre, targets within 0.5 of another at random well-separated
/// offsets (the radii add up to half the distance, as at θ = 0.5): the potential and field of
/// M2L then L2P against the direct sum of gravity (`ψ = −G Σ s / r_s`, `∇ψ = G Σ s (y − x) /
/// r_s³`), unsoftened and softened, charges of both signs. The error is the truncation's:
/// at most `Σ|s| ρ^{p+1} / (|R| − a − b)` with ρ = (a + b)/|R| (Dehnen 2002) for the
/// potential, and `(p + 1)` times that over `|R| − a − b` for the field; measured at up to
/// 0.08 and 0.15 of these at order 1, falling to 0.01 and 0.016 at order 8 (the errors fall
/// faster than ρ^{p+1} here: few sources and targets sit at the cells' edges).
#[test]
fn m2l_matches_the_direct_sum_within_a_bound_falling_with_the_order() {
    let mut rng = Pcg64Mcg::seed_from_u64(SEED_1);
    for eps in [0.0, 0.2] {
        let law = Gravity::<f64>::new(1.0, eps);
        for _ in 0..10 {
            let zb = in_ball(&mut rng, [0.0; 3], 2.0);
            let dir = in_ball(&mut rng, [0.0; 3], 1.0);
            let len = dir.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-3);
            let (a, b) = (0.5, 0.5);
            let reach = 2.0 * (a + b);
            let za: [f64; 3] = std::array::from_fn(|d| zb[d] + reach * dir[d] / len);
            let sources: Vec<([f64; 3], f64)> = (0..30)
                .map(|_| (in_ball(&mut rng, zb, a), rng.random_range(-1.0..1.0)))
                .collect();
            let targets: Vec<[f64; 3]> = (0..10).map(|_| in_ball(&mut rng, za, b)).collect();
            let total: f64 = sources.iter().map(|(_, s)| s.abs()).sum();
            let rho = (a + b) / reach;
            let gap = reach - a - b;
            for p in 1..=MAX_ORDER {
                let exp = Expansion::new(p);
                let m = p2m_about(&exp, &sources, zb);
                let local = m2l_one(&exp, &law, sub(za, zb), &m);
                let bound = total * rho.powi(p as i32 + 1) / gap;
                let mut mono = vec![0.0; terms(p)];
                for &y in &targets {
                    let (grad, psi) = exp.l2p(sub(y, za), &local, true, &mut mono);
                    let (mut want, mut want_grad) = (0.0, [0.0; 3]);
                    for &(x, s) in &sources {
                        let dx = sub(y, x);
                        let rs2 = dx.iter().map(|v| v * v).sum::<f64>() + eps * eps;
                        want -= s / rs2.sqrt();
                        for d in 0..3 {
                            want_grad[d] += s * dx[d] / (rs2 * rs2.sqrt());
                        }
                    }
                    let what = format!("ε {eps} order {p}");
                    assert!((psi - want).abs() <= bound, "{what}: ψ {psi:e} vs {want:e}");
                    let field = (0..3)
                        .map(|d| (grad[d] - want_grad[d]).powi(2))
                        .sum::<f64>()
                        .sqrt();
                    let field_bound = (p + 1) as f64 * bound / gap;
                    assert!(field <= field_bound, "{what}: ∇ψ off by {field:e}");
                }
            }
        }
    }
}

/// A batch of 16 random partners (offsets, derivatives and multipoles of both signs, one
/// lane zero as a padded batch has): the vector M2L of each instruction set this machine has
/// against the portable loop at every order; each lane's coefficients agree to a few units of
/// rounding of their magnitude (the vector loop fuses its multiply-adds).
#[test]
fn vector_m2l_matches_the_portable_loop_at_every_order() {
    let mut rng = Pcg64Mcg::seed_from_u64(SEED_2);
    let mut lanes = || -> Lanes { std::array::from_fn(|_| rng.random::<f64>() * 2.0 - 1.0) };
    for p in 1..=MAX_ORDER {
        let exp = Expansion::new(p);
        let len = exp.len;
        let mut b = Batch::new(len);
        b.r = std::array::from_fn(|_| lanes());
        b.dj = (0..=MAX_ORDER).map(|_| lanes()).collect();
        b.mb = (0..len).map(|_| lanes()).collect();
        for row in &mut b.mb {
            row[LANES - 1] = 0.0;
        }
        let start: Vec<Lanes> = (0..len).map(|_| lanes()).collect();
        let run = |isa: Option<m2l::Isa>| {
            let mut b = Batch {
                la: start.clone(),
                mono: start.clone(),
                t: start.clone(),
                r: b.r,
                dj: b.dj.clone(),
                mb: b.mb.clone(),
            };
            // SAFETY: `isas_here` lists only what this CPU has.
            unsafe { m2l::m2l_batch(isa, &exp, &mut b, 1) };
            b.la
        };
        let want = run(None);
        assert_eq!(
            want[0], start[0],
            "order {p}: the potential was not asked for"
        );
        assert_ne!(want[1], start[1], "order {p}: nothing added");
        for isa in isas_here() {
            let got = run(Some(isa));
            assert_eq!(
                got[0], start[0],
                "{isa:?} order {p}: the potential was not asked for"
            );
            for m in 1..len {
                for l in 0..LANES {
                    let tol = 1e-12 * (1.0 + want[m][l].abs());
                    assert!(
                        (got[m][l] - want[m][l]).abs() <= tol,
                        "{isa:?} order {p}, coefficient {m} lane {l}: {} against {}",
                        got[m][l],
                        want[m][l]
                    );
                }
            }
        }
    }
}
