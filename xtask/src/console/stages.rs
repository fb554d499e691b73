//! The console's stage of `cargo xtask test`: `cargo xtask console --qemu`
//! itself with a script piped in.

use std::{
    io::Write,
    process::{Command, Stdio},
};

use anyhow::{Context, Result, bail};

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
