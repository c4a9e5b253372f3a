//! `fit`: a scaling model fitted to a CSV of measurements from any code.

use crate::cli::args::{CostModel, FitArgs, FitModel};
use anyhow::{Context, bail};
use nbody_harness::fit::csv::{self, WeakTable};
use nbody_harness::fit::{ComplexityClass, fit_power, fit_strong, fit_weak, fit_weak_with_n};
use nbody_harness::render::fit_tables;
use serde::Serialize;
use std::path::Path;

/// The JSON written by `--json`: what was fitted, then the fit's own fields.
#[derive(Serialize)]
struct FitDocument<'a, T: Serialize> {
    schema: &'static str,
    model: &'static str,
    csv: String,
    seed: u64,
    #[serde(flatten)]
    fit: &'a T,
}

pub fn fit(args: FitArgs) -> anyhow::Result<i32> {
    if let Some(json) = &args.json {
        nbody_engine::output::check_outputs(&[("--json", json)], &[("--csv", &args.csv)])?;
    }
    let text = nbody_engine::input::read_text(&args.csv)
        .with_context(|| format!("cannot read {}", args.csv.display()))?;
    let in_csv = |e: csv::CsvError| anyhow::anyhow!("{}: {e}", args.csv.display());
    let name = args.csv.display().to_string();
    if args.cost.is_some() && args.model != FitModel::Gustafson {
        bail!("--cost applies to --model gustafson with an n column only");
    }
    match args.model {
        FitModel::Amdahl => {
            let samples = csv::parse_threads(&text).map_err(in_csv)?;
            let fit = fit_strong(&samples, &[], args.seed)?;
            out!("{}", fit_tables::strong(&name, &fit));
            write_json(&args, "amdahl", &fit)?;
        }
        FitModel::Gustafson => {
            let fit = match csv::parse_weak(&text).map_err(in_csv)? {
                WeakTable::Times(samples) => {
                    if args.cost.is_some() {
                        bail!(
                            "{name}: --cost needs an n column (p,n,time) to know the problem sizes"
                        );
                    }
                    fit_weak(&samples, args.seed)?
                }
                WeakTable::WithN(samples) => {
                    let cost = cost_class(args.cost.unwrap_or(CostModel::N));
                    fit_weak_with_n(&samples, cost, args.seed)?
                }
            };
            out!("{}", fit_tables::weak(&name, &fit));
            write_json(&args, "gustafson", &fit)?;
        }
        FitModel::Power => {
            let samples = csv::parse_sizes(&text).map_err(in_csv)?;
            let fit = fit_power(&samples, args.seed)?;
            out!("{}", fit_tables::power(&name, &fit));
            write_json(&args, "power", &fit)?;
        }
    }
    Ok(0)
}

fn cost_class(cost: CostModel) -> ComplexityClass {
    match cost {
        CostModel::N => ComplexityClass::N,
        CostModel::NLogN => ComplexityClass::NLogN,
        CostModel::NSqrtN => ComplexityClass::NSqrtN,
        CostModel::N2 => ComplexityClass::N2,
        CostModel::N2LogN => ComplexityClass::N2LogN,
        CostModel::N3 => ComplexityClass::N3,
    }
}

fn write_json<T: Serialize>(args: &FitArgs, model: &'static str, fit: &T) -> anyhow::Result<()> {
    let Some(path) = &args.json else {
        return Ok(());
    };
    let doc = FitDocument {
        schema: "nbody-bench/fit/v1",
        model,
        csv: args.csv.display().to_string(),
        seed: args.seed,
        fit,
    };
    let mut text = serde_json::to_string_pretty(&doc)?;
    text.push('\n');
    nbody_engine::output::write_atomic(Path::new(path), text.as_bytes())?;
    outln!("\nfit written to {}", path.display());
    Ok(())
}
