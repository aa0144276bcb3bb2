//! One software-in-the-loop run: what to run ([`SilConfig`]), setting it up
//! (QEMU, the plant, the output files), the lock-step loop
//! ([`super::session`]) and the summary ([`super::report`]).
//!
//! The run follows the board trial's protocol (`crate::board::protocol`):
//! a greedy test episode first, then learning, with the firmware's own test
//! episode after every tenth learning episode, until the learning time
//! reaches `--seconds`; then a final test episode. A fault stops the
//! firmware (torque off); once its window is over the run sends
//! `ClearFault` and `Start` again, as an operator would.

use super::bus::BusEmulator;
use super::fault::FaultSpec;
use super::power_cut::CutSpec;
use super::qemu::{Emulator, QemuSetup};
use super::report::SilSummary;
use super::session::Session;
use anyhow::{anyhow, Context};
use pada_core::policy::PolicyKind;
use pada_core::profile::{Board, LearnerProfile};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// The robots `pada sil` runs (the registry's, [`crate::robots`]).
pub use crate::robots::SilTask;

/// The QEMU machine that emulates `board`: netduinoplus2 (an STM32F405)
/// for `f405`, mps2-an386 (a Cortex-M4F with 16 MB of PSRAM standing in
/// for the DISC1's SDRAM) for `f429-sdram`; `None` for the host.
pub fn machine(board: Board) -> Option<&'static str> {
    match board {
        Board::F405 => Some("netduinoplus2"),
        Board::F429Sdram => Some("mps2-an386"),
        Board::Host => None,
    }
}

/// What to run.
#[derive(Debug, Clone)]
pub struct SilConfig {
    /// `qemu-system-arm`.
    pub qemu: PathBuf,
    /// The firmware image (built for `board`'s emulation and `task`'s
    /// robot).
    pub elf: PathBuf,
    /// The robot.
    pub task: SilTask,
    /// The board learner profile the image was built for.
    pub board: Board,
    /// The policy the run sets (`SetPolicy`) before starting.
    pub policy: PolicyKind,
    /// The wear governor's budget \[s\] (`SetMtbfBudget`, after the policy
    /// and before the first run), or none.
    pub mtbf_budget_s: Option<f32>,
    /// Learning time to reach \[s\].
    pub seconds: f64,
    /// The master seed (`pada run`'s: the board learns with
    /// `crate::seed::trial_seed(seed, 0)`).
    pub seed: u64,
    /// Faults to inject.
    pub faults: Vec<FaultSpec>,
    /// Power cuts (`--power-cut`).
    pub power_cuts: Vec<CutSpec>,
    /// Hangs of the control loop (`--fault hang:at=S`) \[s\].
    pub hangs_s: Vec<f64>,
    /// Learning time between checkpoint saves \[s\] (none: no saves).
    pub save_every_s: Option<f64>,
    /// Forecast the bus's answers (fewer exchanges, the same run).
    pub forecast: bool,
    /// Also run the firmware's controller on the host to compare with (the
    /// same trial of `pada run --board` for LEO; eight seeds for the
    /// pendulum).
    pub compare: bool,
    /// Where the telemetry, logs and summary go (created).
    pub out_dir: PathBuf,
    /// Longest wall-clock wait for the board before calling it hung.
    pub hang_timeout: Duration,
    /// Show a progress bar on stderr.
    pub progress: bool,
    /// Also stream the firmware's telemetry, as it comes, to a file or a
    /// loopback TCP listener.
    pub telemetry: Option<crate::telemetry::TelemetryTarget>,
}

impl SilConfig {
    /// The learner the image runs.
    pub fn profile(&self) -> LearnerProfile {
        self.board.profile(self.task.robot())
    }

    /// The seed of the board's learner.
    pub fn learner_seed(&self) -> u64 {
        crate::seed::trial_seed(self.seed, 0)
    }
}

/// Runs `cfg`; the summary is also written to `summary.json`.
pub fn run(cfg: &SilConfig) -> anyhow::Result<SilSummary> {
    let machine = machine(cfg.board).ok_or_else(|| anyhow!("board {} has no emulation: use f405 or f429-sdram", cfg.board.name()))?;
    std::fs::create_dir_all(&cfg.out_dir).with_context(|| format!("cannot create {}", cfg.out_dir.display()))?;
    let out = |name: &str| cfg.out_dir.join(name);
    let setup = QemuSetup {
        qemu: cfg.qemu.clone(),
        machine,
        elf: cfg.elf.clone(),
        defmt_log: out("firmware.defmt"),
        qemu_log: out("qemu.log"),
    };
    let started = Instant::now();
    let rig = cfg.task.rig()?;
    let bus = BusEmulator::new(rig.as_ref(), cfg.task.robot(), cfg.faults.clone()).map_err(|e| anyhow!(e))?;
    let sink = match &cfg.telemetry {
        Some(t) => Some(crate::telemetry::TelemetrySink::open(t).map_err(|e| anyhow!("{}", e.one_line()))?),
        None => None,
    };
    let emu = Emulator::start(&setup)?;
    let mut s = Session::new(cfg, emu, rig, bus, sink)?;
    let result = s.run_loop();
    let status = s.stop();
    s.flush()?;
    let wall_s = started.elapsed().as_secs_f64();
    decode_defmt(cfg, &setup);
    if let Err(e) = result {
        let how = status.map(|st| format!(" (QEMU {st})")).unwrap_or_default();
        return Err(e.context(format!(
            "SIL run stopped at {:.3} s emulated{how}; logs in {}",
            s.now_s(),
            cfg.out_dir.display()
        )));
    }
    let summary = s.summary(wall_s);
    let json = serde_json::to_string_pretty(&summary)?;
    crate::output::write_atomic(&out("summary.json"), json.as_bytes())?;
    Ok(summary)
}

/// `defmt-print` turns the firmware's binary log into text, if installed.
fn decode_defmt(cfg: &SilConfig, setup: &QemuSetup) {
    let Ok(input) = std::fs::File::open(&setup.defmt_log) else {
        return;
    };
    let Ok(output) = std::fs::File::create(cfg.out_dir.join("firmware.log")) else {
        return;
    };
    let ok = std::process::Command::new("defmt-print")
        .arg("-e")
        .arg(&cfg.elf)
        .stdin(input)
        .stdout(output)
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !ok {
        let _ = std::fs::write(
            cfg.out_dir.join("firmware.log"),
            format!(
                "defmt-print (cargo install defmt-print) was not found or failed; decode the log with\n  defmt-print -e {} < {}\n",
                cfg.elf.display(),
                setup.defmt_log.display()
            ),
        );
    }
}
