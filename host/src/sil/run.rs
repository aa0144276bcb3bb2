//! One software-in-the-loop run: what to run ([`SilConfig`], in
//! [`super::config`]), setting it up
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
use super::config::{machine, SilConfig};
use super::qemu::{Emulator, QemuSetup};
use super::report::SilSummary;
use super::session::Session;
use anyhow::{anyhow, Context};
use std::time::Instant;

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
