/*
 * course.h: what the course codes share, written once.
 *
 * The 2-D Lennard-Jones box of the LJ-box assignment (lj_serial.c, lj_omp.c, lj_mpi.c) and the
 * pieces the Coulomb code (coulomb_mpi.c) also uses: the random generator, the clock, the
 * big-endian writer and the closing report that the harness reads.
 *
 * lj-box parameters, the same as nbody-bench's `lj-box` scenario:
 *   epsilon = 1, sigma = 0.01          LJ_EPSILON, LJ_SIGMA (scenario/mod.rs, physics/lj.rs)
 *   cutoff rc = 2.5 sigma              LJ_CUTOFF (scenario/mod.rs); force truncated at rc, the
 *                                      monitored energy shifted by V(rc) (physics/lj.rs)
 *   500 particles per unit area        LJ_GAS_DENSITY, so the box is [0, L]^2 with
 *                                      L = sqrt(n / 500) (Setup::lj in scenario/mod.rs)
 *   gravity g = 1 downward (-y)        LJ_GRAVITY, applied as a constant acceleration
 *   T0 = 1, velocity components        LJ_T0; variance T0 (std sqrt(T0)), unit mass, k_B = 1
 *   drawn from N(0, T0)
 *   dt = 1e-4                          ScenarioKind::defaults, float32 (Precision::F32)
 *   placement: uniform in the box,     placement::spaced_uniform: rejection sampling against
 *   no two closer than sigma           a grid of cells, so O(n)
 *   walls: elastic reflection at 0, L  Boundary::Reflecting (boundary.rs); a particle still outside
 *                                      after one reflection stops the run
 *   integrator: velocity Verlet        integrator.rs: v += (F + g) dt/2; x += v dt; walls;
 *   (kick-drift-kick)                  F = F(x); v += (F + g) dt/2
 * Our generator is not the engine's PCG, so the initial state is a different sample of the same
 * distribution (same box, density, parameters and time step), not the same particles.
 */
#ifndef COURSE_H
#define COURSE_H

/* getopt and clock_gettime are POSIX; say so before any system header (course.h comes first). */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

/* ---------------------------------------------------------------- clock, random numbers */

/* Monotonic wall clock in seconds (not affected by changes of the system time). */
static inline double wall_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* splitmix64: small, seedable, and the same stream on every machine and every rank, which is
 * what makes the initial state independent of the thread and rank counts (drand48 unseeded,
 * or seeded per rank, is what made the source codes' states depend on p). */
typedef struct {
    uint64_t s;
} rng_t;

static inline uint64_t rng_next(rng_t *r)
{
    uint64_t z = (r->s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Uniform in [0, 1), 53 random bits. */
static inline double rng_uniform(rng_t *r)
{
    return (double)(rng_next(r) >> 11) * 0x1.0p-53;
}

/* ---------------------------------------------------------------- command-line helpers */

/* Strict number parsing: "12x", "", or an out-of-range value is an error, not 12 or 0 (atoi). */
static inline int parse_long(const char *s, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || end == s || *end != '\0' || v < lo || v > hi)
        return -1;
    *out = v;
    return 0;
}

static inline int parse_double(const char *s, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end != '\0' || !isfinite(v))
        return -1;
    *out = v;
    return 0;
}

/* ---------------------------------------------------------------- big-endian output */

/* Big-endian ("network order") bytes whatever the host, as the NBView viewer expects. */
static inline void put_be32(unsigned char *p, uint32_t u)
{
    p[0] = (unsigned char)(u >> 24);
    p[1] = (unsigned char)(u >> 16);
    p[2] = (unsigned char)(u >> 8);
    p[3] = (unsigned char)u;
}

static inline void put_be_float(unsigned char *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u); /* the bits of the float, without breaking aliasing rules */
    put_be32(p, u);
}

static inline void put_be_double(unsigned char *p, double d)
{
    uint64_t u;
    memcpy(&u, &d, sizeof u);
    put_be32(p, (uint32_t)(u >> 32));
    put_be32(p + 4, (uint32_t)u);
}

/* ---------------------------------------------------------------- the closing report */

/* Phase times in seconds, summed over the time-step loop. */
typedef struct {
    double force, reduce, integrate, comm, output, total;
} phases_t;

/* The lines the harness reads (on rank 0 only in the MPI codes). Every line is always printed;
 * a phase the program does not have (reduce outside OpenMP, comm outside MPI) reads 0. */
static inline void print_report(const char *program, long n, long long steps, int threads,
                                int ranks, const phases_t *ph, double e0, double e1)
{
    printf("course-code: %s n=%ld steps=%lld threads=%d ranks=%d\n", program, n, steps, threads,
           ranks);
    printf("phase force %.9f\n", ph->force);
    printf("phase reduce %.9f\n", ph->reduce);
    printf("phase integrate %.9f\n", ph->integrate);
    printf("phase comm %.9f\n", ph->comm);
    printf("phase output %.9f\n", ph->output);
    printf("time total %.9f\n", ph->total);
    printf("energy initial %.10e final %.10e\n", e0, e1);
    fflush(stdout);
}

/* ================================================================ the Lennard-Jones box */

#define LJ_DENSITY 500.0 /* particles per unit area: nbody-bench's LJ_GAS_DENSITY */
#define LJ_RCUT_SIGMAS 2.5 /* cutoff in units of sigma: LJ_CUTOFF */
#define LJ_MAX_N (INT_MAX / 2) /* 2n floats must fit an int (the MPI counts) */

typedef struct {
    const char *out;      /* -o: NBView01 output file, NULL for none */
    long n;               /* -n: particles */
    long frames;          /* -F: frames after the initial one */
    long steps_per_frame; /* -f: steps between frames */
    float dt;             /* -t: time step */
    float eps;            /* -e: LJ well depth epsilon */
    float sigma;          /* -s: LJ length sigma (cutoff 2.5 sigma, minimum initial spacing) */
    float g;              /* -g: downward field strength */
    float T0;             /* -T: initial temperature (velocity variance) */
    unsigned long seed;   /* -r: seed of the initial state */
} lj_params_t;

/* The one place the defaults live; the usage text prints these values, so it cannot drift. */
static inline lj_params_t lj_defaults(void)
{
    lj_params_t p = {
        .out = NULL,
        .n = 500,
        .frames = 200,
        .steps_per_frame = 100,
        .dt = 1e-4f,
        .eps = 1.0f,
        .sigma = 1e-2f,
        .g = 1.0f,
        .T0 = 1.0f,
        .seed = 1,
    };
    return p;
}

static inline void lj_usage(const char *prog, FILE *to)
{
    lj_params_t d = lj_defaults();
    fprintf(to,
            "usage: %s [options]\n"
            "  2-D Lennard-Jones particles in the box [0,L]^2, L = sqrt(n/%g), reflecting walls,\n"
            "  downward gravity; runs F*f time steps.\n"
            "  -h        print this message\n"
            "  -o FILE   write NBView01 binary frames to FILE (default: no output)\n"
            "  -n N      number of particles (%ld)\n"
            "  -F F      number of frames after the initial one (%ld)\n"
            "  -f S      time steps per frame (%ld)\n"
            "  -t DT     time step (%g)\n"
            "  -e EPS    epsilon of the LJ potential (%g)\n"
            "  -s SIG    sigma of the LJ potential, cutoff 2.5 sigma (%g)\n"
            "  -g G      gravitational field strength (%g)\n"
            "  -T T0     initial temperature: velocity components N(0, T0) (%g)\n"
            "  -r SEED   seed of the initial state (%lu)\n",
            prog, LJ_DENSITY, d.n, d.frames, d.steps_per_frame, (double)d.dt, (double)d.eps,
            (double)d.sigma, (double)d.g, (double)d.T0, d.seed);
}

/* Returns 0 to run, 1 after -h, -1 on a bad command line (the message is printed). Only the
 * rank that prints (quiet == 0) says anything, so an MPI run shows each message once. */
static inline int lj_parse(int argc, char **argv, lj_params_t *p, int quiet)
{
    *p = lj_defaults();
    FILE *err = quiet ? NULL : stderr;
    int c;
    long l;
    double d;
    opterr = 0; /* we print our own messages */
    while ((c = getopt(argc, argv, "ho:n:F:f:t:e:s:g:T:r:")) != -1) {
        int bad = 0;
        switch (c) {
        case 'h':
            if (err)
                lj_usage(argv[0], stdout);
            return 1;
        case 'o': p->out = optarg; break;
        case 'n': bad = parse_long(optarg, 1, LJ_MAX_N, &p->n); break;
        case 'F': bad = parse_long(optarg, 1, LONG_MAX, &p->frames); break;
        case 'f': bad = parse_long(optarg, 1, LONG_MAX, &p->steps_per_frame); break;
        case 't': bad = parse_double(optarg, &d) || !(d > 0); if (!bad) p->dt = (float)d; break;
        case 'e': bad = parse_double(optarg, &d) || !(d > 0); if (!bad) p->eps = (float)d; break;
        case 's': bad = parse_double(optarg, &d) || !(d > 0); if (!bad) p->sigma = (float)d; break;
        case 'g': bad = parse_double(optarg, &d); if (!bad) p->g = (float)d; break;
        case 'T': bad = parse_double(optarg, &d) || !(d >= 0); if (!bad) p->T0 = (float)d; break;
        case 'r':
            bad = parse_long(optarg, 0, LONG_MAX, &l);
            if (!bad)
                p->seed = (unsigned long)l;
            break;
        default:
            if (err) {
                fprintf(err, "%s: unknown option or missing value: -%c\n", argv[0], optopt);
                lj_usage(argv[0], err);
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
    if (p->frames > LLONG_MAX / p->steps_per_frame) {
        if (err)
            fprintf(err, "%s: -F times -f is too many steps\n", argv[0]);
        return -1;
    }
    return 0;
}

static inline double lj_box_side(long n)
{
    return sqrt((double)n / LJ_DENSITY);
}

/* The law's constants in the precision of the pair loop. */
typedef struct {
    float eps24, sig2, rc2;
    float half_dt, dt, g, side;
} lj_law_t;

static inline lj_law_t lj_law(const lj_params_t *p)
{
    float rc = (float)LJ_RCUT_SIGMAS * p->sigma;
    lj_law_t law = {
        .eps24 = 24.0f * p->eps,
        .sig2 = p->sigma * p->sigma,
        .rc2 = rc * rc,
        .half_dt = 0.5f * p->dt,
        .dt = p->dt,
        .g = p->g,
        .side = (float)lj_box_side(p->n),
    };
    return law;
}

/* Force coefficient C(r^2): the force on i from j is C * (x_j - x_i), so C < 0 pushes i away.
 * From V = 4 eps (u^2 - u), u = (sigma/r)^6: C = 24 eps u (1 - 2u) / r^2; 0 at and beyond rc
 * (truncated, as in the assignment and physics/lj.rs). Only even powers of r: no square root. */
static inline float lj_coeff(const lj_law_t *law, float r2)
{
    float ir2 = 1.0f / r2;
    float s = law->sig2 * ir2;
    float u = s * s * s;
    float c = law->eps24 * ir2 * u * (1.0f - (u + u));
    return r2 < law->rc2 ? c : 0.0f;
}

/* First half of the step for particle i: half kick, drift, walls. x, v, f are interleaved
 * (x0 y0 x1 y1 ...), unit mass. Returns nonzero when the particle is still outside the box
 * after one reflection (or not a number): the time step is too large, and the run must stop
 * rather than go on with a particle outside the walls (the assignment did not check). */
static inline int lj_kick_drift_reflect(const lj_law_t *law, float *x, float *v, const float *f)
{
    const float ext[2] = {0.0f, -law->g};
    int bad = 0;
    for (int d = 0; d < 2; ++d) {
        v[d] += (f[d] + ext[d]) * law->half_dt;
        float xd = x[d] + v[d] * law->dt;
        if (xd < 0.0f) {
            xd = -xd;
            v[d] = -v[d];
        } else if (xd > law->side) {
            xd = 2.0f * law->side - xd;
            v[d] = -v[d];
        }
        bad |= !(xd >= 0.0f && xd <= law->side);
        x[d] = xd;
    }
    return bad;
}

/* Second half kick with the new forces. */
static inline void lj_kick(const lj_law_t *law, float *v, const float *f)
{
    v[0] += f[0] * law->half_dt;
    v[1] += (f[1] - law->g) * law->half_dt;
}

/* Initial state: positions uniform in [0, L)^2 at least sigma apart, velocities N(0, T0) per
 * component, both from one stream seeded with params->seed. Rejection sampling against a grid
 * of cells of side >= sigma (so only the 3x3 neighbouring cells are checked) keeps it O(n);
 * the assignment's check against every earlier particle is O(n^2). Returns 0, or -1 with a
 * message when the box cannot hold n particles at that spacing (n is never silently lowered:
 * the harness compares runs at the n it asked for). */
static inline int lj_init_state(const lj_params_t *p, float *x, float *v)
{
    const int MAX_TRIALS = 1000;
    const long n = p->n;
    const double side = lj_box_side(n), min_r = p->sigma, min_r2 = min_r * min_r;
    /* At most about one cell per particle: a dilute box would otherwise need a huge grid. */
    long per_side = (long)floor(side / min_r);
    long cap = (long)ceil(sqrt((double)n));
    if (per_side > cap)
        per_side = cap;
    if (per_side < 1)
        per_side = 1;
    const double cell = side / (double)per_side;
    long *head = malloc((size_t)per_side * (size_t)per_side * sizeof *head);
    long *next = malloc((size_t)n * sizeof *next);
    double *px = malloc(2 * (size_t)n * sizeof *px);
    if (!head || !next || !px) {
        fprintf(stderr, "out of memory placing %ld particles\n", n);
        exit(2);
    }
    for (long k = 0; k < per_side * per_side; ++k)
        head[k] = -1;
    rng_t rng = {p->seed};
    long placed = 0;
    for (; placed < n; ++placed) {
        int ok = 0;
        for (int trial = 0; trial < MAX_TRIALS && !ok; ++trial) {
            double cx = rng_uniform(&rng) * side, cy = rng_uniform(&rng) * side;
            long gx = (long)(cx / cell), gy = (long)(cy / cell);
            gx = gx < per_side ? gx : per_side - 1;
            gy = gy < per_side ? gy : per_side - 1;
            ok = 1;
            for (long yy = gy - 1; yy <= gy + 1 && ok; ++yy)
                for (long xx = gx - 1; xx <= gx + 1 && ok; ++xx) {
                    if (xx < 0 || yy < 0 || xx >= per_side || yy >= per_side)
                        continue;
                    for (long j = head[yy * per_side + xx]; j >= 0 && ok; j = next[j]) {
                        double dx = cx - px[2 * j], dy = cy - px[2 * j + 1];
                        ok = dx * dx + dy * dy >= min_r2;
                    }
                }
            if (ok) {
                px[2 * placed] = cx;
                px[2 * placed + 1] = cy;
                next[placed] = head[gy * per_side + gx];
                head[gy * per_side + gx] = placed;
            }
        }
        if (!ok)
            break;
    }
    if (placed < n) {
        fprintf(stderr,
                "could place only %ld of %ld particles at spacing %g in a box of side %g; "
                "lower -n or -s\n",
                placed, n, min_r, side);
        free(head), free(next), free(px);
        return -1;
    }
    for (long i = 0; i < 2 * n; ++i)
        x[i] = (float)px[i];
    /* Box-Muller gives two independent normals: one for vx, one for vy (the assignment wrote
     * both into vx). Standard deviation sqrt(T0), so the variance is T0. */
    const double sd = sqrt((double)p->T0);
    for (long i = 0; i < n; ++i) {
        double r = sd * sqrt(-2.0 * log(1.0 - rng_uniform(&rng))); /* 1 - u > 0: no log(0) */
        double a = 6.283185307179586 * rng_uniform(&rng); /* 2 pi */
        v[2 * i] = (float)(r * cos(a));
        v[2 * i + 1] = (float)(r * sin(a));
    }
    free(head), free(next), free(px);
    return 0;
}

/* Total energy in double: kinetic + LJ shifted by V(rc) (so it is continuous where the force is
 * cut, unlike the assignment's potential_LJ) + g * sum(y). Not timed: called before and after
 * the loop, by one process, so every code measures energy with the same function. */
static inline double lj_energy(const lj_params_t *p, const float *x, const float *v)
{
    const long n = p->n;
    const double sig2 = (double)p->sigma * p->sigma;
    const double rc2 = LJ_RCUT_SIGMAS * LJ_RCUT_SIGMAS * sig2;
    const double uc = pow(sig2 / rc2, 3), shift = uc * (uc - 1.0);
    double kinetic = 0, field = 0, pair = 0;
    for (long i = 0; i < n; ++i) {
        kinetic += 0.5 * ((double)v[2 * i] * v[2 * i] + (double)v[2 * i + 1] * v[2 * i + 1]);
        field += (double)p->g * x[2 * i + 1];
        for (long j = i + 1; j < n; ++j) {
            double dx = (double)x[2 * j] - x[2 * i], dy = (double)x[2 * j + 1] - x[2 * i + 1];
            double r2 = dx * dx + dy * dy;
            if (r2 < rc2) {
                double u = pow(sig2 / r2, 3);
                pair += 4.0 * p->eps * (u * (u - 1.0) - shift);
            }
        }
    }
    return kinetic + pair + field;
}

/* ---------------------------------------------------------------- NBView01 frames */

/* The assignment's binary trajectory: the line "NBView01", then n (uint32) and the view scale
 * (float32, here the box side L so the viewer shows the whole box), then per frame n (x, y)
 * float32 pairs; all numbers big-endian. A frame is converted into one buffer and written with
 * one fwrite, not two fwrites per particle. */
typedef struct {
    FILE *fp;
    unsigned char *buf;
    long n;
} nbview_t;

static inline int nbview_open(nbview_t *w, const char *path, long n, float scale)
{
    w->n = n;
    w->fp = fopen(path, "wb");
    w->buf = malloc(8 * (size_t)n);
    if (!w->fp || !w->buf) {
        fprintf(stderr, "cannot open %s for writing: %s\n", path, strerror(errno));
        return -1;
    }
    unsigned char head[8];
    put_be32(head, (uint32_t)n);
    put_be_float(head + 4, scale);
    if (fputs("NBView01\n", w->fp) == EOF || fwrite(head, 1, 8, w->fp) != 8)
        return -1;
    return 0;
}

static inline int nbview_frame(nbview_t *w, const float *x)
{
    for (long i = 0; i < 2 * w->n; ++i)
        put_be_float(w->buf + 4 * i, x[i]);
    return fwrite(w->buf, 8, (size_t)w->n, w->fp) == (size_t)w->n ? 0 : -1;
}

static inline int nbview_close(nbview_t *w)
{
    int rc = fclose(w->fp);
    free(w->buf);
    return rc;
}

#endif
