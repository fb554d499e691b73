//! `cargo xtask console` run as a person runs it, a script piped in: the
//! console stage of `cargo xtask test`, and the panel's serial port session.

use std::process::Command;

use anyhow::{Result, bail, ensure};

use crate::project;

/// Runs `cargo xtask console <args>` itself with `script` piped into its
/// stdin; fails unless it succeeds and its stdout is `want`, one reply a
/// line (a bare `ok` exactly, the others as the line's start), then `more`
/// lines. Its stdout's lines.
pub fn script(args: &[&str], script: &[u8], want: &[&str], more: usize) -> Result<Vec<String>> {
    let exe = project::exe()?;
    let (text, status) = project::output(Command::new(exe).arg("console").args(args), script)?;
    let lines: Vec<String> = text.lines().map(str::to_owned).collect();
    ensure!(
        lines.len() == want.len() + more,
        "{} lines out for {} in, plus {more}",
        lines.len(),
        want.len()
    );
    for (i, (got, want)) in lines.iter().zip(want).enumerate() {
        let good = got.starts_with(want) && (*want != "ok" || got == "ok");
        ensure!(good, "line {i}: {got:?}, want {want:?}");
    }
    ensure!(status.success(), "`cargo xtask console` failed ({status})");
    Ok(lines)
}

/// The console stage: `cargo xtask console --qemu` with a line not UTF-8, no
/// last line end and rate changes while the head moves (333 Hz saved, 50 Hz
/// by `defaults`, 333 by `load`): a reply a line, then a clean summary.
pub fn piped_script() -> Result<()> {
    const SCRIPT: &[u8] = b"help\nstatus\nservo yaw\nservo yaw neutral 1520\nservo yaw\n\
                            idle amp 60\nservo rate 333\nnod\nservo rate\nseed 42\nsave\n\
                            defaults\nload\nservo yaw\nnodd\n\
                            nod \xff\nservo yaw min 2600\nstatus";
    const WANT: &str = "ok commands:|ok mode=running|ok yaw neutral=1500 |ok|\
                        ok yaw neutral=1520 |ok idle=60|ok servo rate=333 period_us=3003|ok nod |\
                        ok servo rate=333 period_us=3003|ok seed=42|ok|ok|ok|ok yaw neutral=1520 |\
                        err syntax unknown command `nodd`|err line not UTF-8 from byte 4 on|\
                        err invalid yaw servo:|ok mode=running";
    let want: Vec<&str> = WANT.split('|').collect();
    let lines = script(&["--qemu"], SCRIPT, &want, 1)?;
    let (status, summary) = (&lines[want.len() - 1], &lines[want.len()]);
    if !status.ends_with(" rate=333") {
        bail!("the last status {status:?} is not at the loaded 333 Hz");
    }
    if !summary.starts_with("summary ") || !summary.contains(" missed=0 pulse_violations=0 ") {
        bail!("last line {summary:?}");
    }
    let n = want.len();
    println!("console --qemu: {n} lines, {n} replies, then {summary}");
    Ok(())
}
