//! The force loops over a neighbour list. Partners are gathered by slot into lane arrays of
//! `LANES`, the law is evaluated lane by lane as in [`crate::kernels::rows`], and forces are
//! scattered back one lane at a time, in order, so that two lanes with the same slot add up.
//! Lanes past the last entry are zeroed with a select on the coefficient; they read the
//! part's padding (valid slots).
//!
//! - [`half_pairs`]: the half list with Newton's third law, in blocks of entries whatever
//!   their rows, both ends of every pair scattered. One loop serves the gas and the liquid.
//!   A loop over rows (a target's force summed in registers over whole blocks of its
//!   partners, only the reactions scattered) was measured against it (2-vCPU AMD EPYC under
//!   load from other work, CPU time per force computation, n = 1e5): 3–7× slower on the gas at
//!   0.5 to 5 entries per particle, where every row costs a whole block and a sum of its
//!   lanes, and about 5% faster on the liquid at 10 entries (56 against 59 ns per particle,
//!   medians of 8 runs, within the spread of either); so it was not kept.
//!   In three dimensions a row holds about forty entries (a liquid's half list at rc + skin),
//!   enough to fill its blocks, and the loop over rows ([`half_rows`]) is the one taken there:
//!   it halves the scatters and gathers no target per entry.
//! - [`target_rows`]: every partner of each target (a full list: no reactions).

use super::list::Part;
use crate::kernels::images::Images;
use crate::kernels::rows::{LANES, RowSum, lane_sum};
use crate::physics::PairLaw;
use crate::real::{Real, select};
use crate::state::State;

/// Slot-indexed inputs: positions and strengths, each slice of length n.
pub(crate) struct Slots<'a, T, const D: usize> {
    pos: [&'a [T]; D],
    src: &'a [T],
}

impl<'a, T: Real, const D: usize> Slots<'a, T, D> {
    #[inline(always)]
    pub fn of(state: &'a State<T, D>) -> Self {
        Slots::new(state.pos.each_ref().map(|x| x.as_slice()), &state.source)
    }

    /// Slots from their positions and strengths (as many of each).
    #[inline(always)]
    pub fn new(pos: [&'a [T]; D], src: &'a [T]) -> Self {
        let n = src.len();
        Slots {
            pos: pos.map(|x| &x[..n]),
            src,
        }
    }

    /// Positions and strengths of the slots `idx`. The index is clamped to the last slot, which
    /// every entry is below already, so that the loads need no bounds check and vectorize; its
    /// top bit is dropped (slots are below 2^29) so that the gathers take 32-bit indices, 16
    /// lanes at a time rather than 8 (10–15% off the loops, measured on both lists).
    #[inline(always)]
    fn gather(&self, idx: &[u32; LANES]) -> ([[T; LANES]; D], [T; LANES]) {
        let n = self.src.len();
        let (src, last) = (&self.src[..n], n - 1);
        let mut x = [[T::zero(); LANES]; D];
        let mut s = [T::zero(); LANES];
        let mut at = [0usize; LANES];
        for l in 0..LANES {
            at[l] = ((idx[l] & 0x7fff_ffff) as usize).min(last);
        }
        for d in 0..D {
            let pos = &self.pos[d][..n];
            for l in 0..LANES {
                x[d][l] = pos[at[l]];
            }
        }
        for l in 0..LANES {
            s[l] = src[at[l]];
        }
        (x, s)
    }

    /// The position and strength of slot `i` in every lane.
    #[inline(always)]
    fn broadcast(&self, i: usize) -> ([[T; LANES]; D], [T; LANES]) {
        let mut x = [[T::zero(); LANES]; D];
        for d in 0..D {
            x[d] = [self.pos[d][i]; LANES];
        }
        (x, [self.src[i]; LANES])
    }
}

/// Energy and interacting pairs, per lane (probe computations only).
struct Probe<T> {
    energy: [T; LANES],
    count: [u32; LANES],
}

impl<T: Real> Probe<T> {
    fn new() -> Self {
        Probe {
            energy: [T::zero(); LANES],
            count: [0; LANES],
        }
    }

    fn finish<const D: usize>(self) -> RowSum<T, D> {
        RowSum {
            force: [T::zero(); D],
            energy: self.energy.iter().copied().sum(),
            interacting: self.count.iter().map(|&c| c as u64).sum(),
        }
    }
}

/// The forces on the `i` lanes from the `j` lanes (`f[d][l]` on lane `l`'s target), the lanes
/// from `keep` on zeroed.
#[inline(always)]
fn evaluate<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool>(
    law: &L,
    (xi, si): &([[T; LANES]; D], [T; LANES]),
    (xj, sj): &([[T; LANES]; D], [T; LANES]),
    keep: usize,
    probe: &mut Probe<T>,
) -> [[T; LANES]; D] {
    let mut dx = [[T::zero(); LANES]; D];
    let mut r2 = [T::zero(); LANES];
    for d in 0..D {
        for l in 0..LANES {
            dx[d][l] = xj[d][l] - xi[d][l];
            r2[l] += dx[d][l] * dx[d][l];
        }
    }
    let mut c = [T::zero(); LANES];
    for l in 0..LANES {
        c[l] = select(l < keep, law.coeff(r2[l], si[l], sj[l]), T::zero());
    }
    let mut f = [[T::zero(); LANES]; D];
    for d in 0..D {
        for l in 0..LANES {
            f[d][l] = c[l] * dx[d][l];
        }
    }
    if PROBE {
        for l in 0..LANES {
            let e = law.energy(r2[l], si[l], sj[l]);
            probe.energy[l] += select(l < keep, e, T::zero());
            probe.count[l] += u32::from(l < keep && law.interacts(r2[l]));
        }
    }
    f
}

/// The entries `e..e + LANES` of `v` as a block (the padding keeps it in range).
#[inline(always)]
fn block_of(v: &[u32], e: usize) -> &[u32; LANES] {
    v[e..e + LANES].try_into().expect("entries are padded")
}

/// The partners of the entries `e..e + LANES` of `part`, each at the image its entry met in a
/// periodic box (`images`).
#[inline(always)]
fn partners<T: Real, const D: usize>(
    slots: &Slots<'_, T, D>,
    part: &Part,
    e: usize,
    images: Option<&Images<T, D>>,
) -> ([[T; LANES]; D], [T; LANES]) {
    let (mut x, s) = slots.gather(block_of(&part.partner, e));
    if let Some(images) = images {
        let codes: &[u8; LANES] = part.shift[e..e + LANES]
            .try_into()
            .expect("entries are padded");
        let shift = images.shifts(codes);
        for d in 0..D {
            for l in 0..LANES {
                x[d][l] += shift[d][l];
            }
        }
    }
    (x, s)
}

/// Where the forces of a part go, by slot.
pub(crate) trait Scatter<T> {
    /// Adds component `d` of lane `l` of `f` to the force on slot `s`, for every `d`.
    fn add<const D: usize>(&mut self, s: usize, f: &[[T; LANES]; D], l: usize);
    /// Subtracts it (a reaction).
    fn sub<const D: usize>(&mut self, s: usize, f: &[[T; LANES]; D], l: usize);
    /// Adds lane `l` of `f` to slot `i` and subtracts it from slot `j` (one pair, both ends).
    #[inline(always)]
    fn pair<const D: usize>(&mut self, i: usize, j: usize, f: &[[T; LANES]; D], l: usize) {
        self.add(i, f, l);
        self.sub(j, f, l);
    }
}

/// The forces of the slots from `base` on: slot `s` at `out[d][s - base]`.
pub(crate) struct Window<'a, T, const D: usize> {
    pub out: [&'a mut [T]; D],
    pub base: usize,
}

impl<T: Real, const K: usize> Scatter<T> for Window<'_, T, K> {
    #[inline(always)]
    fn add<const D: usize>(&mut self, s: usize, f: &[[T; LANES]; D], l: usize) {
        let at = s - self.base;
        for d in 0..D.min(K) {
            self.out[d][at] += f[d][l];
        }
    }

    #[inline(always)]
    fn sub<const D: usize>(&mut self, s: usize, f: &[[T; LANES]; D], l: usize) {
        let at = s - self.base;
        for d in 0..D.min(K) {
            self.out[d][at] -= f[d][l];
        }
    }

    /// Both ends of the pair axis by axis, each axis's column looked up once: the gas's force
    /// loop scatters every entry's two ends, and the add and subtract of each its own pass
    /// over the axes made the loop 25% slower in the sweep's 2-D walled box.
    #[inline(always)]
    fn pair<const D: usize>(&mut self, i: usize, j: usize, f: &[[T; LANES]; D], l: usize) {
        let (i, j) = (i - self.base, j - self.base);
        for d in 0..D.min(K) {
            let column = &mut *self.out[d];
            column[i] += f[d][l];
            column[j] -= f[d][l];
        }
    }
}

/// Two windows, the slots from `split` on in `high`: a part of a periodic list whose pairs
/// reach across the faces into slots far from its own.
pub(crate) struct Split<'a, T, const D: usize> {
    pub low: Window<'a, T, D>,
    pub high: Window<'a, T, D>,
}

impl<T: Real, const K: usize> Scatter<T> for Split<'_, T, K> {
    #[inline(always)]
    fn add<const D: usize>(&mut self, s: usize, f: &[[T; LANES]; D], l: usize) {
        if s >= self.high.base {
            self.high.add(s, f, l);
        } else {
            self.low.add(s, f, l);
        }
    }

    #[inline(always)]
    fn sub<const D: usize>(&mut self, s: usize, f: &[[T; LANES]; D], l: usize) {
        if s >= self.high.base {
            self.high.sub(s, f, l);
        } else {
            self.low.sub(s, f, l);
        }
    }
}

/// Adds the forces of the pairs of `part` to `out`, both ends of each pair, in blocks of
/// entries that ignore the rows; in a periodic box (`images`), each partner at the image its
/// entry met.
#[inline(always)]
pub(crate) fn half_pairs<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool>(
    law: &L,
    slots: &Slots<'_, T, D>,
    part: &Part,
    out: &mut impl Scatter<T>,
    images: Option<&Images<T, D>>,
) -> RowSum<T, D> {
    if D == 3 {
        return half_rows::<T, L, D, PROBE>(law, slots, part, out, images);
    }
    let mut probe = Probe::new();
    let m = part.entries();
    let mut e = 0;
    while e < m {
        let (ii, jj) = (block_of(&part.owner, e), block_of(&part.partner, e));
        let (xi, xj) = (slots.gather(ii), partners(slots, part, e, images));
        let f = evaluate::<T, L, D, PROBE>(law, &xi, &xj, m - e, &mut probe);
        for l in 0..LANES {
            out.pair(ii[l] as usize, jj[l] as usize, &f, l);
        }
        e += LANES;
    }
    probe.finish()
}

/// [`half_pairs`] row by row, for rows long enough to fill their blocks (three dimensions:
/// about forty entries a row in a liquid): each target's force summed in registers over its
/// partners' blocks and added once, only the reactions scattered lane by lane.
#[inline(always)]
fn half_rows<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool>(
    law: &L,
    slots: &Slots<'_, T, D>,
    part: &Part,
    out: &mut impl Scatter<T>,
    images: Option<&Images<T, D>>,
) -> RowSum<T, D> {
    let mut probe = Probe::new();
    for (r, &i) in part.target.iter().enumerate() {
        let (a, b) = (part.first[r], part.first[r + 1]);
        if a == b {
            continue;
        }
        let target = slots.broadcast(i as usize);
        let mut acc = [[T::zero(); LANES]; D];
        let mut e = a;
        while e < b {
            let jj = block_of(&part.partner, e);
            let partners = partners(slots, part, e, images);
            let f = evaluate::<T, L, D, PROBE>(law, &target, &partners, b - e, &mut probe);
            for l in 0..LANES.min(b - e) {
                out.sub(jj[l] as usize, &f, l);
            }
            for d in 0..D {
                for l in 0..LANES {
                    acc[d][l] += f[d][l];
                }
            }
            e += LANES;
        }
        let mut sum = [[T::zero(); LANES]; D];
        for d in 0..D {
            sum[d][0] = lane_sum(acc[d]);
        }
        out.add(i as usize, &sum, 0);
    }
    probe.finish()
}

/// Overwrites `out[d][r]` with the force on the target of row `part.rows.start + r` from
/// all its partners (a full list), each at its entry's image in a periodic box (`images`).
#[inline(always)]
pub(crate) fn target_rows<T: Real, L: PairLaw<T>, const D: usize>(
    law: &L,
    slots: &Slots<'_, T, D>,
    part: &Part,
    out: &mut [&mut [T]; D],
    images: Option<&Images<T, D>>,
) {
    let mut probe = Probe::new();
    for (r, &i) in part.target.iter().enumerate() {
        let (a, b) = (part.first[r], part.first[r + 1]);
        let target = slots.broadcast(i as usize);
        let mut acc = [[T::zero(); LANES]; D];
        let mut e = a;
        while e < b {
            let partners = partners(slots, part, e, images);
            let f = evaluate::<T, L, D, false>(law, &target, &partners, b - e, &mut probe);
            for d in 0..D {
                for l in 0..LANES {
                    acc[d][l] += f[d][l];
                }
            }
            e += LANES;
        }
        for d in 0..D {
            out[d][r] = lane_sum(acc[d]);
        }
    }
}
