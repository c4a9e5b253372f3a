use super::{kernel_params, setup};
use crate::cli::ValidateArgs;
use crate::scenario::ScenarioKind;
use crate::validate::{ScenarioCheck, ValidateJob};
use std::path::PathBuf;

pub fn validate(args: ValidateArgs) -> anyhow::Result<i32> {
    let scenarios: Vec<ScenarioKind> = match args.scenario {
        Some(s) => vec![s],
        None => ScenarioKind::ALL.to_vec(),
    };
    if let Some(dump) = &args.dump {
        let paths: Vec<PathBuf> = scenarios
            .iter()
            .map(|&s| dump_file(dump, scenarios.len(), s))
            .collect();
        let outputs: Vec<(&str, &std::path::Path)> =
            paths.iter().map(|p| ("--dump", p.as_path())).collect();
        crate::output::check_outputs(&outputs, &[])?;
    }
    let params = kernel_params(&args.kernel_args, None)?;
    let mut results: Vec<ScenarioCheck> = Vec::new();
    for &scenario in &scenarios {
        let mut s = setup(scenario, &args.system);
        if args.scenario.is_none()
            && args.system.density.is_some()
            && scenario.defaults().density.is_none()
        {
            // --density applies to the scenarios that have one.
            s.density = None;
        }
        let job = ValidateJob {
            params,
            threads: args.kernel_args.threads,
            want_dump: args.dump.is_some(),
        };
        let check = s.dispatch(job)??;
        if let (Some(path), Some(text)) = (&args.dump, &check.dump) {
            let path = dump_file(path, scenarios.len(), scenario);
            crate::output::write_atomic(&path, text.as_bytes())?;
            if !args.json {
                outln!("forces written to {}", path.display());
            }
        }
        if !args.json {
            print_check(&check);
        }
        results.push(check);
    }
    let failed: Vec<String> = results
        .iter()
        .flat_map(|c| {
            c.kernels
                .iter()
                .filter(|k| !k.passed)
                .map(move |k| format!("{}/{}", c.scenario, k.kernel))
        })
        .collect();
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&results)?);
    } else if failed.is_empty() {
        outln!("all kernels agree with the reference");
    } else {
        outln!("FAILED: {}", failed.join(", "));
    }
    Ok(if failed.is_empty() { 0 } else { 1 })
}

/// The dump of one scenario: `path` itself, or `path.<scenario>` when several are checked.
fn dump_file(path: &std::path::Path, scenarios: usize, scenario: ScenarioKind) -> PathBuf {
    if scenarios == 1 {
        return path.to_path_buf();
    }
    dump_path(path, scenario)
}

fn dump_path(path: &std::path::Path, scenario: ScenarioKind) -> PathBuf {
    let mut p = path.as_os_str().to_owned();
    p.push(format!(".{}", scenario.name()));
    PathBuf::from(p)
}

fn print_check(c: &ScenarioCheck) {
    outln!(
        "{}: n = {}, {}, reference = naive in f64, theta = {}",
        c.scenario,
        c.n,
        c.precision,
        c.theta
    );
    outln!(
        "  {:<11} {:>12} {:>12}  {:<6} criterion",
        "kernel",
        "max rel err",
        "median",
        "result"
    );
    for k in &c.kernels {
        outln!(
            "  {:<11} {:>12.3e} {:>12.3e}  {:<6} {}",
            k.kernel,
            k.max_rel_error,
            k.median_rel_error,
            if k.passed { "ok" } else { "FAIL" },
            k.criterion
        );
    }
}
