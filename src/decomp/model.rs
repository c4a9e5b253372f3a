//! How much each decomposition communicates per step, as a function of n, p, the density and
//! the cutoff: the inputs of an α-β (latency-bandwidth) prediction of communication time,
//! `T(p) = messages · α + bytes · β`, fitted on `mpi-bench` timings (see `docs/mpi.md`).
//!
//! Counts are for the busiest rank and one step, ignoring migration (a small fraction of the
//! ghosts at the time steps the scenarios use) and the per-step status exchange (one small
//! collective, `log2 p` latencies).

/// Bytes per particle of a ghost: its coordinates and its source strength.
pub fn ghost_bytes(dim: usize, value_bytes: usize) -> usize {
    (dim + 1) * value_bytes
}

/// Replicated data: the bytes every rank receives per step from the Allgatherv of the
/// positions (everyone else's block), `(n − ⌊n/p⌋) · D · w`.
pub fn allgather_bytes_per_rank(n: usize, ranks: usize, dim: usize, value_bytes: usize) -> f64 {
    let ranks = ranks.max(1);
    (n - n / ranks) as f64 * (dim * value_bytes) as f64
}

/// Replicated data: latencies per step of a ring Allgatherv, `p − 1`.
pub fn allgather_messages_per_rank(ranks: usize) -> f64 {
    ranks.saturating_sub(1) as f64
}

/// Spatial decomposition of a box of `n` particles at `density` (per unit area or volume,
/// box side `L = (n/ρ)^(1/D)`) on the rank grid `dims`: ghosts the busiest rank receives
/// per step, the particles in the shell of width `rc` around its region,
/// `ρ · (Π_a (e_a + m_a) − Π_a e_a)` with `e_a = L / dims[a]` and `m_a` = 0, `rc` or `2rc`
/// as the region has 0, 1 or 2 neighbours along axis a.
pub fn domain_ghosts_per_rank(n: usize, density: f64, rc: f64, dims: &[usize]) -> f64 {
    let d = dims.len() as i32;
    let side = (n as f64 / density).powf(1.0 / d as f64);
    let mut outer = 1.0;
    let mut inner = 1.0;
    for &k in dims {
        let e = side / k.max(1) as f64;
        let margin = rc * (k.saturating_sub(1).min(2)) as f64;
        outer *= e + margin.min(side - e);
        inner *= e;
    }
    density * (outer - inner)
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
