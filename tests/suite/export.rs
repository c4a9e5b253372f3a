//! `nbody-bench export`: the files read back give our initial state (LAMMPS data in reduced
//! units, the text table exactly, the .npy array exactly), and other laws are refused for LAMMPS.

use nbody_engine::kernels::CompiledKernels;
use nbody_engine::physics::LawParameters;
use nbody_engine::real::Real;
use nbody_engine::scenario::{ScenarioKind, Setup, System, SystemJob};
use std::path::Path;

/// Per particle in id order: position, velocity, mass, strength (f64), and the law.
struct Rows;
impl SystemJob for Rows {
    type Output = (Vec<[Vec<f64>; 4]>, LawParameters);
    fn run<T: Real, L: CompiledKernels<T, D>, const D: usize>(
        self,
        s: System<T, L, D>,
    ) -> Self::Output {
        let st = &s.state;
        let rows = st
            .slots_by_id()
            .into_iter()
            .map(|i| {
                [
                    (0..D).map(|d| st.pos[d][i].as_f64()).collect(),
                    (0..D).map(|d| st.vel[d][i].as_f64()).collect(),
                    vec![st.mass[i].as_f64()],
                    vec![st.source[i].as_f64()],
                ]
            })
            .collect();
        (rows, s.law.parameters())
    }
}

fn state(scenario: ScenarioKind, n: usize, seed: u64) -> (Vec<[Vec<f64>; 4]>, LawParameters) {
    let mut setup = Setup::new(scenario);
    setup.n = Some(n);
    setup.seed = seed;
    setup.dispatch(Rows).unwrap()
}

fn export(dir: &Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_nbody-bench"))
        .arg("export")
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

/// The numbers of a LAMMPS data file's section, by atom id.
fn section(text: &str, name: &str) -> Vec<Vec<f64>> {
    let start = text.lines().position(|l| l.starts_with(name)).unwrap();
    text.lines()
        .skip(start + 2)
        .take_while(|l| !l.trim().is_empty())
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect()
}

#[test]
fn a_lammps_data_file_reads_back_as_our_state() {
    let dir = tempfile::tempdir().unwrap();
    for scenario in ["lj-box", "lj-liquid"] {
        let out = export(
            dir.path(),
            &[
                "--scenario",
                scenario,
                "-n",
                "300",
                "--seed",
                "4",
                "--format",
                "lammps-data",
                "--out",
                "s.data",
            ],
        );
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = std::fs::read_to_string(dir.path().join("s.data")).unwrap();
        let kind = if scenario == "lj-box" {
            ScenarioKind::LjBox
        } else {
            ScenarioKind::LjLiquid
        };
        let (rows, law) = state(kind, 300, 4);
        let LawParameters::LennardJones { epsilon, sigma, .. } = law else {
            panic!("{law:?}")
        };
        assert!(text.lines().any(|l| l == "300 atoms"));
        assert!(text.lines().any(|l| l == "Atoms # atomic"));
        let atoms = section(&text, "Atoms");
        let vels = section(&text, "Velocities");
        assert_eq!((atoms.len(), vels.len()), (300, 300));
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1e-3);
        for (i, row) in rows.iter().enumerate() {
            assert_eq!(atoms[i][..2], [(i + 1) as f64, 1.0]);
            assert_eq!(vels[i][0], (i + 1) as f64);
            for d in 0..2 {
                assert!(
                    close(atoms[i][2 + d] * sigma, row[0][d]),
                    "{scenario} atom {i}"
                );
                assert!(
                    close(vels[i][1 + d] * epsilon.sqrt(), row[1][d]),
                    "{scenario} atom {i}"
                );
            }
            assert_eq!((atoms[i][4], vels[i][3]), (0.0, 0.0));
        }
        // Every atom inside the box.
        let bounds: Vec<Vec<f64>> = text
            .lines()
            .filter(|l| l.ends_with("xhi") || l.ends_with("yhi"))
            .map(|l| {
                l.split_whitespace()
                    .take(2)
                    .map(|x| x.parse().unwrap())
                    .collect()
            })
            .collect();
        for a in &atoms {
            for d in 0..2 {
                assert!(a[2 + d] >= bounds[d][0] && a[2 + d] <= bounds[d][1]);
            }
        }
    }
    let out = export(
        dir.path(),
        &[
            "--scenario",
            "coulomb",
            "--format",
            "lammps-data",
            "--out",
            "c.data",
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("use --format text or npy"));
    assert!(!dir.path().join("c.data").exists());
}

#[test]
fn text_and_npy_tables_hold_the_state_and_the_law() {
    let dir = tempfile::tempdir().unwrap();
    let (rows, law) = state(ScenarioKind::Coulomb, 50, 2);
    let args = |format: &str, out: &'static str| {
        let o = export(
            dir.path(),
            &[
                "--scenario",
                "coulomb",
                "-n",
                "50",
                "--seed",
                "2",
                "--format",
                format,
                "--out",
                out,
            ],
        );
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    args("text", "s.txt");
    args("npy", "s.npy");
    let text = std::fs::read_to_string(dir.path().join("s.txt")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "# nbody-bench initial state v1");
    assert_eq!(lines[2], format!("# {law}"));
    assert!(lines[2].contains("quench 0.001"), "{}", lines[2]);
    assert_eq!(lines[5], "# columns: id x y z vx vy vz mass strength");
    let bytes = std::fs::read(dir.path().join("s.npy")).unwrap();
    let hlen = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let npy: Vec<f64> = bytes[10 + hlen..]
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    assert_eq!(npy.len(), 50 * 9);
    for (i, row) in rows.iter().enumerate() {
        let want: Vec<f64> = std::iter::once(i as f64)
            .chain(row.iter().flatten().copied())
            .collect();
        let got: Vec<f64> = lines[6 + i]
            .split(' ')
            .map(|x| x.parse().unwrap())
            .collect();
        assert_eq!(got, want, "text row {i}");
        assert_eq!(&npy[i * 9..(i + 1) * 9], &want[..], "npy row {i}");
    }
    // Charges alternate, as the scenario says.
    assert_eq!((rows[0][3][0], rows[1][3][0]), (1.0, -1.0));
}
