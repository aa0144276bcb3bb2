//! The PC's servo bus: a serial port (a USB adapter such as the U2D2, or
//! a pseudo-terminal) behind the firmware's own `BusPort`, so that the
//! firmware's bus transactions (`pada_firmware::bus`) run on the PC as
//! they run on the chip. On the chip they await a UART; here the port
//! blocks, so each future is ready when first polled ([`block_on`]).
//!
//! The port notes when it goes away (an adapter pulled, a pseudo-terminal
//! closed): every later operation fails at once, and the driver asks
//! [`SerialBusPort::gone`] after each period.

use pada_firmware::io::{BusPort, PortError};
use std::io::{Read, Write};
use std::path::Path;
use std::time::{Duration, Instant};

/// A serial port as the firmware's bus port.
pub struct SerialBusPort {
    port: Box<dyn serialport::SerialPort>,
    start: Instant,
    gone: Option<String>,
    /// Bytes sent and received, for the bus-time report.
    pub bytes_out: u64,
    /// Bytes received.
    pub bytes_in: u64,
}

impl SerialBusPort {
    /// Opens `path` at `baud` (8N1, raw).
    pub fn open(path: &Path, baud: u32) -> Result<SerialBusPort, String> {
        check_access(path)?;
        let port = serialport::new(path.to_string_lossy(), baud)
            .timeout(Duration::from_millis(1))
            .open()
            .map_err(|e| format!("--port {}: cannot open at {baud} bps: {e}", path.display()))?;
        Ok(SerialBusPort { port, start: Instant::now(), gone: None, bytes_out: 0, bytes_in: 0 })
    }

    /// Why the port went away, if it did.
    pub fn gone(&self) -> Option<&str> {
        self.gone.as_deref()
    }

    fn lost(&mut self, e: std::io::Error) -> PortError {
        if self.gone.is_none() {
            self.gone = Some(e.to_string());
        }
        PortError::Line
    }
}

impl BusPort for SerialBusPort {
    fn discard_input(&mut self) {
        if self.gone.is_none() {
            let _ = self.port.clear(serialport::ClearBuffer::Input);
        }
    }

    async fn send(&mut self, bytes: &[u8]) -> Result<(), PortError> {
        if self.gone.is_some() {
            return Err(PortError::Transmit);
        }
        match self.port.write_all(bytes).and_then(|()| self.port.flush()) {
            Ok(()) => {
                self.bytes_out += bytes.len() as u64;
                Ok(())
            }
            Err(e) => Err(self.lost(e)),
        }
    }

    async fn receive(&mut self, buf: &mut [u8], deadline_us: u64) -> Result<usize, PortError> {
        if self.gone.is_some() {
            return Err(PortError::Line);
        }
        let now = self.now_us();
        if now >= deadline_us {
            return Ok(0);
        }
        let _ = self.port.set_timeout(Duration::from_micros(deadline_us - now));
        match self.port.read(buf) {
            Ok(0) => Err(self.lost(std::io::Error::new(std::io::ErrorKind::UnexpectedEof, "the port closed"))),
            Ok(n) => {
                self.bytes_in += n as u64;
                Ok(n)
            }
            Err(e) if matches!(e.kind(), std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted | std::io::ErrorKind::WouldBlock) => Ok(0),
            Err(e) => Err(self.lost(e)),
        }
    }

    fn now_us(&self) -> u64 {
        self.start.elapsed().as_micros() as u64
    }
}

/// Runs a future of the firmware's bus to completion. Its port blocks, so
/// the future is ready at its first poll; a pending one is polled again
/// (it cannot be woken by anything else). Written here rather than taken
/// from an executor crate: ten lines with `Waker::noop`.
pub fn block_on<F: std::future::Future>(f: F) -> F::Output {
    let mut f = std::pin::pin!(f);
    let mut cx = std::task::Context::from_waker(std::task::Waker::noop());
    loop {
        if let std::task::Poll::Ready(v) = f.as_mut().poll(&mut cx) {
            return v;
        }
    }
}

/// Whether this user may open `path`: a missing device, or one of the
/// `dialout` group on Linux that the user is not in, is said in one line
/// with what to do.
pub fn check_access(path: &Path) -> Result<(), String> {
    let meta = std::fs::metadata(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => format!(
            "--port {}: no such device; is the adapter plugged in? (ls /dev/ttyUSB* /dev/ttyACM* /dev/serial/by-id/ lists them)",
            path.display()
        ),
        _ => format!("--port {}: {e}", path.display()),
    })?;
    match std::fs::OpenOptions::new().read(true).write(true).open(path) {
        Ok(_) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::PermissionDenied => {
            use std::os::unix::fs::MetadataExt;
            let group = group_name(meta.gid()).unwrap_or_else(|| format!("group {}", meta.gid()));
            Err(format!(
                "--port {}: permission denied; the device belongs to the {group} group: `sudo usermod -aG {group} $USER`, then log out and in (or run `newgrp {group}`)",
                path.display()
            ))
        }
        Err(e) => Err(format!("--port {}: cannot open: {e}", path.display())),
    }
}

/// The name of group `gid` from /etc/group.
fn group_name(gid: u32) -> Option<String> {
    let groups = std::fs::read_to_string("/etc/group").ok()?;
    groups.lines().find_map(|l| {
        let mut f = l.split(':');
        let name = f.next()?;
        let id: u32 = f.nth(1)?.parse().ok()?;
        (id == gid).then(|| name.to_string())
    })
}
