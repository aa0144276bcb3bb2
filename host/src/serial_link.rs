//! A board's serial port that may go away and come back: a USB serial
//! adapter pulled and plugged in again, a pseudo-terminal closed and
//! opened again at the same path (a udev symlink such as
//! `/dev/serial/by-id/…` points at the new device). `pada capture --port`
//! and `pada watch --port` read through it: when the device disappears
//! they keep running, try to open the same path again every
//! [`RETRY`], count the disconnect, and read on once it is back. What the
//! board sent while nothing was connected is lost; the decoder counts the
//! frame the disconnect cut short as lost, and the frames that never came
//! as a sequence gap. [`SerialLink::write_all`] answers the board on the
//! same port (a restore's chunks).

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// How long a read waits for bytes (the callers look at Ctrl-C this often).
pub const POLL: Duration = Duration::from_millis(100);
/// How often a disconnected port is tried again.
pub const RETRY: Duration = Duration::from_millis(200);

/// What one [`SerialLink::read`] brought.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum LinkEvent {
    /// Bytes, at the front of the buffer.
    Data(usize),
    /// Nothing within [`POLL`] (or still disconnected).
    Nothing,
    /// The device went away (why).
    Lost(String),
    /// The device is back.
    Back,
}

/// A serial port, reopened after it goes away.
pub struct SerialLink {
    path: PathBuf,
    baud: u32,
    port: Option<Box<dyn serialport::SerialPort>>,
    retry_at: Instant,
    disconnects: u32,
}

fn open(path: &Path, baud: u32) -> serialport::Result<Box<dyn serialport::SerialPort>> {
    serialport::new(path.to_string_lossy(), baud).timeout(POLL).open()
}

impl SerialLink {
    /// Opens `path` at `baud`; the first open must succeed.
    pub fn open(path: &Path, baud: u32) -> serialport::Result<SerialLink> {
        let port = open(path, baud)?;
        Ok(SerialLink { path: path.to_path_buf(), baud, port: Some(port), retry_at: Instant::now(), disconnects: 0 })
    }

    /// Times the device went away.
    pub fn disconnects(&self) -> u32 {
        self.disconnects
    }

    /// Whether the device is open now.
    pub fn connected(&self) -> bool {
        self.port.is_some()
    }

    /// Writes `bytes` to the board, waiting at most about [`POLL`] for room
    /// at a time. A port that is not open now (gone, not back yet) is an
    /// error of kind `NotConnected`; a failed write leaves the port as it
    /// is: the next [`read`](Self::read) notices that it went away.
    pub fn write_all(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        let Some(port) = self.port.as_mut() else {
            return Err(std::io::Error::new(
                std::io::ErrorKind::NotConnected,
                format!("{} is not connected", self.path.display()),
            ));
        };
        port.write_all(bytes)
    }

    /// Reads what is there, waits at most about [`POLL`].
    pub fn read(&mut self, buf: &mut [u8]) -> LinkEvent {
        let Some(port) = self.port.as_mut() else {
            let now = Instant::now();
            if now < self.retry_at {
                std::thread::sleep((self.retry_at - now).min(POLL));
                return LinkEvent::Nothing;
            }
            return match open(&self.path, self.baud) {
                Ok(p) => {
                    self.port = Some(p);
                    LinkEvent::Back
                }
                Err(_) => {
                    self.retry_at = Instant::now() + RETRY;
                    LinkEvent::Nothing
                }
            };
        };
        let why = match port.read(buf) {
            Ok(0) => "the port closed".to_string(),
            Ok(n) => return LinkEvent::Data(n),
            Err(e) if matches!(e.kind(), std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted) => {
                return LinkEvent::Nothing
            }
            Err(e) => format!("the port went away ({e})"),
        };
        self.port = None;
        self.disconnects += 1;
        self.retry_at = Instant::now() + RETRY;
        LinkEvent::Lost(why)
    }
}
