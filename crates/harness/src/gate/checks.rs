//! Whether two results files may be compared at all: same machine class (CPU model and
//! logical CPU count, not the host name, since CI runs on a fresh machine of the same class),
//! same build (SIMD level, profile) and same config. Each mismatch is an error unless forced,
//! and then a warning in the report.

use super::{GateError, RunInfo};
use nbody_records::results::ResultsFile;

/// Checks that the files are comparable; returns the warnings to carry in the report.
pub(super) fn check_comparable(
    baseline: &ResultsFile,
    current: &ResultsFile,
    force: bool,
) -> Result<Vec<String>, GateError> {
    let mut warnings = Vec::new();
    let refuse = |error: GateError, warnings: &mut Vec<String>| {
        if force {
            warnings.push(format!("forced: {error}"));
            Ok(())
        } else {
            Err(error)
        }
    };
    let (b, c) = (RunInfo::of(baseline), RunInfo::of(current));
    for (info, which) in [(&b, "baseline"), (&c, "current")] {
        if info.cpu_model.is_none() {
            refuse(GateError::UnknownMachine { which }, &mut warnings)?;
        }
    }
    if let (Some(bm), Some(cm)) = (&b.cpu_model, &c.cpu_model)
        && bm != cm
    {
        let error = GateError::OtherMachine {
            what: "CPU model",
            baseline: bm.clone(),
            current: cm.clone(),
        };
        refuse(error, &mut warnings)?;
    }
    match (&b.cpu_signature, &c.cpu_signature) {
        (Some(bs), Some(cs)) if bs != cs => {
            let error = GateError::OtherMachine {
                what: "CPU signature",
                baseline: bs.clone(),
                current: cs.clone(),
            };
            refuse(error, &mut warnings)?;
        }
        (None, Some(_)) | (Some(_), None) => warnings.push(
            "one file records no CPU signature (written before it was recorded): the CPU model \
             matches, but the processor generation cannot be checked"
                .to_string(),
        ),
        _ => {}
    }
    if let (Some(bn), Some(cn)) = (b.logical_cpus, c.logical_cpus)
        && bn != cn
    {
        let error = GateError::OtherMachine {
            what: "logical CPU count",
            baseline: bn.to_string(),
            current: cn.to_string(),
        };
        refuse(error, &mut warnings)?;
    }
    let (bm, cm) = (&baseline.metadata, &current.metadata);
    for (what, bv, cv) in [
        ("SIMD level", &bm.simd, &cm.simd),
        ("profile", &bm.profile, &cm.profile),
    ] {
        if bv != cv {
            let error = GateError::OtherBuild {
                what,
                baseline: bv.clone(),
                current: cv.clone(),
            };
            refuse(error, &mut warnings)?;
        }
    }
    if baseline.config != current.config {
        let differences = config_differences(baseline, current);
        refuse(GateError::OtherConfig { differences }, &mut warnings)?;
    }
    if let Some(busy) = background_cpus(baseline).filter(|&b| b >= BUSY_BASELINE_CPUS) {
        warnings.push(format!(
            "the baseline was measured while other processes used {busy:.1} CPUs: the reference \
             slows down more than the kernels under load, so a quieter current run reads slower \
             than it is; refresh the baseline on a quiet machine (scripts/refresh-baseline.sh)"
        ));
    }
    if let (Some(br), Some(cr)) = (calibrated_rate(baseline), calibrated_rate(current))
        && let Some(why) = rates_differ(br, cr)
    {
        warnings.push(format!(
            "{why}; `gate` without --current measures A/B in that case"
        ));
    }
    for (info, which) in [(&b, "baseline"), (&c, "current")] {
        if info.git_dirty {
            warnings.push(format!(
                "the {which} run was measured with uncommitted changes (commit {})",
                short(&info.git_commit)
            ));
        }
    }
    Ok(warnings)
}

/// How far the calibrated single-thread FMA rates of a baseline and a current run may differ
/// (the faster over the slower, minus 1) before the reference normalisation is not trusted
/// across them. One machine class's calibrations on a quiet machine spread by up to 9.6% in
/// the committed results (GenuineIntel 6/167/1: 219.4-240.5 GFLOP/s within one hour; the
/// start and end of one sweep up to 8.6% apart; AuthenticAMD 25/1/1 90.1 and 92.7 in its
/// baseline), while a baseline at 175 GFLOP/s against runs at 140 (25%) made the
/// normalisation over-correct: 12% lets the machine's own drift through and nothing near that.
pub const RATE_TOLERANCE: f64 = 0.12;

/// The FMA rate of a sweep's calibrations (mean of the start and end), GFLOP/s.
pub fn calibrated_rate(file: &ResultsFile) -> Option<f64> {
    let rates: Vec<f64> = [&file.calibration.start, &file.calibration.end]
        .into_iter()
        .flatten()
        .map(|c| c.fma_gflops_1t)
        .filter(|g| g.is_finite() && *g > 0.0)
        .collect();
    (!rates.is_empty()).then(|| rates.iter().sum::<f64>() / rates.len() as f64)
}

/// Why the calibrated FMA rates `baseline` and `current` (GFLOP/s) are too far apart for the
/// reference normalisation ([`RATE_TOLERANCE`]), or `None` when they are close enough.
pub fn rates_differ(baseline: f64, current: f64) -> Option<String> {
    let (lo, hi) = (baseline.min(current), baseline.max(current));
    if !(lo > 0.0 && hi.is_finite()) || hi / lo - 1.0 <= RATE_TOLERANCE {
        return None;
    }
    Some(format!(
        "the baseline's calibrated FMA rate is {baseline:.1} GFLOP/s and this run's {current:.1} \
         ({:.2}x), more than the {:.0}% the machine drifts by on its own: dividing by the \
         reference workload would over-correct",
        current / baseline,
        RATE_TOLERANCE * 100.0
    ))
}

/// Other processes' CPU use, from the calibrations, above which a baseline is called busy:
/// the one threshold of a shared machine, the calibration's own.
pub const BUSY_BASELINE_CPUS: f64 = nbody_calibrate::SHARED_MACHINE_CPUS;

/// The most CPUs other processes used during the file's calibrations, if measured.
pub fn background_cpus(file: &ResultsFile) -> Option<f64> {
    [&file.calibration.start, &file.calibration.end]
        .into_iter()
        .flatten()
        .filter_map(|c| c.background_cpus)
        .reduce(f64::max)
}

/// The config keys whose values differ, e.g. "n, measure.samples".
fn config_differences(baseline: &ResultsFile, current: &ResultsFile) -> String {
    let to_value = |f: &ResultsFile| serde_json::to_value(&f.config).unwrap_or_default();
    let mut out = Vec::new();
    diff_keys("", &to_value(baseline), &to_value(current), &mut out);
    if out.is_empty() {
        "their values".to_string()
    } else {
        out.join(", ")
    }
}

fn diff_keys(prefix: &str, a: &serde_json::Value, b: &serde_json::Value, out: &mut Vec<String>) {
    match (a.as_object(), b.as_object()) {
        (Some(ao), Some(bo)) => {
            let mut keys: Vec<&String> = ao.keys().chain(bo.keys()).collect();
            keys.sort();
            keys.dedup();
            for k in keys {
                let (av, bv) = (ao.get(k), bo.get(k));
                if av != bv {
                    let name = format!("{prefix}{k}");
                    match (av, bv) {
                        (Some(av), Some(bv)) if av.is_object() && bv.is_object() => {
                            diff_keys(&format!("{name}."), av, bv, out)
                        }
                        _ => out.push(name),
                    }
                }
            }
        }
        _ if a != b => out.push(prefix.trim_end_matches('.').to_string()),
        _ => {}
    }
}

/// The first 10 characters of a commit hash.
pub(super) fn short(commit: &str) -> &str {
    prefix(commit, 10)
}

/// The first `chars` characters of `text` (a commit read from a file may hold anything).
pub fn prefix(text: &str, chars: usize) -> &str {
    text.char_indices()
        .nth(chars)
        .map_or(text, |(i, _)| &text[..i])
}
