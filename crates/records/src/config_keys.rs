//! The keys of a config, each written once: the doc comment of its field says what it means,
//! what it accepts and how it is set (`documented_keys!`), and from that come the config
//! reference page, the example config that sets every key, and the parse errors, which name
//! the key and what would have been accepted (toml's own message gives a line and a Rust type,
//! such as "expected usize", and no key).
//!
//! A field's doc comment is three paragraphs: what the key means; "Accepts ..." with its forms;
//! "Example: `KEY = VALUE`", a line of TOML. A field that holds a table (`[measure]`) has the
//! first only: its forms are its table's keys.

/// A field of a config table and its doc comment, as `documented_keys!` records them.
#[derive(Clone, Copy, Debug)]
pub struct KeyDoc {
    /// The key as written in TOML: the field's name.
    pub name: &'static str,
    /// The field's doc comment, one line of it a line here.
    pub doc: &'static str,
}

/// Declares a config table (a struct) and, beside it, `KEYS`: each field's name and doc comment.
/// Field attributes other than `serde(...)` are not accepted, so that every one is seen here.
macro_rules! documented_keys {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            $(
                $(#[doc = $doc:literal])*
                $(#[serde $serde:tt])*
                $field_vis:vis $field:ident : $ty:ty
            ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        $vis struct $name {
            $(
                $(#[doc = $doc])*
                $(#[serde $serde])*
                $field_vis $field : $ty
            ),*
        }

        impl $name {
            /// Every key of this table with its field's doc comment.
            pub const KEYS: &'static [$crate::config_keys::KeyDoc] = &[$(
                $crate::config_keys::KeyDoc {
                    name: stringify!($field),
                    doc: concat!($($doc, "\n",)* ""),
                }
            ),*];
        }
    };
}
pub(crate) use documented_keys;

/// Whether a key holds a table, and how many.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Holds {
    /// A value: a number, a string, a list, an inline table.
    Value,
    /// One table (`[measure]`).
    Table,
    /// An array of tables (`[[external]]`).
    Tables,
}

/// One key of a config, with what its doc comment says.
#[derive(Clone, Debug, PartialEq)]
pub struct Key {
    /// The dotted key: `name`, `measure.samples`, `external.command`.
    pub dotted: String,
    /// What it means: the doc comment's first paragraph.
    pub meaning: String,
    /// What it accepts: the "Accepts" paragraph without that word, or the keys of the table
    /// it holds.
    pub forms: String,
    /// A line of TOML that sets it (in its table, for a table's key); `None` for a table.
    pub example: Option<String>,
    /// Whether it holds a table.
    pub holds: Holds,
}

/// A config's top-level table and the tables it holds, by the key that holds them.
pub struct Tables<'a> {
    /// The top level's keys.
    pub top: &'a [KeyDoc],
    /// Each table: the key holding it, its keys, and whether it is an array of tables.
    pub nested: &'a [(&'a str, &'a [KeyDoc], bool)],
}

impl Tables<'_> {
    /// Every key, the top level's first, each table's after it under the table's name.
    pub fn keys(&self) -> Vec<Key> {
        let mut out = Vec::new();
        for doc in self.top {
            let nested = self.nested.iter().find(|(name, _, _)| *name == doc.name);
            out.push(match nested {
                None => key_of("", doc, Holds::Value),
                Some((name, keys, array)) => {
                    let names: Vec<&str> = keys.iter().map(|k| k.name).collect();
                    let (holds, forms) = if *array {
                        (
                            Holds::Tables,
                            format!("one [[{name}]] table each, with {}", names.join(", ")),
                        )
                    } else {
                        (
                            Holds::Table,
                            format!("a table [{name}] with {}", names.join(", ")),
                        )
                    };
                    Key {
                        forms,
                        ..key_of("", doc, holds)
                    }
                }
            });
        }
        for (name, keys, _) in self.nested {
            out.extend(keys.iter().map(|doc| key_of(name, doc, Holds::Value)));
        }
        out
    }
}

/// The key `doc` describes, under `table` ("" for the top level).
fn key_of(table: &str, doc: &KeyDoc, holds: Holds) -> Key {
    let dotted = match table {
        "" => doc.name.to_string(),
        t => format!("{t}.{}", doc.name),
    };
    let paragraphs = paragraphs(doc.doc);
    let mut key = Key {
        dotted,
        meaning: paragraphs.first().cloned().unwrap_or_default(),
        forms: String::new(),
        example: None,
        holds,
    };
    for p in &paragraphs[1.min(paragraphs.len())..] {
        if let Some(forms) = p.strip_prefix("Accepts ") {
            key.forms = forms.trim_end_matches('.').to_string();
        } else if let Some(example) = p.strip_prefix("Example: ") {
            key.example = Some(example.trim_matches('`').to_string());
        }
    }
    key
}

/// A doc comment's paragraphs, each one line (its lines joined by spaces).
fn paragraphs(doc: &str) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    let mut open = false;
    for line in doc.lines().map(str::trim) {
        if line.is_empty() {
            open = false;
            continue;
        }
        match out.last_mut() {
            Some(last) if open => {
                last.push(' ');
                last.push_str(line);
            }
            _ => {
                out.push(line.to_string());
                open = true;
            }
        }
    }
    out
}

/// What `dotted` accepts: its own forms, or those of the key whose inline table it is in
/// (`n.from` is part of `n`).
pub fn forms<'a>(keys: &'a [Key], dotted: &str) -> Option<&'a str> {
    let find = |k: &str| keys.iter().find(|key| key.dotted == k);
    let key = find(dotted).or_else(|| {
        let (outer, _) = dotted.split_once('.')?;
        find(outer).filter(|k| k.holds == Holds::Value)
    })?;
    Some(&key.forms)
}

/// What the field `name` of a table accepts, for a deserializer's message ("must be ...").
pub fn forms_of(table: &[KeyDoc], name: &str) -> String {
    let doc = table.iter().find(|k| k.name == name);
    doc.map(|d| key_of("", d, Holds::Value).forms)
        .unwrap_or_default()
}

/// A config that sets every key to its example: the top level's, then each table's under its
/// header.
pub fn example_config(keys: &[Key]) -> String {
    let mut out = String::new();
    for key in keys.iter().filter(|k| !k.dotted.contains('.')) {
        if let Some(line) = &key.example {
            out += &format!("{line}\n");
        }
    }
    for table in keys.iter().filter(|k| k.holds != Holds::Value) {
        out += &match table.holds {
            Holds::Tables => format!("\n[[{}]]\n", table.dotted),
            _ => format!("\n[{}]\n", table.dotted),
        };
        let prefix = format!("{}.", table.dotted);
        for key in keys.iter().filter(|k| k.dotted.starts_with(&prefix)) {
            if let Some(line) = &key.example {
                out += &format!("{line}\n");
            }
        }
    }
    out
}

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

/// A parse error's message with its key (one of `keys`) and the forms the key accepts.
pub fn describe(
    keys: &[Key],
    text: &str,
    message: &str,
    span: Option<std::ops::Range<usize>>,
) -> String {
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
        return match forms(keys, &key) {
            Some(forms) => format!("`{key}` is missing{at}; it must be {forms}"),
            None => format!("`{key}` is missing{at}"),
        };
    }
    let Some(key) = key_at(text, span.start) else {
        return format!("{message}{at}");
    };
    match forms(keys, &key) {
        // A message of our own deserializers already says what the key must be.
        _ if message.starts_with("must be") => format!("`{key}` {message}{at}"),
        Some(forms) => format!("`{key}`: {message}{at}; `{key}` must be {forms}"),
        None => format!("`{key}`: {message}{at}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    documented_keys! {
        /// A table for the tests.
        #[derive(serde::Deserialize)]
        #[allow(dead_code)]
        struct Inner {
            /// What a means,
            /// over two lines.
            ///
            /// Accepts a whole number, such as a = 1.
            ///
            /// Example: `a = 2`
            #[serde(default)]
            a: u32,
        }
    }

    documented_keys! {
        /// The top level for the tests.
        #[derive(serde::Deserialize)]
        #[allow(dead_code)]
        struct Outer {
            /// A name.
            ///
            /// Accepts a string.
            ///
            /// Example: `name = "x"`
            name: String,
            /// The inner table.
            inner: Inner,
        }
    }

    fn test_keys() -> Vec<Key> {
        let nested: &[(&str, &[KeyDoc], bool)] = &[("inner", Inner::KEYS, false)];
        Tables {
            top: Outer::KEYS,
            nested,
        }
        .keys()
    }

    #[test]
    fn a_doc_comment_is_a_meaning_its_forms_and_an_example() {
        let keys = test_keys();
        let dotted: Vec<&str> = keys.iter().map(|k| k.dotted.as_str()).collect();
        assert_eq!(dotted, ["name", "inner", "inner.a"]);
        let a = &keys[2];
        assert_eq!(a.meaning, "What a means, over two lines.");
        assert_eq!(a.forms, "a whole number, such as a = 1");
        assert_eq!(a.example.as_deref(), Some("a = 2"));
        assert_eq!(keys[1].holds, Holds::Table);
        assert_eq!(keys[1].forms, "a table [inner] with a");
        assert_eq!(forms_of(Inner::KEYS, "a"), "a whole number, such as a = 1");
    }

    #[test]
    fn the_example_config_puts_each_key_in_its_table() {
        let text = example_config(&test_keys());
        assert_eq!(text, "name = \"x\"\n\n[inner]\na = 2\n");
        let _: Outer = toml::from_str(&text).unwrap();
    }

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
    fn a_missing_field_is_named_with_its_table() {
        let keys = test_keys();
        let top = "x = 1\n[inner]\n";
        let m = describe(&keys, top, "missing field `name`", Some(0..top.len()));
        assert!(m.starts_with("`name` is missing"), "{m}");
        let text = "[inner]\n";
        let m = describe(&keys, text, "missing field `a`", Some(0..text.len()));
        assert!(m.starts_with("`inner.a` is missing"), "{m}");
        assert!(
            m.ends_with("it must be a whole number, such as a = 1"),
            "{m}"
        );
    }

    #[test]
    fn a_type_error_names_key_and_forms() {
        let keys = test_keys();
        let text = "[inner]\na = -1\n";
        let at = text.find("-1").unwrap();
        let m = describe(&keys, text, "invalid value: integer `-1`", Some(at..at + 2));
        assert!(m.starts_with("`inner.a`: invalid value"), "{m}");
        assert!(m.contains("(line 2, column 5)"), "{m}");
        assert!(m.contains("must be a whole number"), "{m}");
        // Inside an inline table the key is the one holding it.
        assert_eq!(forms(&keys, "name.first"), Some("a string"));
    }
}
