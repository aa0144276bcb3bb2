//! Link setup, as cortex-m-rt projects do it: put the board's memory layout
//! where `link.x` (from cortex-m-rt) can `INCLUDE` it as `memory.x`, and
//! link with `link.x`. And the robot the image drives: `PADA_ROBOT` names
//! one of pada's robots (`pada_core::robot::registry`; the 33 Hz pendulum
//! when unset), written into `$OUT_DIR/robot.rs` for `src/table.rs`, with
//! the board's learner profile for it decided here too (`cfg(pada_table)`:
//! which memory the weight table lies in). A robot whose table fits no
//! memory of the board fails the build with the sizes.

use std::{env, fs, path::PathBuf};

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
    println!("cargo::rustc-check-cfg=cfg(pada_table, values(\"exact_ccm\", \"exact_ccm_sram\", \"exact_sram\", \"claimed_ccm\", \"claimed_sdram\"))");
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
fn robot(out: &std::path::Path, f429: bool) {
    use pada_core::profile::{Board, Memory};
    use pada_core::robot::registry;
    use pada_core::tile_coding::Layout;
    println!("cargo:rerun-if-env-changed=PADA_ROBOT");
    let name = env::var("PADA_ROBOT").unwrap_or_else(|_| "physical-pendulum".into());
    let Some(robot) = registry::find(&name) else {
        let names: Vec<&str> = registry::names().collect();
        panic!("pada-firmware: PADA_ROBOT={name:?} is no robot pada knows: valid are {}", names.join(", "));
    };
    let board = if f429 { Board::F429Sdram } else { Board::F405 };
    let profile = board.profile(robot.spec).unwrap_or_else(|e| panic!("pada-firmware: robot {name}: {e}"));
    let table = match (profile.layout, profile.memory) {
        (Layout::Exact, Memory::Ccm) => "exact_ccm",
        (Layout::Exact, Memory::CcmThenSram { .. }) => "exact_ccm_sram",
        (Layout::Exact, Memory::Sram) => "exact_sram",
        (Layout::Claimed, Memory::Ccm) => "claimed_ccm",
        (Layout::Claimed, Memory::Sdram) => "claimed_sdram",
        (layout, memory) => panic!("pada-firmware: no table layout for {layout:?} in {memory:?}"),
    };
    println!("cargo:rustc-cfg=pada_table=\"{table}\"");
    let mut source = String::from("// Generated by build.rs from PADA_ROBOT.\n");
    robot.rust_source(&mut source).unwrap();
    fs::write(out.join("robot.rs"), source).unwrap();
}
