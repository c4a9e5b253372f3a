/*
 * coulomb_mpi.c: the Coulomb MPI tutorial's particle code, written anew for nbody-bench.
 *
 * 3-D point charges +1/-1 of unit mass, double precision, open space, direct sum with the
 * tutorial's quench (no force between two charges closer than epsilon). Replicated data:
 * every rank holds all positions and owns a block of particles; each step it computes the
 * accelerations of its block against all n charges, integrates its block, and MPI_Allgatherv
 * brings every rank the new positions. Communication is timed apart from computation, as the
 * tutorial does, but per phase, as the mean over ranks (the total as the slowest rank's).
 *
 * Scenario parameters, the same as nbody-bench's `coulomb` scenario
 * (crates/engine/src/scenario/mod.rs, Setup::coulomb and ScenarioKind::defaults; the law in
 * crates/engine/src/physics/coulomb.rs):
 *   positions uniform in the unit cube [0,1)^3, all at rest, mass 1;
 *   charge +1 for even global index, -1 for odd (net charge 0 for even n, +1 for odd n);
 *   force on i: q_i q_j (x_i - x_j) / r^3, zero for r < epsilon, epsilon = 1e-3 (COULOMB_QUENCH:
 *   the tutorial leaves EPSILON unset); energy q_i q_j / r, also zero below epsilon;
 *   dt = 1e-5, n = 1000 by default, float64; open boundary (nothing removed, no walls);
 *   steps 100 and a frame every 10 steps: the defaults of nbody-bench run's --steps and --every.
 * Our generator is not the engine's PCG: same distribution, not the same particles.
 *
 * What the tutorial's code got wrong and this one does not:
 * - n was MAX_PARTICLES / p with the remainder dropped: here n is -n at every p, in blocks that
 *   differ by at most one particle;
 * - each rank drew its particles from its own seed (rank + 28): here rank 0 builds the state
 *   from the -r seed and broadcasts it, so it does not depend on p;
 * - the charge followed the local index, so odd blocks left a net charge: here the global one;
 * - MPI_Allgatherv sent from inside its own receive buffer (not allowed by MPI): here the block
 *   is sent from a buffer of its own, and only positions travel (24 bytes per particle, not the
 *   whole 88-byte particle);
 * - the first-order update (v with a(t), x with the mean velocity) drifts in energy: here velocity
 *   Verlet, as in the LJ codes and the engine;
 * - the int count of interactions overflowed: counts here are 64-bit;
 * - the master printed inside the timed loop and no barrier preceded the clock: here nothing is
 *   printed in the loop and the ranks start together.
 *
 * Build: mpicc -O2 -Wall -Wextra coulomb_mpi.c -o coulomb_mpi -lm
 * Run:   mpirun -n 2 ./coulomb_mpi -n 2000 -s 100
 */
#include "course.h"
#include <mpi.h>

typedef struct {
    const char *out; /* -o: NBView01 file of the (x, y) projection, NULL for none */
    long n;          /* -n: charges */
    long steps;      /* -s: time steps */
    long every;      /* -f: steps between frames (with -o) */
    double dt;       /* -t: time step */
    double quench;   /* -e: no force below this distance */
    unsigned long seed; /* -r: seed of the initial state */
} params_t;

static params_t defaults(void)
{
    params_t p = {NULL, 1000, 100, 10, 1e-5, 1e-3, 1};
    return p;
}

static void usage(const char *prog, FILE *to)
{
    params_t d = defaults();
    fprintf(to,
            "usage: %s [options]\n"
            "  3-D charges +1/-1 at rest in the unit cube, open space, direct sum.\n"
            "  -h        print this message\n"
            "  -o FILE   write NBView01 frames of the (x, y) projection (default: no output)\n"
            "  -n N      number of charges (%ld)\n"
            "  -s S      number of time steps (%ld)\n"
            "  -f K      with -o: a frame every K steps (%ld)\n"
            "  -t DT     time step (%g)\n"
            "  -e EPS    no force between charges closer than EPS (%g)\n"
            "  -r SEED   seed of the initial state (%lu)\n",
            prog, d.n, d.steps, d.every, d.dt, d.quench, d.seed);
}

/* 0 to run, 1 after -h, -1 on a bad command line; only a non-quiet rank prints. */
static int parse(int argc, char **argv, params_t *p, int quiet)
{
    *p = defaults();
    FILE *err = quiet ? NULL : stderr;
    int c;
    long l;
    double d;
    opterr = 0;
    while ((c = getopt(argc, argv, "ho:n:s:f:t:e:r:")) != -1) {
        int bad = 0;
        switch (c) {
        case 'h':
            if (err)
                usage(argv[0], stdout);
            return 1;
        case 'o': p->out = optarg; break;
        case 'n': bad = parse_long(optarg, 1, INT_MAX / 3, &p->n); break; /* 3n is an int */
        case 's': bad = parse_long(optarg, 1, LONG_MAX, &p->steps); break;
        case 'f': bad = parse_long(optarg, 1, LONG_MAX, &p->every); break;
        case 't': bad = parse_double(optarg, &d) || !(d > 0); if (!bad) p->dt = d; break;
        case 'e': bad = parse_double(optarg, &d) || !(d >= 0); if (!bad) p->quench = d; break;
        case 'r':
            bad = parse_long(optarg, 0, LONG_MAX, &l);
            if (!bad)
                p->seed = (unsigned long)l;
            break;
        default:
            if (err) {
                fprintf(err, "%s: unknown option or missing value: -%c\n", argv[0], optopt);
                usage(argv[0], err);
            }
            return -1;
        }
        if (bad) {
            if (err)
                fprintf(err, "%s: bad value for -%c: '%s' (see -h)\n", argv[0], c, optarg);
            return -1;
        }
    }
    if (optind < argc) {
        if (err)
            fprintf(err, "%s: unexpected argument '%s' (see -h)\n", argv[0], argv[optind]);
        return -1;
    }
    return 0;
}

/* Accelerations (unit mass) of the charges [first, first + count) from all n others.
 * x is interleaved (x0 y0 z0 x1 ...); a is the block's own. */
static void block_accelerations(long n, long first, long count, double quench2,
                                const double *restrict x, const double *restrict q,
                                double *restrict a)
{
    for (long b = 0; b < count; ++b) {
        const long i = first + b;
        const double xi = x[3 * i], yi = x[3 * i + 1], zi = x[3 * i + 2];
        double ax = 0, ay = 0, az = 0;
        for (long j = 0; j < n; ++j) {
            /* x_i - x_j: like charges push i away from j. */
            double dx = xi - x[3 * j], dy = yi - x[3 * j + 1], dz = zi - x[3 * j + 2];
            double r2 = dx * dx + dy * dy + dz * dz;
            /* The quench also skips j == i (r2 = 0 < quench2, when quench > 0). */
            if (r2 < quench2 || j == i)
                continue;
            double inv = 1.0 / sqrt(r2);
            double c = q[j] * inv * inv * inv;
            ax += c * dx;
            ay += c * dy;
            az += c * dz;
        }
        a[3 * b] = q[i] * ax;
        a[3 * b + 1] = q[i] * ay;
        a[3 * b + 2] = q[i] * az;
    }
}

/* Total energy: kinetic + sum over pairs of q_i q_j / r (0 below the quench, like the force). */
static double energy(long n, double quench2, const double *x, const double *v, const double *q)
{
    double kinetic = 0, pair = 0;
    for (long i = 0; i < n; ++i) {
        kinetic += 0.5 * (v[3 * i] * v[3 * i] + v[3 * i + 1] * v[3 * i + 1] +
                          v[3 * i + 2] * v[3 * i + 2]);
        for (long j = i + 1; j < n; ++j) {
            double dx = x[3 * i] - x[3 * j], dy = x[3 * i + 1] - x[3 * j + 1],
                   dz = x[3 * i + 2] - x[3 * j + 2];
            double r2 = dx * dx + dy * dy + dz * dz;
            if (r2 >= quench2 && r2 > 0)
                pair += q[i] * q[j] / sqrt(r2);
        }
    }
    return kinetic + pair;
}

static void fail(const char *what)
{
    fprintf(stderr, "coulomb_mpi: %s\n", what);
    MPI_Abort(MPI_COMM_WORLD, 2);
}

/* The (x, y) projection in float for the NBView01 writer (3-D scenarios are viewed so). */
static int write_frame(nbview_t *w, long n, const double *x, float *xy)
{
    for (long i = 0; i < n; ++i) {
        xy[2 * i] = (float)x[3 * i];
        xy[2 * i + 1] = (float)x[3 * i + 1];
    }
    return nbview_frame(w, xy);
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    int rank, nproc;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &nproc);

    params_t p;
    int rc = parse(argc, argv, &p, rank != 0);
    if (rc) {
        MPI_Finalize();
        return rc > 0 ? 0 : 2;
    }
    const long n = p.n;
    const double dt = p.dt, half_dt = 0.5 * p.dt, quench2 = p.quench * p.quench;

    /* Blocks of particles, counts and offsets in doubles (three per particle). */
    int *counts = malloc((size_t)nproc * sizeof *counts);
    int *displs = malloc((size_t)nproc * sizeof *displs);
    if (!counts || !displs)
        fail("out of memory");
    for (int r = 0, off = 0; r < nproc; ++r) {
        long size = n / nproc + (r < n % nproc ? 1 : 0);
        counts[r] = (int)(3 * size);
        displs[r] = off;
        off += counts[r];
    }
    const long first = displs[rank] / 3, count = counts[rank] / 3;

    double *x = malloc(3 * (size_t)n * sizeof *x); /* all positions (receive buffer) */
    double *v = malloc(3 * (size_t)n * sizeof *v); /* all velocities: for the energy */
    double *q = malloc((size_t)n * sizeof *q);
    /* This rank's block, the send buffer; room for one particle at least (a rank may own none). */
    const size_t block_bytes = 3 * (size_t)(count > 0 ? count : 1) * sizeof(double);
    double *xb = malloc(block_bytes), *vb = malloc(block_bytes), *ab = malloc(block_bytes);
    if (!x || !v || !q || !xb || !vb || !ab)
        fail("out of memory");

    /* The charges depend on the global index only; every rank sets them itself. */
    for (long i = 0; i < n; ++i)
        q[i] = i % 2 == 0 ? 1.0 : -1.0;
    /* Rank 0 draws the positions from one seeded stream; everyone receives them. */
    if (rank == 0) {
        rng_t rng = {p.seed};
        for (long k = 0; k < 3 * n; ++k)
            x[k] = rng_uniform(&rng);
    }
    MPI_Bcast(x, (int)(3 * n), MPI_DOUBLE, 0, MPI_COMM_WORLD);
    memset(v, 0, 3 * (size_t)n * sizeof *v); /* the scenario starts at rest */
    memcpy(xb, x + 3 * first, 3 * (size_t)count * sizeof *xb);
    memset(vb, 0, block_bytes);
    const double e0 = rank == 0 ? energy(n, quench2, x, v, q) : 0.0;

    nbview_t out;
    float *xy = NULL;
    int writing = rank == 0 && p.out, ok = 1;
    if (writing) {
        xy = malloc(2 * (size_t)n * sizeof *xy);
        ok = xy && nbview_open(&out, p.out, n, 1.0f) == 0; /* view box: the unit square */
    }
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (!ok) {
        MPI_Finalize();
        return 2;
    }

    /* Set-up, not timed: the accelerations of the initial positions. */
    block_accelerations(n, first, count, quench2, x, q, ab);

    phases_t ph = {0};
    int write_failed = 0;
    MPI_Barrier(MPI_COMM_WORLD); /* start the clocks together */
    double t_start = MPI_Wtime(), t0, t1;
    if (writing) {
        t0 = MPI_Wtime();
        write_failed |= write_frame(&out, n, x, xy) != 0;
        ph.output += MPI_Wtime() - t0;
    }
    for (long s = 1; s <= p.steps; ++s) {
        t0 = MPI_Wtime();
        for (long k = 0; k < 3 * count; ++k) {
            vb[k] += ab[k] * half_dt;
            xb[k] += vb[k] * dt;
        }
        t1 = MPI_Wtime();
        ph.integrate += t1 - t0;
        MPI_Allgatherv(xb, counts[rank], MPI_DOUBLE, x, counts, displs, MPI_DOUBLE,
                       MPI_COMM_WORLD);
        t0 = MPI_Wtime();
        ph.comm += t0 - t1;
        block_accelerations(n, first, count, quench2, x, q, ab);
        t1 = MPI_Wtime();
        ph.force += t1 - t0;
        for (long k = 0; k < 3 * count; ++k)
            vb[k] += ab[k] * half_dt;
        ph.integrate += MPI_Wtime() - t1;
        if (writing && s % p.every == 0) {
            t0 = MPI_Wtime();
            write_failed |= write_frame(&out, n, x, xy) != 0;
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
    MPI_Gatherv(vb, counts[rank], MPI_DOUBLE, v, counts, displs, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    int status = 0;
    if (rank == 0) {
        if (write_failed) {
            fprintf(stderr, "error writing %s\n", p.out);
            status = 2;
        }
        const double e1 = energy(n, quench2, x, v, q);
        print_report("coulomb_mpi", n, p.steps, 1, nproc, &rank_mean, e0, e1);
        fprintf(stderr, "coulomb_mpi: %llu pair evaluations\n",
                (unsigned long long)p.steps * ((unsigned long long)n * (n - 1)));
        if (!isfinite(e1))
            status = 1;
    }
    MPI_Bcast(&status, 1, MPI_INT, 0, MPI_COMM_WORLD);
    free(x), free(v), free(q), free(xb), free(vb), free(ab), free(counts), free(displs);
    free(xy);
    MPI_Finalize();
    return status;
}
