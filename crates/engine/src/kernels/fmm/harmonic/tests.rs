//! The harmonics against their defining theorems, the rotations against their group laws, and
//! every operator against the direct translations (O(p⁴), from the theorems term by term) and
//! against direct sums, with the error falling geometrically in the order.

use super::rotation::Wigner;
use super::solid::{C, at, count, irregular, regular, sign, signed};
use super::{Harmonic, MAX_HARMONIC_ORDER};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

fn rng() -> Pcg64 {
    Pcg64::seed_from_u64(7)
}

fn point(rng: &mut Pcg64, scale: f64) -> [f64; 3] {
    std::array::from_fn(|_| rng.random_range(-scale..scale))
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|d| a[d] - b[d])
}

fn norm(a: [f64; 3]) -> f64 {
    a.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn close(a: C, b: C, scale: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * scale
}

#[test]
fn regular_harmonics_obey_the_addition_theorem() {
    let p = 12;
    let mut rng = rng();
    let (a, b) = (point(&mut rng, 0.6), point(&mut rng, 0.6));
    let ab: [f64; 3] = std::array::from_fn(|d| a[d] + b[d]);
    let (mut ra, mut rb, mut rab) = (
        vec![C::ZERO; count(p)],
        vec![C::ZERO; count(p)],
        vec![C::ZERO; count(p)],
    );
    regular(a, p, &mut ra);
    regular(b, p, &mut rb);
    regular(ab, p, &mut rab);
    for n in 0..=p {
        for m in 0..=n as isize {
            let mut sum = C::ZERO;
            for k in 0..=n {
                for l in -(k as isize)..=k as isize {
                    if (m - l).unsigned_abs() <= n - k {
                        sum += signed(&ra, k, l) * signed(&rb, n - k, m - l);
                    }
                }
            }
            let want = rab[at(n, m as usize)];
            assert!(
                close(sum, want, 1.0, 1e-13),
                "n {n} m {m}: {sum:?} against {want:?}"
            );
        }
    }
}

#[test]
fn the_inverse_distance_expands_in_the_harmonics() {
    let mut rng = rng();
    let (x, y) = ([0.9, -1.1, 1.4], point(&mut rng, 0.4));
    let exact = 1.0 / norm(sub(x, y));
    let mut last = f64::INFINITY;
    for p in [2, 6, 10, 16] {
        let (mut r, mut s) = (vec![C::ZERO; count(p)], vec![C::ZERO; count(p)]);
        regular(y, p, &mut r);
        irregular(x, p, &mut s);
        let mut sum = C::ZERO;
        for n in 0..=p {
            for m in -(n as isize)..=n as isize {
                sum += signed(&r, n, m).conj() * signed(&s, n, m);
            }
        }
        let err = (sum.re - exact).abs() / exact;
        assert!(sum.im.abs() < 1e-14, "imaginary part {}", sum.im);
        assert!(
            err < last,
            "p {p}: error {err:.2e} did not fall from {last:.2e}"
        );
        last = err;
    }
    assert!(last < 1e-9, "p 16: error {last:.2e}");
}

#[test]
fn irregular_harmonics_shift_by_the_regular_ones() {
    // S_n^m(a + b) = Σ_{k,l} (−1)^k conj(R_k^l(b)) S_{n+k}^{m+l}(a), truncated at k ≤ q.
    let (p, q) = (4, 22);
    let (a, b) = ([1.3, -0.4, 0.9], [0.1, 0.15, -0.2]);
    let ab: [f64; 3] = std::array::from_fn(|d| a[d] + b[d]);
    let (mut rb, mut sa, mut sab) = (
        vec![C::ZERO; count(q)],
        vec![C::ZERO; count(p + q)],
        vec![C::ZERO; count(p)],
    );
    regular(b, q, &mut rb);
    irregular(a, p + q, &mut sa);
    irregular(ab, p, &mut sab);
    for n in 0..=p {
        for m in 0..=n as isize {
            let mut sum = C::ZERO;
            for k in 0..=q {
                for l in -(k as isize)..=k as isize {
                    if (m + l).unsigned_abs() <= n + k {
                        sum += signed(&rb, k, l).conj().scale(sign(k)) * signed(&sa, n + k, m + l);
                    }
                }
            }
            let want = sab[at(n, m as usize)];
            assert!(
                close(sum, want, want.abs().max(1e-3), 1e-9),
                "n {n} m {m}: {sum:?} against {want:?}"
            );
        }
    }
}

#[test]
fn wigner_matrices_are_orthogonal_and_compose_about_one_axis() {
    let p = MAX_HARMONIC_ORDER;
    let (b1, b2) = (0.7_f64, 1.9_f64);
    let mut w1 = Wigner::new(p);
    let mut w2 = Wigner::new(p);
    let mut w12 = Wigner::new(p);
    w1.compute(b1.cos(), b1.sin());
    w2.compute(b2.cos(), b2.sin());
    w12.compute((b1 + b2).cos(), (b1 + b2).sin());
    let mut worst: f64 = 0.0;
    for n in 0..=p {
        let ni = n as isize;
        for i in -ni..=ni {
            for j in -ni..=ni {
                let (mut dot, mut prod) = (0.0, 0.0);
                for k in -ni..=ni {
                    dot += w1.get(n, i, k) * w1.get(n, j, k);
                    prod += w1.get(n, i, k) * w2.get(n, k, j);
                }
                let id = if i == j { 1.0 } else { 0.0 };
                worst = worst.max((dot - id).abs());
                worst = worst.max((prod - w12.get(n, i, j)).abs());
            }
        }
    }
    assert!(
        worst < 1e-12,
        "orthogonality or composition off by {worst:.2e}"
    );
    // The small-d matrices of degree 1 in closed form.
    let (c, s) = (b1.cos(), b1.sin());
    assert!((w1.get(1, 1, 1) - (1.0 + c) / 2.0).abs() < 1e-15);
    assert!((w1.get(1, 1, 0) + s / 2f64.sqrt()).abs() < 1e-15);
    assert!((w1.get(1, 0, 0) - c).abs() < 1e-15);
}

#[test]
fn the_small_d_matrices_are_exact_along_the_axis() {
    let p = 16;
    for (c, s) in [(1.0, 0.0), (-1.0, 0.0)] {
        let mut w = Wigner::new(p);
        w.compute(c, s);
        for n in 0..=p {
            let ni = n as isize;
            for i in -ni..=ni {
                for j in -ni..=ni {
                    // β = 0: identity; β = π: d_{m'm} = (−1)^{n+m'} δ_{m',−m}.
                    let want = if c > 0.0 {
                        f64::from(u8::from(i == j))
                    } else if i == -j {
                        sign((ni + i).unsigned_abs())
                    } else {
                        0.0
                    };
                    assert!(
                        (w.get(n, i, j) - want).abs() < 1e-13,
                        "n {n} ({i}, {j}) at cos {c}"
                    );
                }
            }
        }
    }
}

/// Sources in a ball of radius 0.5 about `centre`.
fn sources(rng: &mut Pcg64, centre: [f64; 3], count: usize) -> Vec<([f64; 3], f64)> {
    (0..count)
        .map(|_| {
            let x = loop {
                let x = point(rng, 0.5);
                if norm(x) < 0.5 {
                    break x;
                }
            };
            (
                std::array::from_fn(|d| centre[d] + x[d]),
                rng.random_range(-1.0..1.0),
            )
        })
        .collect()
}

fn multipole(h: &Harmonic, z: [f64; 3], src: &[([f64; 3], f64)]) -> Vec<C> {
    let mut scratch = h.scratch();
    let mut m = vec![C::ZERO; h.len];
    for &(x, s) in src {
        h.p2m(sub(x, z), s, &mut m, &mut scratch);
    }
    m
}

fn direct(src: &[([f64; 3], f64)], x: [f64; 3]) -> (f64, [f64; 3]) {
    let (mut psi, mut grad) = (0.0, [0.0; 3]);
    for &(y, s) in src {
        let d = sub(x, y);
        let r = norm(d);
        psi += s / r;
        for k in 0..3 {
            grad[k] -= s * d[k] / (r * r * r);
        }
    }
    (psi, grad)
}

/// M2M by the theorem term by term (O(p⁴)).
fn m2m_direct(h: &Harmonic, shift: [f64; 3], child: &[C]) -> Vec<C> {
    let p = h.p;
    let mut r = vec![C::ZERO; count(p)];
    regular(shift, p, &mut r);
    let mut out = vec![C::ZERO; count(p)];
    for n in 0..=p {
        for m in 0..=n as isize {
            let mut sum = C::ZERO;
            for k in 0..=n {
                for l in -(k as isize)..=k as isize {
                    if (m - l).unsigned_abs() <= n - k {
                        sum += signed(&r, n - k, m - l).conj() * signed(child, k, l);
                    }
                }
            }
            out[at(n, m as usize)] = sum;
        }
    }
    out
}

/// M2L by the theorem term by term (O(p⁴)).
fn m2l_direct(h: &Harmonic, t: [f64; 3], kappa: f64, m: &[C]) -> Vec<C> {
    let p = h.p;
    let mut s = vec![C::ZERO; count(2 * p)];
    irregular(t, 2 * p, &mut s);
    let mut out = vec![C::ZERO; count(p)];
    for n in 0..=p {
        for mm in 0..=n as isize {
            let mut sum = C::ZERO;
            for j in 0..=p - n {
                for k in -(j as isize)..=j as isize {
                    sum += signed(m, j, k) * signed(&s, j + n, k + mm);
                }
            }
            out[at(n, mm as usize)] = sum.scale(kappa * sign(n));
        }
    }
    out
}

fn worst(a: &[C], b: &[C]) -> f64 {
    let scale = b.iter().map(|c| c.abs()).fold(0.0, f64::max);
    a.iter()
        .zip(b)
        .map(|(x, y)| (*x - *y).abs())
        .fold(0.0, f64::max)
        / scale
}

#[test]
fn m2m_by_rotation_is_the_theorem_and_the_multipole_about_the_new_centre() {
    let mut rng = rng();
    for p in [1, 4, 8, 16] {
        let h = Harmonic::new(p);
        let (z, zp) = ([0.1, -0.2, 0.3], [0.4, 0.1, -0.1]);
        let src = sources(&mut rng, z, 30);
        let child = multipole(&h, z, &src);
        let mut parent = vec![C::ZERO; h.len];
        h.m2m(sub(z, zp), &child, &mut parent, &mut h.scratch());
        let err = worst(&parent, &m2m_direct(&h, sub(z, zp), &child));
        assert!(err < 1e-12, "p {p}: rotation against theorem {err:.2e}");
        let err = worst(&parent, &multipole(&h, zp, &src));
        assert!(err < 1e-12, "p {p}: against P2M about z′ {err:.2e}");
    }
}

#[test]
fn m2m_along_the_axis_either_way_is_exact() {
    let mut rng = rng();
    let h = Harmonic::new(10);
    let z = [0.0; 3];
    let src = sources(&mut rng, z, 20);
    let child = multipole(&h, z, &src);
    for shift in [[0.0, 0.0, 0.3], [0.0, 0.0, -0.3]] {
        let mut parent = vec![C::ZERO; h.len];
        h.m2m(shift, &child, &mut parent, &mut h.scratch());
        let zp = sub(z, shift);
        let err = worst(&parent, &multipole(&h, zp, &src));
        assert!(err < 1e-12, "shift {shift:?}: {err:.2e}");
    }
}

#[test]
fn m2l_by_rotation_is_the_theorem_and_its_error_falls_geometrically() {
    let mut rng = rng();
    let (z, c) = ([0.0; 3], [1.2, -0.9, 1.5]);
    let src = sources(&mut rng, z, 40);
    let targets: Vec<[f64; 3]> = (0..20)
        .map(|_| {
            let x = point(&mut rng, 0.28);
            std::array::from_fn(|d| c[d] + x[d])
        })
        .collect();
    let mut errors = Vec::new();
    for p in 1..=MAX_HARMONIC_ORDER {
        let h = Harmonic::new(p);
        let m = multipole(&h, z, &src);
        let mut scratch = h.scratch();
        let mut local = vec![C::ZERO; h.len];
        h.m2l(sub(c, z), 1.0, &m, &mut local, &mut scratch);
        let err = worst(&local, &m2l_direct(&h, sub(c, z), 1.0, &m));
        assert!(err < 1e-12, "p {p}: rotation against theorem {err:.2e}");
        let mut e: f64 = 0.0;
        for &x in &targets {
            let (psi, grad) = direct(&src, x);
            let (g, ps) = h.l2p(sub(x, c), &local, true, &mut scratch);
            e = e.max(norm(sub(g, grad)) / norm(grad));
            e = e.max((ps - psi).abs() / psi.abs().max(1e-3));
        }
        errors.push(e);
    }
    // Sources within 0.5 of z, targets within 0.5 of c, |c − z| ≈ 2.1: the error falls by
    // about (1/2.1)^p... measured over every 4 orders, at least 4x per 4 orders.
    for p in (1..=MAX_HARMONIC_ORDER - 4).step_by(2) {
        let (a, b) = (errors[p - 1], errors[p + 3]);
        assert!(
            b < a / 4.0 || b < 1e-13,
            "p {p} -> {}: {a:.2e} -> {b:.2e} ({errors:?})",
            p + 4
        );
    }
    assert!(errors[MAX_HARMONIC_ORDER - 1] < 1e-7, "{errors:?}");
}

#[test]
fn l2l_by_rotation_keeps_the_field_exactly() {
    let mut rng = rng();
    for p in [2, 7, 16] {
        let h = Harmonic::new(p);
        let mut scratch = h.scratch();
        let (z, c) = ([0.0; 3], [2.0, 1.0, -1.5]);
        let src = sources(&mut rng, z, 25);
        let m = multipole(&h, z, &src);
        let mut parent = vec![C::ZERO; h.len];
        h.m2l(sub(c, z), 1.0, &m, &mut parent, &mut scratch);
        let shift = [0.15, -0.1, 0.2];
        let cc: [f64; 3] = std::array::from_fn(|d| c[d] + shift[d]);
        let mut child = vec![C::ZERO; h.len];
        h.l2l(shift, &parent, &mut child, &mut scratch);
        for _ in 0..10 {
            let x: [f64; 3] = {
                let o = point(&mut rng, 0.2);
                std::array::from_fn(|d| cc[d] + o[d])
            };
            let (g1, p1) = h.l2p(sub(x, c), &parent, true, &mut scratch);
            let (g2, p2) = h.l2p(sub(x, cc), &child, true, &mut scratch);
            assert!(
                (p1 - p2).abs() < 1e-12 * p1.abs().max(1e-3),
                "p {p}: ψ {p1} {p2}"
            );
            assert!(
                norm(sub(g1, g2)) < 1e-11 * norm(g1),
                "p {p}: ∇ψ {g1:?} {g2:?}"
            );
        }
    }
}

#[test]
fn a_multipole_potential_matches_the_direct_sum_far_away() {
    let mut rng = rng();
    let src = sources(&mut rng, [0.0; 3], 30);
    let h = Harmonic::new(16);
    let m = multipole(&h, [0.0; 3], &src);
    let x = [2.0, 1.5, -2.5];
    let psi = h.m2p(x, &m, &mut h.scratch());
    let (want, _) = direct(&src, x);
    assert!(
        (psi - want).abs() < 1e-10 * want.abs(),
        "{psi} against {want}"
    );
}

#[test]
fn the_batched_m2l_is_the_one_at_a_time() {
    use super::batch::{Batch, far};
    use super::solid::complex;
    use crate::kernels::lanes::{Isa, isas_here};
    let mut rng = rng();
    for p in 1..=MAX_HARMONIC_ORDER {
        let h = Harmonic::new(p);
        let mut scratch = h.scratch();
        let z = [0.1, -0.2, 0.3];
        // Partners all round, along both poles of the axis too, more than a batch of any width.
        let mut centres: Vec<[f64; 3]> = (0..19).map(|_| point(&mut rng, 4.0)).collect();
        centres.push([z[0], z[1], z[2] + 2.5]);
        centres.push([z[0], z[1], z[2] - 3.0]);
        let multipoles: Vec<f64> = centres
            .iter()
            .flat_map(|&c| {
                let src = sources(&mut rng, c, 6);
                let m = multipole(&h, c, &src);
                m.into_iter().flat_map(|v| [v.re, v.im])
            })
            .collect();
        let partners: Vec<u32> = (0..centres.len() as u32).collect();
        let kappa = -0.7;
        let mut want = vec![C::ZERO; count(p)];
        for &b in &partners {
            let b = b as usize;
            let len = 2 * count(p);
            let m = complex(&multipoles[b * len..(b + 1) * len]);
            h.m2l(sub(z, centres[b]), kappa, m, &mut want, &mut scratch);
        }
        let scale = want.iter().map(|v| v.abs()).fold(0.0, f64::max);
        let isas: Vec<Option<Isa>> = std::iter::once(None)
            .chain(isas_here().into_iter().map(Some))
            .collect();
        for isa in isas {
            let mut batch = Batch::new(&h.plan);
            let mut local = vec![f64::NAN; 2 * count(p)];
            far(
                &h.plan,
                kappa,
                isa,
                z,
                &partners,
                &centres,
                &multipoles,
                &mut local,
                &mut batch,
            );
            let got = complex(&local);
            for n in 0..=p {
                for m in 0..=n {
                    let (g, w) = (got[at(n, m)], want[at(n, m)]);
                    assert!(
                        close(g, w, scale, 1e-12),
                        "order {p}, {isa:?}: L_{n}^{m} {g:?} against {w:?}"
                    );
                }
            }
        }
    }
}
