//! `reference` (hidden): prints the generated pages of `docs/reference/`, so that they come from
//! the code and cannot drift from it. `cli` renders the help of every subcommand from the clap
//! definitions in [`args`](crate::cli::args); `config` lists every key of a sweep config, with
//! its default found by parsing a config without it and its forms from
//! `records::config_keys::allowed`. The suite (`tests/suite/docs.rs`) compares both with the
//! committed pages.

use crate::cli::args::{Cli, ReferenceArgs, ReferencePage};
use anyhow::{Context, bail};
use clap::CommandFactory;
use nbody_bench::records::config::SweepConfig;
use nbody_bench::records::config_keys::allowed;

/// Width the help is laid out for, whatever the terminal: the page is the same everywhere.
const WIDTH: usize = 100;

/// How the pages are regenerated, said at the top of each.
const REGENERATE: &str = "Generated from the code by `nbody-bench reference PAGE`; do not edit. \
    `NBODY_BENCH_UPDATE_DOCS=1 cargo test --test suite docs` rewrites it, and the same tests fail \
    while it is stale.";

pub fn reference(args: ReferenceArgs) -> anyhow::Result<i32> {
    let page = match args.page {
        ReferencePage::Cli => cli_page(),
        ReferencePage::Config => config_page()?,
    };
    out!("{page}");
    Ok(0)
}

/// The long help of the command and of every visible subcommand, as Markdown.
pub fn cli_page() -> String {
    let mut root = Cli::command()
        .term_width(WIDTH)
        .max_term_width(WIDTH)
        .color(clap::ColorChoice::Never);
    root.build();
    let mut page = String::from("# Command-line reference\n\n");
    page.push_str(&REGENERATE.replace("PAGE", "cli"));
    page.push_str(
        "\n\nEvery subcommand's `--help`. The [README](../../README.md) has one line per \
         subcommand; the [tutorial](../tutorial.md) uses them in order.\n\n",
    );
    page.push_str("## Subcommands\n\n");
    let names: Vec<String> = root
        .get_subcommands()
        .filter(|s| !s.is_hide_set() && s.get_name() != "help")
        .map(|s| s.get_name().to_string())
        .collect();
    for name in &names {
        page.push_str(&format!("- [`{name}`](#nbody-bench-{name})\n"));
    }
    page.push_str("\n## nbody-bench\n\n");
    push_help(&mut page, &mut root);
    for sub in root
        .get_subcommands_mut()
        .filter(|s| !s.is_hide_set() && s.get_name() != "help")
    {
        page.push_str(&format!("\n## nbody-bench {}\n\n", sub.get_name()));
        push_help(&mut page, sub);
    }
    page
}

fn push_help(page: &mut String, cmd: &mut clap::Command) {
    let help = cmd.render_long_help().to_string();
    page.push_str("```text\n");
    for line in help.trim_end().lines() {
        page.push_str(line.trim_end());
        page.push('\n');
    }
    page.push_str("```\n");
}

/// A config that sets every key (each optional one to something other than its default), so
/// that its parsed and re-serialized form names every field of the config types.
const FULL: &str = r#"
name = "every-key"
study = "weak"
scenarios = ["lj-box"]
kernels = ["naive"]
n = [1000]
threads = [1, 2]
seeds = [2]
theta = [0.7]
multipole = ["monopole"]
order = [6]
skin = [0.004]
precision = "f64"
initial = "bodies.txt"
out = "elsewhere"

[measure]
warmup_s = 0.1
samples = 6
min_sample_s = 0.02
rounds = 3
budget_s = 60
max_energy_drift = 0.1
force_error_sample = 100
reference_s = 0.02

[weak]
rule = "linear"
base_n = 1000

[mpi]
launcher = "mpiexec"
ranks = [1, 2]
args = ["--oversubscribe"]
rank_flag = "-np"
decomp = ["domain"]
steps = 50
warmup_steps = 5

[scheduler]
kind = "slurm"
partition = "short"
account = "proj42"
time_limit = "10:00"
sbatch_args = ["--qos=short"]
poll_s = 5

[[external]]
name = "other"
command = ["other", "{n}", "{threads}"]
setup = ["prepare", "{workdir}"]
steps = 100
time = { regex = 'took ([0-9.]+)', unit = "ms" }
check = 'done'
force_error = 'error ([^ ]+) ([^ ]+)'
family = "other"
phases = { comm = { regex = 'phase comm ([0-9.eE+-]+)', unit = "s", kind = "comm" } }
env = { OMP_NUM_THREADS = "{threads}" }
version = ["other", "--version"]
empty = ["other", "--empty"]
timeout_s = 60
warmup_runs = 1
scenarios = ["lj-box"]
n = [1000]
threads = [1]
ranks = [1]
"#;

/// What a key means (the forms it accepts come from `config_keys::allowed`).
fn meaning(key: &str) -> Option<&'static str> {
    Some(match key {
        "name" => {
            "names the results: `<out>/runs/<name>/<UTC time>/`, or `DIR/<name>/` with `--out DIR`"
        }
        "study" => {
            "how the sweep is read: threads at fixed n (strong), work per thread held (weak), kernels over n (complexity), every combination (cartesian)"
        }
        "scenarios" => "the scenarios measured",
        "kernels" => {
            "the built-in kernels measured (may be empty when `[[external]]` lists programs)"
        }
        "n" => "particle counts; required except in weak studies, which use `weak.base_n` instead",
        "threads" => "thread counts; a strong study must include 1",
        "seeds" => "seeds of the initial state; each is a case of its own",
        "theta" => "opening angles, octree and fmm cases only (the fmm takes those below 1)",
        "multipole" => "expansion orders of the octree's nodes, octree cases only",
        "order" => "expansion orders of the fmm's cells, fmm cases only",
        "skin" => {
            "neighbour-list skins in the scenario's length unit, verlet and cluster-pair cases only (left out: each kernel's default, 0.3 sigma of the LJ scenarios; `run --skin auto` finds the fastest)"
        }
        "precision" => "overrides each scenario's precision (when left out: each scenario's own)",
        "out" => "the results directory",
        "initial" => {
            "every case starts from the bodies in this file (relative to the config's directory) instead of the seeded placement: the built-in kernels, in this process or under [mpi]; read once at the start (launched runs read the sweep's copy, initial/ beside the results)"
        }
        "measure" => "how each case is measured",
        "weak" => "weak studies only: how n grows with the workers",
        "mpi" => {
            "run every case under an MPI launcher (`mpirun -n R nbody-bench run --decomp ...`)"
        }
        "external" => "other programs measured as cases of the sweep",
        "measure.warmup_s" => "untimed stepping before the samples",
        "measure.samples" => "samples per case, shared between the rounds",
        "measure.min_sample_s" => "a sample lasts at least this long (its step count adapts)",
        "measure.rounds" => "interleaved rounds over all cases",
        "measure.budget_s" => {
            "stop starting cases after this many seconds (0 = no limit); the rest is left for `--resume`"
        }
        "measure.max_energy_drift" => "flag a case whose relative energy drift exceeds this",
        "measure.force_error_sample" => {
            "also measure the force error against an f64 direct sum on this many particles"
        }
        "measure.reference_s" => {
            "seconds of the reference workload before each sample, for `gate` (0 = off)"
        }
        "weak.rule" => {
            "cost-model: n grows by each kernel's cost model; linear: n0·p; sqrt: n0·√p; time: n fixed, steps × p"
        }
        "weak.base_n" => "n at one worker",
        "mpi.launcher" => "the launcher program",
        "mpi.ranks" => "rank counts; each case runs at every one",
        "mpi.args" => "launcher arguments before the rank count",
        "mpi.rank_flag" => "the launcher's option that takes the rank count",
        "mpi.decomp" => "decompositions; each kernel runs with those that support it",
        "mpi.steps" => "timed steps per launch, split into the round's samples",
        "mpi.warmup_steps" => "untimed steps before them",
        "scheduler" => {
            "run each case round, and the calibrations, as a batch job on a cluster (Slurm)"
        }
        "scheduler.kind" => "the batch system",
        "scheduler.partition" => "`sbatch --partition` (when left out: the cluster's default)",
        "scheduler.account" => "`sbatch --account` (when left out: the user's default)",
        "scheduler.time_limit" => {
            "`sbatch --time` of each job; the sweep waits for a running job this long plus a \
             margin (10 minutes; NBODY_BENCH_JOB_GRACE_S), then stops for --resume"
        }
        "scheduler.sbatch_args" => "more `sbatch` arguments, given to every job",
        "scheduler.poll_s" => "seconds between two looks at the queue while a job waits or runs",
        "external.name" => "the kernel name of its cases (keys, tables, figures)",
        "external.command" => {
            "the program and its arguments, each token with placeholders; never a shell string"
        }
        "external.setup" => {
            "run once per round before the samples, untimed and without the launcher"
        }
        "external.steps" => {
            "time steps of one run, the same at every n or fewer as n grows: a sample's time per step is its run's time divided by the run's steps"
        }
        "external.time" => {
            "how a run is timed: the whole process, or the first group of the last match in its output"
        }
        "external.check" => {
            "a regular expression the output must match, else the sample is an error"
        }
        "external.force_error" => {
            "a regular expression whose groups are the median (and largest) force error the program reports"
        }
        "external.family" => {
            "entries of one family are one code at several accuracy settings: their cases form one series of force error against cost, like a θ sweep"
        }
        "external.phases" => {
            "phases the program times itself, each the first group of the last match in its output (its total over the run): a phase table and figure, the Amdahl serial fraction from its serial phases, its communication share; a run whose output lacks one is an error"
        }
        "external.env" => "environment variables set for the program (values with placeholders)",
        "external.version" => {
            "a command whose first line of output names the program's version (results metadata)"
        }
        "external.empty" => {
            "the empty run whose wall time is the launch overhead of wall timing (when left out: `true` under the same launcher)"
        }
        "external.timeout_s" => {
            "a run taking longer is stopped (SIGTERM, then SIGKILL) and is an error"
        }
        "external.warmup_runs" => "untimed runs before each round's samples",
        "external.scenarios" => "the scenarios its cases stand for (when left out: the config's)",
        "external.n" => {
            "the particle counts of its cases (when left out: the config's); not in a weak study"
        }
        "external.threads" => "thread counts (when left out: the config's)",
        "external.ranks" => "rank counts (when left out: the `[mpi]` table's, else 1)",
        _ => return None,
    })
}

/// The forms of an `[[external]]` key (`config_keys::allowed` covers the others).
fn external_forms(key: &str) -> Option<&'static str> {
    Some(match key {
        "external.name" => "a plain name, such as name = \"lammps\"",
        "external.command" | "external.setup" | "external.empty" => {
            "a list of strings (argv), such as [\"lmp\", \"-in\", \"{config_dir}/in.lj\"]; placeholders {n} {threads} {ranks} {steps} {seed} {theta} {scenario} {workdir} {config_dir} {nbody_bench}"
        }
        "external.version" => {
            "a list of strings (argv), with the placeholders {config_dir} and {nbody_bench} only"
        }
        "external.steps" => {
            "a whole number of at least 1, such as steps = 2000; or the cost of one run and how a step's cost grows with n, such as steps = { work = 4e8, grows = \"n^2\" } (work / n² steps, rounded, at least 1), grows = \"n\" | \"n log n\" | \"n^2\""
        }
        "external.time" => nbody_bench::records::external::config::TIME_FORMS,
        "external.check" => "a regular expression, such as check = 'Total wall time'",
        "external.force_error" => {
            "a regular expression with one or two groups, such as force_error = 'median ([^ ]+) max ([^ ]+)'"
        }
        "external.family" => {
            "a plain name shared by the entries, such as family = \"fmm3d\"; needs force_error"
        }
        "external.phases" => {
            "a table of phases by name, each { regex, unit = \"s\" | \"ms\" | \"us\" | \"ns\", kind = \"parallel\" (default) | \"serial\" | \"comm\" }, such as phases = { comm = { regex = 'phase comm ([0-9.]+)', unit = \"s\", kind = \"comm\" } }"
        }
        "external.env" => "a table of strings, such as env = { OMP_NUM_THREADS = \"{threads}\" }",
        "external.timeout_s" => "seconds above 0, at most 7 days, such as timeout_s = 600",
        "external.warmup_runs" => "a whole number of at least 0, such as warmup_runs = 1",
        "external.scenarios" => "a list of scenario names, such as scenarios = [\"lj-box\"]",
        "external.n" => "a list of counts of at least 1, such as n = [500, 1000, 2000]",
        "external.threads" => "a list of thread counts of at least 1, such as threads = [1, 2]",
        "external.ranks" => "a list of rank counts of at least 1, such as ranks = [1, 2]",
        _ => return None,
    })
}

/// One key of the page: its dotted name, default, meaning and forms.
struct Row {
    key: String,
    default: String,
    forms: &'static str,
    meaning: &'static str,
}

/// Every key of a sweep config, by table, with what it defaults to and accepts.
pub fn config_page() -> anyhow::Result<String> {
    let full: toml::Table = toml::from_str(FULL).context("the full example config as TOML")?;
    let parsed: SweepConfig = toml::from_str(FULL).context("the full example config")?;
    let serialized = toml::Table::try_from(&parsed).context("serializing the full config")?;
    // (section heading, its rows)
    let mut sections: Vec<(String, Vec<Row>)> = vec![("Top-level keys".into(), Vec::new())];
    for (key, value) in &serialized {
        // (the table under the key, whether it is an array of tables)
        let nested = match value {
            toml::Value::Table(t) => Some((t.clone(), false)),
            toml::Value::Array(a) => a
                .first()
                .and_then(toml::Value::as_table)
                .map(|t| (t.clone(), true)),
            _ => None,
        };
        sections[0].1.push(row(&full, &[key], "")?);
        if let Some((inner, array)) = nested {
            let heading = if array {
                format!("`[[{key}]]`")
            } else {
                format!("`[{key}]`")
            };
            let mut rows = Vec::new();
            for inner_key in inner.keys() {
                rows.push(row(&full, &[key, inner_key], key)?);
            }
            sections.push((heading, rows));
        }
    }
    let mut page = String::from("# Sweep config reference\n\n");
    page.push_str(&REGENERATE.replace("PAGE", "config"));
    page.push_str(
        "\n\nA sweep config is a TOML file (`nbody-bench sweep --config FILE|NAME`; a bare name is \
         looked up in `configs/`). Unknown keys, wrong types, empty lists, zero threads and \
         kernels that apply to none of the scenarios are refused before anything runs, with the \
         file, the key and the forms below. A default of *required* means the config (or the \
         table, when it is given) must set the key; *none* means the key has no value of its own \
         when left out: the feature is off, or what the description names applies. How to write an `[[external]]` entry: \
         [measure your own program](../howto/measure-your-own-program.md); the `[mpi]` table: \
         [run MPI studies](../howto/run-mpi-studies.md).\n",
    );
    for (heading, rows) in &sections {
        page.push_str(&format!("\n## {heading}\n\n"));
        page.push_str("| key | default | what it is | accepted forms |\n|---|---|---|---|\n");
        for r in rows {
            page.push_str(&format!(
                "| `{}` | {} | {} | {} |\n",
                r.key,
                r.default,
                r.meaning,
                r.forms.replace('|', "\\|")
            ));
        }
    }
    Ok(page)
}

/// The row of the key at `path` (one or two levels) of the full config: the config parsed
/// without it says whether it is required and what it defaults to.
fn row(full: &toml::Table, path: &[&String], table: &str) -> anyhow::Result<Row> {
    let dotted = path
        .iter()
        .map(|s| s.as_str())
        .collect::<Vec<_>>()
        .join(".");
    let mut without = full.clone();
    let holder: &mut toml::Table = match path {
        [_] => &mut without,
        [outer, _] => match without.get_mut(outer.as_str()) {
            Some(toml::Value::Table(t)) => t,
            Some(toml::Value::Array(a)) => match a.first_mut() {
                Some(toml::Value::Table(t)) => t,
                _ => bail!("`{outer}` is not an array of tables in the full config"),
            },
            _ => bail!("`{outer}` is not a table of the full config"),
        },
        _ => bail!("keys are one or two levels deep"),
    };
    let Some(last) = path.last().map(|k| k.as_str()) else {
        bail!("an empty key path");
    };
    holder.remove(last);
    let default = match toml::Value::Table(without).try_into::<SweepConfig>() {
        Err(_) => "*required*".to_string(),
        Ok(config) => {
            let table = toml::Table::try_from(&config)?;
            let value = match path {
                [only] => table.get(only.as_str()),
                [outer, inner] => match table.get(outer.as_str()) {
                    Some(toml::Value::Table(t)) => t.get(inner.as_str()),
                    Some(toml::Value::Array(a)) => a
                        .first()
                        .and_then(toml::Value::as_table)
                        .and_then(|t| t.get(inner.as_str())),
                    _ => None,
                },
                _ => None,
            };
            match value {
                None => "*none*".to_string(),
                Some(toml::Value::Table(_)) => "the defaults below".to_string(),
                Some(v) => format!("`{v}`"),
            }
        }
    };
    let forms = match table {
        "external" => external_forms(&dotted),
        _ => allowed(&dotted),
    };
    let forms = match (forms, dotted.as_str()) {
        (Some(f), _) => f,
        (None, "external") => "one `[[external]]` table per program",
        (None, _) => bail!(
            "config key `{dotted}` has no accepted forms: add them to \
             records::config_keys::allowed (or, for [[external]], to src/cli/reference.rs)"
        ),
    };
    let Some(meaning) = meaning(&dotted) else {
        bail!("config key `{dotted}` has no meaning in src/cli/reference.rs: add one");
    };
    Ok(Row {
        key: dotted,
        default,
        forms,
        meaning,
    })
}
