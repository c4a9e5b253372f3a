//! How much each decomposition communicates per step, as a function of n, p, the density and
//! the cutoff: the inputs of an α-β (latency-bandwidth) prediction of communication time,
//! `T(p) = messages · α + bytes · β`, fitted on `mpi-bench` timings (see `docs/explanation/mpi.md`).
//!
//! The tree decompositions of a Barnes-Hut run, counted on a given cloud: the gravity source's
//! octants (top nodes to everyone, and the groups near another domain sent to it and
//! answered: a fixed share of each domain, so like n/p), and the locally essential tree, whose
//! size grows like the surface of a domain (also modelled on a uniform cloud).
//!
//! Counts are for the busiest rank and one step, ignoring migration (a small fraction of the
//! ghosts at the time steps the scenarios use) and the per-step status exchange (one small
//! collective, `log2 p` latencies).

use super::Domains;
use super::essential;
#[cfg(test)]
use super::essential::{body_entry_values, node_entry_values};
#[cfg(test)]
use super::regions::grid_dims;
use super::top_nodes::{TopNodes, TopWalk};
use crate::geometry::Bounds;
use crate::kernels::{Multipole, Octree};
use crate::real::Real;
use crate::state::State;

/// Bytes per particle of a ghost: its coordinates and its source strength.
pub(crate) fn ghost_bytes(dim: usize, value_bytes: usize) -> usize {
    (dim + 1) * value_bytes
}

/// Replicated data: the bytes every rank receives per step from the Allgatherv of the
/// positions (everyone else's block), `(n − ⌊n/p⌋) · D · w`.
pub fn allgather_bytes_per_rank(n: usize, ranks: usize, dim: usize, value_bytes: usize) -> f64 {
    let ranks = ranks.max(1);
    (n - n / ranks) as f64 * (dim * value_bytes) as f64
}

#[cfg(test)]
/// Replicated data: latencies per step of a ring Allgatherv, `p − 1`.
fn allgather_messages_per_rank(ranks: usize) -> f64 {
    ranks.saturating_sub(1) as f64
}

/// Spatial decomposition of a box of `n` particles at `density` (per unit area or volume,
/// box side `L = (n/ρ)^(1/D)`) on the rank grid `dims`: ghosts the busiest rank receives
/// per step, the particles in the shell of width `rc` around its region,
/// `ρ · (Π_a (e_a + m_a) − Π_a e_a)` with `e_a = L / dims[a]` and `m_a` = 0, `rc` or `2rc`
/// as the region has 0, 1 or 2 neighbours along axis a.
pub(crate) fn domain_ghosts_per_rank(n: usize, density: f64, rc: f64, dims: &[usize]) -> f64 {
    let d = dims.len() as i32;
    let side = (n as f64 / density).powf(1.0 / d as f64);
    density * shell_volume(side, rc, dims)
}

/// Volume within distance `r` (per axis) of the busiest region of the grid `dims` over a box
/// of side `side`, outside the region and inside the box: `Π_a (e_a + m_a) − Π_a e_a`, with
/// `e_a = side / dims[a]` and `m_a` = 0, `r` or `2r` as the region has 0, 1 or 2 neighbours
/// along axis a, clipped to the box.
fn shell_volume(side: f64, r: f64, dims: &[usize]) -> f64 {
    let mut outer = 1.0;
    let mut inner = 1.0;
    for &k in dims {
        let e = side / k.max(1) as f64;
        let margin = r * (k.saturating_sub(1).min(2)) as f64;
        outer *= e + margin.min(side - e);
        inner *= e;
    }
    outer - inner
}

/// Spatial decomposition: ghost bytes the busiest rank receives per step.
pub fn domain_bytes_per_rank(
    n: usize,
    density: f64,
    rc: f64,
    dims: &[usize],
    value_bytes: usize,
) -> f64 {
    domain_ghosts_per_rank(n, density, rc, dims) * ghost_bytes(dims.len(), value_bytes) as f64
}

/// Spatial decomposition: messages per step of the busiest rank: a count and a payload to and
/// from each neighbour, for the migration and then for the ghosts (`4 ×` neighbours), where an
/// interior region of a grid has `3^D' − 1` neighbours over the `D'` axes that are cut.
pub fn domain_messages_per_rank(dims: &[usize]) -> f64 {
    let neighbours: usize = dims
        .iter()
        .map(|&k| match k {
            0 | 1 => 1,
            2 => 2,
            _ => 3,
        })
        .product::<usize>()
        - 1;
    4.0 * neighbours as f64
}

/// The octant scheme of the gravity source (`--decomp octants`) on a given cloud, counted by
/// running its selection without MPI: every rank builds the octree of the bodies it owns under
/// `domains`, shares its top nodes (`top_levels` levels, [`super::top_nodes::node_values`] values each,
/// with every other rank), and sends each group of its bodies whose walk of another rank's top
/// nodes must open a node to that rank (a count, then position and strength per body), which
/// answers with D force values per body. Returns the bytes each rank sends in one step, as the
/// MPI driver counts them (a collective's block once per other rank). Grows with the bodies
/// near other domains, within a top node's reach `s/θ`: as the top nodes' side `s` scales
/// with the domains, once the trees are deeper than the shared levels that reach is a fixed
/// share of each domain, so the requests grow like n/p, not like the surface.
pub fn octants_bytes_of_cloud<T: Real, const D: usize>(
    cloud: &State<T, D>,
    domains: &impl Domains<D>,
    theta: f64,
    leaf_size: usize,
    top_levels: u32,
) -> Vec<f64> {
    let ranks = domains.ranks();
    let w = std::mem::size_of::<T>() as f64;
    let trees: Vec<Octree<(), T, D>> = split(cloud, domains)
        .iter()
        .map(|own| {
            let mut tree = Octree::with_multipole((), theta, leaf_size, Multipole::Monopole);
            tree.build(own);
            tree
        })
        .collect();
    let tops: Vec<TopNodes<T, D>> = trees
        .iter()
        .map(|t| {
            if t.view().body_count() == 0 {
                TopNodes::default()
            } else {
                TopNodes::of(&t.view(), top_levels)
            }
        })
        .collect();
    let mut sent = vec![0.0; ranks];
    for (me, tree) in trees.iter().enumerate() {
        let view = tree.view();
        sent[me] += tops[me].encode().len() as f64 * w * (ranks - 1) as f64;
        if view.body_count() == 0 {
            continue;
        }
        for group in view.groups() {
            let points: Vec<[T; D]> = group.clone().map(|k| view.position(k)).collect();
            let Bounds { lo, hi } = Bounds::of_points(points.iter().copied());
            for (r, top) in tops.iter().enumerate() {
                if r != me && !top.is_empty() && top.walk(&lo, &hi) == TopWalk::Open {
                    let bodies = points.len() as f64;
                    sent[me] += (1.0 + bodies * (D + 1) as f64) * w;
                    sent[r] += bodies * D as f64 * w;
                }
            }
        }
    }
    sent
}

/// The bodies each rank owns under `domains`, as states of their own (positions, strengths).
fn split<T: Real, const D: usize>(
    cloud: &State<T, D>,
    domains: &impl Domains<D>,
) -> Vec<State<T, D>> {
    let owners = domains.assign(&cloud.pos);
    (0..domains.ranks())
        .map(|rank| bodies_of(cloud, &owners, rank))
        .collect()
}

/// The bodies of `cloud` whose owner in `owners` is `rank`, as a state of their own (positions
/// and strengths; the rest zero).
pub(crate) fn bodies_of<T: Real, const D: usize>(
    cloud: &State<T, D>,
    owners: &[usize],
    rank: usize,
) -> State<T, D> {
    let mine: Vec<usize> = (0..cloud.len()).filter(|&i| owners[i] == rank).collect();
    let mut own = State::new(mine.len());
    for (k, &i) in mine.iter().enumerate() {
        for d in 0..D {
            own.pos[d][k] = cloud.pos[d][i];
        }
        own.source[k] = cloud.source[i];
    }
    own
}

#[cfg(test)]
/// The locally essential tree the busiest rank receives per step on a uniform cloud of `n`
/// bodies over `ranks` compact domains (the grid of `regions::grid_dims`, as ORB gives on a
/// uniform cloud), at opening angle `theta` and leaf size `leaf_size`: (bodies, nodes).
///
/// At unit density a leaf has side `s = leaf^(1/D)`. The receiver gets the bodies of the
/// leaves whose centres lie within `s/θ` of its domain, and the nodes of side `s·2^j`
/// (j = 0, 1, … up to the cloud) that lie between `s·2^j/θ` and `s·2^(j+1)/θ` (a node is
/// exported where it passes and its parent does not), each shell clipped to the cloud as in
/// `domain_ghosts_per_rank`. Close to the domain the shells are thin, so both counts grow like
/// the domain's surface, `(n/p)^((D−1)/D)`, and not like n: doubling n at fixed p multiplies
/// them by about `2^((D−1)/D)` (1.59 in 3-D) plus a logarithmic far-field term; at θ = 0 the
/// shells cover the cloud and the receiver gets every other body.
fn tree_entries_per_rank(
    n: usize,
    ranks: usize,
    dim: usize,
    theta: f64,
    leaf_size: usize,
) -> (f64, f64) {
    let side = (n as f64).powf(1.0 / dim as f64);
    let dims = grid_dims_of(ranks, dim, side);
    let leaf = (leaf_size.max(1) as f64).powf(1.0 / dim as f64);
    let reach = |s: f64| {
        if theta > 0.0 {
            s / theta
        } else {
            f64::INFINITY
        }
    };
    let bodies = shell_volume(side, reach(leaf), &dims);
    let mut nodes = 0.0;
    let mut s = leaf;
    while theta > 0.0 && s < side {
        let band = shell_volume(side, reach(2.0 * s), &dims) - shell_volume(side, reach(s), &dims);
        nodes += band / s.powi(dim as i32);
        s *= 2.0;
    }
    (bodies, nodes)
}

#[cfg(test)]
/// [`tree_entries_per_rank`] in bytes: bodies with their strength, nodes with their strength
/// and `moment_values` second moments (0 for monopoles, `D(D+1)/2 + 1` for quadrupoles).
fn tree_bytes_per_rank(
    n: usize,
    ranks: usize,
    dim: usize,
    theta: f64,
    leaf_size: usize,
    moment_values: usize,
    value_bytes: usize,
) -> f64 {
    let (bodies, nodes) = tree_entries_per_rank(n, ranks, dim, theta, leaf_size);
    (bodies * body_entry_values(dim) as f64 + nodes * node_entry_values(dim, moment_values) as f64)
        * value_bytes as f64
}

/// The locally essential tree of a given cloud, counted rather than modelled: every rank
/// builds the octree of the bodies it owns under `domains` and selects the essential set of
/// every other rank's domain (`essential::select`); returns the bytes each rank receives.
pub fn tree_bytes_of_cloud<T: Real, const D: usize>(
    cloud: &State<T, D>,
    domains: &impl Domains<D>,
    theta: f64,
    leaf_size: usize,
    multipole: Multipole,
) -> Vec<f64> {
    let ranks = domains.ranks();
    let boxes: Vec<_> = (0..ranks).map(|r| domains.boxes(r)).collect();
    let mut received = vec![0.0; ranks];
    for (sender, own) in split(cloud, domains).iter().enumerate() {
        // The tree needs no force law to be built.
        let mut tree = Octree::with_multipole((), theta, leaf_size, multipole);
        tree.build(own);
        for (r, domain) in boxes.iter().enumerate().filter(|&(r, _)| r != sender) {
            let set = essential::select(&tree.view(), domain);
            received[r] += set.bytes(D, std::mem::size_of::<T>()) as f64;
        }
    }
    received
}

#[cfg(test)]
fn grid_dims_of(ranks: usize, dim: usize, side: f64) -> Vec<usize> {
    match dim {
        2 => grid_dims::<2>(ranks, [side; 2]).to_vec(),
        3 => grid_dims::<3>(ranks, [side; 3]).to_vec(),
        _ => {
            let mut dims = vec![1; dim.max(1)];
            dims[0] = ranks.max(1);
            dims
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decomp::octants::{Octants, root_cube};
    use crate::decomp::orb::Orb;
    use crate::testing::{SEED_1, random_state};

    #[test]
    fn allgather_moves_all_but_the_own_block() {
        assert_eq!(allgather_bytes_per_rank(1000, 1, 2, 4), 0.0);
        assert_eq!(allgather_bytes_per_rank(1000, 4, 2, 4), 750.0 * 8.0);
        assert_eq!(allgather_bytes_per_rank(1001, 4, 3, 8), 751.0 * 24.0);
        assert_eq!(allgather_messages_per_rank(4), 3.0);
    }

    #[test]
    fn ghosts_are_the_shell_around_a_region() {
        // 20000 particles at 500 per unit area: L = sqrt(40); two slabs share one face.
        let side = 40f64.sqrt();
        let g = domain_ghosts_per_rank(20_000, 500.0, 0.025, &[2, 1]);
        assert!((g - 500.0 * 0.025 * side).abs() < 1e-9, "{g}");
        // One rank: nothing to exchange.
        assert_eq!(domain_ghosts_per_rank(20_000, 500.0, 0.025, &[1, 1]), 0.0);
        // An interior block of a 3x3 grid: four sides and four corners.
        let e = side / 3.0;
        let g = domain_ghosts_per_rank(20_000, 500.0, 0.025, &[3, 3]);
        let want = 500.0 * ((e + 0.05).powi(2) - e * e);
        assert!((g - want).abs() < 1e-9, "{g} vs {want}");
        // Weak scaling keeps the regions' size: ghost traffic grows only until the busiest
        // region has neighbours on both sides of each cut axis (here it doubles).
        let a = domain_bytes_per_rank(20_000, 500.0, 0.025, &[2, 2], 4);
        let b = domain_bytes_per_rank(80_000, 500.0, 0.025, &[4, 4], 4);
        assert!(b > a && b < 2.5 * a, "{a} {b}");
        assert_eq!(domain_messages_per_rank(&[2, 1]), 4.0);
        assert_eq!(domain_messages_per_rank(&[3, 3]), 32.0);
    }

    #[test]
    fn octants_send_the_groups_near_other_domains() {
        // One rank: nothing to send. Eight octants of a uniform cloud: every rank sends its top
        // nodes to seven others and some groups; more bodies, more bytes.
        let count = |n: usize, p: usize| {
            let s = random_state::<f64, 3>(n, 1.0, false, SEED_1);
            let (lo, side) = root_cube(&s.pos);
            let octants = Octants::new(lo, side, p, &s.pos).expect("octants");
            octants_bytes_of_cloud(&s, &octants, 0.5, 8, 3)
        };
        assert_eq!(count(4000, 1), vec![0.0]);
        let a = count(8000, 8);
        let b = count(16_000, 8);
        let (ma, mb) = (
            a.iter().copied().fold(0.0, f64::max),
            b.iter().copied().fold(0.0, f64::max),
        );
        assert!(a.iter().all(|&x| x > 0.0), "{a:?}");
        assert!(mb > ma, "×{} for 2× n", mb / ma);
        // Less than replicating every body (the replicated data's Allgatherv).
        assert!(mb < allgather_bytes_per_rank(16_000, 8, 3, 8), "{mb}");
        // θ = 0 accepts no top node: every group goes to every other rank.
        let s = random_state::<f64, 3>(2000, 1.0, false, SEED_1);
        let (lo, side) = root_cube(&s.pos);
        let oct = Octants::new(lo, side, 2, &s.pos).expect("octants");
        let sent = octants_bytes_of_cloud(&s, &oct, 0.0, 8, 3);
        let counts = oct.counts(&s.pos);
        for r in 0..2 {
            // Its bodies (4 values) out, the other's forces (3 values) back, plus the group
            // counts and the top nodes.
            let floor = (counts[r] * 4 + counts[1 - r] * 3) as f64 * 8.0;
            assert!(
                sent[r] > floor && sent[r] < floor * 1.5,
                "{sent:?} {counts:?}"
            );
        }
    }

    #[test]
    fn tree_bytes_grow_like_the_surface_and_allgather_like_n() {
        for dim in [2, 3] {
            let surface = 2f64.powf((dim - 1) as f64 / dim as f64);
            for p in [2, 8, 64] {
                let tree = |n| tree_bytes_per_rank(n, p, dim, 0.5, 8, 0, 8);
                let ratio = tree(2_000_000) / tree(1_000_000);
                // Thick shells around small domains (p = 64) grow slower than the surface.
                assert!(
                    ratio > 1.2 && ratio < surface * 1.1,
                    "{dim}-D, p = {p}: ×{ratio} for 2× n (surface ×{surface})"
                );
                let all = |n| allgather_bytes_per_rank(n, p, dim, 8);
                assert!((all(2_000_000) / all(1_000_000) - 2.0).abs() < 1e-6);
                assert!(tree(1_000_000) < 0.5 * all(1_000_000), "{dim}-D, p = {p}");
            }
        }
        // θ = 0: every other body, nothing else.
        let (bodies, nodes) = tree_entries_per_rank(8000, 8, 3, 0.0, 8);
        assert!(
            (bodies - 7000.0).abs() < 1e-6 && nodes == 0.0,
            "{bodies} {nodes}"
        );
        // Quadrupoles make the nodes, not the bodies, dearer.
        let mono = tree_bytes_per_rank(100_000, 8, 3, 0.5, 8, 0, 8);
        let quad = tree_bytes_per_rank(100_000, 8, 3, 0.5, 8, 7, 8);
        let (_, nodes) = tree_entries_per_rank(100_000, 8, 3, 0.5, 8);
        assert!((quad - mono - nodes * 7.0 * 8.0).abs() < 1e-6 * quad);
    }

    #[test]
    fn counted_tree_bytes_follow_the_model() {
        // Two slabs of a uniform cloud: the counted LET grows like the cut face, and the
        // model is within a factor 2 of the count.
        let counted = |n: usize| {
            let s = random_state::<f64, 3>(n, 1.0, false, SEED_1);
            let orb = Orb::over(2, &s.pos, &vec![1.0; n]).expect("orb");
            let bytes = tree_bytes_of_cloud(&s, &orb, 0.5, 8, Multipole::Monopole);
            bytes.into_iter().fold(0.0, f64::max)
        };
        let (a, b) = (counted(8000), counted(16_000));
        assert!(b / a < 1.8, "counted: ×{} for 2× n", b / a);
        let modelled = tree_bytes_per_rank(16_000, 2, 3, 0.5, 8, 0, 8);
        assert!(
            modelled / b > 0.5 && modelled / b < 2.0,
            "model {modelled} vs count {b}"
        );
        assert!(b < allgather_bytes_per_rank(16_000, 2, 3, 8));
    }
}
