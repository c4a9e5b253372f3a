//! A measuring run of the study: the class's baseline and config, the blocks, the raw file
//! kept after every block, and the class's study file updated with the summary.

use super::{Load, RawStudy, STUDY_SCHEMA, StudyFile, StudyRun};
use crate::gate::baselines::{self, Fitness};
use crate::gate::route::this_machine;
use nbody_engine::kernels::KernelKind;
use nbody_engine::output::provenance::utc_now;
use nbody_records::config::SweepConfig;
use nbody_records::kernel_or_program::KernelOrProgram;
use nbody_records::results::Metadata;
use nbody_records::results::ResultsFile;
use std::path::{Path, PathBuf};

/// What to measure.
pub struct StudyOptions {
    /// The folder of baselines: this class's gives the config and the fast path's reference.
    pub baselines: PathBuf,
    /// The config when this class has no reproducible baseline (then no fast-path decisions).
    pub config: Option<(SweepConfig, String)>,
    /// Blocks to measure: one decision per mode and slowdown each.
    pub blocks: usize,
    /// What else runs on the machine meanwhile.
    pub load: Load,
    /// Measure the two sides of each pair a decision compares at the same moment, one per CPU.
    pub duet: bool,
    /// The kernel made slower for the power decisions; the config must have cases of it.
    pub slowed: KernelKind,
    /// Where the study files are (`results/gate-study`) and where the raw run goes.
    pub out: PathBuf,
    /// Root of the run directories (`results`): the raw run goes to `runs/gate-study/<UTC time>/`.
    pub runs_root: PathBuf,
}

/// Where a run left its files.
pub struct StudyPaths {
    /// The class's study file the summary was added to.
    pub study: PathBuf,
    /// The raw measurements of every block, `raw.json` in the run's directory.
    pub raw: PathBuf,
}

/// This machine class's reproducible baseline in `dir`: its file name and contents.
fn own_baseline(dir: &Path) -> Option<(PathBuf, Box<baselines::Reproducible>)> {
    let here = this_machine();
    let chosen = baselines::choose(dir, &here).ok()?;
    if chosen.info.machine_class_differs(&here).is_some() {
        return None;
    }
    match chosen.fitness {
        Fitness::Reproducible(r) => Some((chosen.path, r)),
        Fitness::Stale(_) => None,
    }
}

/// Summarises a raw file measured earlier (after a change of how decisions are judged) into
/// its class's study file, against this class's baseline in `baselines`; the file's path.
pub fn resummarise(raw_path: &Path, baselines: &Path, out: &Path) -> anyhow::Result<PathBuf> {
    let text = nbody_engine::input::read_text(raw_path)
        .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", raw_path.display()))?;
    let raw: RawStudy = serde_json::from_str(&text)
        .map_err(|e| anyhow::anyhow!("{}: not a gate-study raw file ({e})", raw_path.display()))?;
    if raw.schema != STUDY_SCHEMA {
        anyhow::bail!(
            "{}: schema `{}`, this build reads `{STUDY_SCHEMA}`",
            raw_path.display(),
            raw.schema
        );
    }
    let own = own_baseline(baselines).filter(|(_, r)| r.config == raw.config);
    let name = own
        .as_ref()
        .and_then(|(p, _)| p.file_name().map(|n| n.to_string_lossy().into_owned()));
    summarise(&raw, own.as_ref().map(|(_, r)| &r.file), name, out)
}

/// Measures and summarises; `say` hears the plan and every block. Only in a build with the
/// `test-slowdown` feature: the study slows a kernel on purpose.
pub fn run(options: &StudyOptions, say: &mut dyn FnMut(&str)) -> anyhow::Result<StudyPaths> {
    if !crate::experiment::slowdown::ENABLED {
        anyhow::bail!(
            "gate-study: {}; --docs works in any build",
            crate::experiment::slowdown::NOT_ENABLED
        );
    }
    let own = own_baseline(&options.baselines);
    let (config, baseline, baseline_name) = match (own, &options.config) {
        (_, Some((config, _))) => (config.clone(), None, None),
        (Some((path, r)), None) => {
            let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
            (r.config.clone(), Some(r.file), name)
        }
        (None, None) => anyhow::bail!(
            "no reproducible baseline of this machine class in {}: measure one \
             (scripts/refresh-baseline.sh), or pass --config to study A/B decisions only",
            options.baselines.display()
        ),
    };
    let cases = nbody_records::plan::cases(&config);
    if let Some(c) = cases
        .iter()
        .find(|c| !matches!(c.kernel, KernelOrProgram::Kernel(_)))
    {
        anyhow::bail!(
            "{}: the study measures built-in kernels only (config `{}`)",
            c.key(),
            config.name
        );
    }
    if !cases
        .iter()
        .any(|c| c.kernel == KernelOrProgram::Kernel(options.slowed))
    {
        anyhow::bail!(
            "--slow {}: config `{}` has no case of that kernel",
            options.slowed.name(),
            config.name
        );
    }
    let rounds = crate::gate::AB_ROUNDS;
    let samples = crate::gate::ab::samples_per_round(&config, rounds);
    let run_dir = nbody_records::locate::new_run_dir(&options.runs_root, "gate-study", &utc_now())?;
    let raw_path = run_dir.join("raw.json");
    say(&format!(
        "{} blocks of {} cases x {} to {} rounds x {} samples, sides A and B and `{}` slowed \
         5/10/25%{}, load {:?}{}; fast-path decisions against {}; raw measurements in {}",
        options.blocks,
        cases.len(),
        rounds,
        crate::gate::AB_MAX_ROUNDS,
        samples,
        options.slowed.name(),
        if options.duet {
            ", each pair at the same moment (duet)"
        } else {
            ""
        },
        options.load,
        if options.load == Load::Spin {
            " (a process spinning on one CPU)"
        } else {
            ""
        },
        match (&baseline_name, options.duet) {
            (_, true) => "nothing (CI's sweep runs alone, a duet's sides beside each other)",
            (Some(name), false) => name.as_str(),
            (None, false) => "nothing (no baseline of this class and config)",
        },
        raw_path.display()
    ));
    say("calibrating the machine...");
    let calibration = nbody_calibrate::calibrate(&[1]);
    let mut raw = RawStudy {
        schema: STUDY_SCHEMA.to_string(),
        metadata: Metadata::collect(&crate::experiment::cargo_features()),
        calibration,
        load: options.load,
        duet: options.duet,
        slowed_kernel: options.slowed,
        config: config.clone(),
        rounds,
        samples_per_round: samples,
        blocks: Vec::new(),
    };
    let started = std::time::Instant::now();
    let total = options.blocks;
    let mut saved: anyhow::Result<()> = Ok(());
    let template = raw.clone();
    let blocks = super::measure_blocks(&template, &cases, total, &mut |i, block| {
        // Nothing measured is lost: the raw file holds every finished block.
        raw.blocks.push(block.clone());
        if saved.is_ok() {
            saved = save_json(&raw_path, &raw);
        }
        let left = started.elapsed().as_secs_f64() / (i + 1) as f64 * (total - i - 1) as f64;
        say(&format!(
            "block {}/{total} measured in {:.1} s (about {:.0} min left)",
            i + 1,
            block.wall_s,
            left / 60.0
        ));
    })
    .map_err(|e| anyhow::anyhow!(e))?;
    saved?;
    raw.blocks = blocks;
    save_json(&raw_path, &raw)?;
    let study = summarise(&raw, baseline.as_ref(), baseline_name, &options.out)?;
    Ok(StudyPaths {
        study,
        raw: raw_path,
    })
}

/// Adds the summary of `raw` to its class's study file in `out`; the file's path.
pub fn summarise(
    raw: &RawStudy,
    baseline: Option<&ResultsFile>,
    baseline_name: Option<String>,
    out: &Path,
) -> anyhow::Result<PathBuf> {
    let c = &raw.calibration;
    let mut file = StudyFile {
        schema: STUDY_SCHEMA.to_string(),
        cpu_model: c.cpu_model.clone(),
        cpu_signature: c.cpu_signature.clone(),
        logical_cpus: c.logical_cpus,
        simd: c.simd.clone(),
        config_name: raw.config.name.clone(),
        baseline: baseline_name,
        runs: Vec::new(),
    };
    let path = out.join(format!("{}.json", file.class()));
    if path.exists() {
        let earlier = StudyFile::load(&path).map_err(|e| anyhow::anyhow!(e))?;
        file.runs = earlier.runs;
        if file.baseline.is_none() {
            file.baseline = earlier.baseline;
        }
    }
    file.put(StudyRun::of(raw, baseline));
    nbody_engine::output::create_dir_all(out)
        .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", out.display()))?;
    save_json(&path, &file)?;
    Ok(path)
}

fn save_json<T: serde::Serialize>(path: &Path, value: &T) -> anyhow::Result<()> {
    let text = serde_json::to_string_pretty(value)? + "\n";
    nbody_engine::output::write_atomic(path, text.as_bytes())?;
    Ok(())
}

/// Every study file of `dir`, sorted by name.
pub fn study_files(dir: &Path) -> Result<Vec<StudyFile>, String> {
    if !dir.is_dir() {
        return Ok(Vec::new());
    }
    let paths = baselines::json_files(dir).map_err(|e| e.to_string())?;
    paths.iter().map(|p| StudyFile::load(p)).collect()
}
