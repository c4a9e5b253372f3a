//! One round of an external case: the set-up command, untimed warm-up runs, the launch
//! overhead of the empty run (wall timing), then one run per sample. A run that fails (exit
//! status, timeout, no match of `check`, of the time regex, of a phase or of `force_error`) is
//! kept as an error with the program's last lines of output, and the round goes on.

use super::process::{self, Finished, Launch};
use super::{Context, ExternalError, OVERHEAD_WARN};
use crate::experiment::measure::RoundSpec;
use nbody_engine::stats::median;
use nbody_records::config::MpiLaunch;
use nbody_records::external::placeholders::Vars;
use nbody_records::external::{External, ExternalRound, ExternalRun, SampleError, TimeSource};
use nbody_records::plan::Case;
use nbody_records::round::RoundOutcome;
use regex::Regex;
use std::collections::BTreeMap;
use std::path::Path;

/// Empty runs whose median is the launch overhead.
const EMPTY_RUNS: usize = 3;

/// The steps one run of `ext` simulates for `case`: its rule at the case's n (a weak-by-time
/// case multiplies them).
pub fn steps(ext: &External, case: &Case) -> u64 {
    ext.steps.at(case.n).saturating_mul(case.time_factor.max(1))
}

/// The placeholder values of `case`.
pub(crate) fn case_vars(ext: &External, case: &Case, context: &Context, workdir: &Path) -> Vars {
    let mut v = context.vars();
    v.set("n", case.n)
        .set("threads", case.threads)
        .set("ranks", case.ranks)
        .set("steps", steps(ext, case))
        .set("seed", case.seed)
        .set("scenario", case.scenario.name())
        .set("workdir", workdir.display());
    if let Some(t) = case.theta {
        v.set("theta", t);
    }
    v
}

/// `tokens` with the case's values, under the MPI launcher when the config has one.
fn launch(
    ext: &External,
    tokens: &[String],
    vars: &Vars,
    mpi: Option<&MpiLaunch>,
    ranks: usize,
) -> Result<Launch, ExternalError> {
    let placeholder = |source| ExternalError::Placeholder {
        name: ext.name.clone(),
        source,
    };
    let mut argv = Vec::new();
    if let Some(m) = mpi {
        argv.push(m.launcher.clone());
        argv.extend(m.args.iter().cloned());
        argv.push(m.rank_flag.clone());
        argv.push(ranks.to_string());
    }
    let env = ext
        .env
        .iter()
        .map(|(k, v)| Ok((k.clone(), vars.substitute(v)?)))
        .collect::<Result<Vec<_>, _>>()
        .map_err(placeholder)?;
    let mut program = vars.substitute_all(tokens).map_err(placeholder)?;
    // Under a launcher the program is the launcher's argument: it gets the path this process
    // resolves (the same one the check before the sweep found), not a lookup of the launcher's
    // own from the work directory. One not found stays as written and fails as a sample.
    if mpi.is_some()
        && let Some(first) = program.first_mut()
        && let Ok(found) = process::resolve(first, process::path_of(&env))
        && let Some(found) = found.to_str()
    {
        *first = found.to_string();
    }
    argv.extend(program);
    Ok(Launch { argv, env })
}

/// Measures one round of the external case `case`.
pub(crate) fn measure_round(
    ext: &External,
    case: &Case,
    spec: &RoundSpec,
    mpi: Option<&MpiLaunch>,
    context: &Context,
) -> Result<RoundOutcome, ExternalError> {
    let dir = super::workdir(&context.work_root, &case.key());
    nbody_engine::output::create_dir_all(&dir).map_err(|source| ExternalError::Workdir {
        path: dir.clone(),
        source,
    })?;
    let vars = case_vars(ext, case, context, &dir);
    let main = launch(ext, &ext.command, &vars, mpi, case.ranks)?;
    let mut round = ExternalRound::default();
    let steps = steps(ext, case);
    if !ext.setup.is_empty() {
        // The set-up is not the measured program: it runs without the launcher.
        let setup = launch(ext, &ext.setup, &vars, None, 1)?;
        if let Err(e) = checked_run(&setup, &dir, ext.timeout_s, None, false) {
            round.setup_error = Some(e.error);
            return Ok(outcome(ext, case, round, steps));
        }
    }
    for _ in 0..ext.warmup_runs {
        let _ = process::run(&main, &dir, ext.timeout_s);
    }
    let wall = matches!(ext.time, TimeSource::Wall(_));
    if wall {
        let empty_tokens = if ext.empty.is_empty() {
            vec!["true".to_string()]
        } else {
            ext.empty.clone()
        };
        let empty = launch(ext, &empty_tokens, &vars, mpi, case.ranks)?;
        let times: Vec<f64> = (0..EMPTY_RUNS)
            .filter_map(|_| process::run(&empty, &dir, ext.timeout_s).ok())
            .filter(|f| f.status.is_some_and(|s| s.success()))
            .map(|f| f.wall_s)
            .collect();
        round.launch_overhead_s = median(&times);
        if round.launch_overhead_s.is_none() {
            round.warnings.push(format!(
                "external `{}`: the empty run `{}` failed; the launch overhead is unknown",
                ext.name,
                empty.display()
            ));
        }
    }
    let compile = |re: &str| {
        Regex::new(re).map_err(|source| ExternalError::Regex {
            name: ext.name.clone(),
            regex: re.to_string(),
            source,
        })
    };
    let check = ext.check.as_deref().map(compile).transpose()?;
    let time = match &ext.time {
        TimeSource::Regex(t) => Some((compile(&t.regex)?, t.unit.seconds())),
        TimeSource::Wall(_) => None,
    };
    let error = ext.force_error.as_deref().map(compile).transpose()?;
    let energy = ext.energy.as_deref().map(compile).transpose()?;
    let phases = ext
        .phases
        .iter()
        .map(|(name, p)| Ok((name.as_str(), compile(&p.regex)?, p.unit.seconds())))
        .collect::<Result<Vec<_>, ExternalError>>()?;
    let reads_output = check.is_some()
        || time.is_some()
        || error.is_some()
        || energy.is_some()
        || !phases.is_empty();
    for _ in 0..spec.samples {
        let run = match checked_run(&main, &dir, ext.timeout_s, check.as_ref(), reads_output) {
            Err(e) => ExternalRun {
                wall_s: e.wall_s,
                reported_s: None,
                force_error: None,
                phases: BTreeMap::new(),
                energy_drift: None,
                error: Some(e.error),
            },
            Ok(done) => {
                let patterns = Patterns {
                    time: time.as_ref(),
                    error: error.as_ref(),
                    energy: energy.as_ref(),
                    phases: &phases,
                };
                sample(&main, &done, &patterns)
            }
        };
        round.runs.push(run);
    }
    let walls: Vec<f64> = round
        .runs
        .iter()
        .filter(|r| r.error.is_none())
        .map(|r| r.wall_s)
        .collect();
    if let (Some(o), Some(w)) = (round.launch_overhead_s, median(&walls)) {
        let share = o / w.max(1e-12);
        round.overhead_share = Some(share);
        if share > OVERHEAD_WARN {
            round.warnings.push(format!(
                "external `{}` ({}): launching an empty run takes {:.1} ms, {:.0}% of a sample's \
                 {:.1} ms; raise `steps` so that the program's work dominates",
                ext.name,
                case.key(),
                o * 1e3,
                share * 100.0,
                w * 1e3
            ));
        }
    }
    Ok(outcome(ext, case, round, steps))
}

struct Failed {
    wall_s: f64,
    error: SampleError,
}

/// Runs `launch`; an error unless it exited with status 0 and its output matches `check`. When
/// the output is searched by regular expressions (`reads_output`) it must also be short enough
/// to be read back whole.
fn checked_run(
    launch: &Launch,
    dir: &Path,
    timeout_s: f64,
    check: Option<&Regex>,
    reads_output: bool,
) -> Result<Finished, Failed> {
    let fail = |wall_s: f64, what: String, tail: Vec<String>| Failed {
        wall_s,
        error: SampleError {
            what,
            command: launch.display(),
            output_tail: tail,
        },
    };
    let done = process::run(launch, dir, timeout_s)
        .map_err(|e| fail(0.0, format!("cannot start it: {e}"), Vec::new()))?;
    match done.status {
        None => Err(fail(
            done.wall_s,
            format!("timed out after {timeout_s} s and was killed"),
            done.tail(),
        )),
        Some(s) if !s.success() => Err(fail(done.wall_s, format!("failed ({s})"), done.tail())),
        Some(_) => match (check, done.too_long().filter(|_| reads_output)) {
            (_, Some(why)) => Err(fail(done.wall_s, why, done.tail())),
            (Some(re), None)
                if !re.is_match(&done.stdout.text) && !re.is_match(&done.stderr.text) =>
            {
                Err(fail(
                    done.wall_s,
                    format!("its output does not match the check `{}`", re.as_str()),
                    done.tail(),
                ))
            }
            _ => Ok(done),
        },
    }
}

/// The sample of a successful run: its time (wall, or the last match of the time regex), the
/// force error and the phase times it printed.
/// What a run's output is read for: its time (unit in seconds), force error, total energy and
/// phases (name, pattern, unit), each when the entry gives it.
struct Patterns<'a> {
    time: Option<&'a (Regex, f64)>,
    error: Option<&'a Regex>,
    energy: Option<&'a Regex>,
    phases: &'a [(&'a str, Regex, f64)],
}

fn sample(launch: &Launch, done: &Finished, patterns: &Patterns) -> ExternalRun {
    let Patterns {
        time,
        error,
        energy,
        phases,
    } = *patterns;
    let fail = |what: String| ExternalRun {
        wall_s: done.wall_s,
        reported_s: None,
        force_error: None,
        phases: BTreeMap::new(),
        energy_drift: None,
        error: Some(SampleError {
            what,
            command: launch.display(),
            output_tail: done.tail(),
        }),
    };
    let reported_s = match time {
        None => None,
        Some((re, unit)) => match last_number(re, done) {
            Some(Ok(t)) if t.is_finite() && t > 0.0 => Some(t * unit),
            Some(Ok(t)) => return fail(format!("it printed the time {t}, not a duration")),
            Some(Err(text)) => {
                return fail(format!(
                    "the time regex `{}` matched `{text}`, which is not a number",
                    re.as_str()
                ));
            }
            None => {
                return fail(format!(
                    "its output does not match the time regex `{}`",
                    re.as_str()
                ));
            }
        },
    };
    let force_error = match error {
        None => None,
        Some(re) => match re
            .captures_iter(&(done.stdout.text.clone() + &done.stderr.text))
            .last()
        {
            None => {
                return fail(format!(
                    "its output does not match the force_error regex `{}`",
                    re.as_str()
                ));
            }
            Some(c) => {
                let num = |i: usize| c.get(i).and_then(|m| m.as_str().trim().parse::<f64>().ok());
                let printed = match (num(1), c.get(2).map(|_| num(2))) {
                    (Some(med), None) => Some([med, med]),
                    (Some(med), Some(Some(max))) => Some([med, max]),
                    _ => None,
                };
                match printed.map(|e| (e, nbody_records::vet::force_error(e))) {
                    Some((_, Ok(e))) => Some(e),
                    Some((e, Err(why))) => {
                        return fail(format!(
                            "it printed the force error [{}, {}]: {why}",
                            e[0], e[1]
                        ));
                    }
                    None => {
                        return fail(format!(
                            "the force_error regex `{}` matched no number",
                            re.as_str()
                        ));
                    }
                }
            }
        },
    };
    let mut phase_s = BTreeMap::new();
    for (name, re, unit) in phases {
        let t = match last_number(re, done) {
            // Zero is a duration: a phase the run did not enter (no frame written, say).
            Some(Ok(t)) => match nbody_records::vet::phase_time(t * unit, done.wall_s) {
                Ok(t) => t,
                Err(why) => {
                    return fail(format!(
                        "it printed the phase `{name}` as {t} ({:e} s): {why}",
                        t * unit
                    ));
                }
            },
            Some(Err(text)) => {
                return fail(format!(
                    "the phase `{name}` regex `{}` matched `{text}`, which is not a number",
                    re.as_str()
                ));
            }
            None => {
                return fail(format!(
                    "its output does not match the phase `{name}` regex `{}`",
                    re.as_str()
                ));
            }
        };
        phase_s.insert(name.to_string(), t);
    }
    let energy_drift = match energy.map(|re| energy_drift(re, done)) {
        None => None,
        Some(Ok(drift)) => drift,
        Some(Err(why)) => return fail(why),
    };
    ExternalRun {
        wall_s: done.wall_s,
        reported_s,
        force_error,
        phases: phase_s,
        energy_drift,
        error: None,
    }
}

/// The relative energy drift of a run, as the engine's runs compute theirs: from the total
/// energy at its start (the first match of `re` in its standard output, else standard error)
/// to its end (the last match); `None` when the start energy is zero (relative to nothing).
fn energy_drift(re: &Regex, done: &Finished) -> Result<Option<f64>, String> {
    let text = [&done.stdout.text, &done.stderr.text]
        .into_iter()
        .find(|t| re.is_match(t))
        .ok_or_else(|| {
            format!(
                "its output does not match the energy regex `{}`",
                re.as_str()
            )
        })?;
    let values: Vec<&str> = re
        .captures_iter(text)
        .filter_map(|c| Some(c.get(1)?.as_str().trim()))
        .collect();
    let number = |m: &str| match m.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!(
            "the energy regex `{}` matched `{m}`, which is not a finite number",
            re.as_str()
        )),
    };
    let [first, .., last] = values.as_slice() else {
        return Err(format!(
            "its output matches the energy regex `{}` once: the drift needs the energy at the \
             start and at the end of the run",
            re.as_str()
        ));
    };
    let (e0, e1) = (number(first)?, number(last)?);
    Ok((e0 != 0.0).then(|| (e1 - e0) / e0.abs()))
}

/// The first group of the last match in standard output (else standard error), parsed.
fn last_number(re: &Regex, done: &Finished) -> Option<Result<f64, String>> {
    let text = [&done.stdout.text, &done.stderr.text]
        .into_iter()
        .find(|t| re.is_match(t))?;
    let caps = re.captures_iter(text).last()?;
    let m = caps.get(1)?.as_str().trim();
    Some(m.parse::<f64>().map_err(|_| m.to_string()))
}

/// The round as the results file keeps it: a sample per successful run, its time per step.
fn outcome(ext: &External, case: &Case, round: ExternalRound, steps: u64) -> RoundOutcome {
    let per_step = |r: &ExternalRun| r.reported_s.unwrap_or(r.wall_s) / steps as f64;
    let ok: Vec<&ExternalRun> = round.runs.iter().filter(|r| r.error.is_none()).collect();
    let samples_s: Vec<f64> = ok.iter().map(|r| per_step(r)).collect();
    let errors: Vec<[f64; 2]> = ok.iter().filter_map(|r| r.force_error).collect();
    // The round's drift is its worst run's, as the check of the case is against its worst.
    let energy_drift = ok
        .iter()
        .filter_map(|r| r.energy_drift)
        .max_by(|a, b| a.abs().total_cmp(&b.abs()));
    let force_error = (!errors.is_empty()).then(|| {
        let med: Vec<f64> = errors.iter().map(|e| e[0]).collect();
        [
            median(&med).unwrap_or(0.0),
            errors.iter().map(|e| e[1]).fold(0.0, f64::max),
        ]
    });
    RoundOutcome {
        steps_per_sample: steps,
        steps: steps * samples_s.len() as u64,
        samples_s,
        step_ns: Vec::new(),
        warmup_steps: steps * ext.warmup_runs as u64,
        // None of our timers or counters ran: not measured, never zero.
        phases: None,
        work: None,
        pairs_interacting: None,
        energy_drift,
        force_error,
        n: case.n,
        clock_overhead: round.overhead_share.unwrap_or(0.0),
        reference_s: Vec::new(),
        initial_work: None,
        mpi: None,
        external: Some(round),
        job: None,
    }
}
