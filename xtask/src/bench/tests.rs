use super::*;

const LOG: [&str; 7] = [
    "bench row=default n=900 w=59 engine=563360 direct=37010000 (-160696.5)",
    "bench row=w15 n=900 w=15 engine=541040 direct=9770720 (-34268.844)",
    "bench row=w59 n=900 w=59 engine=563360 direct=37010000 (-160696.5)",
    "bench row=w239 n=900 w=239 engine=676000 direct=133967040 (-885004.0)",
    "bench row=n450 n=450 w=59 engine=305040 direct=18187840 (-39993.406)",
    "bench row=n900 n=900 w=59 engine=563360 direct=37010000 (-160696.5)",
    "bench row=n1800 n=1800 w=59 engine=1086400 direct=74700160 (529792.75)",
];

fn log(lines: &[&str]) -> Vec<LogLine> {
    lines.iter().map(|m| LogLine::new("INFO", *m)).collect()
}

#[test]
fn bench_rows_and_their_verdict() {
    let mut lines = vec![
        "boot",
        "frame bench frames=1 min=1 median=1 max=1 max_at=0 mean=1",
    ];
    lines.extend(LOG);
    let rows = rows(&log(&lines)).unwrap();
    assert_eq!(rows.len(), 7);
    let want = Row {
        label: "w239".to_owned(),
        n: 900,
        w: 239,
        engine: 676_000,
        direct: 133_967_040,
    };
    assert_eq!(rows[3], want);
    assert!(super::rows(&log(&["bench row=x n=9 w=3 engine=1"])).is_err());
    assert!(super::rows(&log(&["bench row=x n=9 w=3 engine=1e3 direct=2"])).is_err());
    let verdict = Verdict::of(&rows).unwrap();
    assert_eq!(verdict.default, 563_360);
    assert!((verdict.flatness - 676_000.0 / 541_040.0).abs() < 1e-12 && verdict.flat());
    assert!((verdict.linearity - 1_086_400.0 / 305_040.0).abs() < 1e-12);
    // (563360 − 305040)/450 = 574.04, (1086400 − 563360)/900 = 581.16
    assert!((verdict.marginal[0] - 574.044_444).abs() < 1e-5);
    assert!((verdict.marginal[1] - 581.155_555).abs() < 1e-5);
    assert!(verdict.linear() && verdict.lines().contains("OVER"));
    let uneven = Verdict {
        marginal: [100.0, 200.0],
        ..verdict
    };
    assert!(!uneven.linear());
    let without: Vec<Row> = rows.into_iter().filter(|row| row.label != "n450").collect();
    assert!(Verdict::of(&without).is_err());
}

#[test]
fn frame_rows_are_held_to_their_own_ceilings_and_named() {
    let lines = [
        "frame bench frames=1601 min=930 median=945 max=1861 max_at=1 mean=1084",
        "frame bench scenario=gesture+look frames=1601 min=900 median=1830 max=3900 max_at=9 mean=1290",
        "frame bench rate=333 frames=1601 min=930 median=945 max=1861 max_at=7 mean=1084",
        "frame bench rate=333 scenario=gesture+look frames=2 min=1 median=2001 max=1 max_at=0 mean=1",
    ];
    let rows = FrameRow::all(&log(&lines)).unwrap();
    let want = FrameRow {
        rate: 50,
        scenario: None,
        frames: 1601,
        min: 930,
        median: 945,
        max: 1861,
        mean: 1084,
    };
    assert_eq!(rows[0], want);
    // 1,084 instructions of one 125 MHz cycle each in 20 ms; in 3003 µs.
    assert!((rows[0].load_percent() - 0.043_36).abs() < 1e-4);
    assert!((rows[2].load_percent() - 0.288_78).abs() < 1e-4);
    assert_eq!(rows[2].label(), "frame at 333 Hz");
    // 1,830 is over the idle row's 1,200 but within this row's 2,000.
    assert!(rows[0].within_budget() && rows[1].within_budget() && rows[2].within_budget());
    let slow = FrameRow {
        max: 4001,
        ..rows[0].clone()
    };
    assert!(!slow.within_budget());
    assert_eq!(
        frames_over_budget(&rows).unwrap(),
        "frame update over its ceiling: row `frame (gesture + look) at 333 Hz` takes 2,001 \
         instructions at the median and 1 at most (ceiling 2,000 and 4,000)"
    );
    assert_eq!(frames_over_budget(&rows[..3]), None);
    let err = FrameRow::all(&log(&lines[..3])).unwrap_err().to_string();
    assert!(
        err.contains("no `frame bench rate=333 scenario=gesture+look` line"),
        "{err}"
    );
    let mut juggling = lines.to_vec();
    juggling.push("frame bench scenario=juggling frames=2 min=1 median=1 max=1 max_at=0 mean=1");
    let err = FrameRow::all(&log(&juggling)).unwrap_err().to_string();
    assert!(err.contains("`frame (juggling)`"), "{err}");
    assert!(FrameRow::all(&log(&["frame bench frames=1 min=2"])).is_err());
}
