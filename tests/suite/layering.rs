//! The layering of the crates. The engine (`crates/engine`) cannot use the harness at all:
//! Cargo forbids the dependency, and its manifest is checked here to stay free of the
//! harness's stacks (plotting, TOML, JSON records, the command line but for the optional clap
//! derives). The MPI crate (`crates/mpi`) depends on the engine alone; the harness on both. Within each crate, the top-level modules form layers: a module names only
//! modules of lower layers, and no files import each other in a cycle. Each file's `crate::`
//! and `super::` paths are resolved to the file of the module they name; a file using its own
//! ancestors' items (`super::Thing` in a submodule) is how Rust modules work and is not
//! counted, the other direction is. Test modules import what they test and are left out. The
//! binary crate (`src/main.rs`, `src/cli/`) is checked on its own; the library cannot import
//! it at all.

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

/// The cycles of `edges`, each as the modules on it (strongly connected components of two or
/// more, by Tarjan's algorithm).
fn cycles(edges: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>) -> Vec<Vec<String>> {
    struct Tarjan<'a> {
        edges: &'a BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
        index: BTreeMap<&'a Vec<String>, usize>,
        low: BTreeMap<&'a Vec<String>, usize>,
        stack: Vec<&'a Vec<String>>,
        on_stack: BTreeSet<&'a Vec<String>>,
        out: Vec<Vec<String>>,
    }
    impl<'a> Tarjan<'a> {
        fn visit(&mut self, v: &'a Vec<String>) {
            let i = self.index.len();
            self.index.insert(v, i);
            self.low.insert(v, i);
            self.stack.push(v);
            self.on_stack.insert(v);
            for w in self.edges.get(v).into_iter().flatten() {
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let lw = self.low[w];
                    let lv = self.low.get_mut(v).unwrap();
                    *lv = (*lv).min(lw);
                } else if self.on_stack.contains(w) {
                    let iw = self.index[w];
                    let lv = self.low.get_mut(v).unwrap();
                    *lv = (*lv).min(iw);
                }
            }
            if self.low[v] == self.index[v] {
                let mut component = Vec::new();
                while let Some(w) = self.stack.pop() {
                    self.on_stack.remove(w);
                    component.push(w.join("::"));
                    if w == v {
                        break;
                    }
                }
                if component.len() > 1 {
                    component.sort();
                    self.out.push(component);
                }
            }
        }
    }
    let mut t = Tarjan {
        edges,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in edges.keys() {
        if !t.index.contains_key(v) {
            t.visit(v);
        }
    }
    t.out
}

/// The engine's top-level modules, bottom up: a module may use modules of lower layers only.
/// `testing` (fixtures for tests) stands above them all and is left out of the check.
const ENGINE_LAYERS: &[&[&str]] = &[
    &["real", "simd", "clock", "input", "stats"],
    &["par", "physics", "geometry"],
    &["state"],
    &["kernels", "boundary", "integrator"],
    &["scenario", "decomp"],
    &["engine", "output", "export"],
    &["run"],
    &["validate"],
    &["stepper"],
];

/// The harness's own top-level modules, bottom up (the engine's and the MPI crate's modules,
/// re-exported at its root, are below them all).
const HARNESS_LAYERS: &[&[&str]] = &[
    &["console", "children", "fit", "calibrate"],
    &["units"],
    // A figure names times and sizes in the units' words.
    &["plot"],
    // The file formats a sweep is defined by and leaves behind.
    &["records"],
    // The runner writes them, analysis reads them: one layer, so neither may use the other.
    &["experiment", "analysis"],
    &["render"],
    // The gate writes its Markdown through render's table builder.
    &["gate", "report"],
    // The history records what sweeps and gates measured, and backfills through the gate.
    &["history"],
];

/// The MPI crate's modules (`crates/mpi`), bottom up, over the engine's.
const MPI_LAYERS: &[&[&str]] = &[&["ranks"], &["mpi"]];

/// Modules of a crate's test support, outside the layers.
const TEST_SUPPORT: &[&str] = &["testing"];

/// The source folder of a workspace crate (`crates/NAME/src`) and its files.
fn member_files(name: &str) -> (PathBuf, Vec<PathBuf>) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("crates")
        .join(name)
        .join("src");
    let mut all = Vec::new();
    rust_files(&root, &mut all);
    (root, all)
}

fn engine_files() -> (PathBuf, Vec<PathBuf>) {
    member_files("engine")
}

fn crate_files() -> (PathBuf, Vec<PathBuf>, Vec<PathBuf>) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut all = Vec::new();
    rust_files(&root, &mut all);
    let (bin, lib): (Vec<PathBuf>, Vec<PathBuf>) = all
        .into_iter()
        .partition(|f| f.ends_with("main.rs") || f.starts_with(root.join("cli")));
    (root, lib, bin)
}

/// The edges of `edges` that go up or across `layers` (as "from -> to" lines), and the
/// top-level modules no layer names.
fn against_layers(
    edges: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
    layers: &[&[&str]],
) -> (Vec<String>, BTreeSet<String>) {
    let layer_of = |m: &str| layers.iter().position(|l| l.contains(&m));
    let mut wrong = Vec::new();
    let mut unplaced = BTreeSet::new();
    for (from, tos) in edges {
        let Some(a) = from.first() else { continue };
        if TEST_SUPPORT.contains(&a.as_str()) {
            continue;
        }
        let Some(la) = layer_of(a) else {
            unplaced.insert(a.clone());
            continue;
        };
        for to in tos {
            let b = &to[0];
            if b == a || TEST_SUPPORT.contains(&b.as_str()) {
                continue;
            }
            match layer_of(b) {
                Some(lb) if lb < la => {}
                Some(_) => wrong.push(format!("{} -> {}", from.join("::"), to.join("::"))),
                None => {
                    unplaced.insert(b.clone());
                }
            }
        }
    }
    (wrong, unplaced)
}

#[test]
fn no_import_cycles_between_files() {
    let (root, lib, bin) = crate_files();
    let lib_cycles = cycles(&graph(&root, &lib));
    assert!(
        lib_cycles.is_empty(),
        "library import cycles: {lib_cycles:#?}"
    );
    let bin_cycles = cycles(&graph(&root, &bin));
    assert!(
        bin_cycles.is_empty(),
        "binary import cycles: {bin_cycles:#?}"
    );
    for member in ["engine", "mpi"] {
        let (root, files) = member_files(member);
        let found = cycles(&graph(&root, &files));
        assert!(found.is_empty(), "{member} import cycles: {found:#?}");
    }
}

#[test]
fn modules_use_only_lower_layers() {
    let (root, engine) = engine_files();
    let (wrong, unplaced) = against_layers(&graph(&root, &engine), ENGINE_LAYERS);
    assert!(
        wrong.is_empty(),
        "engine imports against its layers: {wrong:#?}"
    );
    assert!(
        unplaced.is_empty(),
        "engine modules in no layer of ENGINE_LAYERS: {unplaced:?}"
    );
    let (root, files) = member_files("mpi");
    let (wrong, unplaced) = against_layers(&graph(&root, &files), MPI_LAYERS);
    assert!(
        wrong.is_empty(),
        "MPI crate imports against its layers: {wrong:#?}"
    );
    assert!(
        unplaced.is_empty(),
        "MPI crate modules in no layer of MPI_LAYERS: {unplaced:?}"
    );
    let (root, lib, _) = crate_files();
    let (wrong, unplaced) = against_layers(&graph(&root, &lib), HARNESS_LAYERS);
    assert!(
        wrong.is_empty(),
        "harness imports against its layers: {wrong:#?}"
    );
    assert!(
        unplaced.is_empty(),
        "harness modules in no layer of HARNESS_LAYERS: {unplaced:?}"
    );
}

/// The `[dependencies]` table of `crates/NAME/Cargo.toml`.
fn member_dependencies(name: &str) -> toml::Table {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("crates")
        .join(name)
        .join("Cargo.toml");
    let manifest: toml::Table = toml::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    manifest["dependencies"].as_table().unwrap().clone()
}

#[test]
fn the_engine_depends_on_no_harness_stack() {
    let deps = member_dependencies("engine");
    for name in [
        "nbody-bench",
        "nbody-mpi",
        "plotters",
        "plotters-backend",
        "resvg",
        "toml",
        "serde_json",
        "regex",
        "indicatif",
        "anyhow",
        "mpi",
    ] {
        assert!(!deps.contains_key(name), "the engine depends on {name}");
    }
    // clap only for the derives a command line may ask for, off by default.
    let clap = deps.get("clap").and_then(|c| c.as_table());
    assert!(
        clap.is_none_or(|c| c.get("optional").and_then(|o| o.as_bool()) == Some(true)),
        "clap must stay optional in the engine"
    );
    assert_names_no_harness("engine");
}

/// No source of `crates/NAME` names the harness crate (it could not compile, but a path in a
/// macro or a doc test would only fail later).
fn assert_names_no_harness(name: &str) {
    let (_, files) = member_files(name);
    for file in files {
        let code = code_of(&std::fs::read_to_string(&file).unwrap());
        assert!(
            !code.contains("nbody_bench"),
            "{} names the harness crate",
            file.display()
        );
    }
}

#[test]
fn the_mpi_crate_depends_on_the_engine_only() {
    let deps = member_dependencies("mpi");
    assert!(deps.contains_key("nbody-engine"));
    for name in ["nbody-bench", "plotters", "resvg", "toml", "clap", "regex"] {
        assert!(!deps.contains_key(name), "the MPI crate depends on {name}");
    }
    assert_names_no_harness("mpi");
}

#[test]
fn the_library_does_not_name_the_command_line() {
    let (_, lib, _) = crate_files();
    for file in lib {
        let code = code_of(&std::fs::read_to_string(&file).unwrap());
        assert!(
            !code.contains("crate::cli") && !code.contains("crate::commands"),
            "{} names the command line",
            file.display()
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
    assert_eq!(cycles(&edges), vec![vec!["a".to_string(), "b".to_string()]]);
    // With a below b, a's import is against the layers; b's is not.
    let (wrong, unplaced) = against_layers(&edges, &[&["a"], &["b"]]);
    assert_eq!(wrong, vec!["a -> b".to_string()]);
    assert!(unplaced.is_empty());
    let (_, unplaced) = against_layers(&edges, &[&["a"]]);
    assert_eq!(unplaced, BTreeSet::from(["b".to_string()]));
    // Without b's inline path there is no cycle.
    std::fs::write(src.join("b.rs"), "// crate::a::g() in a comment\n").unwrap();
    let edges = graph(src, &files);
    assert!(cycles(&edges).is_empty());
    assert!(against_layers(&edges, &[&["b"], &["a"]]).0.is_empty());
}
