//! The console's stages of `cargo xtask test`: a flood of lines into a
//! QEMU run, and `cargo xtask console --qemu` itself with a script piped in.

use std::{
    io::Write,
    path::Path,
    process::{Command, Stdio},
    time::Duration,
};

use anyhow::{Context, Result, bail};
use idle_head_core::console::checksum;

use super::qemu::{Pace, qemu_session};
use crate::qemu::{self, Echo};

/// Lines the flood stage streams into the QEMU run.
pub const FLOOD_LINES: usize = 10_000;

/// The flood's lines: valid commands that do not move the head (the smoke
/// run's checks stay meaningful; motion is the host fuzz's), machine-mode
/// lines, and invalid lines of every kind; with the reply each must get
/// (`ok` or `err <code>` prefix, or `#` for machine mode).
fn flood_lines() -> Vec<(String, &'static str)> {
    const KINDS: [(&str, &str); 14] = [
        ("status", "ok mode="),
        ("help", "ok commands:"),
        ("servo pitch", "ok pitch neutral="),
        ("SERVO Yaw", "ok yaw neutral="),
        ("nodd", "err syntax "),
        ("idle amp 150", "err range "),
        ("look 5000", "err syntax "),
        ("servo neck neutral 1500", "err syntax "),
        ("servo roll min 2600", "err invalid "),
        ("nod 6k", "err syntax "),
        ("", "err syntax "),
        ("status \u{1b}[A", "err line "),
        ("#7 status *00", "#7 err line "),
        ("#12 status", "#12 err line "),
    ];
    let overlong = "x".repeat(120);
    (0..FLOOD_LINES)
        .map(|i| match i % 17 {
            15 => (overlong.clone(), "err line "),
            16 => {
                let body = format!("#{i} status");
                let crc = checksum(body.as_bytes());
                (format!("{body} *{crc:02x}"), "#")
            }
            k => {
                let (line, reply) = KINDS[k % KINDS.len()];
                (line.to_owned(), reply)
            }
        })
        .collect()
}

/// The flood stage: [`FLOOD_LINES`] lines into a QEMU run as fast as it
/// takes them; exactly one reply per line, each the one expected, and the
/// summary still `missed=0 pulse_violations=0` with the host's checksum.
pub fn flood(elf: &Path) -> Result<String> {
    let lines = flood_lines();
    let expected: Vec<&str> = lines.iter().map(|(_, want)| *want).collect();
    let input: Vec<u8> = lines
        .iter()
        .flat_map(|(line, _)| line.bytes().chain([b'\n']))
        .collect();
    let mut replies = Vec::with_capacity(FLOOD_LINES);
    let session = qemu_session(
        elf,
        input.as_slice(),
        |reply| replies.push(String::from_utf8_lossy(reply).into_owned()),
        Pace::Fast,
        Echo::Problems,
        Duration::from_secs(60),
    )?;
    let talk = &session.talk;
    let summary = session.summary().unwrap_or_default();
    println!("{}", session.run.describe());
    println!("{summary}");
    if !session.run.succeeded() {
        bail!("the firmware failed: {}", session.run.describe());
    }
    if let Some(early) = &talk.early {
        bail!("the session ended early: {early}");
    }
    if talk.sent != FLOOD_LINES || replies.len() != talk.sent || talk.replies != talk.sent {
        bail!("{} lines sent, {} replies", talk.sent, replies.len());
    }
    for (i, (reply, want)) in replies.iter().zip(&expected).enumerate() {
        if !reply.starts_with(want) {
            bail!("line {i}: reply {reply:?}, want one starting {want:?}");
        }
    }
    let verdict = qemu::check_summary(&session.run.log)?;
    if let Some(line) = session
        .run
        .log
        .iter()
        .find(|l| l.message.starts_with("console: the host hung up"))
    {
        println!("{}", line.message);
    }
    let frames = summary
        .split_whitespace()
        .find_map(|w| w.strip_prefix("frames="))
        .unwrap_or("?");
    Ok(format!(
        "flood: {} lines sent, {} replies (one each, as expected), in {:.2} s of wall time \
         ({:.2} s for the whole run, {frames} frames); {verdict}",
        talk.sent,
        replies.len(),
        talk.until_last_reply.as_secs_f64(),
        session.run.elapsed.as_secs_f64()
    ))
}

/// The console stage: `cargo xtask console --qemu` itself, a script piped
/// into its stdin; one reply per line on stdout, then the summary line. The
/// script has a line that is not UTF-8 (it must reach the firmware and be
/// answered, and the lines after it too), and its last line has no line end.
/// It changes the servos' rate while the head moves (to 333 Hz, saved,
/// back to 50 Hz with `defaults`, 333 Hz again with `load`): the run's
/// summary says no frame was missed and no pulse left its servo's limits.
pub fn piped_script() -> Result<String> {
    const SCRIPT: &[u8] = b"help\nstatus\nservo yaw\nservo yaw neutral 1520\nservo yaw\n\
                            idle amp 60\nservo rate 333\nnod\nservo rate\nseed 42\nsave\n\
                            defaults\nload\nservo yaw\nnodd\n\
                            nod \xff\nservo yaw min 2600\nstatus";
    const WANT: [&str; 18] = [
        "ok commands:",
        "ok mode=running",
        "ok yaw neutral=1500 ",
        "ok",
        "ok yaw neutral=1520 ",
        "ok idle=60",
        "ok servo rate=333 period_us=3003",
        "ok nod ",
        "ok servo rate=333 period_us=3003",
        "ok seed=42",
        "ok",
        "ok",
        "ok",
        "ok yaw neutral=1520 ",
        "err syntax unknown command `nodd`",
        "err line not UTF-8 from byte 4 on",
        "err invalid yaw servo:",
        "ok mode=running",
    ];
    let exe = std::env::current_exe().context("the xtask's own path")?;
    let mut child = Command::new(exe)
        .args(["console", "--qemu"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .context("starting `cargo xtask console --qemu`")?;
    child.stdin.take().context("its stdin")?.write_all(SCRIPT)?;
    let out = child.wait_with_output()?;
    let text = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = text.lines().collect();
    print!("{text}");
    if lines.len() != WANT.len() + 1 {
        bail!(
            "{} lines out for {} in, plus the summary",
            lines.len(),
            WANT.len()
        );
    }
    for (i, (got, want)) in lines.iter().zip(WANT).enumerate() {
        if !(got.starts_with(want) && (want != "ok" || *got == "ok")) {
            bail!("line {i}: {got:?}, want {want:?}");
        }
    }
    if !lines[WANT.len() - 1].ends_with(" rate=333") {
        bail!(
            "the last status {:?} is not at the loaded 333 Hz",
            lines[WANT.len() - 1]
        );
    }
    let summary = lines[WANT.len()];
    if !summary.starts_with("summary ") || !summary.contains(" missed=0 pulse_violations=0 ") {
        bail!("last line {summary:?}");
    }
    if !out.status.success() {
        bail!("`cargo xtask console --qemu` failed ({})", out.status);
    }
    Ok(format!(
        "console --qemu: {} lines, {} replies, then {summary}",
        WANT.len(),
        WANT.len()
    ))
}
