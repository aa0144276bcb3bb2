//! `--telemetry FILE|tcp:HOST:PORT`: the host's runs stream the same wire
//! frames the firmware sends (`pada_core::wire`: postcard, CRC-32, COBS),
//! so one capture path (`pada capture --file`, or anything that reads a
//! board's serial port) serves simulation, emulation and hardware.
//!
//! `pada run` streams trial 0: a `Hello`, then for every agent call a
//! `Step` (start, step, time-limit or absorbing end, with the observation,
//! reward, action, output, TD error and the fatigue of the learned joints)
//! and an `Episode` at every episode's end, as the firmware does. `pada
//! sil` forwards the firmware's own stream.
//!
//! TCP goes to the loopback interface only (a collector on this machine):
//! the stream is neither authenticated nor encrypted.

use crate::error::{usage, CliError};
use pada_core::wire::{FrameEncoder, ToHost, MAX_FRAME_LEN};
use std::io::Write;
use std::net::{SocketAddr, TcpStream, ToSocketAddrs};
use std::path::PathBuf;
use std::time::Duration;

/// Where the frames go.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum TelemetryTarget {
    /// A file (created or truncated).
    File(PathBuf),
    /// A TCP listener on the loopback interface.
    Tcp(SocketAddr),
}

/// Parses `FILE` or `tcp:HOST:PORT`; a non-loopback host is refused.
pub fn parse_target(spec: &str) -> Result<TelemetryTarget, CliError> {
    let Some(addr) = spec.strip_prefix("tcp:") else {
        if spec.is_empty() {
            return Err(usage("--telemetry needs FILE or tcp:HOST:PORT"));
        }
        return Ok(TelemetryTarget::File(PathBuf::from(spec)));
    };
    let addrs: Vec<SocketAddr> = addr
        .to_socket_addrs()
        .map_err(|e| usage(format!("--telemetry {spec}: not a HOST:PORT ({e})")))?
        .collect();
    match addrs.iter().find(|a| a.ip().is_loopback()) {
        Some(a) if addrs.iter().all(|a| a.ip().is_loopback()) => Ok(TelemetryTarget::Tcp(*a)),
        _ => Err(usage(format!(
            "--telemetry {spec}: only the loopback interface is allowed (127.0.0.1, ::1, localhost); \
             the stream is not authenticated"
        ))),
    }
}

/// Buffered frames are pushed out at least this often, so that a live
/// viewer (`pada watch --listen`) sees a slow run as it goes rather than in
/// 8 KiB bursts seconds apart.
pub const FLUSH_EVERY: Duration = Duration::from_millis(100);

/// An open telemetry stream. Write errors end the stream (the run goes on)
/// and are reported by [`TelemetrySink::finish`].
pub struct TelemetrySink {
    last_flush: std::time::Instant,
    out: Box<dyn Write + Send>,
    encoder: FrameEncoder,
    frames: u64,
    bytes: u64,
    error: Option<String>,
    target: String,
}

impl TelemetrySink {
    /// Opens the target (connects, for TCP).
    pub fn open(target: &TelemetryTarget) -> Result<TelemetrySink, CliError> {
        let (out, name): (Box<dyn Write + Send>, String) = match target {
            TelemetryTarget::File(p) => {
                let f = std::fs::File::create(p).map_err(|e| {
                    usage(format!("--telemetry {}: cannot create: {e}", p.display()))
                })?;
                (
                    Box::new(std::io::BufWriter::new(f)),
                    p.display().to_string(),
                )
            }
            TelemetryTarget::Tcp(a) => {
                let s = TcpStream::connect_timeout(a, Duration::from_secs(5))
                    .map_err(|e| usage(format!("--telemetry tcp:{a}: cannot connect: {e}")))?;
                let _ = s.set_nodelay(true);
                (Box::new(std::io::BufWriter::new(s)), format!("tcp:{a}"))
            }
        };
        Ok(TelemetrySink::to_writer(out, name))
    }

    /// A stream into `out`, named `target` in its totals and errors.
    pub fn to_writer(out: Box<dyn Write + Send>, target: String) -> TelemetrySink {
        TelemetrySink {
            last_flush: std::time::Instant::now(),
            out,
            encoder: FrameEncoder::new(),
            frames: 0,
            bytes: 0,
            error: None,
            target,
        }
    }

    /// Frames one message (numbered as the firmware numbers its frames).
    pub fn send(&mut self, msg: &ToHost) {
        if self.error.is_some() {
            return;
        }
        let mut buf = [0u8; MAX_FRAME_LEN];
        match self.encoder.encode(msg, &mut buf) {
            Ok(frame) => {
                let n = frame.len() as u64;
                if let Err(e) = self.out.write_all(frame) {
                    self.error = Some(e.to_string());
                } else {
                    self.frames += 1;
                    self.bytes += n;
                    self.flush_now_and_then();
                }
            }
            Err(e) => self.error = Some(format!("cannot encode a frame: {e:?}")),
        }
    }

    /// Passes bytes through as they are (another sender's frames).
    pub fn forward(&mut self, bytes: &[u8]) {
        if self.error.is_some() {
            return;
        }
        match self.out.write_all(bytes) {
            Ok(()) => {
                self.bytes += bytes.len() as u64;
                self.flush_now_and_then();
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    /// Flushes when [`FLUSH_EVERY`] has passed since the last flush.
    fn flush_now_and_then(&mut self) {
        if self.last_flush.elapsed() >= FLUSH_EVERY {
            self.last_flush = std::time::Instant::now();
            if let Err(e) = self.out.flush() {
                self.error = Some(e.to_string());
            }
        }
    }

    /// Flushes; an error if any write failed.
    pub fn finish(mut self) -> anyhow::Result<TelemetryTotals> {
        if self.error.is_none() {
            if let Err(e) = self.out.flush() {
                self.error = Some(e.to_string());
            }
        }
        match self.error {
            None => Ok(TelemetryTotals {
                frames: self.frames,
                bytes: self.bytes,
                target: self.target,
            }),
            Some(e) => Err(anyhow::anyhow!(
                "the telemetry stream to {} failed after {} frames ({} bytes): {e}",
                self.target,
                self.frames,
                self.bytes
            )),
        }
    }
}

/// What a stream carried.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TelemetryTotals {
    /// Frames written (0 for forwarded streams).
    pub frames: u64,
    /// Bytes written.
    pub bytes: u64,
    /// Where.
    pub target: String,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn targets() {
        assert_eq!(
            parse_target("run.bin").unwrap(),
            TelemetryTarget::File("run.bin".into())
        );
        assert!(
            matches!(parse_target("tcp:127.0.0.1:9000").unwrap(), TelemetryTarget::Tcp(a) if a.port() == 9000)
        );
        assert!(matches!(
            parse_target("tcp:[::1]:9000").unwrap(),
            TelemetryTarget::Tcp(_)
        ));
        assert!(matches!(
            parse_target("tcp:localhost:9000"),
            Ok(TelemetryTarget::Tcp(_))
        ));
        for bad in [
            "tcp:10.0.0.1:9000",
            "tcp:8.8.8.8:53",
            "tcp:127.0.0.1",
            "tcp:",
            "",
        ] {
            let e = parse_target(bad).unwrap_err();
            assert_eq!(e.exit_code(), 2, "{bad}");
        }
    }
}
