use super::*;

fn run(script: &str, seconds: u64) -> Trace {
    watched(script, seconds, None, &[])
}

/// The trace of `script` over `seconds`, with a `watch` and the replies to
/// `ask` after it.
fn watched(script: &str, seconds: u64, watch: Option<u8>, ask: &[&str]) -> Trace {
    let events = script::parse(script, &built_in().unwrap().1).unwrap();
    let micros = seconds * 1_000_000;
    simulate(micros, None, ServoRate::DEFAULT, &events, watch, ask).unwrap()
}

#[test]
fn idle_only_is_the_plain_frame_loop() {
    // No script: the same pulses as the driver fed by the playback alone.
    let trace = run("", 3);
    assert_eq!(trace.rows.len(), 150);
    // The first frame: neutral pulses, 1500 µs as 4800 counts of 312.5 ns.
    assert_eq!(trace.rows[0].angles, [0; 3]);
    assert_eq!(trace.rows[0].pulses, [1_500_000; 3]);
    let driver = DriverConfig::DEFAULT.build().unwrap();
    let playback = Playback::new(LOOP_DURATION, driver.config().frame_period, DEFAULT_N).unwrap();
    let mut source = idle(playback, None).unwrap();
    let period = driver.config().frame_period;
    let mut plain = FrameDriver::new([Channel::at(period).unwrap(); 3], driver);
    for row in &trace.rows {
        let report = plain.write_frame(source.offsets(Timestamp(row.t_us)));
        assert_eq!(row.angles, report.servos.map(|s| s.angle.millidegrees()));
    }
}

#[test]
fn a_looks_return_is_marked_where_the_head_goes_back() {
    // The idle motion off (it fades out in 1 s): only the gaze moves.
    let trace = run("0 idle off\n2 look 10000 0 500 hold=1000\n", 6);
    let returns = |m: &&Mark| m.kind == marks::Kind::Return;
    let back: Vec<&Mark> = trace.marks.iter().filter(returns).collect();
    assert_eq!(back.len(), 1, "{:?}", trace.marks);
    let back = back[0];
    // 500 ms there, the 1 s hold, then back: the mark is at the frame that
    // plays the first step back (as a gesture's is at its first step).
    assert_eq!(back.t_ms, 3500);
    assert_eq!(back.axes, [Axis::Pitch, Axis::Yaw]);
    let pitch = |t_ms: u64| trace.rows[usize::try_from(t_ms / 20).unwrap()].angles[0];
    assert_eq!(pitch(back.t_ms - 40), 10_000);
    assert_eq!(pitch(back.t_ms - 20), 10_000);
    assert!(pitch(back.t_ms) < 10_000);
    assert!(pitch(back.t_ms + back.span_ms - 40) > 0);
    assert_eq!(pitch(back.t_ms + back.span_ms - 20), 0);
    assert_eq!(
        back.reply,
        format!(
            "(the look at line 2 returns to the centre after its 1000 ms hold, in {} ms)",
            back.span_ms
        )
    );
    // The marks are in time order.
    assert!(trace.marks.windows(2).all(|w| w[0].t_ms <= w[1].t_ms));
}

#[test]
fn a_return_is_cut_or_left_out_by_the_next_gaze_move() {
    let returns = |script: &str| -> Vec<(u64, u64)> {
        let marks = run(script, 8).marks.into_iter();
        let back = marks.filter(|m| m.kind == marks::Kind::Return);
        back.map(|m| (m.t_ms, m.span_ms)).collect()
    };
    let look = "2 look 10000 0 500 hold=1000\n";
    let whole = returns(look);
    assert_eq!(whole.len(), 1);
    assert!(whole[0].1 > 100);
    // A center before the return starts: there is none.
    assert_eq!(returns(&format!("{look}3 center\n")), []);
    // Another look while it plays: it ends there.
    assert_eq!(
        returns(&format!("{look}3.6 look 0 5000 hold=stay\n")),
        [(3500, 100)]
    );
    // A nod does not touch it; a return after the end is left out.
    assert_eq!(returns(&format!("{look}3.6 nod\n")), whole);
    assert_eq!(returns("7.5 look 10000 0 500 hold=1000\n"), []);
}

#[test]
fn a_scripted_nod_moves_pitch_only_and_answers() {
    let idle = run("", 6);
    let nodding = run("3 nod 6000 800\n", 6);
    assert_eq!(nodding.marks.len(), 1);
    let reply = &nodding.marks[0].reply;
    assert_eq!(reply, "ok nod amp_mdeg=6000 ms=800 cycles=2 intensity=50");
    let frame = |t: &Trace, k: usize| t.rows[k].angles;
    for k in 0..300 {
        let (a, b) = (frame(&idle, k), frame(&nodding, k));
        assert_eq!((a[1], a[2]), (b[1], b[2]), "frame {k}");
        if !(150..230).contains(&k) {
            assert_eq!(a[0], b[0], "frame {k}");
        }
    }
    // The first dip (10 frames from 149, the last frame mixed before
    // the nod) is the nod's 6°, over the idle ducked by 60 %.
    let dip = frame(&nodding, 159)[0] - frame(&idle, 159)[0];
    let ducked = -frame(&idle, 159)[0] * 6 / 10;
    assert!(
        (dip - 6000 - ducked).abs() <= 3,
        "{dip}, ducked by {ducked}"
    );
}

#[test]
fn a_button_runs_its_action_within_a_frame_of_its_edge() {
    let trace = run("0 input 3 button nod 6000\n3 pin 3 low\n", 5);
    let nod = trace.marks.iter().find(|m| m.label == "inputs:").unwrap();
    // Pressed at 3 s (the press counts at its edge), taken by the frame
    // due then, which is already a step into the nod.
    assert_eq!(nod.t_ms, 3000);
    let reply = &nod.reply;
    assert!(reply.starts_with("ok nod amp_mdeg=6000 "), "{reply}");
    let idle = run("", 5);
    let first = (150..250).find(|&k| trace.rows[k].angles[0] != idle.rows[k].angles[0]);
    assert_eq!(first, Some(150));
}

/// `--telemetry`: a line per tick of `watch` (the first frame at or after
/// each), the core's own; with the radar on, its people and whom the head
/// attends to.
#[test]
fn the_telemetry_of_a_trace_carries_the_radars_people() {
    let script = "0 idle off\n1 radar on\n1.2 radar 400,2000 -900,3000\n";
    let trace = watched(script, 3, Some(20), &["radar", "track"]);
    let lines = trace.watch.unwrap().lines;
    // 3 s at 20 a second: ticks at 0, 50, …, 2950 ms, each taken by the
    // first 20 ms frame at or after it.
    assert_eq!(lines.len(), 60);
    let time = |l: &String| l.split_whitespace().nth(1).unwrap()[2..].parse().unwrap();
    let times: Vec<u64> = lines.iter().map(time).collect();
    assert_eq!(&times[..4], [0, 60, 100, 160]);
    for line in &lines {
        let (body, crc) = line.rsplit_once(" *").unwrap();
        let sum = idle_head_core::console::checksum(body.as_bytes());
        assert_eq!(crc, format!("{sum:02x}"), "{line}");
    }
    assert!(!lines[19].contains("targets="), "{}", lines[19]);
    let nobody = &lines[21];
    assert!(nobody.contains(" targets=0 at=- xy=- who=- *"), "{nobody}");
    let last = lines.last().unwrap();
    assert!(
        last.contains(" targets=2 at=") && last.contains(" xy=400,2000;-900,3000 who=0 *"),
        "{last}"
    );
    // The radar sends from power-up, ten frames a second: 0 to 2.9 s.
    assert_eq!(trace.answers[0], "ok radar=on frames=30 bad=0 targets=2");
    let tracking = &trace.answers[1];
    assert_eq!(tracking, "ok track=on height=300 mount=0 prefer=nearest");
}
