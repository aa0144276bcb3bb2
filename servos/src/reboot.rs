//! `pada servos --reboot ID --port DEVICE`: a Protocol 2.0 REBOOT of one
//! servo, the one way short of its power out of a hardware-error shutdown.
//!
//! An X-series servo that raises its Alert bit (overload, overheating, an
//! input voltage out of range, …) latches the cause in Hardware Error
//! Status and, per its Shutdown setting, switches its own torque off; it
//! refuses torque until rebooted (docs/reference/dynamixel.md, "Shutdown").
//! `pada drive` stops at the alert and names this command. The REBOOT's
//! status comes before the servo restarts; the servo is then PINGed until
//! it answers, and its Alert bit read once more.

use super::scan::{listen, send};
use pada_core::dynamixel::control_table::x_series;
use pada_core::dynamixel::v2::{self as dxl2, PingReply};
use serde::Serialize;
use std::path::Path;
use std::time::{Duration, Instant};

/// How long a rebooted servo may take to answer a PING again.
const BOOT_WAIT: Duration = Duration::from_secs(2);

/// A servo after its REBOOT.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Rebooted {
    /// Its ID.
    pub id: u8,
    /// Its Model Number (the PING after the boot).
    pub model_number: u16,
    /// Its Hardware Error Status before the REBOOT (0 if it read none).
    pub hardware_error_before: u8,
    /// Whether the Alert bit is still set after the boot (the cause
    /// persists: still too hot, the supply still out of range).
    pub alert_after: bool,
}

/// Reboots servo `id` on the port at `path` at `baud`; `timeout` is one
/// answer's wait. The error is one line for the user.
pub fn reboot(path: &Path, baud: u32, id: u8, timeout: Duration) -> Result<Rebooted, String> {
    let io = |e: std::io::Error| format!("--port {}: {e}", path.display());
    let mut port = serialport::new(path.to_string_lossy(), baud).timeout(Duration::from_millis(1)).open().map_err(|e| io(e.into()))?;
    let port = port.as_mut();
    let mut ask = |bytes: &[u8]| -> Result<Option<dxl2::StatusPacket<64>>, String> {
        send(port, bytes).map_err(io)?;
        let got = listen(port, timeout).map_err(io)?;
        let mut dec: dxl2::StatusDecoder<64> = dxl2::StatusDecoder::new();
        Ok(dec.feed(&got).flatten().find(|p| p.id == id))
    };
    let mut tx = [0u8; 32];
    let no_answer = || {
        format!("servo {id} does not answer at {baud} bps on Protocol 2.0 (a wrong ID or baud rate, no power?): `pada servos --scan --port PORT` lists what answers")
    };
    let read_error = dxl2::encoders::read(id, x_series::HARDWARE_ERROR_STATUS, 1, &mut tx).map_err(|e| format!("{e:?}"))?.to_vec();
    let before = ask(&read_error)?.ok_or_else(no_answer)?;
    let hardware_error_before = before.u8_at(0).unwrap_or(0);
    // A servo at Status Return Level 0 or 1 (pada's set-up leaves 1: PING
    // and READ only) sends no status for a REBOOT; one that does may refuse.
    let reboot = dxl2::encoders::reboot(id, &mut tx).map_err(|e| format!("{e:?}"))?.to_vec();
    if let Some(status) = ask(&reboot)? {
        if !status.error.succeeded() {
            return Err(format!("servo {id} refused the REBOOT: error number {}", status.error.number_raw()));
        }
    }
    let ping = dxl2::encoders::ping(id, &mut tx).map_err(|e| format!("{e:?}"))?.to_vec();
    let since = Instant::now();
    let model_number = loop {
        if let Some(p) = ask(&ping)? {
            break PingReply::from_params(&p.params)
                .ok_or_else(|| format!("servo {id} answered the PING after its REBOOT without a model number"))?
                .model_number;
        }
        if since.elapsed() > BOOT_WAIT {
            return Err(format!("servo {id} did not answer a PING within {} s of its REBOOT", BOOT_WAIT.as_secs()));
        }
    };
    let after = ask(&read_error)?.ok_or_else(|| format!("servo {id} answered the PING after its REBOOT but not the READ of its Hardware Error Status"))?;
    Ok(Rebooted { id, model_number, hardware_error_before, alert_after: after.error.alert() || after.u8_at(0).unwrap_or(0) != 0 })
}
