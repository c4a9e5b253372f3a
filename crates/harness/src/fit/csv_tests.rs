use super::*;

#[test]
fn threads_table_groups_samples_by_p() {
    let text = "# strong scaling of some code\n P , Time \n1,2.0\n2,1.1\n\n1,2.2\n\"4\",0.7\r\n";
    let s = parse_threads(text).unwrap();
    assert_eq!(
        s,
        vec![
            Samples::new(1.0, vec![2.0, 2.2]),
            Samples::new(2.0, vec![1.1]),
            Samples::new(4.0, vec![0.7]),
        ]
    );
    let with_bom = parse_threads("\u{feff}p,time\n1,2.0\n").unwrap();
    assert_eq!(with_bom, vec![Samples::new(1.0, vec![2.0])]);
    let reordered = parse_threads("time,p\n2.0,1\n1.0,2\n").unwrap();
    assert_eq!(reordered[1], Samples::new(2.0, vec![1.0]));
}

#[test]
fn sizes_and_weak_tables() {
    let s = parse_sizes("n,time\n1000,0.5\n2000,2.1\n").unwrap();
    assert_eq!(s[1], Samples::new(2000.0, vec![2.1]));
    assert_eq!(
        parse_weak("p,time\n1,1.0\n2,1.1\n").unwrap(),
        WeakTable::Times(vec![
            Samples::new(1.0, vec![1.0]),
            Samples::new(2.0, vec![1.1])
        ])
    );
    let WeakTable::WithN(w) = parse_weak("p,n,time\n1,100,1.0\n2,200,1.1\n2,200,1.2\n").unwrap()
    else {
        panic!("n column given")
    };
    assert_eq!(w[1].n, 200.0);
    assert_eq!(w[1].values, vec![1.1, 1.2]);
}

#[test]
fn errors_name_the_line() {
    let cases: &[(&str, &str)] = &[
        ("", "line 1: the table ends with no header (it is empty)"),
        ("\n# only a comment\n", "line 3: the table ends"),
        ("1,2.0\n2,1.0\n", "line 1: missing header"),
        ("p,time\n", "no data rows after the header on line 1"),
        (
            "p,time,threads\n1,2\n",
            "line 1: unknown column(s) `threads`",
        ),
        ("p,time,\n1,2,\n", "(an empty name)"),
        ("p\n1\n", "line 1: missing column `time`"),
        ("p,time,p\n1,2,1\n", "line 1: column `p` appears twice"),
        ("p,time\n1,2\n2\n", "line 3: 1 fields, but the header has 2"),
        ("p,time\n1,2\n2,3,4\n", "line 3: 3 fields"),
        (
            "p,time\n1,2\n2,fast\n",
            "line 3: `fast` in column `time` is not a finite number",
        ),
        ("p,time\n\n1,nan\n", "line 3: `nan` in column `time`"),
        ("p,time\n1,inf\n", "line 2: `inf`"),
        (
            "p,time\n1,2\n2,0\n",
            "line 3: time = 0, but times must be seconds > 0",
        ),
        (
            "p,time\n0,2\n",
            "line 2: p = 0, but worker counts must be >= 1",
        ),
        ("n,time\n-5,2\n", "line 2: n = -5"),
    ];
    for (text, message) in cases {
        let err = if text.starts_with("n,") {
            parse_sizes(text).unwrap_err()
        } else {
            parse_threads(text).unwrap_err()
        };
        assert!(err.to_string().contains(message), "{text:?}: {err}");
    }
    let err = parse_weak("p,n,time\n1,10,1\n2,20,1\n2,30,1\n").unwrap_err();
    assert!(
        err.to_string()
            .starts_with("line 4: p = 2 has n = 30, but line 3 gave it n = 20"),
        "{err}"
    );
    let err = parse_sizes("p,time\n1,2\n").unwrap_err();
    assert!(err.to_string().contains("unknown column(s) `p`"), "{err}");
}
