//! The layering of the workspace, in two parts. Between crates, cargo enforces the direction
//! a manifest allows; this checks that the manifests keep the order of [`MEMBERS`] (a crate
//! depends on crates of lower layers only) and keep each crate off the stacks it must not pull
//! in (the engine has no plotting, TOML, JSON or command line but clap's optional derives).
//! Within a crate, cargo allows any import; here its top-level modules form layers: a module
//! names only modules of lower layers, never one of its own layer, and no files import each
//! other in a cycle. Each file's `crate::` and `super::` paths are resolved to the file of the
//! module they name; a file using its own ancestors' items (`super::Thing` in a submodule) is
//! how Rust modules work and is not counted, the other direction is. Test modules import what
//! they test and are left out.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Module path (`["gate", "checks"]`) of a source file under `root`.
fn module_of(root: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(root).unwrap().with_extension("");
    let mut parts: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let name = path.file_stem().unwrap().to_string_lossy();
            // Test modules import what they test; they are not part of the layering.
            if name != "tests" && !name.ends_with("_tests") {
                out.push(path);
            }
        }
    }
}

/// The code of a file without comments and string literals (a path in a doc comment or a
/// message is not an import).
fn code_of(text: &str) -> String {
    let mut out = String::new();
    for line in text.lines() {
        let mut in_str = false;
        let mut prev = ' ';
        let mut kept = String::new();
        let chars: Vec<char> = line.chars().collect();
        let mut i = 0;
        while i < chars.len() {
            let c = chars[i];
            if !in_str && c == '/' && chars.get(i + 1) == Some(&'/') {
                break;
            }
            // `'"'` is a character, not the start of a string.
            let char_literal = prev == '\'' && chars.get(i + 1) == Some(&'\'');
            if c == '"' && prev != '\\' && !char_literal {
                in_str = !in_str;
            } else if !in_str {
                kept.push(c);
            }
            prev = if prev == '\\' && c == '\\' { ' ' } else { c };
            i += 1;
        }
        out.push_str(&kept);
        out.push('\n');
    }
    out
}

/// Every path the code names: `use` trees expanded (`a::{b, c::d}` → `a::b`, `a::c::d`) and
/// inline `crate::x::y` / `super::x` paths.
fn paths_in(code: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let flat: String = code.split_whitespace().collect::<Vec<_>>().join(" ");
    let mut rest = flat.as_str();
    while let Some(i) = rest.find("use ") {
        // A `use` item starts a statement: after `;`, a brace, an attribute or a visibility.
        let before = rest[..i].trim_end();
        rest = &rest[i + 4..];
        let starts_item = before.is_empty()
            || before.ends_with([';', '{', '}', ']'])
            || before.ends_with("pub")
            || before.ends_with(')') && before.contains("pub(");
        if !starts_item {
            continue;
        }
        let Some(end) = rest.find(';') else { break };
        expand(&rest[..end].replace(' ', ""), &mut Vec::new(), &mut out);
        rest = &rest[end..];
    }
    let bytes: Vec<char> = flat.chars().collect();
    for start in ["crate::", "super::"] {
        let mut from = 0;
        while let Some(i) = flat[from..].find(start) {
            let at = from + i;
            from = at + start.len();
            let head = flat[..at].chars().last();
            if head.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                continue;
            }
            let mut end = at;
            while end < bytes.len()
                && (bytes[end].is_alphanumeric() || bytes[end] == '_' || bytes[end] == ':')
            {
                end += 1;
            }
            let path: Vec<String> = flat[at..end]
                .split("::")
                .filter(|s| !s.is_empty())
                .map(String::from)
                .collect();
            out.push(path);
        }
    }
    out
}

fn expand(tree: &str, prefix: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    let tree = tree.trim_matches(',');
    if let Some(open) = tree.find('{') {
        let head: Vec<String> = tree[..open]
            .split("::")
            .filter(|s| !s.is_empty())
            .map(String::from)
            .collect();
        let inner = &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())];
        let mut depth = 0;
        let mut last = 0;
        let mut items = Vec::new();
        for (i, c) in inner.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    items.push(&inner[last..i]);
                    last = i + 1;
                }
                _ => {}
            }
        }
        items.push(&inner[last..]);
        let len = prefix.len();
        prefix.extend(head);
        for item in items.into_iter().filter(|s| !s.is_empty()) {
            expand(item, prefix, out);
        }
        prefix.truncate(len);
    } else {
        let mut path = prefix.clone();
        let tree = tree.split(" as ").next().unwrap_or(tree);
        path.extend(tree.split("::").filter(|s| !s.is_empty()).map(String::from));
        out.push(path);
    }
}

/// The file-level import graph of the crate whose files are `files` (module → modules used).
fn graph(root: &Path, files: &[PathBuf]) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let modules: BTreeSet<Vec<String>> = files.iter().map(|f| module_of(root, f)).collect();
    let mut edges: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    for file in files {
        let me = module_of(root, file);
        let code = code_of(&std::fs::read_to_string(file).unwrap());
        let entry = edges.entry(me.clone()).or_default();
        for path in paths_in(&code) {
            let absolute: Vec<String> = match path.first().map(String::as_str) {
                Some("crate") => path[1..].to_vec(),
                Some("super") => {
                    let mut base = me.clone();
                    let mut rest = path.as_slice();
                    while rest.first().map(String::as_str) == Some("super") {
                        base.pop();
                        rest = &rest[1..];
                    }
                    base.extend(rest.iter().cloned());
                    base
                }
                _ => continue,
            };
            // The longest prefix that is a file of the crate.
            let target = (0..=absolute.len())
                .rev()
                .map(|k| absolute[..k].to_vec())
                .find(|p| modules.contains(p));
            let Some(target) = target else { continue };
            // A module using its ancestors (or itself) is not a layering edge.
            if me.starts_with(&target) {
                continue;
            }
            entry.insert(target);
        }
    }
    edges
}

/// The files on or above an import cycle of `edges`: what is left after peeling off, again
/// and again, the files that import no file still left.
fn cycles(edges: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>) -> BTreeSet<String> {
    let mut left = edges.clone();
    loop {
        let sinks: Vec<Vec<String>> = left
            .iter()
            .filter(|(_, tos)| tos.iter().all(|to| !left.contains_key(to)))
            .map(|(from, _)| from.clone())
            .collect();
        if sinks.is_empty() {
            return left.keys().map(|m| m.join("::")).collect();
        }
        for sink in sinks {
            left.remove(&sink);
        }
    }
}

/// The edges of `edges` that go up or across `layers` (as "from -> to" lines), and the
/// top-level modules no layer names. `testing` (a crate's fixtures for tests) is left out.
fn against_layers(
    edges: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
    layers: &[&[&str]],
) -> (Vec<String>, BTreeSet<String>) {
    let layer_of = |m: &str| layers.iter().position(|l| l.contains(&m));
    let mut wrong = Vec::new();
    let mut unplaced = BTreeSet::new();
    for (from, tos) in edges {
        let Some(a) = from.first().filter(|a| *a != "testing") else {
            continue;
        };
        let Some(la) = layer_of(a) else {
            unplaced.insert(a.clone());
            continue;
        };
        for to in tos.iter().filter(|to| to[0] != *a && to[0] != "testing") {
            match layer_of(&to[0]) {
                Some(lb) if lb < la => {}
                Some(_) => wrong.push(format!("{} -> {}", from.join("::"), to.join("::"))),
                None => {
                    unplaced.insert(to[0].clone());
                }
            }
        }
    }
    (wrong, unplaced)
}

/// A crate of the workspace: where it is, its layer among the crates, its top-level modules
/// bottom up, and the dependencies it must never have.
struct Member {
    dir: &'static str,
    package: &'static str,
    layer: usize,
    modules: &'static [&'static [&'static str]],
    never: &'static [&'static str],
}

/// What only the harness and the binary may pull in: figures, configs, records, progress,
/// error plumbing.
const HARNESS_STACKS: &[&str] = &[
    "plotters",
    "resvg",
    "toml",
    "serde_json",
    "regex",
    "indicatif",
    "anyhow",
    "mpi",
];

const MEMBERS: &[Member] = &[
    Member {
        dir: "crates/engine",
        package: "nbody-engine",
        layer: 0,
        modules: &[
            &["real", "simd", "clock", "input", "stats"],
            &["par", "physics", "geometry"],
            &["state"],
            &["kernels", "boundary", "integrator"],
            &["scenario", "decomp"],
            &["engine", "output", "export"],
            &["run"],
            &["validate"],
            &["stepper"],
        ],
        never: HARNESS_STACKS,
    },
    Member {
        dir: "crates/calibrate",
        package: "nbody-calibrate",
        layer: 1,
        modules: &[&["compute", "fork_join", "load", "memory", "team"]],
        never: HARNESS_STACKS,
    },
    Member {
        dir: "crates/mpi",
        package: "nbody-mpi",
        layer: 1,
        modules: &[&["ranks"], &["mpi"]],
        never: &["plotters", "resvg", "toml", "clap", "regex"],
    },
    Member {
        dir: "crates/records",
        package: "nbody-records",
        layer: 2,
        modules: &[
            &["config_keys"],
            &["scheduler", "kernel_or_program"],
            &["external"],
            &["round"],
            &["vet"],
            &["config"],
            &["plan", "config_reference"],
            &["results"],
            &["locate", "tidy"],
        ],
        never: &["plotters", "resvg", "indicatif", "mpi"],
    },
    Member {
        dir: "crates/harness",
        package: "nbody-harness",
        layer: 3,
        modules: &[
            &["console", "children", "git", "fit"],
            &["units"],
            // A figure names times and sizes in the units' words.
            &["plot"],
            // The runner writes results files, analysis reads them: neither uses the other.
            &["experiment", "analysis"],
            &["render"],
            // The gate writes its Markdown through render's table builder.
            &["gate", "report"],
            // The history records what sweeps and gates measured, and backfills through the gate.
            &["history"],
        ],
        never: &[],
    },
    // The binary: arguments in, one library call, output out.
    Member {
        dir: ".",
        package: "nbody-bench",
        layer: 4,
        modules: &[&["cli"]],
        never: &["plotters", "resvg", "indicatif"],
    },
];

fn member_dir(m: &Member) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(m.dir)
}

/// A member's source folder and its files.
fn member_files(m: &Member) -> (PathBuf, Vec<PathBuf>) {
    let root = member_dir(m).join("src");
    let mut all = Vec::new();
    rust_files(&root, &mut all);
    (root, all)
}

/// The `[dependencies]` (or `[dev-dependencies]`) table of a member's manifest.
fn member_dependencies(m: &Member, table: &str) -> toml::Table {
    let text = std::fs::read_to_string(member_dir(m).join("Cargo.toml")).unwrap();
    let manifest: toml::Table = toml::from_str(&text).unwrap();
    let deps = manifest.get(table).and_then(|t| t.as_table());
    deps.cloned().unwrap_or_default()
}

#[test]
fn crates_depend_only_on_lower_crates_and_allowed_stacks() {
    let layer_of = |package: &str| {
        MEMBERS
            .iter()
            .find(|m| m.package == package)
            .map(|m| m.layer)
    };
    for m in MEMBERS {
        // A test may not reach up either.
        for table in ["dependencies", "dev-dependencies"] {
            for name in member_dependencies(m, table).keys() {
                let below = layer_of(name).is_some_and(|l| l < m.layer);
                let within = !name.starts_with("nbody-") || below;
                assert!(within, "{} depends on {name}, not a lower crate", m.package);
            }
        }
        for name in member_dependencies(m, "dependencies").keys() {
            let allowed = !m.never.contains(&name.as_str());
            assert!(allowed, "{} depends on {name}", m.package);
        }
    }
    // clap only for the derives a command line may ask for, off by default.
    let engine = member_dependencies(&MEMBERS[0], "dependencies");
    let clap = engine.get("clap").and_then(|c| c.as_table());
    assert!(
        clap.is_none_or(|c| c.get("optional").and_then(|o| o.as_bool()) == Some(true)),
        "clap must stay optional in the engine"
    );
}

#[test]
fn no_crate_names_one_above_it_or_re_exports_another() {
    for m in MEMBERS {
        let (_, files) = member_files(m);
        for file in files {
            let code = code_of(&std::fs::read_to_string(&file).unwrap());
            // A path in a macro or a doc test would compile until the day it is expanded.
            // (The binary is no library: nothing can name it.)
            for above in MEMBERS
                .iter()
                .filter(|a| a.layer >= m.layer && a.package != m.package && a.dir != ".")
            {
                let name = above.package.replace('-', "_");
                assert!(!code.contains(&name), "{} names {name}", file.display());
            }
            // Another crate's modules are named by their own path, not dressed as this one's.
            let flat = code.split_whitespace().collect::<Vec<_>>().join(" ");
            assert!(
                !flat.contains("pub use nbody_") && !flat.contains("pub(crate) use nbody_"),
                "{} re-exports another crate's items",
                file.display()
            );
        }
    }
}

#[test]
fn modules_use_only_lower_layers_and_files_form_no_cycle() {
    for m in MEMBERS {
        let (root, files) = member_files(m);
        let edges = graph(&root, &files);
        let (wrong, unplaced) = against_layers(&edges, m.modules);
        assert!(
            wrong.is_empty(),
            "{} imports against its layers: {wrong:#?}",
            m.package
        );
        assert!(
            unplaced.is_empty(),
            "{} modules in no layer: {unplaced:?}",
            m.package
        );
        let cyclic = cycles(&edges);
        assert!(
            cyclic.is_empty(),
            "{} files on an import cycle: {cyclic:#?}",
            m.package
        );
    }
}

#[test]
fn the_check_finds_a_cycle_and_expands_use_trees() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path();
    std::fs::create_dir_all(src.join("a")).unwrap();
    std::fs::write(src.join("lib.rs"), "pub mod a;\npub mod b;\n").unwrap();
    std::fs::write(
        src.join("a/mod.rs"),
        "mod x;\nuse crate::b::{self, Thing};\n",
    )
    .unwrap();
    std::fs::write(
        src.join("a/x.rs"),
        "use super::Parent; // a child using its parent\n",
    )
    .unwrap();
    std::fs::write(src.join("b.rs"), "fn f() { crate::a::g(); }\n").unwrap();
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let edges = graph(src, &files);
    let both = BTreeSet::from(["a".to_string(), "b".to_string()]);
    assert_eq!(cycles(&edges), both);
    // With a below b, a's import is against the layers; b's is not; one layer forbids both.
    let (wrong, unplaced) = against_layers(&edges, &[&["a"], &["b"]]);
    assert_eq!(wrong, vec!["a -> b".to_string()]);
    assert!(unplaced.is_empty());
    assert_eq!(against_layers(&edges, &[&["a", "b"]]).0.len(), 2);
    let (_, unplaced) = against_layers(&edges, &[&["a"]]);
    assert_eq!(unplaced, BTreeSet::from(["b".to_string()]));
    // Without b's inline path there is no cycle.
    std::fs::write(src.join("b.rs"), "// crate::a::g() in a comment\n").unwrap();
    let edges = graph(src, &files);
    assert!(cycles(&edges).is_empty());
    assert!(against_layers(&edges, &[&["b"], &["a"]]).0.is_empty());
}
