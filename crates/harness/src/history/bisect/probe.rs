//! The probe of this project's own commits: each built once in the gate's cached worktree
//! ([`base_build`]), two at a time measured on one case by the gate's interleaved A/B sweeps
//! ([`ab::measure`]). Every side-by-side run is kept (both builds' results files) under the
//! bisection's runs folder: nothing measured is lost when the bisection stops early.

use super::Probe;
use crate::gate::ab::{self, AbPlan, OneCase};
use crate::gate::base_build::{self, BaseBinary};
use crate::gate::prefix;
use nbody_records::config::SweepConfig;
use nbody_records::plan::Case;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Builds and measures commits of the repository at `repo` on one case of a sweep config.
pub struct GateProbe<'a> {
    repo: PathBuf,
    config: SweepConfig,
    config_text: String,
    case: OneCase,
    binaries: BTreeMap<String, BaseBinary>,
    runs: PathBuf,
    measured: usize,
    progress: Box<dyn FnMut(&str) + 'a>,
}

impl<'a> GateProbe<'a> {
    /// The probe of case `key` of the config at `config`, keeping its runs under `runs`. A key
    /// the config does not plan is an error listing the keys it does.
    pub fn new(
        repo: &Path,
        config: &Path,
        key: &str,
        runs: &Path,
        progress: Box<dyn FnMut(&str) + 'a>,
    ) -> anyhow::Result<Self> {
        let (parsed, text) = SweepConfig::load(config)?;
        let cases = ab::prepare(&parsed, &text, crate::gate::AB_ROUNDS)?;
        let Some(case) = cases.iter().find(|c| c.case.key() == key).cloned() else {
            let keys: Vec<String> = cases.iter().map(|c| c.case.key()).collect();
            anyhow::bail!(
                "{} plans no case `{key}`; its cases are: {}",
                config.display(),
                keys.join(", ")
            );
        };
        Ok(GateProbe {
            repo: repo.to_path_buf(),
            config: parsed,
            config_text: text,
            case,
            binaries: BTreeMap::new(),
            runs: runs.to_path_buf(),
            measured: 0,
            progress,
        })
    }

    /// The case measured.
    pub fn case(&self) -> &Case {
        &self.case.case
    }
}

impl Probe for GateProbe<'_> {
    fn build(&mut self, commit: &str) -> Result<(), String> {
        let binary = base_build::base_binary(&self.repo, commit, &mut *self.progress)
            .map_err(|e| e.to_string())?;
        self.binaries.insert(commit.to_string(), binary);
        Ok(())
    }

    fn measure(&mut self, a: &str, b: &str, rounds: usize) -> anyhow::Result<[Vec<f64>; 2]> {
        let binary = |c: &str| {
            self.binaries.get(c).ok_or_else(|| {
                anyhow::anyhow!("{} was measured before it was built", prefix(c, 12))
            })
        };
        let (base, current) = (binary(a)?, binary(b)?);
        self.measured += 1;
        let dir = self.runs.join(format!(
            "{:02}-{}-{}",
            self.measured,
            prefix(a, 12),
            prefix(b, 12)
        ));
        let limit = |case: &Case| ab::child_limit(&self.config, case, rounds, None);
        let plan = AbPlan {
            config: &self.config,
            config_text: &self.config_text,
            cases: std::slice::from_ref(&self.case),
            base,
            current: &current.path,
            rounds,
            work: &dir.join("work"),
            limit: &limit,
            // A bisection's few rounds of one case: the builds take turns, as before duets.
            sides: crate::gate::duet::Sides::Turns,
        };
        let mut results = ab::measure(&plan, &mut *self.progress)?;
        // Each binary reads the commit from the checkout it runs in: name the ones measured.
        for (file, commit) in [(&mut results.base, a), (&mut results.current, b)] {
            file.metadata.git_commit = commit.to_string();
            file.metadata.git_dirty = false;
        }
        results.base.save(&dir.join("base.json"))?;
        results.current.save(&dir.join("current.json"))?;
        let _ = std::fs::remove_dir_all(dir.join("work"));
        let samples = |file: &nbody_records::results::ResultsFile| -> Vec<f64> {
            file.cases
                .iter()
                .flat_map(|c| c.rounds.iter().flat_map(|r| r.samples_s.iter().copied()))
                .collect()
        };
        Ok([samples(&results.base), samples(&results.current)])
    }
}
