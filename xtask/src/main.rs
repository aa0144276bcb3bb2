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

mod args;
mod elf;
mod test;
mod toolchain;

use args::{parse_args, Build, Robot, Task, USAGE};
use std::{
    env,
    path::{Path, PathBuf},
    process::ExitCode,
    time::Instant,
};

/// The firmware's compilation target (Cortex-M4F with hardware float).
pub const TARGET: &str = "thumbv7em-none-eabihf";

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
pub(crate) const PROFILES: &str = "f405 or f429-sdram";

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

/// The workspace's root directory.
pub(crate) fn workspace_root() -> PathBuf {
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

    let mut cmd = toolchain.cargo_build_firmware(&firmware_dir, &target_dir, release);
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
    table_demand(root, chip, &robot);
    println!(
        "xtask: flash with: probe-rs run --chip {} {}",
        chip.probe_rs_name(),
        elf_path.display()
    );
    Ok(elf_path)
}

/// Before flashing: whether the robot's learning fits the image's table.
/// `pada claims --board B --robot R` (or `--task NAME`) measures the
/// features one host trial writes over the robot's learning time (cached
/// between runs) against the board's claim table, and warns where the
/// table fills before learning ends; an exact table is said to fit (the
/// build would have failed otherwise). A check that cannot run is said,
/// and the build stands.
fn table_demand(root: &Path, chip: Chip, robot: &Robot) {
    let mut cmd = std::process::Command::new(env::var_os("CARGO").unwrap_or_else(|| "cargo".into()));
    cmd.current_dir(root).args(["run", "--release", "--quiet", "-p", "pada", "--", "claims", "--board", chip.profile()]);
    match robot {
        Robot::File(p) => cmd.arg("--robot").arg(p),
        // pada's own robots: their exact tables are fixed by the build;
        // LEO's claim table is measured as a robot of files' is.
        Robot::BuiltIn(b) if b.spec.table == pada_core::robot::TableNeed::Claimed => cmd.args(["--task", b.spec.name]),
        Robot::BuiltIn(_) => return,
    };
    println!("xtask: will the robot's learning fit the table? (`pada claims`, one host trial, cached)");
    match cmd.status() {
        Ok(s) if s.success() => {}
        Ok(s) => println!("xtask: the table's demand could not be measured ({s}): run `pada claims --board {} --robot …` to know before flashing", chip.profile()),
        Err(e) => println!("xtask: the table's demand could not be measured (cannot start cargo: {e})"),
    }
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
    let mut cmd = toolchain.cargo_build_firmware(&firmware_dir, &target_dir, build.release);
    cmd.args(["--no-default-features", "--features", &features.join(",")]).env("PADA_ROBOT", build.robot.env());
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
