//! The virtual servos' serial port: a pseudo-terminal whose slave a
//! symbolic link at the path the user gave names, so that any program
//! opens it as it opens a USB adapter (`/dev/ttyUSB0`): pada, the ROBOTIS
//! SDK through pyserial, the Dynamixel Wizard under Wine.
//!
//! The server keeps a slave descriptor open itself, so that clients may
//! open and close the port as often as they like (a pty's master reads an
//! error while no slave is open). The client's baud rate is the line's
//! termios speed, which the master reads as the slave's: a client at
//! another rate than the servos' gets no answer, as on a real bus.
//! Written in Rust with `rustix` (already the host's dependency for its
//! FIFOs), rather than through `socat`, so that `pada servos` needs
//! nothing installed.

use rustix::event::{poll, PollFd, PollFlags, Timespec};
use rustix::fs::{fcntl_getfl, fcntl_setfl, OFlags};
use rustix::pty::{grantpt, openpt, ptsname, unlockpt, OpenptFlags};
use rustix::termios::{tcgetattr, tcsetattr, OptionalActions};
use std::io;
use std::os::fd::OwnedFd;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// A pseudo-terminal behind a symbolic link.
pub struct Pty {
    master: OwnedFd,
    /// Keeps the line open while no client has it.
    _slave: std::fs::File,
    link: PathBuf,
    slave_path: String,
}

impl Pty {
    /// A raw pseudo-terminal at 1 Mbps (the clients set their own rate),
    /// linked at `link`. An existing file at `link` is replaced only if it
    /// is a symbolic link (a stale one of an earlier run), never a device
    /// or a regular file.
    pub fn create(link: &Path) -> io::Result<Pty> {
        if let Ok(meta) = std::fs::symlink_metadata(link) {
            if !meta.file_type().is_symlink() {
                return Err(io::Error::new(
                    io::ErrorKind::AlreadyExists,
                    format!("{} exists and is not a symbolic link; give a path for the virtual port", link.display()),
                ));
            }
        }
        let master = openpt(OpenptFlags::RDWR | OpenptFlags::NOCTTY | OpenptFlags::CLOEXEC)?;
        grantpt(&master)?;
        unlockpt(&master)?;
        let slave_path = ptsname(&master, Vec::new())?.into_string().map_err(|_| io::Error::other("pty name"))?;
        let slave = std::fs::OpenOptions::new().read(true).write(true).open(&slave_path)?;
        let mut t = tcgetattr(&slave)?;
        t.make_raw();
        t.set_speed(1_000_000)?;
        tcsetattr(&slave, OptionalActions::Now, &t)?;
        let flags = fcntl_getfl(&master)?;
        fcntl_setfl(&master, flags | OFlags::NONBLOCK)?;
        let tmp = link.with_extension("pada-new");
        let _ = std::fs::remove_file(&tmp);
        std::os::unix::fs::symlink(&slave_path, &tmp)?;
        std::fs::rename(&tmp, link)?;
        Ok(Pty { master, _slave: slave, link: link.to_path_buf(), slave_path })
    }

    /// The pseudo-terminal's own device (`/dev/pts/N`).
    pub fn device(&self) -> &str {
        &self.slave_path
    }

    /// The path the link has.
    pub fn link(&self) -> &Path {
        &self.link
    }

    /// The line's rate as the client set it \[bps\].
    pub fn line_bps(&self) -> u32 {
        tcgetattr(&self.master).map(|t| t.output_speed()).unwrap_or(0)
    }

    /// Waits at most `timeout` for bytes from the client; 0 if none came.
    pub fn read(&self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        let mut fds = [PollFd::new(&self.master, PollFlags::IN)];
        let ts = Timespec { tv_sec: timeout.as_secs() as i64, tv_nsec: timeout.subsec_nanos() as i64 };
        match poll(&mut fds, Some(&ts)) {
            Ok(0) => return Ok(0),
            Ok(_) => {}
            Err(rustix::io::Errno::INTR) => return Ok(0),
            Err(e) => return Err(e.into()),
        }
        match rustix::io::read(&self.master, buf) {
            Ok(n) => Ok(n),
            Err(rustix::io::Errno::AGAIN | rustix::io::Errno::INTR) => Ok(0),
            Err(e) => Err(e.into()),
        }
    }

    /// Writes what the line takes now; returns how many bytes (a client
    /// that does not read fills the line, and the rest waits).
    pub fn write(&self, bytes: &[u8]) -> io::Result<usize> {
        match rustix::io::write(&self.master, bytes) {
            Ok(n) => Ok(n),
            Err(rustix::io::Errno::AGAIN | rustix::io::Errno::INTR) => Ok(0),
            Err(e) => Err(e.into()),
        }
    }
}

impl Drop for Pty {
    /// The link goes with the port (if it is still ours).
    fn drop(&mut self) {
        if std::fs::read_link(&self.link).is_ok_and(|target| target.as_os_str() == self.slave_path.as_str()) {
            let _ = std::fs::remove_file(&self.link);
        }
    }
}
