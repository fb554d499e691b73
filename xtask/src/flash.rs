//! `cargo xtask flash`: the runner of `cargo run --release` (see
//! `.cargo/config.toml`). It copies the image's UF2 onto a board in
//! BOOTSEL mode if one is mounted (someone held its button: that is the
//! route they chose), else runs `probe-rs run` if it is installed, else
//! writes the UF2 and says how to flash it. cargo holds no lock while its
//! runner runs, so this nested `cargo xtask` cannot wait on it.

use std::{
    ffi::OsString,
    io::Write as _,
    path::{Path, PathBuf},
    process::Command,
};

use anyhow::{Context, Result, bail};

use crate::{board::Board, project, uf2};

/// The file a board's boot ROM shows on its BOOTSEL drive, with the line
/// `Board-ID: <label>`.
const INFO_FILE: &str = "INFO_UF2.TXT";
/// The command that installs probe-rs.
const INSTALL_PROBE_RS: &str = "cargo install probe-rs-tools --locked";

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

/// What the runner looks at: the `PATH` searched for probe-rs (and the
/// folder its relative entries start from), and the folders where
/// removable drives are mounted (each a drive, or holding drives).
#[derive(Debug, Clone)]
pub struct Surroundings {
    pub path: Option<OsString>,
    pub cwd: PathBuf,
    pub mounts: Vec<PathBuf>,
}

impl Surroundings {
    /// This machine's.
    pub fn here() -> Self {
        let mounts = if cfg!(windows) {
            (b'A'..=b'Z')
                .map(|letter| PathBuf::from(format!("{}:\\", letter as char)))
                .collect()
        } else {
            let user = std::env::var_os("USER").or_else(|| std::env::var_os("LOGNAME"));
            // udisks' /media/<user> (Debian, Ubuntu) and /run/media/<user>
            // (Fedora, Arch), then other Linux setups and macOS.
            let udisks = user.iter().flat_map(|user| {
                [
                    Path::new("/media").join(user),
                    Path::new("/run/media").join(user),
                ]
            });
            udisks
                .chain(["/media", "/mnt", "/Volumes"].map(PathBuf::from))
                .collect()
        };
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

/// The BOOTSEL drives of `board` in `mounts` (each mount itself, or a
/// folder in it): those whose `INFO_UF2.TXT` names the board's chip.
pub fn bootsel_drives(board: Board, mounts: &[PathBuf]) -> Vec<PathBuf> {
    let id = format!("Board-ID: {}", board.drive_label());
    let is_drive = |dir: &Path| {
        std::fs::read_to_string(dir.join(INFO_FILE))
            .is_ok_and(|info| info.lines().any(|line| line.trim() == id))
    };
    let mut drives: Vec<PathBuf> = mounts
        .iter()
        .flat_map(|mount| {
            let inside = std::fs::read_dir(mount).into_iter().flatten().flatten();
            std::iter::once(mount.clone()).chain(inside.map(|entry| entry.path()))
        })
        .filter(|dir| is_drive(dir))
        .collect();
    // One drive may be reached through two mounts (a symbolic link).
    drives.sort();
    drives.dedup();
    drives
}

/// The route for `board` here: a BOOTSEL drive, else probe-rs, else
/// instructions.
pub fn choose(board: Board, here: &Surroundings) -> Result<Route> {
    match bootsel_drives(board, &here.mounts).as_slice() {
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
    Ok(
        match which::which_in("probe-rs", here.path.as_deref(), &here.cwd) {
            Ok(probe) => Route::Probe(probe),
            Err(_) => Route::Instructions,
        },
    )
}

/// What to do when nothing could flash the board; `uf2` is the image's UF2,
/// ready to copy, and `mounts` where the runner looked for the board.
pub fn instructions(board: Board, uf2: &Path, mounts: &[PathBuf]) -> String {
    let (name, label) = (board.name(), board.drive_label());
    let uf2 = project::relative(uf2);
    let uf2 = uf2.display();
    let looked = if cfg!(windows) {
        "on every drive letter".to_owned()
    } else {
        let list: Vec<String> = mounts.iter().map(|m| m.display().to_string()).collect();
        format!("in {}", list.join(", "))
    };
    format!(
        "Nothing was flashed: no {name} is in BOOTSEL mode, and probe-rs is not installed.
(No drive whose {INFO_FILE} says `Board-ID: {label}` {looked}.)

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
  install probe-rs once with:  {INSTALL_PROBE_RS}
  then run `cargo run --release` again.

Both routes step by step: docs/user/flashing.md"
    )
}

/// `cargo xtask flash` on this machine.
pub fn command(args: &Args) -> Result<bool> {
    run(args, &Surroundings::here())
}

/// Flashes `args.elf` onto the board by the route [`choose`] finds in
/// `here`. `Ok(false)` if there was none (the message says what to do) or
/// probe-rs failed.
pub fn run(args: &Args, here: &Surroundings) -> Result<bool> {
    let board = args.board;
    let route = choose(board, here)?;
    if let Route::Probe(probe) = route {
        let chip = board.probe_rs_chip();
        eprintln!("$ probe-rs run --chip {chip} {}", args.elf.display());
        let status = Command::new(&probe)
            .args(["run", "--chip", chip])
            .arg(&args.elf)
            .args(&args.rest)
            .status()
            .with_context(|| format!("running {}", probe.display()))?;
        return Ok(status.success());
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
        let drive = mounts.path().join(label);
        std::fs::create_dir(&drive).unwrap();
        std::fs::write(drive.join(INFO_FILE), info).unwrap();
        mounts
    }

    fn here(path: &Path, mounts: &[&Path]) -> Surroundings {
        Surroundings {
            path: Some(path.as_os_str().to_owned()),
            cwd: path.to_owned(),
            mounts: mounts.iter().map(|m| m.to_path_buf()).collect(),
        }
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
        // board's, is not one; a mount that is itself the drive is.
        let plain = tempfile::tempdir().unwrap();
        std::fs::create_dir(plain.path().join("RPI-RP2")).unwrap();
        let other = mount_with("RPI-RP2", PICO2_INFO);
        let roots = [plain.path().to_owned(), other.path().to_owned()];
        assert!(bootsel_drives(Board::Pico, &roots).is_empty());
        let letter = pico.path().join("RPI-RP2");
        assert_eq!(
            bootsel_drives(Board::Pico, std::slice::from_ref(&letter)),
            [letter]
        );
        assert!(bootsel_drives(Board::Pico, &[PathBuf::from("/no/such/mount")]).is_empty());
    }

    #[test]
    fn the_route_is_a_drive_then_probe_rs_then_instructions() {
        let empty_path = tempfile::tempdir().unwrap();
        let no_drives = tempfile::tempdir().unwrap();
        let nothing = here(empty_path.path(), &[no_drives.path()]);
        assert_eq!(choose(Board::Pico, &nothing).unwrap(), Route::Instructions);
        let text = instructions(Board::Pico2, Path::new("pico2.uf2"), &nothing.mounts);
        assert!(
            text.contains(INSTALL_PROBE_RS) && text.contains("called RP2350"),
            "{text}"
        );

        let mounts = mount_with("RPI-RP2", PICO_INFO);
        let drive = here(empty_path.path(), &[mounts.path()]);
        let want = Route::Drive(mounts.path().join("RPI-RP2"));
        assert_eq!(choose(Board::Pico, &drive).unwrap(), want);
        // Not for a Pico 2 image: that board is not plugged in.
        assert_eq!(choose(Board::Pico2, &drive).unwrap(), Route::Instructions);

        let two = mount_with("RPI-RP2 1", PICO_INFO);
        let error = choose(
            Board::Pico,
            &here(empty_path.path(), &[mounts.path(), two.path()]),
        );
        assert!(format!("{:#}", error.unwrap_err()).contains("2 boards in BOOTSEL mode"));
    }

    /// probe-rs gets the chip, the ELF and the arguments after it; a board
    /// in BOOTSEL mode still comes first.
    #[cfg(unix)]
    #[test]
    fn probe_rs_flashes_when_no_board_is_in_bootsel_mode() {
        use std::os::unix::fs::PermissionsExt;
        let bin = tempfile::tempdir().unwrap();
        let probe = bin.path().join("probe-rs");
        let log = bin.path().join("args.txt");
        let script = format!("#!/bin/sh\nprintf '%s\\n' \"$@\" > '{}'\n", log.display());
        std::fs::write(&probe, script).unwrap();
        std::fs::set_permissions(&probe, std::fs::Permissions::from_mode(0o755)).unwrap();
        let no_drives = tempfile::tempdir().unwrap();
        let here = here(bin.path(), &[no_drives.path()]);
        assert_eq!(choose(Board::Pico2, &here).unwrap(), Route::Probe(probe));
        let args = Args {
            board: Board::Pico2,
            elf: PathBuf::from("pico2"),
            rest: vec!["--no-location".into()],
        };
        assert!(run(&args, &here).unwrap());
        let passed = std::fs::read_to_string(log).unwrap();
        let passed: Vec<&str> = passed.lines().collect();
        assert_eq!(
            passed,
            ["run", "--chip", "RP235x", "pico2", "--no-location"]
        );
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
}
