//! How a measuring gate judges this build: the fast path (sweep the baseline's own config and
//! compare with the baseline file of this machine class) or A/B (measure a base revision and
//! this build side by side here). Every route is decided, and every refusal made, before
//! anything long starts.

use super::baselines::{self, Chosen, Fitness};
use super::{RunInfo, calibrated_rate, rates_differ};
use nbody_records::config::SweepConfig;
use nbody_records::locate;
use nbody_records::results::ResultsFile;
use std::path::{Path, PathBuf};

/// What the gate judges against, as found on disk.
pub enum Reference {
    /// A folder's (or a file's) baseline.
    Baseline(Box<Chosen>),
    /// No baseline: `--against REV` only.
    None,
}

/// The decided route.
pub enum Route {
    /// Sweep `config` with this build and compare with the baseline file (same machine class,
    /// reproducible, machine speed as when it was measured).
    Fast {
        /// The baseline results file.
        path: PathBuf,
        /// Its results, as this build loaded them.
        baseline: Box<ResultsFile>,
    },
    /// Measure revision `rev` and this build side by side.
    AB {
        /// The base revision: `--against`'s, or the commit the baseline was measured at.
        rev: String,
    },
}

/// The machine this process runs on, as a gate sees a results file's.
pub fn this_machine() -> RunInfo {
    RunInfo {
        git_commit: String::new(),
        git_dirty: false,
        started: String::new(),
        host: String::new(),
        cpu_model: Some(nbody_calibrate::cpu_model()),
        cpu_signature: nbody_calibrate::cpu_signature(),
        logical_cpus: Some(nbody_engine::run::logical_cpus()),
    }
}

/// A folder of per-machine-class baselines (`results/baseline/`), not one results file or a
/// run directory.
pub fn is_baseline_folder(path: &Path) -> bool {
    path.is_dir() && !path.join("results.json").is_file()
}

/// The baseline `--baseline` names: this class's file of a folder, or the one file given
/// (a results file, a run directory or a config name). A missing file is no reference when
/// `--against` names one.
pub fn find_reference(baseline: &Path, against: Option<&str>) -> anyhow::Result<Reference> {
    if is_baseline_folder(baseline) {
        return Ok(Reference::Baseline(Box::new(baselines::choose(
            baseline,
            &this_machine(),
        )?)));
    }
    if !nbody_engine::input::is_readable(baseline) && against.is_some() {
        return Ok(Reference::None);
    }
    let path = locate::find_results(baseline, Path::new("results"))?;
    Ok(Reference::Baseline(Box::new(baselines::examine(&path)?)))
}

/// The config a measuring gate sweeps and its text: `--config`, else the baseline's stored
/// config (resolved when it was measured), else for a stale baseline or none
/// `configs/ci.toml`.
pub fn config_to_sweep(
    config: Option<&Path>,
    reference: &Reference,
    say: &mut dyn FnMut(&str),
) -> anyhow::Result<(SweepConfig, String)> {
    let from_file = |name: &Path| -> anyhow::Result<(SweepConfig, String)> {
        let path = locate::find_config(name)?;
        let text = nbody_engine::input::read_text(&path)
            .map_err(|e| anyhow::anyhow!("cannot read config {}: {e}", path.display()))?;
        Ok((SweepConfig::parse(&text, &path)?, text))
    };
    if let Some(name) = config {
        return from_file(name);
    }
    match reference {
        Reference::Baseline(chosen) => match &chosen.fitness {
            Fitness::Reproducible(r) => Ok((r.config.clone(), r.text.clone())),
            Fitness::Stale(_) => {
                say("the stale baseline's config is not swept: configs/ci.toml is, by both builds");
                from_file(Path::new("ci"))
            }
        },
        Reference::None => from_file(Path::new("ci")),
    }
}

/// Fast path or A/B. `--against` is always A/B. A baseline of this machine class that this
/// build reproduces gets the fast path, unless the machine's calibrated FMA rate now is too
/// far from the baseline's for the reference normalisation ([`super::RATE_TOLERANCE`]). A
/// baseline of another class, or a stale one, gets A/B against its commit, with a notice that
/// says why.
pub fn route(
    against: Option<&str>,
    reference: Reference,
    say: &mut dyn FnMut(&str),
) -> anyhow::Result<Route> {
    let chosen = match (against, reference) {
        (Some(rev), _) => return Ok(Route::AB { rev: rev.into() }),
        (None, Reference::Baseline(chosen)) => chosen,
        (None, Reference::None) => {
            anyhow::bail!("no baseline to judge against; pass --baseline FILE or --against REV")
        }
    };
    let Chosen {
        path,
        info,
        fitness,
    } = *chosen;
    let commit = info.git_commit.clone();
    if let Some(why) = info.machine_class_differs(&this_machine()) {
        say(&format!(
            "the baseline {} comes from another machine class ({why}); measuring its revision \
             {} and this build side by side here (A/B); `gate --save-baseline` on this \
             machine's own sweep gives it the fast path",
            path.display(),
            short(&commit)
        ));
        return Ok(Route::AB { rev: commit });
    }
    let file = match fitness {
        Fitness::Stale(why) => {
            say(&format!(
                "the baseline {} cannot be reproduced by this build: {why}; measuring its \
                 revision {} and this build side by side here (A/B) instead",
                path.display(),
                short(&commit)
            ));
            return Ok(Route::AB { rev: commit });
        }
        Fitness::Reproducible(r) => r.file,
    };
    let Some(rate) = calibrated_rate(&file) else {
        return Ok(Route::Fast {
            path,
            baseline: Box::new(file),
        });
    };
    let here = nbody_calibrate::calibrate(&[1]).fma_gflops_1t;
    if let Some(why) = rates_differ(rate, here) {
        say(&format!(
            "{why}; measuring the baseline's revision {} and this build side by side here \
             (A/B) instead of comparing with {}",
            short(&commit),
            path.display()
        ));
        return Ok(Route::AB { rev: commit });
    }
    say(&format!(
        "calibrated FMA rate {here:.1} GFLOP/s, the baseline's {rate:.1} ({:.2}x, within {:.0}%)",
        here / rate,
        super::RATE_TOLERANCE * 100.0
    ));
    Ok(Route::Fast {
        path,
        baseline: Box::new(file),
    })
}

pub(super) fn short(commit: &str) -> &str {
    super::prefix(commit, 12)
}
