//! Value parsers of the command line's options: counts, times and fractions checked where
//! clap reads them, so that a bad value is refused with its reason before anything runs.

pub(crate) fn parse_count(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(0) => Err("must be at least 1".into()),
        Ok(v) => Ok(v),
        Err(_) => Err(format!("`{s}` is not a whole number")),
    }
}

pub(crate) fn parse_warmup(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(v) if v > 1_000_000 => Err(format!(
            "{v} is more than 1000000, the most this option takes"
        )),
        Ok(v) => Ok(v),
        Err(_) => Err(format!("`{s}` is not a whole number")),
    }
}

/// A count of at least 1 and at most `MAX`, for sizes that allocate or run in proportion.
pub(crate) fn parse_count_at_most<const MAX: usize>(s: &str) -> Result<usize, String> {
    match parse_count(s)? {
        v if v > MAX => Err(format!(
            "{v} is more than {MAX}, the most this option takes"
        )),
        v => Ok(v),
    }
}

pub(crate) fn parse_threads(s: &str) -> Result<usize, String> {
    match parse_count(s)? {
        t if t > nbody_engine::run::MAX_THREADS => Err(format!(
            "{t} threads is more than {} (each is an OS thread with its own stack)",
            nbody_engine::run::MAX_THREADS
        )),
        t => Ok(t),
    }
}

pub(crate) fn parse_float(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err("must be finite".into())
    }
}

pub(crate) fn parse_positive(s: &str) -> Result<f64, String> {
    let v = parse_float(s)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(format!("must be greater than 0 (got {v})"))
    }
}

/// A gate threshold: a fraction from 0 to `gate::MAX_THRESHOLD`.
pub(crate) fn parse_threshold(s: &str) -> Result<f64, String> {
    let v = parse_non_negative(s)?;
    nbody_harness::gate::check_threshold(v).map_err(|e| e.to_string())?;
    Ok(v)
}

/// A/B rounds per build: even, from 2 to `gate::ab::MAX_ROUNDS`.
pub(crate) fn parse_ab_rounds(s: &str) -> Result<usize, String> {
    let v = s
        .parse::<usize>()
        .map_err(|_| format!("`{s}` is not a whole number"))?;
    nbody_harness::gate::ab::check_rounds(v).map_err(|e| e.to_string())?;
    Ok(v)
}

/// Seconds, more than 0 and at most a week.
pub(crate) fn parse_timeout(s: &str) -> Result<f64, String> {
    const WEEK_S: f64 = 7.0 * 24.0 * 3600.0;
    match parse_positive(s)? {
        v if v > WEEK_S => Err(format!("{v} s is more than a week ({WEEK_S} s)")),
        v => Ok(v),
    }
}

pub(crate) fn parse_non_negative(s: &str) -> Result<f64, String> {
    let v = parse_float(s)?;
    if v >= 0.0 {
        Ok(v)
    } else {
        Err(format!("must be 0 or greater (got {v})"))
    }
}
