//! `cargo xtask test`: every test of pada, on a machine that starts with
//! rustup's stable Rust only. It is the README's test command, and `.ci/run`
//! calls it for its test phase, so a newcomer runs what CI runs.
//!
//! 1. **install**: `.ci/install` checks what the tests need beyond Rust
//!    (the firmware toolchain, QEMU 10, Chromium, Slurm and munge, python3
//!    with venv) and installs with apt what is missing, saying what and why.
//!    That script is the one place that knows the packages. The firmware
//!    toolchain is not asked for where rustup's thumbv7em target is
//!    installed ([`toolchain::detect`] then builds with it). Installing and
//!    starting the cluster need root; without it nothing runs: the one
//!    `sudo` line to run first is printed, exit code 2.
//! 2. **slurm**: the one-node cluster of `.ci/slurm` for the cluster tests,
//!    started unless one answers, stopped at the end if this run started it.
//! 3. **workspace**: `cargo test --workspace --no-fail-fast`.
//! 4. **firmware library**: the firmware's library tests on the host (the
//!    firmware is not a workspace member; `cargo xtask firmware-test`).
//! 5. **python**: the `pada` Python package in a virtual environment
//!    (target/test-python-venv), its wheel built in the workspace's target
//!    directory with the dev profile so that it reuses what phase 3 built,
//!    then `pytest python/tests` against target/debug/pada and the numpy
//!    example.
//!
//! The tests run with `CI=true`, the tests' own switch for "every tool is
//! provided": a test that would skip itself for a missing tool (the Slurm
//! tests, the Python tests' `pada` binary and packages) fails instead. The
//! QEMU and Chromium tests fail without their tool in any case. So a green
//! run means every test ran.
//!
//! Phases 3–5 each run even when an earlier one failed, so one run shows
//! every failure; the summary gives each phase's result and wall time.

use std::{
    env,
    ffi::OsStr,
    path::{Path, PathBuf},
    process::{Command, ExitCode},
    time::Instant,
};

use crate::toolchain::{self, Toolchain};

/// The components of `.ci/install`, in its order.
const COMPONENTS: [&str; 5] = ["firmware-toolchain", "qemu", "chromium", "slurm", "python"];

/// The Python packages the tests import beyond the wheel's own
/// dependencies: the build backend, the test runner, and what
/// python/tests/test_mcap.py reads and validates with (the `mcap` reader,
/// JSON Schema validation, a WebSocket client), and the ROBOTIS SDK that
/// python/tests/test_servos_sdk.py drives `pada servos` with (PyPI's
/// `dynamixel-sdk`, the vendor's own, not written from pada), and
/// python/tests/test_servos_feetech.py with Feetech's SDK as LeRobot
/// installs it (`feetech-servo-sdk`) and pollen-robotics' `rustypot`.
const PYTHON_PACKAGES: &[&str] = &["maturin", "numpy", "gymnasium", "pytest", "mcap", "jsonschema", "websockets", "dynamixel-sdk", "feetech-servo-sdk", "rustypot"];

struct Phase {
    name: &'static str,
    seconds: f64,
    result: Result<String, String>,
}

pub fn run(root: &Path) -> ExitCode {
    let started = Instant::now();
    println!("xtask test: every test of pada (load average at start: {})", load_average());
    let mut phases: Vec<Phase> = Vec::new();

    // 1. What the tests need.
    let components: Vec<&str> = match toolchain::detect() {
        Ok(Toolchain::Native { .. }) => {
            println!(
                "xtask test: rustup's {} target is installed: the firmware builds with it, Debian's toolchain is not needed",
                crate::TARGET
            );
            COMPONENTS.iter().copied().filter(|c| *c != "firmware-toolchain").collect()
        }
        _ => COMPONENTS.to_vec(),
    };
    let install = root.join(".ci").join("install");
    let slurm = root.join(".ci").join("slurm");
    let cluster = if is_root() {
        section("install what the tests need (.ci/install)");
        let t = Instant::now();
        let r = status(Command::new(&install).args(&components).current_dir(root));
        phases.push(Phase { name: "install (apt)", seconds: t.elapsed().as_secs_f64(), result: r.clone().map(|()| "ok".into()) });
        if let Err(e) = r {
            return finish(&phases, started, Some(format!(".ci/install failed ({e}); its output is above")));
        }

        // 2. The Slurm cluster, kept for the tests and stopped at the end.
        section("one-node Slurm cluster (.ci/slurm)");
        let t = Instant::now();
        let r = Cluster::start(root, &slurm);
        let result = match &r {
            Ok(c) if c.ours => Ok("started; stopped at the end".to_string()),
            Ok(_) => Ok("one already answered; left up".to_string()),
            Err(e) => Err(e.clone()),
        };
        phases.push(Phase { name: "slurm cluster", seconds: t.elapsed().as_secs_f64(), result });
        match r {
            Ok(c) => c,
            Err(e) => return finish(&phases, started, Some(e)),
        }
    } else {
        match without_root(root, &install, &slurm, &components) {
            Ok(c) => c,
            Err(code) => return code,
        }
    };

    // 3. The workspace.
    let cargo = env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    section("workspace tests (cargo test --workspace --no-fail-fast)");
    let t = Instant::now();
    let mut cmd = tool(root, &cargo, &cluster.conf);
    cmd.args(["test", "--workspace", "--no-fail-fast"]);
    let r = status(&mut cmd);
    phases.push(Phase { name: "workspace tests", seconds: t.elapsed().as_secs_f64(), result: r.map(|()| "ok".into()) });

    // 4. The firmware's library, on the host.
    section("firmware library tests (cargo xtask firmware-test)");
    let t = Instant::now();
    let r = crate::firmware_test(root);
    phases.push(Phase { name: "firmware library tests", seconds: t.elapsed().as_secs_f64(), result: r.map(|()| "ok".into()) });

    // 5. Python.
    section("python (pytest python/tests, the numpy example)");
    let t = Instant::now();
    let r = python(root, &cluster.conf);
    phases.push(Phase { name: "python", seconds: t.elapsed().as_secs_f64(), result: r.map(|()| "ok".into()) });

    drop(cluster);
    finish(&phases, started, None)
}

/// Not root: nothing can be installed or started, so everything must be
/// there already, the cluster included. If something is missing, prints
/// the one line that provides it and returns exit code 2 before any test
/// runs.
fn without_root(root: &Path, install: &Path, slurm: &Path, components: &[&str]) -> Result<Cluster, ExitCode> {
    section("what the tests need (.ci/install --check; not root, so nothing is installed)");
    let missing: Vec<&str> = components
        .iter()
        .copied()
        .filter(|c| status(Command::new(install).args(["--check", c]).current_dir(root)).is_err())
        .collect();
    let cluster_up = Command::new(slurm).arg("check").current_dir(root).status().is_ok_and(|s| s.success());
    if missing.is_empty() && cluster_up {
        let conf = slurm_conf(slurm).map_err(|e| {
            eprintln!("xtask test: {e}");
            ExitCode::FAILURE
        })?;
        println!("xtask test: a Slurm cluster answers ({}); it is left up", conf.display());
        return Ok(Cluster { slurm: slurm.into(), conf, ours: false });
    }
    let mut needs = Vec::new();
    let mut line = Vec::new();
    if !missing.is_empty() {
        needs.push(format!("installing {} (apt-get)", missing.join(", ")));
        line.push(format!("sudo {} {}", install.display(), missing.join(" ")));
    }
    if !cluster_up {
        needs.push("starting the one-node Slurm cluster of the cluster tests".to_string());
        line.push(format!("sudo {} up", slurm.display()));
    }
    eprintln!(
        "\nxtask test: not root, and the tests need root for {}. No test ran. Run first:\n\n  {}\n\n\
         then `cargo xtask test` again. (The cluster stays up for later runs; `sudo {} down` stops it.)",
        needs.join(" and "),
        line.join(" && "),
        slurm.display()
    );
    Err(ExitCode::from(2))
}

/// The cluster of `.ci/slurm`: `ours` if this run started it (then it is
/// stopped when this is dropped).
struct Cluster {
    slurm: PathBuf,
    conf: PathBuf,
    ours: bool,
}

impl Cluster {
    fn start(root: &Path, slurm: &Path) -> Result<Cluster, String> {
        let conf = slurm_conf(slurm)?;
        let answers = Command::new(slurm).arg("check").current_dir(root).status().is_ok_and(|s| s.success());
        if answers {
            // Someone's cluster (a run interrupted with Ctrl-C leaves its
            // own up too: the daemons are not in the terminal's process
            // group). Stopping it could pull it from under another run.
            println!(
                "xtask test: a Slurm cluster already answers ({}); using it and leaving it up (`{} down` stops it)",
                conf.display(),
                slurm.display()
            );
            return Ok(Cluster { slurm: slurm.into(), conf, ours: false });
        }
        status(Command::new(slurm).arg("up").current_dir(root)).map_err(|e| format!(".ci/slurm up failed ({e}); its output is above"))?;
        Ok(Cluster { slurm: slurm.into(), conf, ours: true })
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        if self.ours {
            section("stop the Slurm cluster (.ci/slurm down)");
            if let Err(e) = status(Command::new(&self.slurm).arg("down")) {
                eprintln!("xtask test: .ci/slurm down failed ({e}); stop the daemons by hand");
            }
        }
    }
}

/// SLURM_CONF of `.ci/slurm`'s cluster (`.ci/slurm env` prints it).
fn slurm_conf(slurm: &Path) -> Result<PathBuf, String> {
    let out = Command::new(slurm).arg("env").output().map_err(|e| format!("cannot run {}: {e}", slurm.display()))?;
    String::from_utf8_lossy(&out.stdout)
        .trim()
        .strip_prefix("export SLURM_CONF=")
        .map(PathBuf::from)
        .ok_or_else(|| format!("`{} env` did not print `export SLURM_CONF=…`", slurm.display()))
}

/// A command for the tests: the outer `cargo run`'s variables removed, run
/// from the repository, with CI=true (missing tools fail, not skip) and
/// the cluster's SLURM_CONF.
fn tool(root: &Path, program: impl AsRef<OsStr>, slurm_conf: &Path) -> Command {
    let mut cmd = Command::new(program);
    toolchain::clean_env(&mut cmd, false);
    cmd.current_dir(root).env("CI", "true").env("SLURM_CONF", slurm_conf);
    cmd
}

/// The Python package's tests in a virtual environment.
fn python(root: &Path, slurm_conf: &Path) -> Result<(), String> {
    let target = root.join("target");
    let venv = target.join("test-python-venv");
    let py = venv.join("bin").join("python");
    // Reused from an earlier run if its interpreter still starts.
    let healthy = Command::new(&py).args(["-c", ""]).status().is_ok_and(|s| s.success());
    if !healthy {
        let _ = std::fs::remove_dir_all(&venv);
        println!("xtask test: python3 -m venv {}", venv.display());
        status(Command::new("python3").arg("-m").arg("venv").arg(&venv))?;
        status(Command::new(&py).args(["-m", "pip", "install", "--quiet", "--upgrade", "pip"]))?;
    } else {
        println!("xtask test: reusing {}", venv.display());
    }
    println!("xtask test: pip install {}", PYTHON_PACKAGES.join(" "));
    status(Command::new(&py).args(["-m", "pip", "install", "--quiet"]).args(PYTHON_PACKAGES))?;
    // maturin builds the abi3 wheel with the dev profile, whose rapier3d
    // and math crates are optimised as in the workspace: a release build of
    // pada's dependencies alone takes longer than this phase may. It builds
    // in the workspace's target directory: python/ is not a workspace
    // member, but python/Cargo.toml has the workspace's dev profile and
    // python/Cargo.lock its versions, so the dependencies phase 3 built
    // (rapier3d, plotters, resvg, pada itself) are reused rather than
    // compiled again: from cold the wheel took 15 min on the loaded 2-core
    // development machine; reusing the workspace's build it compiles pyo3
    // and pada-python only (20 s after `cargo test --workspace`, 46 s when
    // pada itself is compiled again). The feature shims in tests/Cargo.toml
    // (syn, either) and python/Cargo.toml (serde, either) keep the two
    // builds' feature sets equal: without them the wheel compiled 47 crates
    // again, rapier3d and nalgebra among them (4 min 42 s).
    println!("xtask test: pip install ./python (maturin, dev profile, target directory {})", target.display());
    let mut cmd = tool(root, &py, slurm_conf);
    cmd.args(["-m", "pip", "install", "--quiet", "./python"])
        .env("CARGO_TARGET_DIR", &target)
        .env("MATURIN_PEP517_ARGS", "--profile dev");
    status(&mut cmd)?;
    // The tests compare with the `pada` command phase 3 built. -rs lists
    // any skip with its reason.
    let pada = target.join("debug").join("pada");
    println!("xtask test: pytest python/tests (PADA_BIN={})", pada.display());
    let mut cmd = tool(root, &py, slurm_conf);
    cmd.args(["-m", "pytest", "-q", "-rs", "-p", "no:cacheprovider", "python/tests"]).env("PADA_BIN", &pada);
    status(&mut cmd)?;
    println!("xtask test: python/examples/numpy_pada.py");
    let mut cmd = tool(root, &py, slurm_conf);
    cmd.arg("python/examples/numpy_pada.py").arg("--out").arg(target.join("test-python-example"));
    status(&mut cmd)
}

/// Runs `cmd`; Err names the command (program's file name and arguments)
/// and its exit status.
fn status(cmd: &mut Command) -> Result<(), String> {
    let name = Path::new(cmd.get_program()).file_name().unwrap_or(cmd.get_program()).to_string_lossy().into_owned();
    let program = std::iter::once(name)
        .chain(cmd.get_args().map(|a| a.to_string_lossy().into_owned()))
        .collect::<Vec<_>>()
        .join(" ");
    match cmd.status() {
        Ok(s) if s.success() => Ok(()),
        Ok(s) => Err(format!("{program}: {s}")),
        Err(e) => Err(format!("cannot start {program}: {e}")),
    }
}

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
}

fn section(title: &str) {
    println!("\n==================== xtask test: {title} ====================");
}

/// Prints the summary; the exit code is 1 if any phase failed or the run
/// stopped early (`stopped`).
fn finish(phases: &[Phase], started: Instant, stopped: Option<String>) -> ExitCode {
    section("summary");
    for p in phases {
        let result = match &p.result {
            Ok(s) => s.clone(),
            Err(e) => format!("FAILED: {e}"),
        };
        println!("  {:<24} {:>6.0} s  {result}", p.name, p.seconds);
    }
    println!("  {:<24} {:>6.0} s  (load average at the end: {})", "total", started.elapsed().as_secs_f64(), load_average());
    let failed: Vec<&str> = phases.iter().filter(|p| p.result.is_err()).map(|p| p.name).collect();
    if let Some(why) = stopped {
        eprintln!("xtask test: stopped before the tests: {why}");
        return ExitCode::FAILURE;
    }
    if failed.is_empty() {
        println!("xtask test: every phase passed");
        ExitCode::SUCCESS
    } else {
        eprintln!("xtask test: failed: {} (their output is above)", failed.join(", "));
        ExitCode::FAILURE
    }
}
