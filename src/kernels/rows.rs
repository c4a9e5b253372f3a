//! The pair loops every kernel is built from: one target against a contiguous run of sources.
//!
//! Floating-point sums are not reassociated by the compiler, so a plain `acc += f` over `j`
//! would run one pair at a time. These loops keep `LANES` independent partial sums, one per
//! position in a block of sources, which LLVM maps onto SIMD registers; the partial sums are
//! added once at the end. `PROBE` additionally accumulates the potential energy and counts
//! interacting pairs; the timed steps run with `PROBE = false` and pay nothing for it.

use crate::physics::PairLaw;
use crate::real::Real;

/// Sources processed together; a multiple of the vector width for both precisions.
pub const LANES: usize = 16;

/// Sum over a run of sources of their effect on one target.
#[derive(Clone, Copy, Debug)]
pub struct RowSum<T, const D: usize> {
    pub force: [T; D],
    /// Potential energy of the target with these sources (only when probing).
    pub energy: T,
    /// Pairs that interact (inside the cutoff, outside the quench radius; only when probing).
    pub interacting: u64,
}

/// A target particle: position and source strength.
#[derive(Clone, Copy, Debug)]
pub struct Target<T, const D: usize> {
    pub x: [T; D],
    pub s: T,
}

/// A contiguous run of sources: positions per component and strengths, all of equal length.
#[derive(Clone, Copy, Debug)]
pub struct Sources<'a, T, const D: usize> {
    pub pos: [&'a [T]; D],
    pub s: &'a [T],
}

impl<'a, T: Real, const D: usize> Sources<'a, T, D> {
    /// The sources with indices `lo..hi` of the given arrays.
    #[inline(always)]
    pub fn range(pos: &'a [Vec<T>; D], s: &'a [T], lo: usize, hi: usize) -> Self {
        Sources {
            pos: std::array::from_fn(|d| &pos[d][lo..hi]),
            s: &s[lo..hi],
        }
    }

    #[inline(always)]
    pub fn len(&self) -> usize {
        self.s.len()
    }

    #[inline(always)]
    pub fn is_empty(&self) -> bool {
        self.s.is_empty()
    }
}

/// One pair: separation, squared distance and coefficient (the tail of a run).
#[inline(always)]
fn pair<T: Real, L: PairLaw<T>, const D: usize>(
    law: &L,
    t: &Target<T, D>,
    pos: &[&[T]; D],
    s: &[T],
    j: usize,
) -> ([T; D], T, T) {
    let mut dx = [T::zero(); D];
    let mut r2 = T::zero();
    for d in 0..D {
        dx[d] = pos[d][j] - t.x[d];
        r2 += dx[d] * dx[d];
    }
    (dx, r2, law.coeff(r2, t.s, s[j]))
}

/// A block of `LANES` pairs: separations, squared distances and coefficients, computed
/// lane-wise on fixed-size arrays (no bounds checks inside, so LLVM vectorizes it).
#[inline(always)]
fn block<T: Real, L: PairLaw<T>, const D: usize>(
    law: &L,
    t: &Target<T, D>,
    pos: &[&[T]; D],
    s: &[T],
    base: usize,
) -> ([[T; LANES]; D], [T; LANES], [T; LANES], [T; LANES]) {
    let xs: [&[T; LANES]; D] = std::array::from_fn(|d| {
        pos[d][base..base + LANES]
            .try_into()
            .expect("block in range")
    });
    let ss: &[T; LANES] = s[base..base + LANES].try_into().expect("block in range");
    let mut dx = [[T::zero(); LANES]; D];
    let mut r2 = [T::zero(); LANES];
    for d in 0..D {
        for l in 0..LANES {
            dx[d][l] = xs[d][l] - t.x[d];
            r2[l] += dx[d][l] * dx[d][l];
        }
    }
    let mut c = [T::zero(); LANES];
    for l in 0..LANES {
        c[l] = law.coeff(r2[l], t.s, ss[l]);
    }
    (dx, r2, c, *ss)
}

/// Energy and interaction count of a block (probe steps only).
#[inline(always)]
fn probe_block<T: Real, L: PairLaw<T>>(
    law: &L,
    si: T,
    r2: &[T; LANES],
    ss: &[T; LANES],
    energy: &mut [T; LANES],
    count: &mut [u32; LANES],
) {
    for l in 0..LANES {
        energy[l] += law.energy(r2[l], si, ss[l]);
        count[l] += law.interacts(r2[l]) as u32;
    }
}

/// Force on `t` from every source in `src` (the gather form: sources are only read).
#[inline(always)]
pub fn gather<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool>(
    law: &L,
    t: &Target<T, D>,
    src: &Sources<'_, T, D>,
) -> RowSum<T, D> {
    let n = src.len();
    let pos: [&[T]; D] = std::array::from_fn(|d| &src.pos[d][..n]);
    let s = &src.s[..n];
    let mut acc = [[T::zero(); LANES]; D];
    let mut energy = [T::zero(); LANES];
    let mut count = [0u32; LANES];
    let full = n - n % LANES;
    for base in (0..full).step_by(LANES) {
        let (dx, r2, c, ss) = block(law, t, &pos, s, base);
        for d in 0..D {
            for l in 0..LANES {
                acc[d][l] += c[l] * dx[d][l];
            }
        }
        if PROBE {
            probe_block(law, t.s, &r2, &ss, &mut energy, &mut count);
        }
    }
    for j in full..n {
        let (dx, r2, c) = pair(law, t, &pos, s, j);
        for d in 0..D {
            acc[d][0] += c * dx[d];
        }
        if PROBE {
            energy[0] += law.energy(r2, t.s, s[j]);
            count[0] += law.interacts(r2) as u32;
        }
    }
    finish(acc, energy, count)
}

/// Force on `t` from every source in `src`, also applying the reaction (Newton's third law) to
/// the sources' force accumulators `fsrc` (the scatter form used by the symmetric kernels).
#[inline(always)]
pub fn scatter<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool>(
    law: &L,
    t: &Target<T, D>,
    src: &Sources<'_, T, D>,
    fsrc: [&mut [T]; D],
) -> RowSum<T, D> {
    let n = src.len();
    let pos: [&[T]; D] = std::array::from_fn(|d| &src.pos[d][..n]);
    let s = &src.s[..n];
    let fsrc = fsrc.map(|f| &mut f[..n]);
    let mut acc = [[T::zero(); LANES]; D];
    let mut energy = [T::zero(); LANES];
    let mut count = [0u32; LANES];
    let full = n - n % LANES;
    for base in (0..full).step_by(LANES) {
        let (dx, r2, c, ss) = block(law, t, &pos, s, base);
        // Accumulate and scatter in separate passes over a finished block: interleaving them
        // makes LLVM's SLP vectorizer shuffle the accumulators through memory.
        let mut f = [[T::zero(); LANES]; D];
        for d in 0..D {
            for l in 0..LANES {
                f[d][l] = c[l] * dx[d][l];
                acc[d][l] += f[d][l];
            }
        }
        for d in 0..D {
            let fj: &mut [T; LANES] = (&mut fsrc[d][base..base + LANES])
                .try_into()
                .expect("block in range");
            for l in 0..LANES {
                fj[l] -= f[d][l];
            }
        }
        if PROBE {
            probe_block(law, t.s, &r2, &ss, &mut energy, &mut count);
        }
    }
    for j in full..n {
        let (dx, r2, c) = pair(law, t, &pos, s, j);
        for d in 0..D {
            let f = c * dx[d];
            acc[d][0] += f;
            fsrc[d][j] -= f;
        }
        if PROBE {
            energy[0] += law.energy(r2, t.s, s[j]);
            count[0] += law.interacts(r2) as u32;
        }
    }
    finish(acc, energy, count)
}

#[inline(always)]
fn finish<T: Real, const D: usize>(
    acc: [[T; LANES]; D],
    energy: [T; LANES],
    count: [u32; LANES],
) -> RowSum<T, D> {
    RowSum {
        force: acc.map(|lanes| lanes.iter().copied().sum()),
        energy: energy.iter().copied().sum(),
        interacting: count.iter().map(|&c| c as u64).sum(),
    }
}

impl<T: Real, const D: usize> RowSum<T, D> {
    pub fn zero() -> Self {
        RowSum {
            force: [T::zero(); D],
            energy: T::zero(),
            interacting: 0,
        }
    }

    #[inline(always)]
    pub fn add(&mut self, other: &RowSum<T, D>) {
        for d in 0..D {
            self.force[d] += other.force[d];
        }
        self.energy += other.energy;
        self.interacting += other.interacting;
    }
}
