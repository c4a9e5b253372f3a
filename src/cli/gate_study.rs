//! `gate-study`: measure the gate's false-alarm rate and power on this machine, or regenerate
//! the gate page's tables from the study files (`nbody_harness::gate::study`).

use crate::cli::args::GateStudyArgs;
use nbody_harness::gate::study::{run, table};
use std::path::Path;

/// The page whose generated region holds the study's tables.
const GATE_PAGE: &str = "docs/explanation/gate.md";

pub fn gate_study(args: GateStudyArgs) -> anyhow::Result<i32> {
    if args.docs {
        return write_docs(&args.out);
    }
    if let Some(raw) = &args.from {
        let study = run::resummarise(raw, &args.baseline, &args.out)?;
        eprintln!(
            "gate-study: {} summarised into {}",
            raw.display(),
            study.display()
        );
        return Ok(0);
    }
    measure(args)
}

fn write_docs(out: &Path) -> anyhow::Result<i32> {
    let files = run::study_files(out).map_err(|e| anyhow::anyhow!(e))?;
    let page = nbody_engine::input::read_text(Path::new(GATE_PAGE))
        .map_err(|e| anyhow::anyhow!("cannot read {GATE_PAGE}: {e}"))?;
    let Some(new) = table::splice(&page, &table::markdown(&files)) else {
        anyhow::bail!("{GATE_PAGE} has no generated region (its marks were removed)");
    };
    nbody_engine::output::write_atomic(Path::new(GATE_PAGE), new.as_bytes())?;
    eprintln!(
        "gate-study: {GATE_PAGE} regenerated from {} study file(s) in {}",
        files.len(),
        out.display()
    );
    Ok(0)
}

fn measure(args: GateStudyArgs) -> anyhow::Result<i32> {
    use nbody_records::{config::SweepConfig, locate};
    let config = match &args.config {
        Some(name) => {
            let path = locate::find_config(name)?;
            let text = nbody_engine::input::read_text(&path)
                .map_err(|e| anyhow::anyhow!("cannot read config {}: {e}", path.display()))?;
            Some((SweepConfig::parse(&text, &path)?, text))
        }
        None => None,
    };
    let options = run::StudyOptions {
        baselines: args.baseline,
        config,
        blocks: args.blocks as usize,
        load: args.load,
        duet: args.duet,
        slowed: args.slow,
        out: args.out,
        runs_root: "results".into(),
    };
    let paths = run::run(&options, &mut |line| eprintln!("gate-study: {line}"))?;
    eprintln!(
        "gate-study: summary in {}, raw measurements in {}; `nbody-bench gate-study --docs` \
         regenerates {GATE_PAGE}",
        paths.study.display(),
        paths.raw.display()
    );
    let file = nbody_harness::gate::study::StudyFile::load(&paths.study)
        .map_err(|e| anyhow::anyhow!(e))?;
    out!("{}", table::markdown(&[file]));
    Ok(0)
}
