//! `cargo xtask flash`, the runner of `cargo run --release`: onto a mounted
//! BOOTSEL drive (someone held its button: their choice), else through
//! `probe-rs run`, else the UF2 and how to flash it.

use std::{
    ffi::OsString,
    io::Write as _,
    path::{Path, PathBuf},
};

use anyhow::{Context, Result, bail};
use xshell::{Shell, cmd};

use crate::{board::Board, project, uf2};

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

/// What the runner looks at: the `PATH` for probe-rs, and where drives are
/// mounted (each a drive, or holding drives).
#[derive(Debug, Clone)]
pub struct Surroundings {
    pub path: Option<OsString>,
    pub mounts: Vec<PathBuf>,
}

impl Surroundings {
    pub fn here() -> Self {
        let mounts = if cfg!(windows) {
            (b'A'..=b'Z')
                .map(|letter| PathBuf::from(format!("{}:\\", letter as char)))
                .collect()
        } else {
            let user = std::env::var_os("USER").or_else(|| std::env::var_os("LOGNAME"));
            // udisks' /media/<user> (Debian, Ubuntu) and /run/media/<user>
            // (Fedora, Arch), then other Linux setups and macOS.
            let udisks = user
                .iter()
                .flat_map(|user| ["/media", "/run/media"].map(|m| Path::new(m).join(user)));
            udisks
                .chain(["/media", "/mnt", "/Volumes"].map(PathBuf::from))
                .collect()
        };
        let path = std::env::var_os("PATH");
        Self { path, mounts }
    }
}

/// How the image goes onto the board: onto this BOOTSEL drive, through
/// this `probe-rs`, or no way (say what to do).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Route {
    Drive(PathBuf),
    Probe(PathBuf),
    Instructions,
}

/// The route for `board` here: a BOOTSEL drive (a mount, or a folder in
/// one, whose `INFO_UF2.TXT` names the board), else probe-rs, else none.
pub fn choose(board: Board, here: &Surroundings) -> Result<Route> {
    let id = format!("Board-ID: {}", board.drive_label());
    let is_drive = |dir: &PathBuf| {
        let info = std::fs::read_to_string(dir.join("INFO_UF2.TXT"));
        info.is_ok_and(|info| info.lines().any(|line| line.trim() == id))
    };
    let mut drives: Vec<PathBuf> = (here.mounts.iter())
        .flat_map(|mount| {
            let inside = std::fs::read_dir(mount).into_iter().flatten().flatten();
            std::iter::once(mount.clone()).chain(inside.map(|entry| entry.path()))
        })
        .filter(is_drive)
        .collect();
    // One drive may be reached through two mounts (a symbolic link).
    drives.sort();
    drives.dedup();
    match drives.as_slice() {
        [drive] => Ok(Route::Drive(drive.clone())),
        [] => Ok(
            which::which_in("probe-rs", here.path.as_deref(), std::env::current_dir()?)
                .map_or(Route::Instructions, Route::Probe),
        ),
        several => {
            let list: Vec<String> = several.iter().map(|d| d.display().to_string()).collect();
            bail!(
                "{} boards in BOOTSEL mode ({}): unplug all but the one to flash",
                several.len(),
                list.join(", ")
            )
        }
    }
}

/// What to do when nothing could flash the board: `uf2` is ready to copy,
/// `mounts` where the runner looked.
pub fn instructions(board: Board, uf2: &Path, mounts: &[PathBuf]) -> String {
    let (name, label, uf2) = (board.name(), board.drive_label(), project::relative(uf2));
    let uf2 = uf2.display();
    let looked = if cfg!(windows) {
        "on every drive letter".to_owned()
    } else {
        let list: Vec<String> = mounts.iter().map(|m| m.display().to_string()).collect();
        format!("in {}", list.join(", "))
    };
    format!(
        "Nothing was flashed: no {name} is in BOOTSEL mode, and probe-rs is not installed.
(No drive whose INFO_UF2.TXT says `Board-ID: {label}` {looked}.)

The image is ready as a UF2 file: {uf2}

Flash it over USB, with nothing else to buy:
  1. Unplug the {name}. Hold its BOOTSEL button while you plug it in, then
     let go: a USB drive called {label} appears.
  2. Run `cargo run --release` again: it copies the UF2 onto the drive.
     Or copy {uf2} onto the drive yourself.
  The board restarts and runs the new firmware when the copy is complete.

Or flash it through a debug probe, which also shows the firmware's log (a
Raspberry Pi Debug Probe or any CMSIS-DAP probe, wired to the board's SWCLK,
SWDIO and GND):
  install probe-rs once with:  cargo install probe-rs-tools --locked
  then run `cargo run --release` again.

Both routes step by step: docs/user/flashing.md"
    )
}

/// `cargo xtask flash`: flashes `args.elf` by the route [`choose`] finds in
/// `here` (this machine's, or a test's); `Ok(false)` if there was none, an
/// error if probe-rs failed.
pub fn run(args: &Args, here: &Surroundings) -> Result<bool> {
    let board = args.board;
    let route = choose(board, here)?;
    if let Route::Probe(probe) = route {
        let (sh, chip, elf, rest) = (Shell::new()?, board.probe_rs_chip(), &args.elf, &args.rest);
        cmd!(sh, "{probe} run --chip {chip} {elf} {rest...}").run()?;
        return Ok(true);
    }
    let (path, bytes) = uf2::write(&args.elf, board, "uf2")?;
    let Route::Drive(drive) = route else {
        eprintln!("{}", instructions(board, &path, &here.mounts));
        return Ok(false);
    };
    println!("{}", uf2::describe(&path, board, &bytes));
    let target = drive.join(format!("{}.uf2", board.image().bin));
    let mut file =
        std::fs::File::create(&target).with_context(|| format!("creating {}", target.display()))?;
    file.write_all(&bytes)
        .with_context(|| format!("writing {}", target.display()))?;
    // The board may restart, and its drive vanish, as the last block lands.
    if let Err(error) = file.sync_all() {
        eprintln!(
            "note: the drive did not confirm the end of the copy ({error}); if the board \
             restarted, the copy was complete"
        );
    }
    println!(
        "Copied to {}: the {} restarts and runs it.\nThe log (defmt over RTT) needs a debug \
         probe; the console is on the board's USB port: `cargo xtask console`.",
        target.display(),
        board.name()
    );
    Ok(true)
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
        std::fs::create_dir(mounts.path().join(label)).unwrap();
        std::fs::write(mounts.path().join(label).join("INFO_UF2.TXT"), info).unwrap();
        mounts
    }

    fn here(path: &Path, mounts: &[&Path]) -> Surroundings {
        let mounts = mounts.iter().map(|m| m.to_path_buf()).collect();
        let path = Some(path.as_os_str().to_owned());
        Surroundings { path, mounts }
    }

    #[test]
    fn the_route_is_a_bootsel_drive_known_by_its_board_id_then_instructions() {
        let no_path = tempfile::tempdir().unwrap();
        let route = |board, mounts: &[&Path]| {
            let here = here(no_path.path(), mounts);
            choose(board, &here).map_err(|e| format!("{e:#}"))
        };
        let pico = mount_with("RPI-RP2", PICO_INFO);
        let pico2 = mount_with("RP2350", PICO2_INFO);
        let both = [pico.path(), pico2.path()];
        let drive = pico.path().join("RPI-RP2");
        assert_eq!(route(Board::Pico, &both), Ok(Route::Drive(drive.clone())));
        let drive2 = pico2.path().join("RP2350");
        assert_eq!(route(Board::Pico2, &both), Ok(Route::Drive(drive2)));
        // A drive called RPI-RP2 without the info file, or with another
        // board's, is not one; a mount that is itself the drive is.
        let plain = tempfile::tempdir().unwrap();
        std::fs::create_dir(plain.path().join("RPI-RP2")).unwrap();
        let other = mount_with("RPI-RP2", PICO2_INFO);
        let neither = [plain.path(), other.path()];
        assert_eq!(route(Board::Pico, &neither), Ok(Route::Instructions));
        assert_eq!(route(Board::Pico, &[&drive]), Ok(Route::Drive(drive)));
        let looked = neither.map(Path::to_path_buf);
        let text = instructions(Board::Pico2, Path::new("pico2.uf2"), &looked);
        assert!(
            text.contains("probe-rs-tools") && text.contains("called RP2350"),
            "{text}"
        );
        let two = mount_with("RPI-RP2 1", PICO_INFO);
        let error = route(Board::Pico, &[pico.path(), two.path()]).unwrap_err();
        assert!(error.contains("2 boards in BOOTSEL mode"), "{error}");
    }

    /// probe-rs gets the chip, the ELF and the arguments after it; a board
    /// in BOOTSEL mode still comes first.
    #[cfg(unix)]
    #[test]
    fn probe_rs_flashes_when_no_board_is_in_bootsel_mode() {
        use std::os::unix::fs::PermissionsExt;
        let bin = tempfile::tempdir().unwrap();
        let (probe, log) = (bin.path().join("probe-rs"), bin.path().join("args.txt"));
        let script = format!("#!/bin/sh\nprintf '%s\\n' \"$@\" > '{}'\n", log.display());
        std::fs::write(&probe, script).unwrap();
        std::fs::set_permissions(&probe, std::fs::Permissions::from_mode(0o755)).unwrap();
        let no_drives = tempfile::tempdir().unwrap();
        let probed = here(bin.path(), &[no_drives.path()]);
        assert_eq!(choose(Board::Pico2, &probed).unwrap(), Route::Probe(probe));
        let (elf, rest) = (PathBuf::from("pico2"), vec!["--no-location".into()]);
        let board = Board::Pico2;
        assert!(run(&Args { board, elf, rest }, &probed).unwrap());
        let passed = std::fs::read_to_string(log).unwrap();
        let passed: Vec<&str> = passed.lines().collect();
        assert_eq!(
            passed,
            ["run", "--chip", "RP235x", "pico2", "--no-location"]
        );
        let mounts = mount_with("RP2350", PICO2_INFO);
        let both = here(bin.path(), &[mounts.path()]);
        let drive = Route::Drive(mounts.path().join("RP2350"));
        assert_eq!(choose(Board::Pico2, &both).unwrap(), drive);
    }
}
