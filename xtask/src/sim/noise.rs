//! Line noise on UART0: `sta`, a byte with a framing error, `tus`, then
//! `status`. The first line must be answered `err line bytes lost …`, the
//! second `ok mode=…`, and every pulse stays the host's.

use std::{fmt::Write as _, path::Path, time::Duration};

use anyhow::Result;

use super::{
    node::UartScript,
    run::{self, Report},
    stages::{WALL, conclude, shipped_image},
};
use crate::project::Metadata;

/// Stage name.
pub const NOISE_STAGE: &str = "Pico image in the RP2040 emulator: a byte with a framing \
     error on UART0: its line answered `err line bytes lost`, the next one `ok`";

/// The bytes sent, and which of them arrives with a framing error.
const SCRIPT: &[u8] = b"staXtus\r\nstatus\r\n";
const NOISY: usize = 3;
/// When the script goes out (after the fade-in), and the whole run.
const AT: Duration = Duration::from_secs(3);
const TIME: Duration = Duration::from_millis(3_500);
/// The replies, as prefixes.
const REPLIES: [&str; 2] = ["err line bytes lost", "ok mode="];

/// Runs the scenario and checks it (see the module docs).
pub fn test_noise(root: &Path, metadata: &Metadata) -> Result<()> {
    let elf = shipped_image(root, metadata)?;
    let mut report = run::run_with(root, &elf, TIME, WALL, |config| {
        config.uart = vec![UartScript {
            errors: vec![NOISY],
            ..UartScript::new(0, SCRIPT.to_vec(), AT)
        }];
    })?;
    run::check(&mut report)?;
    conclude(&report, check(&report))
}

/// The replies against [`REPLIES`]: a transcript and the problems found.
fn check(report: &Report) -> (String, Vec<String>) {
    let Some(boot) = report.boots.first() else {
        return (String::new(), vec!["no boot".to_owned()]);
    };
    let replies = boot.uart_replies();
    let mut transcript =
        String::from("UART0, `sta` + a byte with a framing error + `tus`, then `status`:\n");
    for reply in &replies {
        let _ = writeln!(transcript, "  < {reply}");
    }
    let fits = replies.len() == REPLIES.len()
        && replies
            .iter()
            .zip(REPLIES)
            .all(|(got, want)| got.starts_with(want));
    let problems = if fits {
        Vec::new()
    } else {
        vec![format!(
            "replies {replies:?}, not `{}…` and `{}…`",
            REPLIES[0], REPLIES[1]
        )]
    };
    (transcript, problems)
}
