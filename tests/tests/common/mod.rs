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
/// qemu` (which needs a toolchain for thumbv7em-none-eabihf; `cargo xtask
/// test` installs Debian's).
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
        "cargo xtask qemu --board {board} --robot {robot} failed (a thumbv7em-none-eabihf toolchain is needed: `cargo xtask test` installs Debian's, or `sudo .ci/install firmware-toolchain`):\n{stdout}\n{}",
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

/// `qemu-system-arm` 10 or later is there (an older one does not model the
/// F405's CCM RAM, where the firmware keeps its weight table: the image
/// would fault, not fail clearly). Panics with what to do otherwise: the
/// SIL tests are meant to run, not to be skipped. `cargo xtask test`
/// installs it (`.ci/install qemu`: QEMU 10 from bookworm-backports).
pub fn require_qemu() {
    const FIX: &str = "`cargo xtask test` installs QEMU 10 from bookworm-backports (as root; or run `sudo .ci/install qemu`)";
    let out = Command::new("qemu-system-arm").arg("--version").output();
    let version = match out {
        Ok(o) if o.status.success() => String::from_utf8_lossy(&o.stdout).into_owned(),
        _ => panic!("qemu-system-arm is not installed: {FIX}"),
    };
    let major = version
        .lines()
        .next()
        .and_then(|l| l.strip_prefix("QEMU emulator version "))
        .and_then(|v| v.split('.').next())
        .and_then(|m| m.parse::<u32>().ok());
    assert!(
        major.is_some_and(|m| m >= 10),
        "qemu-system-arm is too old or unrecognised ({:?}; 10 or later models the F405's CCM RAM): {FIX}",
        version.lines().next().unwrap_or("")
    );
}
