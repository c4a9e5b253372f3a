//! The keys of a sweep config and the forms each one takes, so that a parse error names the key
//! it is about and what would have been accepted (toml's own message gives a line and a Rust
//! type, such as "expected usize", and no key).

/// The dotted key a parse error at byte `offset` of `text` is about: the nearest `key =` at or
/// above the offset, prefixed by the table header it sits under.
pub(crate) fn key_at(text: &str, offset: usize) -> Option<String> {
    let upto = &text[..line_end(text, offset)];
    let mut key = None;
    for line in upto.lines().rev() {
        let line = line.trim();
        if let Some(header) = table_header(line) {
            return Some(match key {
                Some(k) => format!("{header}.{k}"),
                // The error is on the header itself, or on a table with no key yet.
                None => header.to_string(),
            });
        }
        if key.is_none() {
            key = assigned_key(line).map(str::to_string);
        }
    }
    key
}

/// The end of the line that holds `offset` (so that a key on the error's own line counts).
fn line_end(text: &str, offset: usize) -> usize {
    let offset = offset.min(text.len());
    let mut end = text[offset..].find('\n').map_or(text.len(), |i| offset + i);
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    end
}

/// `measure` for `[measure]` (and `[[measure]]`).
fn table_header(line: &str) -> Option<&str> {
    let inner = line.strip_prefix('[')?;
    let inner = inner.strip_prefix('[').unwrap_or(inner);
    let end = inner.find(']')?;
    Some(inner[..end].trim())
}

/// `samples` for `samples = 6`, nothing for a line that assigns no bare key.
fn assigned_key(line: &str) -> Option<&str> {
    let (key, _) = line.split_once('=')?;
    let key = key.trim();
    let bare = !key.is_empty()
        && key
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "_-.".contains(c));
    bare.then_some(key)
}

/// The forms `n` takes.
pub(crate) const COUNTS_FORMS: &str = "a list of whole numbers, such as n = [1000, 2000], or a \
    geometric range, such as n = { from = 1000, to = 32000, factor = 2 }";

/// What a key accepts, as a user would write it; `None` for a key the config does not have.
pub fn allowed(key: &str) -> Option<&'static str> {
    Some(match key {
        "name" => {
            "a plain file name (letters, digits, `-`, `_`, `.`; not starting with `.`), such as name = \"strong\""
        }
        "study" => "one of \"strong\", \"weak\", \"complexity\", \"cartesian\"",
        "scenarios" => {
            "a list of scenario names, such as scenarios = [\"lj-box\", \"galaxy\"] (`nbody-bench list` shows them)"
        }
        "kernels" => {
            "a list of kernel names, such as kernels = [\"naive\", \"cell-list\"] (`nbody-bench list` shows them)"
        }
        "n" | "n.from" | "n.to" | "n.factor" => COUNTS_FORMS,
        "threads" => "a list of thread counts of at least 1, such as threads = [1, 2]",
        "seeds" => "a list of whole numbers of at least 0, such as seeds = [1, 2, 3]",
        "theta" => "a list of opening angles of at least 0, such as theta = [0.5, 0.7]",
        "multipole" => {
            "a list of expansion orders, such as multipole = [\"monopole\", \"quadrupole\"]"
        }
        "order" => "a list of fmm expansion orders from 1 to 8, such as order = [3, 4, 6]",
        "skin" => "a list of lengths above 0 in the scenario's unit, such as skin = [0.003, 0.012]",
        "precision" => "\"f32\" or \"f64\"",
        "out" => "a directory, as a string, such as out = \"results\"",
        "initial" => {
            "a file, as a string, such as initial = \"bodies.txt\": `nbody-bench export --format text` output, or one body a line `m x y z vx vy vz` (3-D, # comments); not with [[external]], [scheduler] or a weak study, and `n` must be the file's"
        }
        "measure" => {
            "a table [measure] with warmup_s, samples, min_sample_s, rounds, budget_s, max_energy_drift, force_error_sample, reference_s"
        }
        "measure.warmup_s" => "seconds of at least 0, such as warmup_s = 0.05",
        "measure.samples" => "a whole number of at least 1, such as samples = 10",
        "measure.min_sample_s" => "seconds above 0, such as min_sample_s = 0.01",
        "measure.rounds" => "a whole number of at least 1, such as rounds = 2",
        "measure.budget_s" => "seconds of at least 0 (0 = no budget), such as budget_s = 600",
        "measure.max_energy_drift" => "a relative drift above 0, such as max_energy_drift = 0.05",
        "measure.force_error_sample" => {
            "a whole number of particles of at least 0 (0 = off), such as force_error_sample = 200"
        }
        "measure.reference_s" => "seconds of at least 0 (0 = off), such as reference_s = 0.01",
        "weak" => "a table [weak] with rule and base_n",
        "weak.rule" => "one of \"cost-model\", \"linear\", \"sqrt\", \"time\"",
        "weak.base_n" => "a whole number of particles of at least 1, such as base_n = 10000",
        "mpi" => {
            "a table [mpi] with ranks and optionally launcher, args, rank_flag, decomp, steps, warmup_steps"
        }
        "mpi.launcher" => "a program name, as a string, such as launcher = \"mpirun\"",
        "mpi.ranks" => "a list of rank counts of at least 1, such as ranks = [1, 2, 4]",
        "mpi.args" => "a list of strings, such as args = [\"--oversubscribe\"]",
        "mpi.rank_flag" => {
            "the launcher's option for the rank count, as a string, such as rank_flag = \"-n\""
        }
        "mpi.decomp" => "a list of decompositions, such as decomp = [\"allgather\", \"domain\"]",
        "mpi.steps" => "a whole number of timed steps per launch, such as steps = 100",
        "mpi.warmup_steps" => "a whole number of untimed steps, such as warmup_steps = 10",
        "scheduler" => {
            "a table [scheduler] with kind and optionally partition, account, time_limit, sbatch_args, poll_s"
        }
        "scheduler.kind" => "\"slurm\"",
        "scheduler.partition" => "a partition name, such as partition = \"short\"",
        "scheduler.account" => "an account name, such as account = \"proj42\"",
        "scheduler.time_limit" => {
            "a Slurm time limit per job, above zero: minutes, MM:SS, HH:MM:SS or D-HH[:MM[:SS]], such as time_limit = \"10:00\""
        }
        "scheduler.sbatch_args" => "a list of strings, such as sbatch_args = [\"--qos=short\"]",
        "scheduler.poll_s" => "seconds above 0, at most 3600, such as poll_s = 5",
        _ => return None,
    })
}

/// `study` for "missing field `study`".
fn missing_field(message: &str) -> Option<&str> {
    let rest = message.strip_prefix("missing field `")?;
    rest.split('`').next()
}

/// " at line L, column C" for a parse error span.
pub fn location(text: &str, offset: usize) -> String {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.len() - before.rfind('\n').map(|i| i + 1).unwrap_or(0) + 1;
    format!(" (line {line}, column {col})")
}

/// A parse error's message with its key and the key's allowed forms.
pub fn describe(text: &str, message: &str, span: Option<std::ops::Range<usize>>) -> String {
    let message = message.trim_end();
    let Some(span) = span else {
        return message.to_string();
    };
    let at = location(text, span.start);
    if let Some(field) = missing_field(message) {
        // The span is the whole table that lacks the field: a header or the document.
        let line = text[span.start.min(text.len())..]
            .lines()
            .next()
            .unwrap_or("");
        let key = match table_header(line.trim()) {
            Some(table) => format!("{table}.{field}"),
            None => field.to_string(),
        };
        return match allowed(&key) {
            Some(forms) => format!("`{key}` is missing{at}; it must be {forms}"),
            None => format!("`{key}` is missing{at}"),
        };
    }
    let Some(key) = key_at(text, span.start) else {
        return format!("{message}{at}");
    };
    match allowed(&key) {
        // A message of our own deserializers already says what the key must be.
        _ if message.starts_with("must be") => format!("`{key}` {message}{at}"),
        Some(forms) => format!("`{key}`: {message}{at}; `{key}` must be {forms}"),
        None => format!("`{key}`: {message}{at}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_key_under_its_table() {
        let text = "name = \"a\"\n[measure]\nwarmup_s = 0.1\nsamples = \"6\"\n";
        let at = text.find("\"6\"").unwrap();
        assert_eq!(key_at(text, at).as_deref(), Some("measure.samples"));
        let at = text.find("\"a\"").unwrap();
        assert_eq!(key_at(text, at).as_deref(), Some("name"));
    }

    #[test]
    fn finds_the_key_of_a_multi_line_list() {
        let text = "threads = [\n  1,\n  \"2\",\n]\n";
        let at = text.find("\"2\"").unwrap();
        assert_eq!(key_at(text, at).as_deref(), Some("threads"));
    }

    #[test]
    fn every_key_of_the_config_has_its_forms() {
        // Every field a config can hold, from the types themselves: a new field without its
        // forms fails here.
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/configs/weak-mpi.toml"
        ))
        .unwrap();
        let config: super::super::config::SweepConfig = toml::from_str(&text).unwrap();
        let mut full = config.clone();
        full.precision = Some(crate::scenario::Precision::F32);
        full.n = Some(super::super::config::Counts::List(vec![10]));
        let value = toml::Value::try_from(&full).unwrap();
        let mut keys = Vec::new();
        for (k, v) in value.as_table().unwrap() {
            keys.push(k.clone());
            if let Some(t) = v.as_table() {
                keys.extend(t.keys().map(|inner| format!("{k}.{inner}")));
            }
        }
        assert!(keys.iter().any(|k| k == "mpi.ranks"), "{keys:?}");
        assert!(keys.iter().any(|k| k == "measure.reference_s"), "{keys:?}");
        for key in keys {
            assert!(allowed(&key).is_some(), "no allowed forms for `{key}`");
        }
    }

    #[test]
    fn a_missing_field_is_named_with_its_table() {
        let text = "name = \"a\"\n[weak]\nrule = \"linear\"\n";
        let m = describe(text, "missing field `study`", Some(0..text.len()));
        assert!(m.starts_with("`study` is missing"), "{m}");
        let at = text.find("[weak]").unwrap();
        let m = describe(text, "missing field `base_n`", Some(at..text.len()));
        assert!(m.starts_with("`weak.base_n` is missing"), "{m}");
        assert!(m.contains("a whole number of particles"), "{m}");
    }

    #[test]
    fn a_type_error_names_key_and_forms() {
        let text = "[measure]\nsamples = -1\n";
        let at = text.find("-1").unwrap();
        let m = describe(
            text,
            "invalid value: integer `-1`, expected usize",
            Some(at..at + 2),
        );
        assert!(m.starts_with("`measure.samples`: invalid value"), "{m}");
        assert!(m.contains("(line 2, column 11)"), "{m}");
        assert!(m.contains("must be a whole number of at least 1"), "{m}");
    }
}
