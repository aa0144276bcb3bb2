//! Which Rust toolchain can build for the chip here, and how to call it.
//!
//! 1. **Native**: the rustc that `cargo xtask` itself runs with (rustup's,
//!    usually) has the thumbv7em-none-eabihf standard library installed
//!    (`rustup target add thumbv7em-none-eabihf`). Plain `cargo build
//!    --target …`, linked with rust-lld (the target's default).
//! 2. **Debian**: `/usr/bin/rustc` and `/usr/bin/cargo` (packages rustc-web,
//!    cargo-web) with the library source (rust-web-src) build `core` for the
//!    target themselves (`-Z build-std=core`, allowed on a stable compiler by
//!    `RUSTC_BOOTSTRAP=1`) and link with `arm-none-eabi-ld`
//!    (binutils-arm-none-eabi): Debian's `/usr/bin/rust-lld` is only a link
//!    to an `lld-NN` that the packages do not pull in.
//! 3. Otherwise: an error that says what to install.
//!
//! The inner cargo must not inherit what the outer `cargo run` (and rustup's
//! proxy) put into the environment: `CARGO`, `CARGO_PKG_*`,
//! `CARGO_MANIFEST_DIR`, `RUSTUP_TOOLCHAIN`, a toolchain's `lib` on
//! `LD_LIBRARY_PATH`, host `RUSTFLAGS`, … . [`clean_env`] removes them.

use std::{
    env,
    ffi::OsString,
    path::{Path, PathBuf},
    process::Command,
};

use crate::TARGET;

const DEBIAN_RUSTC: &str = "/usr/bin/rustc";
const DEBIAN_CARGO: &str = "/usr/bin/cargo";
const GNU_LINKER: &str = "arm-none-eabi-ld";
const DEBIAN_PACKAGES: &str = "rustc-web cargo-web rust-web-src binutils-arm-none-eabi";

pub enum Toolchain {
    Native {
        cargo: PathBuf,
        /// `RUSTC` as the user set it (it chose the rustc that was checked).
        rustc: Option<OsString>,
        rustc_version: String,
    },
    Debian {
        rustc_version: String,
        linker: PathBuf,
    },
}

impl Toolchain {
    pub fn short_name(&self) -> &'static str {
        match self {
            Toolchain::Native { .. } => "the native toolchain (rust-lld)",
            Toolchain::Debian { .. } => "Debian's toolchain (build-std, arm-none-eabi-ld)",
        }
    }

    pub fn describe(&self) -> String {
        match self {
            Toolchain::Native {
                cargo,
                rustc_version,
                ..
            } => format!(
                "native: {rustc_version} has the {TARGET} target installed; \
                 {} build --target {TARGET}, linker rust-lld",
                cargo.display()
            ),
            Toolchain::Debian {
                rustc_version,
                linker,
            } => format!(
                "Debian: {rustc_version} ({DEBIAN_RUSTC}) with its library source; \
                 RUSTC_BOOTSTRAP=1 {DEBIAN_CARGO} build -Z build-std=core --target {TARGET}, \
                 linker {} (the current rustc has no {TARGET} target)",
                linker.display()
            ),
        }
    }

    pub fn cargo_path(&self) -> PathBuf {
        match self {
            Toolchain::Native { cargo, .. } => cargo.clone(),
            Toolchain::Debian { .. } => PathBuf::from(DEBIAN_CARGO),
        }
    }

    /// `cargo build` for the firmware, with a clean environment, run in
    /// `dir` (so the firmware's `.cargo/config.toml` applies). The caller
    /// adds manifest, target, target dir and profile.
    pub fn cargo_build(&self, dir: &Path) -> Command {
        let mut cmd = Command::new(self.cargo_path());
        cmd.current_dir(dir);
        match self {
            Toolchain::Native { rustc, .. } => {
                // Keep RUSTUP_TOOLCHAIN: `cargo +nightly xtask firmware`
                // should build the firmware with nightly too.
                clean_env(&mut cmd, false);
                if let Some(rustc) = rustc {
                    cmd.env("RUSTC", rustc);
                }
                cmd.arg("build");
            }
            Toolchain::Debian { linker, .. } => {
                clean_env(&mut cmd, true);
                cmd.env("RUSTC", DEBIAN_RUSTC)
                    .env("RUSTC_BOOTSTRAP", "1")
                    .env("CARGO_TARGET_THUMBV7EM_NONE_EABIHF_LINKER", linker);
                // `core` only: cargo then also enables compiler-builtins'
                // `mem` feature, so memcpy/memset come with it.
                cmd.args(["build", "-Z", "build-std=core"]);
            }
        }
        cmd
    }

    /// `cargo build` of the firmware crate in `firmware_dir` for [`TARGET`]
    /// into `target_dir`, in release when `release`: what every firmware
    /// image's build starts from (features and the robot come after).
    pub fn cargo_build_firmware(&self, firmware_dir: &Path, target_dir: &Path, release: bool) -> Command {
        let mut cmd = self.cargo_build(firmware_dir);
        cmd.arg("--manifest-path")
            .arg(firmware_dir.join("Cargo.toml"))
            .arg("--target")
            .arg(TARGET)
            .arg("--target-dir")
            .arg(target_dir);
        if release {
            cmd.arg("--release");
        }
        cmd
    }
}

/// Finds a toolchain that can build for [`TARGET`], preferring the native one.
pub fn detect() -> Result<Toolchain, String> {
    // 1. The rustc this xtask was started with (a rustup proxy honours
    //    RUSTUP_TOOLCHAIN, which is still set here).
    let rustc_env = env::var_os("RUSTC");
    let rustc = rustc_env.clone().unwrap_or_else(|| OsString::from("rustc"));
    let mut native_sysroot = None;
    if let Some(sysroot) = output(Command::new(&rustc).args(["--print", "sysroot"])) {
        let target_lib = Path::new(&sysroot)
            .join("lib/rustlib")
            .join(TARGET)
            .join("lib");
        if target_lib.is_dir() {
            let rustc_version =
                output(Command::new(&rustc).arg("-V")).unwrap_or_else(|| "rustc".into());
            let cargo = env::var_os("CARGO")
                .map(PathBuf::from)
                .unwrap_or_else(|| "cargo".into());
            return Ok(Toolchain::Native {
                cargo,
                rustc: rustc_env,
                rustc_version,
            });
        }
        native_sysroot = Some(sysroot);
    }

    // 2. Debian's rustc + cargo + library source + GNU linker.
    let debian_rustc = Path::new(DEBIAN_RUSTC).is_file();
    let debian_cargo = Path::new(DEBIAN_CARGO).is_file();
    let mut library = None;
    let mut rustc_version = None;
    if debian_rustc {
        let mut print_sysroot = Command::new(DEBIAN_RUSTC);
        clean_env(&mut print_sysroot, true);
        if let Some(sysroot) = output(print_sysroot.args(["--print", "sysroot"])) {
            // Where cargo's build-std looks for the standard library source.
            let lib = Path::new(&sysroot).join("lib/rustlib/src/rust/library");
            if lib.join("core/src/lib.rs").is_file() {
                library = Some(lib);
            }
        }
        let mut version = Command::new(DEBIAN_RUSTC);
        clean_env(&mut version, true);
        rustc_version = output(version.arg("-V"));
    }
    let linker = find_in_path(GNU_LINKER);
    if let (true, true, Some(_), Some(linker), Some(rustc_version)) = (
        debian_rustc,
        debian_cargo,
        &library,
        &linker,
        &rustc_version,
    ) {
        return Ok(Toolchain::Debian {
            rustc_version: rustc_version.clone(),
            linker: linker.clone(),
        });
    }

    // 3. Nothing fits: say what was found and what to install.
    let yes_no = |b: bool| if b { "found" } else { "missing" };
    Err(format!(
        "no toolchain on this machine can build for {TARGET}.\n\
         \x20 native: `{rustc}` {native} has no {TARGET} standard library\n\
         \x20         -> rustup target add {TARGET}\n\
         \x20 Debian: {DEBIAN_RUSTC} {}, {DEBIAN_CARGO} {}, library source {}, {GNU_LINKER} {}\n\
         \x20         -> apt-get install -y {DEBIAN_PACKAGES}",
        yes_no(debian_rustc),
        yes_no(debian_cargo),
        yes_no(library.is_some()),
        yes_no(linker.is_some()),
        rustc = rustc.to_string_lossy(),
        native = match &native_sysroot {
            Some(s) => format!("(sysroot {s})"),
            None => "(not runnable)".into(),
        },
    ))
}

/// Removes what an outer `cargo run`/rustup put into the environment so the
/// inner firmware build is configured only by its own files and the flags
/// the xtask passes. With `foreign` (a different toolchain than the outer
/// one) also drops rustup's toolchain choice and the outer toolchain's
/// directories from PATH and LD_LIBRARY_PATH.
pub fn clean_env(cmd: &mut Command, foreign: bool) {
    let rustup_toolchains = env::var_os("RUSTUP_HOME")
        .map(PathBuf::from)
        .or_else(|| env::var_os("HOME").map(|h| PathBuf::from(h).join(".rustup")))
        .map(|h| h.join("toolchains"));
    let workspace_target = crate::workspace_root().join("target");
    for (key, value) in env::vars_os() {
        let Some(key) = key.to_str() else { continue };
        if should_remove(key, foreign) {
            cmd.env_remove(key);
        } else if foreign && (key == "PATH" || key == "LD_LIBRARY_PATH") {
            // rustup may prepend its toolchain's bin/ to PATH, and `cargo
            // run` puts the host toolchain's lib/ and our target/ on
            // LD_LIBRARY_PATH; neither belongs to Debian's rustc.
            let kept: Vec<PathBuf> = env::split_paths(&value)
                .filter(|p| match &rustup_toolchains {
                    Some(t) => !p.starts_with(t),
                    None => true,
                })
                .filter(|p| key == "PATH" || !p.starts_with(&workspace_target))
                .collect();
            if let Ok(joined) = env::join_paths(kept) {
                cmd.env(key, joined);
            }
        }
    }
}

fn should_remove(key: &str, foreign: bool) -> bool {
    const ALWAYS: &[&str] = &[
        // Set by `cargo run` for the program it runs (here: the xtask).
        "CARGO",
        "CARGO_MANIFEST_DIR",
        "CARGO_MANIFEST_PATH",
        "CARGO_MANIFEST_LINKS",
        "CARGO_BIN_NAME",
        "CARGO_CRATE_NAME",
        "CARGO_PRIMARY_PACKAGE",
        "CARGO_RUSTC_CURRENT_DIR",
        // Would redirect or reconfigure the inner build.
        "CARGO_TARGET_DIR",
        "CARGO_ENCODED_RUSTFLAGS",
        "CARGO_MAKEFLAGS",
        "RUSTC",
        "RUSTC_WRAPPER",
        "RUSTC_WORKSPACE_WRAPPER",
        "RUSTDOC",
        "RUSTDOCFLAGS",
        // Host flags (e.g. `-C target-cpu=native`) do not suit the chip;
        // firmware flags belong in .cargo/config.toml [target.thumbv7em-…].
        "RUSTFLAGS",
        "RUSTC_BOOTSTRAP",
        "CARGO_TARGET_THUMBV7EM_NONE_EABIHF_LINKER",
    ];
    const ALWAYS_PREFIXES: &[&str] = &[
        "CARGO_PKG_",     // cargo run: package metadata of the xtask
        "CARGO_CFG_",     // build-script variables, if started from one
        "CARGO_FEATURE_", // idem
        "CARGO_BUILD_",   // build.target, build.rustc, build.rustflags, …
        "__CARGO",        // cargo-internal
    ];
    // rustup's proxy: which toolchain, and its recursion guard.
    const FOREIGN: &[&str] = &[
        "RUSTUP_TOOLCHAIN",
        "RUSTUP_TOOLCHAIN_SOURCE",
        "RUST_RECURSION_COUNT",
    ];
    ALWAYS.contains(&key)
        || ALWAYS_PREFIXES.iter().any(|p| key.starts_with(p))
        || (foreign && FOREIGN.contains(&key))
}

/// The trimmed stdout of a command that succeeded.
fn output(cmd: &mut Command) -> Option<String> {
    let out = cmd.output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn find_in_path(program: &str) -> Option<PathBuf> {
    env::split_paths(&env::var_os("PATH")?)
        .map(|dir| dir.join(program))
        .find(|p| p.is_file())
}

#[cfg(test)]
mod tests {
    use super::should_remove;

    #[test]
    fn outer_cargo_variables_do_not_leak() {
        for key in [
            "CARGO",
            "CARGO_PKG_NAME",
            "CARGO_MANIFEST_DIR",
            "RUSTFLAGS",
            "RUSTC",
        ] {
            assert!(should_remove(key, false), "{key}");
        }
        assert!(should_remove("RUSTUP_TOOLCHAIN", true));
        assert!(!should_remove("RUSTUP_TOOLCHAIN", false));
        for key in [
            "CARGO_HOME",
            "CARGO_NET_OFFLINE",
            "CARGO_TERM_COLOR",
            "PATH",
            "HOME",
        ] {
            assert!(!should_remove(key, true), "{key}");
        }
    }
}
