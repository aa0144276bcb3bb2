//! Link setup, as cortex-m-rt projects do it: put the board's memory layout
//! where `link.x` (from cortex-m-rt) can `INCLUDE` it as `memory.x`, and
//! link with `link.x`. And the robot the image drives: `PADA_ROBOT` names
//! one of pada's robots (`pada_core::robot::registry`; the 33 Hz pendulum
//! when unset) or is the path of a robot's `robot.toml` (read by
//! pada-robot-file, a build-dependency only: the image holds the generated
//! constants, not the reader), written into `$OUT_DIR/robot.rs` for `src/table.rs`, with
//! the board's learner profile for it decided here too (`cfg(pada_table)`:
//! which memory the weight table lies in). A robot whose table fits no
//! memory of the board fails the build with the sizes.

use std::{
    env, fs,
    path::{Path, PathBuf},
};

fn main() {
    // `emulated`: a board of the software-in-the-loop run (src/board/lockstep/);
    // `profile_f429`: the f429-sdram board learner profile (the F429I-DISC1
    // and its emulation on mps2-an386).
    println!("cargo::rustc-check-cfg=cfg(emulated)");
    println!("cargo::rustc-check-cfg=cfg(profile_f429)");
    let feature = |f: &str| env::var_os(format!("CARGO_FEATURE_{}", f.to_uppercase())).is_some();
    if feature("qemu") || feature("mps2") {
        println!("cargo:rustc-cfg=emulated");
    }
    if feature("stm32f429") || feature("mps2") {
        println!("cargo:rustc-cfg=profile_f429");
    }
    let chips: Vec<&str> = ["stm32f405", "stm32f407", "stm32f429", "qemu", "mps2"]
        .into_iter()
        .filter(|c| feature(c))
        .collect();
    let for_chip = env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("none");
    // On the host only the library is built (its tests, and the host's
    // replay of the firmware's agent); it needs no board.
    if !for_chip && chips.is_empty() {
        println!("cargo:rerun-if-changed=build.rs");
        return;
    }
    println!("cargo::rustc-check-cfg=cfg(pada_table, values(\"exact_ccm\", \"exact_ccm_sram\", \"exact_sram\", \"claimed_ccm\", \"hashed_ccm\", \"claimed_sdram\"))");
    if chips.len() != 1 {
        panic!(
            "pada-firmware: enable exactly one board feature (stm32f405, stm32f407, stm32f429, qemu, mps2); \
             got {chips:?}. For a non-default board use --no-default-features --features <board>."
        );
    }
    let manifest_dir = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").unwrap());
    // The workspace's memory.x describes the STM32F405RG and the F407VG
    // (same layout; QEMU's netduinoplus2 is an F405RG); the STM32F429ZI
    // (2 MB of flash in two banks, 192 KB SRAM, the DISC1's SDRAM) and
    // QEMU's mps2-an386 (its emulation) have their own. Each is copied
    // under the name link.x includes.
    let memory_x = match chips.first() {
        Some(&"stm32f429") => manifest_dir.join("memory-f429.x"),
        Some(&"mps2") => manifest_dir.join("memory-mps2.x"),
        _ => manifest_dir.join("..").join("memory.x"),
    };
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap());
    let contents = fs::read(&memory_x)
        .unwrap_or_else(|e| panic!("pada-firmware: cannot read {}: {e}", memory_x.display()));
    fs::write(out.join("memory.x"), contents).unwrap();
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={}", memory_x.display());
    println!("cargo:rerun-if-changed=build.rs");
    robot(&out, feature("stm32f429") || feature("mps2"));

    // The library also builds for the host (its tests); only the chip's
    // binary is linked with these scripts.
    if !for_chip {
        return;
    }
    // Segments need no page alignment in flash (keeps images small); both
    // rust-lld and GNU ld (arm-none-eabi-ld) accept it.
    println!("cargo:rustc-link-arg-bins=--nmagic");
    // cortex-m-rt's linker script; it includes memory.x. Set here rather
    // than in .cargo/config.toml so every way of building gets it once.
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    // defmt's symbol table (the log format strings live in the ELF only).
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}

/// The robot of the image: `$OUT_DIR/robot.rs` and `cfg(pada_table)`.
/// `PADA_ROBOT` is a robot of pada's registry by name, or the path of a
/// robot's `robot.toml` ([`is_file`]).
fn robot(out: &Path, f429: bool) {
    use pada_core::profile::{Board, Memory};
    use pada_core::robot::registry;
    use pada_core::tile_coding::Layout;
    println!("cargo:rerun-if-env-changed=PADA_ROBOT");
    let name = env::var("PADA_ROBOT").unwrap_or_else(|_| "physical-pendulum".into());
    let board = if f429 { Board::F429Sdram } else { Board::F405 };
    let (spec, source) = if is_file(&name) {
        robot_of_file(Path::new(&name), board)
    } else {
        let Some(robot) = registry::find(&name) else {
            let names: Vec<&str> = registry::names().collect();
            fail(&format!(
                "PADA_ROBOT={name:?} is no robot pada knows: valid are {}, or the path of a robot.toml",
                names.join(", ")
            ));
        };
        let mut source = String::from("// Generated by build.rs from PADA_ROBOT.\n");
        robot.rust_source(&mut source).unwrap();
        (robot.spec, source)
    };
    let profile = board.profile(spec).unwrap_or_else(|e| fail(&format!("robot {}: {e}", spec.name)));
    let table = match (profile.layout, profile.memory) {
        (Layout::Exact, Memory::Ccm) => "exact_ccm",
        (Layout::Exact, Memory::CcmThenSram { .. }) => "exact_ccm_sram",
        (Layout::Exact, Memory::Sram) => "exact_sram",
        (Layout::Claimed, Memory::Ccm) => "claimed_ccm",
        (Layout::Hashed, Memory::Ccm) => "hashed_ccm",
        (Layout::Claimed, Memory::Sdram) => "claimed_sdram",
        (layout, memory) => fail(&format!("no table layout for {layout:?} in {memory:?}")),
    };
    println!("cargo:rustc-cfg=pada_table=\"{table}\"");
    fs::write(out.join("robot.rs"), source).unwrap();
}

/// Whether `PADA_ROBOT` names a file rather than a built-in robot: a
/// `robot.toml` path ends in `.toml` or has a directory in it, and no
/// built-in robot's name does either.
fn is_file(robot: &str) -> bool {
    robot.ends_with(".toml") || robot.contains(std::path::MAIN_SEPARATOR) || robot.contains('/')
}

/// A robot of files: its definition (read and checked by pada-robot-file,
/// the host's own reader, so both learn on the same bits) and its Rust
/// source. A relative path is taken from the firmware's directory, where
/// cargo runs build scripts; `cargo xtask` passes an absolute one.
fn robot_of_file(path: &Path, board: pada_core::profile::Board) -> (&'static pada_core::robot::RobotSpec, String) {
    let file = pada_robot_file::load(path).unwrap_or_else(|e| fail(&e.to_string()));
    // Rebuild when the robot's files change, not only when the variable does.
    println!("cargo:rerun-if-changed={}", path.display());
    println!("cargo:rerun-if-changed={}", file.urdf.path.display());
    // The table must fit the board: the file's error, with its name.
    file.profile(board).unwrap_or_else(|e| fail(&e.to_string()));
    let source = pada_robot_file::rust_source(file.spec, &path.display().to_string())
        .unwrap_or_else(|e| fail(&format!("{}: {e}", path.display())));
    (file.spec, source)
}

/// Stops the build with one line: cargo prints a `cargo::error` as
/// `error: …` and fails the build after the script ends. (Exiting with a
/// failure instead, or panicking, makes cargo dump everything the script
/// printed around it.)
fn fail(message: &str) -> ! {
    println!("cargo::error={message}");
    std::process::exit(0)
}
