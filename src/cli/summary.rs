//! The summary `run` prints, serial or under MPI.

use nbody_engine::run::RunOutcome;
use nbody_harness::units::Duration;

/// The run's measurements, one labelled line each.
pub fn print_summary(r: &RunOutcome) {
    let t = &r.timing;
    outln!(
        "{} / {}: n = {}, {} steps, {} thread{}{}, {}-D {}, {}, simd {}",
        r.scenario,
        r.kernel,
        r.n,
        r.steps,
        r.threads,
        if r.threads == 1 { "" } else { "s" },
        if r.oversubscribed {
            " (oversubscribed)"
        } else {
            ""
        },
        r.dim,
        r.precision,
        match &r.initial {
            Some(path) => format!("bodies from {path}"),
            None => format!("seed {}", r.seed),
        },
        r.simd
    );
    if r.n < r.n_requested {
        outln!(
            "note: placed {} of the {} particles requested (--allow-fewer)",
            r.n,
            r.n_requested
        );
    }
    let p = &t.per_step_ns;
    outln!(
        "time per step     p50 {}  p90 {}  p99 {}  max {}",
        Duration::from_ns(p.p50 as f64),
        Duration::from_ns(p.p90 as f64),
        Duration::from_ns(p.p99 as f64),
        Duration::from_ns(p.max as f64)
    );
    outln!(
        "per particle-step {} (mean over the steps)",
        Duration::from_ns(t.ns_per_particle_step)
    );
    outln!(
        "throughput        {:.3e} particle-steps/s, {:.3e} pair-evaluations/s",
        r.throughput.particle_steps_per_s,
        r.throughput.pair_evals_per_s
    );
    let ph = &t.phases;
    let total = ph.total().max(f64::MIN_POSITIVE);
    let pct = |x: f64| 100.0 * x / total;
    outln!(
        "phases            force build {:.1}%  interact {:.1}%  integrate {:.1}%  boundary {:.1}%  output {:.1}%",
        pct(ph.force_build),
        pct(ph.force_interact),
        pct(ph.integrate),
        pct(ph.boundary),
        pct(ph.output)
    );
    print_work(r);
    outln!(
        "energy            {:.6e} -> {:.6e}, relative drift {:+.3e}",
        r.energy.initial.total(),
        r.energy.last.total(),
        r.energy.rel_drift
    );
}

/// The work per step: pair checks, tree nodes, cells, pairs in range, and the neighbour list
/// when the kernel keeps one.
fn print_work(r: &RunOutcome) {
    let t = &r.timing;
    let c = &r.counters;
    out!(
        "work per step     {:.4e} pair checks",
        c.pair_checks_per_step
    );
    let steps = r.steps.max(1) as f64;
    if c.total.nodes_opened > 0 {
        out!(
            ", {:.4e} nodes opened, {:.4e} accepted",
            c.total.nodes_opened as f64 / steps,
            c.total.nodes_accepted as f64 / steps
        );
    }
    if c.total.cells_visited > 0 {
        out!(
            ", {:.4e} cells visited",
            c.total.cells_visited as f64 / steps
        );
    }
    outln!(
        "; {} interacting pairs at the end",
        c.pairs_interacting_final
    );
    if c.total.list_entries > 0 || c.total.rebuilds > 0 {
        let entries = c.total.list_entries as f64 / steps;
        let every = match c.total.rebuilds {
            0 => "no rebuild".to_string(),
            k => format!("{k} rebuilds, one per {:.1} steps", steps / k as f64),
        };
        let pairs = c.pairs_interacting_final as f64 / entries.max(1.0);
        // A Verlet list's entry is one pair; a cluster list's is a run of particles against a
        // cluster, many pairs.
        let inside = if r.kernel == "verlet" {
            format!("{:.1}% of the entries", 100.0 * pairs)
        } else {
            format!("{pairs:.1} per entry")
        };
        // The median step is one between rebuilds: the mean carries their cost.
        outln!(
            "neighbour list    {entries:.4e} entries per step, {every} (mean {} per \
             particle-step); pairs inside the cutoff at the end: {inside}",
            Duration::from_ns(t.per_step_ns.mean / r.n.max(1) as f64),
        );
    }
}
