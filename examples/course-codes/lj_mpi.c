/*
 * lj_mpi.c: the LJ-box assignment's MPI code, written anew for nbody-bench.
 *
 * Replicated data: every rank holds all n positions and owns a contiguous block of particles
 * (block sizes differ by at most one). Each step a rank computes the forces on its own block
 * against all n particles (each pair is evaluated on both sides, n(n-1) pair evaluations in
 * all, twice the serial code's, though without the serial loop's writes to the partner's
 * force, so at p = 1 it is slower than lj_serial by less than two), integrates its block, and MPI_Allgatherv brings every rank the new positions.
 *
 * What the assignment's MPI code got wrong and this one does not:
 * - the initial state: rank 0 builds it from the -r seed (the same function as the serial code)
 *   and broadcasts positions and velocities, so it is the same at every rank count;
 *   the velocities are not zeroed before the run, so -T has its effect;
 * - n is the -n given at every rank count (the remainder of n / p is spread, not dropped);
 * - the Allgatherv sends from a separate buffer (the block being integrated), never from
 *   inside the receive buffer;
 * - frame output is timed as its own phase (rank 0 writes; the others then wait at the next
 *   Allgatherv, which shows in their comm time).
 *
 * Scenario parameters: nbody-bench's `lj-box` (crates/engine/src/scenario/mod.rs, Setup::lj and
 * ScenarioKind::defaults; placement.rs; physics/lj.rs): epsilon 1, sigma 0.01, force truncated
 * at rc = 2.5 sigma, box [0, L]^2 with L = sqrt(n / 500), reflecting walls, gravity g = 1 along
 * -y, velocity components N(0, T0 = 1), unit mass, dt = 1e-4, float32, positions uniform at least
 * sigma apart. The top of course.h says where each one is defined.
 *
 * Build: mpicc -O2 -Wall -Wextra lj_mpi.c -o lj_mpi -lm
 * Run:   mpirun -n 2 ./lj_mpi -n 1000 -F 1 -f 100
 */
#include "course.h"
#include <mpi.h>

/* Forces on the particles [first, first + count) from all n others; f is the block's own. */
static void block_forces(const lj_law_t *law, long n, long first, long count,
                         const float *restrict x, float *restrict f)
{
    for (long b = 0; b < count; ++b) {
        const long i = first + b;
        const float xi = x[2 * i], yi = x[2 * i + 1];
        float fx = 0.0f, fy = 0.0f;
        /* Two loops around j == i instead of a test inside one. */
        for (long j = 0; j < i; ++j) {
            float dx = x[2 * j] - xi, dy = x[2 * j + 1] - yi;
            float c = lj_coeff(law, dx * dx + dy * dy);
            fx += c * dx;
            fy += c * dy;
        }
        for (long j = i + 1; j < n; ++j) {
            float dx = x[2 * j] - xi, dy = x[2 * j + 1] - yi;
            float c = lj_coeff(law, dx * dx + dy * dy);
            fx += c * dx;
            fy += c * dy;
        }
        f[2 * b] = fx;
        f[2 * b + 1] = fy;
    }
}

static void fail(const char *what)
{
    fprintf(stderr, "lj_mpi: %s\n", what);
    MPI_Abort(MPI_COMM_WORLD, 2);
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    int rank, nproc;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &nproc);

    /* Every rank parses the same command line; only rank 0 prints about it. */
    lj_params_t p;
    int rc = lj_parse(argc, argv, &p, rank != 0);
    if (rc) {
        MPI_Finalize();
        return rc > 0 ? 0 : 2;
    }
    const long n = p.n;
    const long long steps = (long long)p.frames * p.steps_per_frame;
    const lj_law_t law = lj_law(&p);

    /* Blocks: the first n % p ranks get one particle more. Counts and offsets are in floats
     * (two per particle), which is what Allgatherv of MPI_FLOAT needs; 2n fits an int (-n is
     * limited to INT_MAX / 2). */
    int *counts = malloc((size_t)nproc * sizeof *counts);
    int *displs = malloc((size_t)nproc * sizeof *displs);
    if (!counts || !displs)
        fail("out of memory");
    for (int r = 0, off = 0; r < nproc; ++r) {
        long size = n / nproc + (r < n % nproc ? 1 : 0);
        counts[r] = (int)(2 * size);
        displs[r] = off;
        off += counts[r];
    }
    const long first = displs[rank] / 2, count = counts[rank] / 2;

    float *x = malloc(2 * (size_t)n * sizeof *x); /* all positions (receive buffer) */
    float *v = malloc(2 * (size_t)n * sizeof *v); /* all velocities: set-up and energy */
    /* This rank's block (send buffer); at least one particle's room, since a rank may own
     * none (n < p) and malloc(0) may return NULL. */
    const size_t block_bytes = 2 * (size_t)(count > 0 ? count : 1) * sizeof(float);
    float *xb = malloc(block_bytes), *vb = malloc(block_bytes), *fb = malloc(block_bytes);
    if (!x || !v || !xb || !vb || !fb)
        fail("out of memory");

    /* Rank 0 builds the initial state, everyone receives it: the same state at any p. */
    int ok = 1;
    double e0 = 0;
    if (rank == 0) {
        ok = lj_init_state(&p, x, v) == 0;
        if (ok)
            e0 = lj_energy(&p, x, v);
    }
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (!ok) {
        MPI_Finalize();
        return 2;
    }
    MPI_Bcast(x, (int)(2 * n), MPI_FLOAT, 0, MPI_COMM_WORLD);
    MPI_Bcast(v, (int)(2 * n), MPI_FLOAT, 0, MPI_COMM_WORLD);
    memcpy(xb, x + 2 * first, 2 * (size_t)count * sizeof *xb);
    memcpy(vb, v + 2 * first, 2 * (size_t)count * sizeof *vb);

    nbview_t out;
    int writing = rank == 0 && p.out;
    ok = !writing || nbview_open(&out, p.out, n, law.side) == 0;
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (!ok) {
        MPI_Finalize();
        return 2;
    }

    /* Set-up, not timed: the forces of the initial positions. */
    block_forces(&law, n, first, count, x, fb);

    phases_t ph = {0};
    int write_failed = 0;
    MPI_Barrier(MPI_COMM_WORLD); /* start the clocks together */
    double t_start = MPI_Wtime(), t0, t1;
    if (writing) {
        t0 = MPI_Wtime();
        write_failed |= nbview_frame(&out, x) != 0;
        ph.output += MPI_Wtime() - t0;
    }
    for (long frame = 0; frame < p.frames; ++frame) {
        for (long s = 0; s < p.steps_per_frame; ++s) {
            t0 = MPI_Wtime();
            int bad = 0;
            for (long b = 0; b < count; ++b)
                bad |= lj_kick_drift_reflect(&law, xb + 2 * b, vb + 2 * b, fb + 2 * b);
            t1 = MPI_Wtime();
            ph.integrate += t1 - t0;
            if (bad) {
                fprintf(stderr,
                        "rank %d, step %lld: a particle is still outside the box after one "
                        "reflection (or not a number); reduce -t\n",
                        rank, (long long)frame * p.steps_per_frame + s + 1);
                MPI_Abort(MPI_COMM_WORLD, 1);
            }
            /* The block goes from its own buffer into everyone's copy of x. */
            MPI_Allgatherv(xb, counts[rank], MPI_FLOAT, x, counts, displs, MPI_FLOAT,
                           MPI_COMM_WORLD);
            t0 = MPI_Wtime();
            ph.comm += t0 - t1;
            block_forces(&law, n, first, count, x, fb);
            t1 = MPI_Wtime();
            ph.force += t1 - t0;
            for (long b = 0; b < count; ++b)
                lj_kick(&law, vb + 2 * b, fb + 2 * b);
            ph.integrate += MPI_Wtime() - t1;
        }
        if (writing) {
            t0 = MPI_Wtime();
            write_failed |= nbview_frame(&out, x) != 0;
            ph.output += MPI_Wtime() - t0;
        }
    }
    if (writing) {
        t0 = MPI_Wtime();
        write_failed |= nbview_close(&out) != 0;
        ph.output += MPI_Wtime() - t0;
    }
    ph.total = MPI_Wtime() - t_start;

    /* Each phase as the mean over the ranks, so the phases add up to a rank's step (the wait
     * for a slower rank is in `comm`); the total as the slowest rank's, the step being as slow
     * as its slowest rank. (The maximum of each phase apart would add the fastest rank's wait to
     * the slowest rank's work.) */
    phases_t rank_mean;
    MPI_Reduce(&ph, &rank_mean, (int)(sizeof ph / sizeof(double)), MPI_DOUBLE, MPI_SUM, 0,
               MPI_COMM_WORLD);
    MPI_Reduce(&ph.total, &rank_mean.total, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
    rank_mean.force /= nproc;
    rank_mean.reduce /= nproc;
    rank_mean.integrate /= nproc;
    rank_mean.comm /= nproc;
    rank_mean.output /= nproc;

    /* Final energy on rank 0 with the same function as the serial code: gather the velocities
     * (x is already complete on every rank). */
    MPI_Gatherv(vb, counts[rank], MPI_FLOAT, v, counts, displs, MPI_FLOAT, 0, MPI_COMM_WORLD);
    int status = 0;
    if (rank == 0) {
        if (write_failed) {
            fprintf(stderr, "error writing %s\n", p.out);
            status = 2;
        }
        const double e1 = lj_energy(&p, x, v);
        print_report("lj_mpi", n, steps, 1, nproc, &rank_mean, e0, e1);
        fprintf(stderr, "lj_mpi: %llu pair evaluations\n",
                (unsigned long long)steps * ((unsigned long long)n * (n - 1)));
        if (!isfinite(e1))
            status = 1;
    }
    MPI_Bcast(&status, 1, MPI_INT, 0, MPI_COMM_WORLD);
    free(x), free(v), free(xb), free(vb), free(fb), free(counts), free(displs);
    MPI_Finalize();
    return status;
}
