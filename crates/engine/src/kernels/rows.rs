//! The pair loops every kernel is built from: one target against a contiguous run of sources.
//!
//! Floating-point sums are not reassociated by the compiler, so a plain `acc += f` over `j`
//! would run one pair at a time. These loops keep `LANES` independent partial sums, one per
//! position in a block of sources, which LLVM maps onto SIMD registers; the partial sums are
//! added once at the end. `PROBE` additionally accumulates the potential energy and counts
//! interacting pairs; the timed steps run with `PROBE = false` and pay nothing for it.
//!
//! A run may exclude some of its sources ([`Exclude`]): the target itself, or the sources
//! before a given index. Excluded lanes are zeroed with a select in the blocks that contain
//! them, so a kernel can run whole blocks across a row's start instead of a scalar tail.

use crate::physics::PairLaw;
use crate::real::{Real, select};

pub use crate::simd::LANES;

/// Sum over a run of sources of their effect on one target.
#[derive(Clone, Copy, Debug)]
pub struct RowSum<T, const D: usize> {
    /// Force on the target from these sources.
    pub force: [T; D],
    /// Potential energy of the target with these sources (only when probing).
    pub energy: T,
    /// Pairs that interact (inside the cutoff, outside the quench radius; only when probing).
    pub interacting: u64,
}

/// A target particle: position and source strength.
#[derive(Clone, Copy, Debug)]
pub struct Target<T, const D: usize> {
    /// The target's position.
    pub x: [T; D],
    /// The target's source strength (charge, gravitational mass; 1 for Lennard-Jones).
    pub s: T,
}

/// A contiguous run of sources: positions per component and strengths, all of equal length.
#[derive(Clone, Copy, Debug)]
pub struct Sources<'a, T, const D: usize> {
    /// Positions, one slice per coordinate.
    pub pos: [&'a [T]; D],
    /// Source strengths.
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

    /// Number of sources in the run.
    #[inline(always)]
    pub fn len(&self) -> usize {
        self.s.len()
    }

    /// Whether the run has no sources.
    #[inline(always)]
    pub fn is_empty(&self) -> bool {
        self.s.is_empty()
    }
}

/// Sources of a run that must not act, by index within the run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Exclude {
    /// Sources before this index are skipped.
    pub below: usize,
    /// This source is skipped (the target itself); `usize::MAX` for none.
    pub index: usize,
}

impl Exclude {
    /// Nothing excluded: every source acts.
    pub const NONE: Exclude = Exclude {
        below: 0,
        index: usize::MAX,
    };

    /// Skip only source `index` (the target's own slot).
    pub fn index(index: usize) -> Self {
        Exclude { below: 0, index }
    }

    /// Skip the sources before `below`.
    pub fn below(below: usize) -> Self {
        Exclude {
            below,
            index: usize::MAX,
        }
    }

    #[inline(always)]
    fn keeps(&self, j: usize) -> bool {
        j >= self.below && j != self.index
    }
}

/// Sum of the lanes, as a tree (four dependent additions for sixteen lanes, not sixteen);
/// `N` a power of two.
#[inline(always)]
pub(crate) fn lane_sum<T: Real, const N: usize>(mut v: [T; N]) -> T {
    let mut width = N / 2;
    while width > 0 {
        for l in 0..width {
            v[l] += v[l + width];
        }
        width /= 2;
    }
    v[0]
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

/// A block of `LANES` pairs computed lane-wise on fixed-size arrays (no bounds checks inside,
/// so LLVM vectorizes it): separations, squared distances, coefficients, source strengths.
type Block<T, const D: usize> = ([[T; LANES]; D], [T; LANES], [T; LANES], [T; LANES]);

#[inline(always)]
fn block<T: Real, L: PairLaw<T>, const D: usize>(
    law: &L,
    t: &Target<T, D>,
    pos: &[&[T]; D],
    s: &[T],
    base: usize,
) -> Block<T, D> {
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
fn probe_block<T: Real, L: PairLaw<T>, const D: usize, const MASK: bool>(
    law: &L,
    si: T,
    r2: &[T; LANES],
    ss: &[T; LANES],
    keep: &[bool; LANES],
    acc: &mut Accumulator<T, D>,
) {
    for l in 0..LANES {
        let e = law.energy(r2[l], si, ss[l]);
        let kept = !MASK || keep[l];
        acc.energy[l] += select(kept, e, T::zero());
        acc.count[l] += (kept && law.interacts(r2[l])) as u32;
    }
}

/// The per-lane partial sums of a run.
struct Accumulator<T, const D: usize> {
    force: [[T; LANES]; D],
    energy: [T; LANES],
    count: [u32; LANES],
}

impl<T: Real, const D: usize> Accumulator<T, D> {
    #[inline(always)]
    fn new() -> Self {
        Accumulator {
            force: [[T::zero(); LANES]; D],
            energy: [T::zero(); LANES],
            count: [0; LANES],
        }
    }

    /// Adds the lanes up; a run of `blocks` whole blocks (0 or more) came first. With none, the
    /// one-pair tail summed into lane 0 is the result as it stands: the other lanes hold zeros,
    /// and their reduction (a chain of sixteen dependent additions per component) was most of
    /// a dilute gas's force loop, where runs are a few pairs long.
    #[inline(always)]
    fn finish(self, blocks: usize) -> RowSum<T, D> {
        if blocks == 0 {
            return RowSum {
                force: self.force.map(|lanes| lanes[0]),
                energy: self.energy[0],
                interacting: self.count[0] as u64,
            };
        }
        RowSum {
            force: self.force.map(|lanes| lanes.iter().copied().sum()),
            energy: self.energy.iter().copied().sum(),
            interacting: self.count.iter().map(|&c| c as u64).sum(),
        }
    }
}

/// Coefficients of one block, zeroed for excluded lanes when `MASK`; `keep` marks the lanes
/// that act (for the probe).
#[inline(always)]
fn coefficients<T: Real, L: PairLaw<T>, const D: usize, const MASK: bool>(
    law: &L,
    t: &Target<T, D>,
    pos: &[&[T]; D],
    s: &[T],
    base: usize,
    exclude: &Exclude,
) -> (Block<T, D>, [bool; LANES]) {
    let (dx, r2, mut c, ss) = block(law, t, pos, s, base);
    let mut keep = [true; LANES];
    if MASK {
        for l in 0..LANES {
            keep[l] = exclude.keeps(base + l);
            c[l] = select(keep[l], c[l], T::zero());
        }
    }
    ((dx, r2, c, ss), keep)
}

/// One block of the gather form. Each block is handled whole in one call, so the masked and
/// the plain path never merge their block arrays (which would spill them to memory).
#[inline(always)]
fn gather_block<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool, const MASK: bool>(
    law: &L,
    t: &Target<T, D>,
    pos: &[&[T]; D],
    s: &[T],
    base: usize,
    exclude: &Exclude,
    acc: &mut Accumulator<T, D>,
) {
    let ((dx, r2, c, ss), keep) = coefficients::<T, L, D, MASK>(law, t, pos, s, base, exclude);
    for d in 0..D {
        for l in 0..LANES {
            acc.force[d][l] += c[l] * dx[d][l];
        }
    }
    if PROBE {
        probe_block::<T, L, D, MASK>(law, t.s, &r2, &ss, &keep, acc);
    }
}

/// One block of the scatter form: the target's sums, then the reaction on the sources.
#[inline(always)]
fn scatter_block<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool, const MASK: bool>(
    law: &L,
    t: &Target<T, D>,
    pos: &[&[T]; D],
    s: &[T],
    base: usize,
    exclude: &Exclude,
    acc: &mut Accumulator<T, D>,
    fsrc: &mut [&mut [T]; D],
) {
    let ((dx, r2, c, ss), keep) = coefficients::<T, L, D, MASK>(law, t, pos, s, base, exclude);
    // Accumulate and scatter in separate passes over the finished block: interleaving them
    // makes LLVM's SLP vectorizer shuffle the accumulators through memory.
    let mut f = [[T::zero(); LANES]; D];
    for d in 0..D {
        for l in 0..LANES {
            f[d][l] = c[l] * dx[d][l];
            acc.force[d][l] += f[d][l];
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
        probe_block::<T, L, D, MASK>(law, t.s, &r2, &ss, &keep, acc);
    }
}

/// Force on `t` from every source in `src` (the gather form: sources are only read).
#[inline(always)]
pub fn gather<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool>(
    law: &L,
    t: &Target<T, D>,
    src: &Sources<'_, T, D>,
) -> RowSum<T, D> {
    gather_excluding::<T, L, D, PROBE>(law, t, src, Exclude::NONE)
}

/// Calls `$block::<MASK>` for every whole block of a run of `$full` sources, the blocks that
/// hold excluded sources with MASK = true, outside the plain loops (so the hot loops carry
/// no test and no masking).
macro_rules! for_blocks {
    ($exclude:expr, $full:expr, |$base:ident, $mask:ident| $body:expr) => {{
        let masked_end = $exclude.below.next_multiple_of(LANES).min($full);
        let index_block = ($exclude.index < $full)
            .then(|| $exclude.index / LANES * LANES)
            .filter(|&b| b >= masked_end);
        let plain_end = index_block.unwrap_or($full);
        for $base in (0..masked_end).step_by(LANES) {
            const $mask: bool = true;
            $body;
        }
        for $base in (masked_end..plain_end).step_by(LANES) {
            const $mask: bool = false;
            $body;
        }
        if let Some(b) = index_block {
            {
                let $base = b;
                const $mask: bool = true;
                $body;
            }
            for $base in (b + LANES..$full).step_by(LANES) {
                const $mask: bool = false;
                $body;
            }
        }
    }};
}

/// Force on `t` from the sources in `src` that `exclude` keeps.
#[inline(always)]
pub(crate) fn gather_excluding<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool>(
    law: &L,
    t: &Target<T, D>,
    src: &Sources<'_, T, D>,
    exclude: Exclude,
) -> RowSum<T, D> {
    let n = src.len();
    let pos: [&[T]; D] = std::array::from_fn(|d| &src.pos[d][..n]);
    let s = &src.s[..n];
    let mut acc = Accumulator::<T, D>::new();
    let full = n - n % LANES;
    for_blocks!(exclude, full, |base, MASK| gather_block::<
        T,
        L,
        D,
        PROBE,
        MASK,
    >(
        law, t, &pos, s, base, &exclude, &mut acc
    ));
    for j in (full..n).filter(|&j| exclude.keeps(j)) {
        let (dx, r2, c) = pair(law, t, &pos, s, j);
        for d in 0..D {
            acc.force[d][0] += c * dx[d];
        }
        if PROBE {
            acc.energy[0] += law.energy(r2, t.s, s[j]);
            acc.count[0] += law.interacts(r2) as u32;
        }
    }
    acc.finish(full)
}

/// Force on `t` from every source in `src` that `exclude` keeps, also applying the reaction
/// (Newton's third law) to the sources' force accumulators `fsrc` (the scatter form used by
/// the symmetric kernels).
#[inline(always)]
pub fn scatter<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool>(
    law: &L,
    t: &Target<T, D>,
    src: &Sources<'_, T, D>,
    fsrc: [&mut [T]; D],
    exclude: Exclude,
) -> RowSum<T, D> {
    let n = src.len();
    let pos: [&[T]; D] = std::array::from_fn(|d| &src.pos[d][..n]);
    let s = &src.s[..n];
    let mut fsrc = fsrc.map(|f| &mut f[..n]);
    let mut acc = Accumulator::<T, D>::new();
    let full = n - n % LANES;
    for_blocks!(exclude, full, |base, MASK| scatter_block::<
        T,
        L,
        D,
        PROBE,
        MASK,
    >(
        law, t, &pos, s, base, &exclude, &mut acc, &mut fsrc
    ));
    for j in (full..n).filter(|&j| exclude.keeps(j)) {
        let (dx, r2, c) = pair(law, t, &pos, s, j);
        for d in 0..D {
            let f = c * dx[d];
            acc.force[d][0] += f;
            fsrc[d][j] -= f;
        }
        if PROBE {
            acc.energy[0] += law.energy(r2, t.s, s[j]);
            acc.count[0] += law.interacts(r2) as u32;
        }
    }
    acc.finish(full)
}

impl<T: Real, const D: usize> RowSum<T, D> {
    /// No force, no energy, no pairs: the sum over no sources.
    pub fn zero() -> Self {
        RowSum {
            force: [T::zero(); D],
            energy: T::zero(),
            interacting: 0,
        }
    }

    /// Adds the sum over another run of sources for the same target.
    #[inline(always)]
    pub fn add(&mut self, other: &RowSum<T, D>) {
        for d in 0..D {
            self.force[d] += other.force[d];
        }
        self.energy += other.energy;
        self.interacting += other.interacting;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::Gravity;

    /// Excluded sources contribute nothing, in full blocks and in the scalar tail alike.
    #[test]
    fn exclusion_matches_the_sum_over_kept_sources() {
        let law = Gravity::<f64>::new(1.0, 0.0);
        let n = 2 * LANES + 5;
        let pos: [Vec<f64>; 2] = [
            (0..n).map(|j| 1.0 + j as f64).collect(),
            (0..n).map(|j| (j as f64).sin()).collect(),
        ];
        let s = vec![1.0; n];
        let t = Target {
            x: [0.5, 0.0],
            s: 1.0,
        };
        let src = Sources::range(&pos, &s, 0, n);
        for ex in [
            Exclude::index(3),
            Exclude::index(n - 1),
            Exclude::below(7),
            Exclude::below(LANES + 2),
        ] {
            let got = gather_excluding::<f64, _, 2, true>(&law, &t, &src, ex);
            let mut want = [0.0; 2];
            let mut kept = 0;
            for j in (0..n).filter(|&j| ex.keeps(j)) {
                let f = crate::physics::pair_force(&law, [pos[0][j] - 0.5, pos[1][j]], 1.0, 1.0);
                want[0] += f[0];
                want[1] += f[1];
                kept += 1;
            }
            assert!(
                (got.force[0] - want[0]).abs() < 1e-12 && (got.force[1] - want[1]).abs() < 1e-12,
                "{ex:?}"
            );
            assert_eq!(got.interacting, kept);
        }
    }
}
