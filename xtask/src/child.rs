//! A child process run to its end: its stdout and stderr read on threads of
//! their own while it runs (so that neither pipe fills up and stalls it),
//! something else done meanwhile on this thread, and a wall-clock limit past
//! which it is killed. QEMU and the emulator harness run through it.

use std::{
    process::{Child, ChildStderr, ChildStdout},
    thread,
    time::Duration,
};

use anyhow::{Context, Result, anyhow};
use wait_timeout::ChildExt;

use crate::log::Exit;

/// What a child left behind.
#[derive(Debug)]
pub struct Finished<O, E, R> {
    /// How it ended.
    pub exit: Exit,
    /// What the stdout reader returned.
    pub stdout: O,
    /// What the stderr reader returned.
    pub stderr: E,
    /// What `meanwhile` returned.
    pub meanwhile: R,
}

/// Runs `child` (spawned with its stdout and stderr piped) to its end:
/// `stdout` and `stderr` each read their pipe on a thread of their own,
/// `meanwhile` runs on this thread; once it returns, `child` has `timeout`
/// to exit before it is killed. The readers end with the pipes, when the
/// child has exited.
///
/// # Errors
/// A pipe that was not set up, a failed wait, or a reader that panicked.
pub fn run<O: Send, E: Send, R>(
    mut child: Child,
    name: &str,
    timeout: Duration,
    stdout: impl FnOnce(ChildStdout) -> O + Send,
    stderr: impl FnOnce(ChildStderr) -> E + Send,
    meanwhile: impl FnOnce() -> R,
) -> Result<Finished<O, E, R>> {
    let (Some(out), Some(err)) = (child.stdout.take(), child.stderr.take()) else {
        let _ = child.kill();
        let _ = child.wait();
        return Err(anyhow!(
            "{name} was started without piped stdout and stderr"
        ));
    };
    thread::scope(|scope| {
        let out = scope.spawn(move || stdout(out));
        let err = scope.spawn(move || stderr(err));
        let meanwhile = meanwhile();
        let exit = wait_or_kill(&mut child, name, timeout)?;
        let stdout = out
            .join()
            .map_err(|_| anyhow!("the reader of {name}'s stdout panicked"))?;
        let stderr = err
            .join()
            .map_err(|_| anyhow!("the reader of {name}'s stderr panicked"))?;
        Ok(Finished {
            exit,
            stdout,
            stderr,
            meanwhile,
        })
    })
}

/// Waits for `child` to exit, at most `timeout`; kills it past that.
fn wait_or_kill(child: &mut Child, name: &str, timeout: Duration) -> Result<Exit> {
    if let Some(status) = child
        .wait_timeout(timeout)
        .with_context(|| format!("waiting for {name}"))?
    {
        return Ok(Exit::Status(status));
    }
    let _ = child.kill();
    let _ = child.wait();
    Ok(Exit::TimedOut(timeout))
}

#[cfg(test)]
mod tests {
    use std::{
        io::Read,
        process::{Command, Stdio},
        time::Instant,
    };

    use super::*;

    fn spawn(script: &str) -> Child {
        Command::new("sh")
            .args(["-c", script])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    }

    fn text(mut pipe: impl Read) -> String {
        let mut text = String::new();
        pipe.read_to_string(&mut text).unwrap();
        text
    }

    #[test]
    fn both_pipes_are_read_and_meanwhile_runs_before_the_wait() {
        // More than a pipe holds on each stream: neither may stall the child.
        let child = spawn("head -c 200000 /dev/zero; head -c 100000 /dev/zero >&2; exit 3");
        let done = run(
            child,
            "sh",
            Duration::from_secs(60),
            |out| text(out).len(),
            |err| text(err).len(),
            || 7,
        )
        .unwrap();
        assert_eq!(
            (done.stdout, done.stderr, done.meanwhile),
            (200_000, 100_000, 7)
        );
        assert!(matches!(done.exit, Exit::Status(status) if status.code() == Some(3)));
    }

    #[test]
    fn a_hung_child_is_killed_at_the_timeout() {
        // A program that does not end stands for a hung firmware: the wait
        // ends at the limit, not with the program.
        let start = Instant::now();
        let done = run(
            spawn("exec sleep 30"),
            "sleep",
            Duration::from_millis(200),
            text,
            text,
            || (),
        )
        .unwrap();
        assert!(matches!(done.exit, Exit::TimedOut(limit) if limit.as_millis() == 200));
        assert!(start.elapsed() < Duration::from_secs(10));
        let done = run(
            spawn("true"),
            "true",
            Duration::from_secs(60),
            text,
            text,
            || (),
        )
        .unwrap();
        assert!(matches!(done.exit, Exit::Status(status) if status.success()));
    }

    #[test]
    fn the_timeout_counts_from_the_end_of_meanwhile() {
        // The child takes longer than the limit, but ends while meanwhile
        // still runs: it is not killed.
        let done = run(
            spawn("sleep 0.3"),
            "sleep",
            Duration::from_millis(200),
            text,
            text,
            || thread::sleep(Duration::from_millis(600)),
        )
        .unwrap();
        assert!(matches!(done.exit, Exit::Status(status) if status.success()));
    }

    #[test]
    fn a_child_without_pipes_is_an_error_and_is_not_left_running() {
        let child = Command::new("sleep").arg("30").spawn().unwrap();
        let id = child.id();
        let err = run(child, "sleep", Duration::from_secs(1), text, text, || ()).unwrap_err();
        assert!(err.to_string().contains("without piped"), "{err}");
        assert!(!std::path::Path::new(&format!("/proc/{id}")).exists());
    }
}
