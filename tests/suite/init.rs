//! `nbody-bench init --external NAME`: a commented config for the user's program that the sweep
//! accepts as written, with every `[[external]]` key it can take named; never over a file.

use super::bin;
use nbody_records::config::SweepConfig;

#[test]
fn init_writes_a_config_the_sweep_accepts_and_never_replaces_a_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = bin()
        .current_dir(dir.path())
        .args(["init", "--external", "heat"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let path = dir.path().join("heat.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let config = SweepConfig::parse(&text, &path).unwrap();
    assert_eq!(config.name, "heat");
    assert_eq!(config.external[0].name, "heat");
    assert!(text.contains("{config_dir}/heat.c") && !text.contains("mycode"));
    // Every key of an external entry appears in it, set or commented, so none is a surprise.
    for key in [
        "name",
        "setup",
        "command",
        "steps",
        "env",
        "time",
        "check",
        "phases",
        "version",
        "timeout_s",
        "ranks",
    ] {
        assert!(
            text.lines()
                .any(|l| l.trim_start_matches("# ").starts_with(&format!("{key} = "))),
            "`{key}` is not in the template"
        );
    }
    for (args, expected) in [
        (&["init", "--external", "heat"][..], "heat.toml exists"),
        (&["init", "--external", "a/b"], "letters, digits"),
        (&["init", "--external", "octree"], "built-in kernel"),
        (
            &["init", "--external", "x", "--out", "no/such/dir/x.toml"],
            "no/such/dir",
        ),
    ] {
        let out = bin().current_dir(dir.path()).args(args).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
    }
    assert_eq!(
        std::fs::read_to_string(&path).unwrap(),
        text,
        "left as it was"
    );
}
