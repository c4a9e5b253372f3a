//! The one reader of the history folder's JSON Lines files: the records (`<class>.jsonl`,
//! [`super::store`]) and the gate verdicts (`<class>.gate.jsonl`, [`super::verdicts`]).
//! `history`, `publish`, `export-results` and the appenders all read through here, so that
//! they agree on what a line is, and one bad line costs that line only:
//!
//! - the file is read as bytes and cut at newlines; a line that is not UTF-8 is that line's
//!   problem, not the file's;
//! - a line is of a kind by the `schema` field of its JSON object, never by its text (a line
//!   written with spaces, as Python's `json.dumps` writes, or with its keys in another order,
//!   is the same record);
//! - a line of the kind is read only when every field it needs is there, its values are ones a
//!   measurement gives ([`Line::problem`]) and it names the class of its file.
//!
//! Every line that is not read is kept as a [`BadLine`]: its number and why.

use serde::de::DeserializeOwned;
use std::path::Path;

/// A line of a history or verdict file that was left out.
#[derive(Clone, Debug, PartialEq)]
pub struct BadLine {
    /// Line number in the file, from 1.
    pub line: usize,
    /// What is wrong with it: not UTF-8, not JSON, another schema, a field missing, a value no
    /// measurement gives, another class than its file's.
    pub problem: String,
}

impl BadLine {
    /// The warning every reader prints for it: the file, the line, why, and that only the
    /// line is lost.
    pub fn warning(&self, path: &Path) -> String {
        format!(
            "{} line {}: {}; the line is left out",
            path.display(),
            self.line,
            self.problem
        )
    }
}

/// A line of one of the history folder's JSON Lines files: the schema that marks it, the file
/// name of its class, and what makes a parsed line unusable.
pub(crate) trait Line: DeserializeOwned {
    /// The `schema` field of every line of the kind.
    const SCHEMA: &'static str;
    /// "a history record", "a gate verdict line".
    const WHAT: &'static str;
    /// What a file of the kind is named after its class: `<class>` then this.
    const SUFFIX: &'static str;
    /// The machine class the line is of.
    fn class(&self) -> &str;
    /// Why the line, although it parsed, holds nothing a reader can use (a median that is not
    /// a time); `None` when it is sound.
    fn problem(&self) -> Option<String>;
}

/// What a file's lines held.
#[derive(Debug)]
pub(crate) struct Lines<T> {
    /// The lines read, in file order.
    pub good: Vec<T>,
    /// The lines left out, with their numbers.
    pub bad: Vec<BadLine>,
    /// Lines that carry the kind's schema, read or left out: a file with one is a file of the
    /// kind, however damaged.
    pub tagged: usize,
}

/// The class a file at `path` holds: its name without `T::SUFFIX`; `None` for a file named
/// otherwise (a pipe, a copy under another name), whose lines are read under their own class.
pub(crate) fn class_of_file<T: Line>(path: &Path) -> Option<String> {
    let name = path.file_name()?.to_str()?;
    let class = name.strip_suffix(T::SUFFIX)?;
    // `<class>.gate.jsonl` ends with `.jsonl` too, but is not a record file.
    (!class.is_empty() && !class.ends_with(".gate")).then(|| class.to_string())
}

/// Every line of the file at `path` that is a sound `T` of the file's class, and every one that
/// is not with its number. A missing file holds none.
pub(crate) fn read_lines<T: Line>(path: &Path) -> std::io::Result<Lines<T>> {
    match nbody_engine::input::read_file_bytes(path) {
        Ok(bytes) => Ok(parse_lines(&bytes, class_of_file::<T>(path).as_deref())),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Lines {
            good: Vec::new(),
            bad: Vec::new(),
            tagged: 0,
        }),
        Err(e) => Err(e),
    }
}

/// The lines of `bytes` (see [`read_lines`]); `class`, when given, is the one every line must
/// name.
pub(crate) fn parse_lines<T: Line>(bytes: &[u8], class: Option<&str>) -> Lines<T> {
    let mut out = Lines {
        good: Vec::new(),
        bad: Vec::new(),
        tagged: 0,
    };
    for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
        if line.iter().all(u8::is_ascii_whitespace) {
            continue;
        }
        let (tagged, read) = parse_line::<T>(line, class);
        out.tagged += tagged as usize;
        match read {
            Ok(t) => out.good.push(t),
            Err(problem) => out.bad.push(BadLine {
                line: i + 1,
                problem,
            }),
        }
    }
    out
}

/// One line: whether it carries `T`'s schema, and the `T` it is or why it is not one.
fn parse_line<T: Line>(line: &[u8], class: Option<&str>) -> (bool, Result<T, String>) {
    let text = match std::str::from_utf8(line) {
        Ok(text) => text,
        Err(e) => {
            let problem = format!(
                "not UTF-8 text (an invalid byte at column {})",
                e.valid_up_to() + 1
            );
            return (false, Err(problem));
        }
    };
    let value: serde_json::Value = match serde_json::from_str(text) {
        Ok(v) => v,
        Err(e) => return (false, Err(format!("not {} ({e})", T::WHAT))),
    };
    match value.get("schema").and_then(|s| s.as_str()) {
        Some(s) if s == T::SCHEMA => {}
        Some(s) => {
            let problem = format!("schema `{s}`, this version reads `{}`", T::SCHEMA);
            return (false, Err(problem));
        }
        None => {
            let problem = format!("not {}: it has no `schema` field", T::WHAT);
            return (false, Err(problem));
        }
    }
    let read = match serde_json::from_value::<T>(value) {
        Err(e) => Err(format!(
            "not {}: a field is missing or wrong ({e})",
            T::WHAT
        )),
        Ok(t) => match (t.problem(), class) {
            (Some(p), _) => Err(format!("{}, but {p}", T::WHAT)),
            (None, Some(class)) if t.class() != class => Err(format!(
                "{} of machine class `{}` in the file of class `{class}` (a file holds the \
                 lines of the class it is named after, `<class>{}`)",
                T::WHAT,
                t.class(),
                T::SUFFIX
            )),
            (None, _) => Ok(t),
        },
    };
    (true, read)
}

#[cfg(test)]
mod tests;
