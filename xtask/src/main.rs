//! Build orchestration for pada: `cargo xtask <task>`.
//!
//! Tasks:
//! - `firmware [--release] [--board f405|f429-sdram] [--chip f405|f407|f429]
//!   [--robot …]`: build the firmware ELF of a board's learner profile for
//!   thumbv7em-none-eabihf with whichever toolchain this machine has (see
//!   [`toolchain`]), then print its use of each memory region and where the
//!   weight table lies (see [`elf`]).
//! - `qemu`, `sil`: the same firmware for the emulated board of a board
//!   profile (QEMU's `netduinoplus2` for `f405`, `mps2-an386` for
//!   `f429-sdram`), and a software-in-the-loop run of it (`pada sil`).
//! - `fuzz [--seconds S]`: the decoders that face untrusted bytes, fuzzed
//!   on stable Rust (`fuzz/`, package `pada-fuzz`).
//! - `test`: every test, after installing what the tests need (see
//!   [`test`]); the README's test command.
//!
//! The xtask has no dependencies. Its command line is a few flags and a
//! subcommand, so a hand-written parser is shorter than the argument-parser
//! crate it would replace and keeps `cargo xtask` quick to build on a fresh
//! CI machine.

mod elf;
mod test;
mod toolchain;

use pada_core::robot::registry::{self, BuiltIn};
use std::{
    env,
    path::{Path, PathBuf},
    process::ExitCode,
    time::Instant,
};

/// The firmware's compilation target (Cortex-M4F with hardware float).
pub const TARGET: &str = "thumbv7em-none-eabihf";

const USAGE: &str = "\
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
        flash, SRAM, CCM and SDRAM and where the weight table lies.
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

/// A microcontroller the firmware can be built for (one cargo feature each),
/// on the board whose pins the firmware uses for it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Chip {
    F405,
    F407,
    F429,
}

/// The board learner profiles (`pada_core::profile::Board`'s names) a
/// chip's image is built with.
const PROFILES: &str = "f405 or f429-sdram";

impl Chip {
    fn parse(s: &str) -> Option<Chip> {
        match s.to_ascii_lowercase().trim_start_matches("stm32") {
            "f405" => Some(Chip::F405),
            "f407" => Some(Chip::F407),
            "f429" => Some(Chip::F429),
            _ => None,
        }
    }

    /// The chip a board learner profile is built for unless `--chip` says
    /// otherwise.
    fn for_profile(profile: &str) -> Option<Chip> {
        match profile.to_ascii_lowercase().as_str() {
            "f405" => Some(Chip::F405),
            "f429-sdram" => Some(Chip::F429),
            _ => None,
        }
    }

    /// The board learner profile the firmware takes on this chip
    /// (`firmware/src/table.rs`).
    pub fn profile(self) -> &'static str {
        match self {
            Chip::F405 | Chip::F407 => "f405",
            Chip::F429 => "f429-sdram",
        }
    }

    /// The board whose pins the firmware uses.
    pub fn board(self) -> &'static str {
        match self {
            Chip::F405 => "a generic STM32F405RG board",
            Chip::F407 => "the STM32F4-Discovery",
            Chip::F429 => "the STM32F429I-DISC1",
        }
    }

    /// The firmware's cargo feature that selects this chip.
    pub fn feature(self) -> &'static str {
        match self {
            Chip::F405 => "stm32f405",
            Chip::F407 => "stm32f407",
            Chip::F429 => "stm32f429",
        }
    }

    /// The linker memory layout the firmware's build script uses for this
    /// chip, relative to the workspace root.
    pub fn memory_x(self) -> &'static str {
        match self {
            Chip::F405 | Chip::F407 => "memory.x",
            Chip::F429 => "firmware/memory-f429.x",
        }
    }

    /// The emulated board of this chip's profile: the firmware's cargo
    /// feature, QEMU's machine, and the linker memory layout.
    pub fn emulated(self) -> (&'static str, &'static str, &'static str) {
        match self {
            Chip::F405 | Chip::F407 => ("qemu", "netduinoplus2", "memory.x"),
            Chip::F429 => ("mps2", "mps2-an386", "firmware/memory-mps2.x"),
        }
    }

    /// The name probe-rs knows the usual package of this chip by.
    pub fn probe_rs_name(self) -> &'static str {
        match self {
            Chip::F405 => "STM32F405RGTx",
            Chip::F407 => "STM32F407VGTx",
            Chip::F429 => "STM32F429ZITx",
        }
    }
}

/// The robot `--robot` names: a robot of pada's registry
/// (`pada_core::robot::registry`), by its full name (`physical-pendulum`,
/// `physical-pendulum-20hz`, `leo`) or the short one its images carry; or
/// a robot of files, by the path of its `robot.toml` ([`Robot::is_path`]),
/// relative to `cwd` unless absolute.
fn parse_robot(s: &str, cwd: &Path) -> Result<Robot, String> {
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
enum Robot {
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
    fn is_path(s: &str) -> bool {
        s.ends_with(".toml") || s.contains('/') || s.contains(std::path::MAIN_SEPARATOR)
    }

    /// `PADA_ROBOT` for the firmware's build.rs.
    fn env(&self) -> std::ffi::OsString {
        match self {
            Robot::BuiltIn(b) => b.spec.name.into(),
            Robot::File(p) => p.clone().into_os_string(),
        }
    }

    /// How messages name it.
    fn label(&self) -> String {
        match self {
            Robot::BuiltIn(b) => b.spec.name.to_string(),
            Robot::File(p) => p.display().to_string(),
        }
    }

    /// Its part of an emulated image's file name: the short name of a
    /// built-in; for a robot of files its folder's name and a hash of its
    /// path, so that two robots in folders of the same name never share
    /// an image.
    fn image_name(&self) -> String {
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
fn pendulum() -> Robot {
    Robot::BuiltIn(registry::find("pendulum").expect("the registry has the 33 Hz pendulum (xtask's tests check it)"))
}

#[cfg(test)]
fn leo() -> Robot {
    Robot::BuiltIn(registry::find("leo").unwrap())
}

/// What to build.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Build {
    release: bool,
    chip: Chip,
    robot: Robot,
}

#[derive(Debug, PartialEq, Eq)]
enum Task {
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
fn parse_emulated(task: &str, rest: &[String]) -> Result<Task, String> {
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

fn parse_args(args: &[String]) -> Result<Task, String> {
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
fn cwd() -> Result<PathBuf, String> {
    env::current_dir().map_err(|e| format!("cannot read the current directory: {e}"))
}

/// The repository root (the directory holding the workspace Cargo.toml).
fn workspace_root() -> PathBuf {
    // `cargo run` sets CARGO_MANIFEST_DIR for the program as well; fall back
    // to where the xtask was compiled if it is started some other way.
    let manifest_dir = env::var_os("CARGO_MANIFEST_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")));
    manifest_dir
        .parent()
        .expect("xtask lives one level below the workspace root")
        .to_path_buf()
}

fn main() -> ExitCode {
    let args: Vec<String> = env::args().skip(1).collect();
    let task = match parse_args(&args) {
        Ok(task) => task,
        Err(e) => {
            // One line: the mistake and where the usage is (the usage
            // itself is longer than a screen and buried the mistake).
            eprintln!("xtask: error: {e} (`cargo xtask help` prints the usage)");
            return ExitCode::from(2);
        }
    };
    let result = match task {
        // Its own exit codes: 2 when it needs root to install (no test ran).
        Task::Test => return test::run(&workspace_root()),
        Task::Help => {
            println!("{USAGE}");
            Ok(())
        }
        Task::Firmware(build) => firmware(&workspace_root(), build).map(|_| ()),
        Task::Flash(build) => {
            let chip = build.chip;
            firmware(&workspace_root(), build).and_then(|elf| flash(&elf, chip))
        }
        Task::FirmwareTest => firmware_test(&workspace_root()),
        Task::Fuzz(args) => fuzz(&workspace_root(), &args),
        Task::Qemu(build) => qemu_image(&workspace_root(), build).map(|_| ()),
        Task::Sil(build, args) => {
            qemu_image(&workspace_root(), build.clone()).and_then(|elf| sil(&workspace_root(), &elf, build, &args))
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask: error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Builds the firmware; returns the ELF's path.
fn firmware(root: &Path, build: Build) -> Result<PathBuf, String> {
    let Build { release, chip, robot } = build;
    let toolchain = toolchain::detect()?;
    println!("xtask: toolchain: {}", toolchain.describe());

    let firmware_dir = root.join("firmware");
    // A target directory of its own: host builds (target/debug, …) and the
    // firmware's (other toolchain, other target, other flags) never
    // invalidate each other. firmware/.cargo/config.toml names the same one.
    let target_dir = root.join("target").join("firmware");
    let profile = if release { "release" } else { "debug" };

    let mut cmd = toolchain.cargo_build(&firmware_dir);
    cmd.arg("--manifest-path")
        .arg(firmware_dir.join("Cargo.toml"))
        .arg("--target")
        .arg(TARGET)
        .arg("--target-dir")
        .arg(&target_dir);
    if release {
        cmd.arg("--release");
    }
    let mut features: Vec<&str> = Vec::new();
    if chip != Chip::F405 {
        cmd.arg("--no-default-features");
        features.push(chip.feature());
    }
    if !features.is_empty() {
        cmd.args(["--features", &features.join(",")]);
    }
    // The image's robot: firmware/build.rs reads it.
    cmd.env("PADA_ROBOT", robot.env());

    println!(
        "xtask: building pada-firmware ({profile}, board profile {}: {} on {}, robot {}) for {TARGET}",
        chip.profile(),
        chip.feature(),
        chip.board(),
        robot.label()
    );
    let started = Instant::now();
    let status = cmd
        .status()
        .map_err(|e| format!("cannot start {}: {e}", toolchain.cargo_path().display()))?;
    if !status.success() {
        return Err(format!(
            "firmware build failed ({status}) with {}; cargo's errors are above",
            toolchain.short_name()
        ));
    }
    let elapsed = started.elapsed();

    let elf_path = target_dir.join(TARGET).join(profile).join("pada-firmware");
    let bytes = std::fs::read(&elf_path).map_err(|e| {
        format!(
            "build succeeded but {} is unreadable: {e}",
            elf_path.display()
        )
    })?;
    let sizes = elf::section_sizes(&bytes)
        .map_err(|e| format!("{}: not a usable ELF: {e}", elf_path.display()))?;
    let regions = std::fs::read_to_string(root.join(chip.memory_x()))
        .map(|text| elf::parse_memory_x(&text))
        .unwrap_or_default();
    let usage = elf::Usage::classify(&sizes, &regions);
    let table = elf::symbols(&bytes, "PADA_TABLE_")
        .map_err(|e| format!("{}: unreadable symbol table: {e}", elf_path.display()))?;

    println!(
        "xtask: built in {:.1} s with {}",
        elapsed.as_secs_f64(),
        toolchain.short_name()
    );
    println!("xtask: firmware ELF: {}", elf_path.display());
    print!("{}", usage.report(&regions, &table));
    println!(
        "xtask: flash with: probe-rs run --chip {} {}",
        chip.probe_rs_name(),
        elf_path.display()
    );
    Ok(elf_path)
}

/// Builds the emulated board's image; returns the ELF's path.
///
/// Every emulated image builds in one target directory
/// (`target/firmware-emulated`: the dependencies of both machines and all
/// robots are built once, about 700 MB, instead of once per image) and is
/// copied to `images/<board>-<robot>.elf` there, under a lock on the
/// directory so that two builds of different images cannot swap their
/// ELFs between build and copy.
fn qemu_image(root: &Path, build: Build) -> Result<PathBuf, String> {
    let toolchain = toolchain::detect()?;
    println!("xtask: toolchain: {}", toolchain.describe());
    let firmware_dir = root.join("firmware");
    let target_dir = root.join("target").join("firmware-emulated");
    let images = target_dir.join("images");
    std::fs::create_dir_all(&images).map_err(|e| format!("cannot create {}: {e}", images.display()))?;
    let lock_path = target_dir.join(".image.lock");
    let lock = std::fs::File::create(&lock_path).map_err(|e| format!("cannot create {}: {e}", lock_path.display()))?;
    lock.lock().map_err(|e| format!("cannot lock {}: {e}", lock_path.display()))?;
    let profile = if build.release { "release" } else { "debug" };
    let (machine_feature, machine, memory_x) = build.chip.emulated();
    let features = [machine_feature];
    let mut cmd = toolchain.cargo_build(&firmware_dir);
    cmd.arg("--manifest-path")
        .arg(firmware_dir.join("Cargo.toml"))
        .arg("--target")
        .arg(TARGET)
        .arg("--target-dir")
        .arg(&target_dir)
        .args(["--no-default-features", "--features", &features.join(",")])
        .env("PADA_ROBOT", build.robot.env());
    if build.release {
        cmd.arg("--release");
    }
    println!(
        "xtask: building pada-firmware ({profile}, board profile {} emulated on QEMU's {machine}, robot {}) for {TARGET}",
        build.chip.profile(),
        build.robot.label()
    );
    let started = Instant::now();
    let status = cmd
        .status()
        .map_err(|e| format!("cannot start {}: {e}", toolchain.cargo_path().display()))?;
    if !status.success() {
        return Err(format!("emulated-board build failed ({status}); cargo's errors are above"));
    }
    let built = target_dir.join(TARGET).join(profile).join("pada-firmware");
    let debug = if build.release { "" } else { "-debug" };
    let elf = images.join(format!("{}-{}{debug}.elf", build.chip.profile(), build.robot.image_name()));
    std::fs::copy(&built, &elf).map_err(|e| format!("cannot copy {} to {}: {e}", built.display(), elf.display()))?;
    drop(lock);
    println!("xtask: built in {:.1} s", started.elapsed().as_secs_f64());
    if let Ok(bytes) = std::fs::read(&elf) {
        let regions = std::fs::read_to_string(root.join(memory_x)).map(|t| elf::parse_memory_x(&t)).unwrap_or_default();
        if let (Ok(sizes), Ok(table)) = (elf::section_sizes(&bytes), elf::symbols(&bytes, "PADA_TABLE_")) {
            print!("{}", elf::Usage::classify(&sizes, &regions).report(&regions, &table));
        }
    }
    println!("xtask: firmware ELF: {}", elf.display());
    Ok(elf)
}

/// Runs `pada sil --elf <elf> --task <robot's task> --board <profile> <args>`
/// (release build); a robot of files is `--robot <robot.toml>` instead of
/// `--task`.
fn sil(root: &Path, elf: &Path, build: Build, args: &[String]) -> Result<(), String> {
    let cargo = env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut cmd = std::process::Command::new(&cargo);
    toolchain::clean_env(&mut cmd, false);
    cmd.current_dir(root)
        .args(["run", "--release", "--quiet", "--package", "pada", "--", "sil", "--elf"])
        .arg(elf);
    let given = |flag: &str| args.iter().any(|a| a == flag || a.starts_with(&format!("{flag}=")));
    match &build.robot {
        Robot::BuiltIn(b) if !given("--task") && !given("--robot") => {
            cmd.args(["--task", b.short_name]);
        }
        Robot::File(p) if !given("--robot") => {
            cmd.arg("--robot").arg(p);
        }
        _ => {}
    }
    if !given("--board") {
        cmd.args(["--board", build.chip.profile()]);
    }
    cmd.args(args);
    let status = cmd.status().map_err(|e| format!("cannot start cargo: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("pada sil failed ({status})"))
    }
}

/// Flashes `elf` and streams its defmt log (`probe-rs run`), as `cargo run`
/// does with the runner of `.cargo/config.toml`.
fn flash(elf: &Path, chip: Chip) -> Result<(), String> {
    println!("xtask: probe-rs run --chip {} {}", chip.probe_rs_name(), elf.display());
    let status = std::process::Command::new("probe-rs")
        .args(["run", "--chip", chip.probe_rs_name()])
        .arg(elf)
        .status()
        .map_err(|e| {
            format!(
                "cannot start probe-rs ({e}); install it (`cargo install probe-rs-tools`, \
                 https://probe.rs) or flash {} with another tool",
                elf.display()
            )
        })?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("probe-rs failed ({status})"))
    }
}

/// Runs the firmware library's tests for the host with the toolchain this
/// xtask runs with.
fn firmware_test(root: &Path) -> Result<(), String> {
    let cargo = env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let host = std::process::Command::new(env::var_os("RUSTC").unwrap_or_else(|| "rustc".into()))
        .arg("-vV")
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .and_then(|v| v.lines().find_map(|l| l.strip_prefix("host: ").map(str::to_owned)))
        .ok_or("cannot ask rustc for the host target")?;
    let mut cmd = std::process::Command::new(&cargo);
    toolchain::clean_env(&mut cmd, false);
    cmd.current_dir(root)
        .arg("test")
        .arg("--manifest-path")
        .arg(root.join("firmware").join("Cargo.toml"))
        .args(["--lib", "--target", &host])
        .arg("--target-dir")
        .arg(root.join("target").join("firmware"));
    println!("xtask: testing the firmware library on {host}");
    let status = cmd.status().map_err(|e| format!("cannot start cargo: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("firmware library tests failed ({status})"))
    }
}

/// Builds `pada-fuzz` in the `fuzz` profile (optimised, overflow checks
/// on) and runs it with `args`.
fn fuzz(root: &Path, args: &[String]) -> Result<(), String> {
    let cargo = env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut cmd = std::process::Command::new(&cargo);
    toolchain::clean_env(&mut cmd, false);
    cmd.current_dir(root)
        .args(["run", "--quiet", "--profile", "fuzz", "--package", "pada-fuzz", "--manifest-path"])
        .arg(root.join("Cargo.toml"))
        .arg("--")
        .args(args);
    println!("xtask: fuzzing the decoders (pada-fuzz {})", args.join(" "));
    let status = cmd.status().map_err(|e| format!("cannot start cargo: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("fuzzing found inputs that break an invariant ({status})"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
