//! The committed baselines stay usable: every file of `results/baseline/` is one this build
//! reproduces (its stored, resolved config parses and plans exactly its cases), so no machine
//! class's CI falls to the A/B route, or to a refusal, because of a change of a key, a default
//! or a schema. A baseline that is stale all the same takes the A/B route with a notice.

use nbody_harness::gate::baselines::{self, Fitness};
use std::path::{Path, PathBuf};

fn folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("results/baseline")
}

/// No timing: each committed baseline's config is parsed and planned by this build.
#[test]
fn every_committed_baseline_is_reproducible_by_this_build() {
    let examined = baselines::examine_all(&folder()).unwrap();
    assert!(!examined.is_empty(), "no committed baseline");
    let stale: Vec<String> = examined
        .iter()
        .filter_map(|c| match &c.fitness {
            Fitness::Stale(why) => Some(format!("{}: {why}", c.path.display())),
            Fitness::Reproducible(_) => None,
        })
        .collect();
    assert!(
        stale.is_empty(),
        "baselines this build would not sweep again (a change of a key, default or schema made \
         them stale; keep the change compatible with the stored configs, or re-measure them):\n{}",
        stale.join("\n")
    );
}

/// The stored config of a committed baseline, edited, in a file of its own.
fn edited(dir: &Path, edit: impl FnOnce(&mut serde_json::Value)) -> PathBuf {
    let first = baselines::examine_all(&folder()).unwrap().remove(0).path;
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(first).unwrap()).unwrap();
    edit(&mut v);
    let path = dir.join("edited.json");
    std::fs::write(&path, serde_json::to_string(&v).unwrap()).unwrap();
    path
}

fn fitness(path: &Path) -> Result<(), String> {
    match baselines::examine(path).unwrap().fitness {
        Fitness::Reproducible(_) => Ok(()),
        Fitness::Stale(why) => Err(why),
    }
}

/// What went wrong with `multipole`: a baseline saved when the key was not written out (the
/// octree's default then: monopole) is swept under today's default. Without the key, this
/// build's default decides, and the cases it plans must still be the baseline's; when the
/// default is another expansion the octree's keys change and the baseline is stale, said with
/// the cases that differ.
#[test]
fn a_changed_default_is_caught() {
    let dir = tempfile::tempdir().unwrap();
    let today = nbody_engine::kernels::KernelParams::default().multipole;
    let without = edited(dir.path(), |v| {
        v["config"].as_object_mut().unwrap().remove("multipole");
    });
    if today == nbody_engine::kernels::Multipole::Monopole {
        assert_eq!(fitness(&without), Ok(()));
    } else {
        let why = fitness(&without).unwrap_err();
        assert!(why.contains("plans other cases"), "{why}");
        assert!(why.contains(&format!("/{}", today.name())), "{why}");
    }
    // Spelled out, the stored value holds whatever today's default is.
    assert_eq!(fitness(&edited(dir.path(), |_| {})), Ok(()));
}

#[test]
fn a_retired_key_kernel_or_schema_makes_a_baseline_stale_not_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let key = edited(dir.path(), |v| v["config"]["retired"] = 1.into());
    assert!(fitness(&key).unwrap_err().contains("retired"));
    let kernel = edited(dir.path(), |v| {
        v["config"]["kernels"] = serde_json::json!(["naive", "gone"]);
    });
    assert!(fitness(&kernel).unwrap_err().contains("gone"));
    let schema = edited(dir.path(), |v| {
        v["schema"] = "nbody-bench/results/v0".into()
    });
    let why = fitness(&schema).unwrap_err();
    assert!(why.contains("nbody-bench/results/v0"), "{why}");
    // Not a results file at all: that one is the user's to fix.
    let junk = dir.path().join("junk.json");
    std::fs::write(&junk, "{\"schema\": 1}").unwrap();
    assert!(baselines::examine(&junk).is_err());
}
