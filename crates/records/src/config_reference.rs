//! The sweep config's reference page (`docs/reference/config.md`), from the keys' doc comments
//! (`config::keys`): per key its default, found by parsing the example config without it,
//! what it means and what it accepts.

use crate::config::{SweepConfig, keys};
use crate::config_keys::{Holds, Key, example_config};

/// One key of the page: its dotted name, default, meaning and forms.
#[derive(Debug, PartialEq)]
pub struct Row {
    /// The dotted key.
    pub key: String,
    /// `*required*`, `*none*`, `the defaults below` (a table) or the value in backticks.
    pub default: String,
    /// What it means.
    pub meaning: String,
    /// What it accepts.
    pub forms: String,
}

/// Why the page cannot be made: a key's doc comment lacks a part, or the example config
/// built from them does not parse.
#[derive(Debug, thiserror::Error)]
pub enum ReferenceError {
    /// A key without a meaning, forms or example.
    #[error("config key `{0}` has no {1} in its field's doc comment (see config_keys)")]
    Undocumented(String, &'static str),
    /// The examples together are not a config.
    #[error("the config of every key's example does not parse: {0}")]
    Example(String),
}

/// The page's sections: the top level's keys, then each table's, with their rows.
pub fn sections(keys: &[Key]) -> Result<Vec<(String, Vec<Row>)>, ReferenceError> {
    for key in keys {
        let lacks = match key.holds {
            _ if key.meaning.is_empty() => Some("meaning"),
            Holds::Value if key.forms.is_empty() => Some("\"Accepts\" paragraph"),
            Holds::Value if key.example.is_none() => Some("\"Example\" paragraph"),
            _ => None,
        };
        if let Some(part) = lacks {
            return Err(ReferenceError::Undocumented(key.dotted.clone(), part));
        }
    }
    let full: toml::Table = toml::from_str(&example_config(keys))
        .map_err(|e| ReferenceError::Example(e.message().to_string()))?;
    let mut sections = vec![("Top-level keys".to_string(), Vec::new())];
    for key in keys {
        let row = Row {
            key: key.dotted.clone(),
            default: default_of(&full, &key.dotted),
            meaning: key.meaning.clone(),
            forms: key.forms.clone(),
        };
        match key.holds {
            Holds::Table => sections.push((format!("`[{}]`", key.dotted), Vec::new())),
            Holds::Tables => sections.push((format!("`[[{}]]`", key.dotted), Vec::new())),
            Holds::Value => {}
        }
        let section = match key.dotted.split_once('.') {
            None => 0,
            Some((table, _)) => sections
                .iter()
                .position(|(h, _)| h.trim_matches(['`', '[', ']']) == table)
                .unwrap_or(0),
        };
        sections[section].1.push(row);
    }
    Ok(sections)
}

/// What `dotted` is when the config `full` leaves it out: required (the config no longer
/// parses), nothing, the table's own defaults, or a value.
fn default_of(full: &toml::Table, dotted: &str) -> String {
    let path: Vec<&str> = dotted.split('.').collect();
    let mut without = full.clone();
    let holder = match path.as_slice() {
        [_] => Some(&mut without),
        [outer, _] => match without.get_mut(*outer) {
            Some(toml::Value::Table(t)) => Some(t),
            Some(toml::Value::Array(a)) => a.first_mut().and_then(toml::Value::as_table_mut),
            _ => None,
        },
        _ => None,
    };
    if let Some(holder) = holder {
        holder.remove(*path.last().unwrap_or(&""));
    }
    let Ok(config) = toml::Value::Table(without).try_into::<SweepConfig>() else {
        return "*required*".to_string();
    };
    let Ok(table) = toml::Table::try_from(&config) else {
        return "*none*".to_string();
    };
    let value = match path.as_slice() {
        [only] => table.get(*only),
        [outer, inner] => match table.get(*outer) {
            Some(toml::Value::Table(t)) => t.get(*inner),
            Some(toml::Value::Array(a)) => a
                .first()
                .and_then(toml::Value::as_table)
                .and_then(|t| t.get(*inner)),
            _ => None,
        },
        _ => None,
    };
    match value {
        None => "*none*".to_string(),
        Some(toml::Value::Table(_)) => "the defaults below".to_string(),
        Some(v) => format!("`{v}`"),
    }
}

/// The page as Markdown, its heading and `preface` (how it is regenerated) first.
pub fn page(preface: &str) -> Result<String, ReferenceError> {
    page_of(&keys(), preface)
}

fn page_of(keys: &[Key], preface: &str) -> Result<String, ReferenceError> {
    let mut page = String::from("# Sweep config reference\n\n");
    page.push_str(preface);
    page.push_str(
        "\n\nA sweep config is a TOML file (`nbody-bench sweep --config FILE|NAME`; a bare name is \
         looked up in `configs/`). Unknown keys, wrong types, empty lists, zero threads and \
         kernels that apply to none of the scenarios are refused before anything runs, with the \
         file, the key and the forms below. A default of *required* means the config (or the \
         table, when it is given) must set the key; *none* means the key has no value of its own \
         when left out: the feature is off, or what the description names applies. Each row is \
         the doc comment of the key's field in `crates/records/src/`. How to write an \
         `[[external]]` entry: [measure your own program](../howto/measure-your-own-program.md); \
         the `[mpi]` table: [run MPI studies](../howto/run-mpi-studies.md).\n",
    );
    for (heading, rows) in sections(keys)? {
        page.push_str(&format!("\n## {heading}\n\n"));
        page.push_str("| key | default | what it is | accepted forms |\n|---|---|---|---|\n");
        for r in rows {
            page.push_str(&format!(
                "| `{}` | {} | {} | {} |\n",
                r.key,
                r.default,
                r.meaning.replace('|', "\\|"),
                r.forms.replace('|', "\\|")
            ));
        }
    }
    Ok(page)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_key_is_documented_and_the_examples_form_a_config() {
        let keys = keys();
        let sections = sections(&keys).unwrap();
        let names: Vec<&str> = sections.iter().map(|(h, _)| h.as_str()).collect();
        assert_eq!(
            names,
            [
                "Top-level keys",
                "`[measure]`",
                "`[weak]`",
                "`[mpi]`",
                "`[[external]]`",
                "`[scheduler]`"
            ]
        );
        let row = |key: &str| {
            let all = sections.iter().flat_map(|(_, rows)| rows);
            all.into_iter().find(|r| r.key == key).unwrap()
        };
        assert_eq!(row("name").default, "*required*");
        assert_eq!(row("threads").default, "`[1]`");
        assert_eq!(row("measure").default, "the defaults below");
        assert_eq!(row("measure.samples").default, "`10`");
        assert_eq!(row("mpi.ranks").default, "*required*");
        assert_eq!(row("precision").default, "*none*");
        assert!(
            row("measure").forms.contains("samples"),
            "{:?}",
            row("measure")
        );
    }

    #[test]
    fn the_page_is_the_doc_comments() {
        // The `name` field's first doc line, read from the source, is the page's meaning.
        let source = include_str!("config.rs");
        let field = source.find("pub name: String").unwrap();
        let doc_start = source[..field].rfind("pub struct SweepConfig {").unwrap();
        let first_doc = source[doc_start..field]
            .lines()
            .find_map(|l| l.trim().strip_prefix("/// "))
            .unwrap();
        let page = page("").unwrap();
        assert!(page.contains(first_doc), "{first_doc}");
        // A changed doc comment changes the page, and nothing else holds the old words.
        let mut keys = keys();
        let name = keys.iter_mut().find(|k| k.dotted == "name").unwrap();
        let old = std::mem::replace(&mut name.meaning, "a changed meaning".into());
        let changed = page_of(&keys, "").unwrap();
        assert!(changed.contains("| `name` | *required* | a changed meaning |"));
        assert!(!changed.contains(&old));
    }

    #[test]
    fn an_undocumented_key_stops_the_page() {
        let mut keys = keys();
        keys.iter_mut()
            .find(|k| k.dotted == "seeds")
            .unwrap()
            .example = None;
        let err = page_of(&keys, "").unwrap_err().to_string();
        assert!(err.contains("`seeds`") && err.contains("Example"), "{err}");
    }
}
