//! Helpers shared by the end-to-end tests: the repository, the firmware
//! image for the emulated board, QEMU.

#![allow(dead_code)]

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

/// The repository root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ is inside the repository")
        .to_path_buf()
}

fn cargo() -> Command {
    let mut c = Command::new(env!("CARGO"));
    c.current_dir(root());
    c
}

/// The firmware image for the emulated board of board profile `board`
/// (`f405`: QEMU's netduinoplus2; `f429-sdram`: mps2-an386) and `robot`
/// (`pendulum` or `leo`), built once per test binary with `cargo xtask
/// qemu` (which needs a toolchain for thumbv7em-none-eabihf; CI installs
/// Debian's).
pub fn image(board: &str, robot: &str) -> PathBuf {
    static BUILT: Mutex<Option<HashMap<String, PathBuf>>> = Mutex::new(None);
    let mut built = BUILT.lock().unwrap_or_else(|e| e.into_inner());
    let map = built.get_or_insert_with(HashMap::new);
    let key = format!("{board}-{robot}");
    if let Some(p) = map.get(&key) {
        return p.clone();
    }
    let out = cargo()
        .args(["xtask", "qemu", "--board", board, "--robot", robot])
        .output()
        .expect("cannot run cargo xtask qemu");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "cargo xtask qemu --board {board} --robot {robot} failed (a thumbv7em-none-eabihf toolchain is needed, see .ci/run):\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let elf = stdout
        .lines()
        .rev()
        .find_map(|l| l.strip_prefix("xtask: firmware ELF: "))
        .map(PathBuf::from)
        .expect("xtask names the ELF");
    map.insert(key, elf.clone());
    elf
}

/// `qemu-system-arm` is there (10 or later; CI installs it from
/// bookworm-backports). Panics with what to do otherwise: the SIL tests
/// are meant to run, not to be skipped.
pub fn require_qemu() {
    let out = Command::new("qemu-system-arm").arg("--version").output();
    let ok = out.as_ref().is_ok_and(|o| o.status.success());
    assert!(
        ok,
        "qemu-system-arm is not installed: install QEMU 10 from bookworm-backports (DESIGN.md, .ci/run)"
    );
}
