//! The octree against the naive direct sum: exact at θ = 0, errors ordered by θ and bounded at
//! θ = 0.5, degenerate configurations, determinism and independence of the particle order; the
//! quadrupole order against an analytic cluster and below the monopole's error.

use super::*;
use crate::kernels::Naive;
use crate::physics::{Coulomb, Gravity};
use crate::state::zero_field;
use crate::testing::{
    SEED_1, SEED_2, forces_of, max_rel_diff, median_rel_err, plummer_state as plummer, random_state,
};

fn pool(p: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(p)
        .build()
        .expect("thread pool")
}

fn gravity<T: Real>() -> Gravity<T> {
    Gravity::new(1.0, 0.05)
}

fn coulomb<T: Real>() -> Coulomb<T> {
    Coulomb::new(1e-3)
}

/// θ = 0 opens every node: the tree must reproduce the direct sum, forces and energy.
fn exact_at_theta0<T: Real, const D: usize>(tol: f64) {
    for charged in [false, true] {
        for n in [1, 2, 3, 17, 500, 3000] {
            let s = random_state::<T, D>(n, 10.0, charged, SEED_1);
            for p in [1, 2] {
                let what = format!("{} D={D} n={n} p={p} charged={charged}", T::NAME);
                pool(p).install(|| {
                    if charged {
                        check_exact(coulomb::<T>(), &s, tol, &what);
                    } else {
                        check_exact(gravity::<T>(), &s, tol, &what);
                    }
                });
            }
        }
    }
}

fn check_exact<T: Real, L: PairLaw<T>, const D: usize>(
    law: L,
    s: &State<T, D>,
    tol: f64,
    what: &str,
) {
    let (want, rw) = forces_of(&mut Naive::new(law), s, true);
    for multipole in Multipole::ALL {
        let what = format!("{what} {}", multipole.name());
        check_exact_order(law, s, &want, &rw, multipole, tol, &what);
    }
}

fn check_exact_order<T: Real, L: PairLaw<T>, const D: usize>(
    law: L,
    s: &State<T, D>,
    want: &Field<T, D>,
    rw: &ForceReport,
    multipole: Multipole,
    tol: f64,
    what: &str,
) {
    let n = s.len();
    let mut tree = Octree::with_multipole(law, 0.0, 16, multipole);
    let (got, _) = forces_of(&mut tree, s, false);
    let (probed, rg) = forces_of(&mut tree, s, true);
    let diff = max_rel_diff(&got, want);
    assert!(diff <= tol, "{what}: max diff {diff:e} > {tol:e}");
    assert!(max_rel_diff(&probed, want) <= tol, "{what}: probe forces");
    let (ew, eg) = (rw.energy.unwrap_or(f64::NAN), rg.energy.unwrap_or(0.0));
    // The energy is a sum of terms of both signs (Coulomb): compare against their scale.
    let scale = ew.abs().max(1.0);
    assert!(
        (ew - eg).abs() <= 10.0 * tol * scale,
        "{what}: energy {eg} vs {ew}"
    );
    // Every ordered pair but the self-pairs, nothing accepted.
    assert_eq!(rg.work.pair_checks, (n * (n - 1)) as u64, "{what}");
    assert_eq!(rg.work.nodes_accepted, 0, "{what}");
    assert_eq!(
        rg.work.pairs_interacting, rw.work.pairs_interacting,
        "{what}"
    );
}

#[test]
fn theta_zero_is_the_direct_sum_f64() {
    exact_at_theta0::<f64, 2>(1e-10);
    exact_at_theta0::<f64, 3>(1e-10);
}

#[test]
fn theta_zero_is_the_direct_sum_f32() {
    exact_at_theta0::<f32, 2>(1e-4);
    exact_at_theta0::<f32, 3>(1e-4);
}

/// Median relative error of the tree against the direct sum at several θ.
fn errors<T: Real, L: PairLaw<T>, const D: usize>(
    law: L,
    s: &State<T, D>,
    thetas: &[f64],
) -> Vec<f64> {
    errors_of_order(law, s, thetas, Multipole::Monopole)
}

fn errors_of_order<T: Real, L: PairLaw<T>, const D: usize>(
    law: L,
    s: &State<T, D>,
    thetas: &[f64],
    multipole: Multipole,
) -> Vec<f64> {
    let (want, _) = forces_of(&mut Naive::new(law), s, false);
    thetas
        .iter()
        .map(|&theta| {
            let mut k = Octree::with_multipole(law, theta, 16, multipole);
            let (got, _) = forces_of(&mut k, s, false);
            median_rel_err(&got, &want)
        })
        .collect()
}

#[test]
fn gravity_error_grows_with_theta_and_is_small_at_half() {
    let thetas = [0.3, 0.5, 0.8];
    let e3 = errors(gravity::<f64>(), &plummer::<f64, 3>(3000, SEED_1), &thetas);
    let e3f = errors(gravity::<f32>(), &plummer::<f32, 3>(3000, SEED_1), &thetas);
    let e2 = errors(gravity::<f64>(), &plummer::<f64, 2>(3000, SEED_2), &thetas);
    // Measured: 3-D 1.6e-4, 5.4e-4, 2.1e-3 (f32 the same); 2-D 2.7e-3, 7.5e-3, 2.0e-2.
    for (what, e, bound) in [
        ("3-D f64", &e3, 1e-3),
        ("3-D f32", &e3f, 1e-3),
        ("2-D f64", &e2, 1e-2),
    ] {
        assert!(
            e[0] < e[1] && e[1] < e[2],
            "{what}: errors {e:?} not increasing with θ"
        );
        // A 1/r² law in a plane draws as much force from each octave of distance (in 3-D the
        // far field dominates), so the first accepted nodes, whose monopole error is largest,
        // carry more of the force: the disc's error is ~15× the sphere's at the same θ. The
        // quadtree itself is checked against the octree in `quadtree_equals_octree_on_a_plane`.
        assert!(e[1] <= bound, "{what}: median error {:e} at θ = 0.5", e[1]);
    }
}

#[test]
fn mixed_sign_coulomb_error_is_bounded() {
    // Alternating ±1 charges spread uniformly. Each sign has its own tree, whose monopoles are
    // as accurate as gravity's on the same positions (median 8.3e-4 at θ = 0.5, measured with
    // like charges on this state); but the net force is the small residual of the two trees'
    // partial forces, so their errors are amplified. Measured at θ = 0.3 / 0.5 / 0.8:
    // 9.5e-4 / 3.9e-3 / 1.4e-2 in 3-D; 7.4e-4 at θ = 0.5 in 2-D. Bound at θ = 0.5: 1e-2.
    let thetas = [0.3, 0.5, 0.8];
    let s3 = random_state::<f64, 3>(3000, 10.0, true, SEED_1);
    let e3 = errors(coulomb::<f64>(), &s3, &thetas);
    let e2 = errors(
        coulomb::<f64>(),
        &random_state::<f64, 2>(3000, 10.0, true, SEED_2),
        &[0.5],
    );
    assert!(
        e3[0] < e3[1] && e3[1] < e3[2],
        "3-D errors {e3:?} not increasing with θ"
    );
    assert!(e3[1] <= 1e-2, "3-D median error {:e}", e3[1]);
    assert!(e2[0] <= 1e-2, "2-D median error {:e}", e2[0]);
    // Both signs got a tree.
    let mut k = Octree::new(coulomb::<f64>(), 0.5, 8);
    let (_, r) = forces_of(&mut k, &s3, false);
    assert_eq!(k.tree.roots.len(), 2);
    assert!(r.work.nodes_accepted > 0);
}

#[test]
fn degenerate_configurations_terminate() {
    for n in [2, 100, 5000] {
        // All particles at one point: one leaf at the maximal depth (softened gravity: no
        // force; Coulomb: every pair quenched).
        let s = State::<f64, 3>::new(n);
        let (f, r) = forces_of(&mut Octree::new(gravity::<f64>(), 0.5, 16), &s, true);
        assert!(f.iter().all(|c| c.iter().all(|x| *x == 0.0)));
        assert_eq!(r.work.pair_checks, (n * (n - 1)) as u64);
        let s = random_state::<f64, 3>(n, 0.0, true, SEED_1);
        let (f, _) = forces_of(&mut Octree::new(coulomb::<f64>(), 0.5, 16), &s, false);
        assert!(f.iter().all(|c| c.iter().all(|x| *x == 0.0)));
        // On a line, half of them coincident at the origin.
        let mut s = State::<f32, 2>::new(n);
        for i in 0..n / 2 {
            s.pos[0][i] = i as f32 * 0.01;
        }
        let (want, _) = forces_of(&mut Naive::new(gravity::<f32>()), &s, false);
        let (got, _) = forces_of(&mut Octree::new(gravity::<f32>(), 0.0, 1), &s, false);
        assert!(max_rel_diff(&got, &want) < 1e-4, "line, n={n}");
        let (got, _) = forces_of(&mut Octree::new(gravity::<f32>(), 0.5, 1), &s, false);
        // On a uniform line the pulls from both sides nearly cancel (the net force is ~a/x of
        // either side's, a the spacing), which amplifies relative errors: measured 9e-3 and
        // 1.2e-2 at n = 100 and 5000.
        let e = median_rel_err(&got, &want);
        assert!(e < 5e-2, "line, n={n}: median error {e:e}");
    }
    // Non-finite positions give non-finite forces, not a panic or an endless walk.
    let mut s = random_state::<f64, 3>(100, 1.0, false, SEED_2);
    s.pos[0][3] = f64::NAN;
    s.pos[1][7] = f64::INFINITY;
    forces_of(&mut Octree::new(gravity::<f64>(), 0.5, 4), &s, true);
}

#[test]
fn serial_parallel_and_permuted_runs_agree() {
    for multipole in Multipole::ALL {
        serial_parallel_and_permuted::<f64>(multipole);
        serial_parallel_and_permuted::<f32>(multipole);
    }
}

fn serial_parallel_and_permuted<T: Real>(multipole: Multipole) {
    let s = plummer::<T, 3>(20_000, SEED_2);
    let mut k = Octree::with_multipole(gravity::<T>(), 0.5, 16, multipole);
    let (serial, r1) = pool(1).install(|| forces_of(&mut k, &s, false));
    let (par, r2) = pool(2).install(|| forces_of(&mut k, &s, false));
    assert_eq!(
        serial, par,
        "{multipole:?}: the walk does not depend on the thread count"
    );
    assert_eq!(r1.work, r2.work);
    assert!(r1.work.nodes_accepted > 0 && r1.work.pair_checks < 20_000 * 20_000 / 4);

    // In tree order the same tree is built, so the forces match per particle id.
    let mut sorted = s.clone();
    let order = k.spatial_order(&s).expect("the octree has an order");
    sorted.permute(&order, &mut []);
    let (f, r3) = forces_of(&mut k, &sorted, false);
    assert_eq!(r3.work, r1.work);
    for (slot, &id) in sorted.id.iter().enumerate() {
        for d in 0..3 {
            assert_eq!(f[d][slot], serial[d][id as usize]);
        }
    }
}

#[test]
fn morton_keys_interleave_bits() {
    use super::tree::max_depth;
    assert_eq!(max_depth(3), 21);
    assert_eq!(max_depth(2), 31);
    // Two particles in opposite corners of the cube split at the root.
    let mut s = State::<f64, 3>::new(2);
    s.pos[0][1] = 1.0;
    s.pos[1][1] = 1.0;
    s.pos[2][1] = 1.0;
    let mut k = Octree::new(gravity::<f64>(), 0.5, 1);
    assert_eq!(k.spatial_order(&s), Some(vec![0, 1]));
    s.pos[0].swap(0, 1);
    s.pos[1].swap(0, 1);
    s.pos[2].swap(0, 1);
    assert_eq!(k.spatial_order(&s), Some(vec![1, 0]));
}

#[test]
fn quadtree_equals_octree_on_a_plane() {
    // A planar set in 3-D (z = 0) gives the octree the quadtree's cells, sides and groups, so
    // both must compute the same forces: a check of the 2-D tree independent of the accuracy.
    let s2 = plummer::<f64, 2>(3000, SEED_1);
    let mut s3 = State::<f64, 3>::new(s2.len());
    for d in 0..2 {
        s3.pos[d].clone_from(&s2.pos[d]);
    }
    s3.source.clone_from(&s2.source);
    let (f2, r2) = forces_of(&mut Octree::new(gravity::<f64>(), 0.5, 8), &s2, false);
    let (f3, r3) = forces_of(&mut Octree::new(gravity::<f64>(), 0.5, 8), &s3, false);
    assert_eq!(r2.work, r3.work);
    let f3xy: Field<f64, 2> = [f3[0].clone(), f3[1].clone()];
    assert!(max_rel_diff(&f2, &f3xy) < 1e-12);
}

/// Two equal sources at c ± a·e_x seen by a far target along x and along y: the listed node
/// must match the direct sum to O((a/r)⁴) (the octupole vanishes by symmetry), the monopole
/// only to O((a/r)²). Halving a/r divides the quadrupole's error by ~16 and the monopole's by
/// ~4. Checks the sign convention of the expansion for gravity (softened and not) and Coulomb
/// (κ < 0), in 3-D and 2-D, for the force and the energy.
fn cluster_field<L: PairLaw<f64>, const D: usize>(law: L, what: &str) {
    let (a, c) = (0.1, [0.3; D]);
    let mut s = State::<f64, D>::new(2);
    for d in 0..D {
        s.pos[d][0] = c[d];
        s.pos[d][1] = c[d];
    }
    s.pos[0][0] += a;
    s.pos[0][1] -= a;
    s.source.fill(1.5);
    let mut tree = super::tree::Tree::<f64, D>::new(0.5, 2, GROUP_SIZE, true);
    tree.build(&s);
    assert_eq!(tree.nodes.len(), 1, "{what}: one leaf");
    let mut list = super::nodes::NodeList::<f64, D>::new();
    list.fill(&tree, &[0]);
    for axis in [0, 1] {
        // (force error, energy error) of (monopole, quadrupole) at distance r.
        let errors = |r: f64| {
            let mut x = c;
            x[axis] += r;
            let t = crate::kernels::rows::Target { x, s: 0.5 };
            let (mut f, mut e) = ([0.0; D], 0.0);
            for j in 0..2 {
                let dx: [f64; D] = std::array::from_fn(|d| s.pos[d][j] - x[d]);
                let fj = crate::physics::pair_force(&law, dx, t.s, s.source[j]);
                for d in 0..D {
                    f[d] += fj[d];
                }
                let r2: f64 = dx.iter().map(|v| v * v).sum();
                e += law.energy(r2, t.s, s.source[j]);
            }
            let quad = list.gather::<L, true>(&law, &t);
            // The monopole: the node as one particle at c.
            let dc: [f64; D] = std::array::from_fn(|d| c[d] - x[d]);
            let mono = crate::physics::pair_force(&law, dc, t.s, 3.0);
            let e_mono = law.energy(r * r, t.s, 3.0);
            let rel = |g: &[f64; D]| {
                let err: f64 = (0..D).map(|d| (g[d] - f[d]).powi(2)).sum::<f64>().sqrt();
                err / f.iter().map(|v| v * v).sum::<f64>().sqrt()
            };
            assert_eq!(quad.interacting, 1);
            (
                (rel(&mono), rel(&quad.force)),
                (
                    (e_mono - e).abs() / e.abs(),
                    (quad.energy - e).abs() / e.abs(),
                ),
            )
        };
        let (near, far) = (errors(2.0), errors(4.0));
        for (kind, (mn, qn), (mf, qf)) in [("force", near.0, far.0), ("energy", near.1, far.1)] {
            let what = format!("{what}, axis {axis}, {kind}");
            // (a/r)² = 2.5e-3 at r = 2: the monopole's error is of that order, the
            // quadrupole's of its square.
            assert!(
                mn > 1e-3 && qn < 1e-4,
                "{what}: errors {mn:e} {qn:e} at r = 2"
            );
            let (mono_ratio, quad_ratio) = (mn / mf, qn / qf);
            assert!(
                (3.5..4.6).contains(&mono_ratio),
                "{what}: monopole ratio {mono_ratio}"
            );
            assert!(
                (13.0..19.0).contains(&quad_ratio),
                "{what}: quadrupole ratio {quad_ratio}"
            );
        }
    }
}

#[test]
fn quadrupole_of_a_two_particle_cluster_matches_the_direct_sum() {
    cluster_field::<_, 3>(Gravity::<f64>::new(1.0, 0.0), "gravity 3-D");
    cluster_field::<_, 3>(Gravity::<f64>::new(0.7, 0.3), "softened gravity 3-D");
    cluster_field::<_, 3>(coulomb::<f64>(), "coulomb 3-D");
    cluster_field::<_, 2>(Gravity::<f64>::new(1.0, 0.05), "gravity 2-D");
    cluster_field::<_, 2>(coulomb::<f64>(), "coulomb 2-D");
}

/// At every θ the quadrupole order's median force error is below the monopole's, on the
/// clustered sphere and disc (gravity, f64 and f32) and on mixed-sign charges (Coulomb).
#[test]
fn quadrupole_error_is_below_the_monopoles() {
    let thetas = [0.3, 0.5, 0.7];
    fn both<T: Real, L: PairLaw<T>, const D: usize>(
        law: L,
        s: &State<T, D>,
        t: &[f64],
    ) -> [Vec<f64>; 2] {
        Multipole::ALL.map(|m| errors_of_order(law, s, t, m))
    }
    let cases = [
        (
            "sphere f64",
            both(gravity::<f64>(), &plummer::<f64, 3>(3000, SEED_1), &thetas),
        ),
        (
            "sphere f32",
            both(gravity::<f32>(), &plummer::<f32, 3>(3000, SEED_1), &thetas),
        ),
        (
            "disc f64",
            both(gravity::<f64>(), &plummer::<f64, 2>(3000, SEED_2), &thetas),
        ),
        (
            "charges 3-D",
            both(
                coulomb::<f64>(),
                &random_state::<f64, 3>(3000, 10.0, true, SEED_1),
                &thetas,
            ),
        ),
        (
            "charges 2-D",
            both(
                coulomb::<f64>(),
                &random_state::<f64, 2>(3000, 10.0, true, SEED_2),
                &thetas,
            ),
        ),
    ];
    for (what, [mono, quad]) in &cases {
        assert!(
            quad.windows(2).all(|w| w[0] < w[1]),
            "{what}: quadrupole errors {quad:?} not increasing with θ"
        );
        for (i, theta) in thetas.iter().enumerate() {
            assert!(
                quad[i] < mono[i],
                "{what} θ = {theta}: quadrupole {:e} vs monopole {:e}",
                quad[i],
                mono[i]
            );
        }
    }
}

/// The probe path's energy at quadrupole order against the direct sum, and closer to it than
/// the monopole's; the probe's forces are the timed path's.
#[test]
fn quadrupole_energy_matches_the_direct_sum() {
    fn check<T: Real, L: PairLaw<T>, const D: usize>(
        law: L,
        s: &State<T, D>,
        bound: f64,
        what: &str,
    ) {
        let (_, want) = forces_of(&mut Naive::new(law), s, true);
        let want = want.energy.expect("probe energy");
        let [mono, quad] = Multipole::ALL.map(|m| {
            let mut k = Octree::with_multipole(law, 0.5, 16, m);
            let (timed, _) = forces_of(&mut k, s, false);
            let (probed, r) = forces_of(&mut k, s, true);
            assert!(
                max_rel_diff(&probed, &timed) < 1e-5,
                "{what} {m:?}: probe forces"
            );
            (r.energy.expect("probe energy") - want).abs() / want.abs()
        });
        assert!(
            quad < mono && quad < bound,
            "{what}: energy errors {quad:e} (quadrupole) {mono:e}"
        );
    }
    check(
        gravity::<f64>(),
        &plummer::<f64, 3>(3000, SEED_1),
        1e-4,
        "sphere",
    );
    check(
        gravity::<f32>(),
        &plummer::<f32, 3>(3000, SEED_1),
        1e-4,
        "sphere f32",
    );
    check(
        gravity::<f64>(),
        &plummer::<f64, 2>(3000, SEED_2),
        1e-3,
        "disc",
    );
    check(
        coulomb::<f64>(),
        &random_state::<f64, 3>(3000, 10.0, true, SEED_2),
        // The energy of mixed charges is a small sum of terms of both signs: measured 1.8e-3
        // (quadrupole) and 9.9e-3 (monopole).
        5e-3,
        "charges",
    );
}

#[test]
fn target_costs_are_each_targets_share_of_the_pair_checks() {
    let s = plummer::<f64, 3>(5000, SEED_1);
    let n = s.len();
    let mut k = Octree::new(gravity::<f64>(), 0.5, 8);
    let mut out = zero_field::<f64, 3>(n);
    fn slices(f: &mut Field<f64, 3>) -> [&mut [f64]; 3] {
        f.each_mut().map(|v| v.as_mut_slice())
    }
    k.compute_targets(&s, 0..n, slices(&mut out));
    assert!(k.target_costs().is_none(), "recorded only when asked");

    k.record_target_costs();
    for threads in [1, 2] {
        let r = pool(threads).install(|| k.compute_targets(&s, 0..n, slices(&mut out)));
        let costs = k.target_costs().expect("recording").to_vec();
        assert_eq!(costs.len(), n);
        let total: u64 = costs.iter().map(|&c| u64::from(c)).sum();
        assert_eq!(total, r.work.pair_checks, "{threads} thread(s)");
        // The dense centre of the cloud costs more than its outskirts.
        let r2 = |i: usize| (0..3).map(|d| s.pos[d][i] * s.pos[d][i]).sum::<f64>();
        let mut by_radius: Vec<usize> = (0..n).collect();
        by_radius.sort_by(|&a, &b| r2(a).total_cmp(&r2(b)));
        let mean = |ids: &[usize]| {
            ids.iter().map(|&i| f64::from(costs[i])).sum::<f64>() / ids.len() as f64
        };
        assert!(mean(&by_radius[..n / 10]) > 1.2 * mean(&by_radius[n - n / 10..]));
    }
    // A block of targets gets its own bodies' costs, in target order.
    let all = k.target_costs().unwrap().to_vec();
    let mut part = zero_field::<f64, 3>(1000);
    k.compute_targets(&s, 2000..3000, slices(&mut part));
    assert_eq!(k.target_costs().unwrap(), &all[2000..3000]);
}
