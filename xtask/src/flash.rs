//! `cargo xtask flash`: the runner of `cargo run --release` (see
//! `.cargo/config.toml`), which puts the image on the board whichever way
//! this machine has:
//!
//! 1. a board in BOOTSEL mode is plugged in (its boot ROM's USB drive is
//!    mounted): the image's UF2 is copied onto the drive. This comes first:
//!    a board is only in BOOTSEL mode when someone held its button to put
//!    it there, and it waits for a UF2;
//! 2. `probe-rs` is installed: `probe-rs run --chip …`, which flashes
//!    through a debug probe and shows the log;
//! 3. neither: the UF2 is written anyway, and the message says how to use
//!    it, or what to install.
//!
//! cargo runs this while it holds no lock, so the nested `cargo xtask`
//! (which builds this crate first) cannot wait on the outer `cargo run`.

use std::{
    ffi::{OsStr, OsString},
    fs::File,
    io::Write as _,
    path::{Path, PathBuf},
    process::Command,
};

use anyhow::{Context, Result, bail};

use crate::{board::Board, project, uf2};

/// The file a board's boot ROM shows on its BOOTSEL drive, with the line
/// `Board-ID: <label>`.
pub const INFO_FILE: &str = "INFO_UF2.TXT";

/// The command that installs probe-rs.
pub const INSTALL_PROBE_RS: &str = "cargo install probe-rs-tools --locked";

/// `cargo xtask flash`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The board the image is for.
    #[arg(long, value_enum)]
    pub board: Board,
    /// The firmware ELF (cargo passes it to its runner).
    #[arg(value_name = "ELF")]
    pub elf: PathBuf,
    /// Anything after the ELF (`cargo run --release -- …`), passed on to
    /// probe-rs.
    #[arg(
        value_name = "ARGS",
        trailing_var_arg = true,
        allow_hyphen_values = true
    )]
    pub rest: Vec<OsString>,
}

/// What the runner looks at on this machine.
#[derive(Debug, Clone)]
pub struct Surroundings {
    /// The `PATH` searched for `probe-rs`.
    pub path: Option<OsString>,
    /// The folder relative `PATH` entries start from.
    pub cwd: PathBuf,
    /// Folders where removable drives are mounted (each one a drive, or
    /// holding drives as its subfolders).
    pub mounts: Vec<PathBuf>,
}

impl Surroundings {
    /// This machine's: its `PATH`, and where its system mounts USB drives.
    pub fn here() -> Self {
        let mut mounts = Vec::new();
        if cfg!(windows) {
            // Every drive letter is a mount of its own.
            mounts.extend(
                (b'A'..=b'Z').map(|letter| PathBuf::from(format!("{}:\\", letter as char))),
            );
        } else {
            let user = std::env::var_os("USER").or_else(|| std::env::var_os("LOGNAME"));
            if let Some(user) = user {
                // udisks (GNOME, KDE): /media/<user>/<label> on Debian and
                // Ubuntu, /run/media/<user>/<label> on Fedora and Arch.
                mounts.push(Path::new("/media").join(&user));
                mounts.push(Path::new("/run/media").join(&user));
            }
            // Other Linux setups, and macOS.
            mounts.extend(["/media", "/mnt", "/Volumes"].map(PathBuf::from));
        }
        Self {
            path: std::env::var_os("PATH"),
            cwd: std::env::current_dir().unwrap_or_default(),
            mounts,
        }
    }
}

/// How the image goes onto the board.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Route {
    /// Copy the UF2 onto this mounted BOOTSEL drive.
    Drive(PathBuf),
    /// Run this `probe-rs`.
    Probe(PathBuf),
    /// No way found: say what to do.
    Instructions,
}

/// The `probe-rs` that `path` finds, if any.
pub fn probe_rs(path: Option<&OsStr>, cwd: &Path) -> Option<PathBuf> {
    which::which_in("probe-rs", path, cwd).ok()
}

/// Whether `dir` is the BOOTSEL drive of a `board`: its `INFO_UF2.TXT`
/// names the board's chip.
pub fn is_bootsel_drive(dir: &Path, board: Board) -> bool {
    let Ok(info) = std::fs::read_to_string(dir.join(INFO_FILE)) else {
        return false;
    };
    let id = format!("Board-ID: {}", board.drive_label());
    info.lines().any(|line| line.trim() == id)
}

/// The BOOTSEL drives of `board` in `mounts`: each mount itself, or a
/// folder in it.
pub fn bootsel_drives(board: Board, mounts: &[PathBuf]) -> Vec<PathBuf> {
    let mut drives = Vec::new();
    for mount in mounts {
        if is_bootsel_drive(mount, board) {
            drives.push(mount.clone());
            continue;
        }
        let Ok(entries) = std::fs::read_dir(mount) else {
            continue;
        };
        let mut found: Vec<PathBuf> = entries
            .filter_map(|entry| entry.ok().map(|entry| entry.path()))
            .filter(|dir| is_bootsel_drive(dir, board))
            .collect();
        found.sort();
        drives.extend(found);
    }
    // One drive may be reached through two mounts (a symbolic link).
    drives.sort();
    drives.dedup();
    drives
}

/// The route for `board` here: a BOOTSEL drive, else probe-rs, else
/// instructions.
///
/// # Errors
/// If more than one board of the kind is in BOOTSEL mode: which one is
/// meant cannot be told.
pub fn choose(board: Board, here: &Surroundings) -> Result<Route> {
    let drives = bootsel_drives(board, &here.mounts);
    match drives.as_slice() {
        [drive] => return Ok(Route::Drive(drive.clone())),
        [] => {}
        several => bail!(
            "{} boards in BOOTSEL mode ({}): unplug all but the one to flash",
            several.len(),
            several
                .iter()
                .map(|drive| drive.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
    Ok(match probe_rs(here.path.as_deref(), &here.cwd) {
        Some(probe) => Route::Probe(probe),
        None => Route::Instructions,
    })
}

/// Writes `bytes` to `<drive>/<bin>.uf2`, and to the device: the board
/// starts flashing as the blocks arrive and restarts after the last.
fn copy_to_drive(bytes: &[u8], drive: &Path, board: Board) -> Result<PathBuf> {
    let target = drive.join(format!("{}.uf2", board.bin()));
    let mut file =
        File::create(&target).with_context(|| format!("creating {}", target.display()))?;
    file.write_all(bytes)
        .with_context(|| format!("writing {}", target.display()))?;
    if let Err(error) = file.sync_all() {
        // The board may restart, and its drive vanish, as the last block
        // lands, before the system has heard back.
        eprintln!(
            "note: the drive did not confirm the end of the copy ({error}); if the board \
             restarted, the copy was complete"
        );
    }
    Ok(target)
}

/// What to do when nothing could flash the board; `uf2` is the image's UF2,
/// ready to copy, and `mounts` where the runner looked for the board.
pub fn instructions(board: Board, uf2: &Path, mounts: &[PathBuf]) -> String {
    let name = board.name();
    let label = board.drive_label();
    let uf2 = project::relative(uf2);
    let uf2 = uf2.display();
    let looked = if cfg!(windows) {
        "on every drive letter".to_owned()
    } else {
        let list: Vec<String> = mounts.iter().map(|m| m.display().to_string()).collect();
        format!("in {}", list.join(", "))
    };
    let mut text = String::new();
    let mut line = |line: &str| {
        text.push_str(line);
        text.push('\n');
    };
    line(&format!(
        "Nothing was flashed: no {name} is in BOOTSEL mode, and probe-rs is not installed."
    ));
    line(&format!(
        "(No drive whose {INFO_FILE} says `Board-ID: {label}` {looked}.)"
    ));
    line("");
    line(&format!("The image is ready as a UF2 file: {uf2}"));
    line("");
    line("Flash it over USB, with nothing else to buy:");
    line(&format!(
        "  1. Unplug the {name}. Hold its BOOTSEL button while you plug it in, then"
    ));
    line(&format!("     let go: a USB drive called {label} appears."));
    line("  2. Run `cargo run --release` again: it copies the UF2 onto the drive.");
    line(&format!("     Or copy {uf2} onto the drive yourself."));
    line("  The board restarts and runs the new firmware when the copy is complete.");
    line("");
    line("Or flash it through a debug probe, which also shows the firmware's log (a");
    line("Raspberry Pi Debug Probe or any CMSIS-DAP probe, wired to the board's SWCLK,");
    line("SWDIO and GND):");
    line(&format!(
        "  install probe-rs once with:  {INSTALL_PROBE_RS}"
    ));
    line("  then run `cargo run --release` again.");
    line("");
    line("Both routes step by step: docs/user/flashing.md");
    text.truncate(text.trim_end().len());
    text
}

/// `cargo xtask flash` on this machine.
///
/// # Errors
/// See [`run`].
pub fn command(args: &Args) -> Result<bool> {
    run(args, &Surroundings::here())
}

/// Flashes `args.elf` onto the board by the route [`choose`] finds in
/// `here`. `Ok(false)` if there was none (the message says what to do) or
/// probe-rs failed.
///
/// # Errors
/// If the UF2 cannot be made or copied, probe-rs cannot be started, or
/// [`choose`] fails.
pub fn run(args: &Args, here: &Surroundings) -> Result<bool> {
    let board = args.board;
    match choose(board, here)? {
        Route::Drive(drive) => {
            let (path, made) = uf2::write(&args.elf, board)?;
            println!("{}", uf2::describe(&path, board, &made.layout));
            let target = copy_to_drive(&made.bytes, &drive, board)?;
            println!(
                "Copied to {}: the {} restarts and runs it.",
                target.display(),
                board.name()
            );
            println!(
                "The log (defmt over RTT) needs a debug probe; the console is on the board's \
                 USB port: `cargo xtask console`."
            );
            Ok(true)
        }
        Route::Probe(probe) => {
            let mut command = Command::new(&probe);
            command
                .arg("run")
                .arg("--chip")
                .arg(board.probe_rs_chip())
                .arg(&args.elf)
                .args(&args.rest);
            eprintln!(
                "$ probe-rs run --chip {} {}",
                board.probe_rs_chip(),
                args.elf.display()
            );
            let status = command
                .status()
                .with_context(|| format!("running {}", probe.display()))?;
            Ok(status.success())
        }
        Route::Instructions => {
            let (path, _) = uf2::write(&args.elf, board)?;
            eprintln!("{}", instructions(board, &path, &here.mounts));
            Ok(false)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PICO_INFO: &str =
        "UF2 Bootloader v3.0\r\nModel: Raspberry Pi RP2\r\nBoard-ID: RPI-RP2\r\n";
    const PICO2_INFO: &str = "UF2 Bootloader v1.0\nModel: Raspberry Pi RP2350\nBoard-ID: RP2350\n";

    /// A folder of mounts with one drive `label` whose info file says `info`.
    fn mount_with(label: &str, info: &str) -> tempfile::TempDir {
        let mounts = tempfile::tempdir().unwrap();
        let drive = mounts.path().join(label);
        std::fs::create_dir(&drive).unwrap();
        std::fs::write(drive.join(INFO_FILE), info).unwrap();
        mounts
    }

    /// Surroundings with `path` as PATH and `mounts` to look in.
    fn here(path: &Path, mounts: &[&Path]) -> Surroundings {
        Surroundings {
            path: Some(path.as_os_str().to_owned()),
            cwd: path.to_owned(),
            mounts: mounts.iter().map(|m| m.to_path_buf()).collect(),
        }
    }

    /// A folder for PATH with an executable `probe-rs` that writes its
    /// arguments, one a line, to `args.txt` beside it.
    #[cfg(unix)]
    fn fake_probe_rs() -> tempfile::TempDir {
        use std::os::unix::fs::PermissionsExt;
        let bin = tempfile::tempdir().unwrap();
        let probe = bin.path().join("probe-rs");
        let log = bin.path().join("args.txt");
        std::fs::write(
            &probe,
            format!("#!/bin/sh\nprintf '%s\\n' \"$@\" > '{}'\n", log.display()),
        )
        .unwrap();
        std::fs::set_permissions(&probe, std::fs::Permissions::from_mode(0o755)).unwrap();
        bin
    }

    #[test]
    fn a_bootsel_drive_is_known_by_its_board_id() {
        let pico = mount_with("RPI-RP2", PICO_INFO);
        let pico2 = mount_with("RP2350", PICO2_INFO);
        let roots = [pico.path().to_owned(), pico2.path().to_owned()];
        assert_eq!(
            bootsel_drives(Board::Pico, &roots),
            [pico.path().join("RPI-RP2")]
        );
        assert_eq!(
            bootsel_drives(Board::Pico2, &roots),
            [pico2.path().join("RP2350")]
        );
        // A drive called RPI-RP2 without the info file, or with another
        // board's, is not one.
        let plain = tempfile::tempdir().unwrap();
        std::fs::create_dir(plain.path().join("RPI-RP2")).unwrap();
        let other = mount_with("RPI-RP2", PICO2_INFO);
        let roots = [plain.path().to_owned(), other.path().to_owned()];
        assert!(bootsel_drives(Board::Pico, &roots).is_empty());
        // A mount that is itself the drive (a drive letter on Windows).
        let letter = pico.path().join("RPI-RP2");
        assert_eq!(
            bootsel_drives(Board::Pico, std::slice::from_ref(&letter)),
            [letter]
        );
        // Mounts that do not exist are skipped.
        assert!(bootsel_drives(Board::Pico, &[PathBuf::from("/no/such/mount")]).is_empty());
    }

    #[test]
    fn without_probe_rs_or_a_drive_the_runner_says_what_to_do() {
        let empty_path = tempfile::tempdir().unwrap();
        let no_drives = tempfile::tempdir().unwrap();
        let here = here(empty_path.path(), &[no_drives.path()]);
        assert_eq!(probe_rs(here.path.as_deref(), &here.cwd), None);
        assert_eq!(choose(Board::Pico, &here).unwrap(), Route::Instructions);

        // The whole runner: nothing flashed, the UF2 left beside the ELF.
        let dir = tempfile::tempdir().unwrap();
        let elf = dir.path().join("pico");
        std::fs::write(&elf, crate::uf2::sample_elf()).unwrap();
        let args = Args {
            board: Board::Pico,
            elf: elf.clone(),
            rest: Vec::new(),
        };
        assert!(!run(&args, &here).unwrap());
        assert!(dir.path().join("pico.uf2").is_file());

        let text = instructions(Board::Pico, &dir.path().join("pico.uf2"), &here.mounts);
        assert!(text.contains(INSTALL_PROBE_RS), "{text}");
        assert!(text.contains("Hold its BOOTSEL button"), "{text}");
        assert!(text.contains("RPI-RP2"));
        assert!(text.contains("pico.uf2"));
        let text = instructions(Board::Pico2, Path::new("pico2.uf2"), &[]);
        assert!(text.contains("called RP2350"), "{text}");
    }

    #[test]
    fn a_board_in_bootsel_mode_gets_the_uf2() {
        let empty_path = tempfile::tempdir().unwrap();
        let mounts = mount_with("RPI-RP2", PICO_INFO);
        let here = here(empty_path.path(), &[mounts.path()]);
        let drive = mounts.path().join("RPI-RP2");
        assert_eq!(
            choose(Board::Pico, &here).unwrap(),
            Route::Drive(drive.clone())
        );
        // Not for a Pico 2 image: that board is not plugged in.
        assert_eq!(choose(Board::Pico2, &here).unwrap(), Route::Instructions);

        let dir = tempfile::tempdir().unwrap();
        let elf = dir.path().join("pico");
        std::fs::write(&elf, crate::uf2::sample_elf()).unwrap();
        let args = Args {
            board: Board::Pico,
            elf,
            rest: Vec::new(),
        };
        assert!(run(&args, &here).unwrap());
        let copied = std::fs::read(drive.join("pico.uf2")).unwrap();
        assert_eq!(copied, std::fs::read(dir.path().join("pico.uf2")).unwrap());
        assert!(!copied.is_empty());
    }

    #[test]
    fn two_boards_in_bootsel_mode_are_refused() {
        let empty_path = tempfile::tempdir().unwrap();
        let one = mount_with("RPI-RP2", PICO_INFO);
        let two = mount_with("RPI-RP2 1", PICO_INFO);
        let here = here(empty_path.path(), &[one.path(), two.path()]);
        let error = choose(Board::Pico, &here).unwrap_err().to_string();
        assert!(error.contains("2 boards in BOOTSEL mode"), "{error}");
    }

    #[cfg(unix)]
    #[test]
    fn probe_rs_flashes_when_no_board_is_in_bootsel_mode() {
        let bin = fake_probe_rs();
        let no_drives = tempfile::tempdir().unwrap();
        let here = here(bin.path(), &[no_drives.path()]);
        let probe = bin.path().join("probe-rs");
        assert_eq!(choose(Board::Pico2, &here).unwrap(), Route::Probe(probe));
        let args = Args {
            board: Board::Pico2,
            elf: PathBuf::from("target/thumbv8m.main-none-eabihf/release/pico2"),
            rest: vec!["--no-location".into()],
        };
        assert!(run(&args, &here).unwrap());
        let passed = std::fs::read_to_string(bin.path().join("args.txt")).unwrap();
        assert_eq!(
            passed.lines().collect::<Vec<_>>(),
            [
                "run",
                "--chip",
                "RP235x",
                "target/thumbv8m.main-none-eabihf/release/pico2",
                "--no-location"
            ]
        );
        // A board in BOOTSEL mode comes first, probe-rs or not.
        let mounts = mount_with("RP2350", PICO2_INFO);
        let here = Surroundings {
            mounts: vec![mounts.path().to_owned()],
            ..here
        };
        assert!(matches!(
            choose(Board::Pico2, &here).unwrap(),
            Route::Drive(_)
        ));
    }

    #[cfg(unix)]
    #[test]
    fn a_probe_rs_that_cannot_run_is_not_found() {
        use std::os::unix::fs::PermissionsExt;
        let bin = tempfile::tempdir().unwrap();
        let probe = bin.path().join("probe-rs");
        std::fs::write(&probe, "not a program").unwrap();
        std::fs::set_permissions(&probe, std::fs::Permissions::from_mode(0o644)).unwrap();
        assert_eq!(probe_rs(Some(bin.path().as_os_str()), bin.path()), None);
    }
}
