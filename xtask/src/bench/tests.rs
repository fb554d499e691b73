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

fn log() -> Vec<LogLine> {
    std::iter::once("boot")
        .chain(LOG)
        .map(|message| LogLine {
            level: Some("INFO".to_owned()),
            message: message.to_owned(),
            timestamp: None,
            location: None,
        })
        .collect()
}

#[test]
fn parses_bench_lines_and_skips_others() {
    let row = Row::parse(LOG[3]).unwrap().unwrap();
    assert_eq!(
        row,
        Row {
            label: "w239".to_owned(),
            n: 900,
            w: 239,
            engine: 676_000,
            direct: 133_967_040,
        }
    );
    assert!(Row::parse("summary frames=900").unwrap().is_none());
    assert!(Row::parse("bench row=x n=9 w=3 engine=1").is_err());
    assert!(Row::parse("bench row=x n=9 w=3 engine=1e3 direct=2").is_err());
    assert_eq!(rows(&log()).unwrap().len(), 7);
}

#[test]
fn derived_columns() {
    let row = Row::parse(LOG[0]).unwrap().unwrap();
    assert!((row.ratio() - 37_010_000.0 / 563_360.0).abs() < 1e-9);
}

#[test]
fn verdict_of_the_sample_log() {
    let verdict = Verdict::of(&rows(&log()).unwrap()).unwrap();
    assert_eq!(verdict.default, 563_360);
    assert!(!verdict.within_budget());
    assert!((verdict.flatness - 676_000.0 / 541_040.0).abs() < 1e-12);
    assert!(verdict.flat());
    assert!((verdict.linearity - 1_086_400.0 / 305_040.0).abs() < 1e-12);
    // (563360 − 305040)/450 = 574.04, (1086400 − 563360)/900 = 581.16
    assert!((verdict.marginal[0] - 574.044_444).abs() < 1e-5);
    assert!((verdict.marginal[1] - 581.155_555).abs() < 1e-5);
    assert!(verdict.linear());
    assert!(verdict.lines().contains("OVER"));
    let quadratic = Verdict {
        marginal: [100.0, 200.0],
        ..verdict
    };
    assert!(!quadratic.linear());
    let mut rows = rows(&log()).unwrap();
    rows.retain(|row| row.label != "n450");
    assert!(Verdict::of(&rows).is_err());
}

#[test]
fn frame_row_is_parsed_and_held_to_its_ceiling() {
    let line = "frame bench frames=1601 min=930 median=945 max=1861 max_at=1 mean=1084";
    let row = FrameRow::parse(line).unwrap().unwrap();
    assert_eq!(
        row,
        FrameRow {
            rate: 50,
            scenario: None,
            frames: 1601,
            min: 930,
            median: 945,
            max: 1861,
            max_at: 1,
            mean: 1084,
        }
    );
    assert!(row.within_budget());
    // 1,084 instructions of one 125 MHz cycle each in 20 ms.
    assert!(
        (row.load_percent() - 0.043_36).abs() < 1e-4,
        "{}",
        row.load_percent()
    );
    let slow = FrameRow {
        median: 1201,
        ..row.clone()
    };
    assert!(!slow.within_budget());
    let spiky = FrameRow { max: 4001, ..row };
    assert!(!spiky.within_budget());
    // At 333 Hz: its own label, the period rounded to 3003 µs, the load
    // over it.
    let fast = FrameRow::parse(
        "frame bench rate=333 frames=1601 min=930 median=945 max=1861 max_at=7 mean=1084",
    )
    .unwrap()
    .unwrap();
    assert_eq!(
        (fast.rate, fast.label()),
        (333, "frame at 333 Hz".to_owned())
    );
    assert_eq!(fast.period_us(), 3003);
    // 8.672 µs in 3003 µs.
    assert!(
        (fast.load_percent() - 0.288_78).abs() < 1e-4,
        "{}",
        fast.load_percent()
    );
    assert!(
        FrameRow::parse("bench row=default n=900")
            .unwrap()
            .is_none()
    );
    assert!(FrameRow::parse("frame bench frames=1 min=2").is_err());
    // The benchmark rows ignore the frame line and the other way round.
    assert!(Row::parse(line).unwrap().is_none());
    assert!(FrameRow::all(&log()).is_err());
    let active =
        "frame bench scenario=gesture+look frames=1601 min=1 median=2 max=3 max_at=4 mean=5";
    let active = FrameRow::parse(active).unwrap().unwrap();
    assert_eq!(active.scenario.as_deref(), Some("gesture+look"));
}

#[test]
fn each_frame_row_is_held_to_its_own_ceiling_and_named() {
    let idle =
        FrameRow::parse("frame bench frames=1601 min=880 median=890 max=1500 max_at=1 mean=950")
            .unwrap()
            .unwrap();
    let busy = FrameRow::parse(
        "frame bench scenario=gesture+look frames=1601 min=900 median=1930 max=3900 max_at=9 mean=1290",
    )
    .unwrap()
    .unwrap();
    let busy = FrameRow {
        median: 1830,
        ..busy
    };
    // 1,830 is over the idle row's 1,200 but within this row's 2,000:
    // no OVER printed for it, and the bench passes.
    assert!(busy.within_budget());
    assert_eq!(frames_over_budget(&[idle.clone(), busy.clone()]), None);
    let slow_busy = FrameRow {
        median: 2001,
        rate: 333,
        ..busy.clone()
    };
    let message = frames_over_budget(&[idle.clone(), slow_busy]).unwrap();
    assert_eq!(
        message,
        "frame update over its ceiling: row `frame (gesture + look) at 333 Hz` takes 2,001 \
         instructions at the median and 3,900 at most (ceiling 2,000 and 4,000)"
    );
    let spiky_idle = FrameRow { max: 4001, ..idle };
    let message = frames_over_budget(&[spiky_idle, busy]).unwrap();
    assert!(message.contains("`frame` takes 890 instructions at the median and 4,001"));
    assert!(!message.contains("gesture"), "{message}");
}

#[test]
fn a_frame_row_of_an_unknown_scenario_or_a_missing_rate_is_an_error() {
    let log: Vec<LogLine> = [
        "frame bench rate=50 frames=2 min=1 median=1 max=1 max_at=0 mean=1",
        "frame bench rate=50 scenario=gesture+look frames=2 min=1 median=1 max=1 max_at=0 mean=1",
        "frame bench rate=333 frames=2 min=1 median=1 max=1 max_at=0 mean=1",
        "frame bench rate=333 scenario=gesture+look frames=2 min=1 median=1 max=1 max_at=0 mean=1",
        "frame bench scenario=juggling frames=2 min=1 median=1 max=1 max_at=0 mean=1",
    ]
    .into_iter()
    .map(|message| LogLine::new("INFO", message))
    .collect();
    let err = FrameRow::all(&log).unwrap_err().to_string();
    assert!(err.contains("`frame (juggling)`"), "{err}");
    assert_eq!(FrameRow::all(&log[..4]).unwrap().len(), 4);
    let err = FrameRow::all(&log[..3]).unwrap_err().to_string();
    assert!(
        err.contains("no `frame bench rate=333 scenario=gesture+look` line"),
        "{err}"
    );
}
