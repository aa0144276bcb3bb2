//! Build orchestration for pada: `cargo xtask <task>`.
//!
//! Tasks:
//! - `firmware [--release] [--chip f405|f407|f446]`: build the firmware ELF
//!   for thumbv7em-none-eabihf with whichever toolchain this machine has
//!   (see [`toolchain`]), then print its flash and RAM use (see [`elf`]).
//!
//! The xtask has no dependencies. Its command line is two flags and a
//! subcommand, so a hand-written parser is shorter than the argument-parser
//! crate it would replace and keeps `cargo xtask` quick to build on a fresh
//! CI machine.

mod elf;
mod toolchain;

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
  firmware [--release] [--chip f405|f407|f446]
        build the firmware ELF for thumbv7em-none-eabihf (debug unless
        --release; chip f405 unless --chip) and print its flash/RAM use
  help  print this message";

/// A microcontroller the firmware can be built for (one cargo feature each).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Chip {
    F405,
    F407,
    F446,
}

impl Chip {
    fn parse(s: &str) -> Option<Chip> {
        match s.to_ascii_lowercase().trim_start_matches("stm32") {
            "f405" => Some(Chip::F405),
            "f407" => Some(Chip::F407),
            "f446" => Some(Chip::F446),
            _ => None,
        }
    }

    /// The firmware's cargo feature that selects this chip.
    pub fn feature(self) -> &'static str {
        match self {
            Chip::F405 => "stm32f405",
            Chip::F407 => "stm32f407",
            Chip::F446 => "stm32f446",
        }
    }

    /// The name probe-rs knows the usual package of this chip by.
    pub fn probe_rs_name(self) -> &'static str {
        match self {
            Chip::F405 => "STM32F405RGTx",
            Chip::F407 => "STM32F407VGTx",
            Chip::F446 => "STM32F446RETx",
        }
    }
}

#[derive(Debug, PartialEq, Eq)]
enum Task {
    Help,
    Firmware { release: bool, chip: Chip },
}

fn parse_args(args: &[String]) -> Result<Task, String> {
    let Some((task, rest)) = args.split_first() else {
        return Err("no task given".into());
    };
    match task.as_str() {
        "help" | "-h" | "--help" => Ok(Task::Help),
        "firmware" => {
            let mut release = false;
            let mut chip = Chip::F405;
            let mut rest = rest.iter();
            while let Some(arg) = rest.next() {
                let chip_value = match arg.as_str() {
                    "--release" | "-r" => {
                        release = true;
                        continue;
                    }
                    "-h" | "--help" => return Ok(Task::Help),
                    "--chip" => rest
                        .next()
                        .ok_or("--chip needs a value: f405, f407 or f446")?,
                    other => match other.strip_prefix("--chip=") {
                        Some(v) => v,
                        None => return Err(format!("unknown argument `{other}` for `firmware`")),
                    },
                };
                chip = Chip::parse(chip_value).ok_or_else(|| {
                    format!("unknown chip `{chip_value}`: expected f405, f407 or f446")
                })?;
            }
            Ok(Task::Firmware { release, chip })
        }
        other => Err(format!("unknown task `{other}`")),
    }
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
            eprintln!("xtask: error: {e}\n\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    let result = match task {
        Task::Help => {
            println!("{USAGE}");
            Ok(())
        }
        Task::Firmware { release, chip } => firmware(&workspace_root(), release, chip),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask: error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn firmware(root: &Path, release: bool, chip: Chip) -> Result<(), String> {
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
    if chip != Chip::F405 {
        cmd.args(["--no-default-features", "--features", chip.feature()]);
    }

    println!(
        "xtask: building pada-firmware ({profile}, {}) for {TARGET}",
        chip.feature()
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
    let regions = std::fs::read_to_string(root.join("memory.x"))
        .map(|text| elf::parse_memory_x(&text))
        .unwrap_or_default();
    let usage = elf::Usage::classify(&sizes, &regions);

    println!(
        "xtask: built in {:.1} s with {}",
        elapsed.as_secs_f64(),
        toolchain.short_name()
    );
    println!("xtask: firmware ELF: {}", elf_path.display());
    print!("{}", usage.report(&regions));
    println!(
        "xtask: flash with: probe-rs run --chip {} {}",
        chip.probe_rs_name(),
        elf_path.display()
    );
    if chip == Chip::F446 {
        println!(
            "xtask: note: linked with the STM32F405 memory.x; the F446RE has 512 KB flash and no CCM"
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(s: &str) -> Vec<String> {
        s.split_whitespace().map(String::from).collect()
    }

    #[test]
    fn firmware_defaults_to_debug_f405() {
        assert_eq!(
            parse_args(&args("firmware")),
            Ok(Task::Firmware {
                release: false,
                chip: Chip::F405
            })
        );
    }

    #[test]
    fn firmware_flags_in_any_order_and_both_chip_spellings() {
        let want = Ok(Task::Firmware {
            release: true,
            chip: Chip::F446,
        });
        assert_eq!(parse_args(&args("firmware --chip f446 --release")), want);
        assert_eq!(
            parse_args(&args("firmware --release --chip=stm32F446")),
            want
        );
    }

    #[test]
    fn bad_arguments_are_errors() {
        assert!(parse_args(&args("")).is_err());
        assert!(parse_args(&args("flash")).is_err());
        assert!(parse_args(&args("firmware --chip")).is_err());
        assert!(parse_args(&args("firmware --chip f103")).is_err());
        assert!(parse_args(&args("firmware --relase")).is_err());
    }
}
