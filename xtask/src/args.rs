//! `cargo xtask`'s command line: its usage text, the robot an image
//! drives, and the parser of the tasks and their flags (hand-written: see
//! main.rs).

use crate::{Chip, PROFILES};
use std::env;
use pada_core::robot::registry::{self, BuiltIn};
use std::path::{Path, PathBuf};

pub(crate) const USAGE: &str = "\
usage: cargo xtask <task>

tasks:
  test  every test of pada: installs with apt what the tests need and is
        missing (.ci/install: the firmware toolchain, QEMU 10 from
        bookworm-backports, Chromium, Slurm and munge, python3-venv; needs
        root, else it prints the one `sudo` line to run first and exits 2),
        starts a one-node Slurm cluster (.ci/slurm) for the run, then runs
        `cargo test --workspace`, the firmware library's tests
        (`firmware-test`) and the Python package's (pytest in a venv), all
        with CI=true (a test whose tool is missing fails, never skips)
  firmware [--release] [--board f405|f429-sdram] [--chip f405|f407|f429]
           [--robot pendulum|pendulum-20hz|leo|PATH/robot.toml]
        build the firmware ELF of a board's learner profile for
        thumbv7em-none-eabihf (debug unless --release; board f405 unless
        --board; the 33 Hz pendulum unless --robot) and print its use of
        flash, SRAM, CCM and SDRAM and where the weight table lies; then,
        for a claim table, whether the robot's learning fits it (`pada
        claims --board B --robot R`: one host trial, cached, against the
        board's slots, and a warning where it fills before learning ends).
        --robot takes a robot of pada's by name, or a robot of your own by
        the path of its robot.toml (a value ending in .toml or holding a
        /; relative to the current directory): its constants are
        generated at build time, and a bad file or a table the board
        cannot hold stops the build with one line naming the file.
        --board f405 builds the STM32F405RG (--chip f407: the
        STM32F4-Discovery's F407VG, same profile); --board f429-sdram the
        STM32F429I-DISC1 (--chip f429)
  flash [--release] [--board ...] [--chip ...] [--robot ...]
        build as `firmware`, then flash it and show its defmt log through
        a debug probe (`probe-rs run`)
  firmware-test
        run the firmware library's tests on the host (controller, servo-bus
        transactions, LEO and pendulum observers)
  qemu [--debug] [--board f405|f429-sdram] [--robot ...]
        build the firmware for the emulated board of a board profile
        (f405: QEMU's netduinoplus2, an STM32F405RG, cargo feature `qemu`;
        f429-sdram: QEMU's mps2-an386, a Cortex-M4F whose PSRAM holds LEO's
        8 MiB table, feature `mps2`; f405 unless --board) into
        target/firmware-emulated/images/<board>-<robot>.elf, release unless
        --debug; its ELF path is the last line printed; --robot as for
        `firmware`
  sil [--debug] [--board ...] [--robot ...] [-- <pada sil options>]
        build as `qemu`, then run it in qemu-system-arm against the
        simulated plant: `pada sil --elf <ELF> <options>` (release build
        of the host); the robot's task and the board are passed on
        (--task, or --robot for a robot.toml; --board)
  fuzz [--seconds S] [--seed K]
        fuzz every decoder that faces untrusted bytes (wire frames of host
        and chip, Dynamixel status and instruction packets, checkpoint load
        and torn saves) for about S seconds in all (default 60) and print
        the inputs per second of each; fails if any invariant broke
  help  print this message";

/// The robot `--robot` names: a robot of pada's registry
/// (`pada_core::robot::registry`), by its full name (`physical-pendulum`,
/// `physical-pendulum-20hz`, `leo`) or the short one its images carry; or
/// a robot of files, by the path of its `robot.toml` ([`Robot::is_path`]),
/// relative to `cwd` unless absolute.
pub(crate) fn parse_robot(s: &str, cwd: &Path) -> Result<Robot, String> {
    if Robot::is_path(s) {
        let path = cwd.join(s);
        if !path.is_file() {
            return Err(format!("--robot {s}: no such file ({}); a robot of files is the path of its robot.toml", path.display()));
        }
        return Ok(Robot::File(path));
    }
    registry::find(&s.to_ascii_lowercase()).map(Robot::BuiltIn).ok_or_else(|| {
        let names: Vec<&str> = registry::BUILT_IN.iter().map(|b| b.short_name).collect();
        format!("unknown robot `{s}`: expected {}, or the path of a robot.toml", names.join(", "))
    })
}

/// The robot an image drives.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Robot {
    /// One of pada's robots.
    BuiltIn(&'static BuiltIn),
    /// A robot of files: its `robot.toml`, as an absolute path (the
    /// firmware's build script runs in `firmware/`, not where the user
    /// typed the path).
    File(PathBuf),
}

impl Robot {
    /// Whether `--robot`'s value is a path: it ends in `.toml` or has a
    /// directory in it (no built-in robot's name does either; the
    /// firmware's build.rs tells them apart the same way).
    pub(crate) fn is_path(s: &str) -> bool {
        s.ends_with(".toml") || s.contains('/') || s.contains(std::path::MAIN_SEPARATOR)
    }

    /// `PADA_ROBOT` for the firmware's build.rs.
    pub(crate) fn env(&self) -> std::ffi::OsString {
        match self {
            Robot::BuiltIn(b) => b.spec.name.into(),
            Robot::File(p) => p.clone().into_os_string(),
        }
    }

    /// How messages name it.
    pub(crate) fn label(&self) -> String {
        match self {
            Robot::BuiltIn(b) => b.spec.name.to_string(),
            Robot::File(p) => p.display().to_string(),
        }
    }

    /// Its part of an emulated image's file name: the short name of a
    /// built-in; for a robot of files its folder's name and a hash of its
    /// path, so that two robots in folders of the same name never share
    /// an image.
    pub(crate) fn image_name(&self) -> String {
        match self {
            Robot::BuiltIn(b) => b.short_name.to_string(),
            Robot::File(p) => {
                let folder = p.parent().and_then(Path::file_name).map(|f| f.to_string_lossy().into_owned());
                let stem = folder.unwrap_or_else(|| "robot".into());
                // FNV-1a of the path: stable across runs and builds (std's
                // hasher is seeded per process).
                let hash = p.to_string_lossy().bytes().fold(0x811c_9dc5u32, |h, b| (h ^ b as u32).wrapping_mul(0x0100_0193));
                format!("{stem}-{hash:08x}")
            }
        }
    }
}

/// The robot when `--robot` is not given: the 33 Hz pendulum.
pub(crate) fn pendulum() -> Robot {
    Robot::BuiltIn(registry::find("pendulum").expect("the registry has the 33 Hz pendulum (xtask's tests check it)"))
}

#[cfg(test)]
pub(crate) fn leo() -> Robot {
    Robot::BuiltIn(registry::find("leo").unwrap())
}

/// What to build.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Build {
    pub(crate) release: bool,
    pub(crate) chip: Chip,
    pub(crate) robot: Robot,
}

#[derive(Debug, PartialEq, Eq)]
pub(crate) enum Task {
    Help,
    Firmware(Build),
    Flash(Build),
    FirmwareTest,
    /// Build for the emulated board.
    Qemu(Build),
    /// Build for the emulated board and run `pada sil` with these options.
    Sil(Build, Vec<String>),
    /// Run `pada-fuzz` with these options (`--seconds S`, `--seed K`).
    Fuzz(Vec<String>),
    /// Install what the tests need, then run every test.
    Test,
}

/// `qemu` and `sil`: release unless `--debug`, a board profile, a robot,
/// and for `sil` everything after `--`.
pub(crate) fn parse_emulated(task: &str, rest: &[String]) -> Result<Task, String> {
    let mut build = Build { release: true, chip: Chip::F405, robot: pendulum() };
    let (own, passed) = match rest.iter().position(|a| a == "--") {
        Some(i) if task == "sil" => (&rest[..i], rest[i + 1..].to_vec()),
        _ => (rest, Vec::new()),
    };
    let mut own = own.iter();
    while let Some(arg) = own.next() {
        let (key, value) = match arg.as_str() {
            "--debug" => {
                build.release = false;
                continue;
            }
            "-h" | "--help" => return Ok(Task::Help),
            key @ ("--robot" | "--board") => {
                let robots: Vec<&str> = registry::BUILT_IN.iter().map(|b| b.short_name).collect();
                let robots = robots.join(", ");
                let robots = format!("{robots} or the path of a robot.toml");
                let choices = if key == "--robot" { robots.as_str() } else { PROFILES };
                (key, own.next().ok_or_else(|| format!("{key} needs a value: {choices}"))?.as_str())
            }
            other => match ["--robot", "--board"]
                .into_iter()
                .find_map(|key| Some((key, other.strip_prefix(key)?.strip_prefix('=')?)))
            {
                Some(pair) => pair,
                None => return Err(format!("unknown argument `{other}` for `{task}`")),
            },
        };
        if key == "--board" {
            build.chip = Chip::for_profile(value).ok_or_else(|| format!("unknown board `{value}`: expected {PROFILES}"))?;
        } else {
            build.robot = parse_robot(value, &cwd()?)?;
        }
    }
    Ok(if task == "sil" { Task::Sil(build, passed) } else { Task::Qemu(build) })
}

pub(crate) fn parse_args(args: &[String]) -> Result<Task, String> {
    let Some((task, rest)) = args.split_first() else {
        return Err("no task given".into());
    };
    match task.as_str() {
        "help" | "-h" | "--help" => Ok(Task::Help),
        "firmware" | "flash" => {
            let mut release = false;
            let (mut board, mut chip, mut robot) = (None, None, pendulum());
            let mut rest = rest.iter();
            while let Some(arg) = rest.next() {
                let (key, value) = match arg.as_str() {
                    "--release" | "-r" => {
                        release = true;
                        continue;
                    }
                    "-h" | "--help" => return Ok(Task::Help),
                    key @ ("--board" | "--chip" | "--robot") => {
                        let choices = match key {
                            "--board" => PROFILES,
                            "--chip" => "f405, f407 or f429",
                            _ => "pendulum, pendulum-20hz, leo or the path of a robot.toml",
                        };
                        (key, rest.next().ok_or_else(|| format!("{key} needs a value: {choices}"))?.as_str())
                    }
                    other => match ["--board", "--chip", "--robot"]
                        .into_iter()
                        .find_map(|key| Some((key, other.strip_prefix(key)?.strip_prefix('=')?)))
                    {
                        Some(pair) => pair,
                        None => return Err(format!("unknown argument `{other}` for `{task}`")),
                    },
                };
                match key {
                    "--board" => {
                        board = Some(
                            Chip::for_profile(value)
                                .ok_or_else(|| format!("unknown board `{value}`: expected {PROFILES}"))?,
                        )
                    }
                    "--chip" => {
                        chip = Some(
                            Chip::parse(value)
                                .ok_or_else(|| format!("unknown chip `{value}`: expected f405, f407 or f429"))?,
                        )
                    }
                    _ => robot = parse_robot(value, &cwd()?)?,
                }
            }
            let chip = match (board, chip) {
                (Some(b), Some(c)) if b.profile() != c.profile() => {
                    return Err(format!(
                        "--chip {} is built with the board profile {}, not {}",
                        c.feature().trim_start_matches("stm32"),
                        c.profile(),
                        b.profile()
                    ))
                }
                (_, Some(c)) => c,
                (Some(b), None) => b,
                (None, None) => Chip::F405,
            };
            let build = Build { release, chip, robot };
            Ok(if task == "flash" { Task::Flash(build) } else { Task::Firmware(build) })
        }
        "qemu" | "sil" => parse_emulated(task, rest),
        "fuzz" => {
            let mut it = rest.iter();
            while let Some(arg) = it.next() {
                match arg.as_str() {
                    "-h" | "--help" => return Ok(Task::Help),
                    "--seconds" | "--seed" => {
                        let v = it.next().ok_or_else(|| format!("{arg} needs a value"))?;
                        let ok = if arg == "--seconds" {
                            v.parse::<f64>().is_ok_and(|s| s.is_finite() && s > 0.0 && s <= 86_400.0)
                        } else {
                            v.parse::<u64>().is_ok()
                        };
                        if !ok {
                            return Err(if arg == "--seconds" {
                                format!("--seconds {v} is out of range: valid is 0 < S <= 86400")
                            } else {
                                format!("--seed {v}: valid is an integer 0..=18446744073709551615")
                            });
                        }
                    }
                    other => return Err(format!("unknown argument `{other}` for `fuzz`")),
                }
            }
            Ok(Task::Fuzz(rest.to_vec()))
        }
        "firmware-test" => match rest.first() {
            None => Ok(Task::FirmwareTest),
            Some(other) => Err(format!("unknown argument `{other}` for `firmware-test`")),
        },
        "test" => match rest.first().map(String::as_str) {
            None => Ok(Task::Test),
            Some("-h" | "--help") => Ok(Task::Help),
            Some(other) => Err(format!("unknown argument `{other}` for `test`")),
        },
        other => Err(format!("unknown task `{other}`")),
    }
}

/// Where the user ran `cargo xtask`: a relative `--robot` path is theirs
/// (`cargo run` keeps the caller's directory).
pub(crate) fn cwd() -> Result<PathBuf, String> {
    env::current_dir().map_err(|e| format!("cannot read the current directory: {e}"))
}

/// The repository root (the directory holding the workspace Cargo.toml).
#[cfg(test)]
mod tests {
    use super::*;
    use crate::workspace_root;

    fn args(s: &str) -> Vec<String> {
        s.split_whitespace().map(String::from).collect()
    }

    #[test]
    fn fuzz_takes_seconds_and_seed_and_refuses_the_rest() {
        assert_eq!(parse_args(&args("fuzz")), Ok(Task::Fuzz(vec![])));
        assert_eq!(parse_args(&args("fuzz --seconds 90 --seed 7")), Ok(Task::Fuzz(args("--seconds 90 --seed 7"))));
        for bad in ["fuzz --seconds 0", "fuzz --seconds nan", "fuzz --seconds", "fuzz --seed -1", "fuzz --release"] {
            assert!(parse_args(&args(bad)).is_err(), "{bad}");
        }
    }

    #[test]
    fn firmware_defaults_to_debug_f405() {
        assert_eq!(
            parse_args(&args("firmware")),
            Ok(Task::Firmware(Build { release: false, chip: Chip::F405, robot: pendulum() }))
        );
    }

    #[test]
    fn firmware_flags_in_any_order_and_both_chip_spellings() {
        let want = Ok(Task::Firmware(Build { release: true, chip: Chip::F407, robot: pendulum() }));
        assert_eq!(parse_args(&args("firmware --chip f407 --release")), want);
        assert_eq!(parse_args(&args("firmware --release --chip=stm32F407")), want);
    }

    #[test]
    fn a_board_profile_picks_its_chip_and_a_chip_its_profile() {
        let f429_leo = Ok(Task::Firmware(Build { release: true, chip: Chip::F429, robot: leo() }));
        assert_eq!(parse_args(&args("firmware --release --board f429-sdram --robot leo")), f429_leo);
        assert_eq!(parse_args(&args("firmware --robot=leo --board=F429-SDRAM --release")), f429_leo);
        assert_eq!(parse_args(&args("firmware --release --chip f429 --robot leo")), f429_leo);
        assert_eq!(parse_args(&args("firmware --release --board f429-sdram --chip stm32f429 --robot leo")), f429_leo);
        assert_eq!(
            parse_args(&args("firmware --board f405")),
            Ok(Task::Firmware(Build { release: false, chip: Chip::F405, robot: pendulum() }))
        );
        // The Discovery's F407 is an f405-profile board.
        assert_eq!(
            parse_args(&args("flash --board f405 --chip f407")),
            Ok(Task::Flash(Build { release: false, chip: Chip::F407, robot: pendulum() }))
        );
        assert_eq!((Chip::F407.profile(), Chip::F429.profile()), ("f405", "f429-sdram"));
        assert_eq!(Chip::F429.memory_x(), "firmware/memory-f429.x");
        // A chip of another profile, an unknown board, the dropped F446.
        let err = parse_args(&args("firmware --board f429-sdram --chip f407")).unwrap_err();
        assert!(err.contains("f405") && err.contains("f429-sdram"), "{err}");
        assert!(parse_args(&args("firmware --board f405 --chip f429")).is_err());
        assert!(parse_args(&args("firmware --board host")).unwrap_err().contains("f405 or f429-sdram"));
        assert!(parse_args(&args("firmware --board")).is_err());
        assert!(parse_args(&args("firmware --chip f446")).is_err());
    }

    #[test]
    fn flash_robot_and_firmware_test() {
        assert_eq!(
            parse_args(&args("flash --robot leo --release")),
            Ok(Task::Flash(Build { release: true, chip: Chip::F405, robot: leo() }))
        );
        assert_eq!(
            parse_args(&args("firmware --robot=pendulum-20hz --chip=f407")),
            Ok(Task::Firmware(Build { release: false, chip: Chip::F407, robot: Robot::BuiltIn(registry::find("pendulum-20hz").unwrap()) }))
        );
        assert_eq!(parse_args(&args("firmware-test")), Ok(Task::FirmwareTest));
        assert_eq!(parse_args(&args("test")), Ok(Task::Test));
        assert!(parse_args(&args("test --workspace")).is_err());
        assert!(parse_args(&args("firmware-test --release")).is_err());
        assert!(parse_args(&args("firmware --robot walker")).is_err());
    }

    #[test]
    fn emulated_board_builds_release_by_default_and_passes_sil_options_on() {
        let release = Build { release: true, chip: Chip::F405, robot: pendulum() };
        assert_eq!(parse_args(&args("qemu")), Ok(Task::Qemu(release.clone())));
        assert_eq!(
            parse_args(&args("qemu --debug --robot leo")),
            Ok(Task::Qemu(Build { release: false, chip: Chip::F405, robot: leo() }))
        );
        assert_eq!(
            parse_args(&args("sil -- --seconds 60 --json")),
            Ok(Task::Sil(release.clone(), args("--seconds 60 --json")))
        );
        assert_eq!(parse_args(&args("sil --robot=leo")), Ok(Task::Sil(Build { robot: leo(), ..release }, vec![])));
        assert!(parse_args(&args("qemu --release")).is_err());
        assert!(parse_args(&args("qemu -- --json")).is_err());
        assert!(parse_args(&args("sil --robot")).is_err());
        // The f429-sdram profile is emulated on mps2-an386.
        let f429_leo = Build { release: true, chip: Chip::F429, robot: leo() };
        assert_eq!(parse_args(&args("qemu --board f429-sdram --robot leo")), Ok(Task::Qemu(f429_leo.clone())));
        assert_eq!(parse_args(&args("sil --robot=leo --board=f429-sdram -- --seconds 5")), Ok(Task::Sil(f429_leo, args("--seconds 5"))));
        assert_eq!(Chip::F429.emulated(), ("mps2", "mps2-an386", "firmware/memory-mps2.x"));
        assert_eq!(Chip::F405.emulated().1, "netduinoplus2");
        assert!(parse_args(&args("qemu --board host")).unwrap_err().contains("f405 or f429-sdram"));
        assert!(parse_args(&args("qemu --board")).is_err());
    }

    #[test]
    fn a_robot_toml_is_a_path_from_the_current_directory() {
        let root = workspace_root();
        let arm2 = root.join("examples/robots/arm2/robot.toml");
        // Relative to where the user stands, whatever directory cargo
        // builds the firmware in.
        assert_eq!(parse_robot("robots/arm2/robot.toml", &root.join("examples")), Ok(Robot::File(arm2.clone())));
        assert_eq!(parse_robot(&arm2.display().to_string(), Path::new("/")), Ok(Robot::File(arm2.clone())));
        let e = parse_robot("no/such/robot.toml", &root).unwrap_err();
        assert!(e.contains("no such file") && e.contains("robot.toml"), "{e}");
        assert!(parse_robot("walker", &root).unwrap_err().contains("path of a robot.toml"));
        assert_eq!(parse_robot("leo", &root), Ok(leo()));
        let arm2 = Robot::File(arm2);
        assert_eq!(arm2.env(), root.join("examples/robots/arm2/robot.toml").into_os_string());
        assert!(arm2.image_name().starts_with("arm2-"), "{}", arm2.image_name());
        assert_ne!(arm2.image_name(), Robot::File("/elsewhere/arm2/robot.toml".into()).image_name());
        assert_eq!(leo().image_name(), "leo");
    }

    #[test]
    fn bad_arguments_are_errors() {
        assert!(parse_args(&args("")).is_err());
        assert!(parse_args(&args("deploy")).is_err());
        assert!(parse_args(&args("firmware --chip")).is_err());
        assert!(parse_args(&args("firmware --chip f103")).is_err());
        assert!(parse_args(&args("firmware --relase")).is_err());
    }
}
