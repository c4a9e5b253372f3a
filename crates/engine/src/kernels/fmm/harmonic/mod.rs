//! Expansions in complex solid harmonics, whose translations (M2M, M2L, L2L) cost O(p³) by
//! rotation to the z-axis, shift along it and rotation back ([`rotation`]); orders up to
//! [`MAX_HARMONIC_ORDER`]. For the 1/r law without softening (Coulomb, unsoftened gravity):
//! a softened Green's function has no finite expansion in these harmonics.
//!
//! With the harmonics of [`solid`], a cell's multipole about its centre z is
//! `M_n^m = Σ_b s_b conj(R_n^m(x_b − z))`, so that its potential is `ψ(x) = κ Σ_{n,m} M_n^m
//! S_n^m(x − z)`; a local expansion about c has `ψ(x) = Σ_{n,m} L_n^m conj(R_n^m(x − c))`
//! (κ folded in). Then, each from the translation theorems:
//!
//! - M2M to a parent at z′: `M′_n^m = Σ_{k,l} conj(R_{n−k}^{m−l}(z − z′)) M_k^l`;
//! - M2L to a cell at c: `L_n^m = κ (−1)^n Σ_{j,k} M_j^k S_{j+n}^{k+m}(c − z)`;
//! - L2L to a child at c′: `L′_k^l = Σ_{n,m} L_n^m conj(R_{n−k}^{m−l}(c′ − c))`.
//!
//! Along +z only the order-0 harmonics are non-zero (`R_n^0(ρẑ) = ρⁿ/n!`,
//! `S_n^0(ρẑ) = n!/ρ^{n+1}`), so each sum loses its order index there. Only the orders
//! `m ≥ 0` are stored (`(p+1)(p+2)/2` complex numbers): a real potential has
//! `M_n^{−m} = (−1)^m conj(M_n^m)`, the same for `L`.

pub mod batch;
pub mod rotation;
pub mod solid;

#[cfg(test)]
mod tests;

use rotation::{Wigner, apply};
#[cfg(test)]
use solid::sign;
use solid::{C, at, count, regular, signed};

/// Highest order of the harmonic expansions.
pub const MAX_HARMONIC_ORDER: usize = 20;

/// The tables of one order, built once per kernel.
pub struct Harmonic {
    pub p: usize,
    /// `count(p)`: the stored coefficients of an expansion.
    pub len: usize,
    /// `√((n+m)! (n−m)!)` at `at(n, m)`: the scale between these harmonics and the ones that
    /// rotate by Wigner's matrices (`R = C/N`, `S = N C / r^{2n+1}`).
    norm: Vec<f64>,
    /// The tables of the batched M2L.
    pub plan: batch::Plan,
}

/// A direction and length: the translation vector's spherical angles.
#[derive(Clone, Copy, Debug)]
struct Direction {
    rho: f64,
    cos_theta: f64,
    sin_theta: f64,
    /// `e^{iφ}`.
    phase: C,
}

impl Direction {
    fn of(t: [f64; 3]) -> Direction {
        let xy = t[0].hypot(t[1]);
        let rho = xy.hypot(t[2]);
        let phase = if xy > 0.0 {
            C::new(t[0] / xy, t[1] / xy)
        } else {
            C::ONE
        };
        Direction {
            rho,
            cos_theta: if rho > 0.0 { t[2] / rho } else { 1.0 },
            sin_theta: if rho > 0.0 { xy / rho } else { 0.0 },
            phase,
        }
    }
}

/// Per-thread scratch of the translations.
pub struct Scratch {
    wigner: Wigner,
    /// `e^{imφ}`, m = 0..=p.
    phases: Vec<C>,
    /// One degree's coefficients over m ≥ 0, before and after a rotation.
    full: Vec<C>,
    row: Vec<C>,
    /// Triangles: the rotated input, the shifted one; the harmonics of a point.
    rotated: Vec<C>,
    shifted: Vec<C>,
    harmonics: Vec<C>,
    /// Powers `ρ^k / k!` or `k!/ρ^{k+1}` along the axis.
    axis: Vec<f64>,
    /// The rows of the batched M2L.
    pub batch: batch::Batch,
}

/// Which expansion a rotation moves: they rotate by conjugate matrices.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Multipole,
    Local,
}

impl Harmonic {
    /// Tables for order `p` (1 ≤ p ≤ [`MAX_HARMONIC_ORDER`]).
    pub fn new(p: usize) -> Self {
        assert!(
            (1..=MAX_HARMONIC_ORDER).contains(&p),
            "harmonic expansion order {p} out of range"
        );
        let mut fact = vec![1.0; 2 * p + 2];
        for k in 1..fact.len() {
            fact[k] = fact[k - 1] * k as f64;
        }
        let mut norm = vec![0.0; count(p)];
        for n in 0..=p {
            for m in 0..=n {
                norm[at(n, m)] = (fact[n + m] * fact[n - m]).sqrt();
            }
        }
        Harmonic {
            p,
            len: count(p),
            plan: batch::Plan::new(p, &norm),
            norm,
        }
    }

    /// Scratch for the translations of this order.
    pub fn scratch(&self) -> Scratch {
        let p = self.p;
        Scratch {
            wigner: Wigner::new(p),
            phases: vec![C::ZERO; p + 1],
            full: vec![C::ZERO; p + 1],
            row: vec![C::ZERO; p + 1],
            rotated: vec![C::ZERO; count(p)],
            shifted: vec![C::ZERO; count(p)],
            harmonics: vec![C::ZERO; count(p)],
            axis: vec![0.0; 2 * p + 2],
            batch: batch::Batch::new(&self.plan),
        }
    }

    /// P2M: adds the source `s` at `x − z = offset` to the multipole `m`.
    pub fn p2m(&self, offset: [f64; 3], s: f64, m: &mut [C], scratch: &mut Scratch) {
        regular(offset, self.p, &mut scratch.harmonics);
        for (mi, r) in m.iter_mut().zip(&scratch.harmonics) {
            *mi += r.conj().scale(s);
        }
    }

    /// The potential of the multipole `m` (κ = 1) at `x − z = offset` (outside its sphere).
    #[cfg(test)]
    pub fn m2p(&self, offset: [f64; 3], m: &[C], scratch: &mut Scratch) -> f64 {
        solid::irregular(offset, self.p, &mut scratch.harmonics);
        real_sum(self.p, m, &scratch.harmonics, false)
    }

    /// M2M: adds the multipole `child` about z to `parent` about z′, `shift = z − z′`.
    pub fn m2m(&self, shift: [f64; 3], child: &[C], parent: &mut [C], scratch: &mut Scratch) {
        let dir = Direction::of(shift);
        self.prepare(&dir, scratch);
        self.rotate_forward(child, Kind::Multipole, scratch);
        // M′_n^m = Σ_{k=m}^{n} ρ^{n−k}/(n−k)! M_k^m along +z.
        self.powers(dir.rho, &mut scratch.axis);
        let (rot, shifted, axis) = (&scratch.rotated, &mut scratch.shifted, &scratch.axis);
        for n in 0..=self.p {
            for m in 0..=n {
                let mut sum = C::ZERO;
                for k in m..=n {
                    sum += rot[at(k, m)].scale(axis[n - k]);
                }
                shifted[at(n, m)] = sum;
            }
        }
        self.rotate_back(Kind::Multipole, parent, scratch);
    }

    /// M2L: adds to the local expansion `local` about c the field `κ ψ` of the multipole `m`
    /// about z, `t = c − z`: one translation at a time, the reference of the batched ones
    /// ([`batch`]) that the kernel runs.
    #[cfg(test)]
    pub fn m2l(&self, t: [f64; 3], kappa: f64, m: &[C], local: &mut [C], scratch: &mut Scratch) {
        let dir = Direction::of(t);
        self.prepare(&dir, scratch);
        self.rotate_forward(m, Kind::Multipole, scratch);
        // L′_n^m = κ (−1)^n Σ_{j ≥ m} M′_j^{−m} (j+n)!/ρ^{j+n+1}, M′_j^{−m} = (−1)^m conj(M′_j^m).
        let inv = 1.0 / dir.rho;
        let axis = &mut scratch.axis;
        axis[0] = inv;
        for k in 1..axis.len() {
            axis[k] = axis[k - 1] * k as f64 * inv;
        }
        let (rot, shifted, axis) = (&scratch.rotated, &mut scratch.shifted, &scratch.axis);
        let p = self.p;
        for n in 0..=p {
            for m in 0..=n.min(p - n) {
                let mut sum = C::ZERO;
                for j in m..=p - n {
                    sum += rot[at(j, m)].scale(axis[j + n]);
                }
                shifted[at(n, m)] = sum.conj().scale(kappa * sign(n) * sign(m));
            }
            for m in n.min(p - n) + 1..=n {
                shifted[at(n, m)] = C::ZERO;
            }
        }
        self.rotate_back(Kind::Local, local, scratch);
    }

    /// L2L: adds the local expansion `parent` about c, moved to c′ (`shift = c′ − c`), to
    /// `child`.
    pub fn l2l(&self, shift: [f64; 3], parent: &[C], child: &mut [C], scratch: &mut Scratch) {
        let dir = Direction::of(shift);
        self.prepare(&dir, scratch);
        self.rotate_forward(parent, Kind::Local, scratch);
        // L′_k^l = Σ_{n=k}^{p} L_n^l ρ^{n−k}/(n−k)! along +z.
        self.powers(dir.rho, &mut scratch.axis);
        let (rot, shifted, axis) = (&scratch.rotated, &mut scratch.shifted, &scratch.axis);
        let p = self.p;
        for k in 0..=p {
            for l in 0..=k {
                let mut sum = C::ZERO;
                for n in k..=p {
                    sum += rot[at(n, l)].scale(axis[n - k]);
                }
                shifted[at(k, l)] = sum;
            }
        }
        self.rotate_back(Kind::Local, child, scratch);
    }

    /// L2P at `x − c = offset`: the gradient of ψ and, with `potential`, ψ (else 0).
    pub fn l2p(
        &self,
        offset: [f64; 3],
        local: &[C],
        potential: bool,
        scratch: &mut Scratch,
    ) -> ([f64; 3], f64) {
        let p = self.p;
        let r = &mut scratch.harmonics;
        regular(offset, p, r);
        // ψ's first-order coefficients moved to x: L′_1^0 = Σ L_n^m conj(R_{n−1}^m),
        // L′_1^1 = Σ L_n^m conj(R_{n−1}^{m−1}); ∇ψ = (−Re L′_1^1, −Im L′_1^1, L′_1^0).
        let (mut z, mut xy) = (0.0, C::ZERO);
        for n in 1..=p {
            let ni = n as isize;
            for m in -(ni - 1)..=ni - 1 {
                let term = signed(local, n, m) * signed(r, n - 1, m).conj();
                z += term.re;
            }
            for m in -(ni - 2).max(-ni)..=ni {
                if (m - 1).unsigned_abs() > n - 1 {
                    continue;
                }
                xy += signed(local, n, m) * signed(r, n - 1, m - 1).conj();
            }
        }
        let psi = if potential {
            real_sum(p, local, r, true)
        } else {
            0.0
        };
        ([-xy.re, -xy.im, z], psi)
    }

    /// `ρ^k / k!` for k = 0..=p into `out`.
    fn powers(&self, rho: f64, out: &mut [f64]) {
        out[0] = 1.0;
        for k in 1..=self.p {
            out[k] = out[k - 1] * rho / k as f64;
        }
    }

    /// The rotation's matrices and phases.
    fn prepare(&self, dir: &Direction, scratch: &mut Scratch) {
        scratch.wigner.compute(dir.cos_theta, dir.sin_theta);
        scratch.phases[0] = C::ONE;
        for m in 1..=self.p {
            scratch.phases[m] = scratch.phases[m - 1] * dir.phase;
        }
    }

    /// `input` in the frame where the translation points along +z, into `scratch.rotated`:
    /// the turn by −φ about z, then by −θ about y.
    fn rotate_forward(&self, input: &[C], kind: Kind, scratch: &mut Scratch) {
        let Scratch {
            wigner,
            phases,
            full,
            row,
            rotated,
            ..
        } = scratch;
        for n in 0..=self.p {
            for m in 0..=n {
                let norm = self.norm[at(n, m)];
                // Multipoles rotate as N·M, locals as L/N; the z-turn by e^{±imφ}.
                let (scaled, phase) = match kind {
                    Kind::Multipole => (input[at(n, m)].scale(norm), phases[m]),
                    Kind::Local => (input[at(n, m)].scale(1.0 / norm), phases[m].conj()),
                };
                full[m] = scaled * phase;
            }
            apply(wigner, n, &full[..=n], true, &mut row[..=n]);
            for m in 0..=n {
                let norm = self.norm[at(n, m)];
                rotated[at(n, m)] = match kind {
                    Kind::Multipole => row[m].scale(1.0 / norm),
                    Kind::Local => row[m].scale(norm),
                };
            }
        }
    }

    /// `scratch.shifted`, in the rotated frame, back in the original one, added to `out`.
    fn rotate_back(&self, kind: Kind, out: &mut [C], scratch: &mut Scratch) {
        let Scratch {
            wigner,
            phases,
            full,
            row,
            shifted,
            ..
        } = scratch;
        for n in 0..=self.p {
            for m in 0..=n {
                let norm = self.norm[at(n, m)];
                full[m] = match kind {
                    Kind::Multipole => shifted[at(n, m)].scale(norm),
                    Kind::Local => shifted[at(n, m)].scale(1.0 / norm),
                };
            }
            apply(wigner, n, &full[..=n], false, &mut row[..=n]);
            for m in 0..=n {
                let norm = self.norm[at(n, m)];
                let v = match kind {
                    Kind::Multipole => (row[m] * phases[m].conj()).scale(1.0 / norm),
                    Kind::Local => (row[m] * phases[m]).scale(norm),
                };
                out[at(n, m)] += v;
            }
        }
    }
}

/// `Σ_{n,m} a_n^m b_n^m` over all orders −n..=n (with `conj_b`, `a conj(b)`), a real number
/// since both have the symmetry of a real field.
fn real_sum(p: usize, a: &[C], b: &[C], conj_b: bool) -> f64 {
    let mut sum = 0.0;
    for n in 0..=p {
        for m in 0..=n {
            let bv = if conj_b {
                b[at(n, m)].conj()
            } else {
                b[at(n, m)]
            };
            let term = (a[at(n, m)] * bv).re;
            sum += if m == 0 { term } else { 2.0 * term };
        }
    }
    sum
}
