//! The course's C codes (examples/course-codes/) through configs/course-codes.toml at a tiny
//! n: each round compiles its program (cc -fopenmp, mpicc), runs it on 1 and 2 OpenMP threads
//! and MPI ranks, and reads the phases it prints; the analysis gets their phase table and the
//! serial fraction timed from their output phase. Needs Open MPI (scripts/install-mpi.sh).

use std::path::Path;

/// configs/course-codes.toml with n, the kernels and the measurement cut down to seconds.
fn tiny_config() -> String {
    let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs");
    let text = std::fs::read_to_string(configs.join("course-codes.toml")).unwrap();
    let mut table: toml::Table = toml::from_str(&text).unwrap();
    table.insert("n".into(), toml::Value::Array(vec![200.into()]));
    table.insert(
        "kernels".into(),
        toml::Value::Array(vec!["per-thread".into()]),
    );
    let measure = table["measure"].as_table().unwrap().clone();
    let mut measure = measure;
    measure.insert("samples".into(), 2.into());
    measure.insert("rounds".into(), 1.into());
    table.insert("measure".into(), toml::Value::Table(measure));
    toml::to_string(&table).unwrap()
}

#[test]
fn the_course_codes_build_run_and_report_their_phases() {
    for tool in ["cc", "mpicc", "mpirun"] {
        assert!(
            std::process::Command::new("sh")
                .args(["-c", &format!("command -v {tool}")])
                .output()
                .unwrap()
                .status
                .success(),
            "`{tool}` not found: the course codes need a C compiler and Open MPI \
             (scripts/install-mpi.sh installs them)"
        );
    }
    let (results, path, _dir) = crate::sweep_committed_config(&tiny_config(), "course-codes.toml");
    let expected = [
        (
            "lj-box/lj_serial/n=200/p=1/r=1/seed=1",
            &["force", "integrate", "output"][..],
        ),
        (
            "lj-box/lj_omp/n=200/p=2/r=1/seed=1",
            &["force", "integrate", "output", "reduce"],
        ),
        (
            "lj-box/lj_mpi/n=200/p=1/r=2/seed=1",
            &["comm", "force", "integrate", "output"],
        ),
        (
            "coulomb/coulomb_mpi/n=200/p=1/r=2/seed=1",
            &["comm", "force", "integrate"],
        ),
    ];
    for (key, phases) in expected {
        let case = results
            .cases
            .iter()
            .find(|c| c.key == key)
            .unwrap_or_else(|| panic!("no case {key}"));
        let runs = &case.rounds[0].external.as_ref().unwrap().runs;
        for run in runs {
            assert!(run.error.is_none(), "{key}: {:#?}", run.error);
            let names: Vec<&str> = run.phases.keys().map(String::as_str).collect();
            assert_eq!(names, phases, "{key}");
            assert!(run.reported_s.is_some_and(|t| t > 0.0), "{key}");
        }
    }
    let analysis = nbody_harness::analysis::analyze(&results, &path).unwrap();
    let table = nbody_harness::render::runs::external_phases(&analysis);
    for program in ["lj_serial", "lj_omp", "lj_mpi", "coulomb_mpi"] {
        assert!(table.contains(program), "{program} missing from\n{table}");
    }
    // The OpenMP code's frames are its serial part, timed.
    let omp = analysis
        .strong
        .iter()
        .find(|s| s.series.kernel.name() == "lj_omp")
        .expect("lj_omp over threads");
    let timed = omp.timed_serial.as_ref().expect("a timed serial fraction");
    assert!(timed.fraction > 0.0 && timed.fraction < 1.0, "{timed:?}");
    // The MPI code's Allgatherv is its communication.
    let mpi = analysis
        .cases
        .iter()
        .find(|c| c.key == "lj-box/lj_mpi/n=200/p=1/r=2/seed=1")
        .unwrap();
    assert!(mpi.comm_s_per_step.is_some_and(|c| c > 0.0));
}
