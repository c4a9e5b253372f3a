use super::*;
use crate::export::{ExportFormat, export_setup};
use crate::scenario::Setup;

fn parse_str(text: &str) -> Result<InitialBodies, InitialError> {
    parse(Path::new("bodies.txt"), text)
}

/// The line and the problem of an error that names a line.
fn line_error(text: &str) -> (usize, LineProblem) {
    match parse_str(text).unwrap_err() {
        InitialError::Line { line, problem, .. } => (line, problem),
        e => panic!("not a line error: {e}"),
    }
}

fn exported(scenario: ScenarioKind, n: usize) -> (Setup, String) {
    let mut setup = Setup::new(scenario);
    setup.n = Some(n);
    let bytes = export_setup(&setup, ExportFormat::Text).unwrap().unwrap();
    (setup, String::from_utf8(bytes).unwrap())
}

#[test]
fn an_exported_state_starts_the_same_state_in_every_scenario() {
    for scenario in ScenarioKind::ALL {
        let (setup, text) = exported(scenario, scenario.count_at_most(300));
        let bodies = parse_str(&text).unwrap();
        assert_eq!(bodies.format, InitialFormat::Export);
        assert_eq!(bodies.dim, scenario.dim());
        assert_eq!(bodies.exported_from.as_deref(), Some(scenario.name()));
        let mut from_file = Setup::new(scenario);
        from_file.seed = setup.seed + 1;
        from_file.initial = Some(std::sync::Arc::new(bodies));
        from_file.validate().unwrap();
        let again = export_setup(&from_file, ExportFormat::Text)
            .unwrap()
            .unwrap();
        // Only the seed line differs: the bodies are the file's, not the seed's.
        let strip = |t: &str| t.replace(" seed 2 ", " seed 1 ");
        assert_eq!(
            strip(&String::from_utf8(again).unwrap()),
            text,
            "{scenario:?}"
        );
    }
}

#[test]
fn ids_in_any_order_put_each_body_at_its_id() {
    let text = "# nbody-bench initial state v1\n# columns: id x y vx vy mass strength\n\
                1 0.5 0.6 0 0 2 1\n0 0.1 0.2 0 0 1 1\n";
    let b = parse_str(text).unwrap();
    assert_eq!(b.bodies[0].pos[..2], [0.1, 0.2]);
    assert_eq!((b.bodies[1].mass, b.bodies[1].line), (2.0, 3));
    let (line, p) = line_error(&text.replace("\n0 0.1", "\n1 0.1"));
    assert_eq!((line, p), (3, LineProblem::DuplicateId { id: 1, again: 4 }));
    let (line, p) = line_error(&text.replace("\n0 0.1", "\n7 0.1"));
    assert_eq!(line, 4);
    assert!(matches!(p, LineProblem::Id { n: 2, .. }), "{p:?}");
}

#[test]
fn a_body_file_with_comments_and_blank_lines_is_read() {
    let text = "# the report's nbody_start.txt\n\n1000 0 0 0 0 0 0\n  \n\
                # a planet\n1 3 0 0 0 18.3 0\n1e-3\t-1.5 2 0.25  0.1 0 -0.2\n";
    let b = parse_str(text).unwrap();
    assert_eq!((b.format, b.dim, b.len()), (InitialFormat::BarnesHut, 3, 3));
    assert_eq!(b.bodies[1].pos, [3.0, 0.0, 0.0]);
    assert_eq!(b.bodies[1].vel, [0.0, 18.3, 0.0]);
    assert_eq!(b.bodies[2].mass, 1e-3);
    assert_eq!(b.bodies[2].strength, 1e-3);
    assert_eq!(
        b.bodies.iter().map(|b| b.line).collect::<Vec<_>>(),
        [3, 6, 7]
    );
}

#[test]
fn each_bad_line_is_named() {
    let good = "1 0 0 0 0 0 0\n";
    let cases: [(&str, usize, &str); 7] = [
        (
            "1 0 0 0 0 0\n",
            2,
            "6 values where 7 were expected (m x y z vx vy vz)",
        ),
        (
            "1 0 0 zero 0 0 0\n",
            2,
            "`zero` (column 4, z) is not a number",
        ),
        ("1 0 0 0 NaN 0 0\n", 2, "vx (column 5) is NaN"),
        ("1 0 inf 0 0 0 0\n", 2, "y (column 3) is inf"),
        ("-2 0 0 0 0 0 0\n", 2, "mass -2 is not positive"),
        ("0 0 0 0 0 0 0\n", 2, "mass 0 is not positive"),
        ("1 0 0 0 0 0 0 # a note\n", 2, "10 values"),
    ];
    for (bad, line, want) in cases {
        let err = parse_str(&format!("{good}{bad}")).unwrap_err().to_string();
        assert!(
            err.starts_with(&format!("initial state bodies.txt line {line}: "))
                && err.contains(want),
            "{bad:?}: {err}"
        );
    }
}

#[test]
fn an_empty_file_and_a_headless_export_are_refused() {
    let e = parse_str("# nothing\n\n").unwrap_err().to_string();
    assert!(e.contains("bodies.txt: no bodies (2 lines"), "{e}");
    assert!(parse_str("").is_err());
    let (line, p) = line_error("# nbody-bench initial state v1\n0 1 2 0 0 1 1\n");
    assert_eq!((line, p), (2, LineProblem::NoColumns));
    let (line, p) = line_error("\n# nbody-bench initial state v9\n");
    assert!(line == 2 && matches!(p, LineProblem::Version(_)), "{p:?}");
    let (line, p) = line_error("# nbody-bench initial state v1\n# columns: id x vx mass\n");
    assert!(line == 2 && matches!(p, LineProblem::Columns(_)), "{p:?}");
    // A second columns line would read the bodies after it in another dimension.
    let (line, p) = line_error(
        "# nbody-bench initial state v1\n# columns: id x y vx vy mass strength\n\
         0 0.1 0.2 0 0 1 1\n# columns: id x y z vx vy vz mass strength\n\
         1 0.1 0.2 0.3 0 0 0 1 1\n",
    );
    assert_eq!((line, p), (4, LineProblem::ColumnsTwice { first: 2 }));
}

#[test]
fn bodies_that_cannot_start_the_scenario_are_refused_at_their_line() {
    let body_file = parse_str("# m x y z vx vy vz\n1 0.5 0.5 0.5 0 0 0\n").unwrap();
    let check = |b: &InitialBodies, s, side| match b.check(s, side).unwrap_err() {
        InitialError::Line { line, problem, .. } => (line, problem),
        e => panic!("{e}"),
    };
    assert!(body_file.check(ScenarioKind::Galaxy, None).is_ok());
    let (line, p) = check(&body_file, ScenarioKind::LjBox, Some(1.0));
    assert!(
        line == 2
            && matches!(
                p,
                LineProblem::Dimension {
                    file: 3,
                    want: 2,
                    ..
                }
            )
    );
    assert_eq!(
        check(&body_file, ScenarioKind::Coulomb, None),
        (2, LineProblem::NoCharges)
    );

    let (_, text) = exported(ScenarioKind::LjBox, 20);
    let lj = parse_str(&text).unwrap();
    assert!(lj.check(ScenarioKind::LjBox, Some(1.0)).is_ok());
    let (line, p) = check(&lj, ScenarioKind::Galaxy, None);
    assert!(
        line == 6
            && matches!(
                p,
                LineProblem::Dimension {
                    file: 2,
                    want: 3,
                    ..
                }
            )
    );
    // A smaller box (20 bodies fill a side of 0.2) leaves some body outside: the first
    // such body's line.
    let (line, p) = check(&lj, ScenarioKind::LjBox, Some(0.1));
    let first = lj
        .bodies
        .iter()
        .filter(|b| b.pos[..2].iter().any(|&x| x > 0.1));
    assert_eq!(line, first.map(|b| b.line).min().unwrap());
    assert!(matches!(
        p,
        LineProblem::OutsideBox {
            side: 0.1,
            dim: 2,
            ..
        }
    ));

    let (_, text) = exported(ScenarioKind::Galaxy, 10);
    let negative = text.replacen(" 1e0\n", " -1e0\n", 1);
    let g = parse_str(&negative).unwrap();
    assert!(matches!(
        check(&g, ScenarioKind::Galaxy, None),
        (_, LineProblem::NegativeStrength(-1.0))
    ));
    assert!(g.check(ScenarioKind::Coulomb, None).is_ok());
}
