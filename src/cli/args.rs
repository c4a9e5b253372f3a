//! Command-line interface: argument definitions only; the work is in `commands`.

use super::values::{
    parse_ab_rounds, parse_count, parse_count_at_most, parse_float, parse_non_negative,
    parse_positive, parse_threads, parse_threshold, parse_timeout, parse_warmup,
};
use clap::{Args, Parser, Subcommand};
use nbody_engine::decomp::Decomposition;
use nbody_engine::export::ExportFormat;
use nbody_engine::kernels::{KernelKind, Multipole};
use nbody_engine::output::nbview::NbviewFormat;
use nbody_engine::scenario::{Precision, ScenarioKind, lj};
use nbody_records::tidy::TidyFormat;
use std::path::PathBuf;

#[derive(Debug, Parser)]
#[command(
    name = "nbody-bench",
    version,
    about = "Characterize the performance of particle (N-body) simulation codes",
    long_about = "Characterize the performance of particle (N-body) simulation codes.\n\n\
        An engine with interchangeable force kernels (naive, symmetric, per-thread, cell-list, \
        octree, verlet, cluster-pair, fmm, fmm-harmonic) over physical scenarios (lj-box, lj-liquid, lj-gas, \
        lj-melt, coulomb, galaxy), with timers, work counters and physics checks.\n\nExit codes: 0 success, 1 validation failed, 2 bad input or a run that failed.",
    after_help = "Examples:\n  nbody-bench list\n  nbody-bench sweep --config configs/quick.toml\n  nbody-bench run --scenario lj-box --kernel cell-list -n 100000 --steps 200\n  nbody-bench validate"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// List kernels, scenarios and which combinations are supported.
    List,
    /// Integrate one scenario with one kernel and report timings, throughput and energy drift.
    Run(RunArgs),
    /// Check every applicable kernel's forces against the naive sum in f64 (exit 1 on a mismatch).
    Validate(ValidateArgs),
    /// Measure every case of a TOML config (n, threads, kernels, scenarios) with statistics and
    /// machine calibration; writes <out>/<name>/results.json after every case (one sweep at a
    /// time per file). Exit 1 when a case has no successful sample (its errors are kept).
    Sweep(SweepArgs),
    /// Fit a scaling model (amdahl, gustafson, power) to a CSV of measurements from any code.
    Fit(FitArgs),
    /// Refit and re-plot a saved sweep: writes fits.json, summary.md and the figures (SVG + PNG).
    Analyze(AnalyzeArgs),
    /// Regenerate REPORT.md from the committed results (every number and figure from a results
    /// file); hand-written text between `<!-- keep:NAME -->` markers is kept.
    Report(ReportArgs),
    /// Compare a sweep's results with a baseline, case by case; exit 1 if a case got slower
    /// beyond the threshold (held across all the cases judged), 2 for bad input.
    Gate(GateArgs),
    /// Measure the gate's false-alarm rate and power on this machine: many gate decisions on
    /// unchanged code and with one kernel slowed by 5, 10 and 25% (needs the `test-slowdown`
    /// feature); writes results/gate-study/<machine class>.json.
    GateStudy(GateStudyArgs),
    /// Measure MPI ping-pong and Allgatherv times over message sizes, for the latency-bandwidth
    /// model (needs the `mpi` feature; run under `mpirun -n 2` or more).
    MpiBench(MpiBenchArgs),
    /// Run a scenario over MPI ranks and compare the final state with a serial run of the same
    /// kernel: same particles, same positions and velocities to rounding (exit 1 if not; needs
    /// the `mpi` feature; run under mpirun).
    MpiCheck(MpiCheckArgs),
    /// Write a scenario's initial state for another code: a LAMMPS data file (reduced units),
    /// or a text / .npy table of positions, velocities, masses and strengths.
    Export(ExportArgs),
    /// Write a results file as a tidy table for notebooks (pandas, polars, R): one row per
    /// sample, each case field, round value and build field a column of its own; CSV or JSON
    /// lines.
    ExportResults(ExportResultsArgs),
    /// Write a commented sweep config for your own program, every key explained (NAME.toml;
    /// with `--lang python` also NAME.py, a driver to put your code in): edit it, then
    /// `nbody-bench sweep --config NAME.toml`.
    Init(InitArgs),
    /// The performance history of a machine class: each case's series over the commits, with
    /// the steps found in it; `history record RESULTS` appends a sweep's results to it.
    History(crate::cli::history::HistoryArgs),
    /// Name the commit between GOOD (fast) and BAD (slow) that made a case slower (with
    /// `--faster`, faster): midpoints built (cached) and measured side by side with both ends,
    /// judged as the gate judges; warns instead of guessing when the series is not monotone
    /// between the ends.
    Bisect(crate::cli::bisect::BisectArgs),
    /// The performance history as one self-contained HTML page (every case's series per
    /// machine class, the steps found, the latest gate verdicts), or with `--markdown` a
    /// summary of the changes since a base commit for a pull-request comment.
    Publish(crate::cli::publish::PublishArgs),
    /// Print a generated page of docs/reference/ (Markdown): the help of every subcommand, or
    /// every key of a sweep config.
    #[command(hide = true)]
    Reference(ReferenceArgs),
    /// Inside a batch job submitted by a sweep with a `[scheduler]`: do the work the sweep wrote
    /// into DIR (one case round, or a calibration) and write DIR/result.json.
    #[command(hide = true)]
    Job(JobArgs),
}

#[derive(Debug, Args)]
#[command(
    after_help = "Examples:\n  nbody-bench init --external mycode                # mycode.toml, for mycode.c\n  \
    nbody-bench init --external mysim --lang python   # mysim.toml and the driver mysim.py\n  \
    nbody-bench init --external mymd --lang python --physics lj   # a periodic Lennard-Jones driver"
)]
pub struct InitArgs {
    /// Your program's name: the name of its cases and of the config file.
    #[arg(long, value_name = "NAME")]
    pub external: String,
    /// The language of the program, which sets how the config builds and runs it.
    #[arg(long, value_enum, default_value_t = InitLang::C)]
    pub lang: InitLang,
    /// The physics of the Python driver and of the config's scenario (with `--lang python`).
    #[arg(long, value_enum, default_value_t = InitPhysics::Gravity)]
    pub physics: InitPhysics,
    /// Write the config here [default: NAME.toml in the current directory]; an existing file
    /// is never replaced. With `--lang python` the driver NAME.py is written beside it.
    #[arg(long, value_name = "FILE")]
    pub out: Option<std::path::PathBuf>,
}

/// The language an `init` template is written for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum InitLang {
    /// A C program with OpenMP, compiled by `setup` (cc -fopenmp) from NAME.c beside the config.
    C,
    /// A Python program run by python3: also writes NAME.py, a standard-library direct-summation
    /// driver that prints its time, where your code's calls go (REBOUND's, for example).
    Python,
}

/// The physics an `init --lang python` driver simulates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum InitPhysics {
    /// Direct-summation gravity on the `galaxy` scenario's bodies (`export --format text`).
    Gravity,
    /// Lennard-Jones molecular dynamics in a periodic box on the `lj-melt` scenario's atoms
    /// (`export --format lammps-data`), passed the sweep's thread count.
    Lj,
}

#[derive(Debug, Args)]
pub struct JobArgs {
    /// The job's directory (under the sweep's results, `jobs/...`).
    pub dir: std::path::PathBuf,
}

#[derive(Debug, Args)]
pub struct ReferenceArgs {
    /// The page to print.
    #[arg(value_enum)]
    pub page: ReferencePage,
}

/// A generated reference page.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ReferencePage {
    /// docs/reference/cli.md: every subcommand's help.
    Cli,
    /// docs/reference/config.md: every key of a sweep config.
    Config,
}

#[derive(Debug, Args)]
pub struct ReportArgs {
    /// Directory with one sub-directory per sweep, each holding results.json.
    #[arg(long, value_name = "DIR", default_value = "results")]
    pub results: PathBuf,
    /// The report to write (its kept regions are carried over).
    #[arg(long, value_name = "FILE", default_value = "REPORT.md")]
    pub out: PathBuf,
}

#[derive(Debug, Args)]
pub struct AnalyzeArgs {
    /// The results of a sweep: a results.json, a run directory, or a config name (its latest
    /// run under results/runs/ with a successful case, else its reference results
    /// results/<name>/; the run taken is named).
    #[arg(value_name = "RESULTS")]
    pub results: PathBuf,
    /// Directory for fits.json, summary.md and the figures [default: `analysis/` beside the results file].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

/// Options that define the simulated system.
#[derive(Debug, Args, Clone)]
pub struct SystemArgs {
    /// Number of particles [default: the scenario's, see `list`].
    #[arg(short = 'n', long = "n", value_parser = parse_count)]
    pub n: Option<usize>,
    /// Seed of the initial state; the same seed gives the same state for every kernel and thread count.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Time step [default: the scenario's].
    #[arg(long, value_parser = parse_positive, allow_hyphen_values = true)]
    pub dt: Option<f64>,
    /// Particles per unit area (per unit volume for lj-melt): the box side becomes (n / density)^(1/D).
    #[arg(long, value_parser = parse_positive, allow_hyphen_values = true)]
    pub density: Option<f64>,
    /// Floating-point precision [default: the scenario's: f32 for LJ, f64 otherwise].
    #[arg(long, value_enum)]
    pub precision: Option<Precision>,
    /// Run with fewer particles when the box cannot hold n at the minimum spacing.
    #[arg(long)]
    pub allow_fewer: bool,
}

/// Where a run starts: bodies from a file, and the Lennard-Jones parameters.
#[derive(Debug, Args, Clone)]
pub struct StartArgs {
    /// Start from the bodies in FILE instead of the scenario's placement (the file sets n; the
    /// law, box and field stay the scenario's): `nbody-bench export --format text` output, or a
    /// Barnes-Hut body file, one body per line `m x y z vx vy vz` with `#` comments (3-D
    /// scenarios but coulomb, which needs charges).
    #[arg(long, value_name = "FILE")]
    pub initial: Option<PathBuf>,
    #[command(flatten)]
    pub lj: LjArgs,
}

const LJ_HEADING: &str = "Lennard-Jones (lj-box, lj-liquid, lj-gas, lj-melt)";

/// The Lennard-Jones parameters; their help shows the scenario's own constants.
#[derive(Debug, Args, Clone)]
pub struct LjArgs {
    #[arg(long, value_parser = parse_positive, allow_hyphen_values = true, help_heading = LJ_HEADING, help = lj_help(
        "Well depth epsilon",
        format!("{}", lj::LJ_EPSILON),
    ))]
    pub epsilon: Option<f64>,
    #[arg(long, value_parser = parse_positive, allow_hyphen_values = true, help_heading = LJ_HEADING, help = lj_help(
        "Particle size sigma: the cutoff is 2.5 sigma, generated particles are at least sigma \
         apart, and lj-liquid's default density follows it (reduced density 0.8)",
        format!("{}", lj::LJ_SIGMA),
    ))]
    pub sigma: Option<f64>,
    #[arg(long = "g", value_parser = parse_float, allow_hyphen_values = true, help_heading = LJ_HEADING, help = lj_help(
        "Downward acceleration of the external field (negative: upward)",
        format!("{} for lj-box, 0 for the others", lj::LJ_GRAVITY),
    ))]
    pub g: Option<f64>,
    #[arg(long, value_parser = parse_non_negative, allow_hyphen_values = true, help_heading = LJ_HEADING, help = lj_help(
        "Initial temperature: velocity components are drawn from N(0, sqrt(T0)); not with \
         --initial, whose bodies carry their velocities",
        format!(
            "{}, {} for lj-melt",
            lj::LJ_T0,
            nbody_engine::scenario::melt::MELT_T0
        ),
    ))]
    pub t0: Option<f64>,
}

/// The help of a Lennard-Jones option, with the default the scenario uses.
fn lj_help(what: &str, default: String) -> String {
    format!("{what} [default: {default}]")
}

impl LjArgs {
    pub fn overrides(&self) -> nbody_engine::scenario::LjOverrides {
        nbody_engine::scenario::LjOverrides {
            epsilon: self.epsilon,
            sigma: self.sigma,
            g: self.g,
            t0: self.t0,
        }
    }
}

/// Kernel tuning options.
#[derive(Debug, Args, Clone)]
pub struct KernelArgs {
    /// Opening angle (octree and fmm): the octree uses a node of side s at distance d whole
    /// when s/d < theta; the fmm lets two cells of radii r1, r2 at distance d interact through
    /// their expansions when r1 + r2 < theta d (fmm: below 1) [default: 0.5].
    #[arg(long, value_parser = parse_non_negative, allow_hyphen_values = true)]
    pub theta: Option<f64>,
    /// Expansion order of the tree nodes the octree accepts (octree only) [default: quadrupole].
    #[arg(long, value_enum)]
    pub multipole: Option<Multipole>,
    /// Expansion order p of the fmm's cells, 1 to 8 for the fmm, 1 to 20 for fmm-harmonic:
    /// the force error falls as theta^p [default: 4].
    #[arg(long, value_parser = parse_count_at_most::<{ nbody_engine::kernels::MAX_FMM_HARMONIC_ORDER }>)]
    pub order: Option<usize>,
    /// Most particles in a tree leaf (octree and fmm) [default: 8 for the octree, 64 for
    /// the fmm].
    #[arg(long, value_parser = parse_count)]
    pub leaf_size: Option<usize>,
    /// Verlet list skin, in the scenario's length unit (verlet and cluster-pair only): pairs
    /// within the cutoff plus the skin are listed, and the list is rebuilt once a particle has
    /// moved half the skin [default: 0.003, 0.3 sigma]. `auto` (run only): the default and up
    /// to six times it are timed on this system and these threads first, and the fastest is
    /// used and reported.
    #[arg(long, value_parser = parse_skin, allow_hyphen_values = true)]
    pub skin: Option<SkinArg>,
    /// Threads in the rayon pool for this run, at most 1024 (the environment's
    /// RAYON_NUM_THREADS is not used).
    #[arg(long, default_value_t = 1, value_parser = parse_threads)]
    pub threads: usize,
}

#[derive(Debug, Args)]
pub struct RunArgs {
    /// Scenario to simulate.
    #[arg(long, value_enum)]
    pub scenario: ScenarioKind,
    /// Force kernel.
    #[arg(long, value_enum)]
    pub kernel: KernelKind,
    /// Time steps to integrate.
    #[arg(long, default_value_t = 100, value_parser = parse_count)]
    pub steps: usize,
    #[command(flatten)]
    pub system: SystemArgs,
    #[command(flatten)]
    pub start: StartArgs,
    #[command(flatten)]
    pub kernel_args: KernelArgs,
    /// Write a machine-readable result (schema nbody-bench/run/v1) to this file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Write an NBView trajectory (x, y; 3-D scenarios projected) to this file.
    #[arg(long, value_name = "FILE")]
    pub trajectory: Option<PathBuf>,
    /// Trajectory format.
    #[arg(
        long,
        value_enum,
        default_value = "nbview-bin",
        requires = "trajectory"
    )]
    pub format: NbviewFormat,
    /// Write a trajectory frame every K steps.
    #[arg(long, default_value_t = 10, value_parser = parse_count, requires = "trajectory")]
    pub every: usize,
    /// Write the final positions, velocities, masses, strengths and forces, with the law's
    /// parameters in the header (text, id order, nothing run-dependent).
    #[arg(long, value_name = "FILE")]
    pub dump_state: Option<PathBuf>,
    /// Start a run estimated at more than an hour (a probe at small n carried to -n, --steps
    /// and --threads) instead of refusing it.
    #[arg(long)]
    pub yes: bool,
    /// Split the run over MPI ranks (start it under `mpirun -n P`): allgather (replicated data,
    /// any kernel), domain (spatial regions; cell-list or verlet), octants (the source's
    /// distributed octree) or tree (locally essential trees over a balanced bisection); the
    /// last two with the octree. Needs the `mpi` feature.
    #[arg(long, value_enum, help_heading = MPI_HEADING)]
    pub decomp: Option<Decomposition>,
    #[command(flatten)]
    pub mpi: MpiOptions,
}

const MPI_HEADING: &str = "MPI (build with --features mpi, start under mpirun)";

/// Options of distributed runs.
#[derive(Debug, Args, Clone)]
#[command(next_help_heading = MPI_HEADING)]
pub struct MpiOptions {
    /// Untimed steps before the timed ones.
    #[arg(long, default_value_t = 0, value_parser = parse_warmup, requires = "decomp")]
    pub warmup_steps: usize,
    /// Regions per axis of the domain decomposition, e.g. 4x1 (slabs) or 2x2 (blocks)
    /// [default: the factorization with the least cut area].
    #[arg(long, value_name = "AxB[xC]", requires = "decomp")]
    pub rank_grid: Option<String>,
    /// Move the domain boundaries when the busiest rank owns more than this times the mean
    /// particle count (domain), or spent more than this times the mean force time in the last
    /// step (tree; octants never moves them).
    #[arg(long, default_value_t = 1.1, value_parser = parse_positive, requires = "decomp")]
    pub rebalance_above: f64,
    /// Keep the domain boundaries fixed: equal regions, never rebalanced.
    #[arg(long, requires = "decomp")]
    pub no_rebalance: bool,
}

#[derive(Debug, Args)]
pub struct MpiCheckArgs {
    /// Scenario to simulate.
    #[arg(long, value_enum)]
    pub scenario: ScenarioKind,
    /// Force kernel (the same for the MPI and the serial run).
    #[arg(long, value_enum)]
    pub kernel: KernelKind,
    /// Decomposition to check.
    #[arg(long, value_enum)]
    pub decomp: Decomposition,
    /// Time steps to integrate (a check: at most 1000000).
    #[arg(long, default_value_t = 20, value_parser = parse_count_at_most::<1_000_000>)]
    pub steps: usize,
    #[command(flatten)]
    pub system: SystemArgs,
    #[command(flatten)]
    pub kernel_args: KernelArgs,
    #[command(flatten)]
    pub mpi: MpiOptions,
    /// Largest difference allowed, relative to the box size (positions) and the largest speed
    /// (velocities) [default: 1e-9 in f64, 1e-4 in f32].
    #[arg(long, value_parser = parse_positive)]
    pub tolerance: Option<f64>,
    /// Also fail unless some particle changed rank during the run.
    #[arg(long)]
    pub expect_migration: bool,
    /// Also fail unless some particle moved beyond the neighbouring regions in one step.
    #[arg(long)]
    pub expect_far_migration: bool,
    /// Also fail unless some rank owns no particle at the end.
    #[arg(long)]
    pub expect_empty_rank: bool,
    /// Also fail unless the domain boundaries moved to rebalance the load during the run.
    #[arg(long)]
    pub expect_rebalance: bool,
}

#[derive(Debug, Args)]
pub struct MpiBenchArgs {
    /// Where to write the timings (JSON, schema nbody-bench/mpi-bench/v1).
    #[arg(long, value_name = "FILE", default_value = "mpi-bench.json")]
    pub out: PathBuf,
    /// Largest message in bytes (per rank for Allgatherv), at most 1 GiB; sizes are 1, 4,
    /// 16, ... up to it.
    #[arg(long, default_value_t = 4 << 20, value_parser = parse_count_at_most::<{ 1 << 30 }>)]
    pub max_bytes: usize,
    /// Timed repetitions per size up to 64 KiB (fewer above, in proportion, at least 10), at
    /// most 1000000.
    #[arg(long, default_value_t = 100, value_parser = parse_count_at_most::<1_000_000>)]
    pub reps: usize,
    /// Untimed repetitions before each size, at most 1000000.
    #[arg(long, default_value_t = 5, value_parser = parse_warmup)]
    pub warmup: usize,
}

#[derive(Debug, Args)]
pub struct ValidateArgs {
    /// Scenario to check [default: all].
    #[arg(long, value_enum)]
    pub scenario: Option<ScenarioKind>,
    #[command(flatten)]
    pub system: SystemArgs,
    #[command(flatten)]
    pub kernel_args: KernelArgs,
    /// Write positions, strengths, reference forces and every kernel's forces, with the law's
    /// parameters in the header (text) to this file;
    /// with several scenarios, one file per scenario named FILE.<scenario>.
    #[arg(long, value_name = "FILE")]
    pub dump: Option<PathBuf>,
    /// Print the result as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Check a system estimated at more than an hour (the direct sums grow as n²) instead of
    /// refusing it.
    #[arg(long)]
    pub yes: bool,
}

/// A Verlet skin: a length, or `auto`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SkinArg {
    Auto,
    Length(f64),
}

fn parse_skin(s: &str) -> Result<SkinArg, String> {
    if s == "auto" {
        return Ok(SkinArg::Auto);
    }
    parse_positive(s)
        .map(SkinArg::Length)
        .map_err(|e| format!("{e}; or `auto`"))
}

#[derive(Debug, Args)]
pub struct SweepArgs {
    /// The sweep config: a path (a file or a pipe such as `<(...)`, whose {config_dir} is the
    /// current directory), or a name looked up in configs/ (`strong`, `strong.toml`).
    #[arg(long, value_name = "FILE|NAME")]
    pub config: PathBuf,
    /// Continue an interrupted sweep: cases already measured are kept and not repeated. Without
    /// a value, the latest unfinished run of the config (or, with --out, DIR/<name>/); with
    /// one, that run directory or results.json.
    #[arg(long, value_name = "RUN", num_args = 0..=1, conflicts_with = "fresh")]
    pub resume: Option<Option<PathBuf>>,
    /// With --resume: accept a results file from a different config or commit.
    #[arg(long, requires = "resume")]
    pub force: bool,
    /// Start over; an existing results file is kept under a new .bak name, never replacing
    /// an earlier backup (with --out; a run without --out always starts in a new run
    /// directory).
    #[arg(long)]
    pub fresh: bool,
    /// Write to DIR/<name>/results.json (the layout of the committed reference results)
    /// instead of a new run directory <out>/runs/<name>/<UTC time>/ (<out> is the config's
    /// `out`, default `results`).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Skip the machine calibration at the start and end (faster; speedups then have no ceiling).
    #[arg(long)]
    pub no_calibration: bool,
    /// Print the planned cases and the estimated wall time (from a short probe of each kernel),
    /// then exit without measuring or writing anything.
    #[arg(long)]
    pub dry_run: bool,
    /// Start a sweep estimated at more than an hour without asking; without a terminal (CI)
    /// such a sweep needs this flag or a `measure.budget_s`.
    #[arg(long)]
    pub yes: bool,
    /// Append the measured cases to the performance history of this machine class,
    /// DIR/<class>.jsonl (default results/history); `nbody-bench history` shows the series.
    #[arg(long, value_name = "DIR", num_args = 0..=1, default_missing_value = "results/history")]
    pub record: Option<PathBuf>,
}

/// A scaling model the `fit` command fits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum FitModel {
    /// Strong scaling, CSV `p,time`: speedup, efficiency, Amdahl's serial fraction, Karp-Flatt.
    Amdahl,
    /// Weak scaling, CSV `p,time` or `p,n,time`: efficiency and Gustafson's serial fraction.
    Gustafson,
    /// Complexity in n, CSV `n,time`: T = c*n^k and the complexity class.
    Power,
}

/// The cost g(n) of a whole problem of size n, for weak scaling with an n column.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum CostModel {
    #[value(name = "n")]
    N,
    #[value(name = "n-log-n")]
    NLogN,
    #[value(name = "n1.5")]
    NSqrtN,
    #[value(name = "n2")]
    N2,
    #[value(name = "n2-log-n")]
    N2LogN,
    #[value(name = "n3")]
    N3,
}

#[derive(Debug, Args)]
#[command(
    after_help = "CSV: a header naming the columns (any order, case-insensitive), one row per \
    measured sample, several rows per p or n; times in seconds.\n\nExamples:\n  \
    nbody-bench fit --model amdahl --csv strong.csv\n  \
    nbody-bench fit --model power --csv sizes.csv --json fit.json"
)]
pub struct FitArgs {
    /// The model to fit.
    #[arg(long, value_enum)]
    pub model: FitModel,
    /// The measurements: `p,time` (amdahl), `p,time` or `p,n,time` (gustafson), `n,time` (power).
    /// A file or a pipe; a pipe silent for 60 s (NBODY_BENCH_PIPE_WAIT_S) is given up.
    #[arg(long, value_name = "FILE")]
    pub csv: PathBuf,
    /// Also write the fit as JSON (schema nbody-bench/fit/v1): every parameter as
    /// {"estimate", "ci95": [lo, hi]}.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Seed of the bootstrap that gives the confidence intervals (fixed by default, so the
    /// output is reproducible).
    #[arg(long, default_value_t = nbody_harness::fit::DEFAULT_SEED)]
    pub seed: u64,
    /// gustafson with an n column: the cost g(n) of the whole problem; times are normalised to
    /// the one-worker run's work per worker g(n)/p [default: n].
    #[arg(long, value_enum)]
    pub cost: Option<CostModel>,
}

#[derive(Debug, Args)]
#[command(
    long_about = "Compare this build's timings with a baseline, case by case; exit 1 if a case got \
        slower beyond the threshold (at a family-wise error of 2.5% over all the cases judged, \
        Holm's step-down on one-sided t p-values), 2 for bad input or a comparison that cannot \
        be made. Each case is regressed, improved, unchanged (its 90% interval within twice the \
        threshold) or unknown (neither: named in the report, with how to measure more; not a \
        failure).\n\n\
        The baseline is a results file or a folder of them, one per machine class (CPU model, \
        CPU signature, logical CPUs): from a folder the gate takes the file of the class it \
        compares with, else the newest.\n\n\
        Three ways:\n\
        - with --current: compare two results files (they must come from one machine class);\n\
        - without --current: the gate sweeps the config stored in the baseline (every key as \
        it was resolved when measured) with this build; if the baseline comes from this \
        machine class and this build reproduces it, it is compared with the baseline file (the \
        fast path), else (another class, or a stale baseline: the gate says why) the gate builds the baseline's revision (a git worktree, cached in \
        target/gate-base/) and measures both builds here, interleaved case by case (A/B): each \
        round of a case gives one paired log-ratio of the two builds, and the cases a first \
        look of --rounds rounds leaves undecided get --rounds more at a time, up to \
        --max-rounds;\n\
        - with --against REV: always A/B against REV.\n\n\
        --save-baseline RESULTS files a sweep of the baseline's config as this machine class's \
        baseline (scripts/refresh-baseline.sh does it from a fresh sweep). A baseline never \
        absorbs a regression silently: if the class has one, this build is first measured A/B \
        against its commit, and the save is refused (exit 1) while a case regressed that \
        --accept CASE... --reason TEXT does not name.",
    after_help = "Examples:\n  nbody-bench gate                       # CI: judge this build on any machine\n  \
    nbody-bench gate --against origin/main  # a pull request against its base\n  \
    nbody-bench gate --baseline results/baseline --current ci --format markdown\n  \
    nbody-bench gate --save-baseline ci     # the latest ci sweep becomes this machine's baseline\n  \
    nbody-bench gate --save-baseline ci --accept lj-box/symmetric/n=2000/p=1/r=1/seed=1 \\\n      \
    --reason \"exact pair forces now\"   # a save that keeps an intended slowdown"
)]
pub struct GateArgs {
    /// The reference run: a results file, or a folder of baselines, one per machine class
    /// (the gate takes the one of this machine's class, else A/B against the newest one's
    /// commit).
    #[arg(long, value_name = "FILE|DIR", default_value = "results/baseline")]
    pub baseline: PathBuf,
    /// Keep RESULTS (a results.json, a run directory or a config name) in the --baseline folder
    /// as the baseline of the machine class it was measured on. Refused when other processes
    /// used 0.25 CPUs or more while it was calibrated: a baseline must come from a quiet
    /// machine. When that class already has a baseline, this build and the commit that
    /// baseline records are first measured side by side (A/B, on RESULTS' config, judged as
    /// any A/B gate run: --rounds, --threshold, --out apply), and a case that regressed
    /// refuses the save (exit 1, the old file untouched) unless named with --accept.
    #[arg(long, value_name = "RESULTS", conflicts_with_all = ["current", "against", "config"])]
    pub save_baseline: Option<PathBuf>,
    /// With --save-baseline: let these regressed cases (keys as the gate prints them) into the
    /// new baseline; needs --reason. Every case that regressed must be named, and only those:
    /// a key that is no case of RESULTS, or did not regress, is an error (exit 2). The
    /// acceptance (cases, ratios, reason, both commits, machine class, time) is appended to
    /// the history's gate verdicts, DIR/<class>.gate.jsonl of --record (default
    /// results/history).
    #[arg(long, value_name = "CASE", num_args = 1.., requires = "save_baseline")]
    pub accept: Vec<String>,
    /// Why the slowdown of the --accept cases is intended, kept with them in the history.
    #[arg(long, value_name = "TEXT", requires = "accept")]
    pub reason: Option<String>,
    /// Results of the run to check: a results.json, a run directory or a config name (its
    /// latest run with a successful case). Without it the gate measures this build itself.
    #[arg(long, value_name = "RESULTS")]
    pub current: Option<PathBuf>,
    /// Measure this build and revision REV side by side (A/B), whatever machine the baseline
    /// comes from [default base when A/B is needed: the commit recorded in the baseline].
    #[arg(long, value_name = "REV", conflicts_with = "current")]
    pub against: Option<String>,
    /// The config to measure when the gate measures [default: the baseline's own config].
    #[arg(long, value_name = "FILE|NAME", conflicts_with = "current")]
    pub config: Option<PathBuf>,
    /// Rounds of every case per build in an A/B run's first look: even (each build goes first
    /// as often), from 2 to 100.
    #[arg(long, default_value_t = nbody_harness::gate::AB_ROUNDS, value_parser = parse_ab_rounds, conflicts_with = "current")]
    pub rounds: usize,
    /// Most rounds per build a case still undecided after the first look is measured to, in
    /// looks of --rounds more each (at least --rounds; equal to it judges once). The run's
    /// family-wise error is split evenly over its looks.
    #[arg(long, default_value_t = nbody_harness::gate::AB_MAX_ROUNDS, value_parser = parse_ab_rounds, conflicts_with = "current")]
    pub max_rounds: usize,
    /// How an A/B run's two builds share the machine in a round: `duet` runs both at the same
    /// moment, each pinned to a CPU of its own, the CPUs swapped every round (what the machine
    /// does meanwhile falls on both); `turns` runs one after the other. Cases of several
    /// threads or ranks, and external programs, always take turns. [default: duet, unless this
    /// process may use one CPU only or other processes kept a CPU busy while the gate
    /// calibrated; A/B runs only]
    #[arg(long, value_enum, conflicts_with = "current")]
    pub sides: Option<nbody_harness::gate::duet::Sides>,
    /// Longest one build's sweep of one case may take in an A/B run, seconds (also the limit
    /// of asking the base binary for its options) [default: 10 times the case's estimate, at
    /// least 120 s]; a child past its limit is stopped and the gate exits 2. The base build has
    /// a limit of its own, an hour.
    #[arg(long, value_name = "SECONDS", value_parser = parse_timeout, conflicts_with = "current")]
    pub timeout: Option<f64>,
    /// Where a measuring gate keeps what it measured [default: results/runs/gate/<UTC time>/].
    #[arg(long, value_name = "DIR", conflicts_with = "current")]
    pub out: Option<PathBuf>,
    /// Relative slowdown a case must exceed to count as a regression (0.02 = 2%), at a
    /// family-wise error of 2.5% over all the cases judged (Holm); the same margin below 1
    /// counts as an improvement [default: 0.02 for A/B runs, 0.10 when the gate compares with
    /// a baseline file measured at another time (the fast path, and two files), chosen from
    /// the gate's noise study, docs/explanation/gate.md]; at most 1 (a doubling).
    #[arg(long, value_parser = parse_threshold, allow_hyphen_values = true)]
    pub threshold: Option<f64>,
    /// Output format; markdown is made for a CI job summary.
    #[arg(long, value_enum, default_value = "text")]
    pub format: nbody_harness::gate::Format,
    /// What the times are divided by before comparing: the reference workload timed around each
    /// case, the sweep's calibration, or nothing; auto takes the best both files have.
    #[arg(long, value_enum, default_value = "auto")]
    pub normalize: nbody_harness::gate::NormalizationChoice,
    /// Which ratio a case is judged on: the normalised one, the raw one, or both (a change is
    /// claimed only when both show it) [default: raw for A/B runs, where measuring side by side
    /// keeps raw times fair; both for the fast path and two files, measured at different times:
    /// the rules the gate's noise study chose, docs/explanation/gate.md].
    #[arg(long, value_enum)]
    pub judge: Option<nbody_harness::gate::Judged>,
    /// Compare results from another machine (CPU model, logical CPUs), build or config anyway.
    #[arg(long)]
    pub force: bool,
    /// Also fail (exit 1) when a deterministic work counter changed; a case whose counters
    /// cannot be compared (a file without them) is then an error (exit 2), not a pass.
    #[arg(long)]
    pub fail_on_work_change: bool,
    /// Append what the gate measured (this build, and the baseline's revision in an A/B run) to
    /// the performance history of this machine class, DIR/<class>.jsonl (default
    /// results/history), and the run's verdicts to DIR/<class>.gate.jsonl.
    #[arg(long, value_name = "DIR", num_args = 0..=1, default_missing_value = "results/history")]
    pub record: Option<PathBuf>,
}

#[derive(Debug, Args)]
#[command(
    long_about = "Measure the gate's false-alarm rate and power on this machine.\n\n\
        One long interleaved run is cut into disjoint blocks. Each block measures every case \
        of the gate's config (this machine class's baseline's) as two sides of the same code, A \
        and B, and the slowed kernel's cases at 5, 10 and 25% slower (the test-only knob), \
        each for the rounds and samples one gate decision takes. Every block gives an A/B \
        decision (A against B) and a fast-path decision (B against the committed baseline), on \
        unchanged code and at each slowdown, judged under each rule and candidate threshold. \
        The summary goes to results/gate-study/<machine class>.json (a run of the same load and \
        mode replaces the earlier one), the raw measurements to \
        results/runs/gate-study/<UTC time>/raw.json. Run it on a quiet machine, under the lock \
        the gate uses (flock /tmp/nbody-bench.lock).",
    after_help = "Examples:\n  cargo build --release --features test-slowdown\n  \
    flock /tmp/nbody-bench.lock target/release/nbody-bench gate-study --blocks 125\n  \
    flock /tmp/nbody-bench.lock target/release/nbody-bench gate-study --load spin --blocks 50\n  \
    flock /tmp/nbody-bench.lock target/release/nbody-bench gate-study --duet --blocks 30\n  \
    nbody-bench gate-study --docs     # docs/explanation/gate.md's tables from the study files"
)]
pub struct GateStudyArgs {
    /// Blocks to measure: one decision per mode and slowdown each.
    #[arg(long, default_value_t = 120, value_parser = clap::value_parser!(u64).range(1..=10_000))]
    pub blocks: u64,
    /// What else runs meanwhile: nothing, or a process spinning on one CPU.
    #[arg(long, value_enum, default_value = "quiet")]
    pub load: nbody_harness::gate::study::Load,
    /// Measure the two sides of each pair a decision compares at the same moment, one per CPU
    /// (as the A/B gate's `--sides duet`).
    #[arg(long)]
    pub duet: bool,
    /// The kernel made slower for the power decisions.
    #[arg(long, value_enum, default_value = "octree")]
    pub slow: nbody_engine::kernels::KernelKind,
    /// The folder of baselines: this machine class's file gives the config and the fast
    /// path's reference.
    #[arg(long, value_name = "DIR", default_value = "results/baseline")]
    pub baseline: PathBuf,
    /// Study this config instead (A/B decisions only, unless it is the baseline's).
    #[arg(long, value_name = "FILE|NAME")]
    pub config: Option<PathBuf>,
    /// Folder of the study files.
    #[arg(long, value_name = "DIR", default_value = "results/gate-study")]
    pub out: PathBuf,
    /// Measure nothing: rewrite the generated tables of docs/explanation/gate.md from the
    /// study files of --out.
    #[arg(long, conflicts_with_all = ["duet", "config", "from"])]
    pub docs: bool,
    /// Measure nothing: summarise this raw file of an earlier run
    /// (results/runs/gate-study/<UTC time>/raw.json) into its class's study file again.
    #[arg(long, value_name = "RAW", conflicts_with_all = ["duet", "config"])]
    pub from: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub struct ExportArgs {
    /// Scenario whose initial state is written.
    #[arg(long, value_enum)]
    pub scenario: ScenarioKind,
    #[command(flatten)]
    pub system: SystemArgs,
    #[command(flatten)]
    pub start: StartArgs,
    /// lammps-data: a LAMMPS data file in LJ reduced units (atom style atomic, the walls as the
    /// box; Lennard-Jones scenarios only); text: positions, velocities, mass and strength per
    /// particle with the law's parameters in the header; npy: the same columns as float64.
    #[arg(long, value_enum)]
    pub format: ExportFormat,
    /// The file to write (atomically).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
}

#[derive(Debug, Args)]
#[command(
    after_long_help = export_results_help(),
    after_help = "Examples:\n  nbody-bench export-results quick > quick.csv\n  \
    nbody-bench export-results results/quick/results.json --format jsonl --out quick.jsonl\n  \
    nbody-bench export-results results/history > history.csv"
)]
pub struct ExportResultsArgs {
    /// The results of a sweep (a results.json, a run directory, or a config name: its latest
    /// run under results/runs/ with a successful case, else its reference results
    /// results/<name>/), or a performance
    /// history (a history file, or the folder of them: every machine class).
    #[arg(value_name = "RESULTS|HISTORY")]
    pub results: PathBuf,
    /// The table's format.
    #[arg(long, value_enum, default_value = "csv")]
    pub format: TidyFormat,
    /// Write the table to FILE (atomically) instead of standard output; never an input
    /// file itself, nor a file that holds history records.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
}

/// `export-results --help`: the columns, from the list the table is built with.
fn export_results_help() -> String {
    let mut help = String::from(
        "Columns, one row per sample, in this order (an empty CSV cell or JSON null: not \
         measured, never 0; the build's fields repeat on every row, so the tables of several \
         sweeps can be concatenated):\n",
    );
    for (name, what) in nbody_records::tidy::SAMPLE_COLUMNS {
        help.push_str(&format!("  {name:<19} {what}\n"));
    }
    help.push_str(
        "\nColumns of a history, one row per record (the case's fields taken from its key):\n",
    );
    for (name, what) in nbody_harness::history::tidy::HISTORY_COLUMNS {
        help.push_str(&format!("  {name:<22} {what}\n"));
    }
    help.push_str(
        "\npandas: pd.read_csv(FILE, float_precision=\"round_trip\") reads every number back \
         to the bits written; pd.read_json(FILE, lines=True, precise_float=True) the JSON \
         lines.\n\nExamples:\n  nbody-bench export-results quick > quick.csv\n  \
         nbody-bench export-results results/quick/results.json --format jsonl --out quick.jsonl\n  \
         nbody-bench export-results results/history > history.csv",
    );
    help
}
