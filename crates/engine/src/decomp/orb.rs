//! Weighted orthogonal recursive bisection (ORB) for any rank count p ≥ 1.
//!
//! A box holding q ranks is cut across its longest axis into a lower part of `⌊q/2⌋` ranks and
//! an upper part of `⌈q/2⌉`, at the weighted quantile `⌊q/2⌋/q` of the bodies inside, and each
//! part is cut again until it holds one rank. The weights are the bodies' costs: interaction
//! counts from the previous step (`pair_checks` per body in a tree code), all ones on the first
//! step. Cutting at the quantile rather than the median is what makes odd counts balance.
//!
//! A cut is a plane `x[axis] = at`: bodies with `x[axis] < at` go below, so the regions are
//! half-open `[lo, hi)` and tile the root box (its top walls belong to the regions touching
//! them). Bodies at equal coordinates cannot be separated by a plane, so a cut only falls
//! between distinct coordinates: with distinct coordinates every rank's weight is within about
//! one body's weight of the mean; bodies that coincide go to one rank together. A part without
//! weight (no bodies, or only weightless ones) is cut geometrically at the same fraction, so
//! every rank still gets a region, possibly empty of bodies.

use super::{Aabb, DomainError, Domains};
use crate::geometry::Bounds;
use crate::real::Real;

/// Where a cut sends each side: another cut or a rank.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Child {
    Cut(usize),
    Rank(usize),
}

/// One plane of the bisection tree.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Cut {
    axis: usize,
    at: f64,
    below: Child,
    above: Child,
}

/// The regions of p ranks and the bisection tree that finds a point's owner in `log2 p` steps.
#[derive(Clone, Debug, PartialEq)]
pub struct Orb<const D: usize> {
    regions: Vec<Aabb<D>>,
    cuts: Vec<Cut>,
    root: Child,
}

/// The box the bisection starts from: the bounding box of the bodies, or `[0, 1]^D` when they
/// leave an axis empty (no bodies, or only NaN there) or all sit at +∞ on one, so that a rank
/// without bodies still gets a finite region to cut.
pub fn root_box<T: Real, const D: usize>(pos: &[Vec<T>; D]) -> Aabb<D> {
    let Bounds { lo, hi } = Bounds::of_columns(pos.each_ref().map(Vec::as_slice)).to_f64();
    if lo.contains(&f64::INFINITY) {
        return ([0.0; D], [1.0; D]);
    }
    (lo, hi)
}

impl<const D: usize> Orb<D> {
    /// Bisects the bounding box of the bodies (see [`Orb::new`]).
    pub fn over<T: Real>(
        ranks: usize,
        pos: &[Vec<T>; D],
        weights: &[f64],
    ) -> Result<Self, DomainError> {
        let (lo, hi) = root_box(pos);
        Self::new(lo, hi, ranks, pos, weights)
    }

    /// Bisects the box `[lo, hi]` for `ranks` ranks, balancing `weights` (one per body of
    /// `pos`, finite and ≥ 0). Bodies outside the box are counted on the side of each cut
    /// they compare to, as [`Domains::owner`] places them.
    pub fn new<T: Real>(
        lo: [f64; D],
        hi: [f64; D],
        ranks: usize,
        pos: &[Vec<T>; D],
        weights: &[f64],
    ) -> Result<Self, DomainError> {
        if ranks == 0 {
            return Err(DomainError::NoRanks);
        }
        if !(0..D).all(|a| lo[a].is_finite() && hi[a].is_finite() && hi[a] >= lo[a]) {
            return Err(DomainError::BadBox {
                lo: lo.to_vec(),
                hi: hi.to_vec(),
            });
        }
        let n = pos.first().map_or(0, Vec::len);
        if weights.len() != n {
            return Err(DomainError::WeightCount {
                weights: weights.len(),
                bodies: n,
            });
        }
        if let Some((body, &value)) = weights
            .iter()
            .enumerate()
            .find(|(_, w)| !(w.is_finite() && **w >= 0.0))
        {
            return Err(DomainError::BadWeight { body, value });
        }
        let mut orb = Orb {
            regions: vec![(lo, hi); ranks],
            cuts: Vec::new(),
            root: Child::Rank(0),
        };
        let mut bodies: Vec<u32> = (0..n as u32).collect();
        let input = Input { pos, weights };
        orb.root = orb.split(0, ranks, (lo, hi), &mut bodies, &input);
        Ok(orb)
    }

    /// The region of `rank`.
    pub fn region(&self, rank: usize) -> Aabb<D> {
        self.regions[rank]
    }

    #[cfg(test)]
    /// The sum of `weights` over the bodies each rank owns.
    pub(crate) fn weights_per_rank<T: Real>(&self, pos: &[Vec<T>; D], weights: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.ranks()];
        for (r, w) in self.assign(pos).into_iter().zip(weights) {
            out[r] += w;
        }
        out
    }

    /// Gives ranks `first..first + count` the box `b` and the bodies `idx` inside it.
    fn split<T: Real>(
        &mut self,
        first: usize,
        count: usize,
        b: Aabb<D>,
        idx: &mut [u32],
        input: &Input<'_, T, D>,
    ) -> Child {
        if count == 1 {
            self.regions[first] = b;
            return Child::Rank(first);
        }
        let (lo, hi) = b;
        let lower = count / 2;
        let fraction = lower as f64 / count as f64;
        // The longest axis (the first on a tie), so the regions stay compact.
        let axis = (0..D).fold(0, |best, a| {
            if hi[a] - lo[a] > hi[best] - lo[best] {
                a
            } else {
                best
            }
        });
        let at = weighted_cut(lo[axis], hi[axis], fraction, axis, idx, input);
        // Stable partition: below the plane first.
        let coord = |i: u32| input.pos[axis][i as usize].as_f64();
        let (mut below, above): (Vec<u32>, Vec<u32>) = idx.iter().partition(|&&i| coord(i) < at);
        let k = below.len();
        below.extend(above);
        idx.copy_from_slice(&below);
        let (idx_below, idx_above) = idx.split_at_mut(k);
        let mut hi_below = hi;
        hi_below[axis] = at;
        let mut lo_above = lo;
        lo_above[axis] = at;
        let index = self.cuts.len();
        self.cuts.push(Cut {
            axis,
            at,
            below: Child::Rank(first),
            above: Child::Rank(first + lower),
        });
        let below = self.split(first, lower, (lo, hi_below), idx_below, input);
        let above = self.split(
            first + lower,
            count - lower,
            (lo_above, hi),
            idx_above,
            input,
        );
        self.cuts[index].below = below;
        self.cuts[index].above = above;
        Child::Cut(index)
    }
}

/// The sample of a rank's `bodies` that a new bisection is cut on: every `stride`-th body
/// (indices `0, stride, 2·stride, …`), each weighing what the bodies it stands for cost — its
/// own and the next `stride − 1`'s interaction counts from `costs` (one per body; a body
/// counted at zero still weighs 1, so that it goes somewhere) — or, without per-body costs,
/// `mean_cost` per body. The weights add up to the rank's total cost either way.
pub fn sample_weights(
    bodies: usize,
    stride: usize,
    costs: Option<&[u32]>,
    mean_cost: f64,
) -> Vec<f64> {
    let stride = stride.max(1);
    (0..bodies)
        .step_by(stride)
        .map(|i| {
            let stands_for = i..(i + stride).min(bodies);
            match costs {
                Some(c) => c[stands_for].iter().map(|&x| f64::from(x.max(1))).sum(),
                None => mean_cost * stands_for.len() as f64,
            }
        })
        .collect()
}

impl<const D: usize> Domains<D> for Orb<D> {
    fn ranks(&self) -> usize {
        self.regions.len()
    }

    fn owner(&self, x: [f64; D]) -> usize {
        let mut at = self.root;
        loop {
            match at {
                Child::Rank(r) => return r,
                Child::Cut(c) => {
                    let cut = &self.cuts[c];
                    at = if x[cut.axis] < cut.at {
                        cut.below
                    } else {
                        cut.above
                    };
                }
            }
        }
    }

    fn boxes(&self, rank: usize) -> Vec<Aabb<D>> {
        vec![self.regions[rank]]
    }
}

/// The bodies and their weights.
struct Input<'a, T, const D: usize> {
    pos: &'a [Vec<T>; D],
    weights: &'a [f64],
}

/// The plane across `axis` (inside `[lo, hi]`) that puts the weight of the bodies `idx` below
/// it closest to `fraction` of their total; sorts `idx` along the axis. Geometric without
/// weight.
fn weighted_cut<T: Real, const D: usize>(
    lo: f64,
    hi: f64,
    fraction: f64,
    axis: usize,
    idx: &mut [u32],
    input: &Input<'_, T, D>,
) -> f64 {
    let coord = |i: u32| input.pos[axis][i as usize].as_f64();
    let total: f64 = idx.iter().map(|&i| input.weights[i as usize]).sum();
    if total <= 0.0 {
        return lo + fraction * (hi - lo);
    }
    idx.sort_by(|&a, &b| coord(a).total_cmp(&coord(b)));
    let goal = fraction * total;
    let m = idx.len();
    // Candidates: k bodies below, where a plane can fall between body k−1 and body k.
    let (mut best, mut best_gap) = (0, goal);
    let mut below = 0.0;
    for k in 1..=m {
        below += input.weights[idx[k - 1] as usize];
        let x = coord(idx[k - 1]);
        let separable = if k < m { x < coord(idx[k]) } else { x < hi };
        let gap = (below - goal).abs();
        if separable && gap < best_gap {
            (best, best_gap) = (k, gap);
        }
    }
    if best == 0 {
        return lo;
    }
    let x = coord(idx[best - 1]);
    let next = if best < m { coord(idx[best]) } else { hi };
    // Halfway between the two bodies, but strictly above the lower one.
    let mid = x + 0.5 * (next - x);
    let at = if mid > x { mid } else { next };
    at.clamp(lo, hi)
}

#[cfg(test)]
mod tests;
