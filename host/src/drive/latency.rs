//! The USB adapter's latency timer. An FTDI adapter (the U2D2 is one)
//! holds received bytes until its buffer fills or its latency timer runs
//! out, 16 ms by default on Linux: every bus exchange then waits up to
//! 16 ms for its answer, and a 30 ms control period has no room for one
//! read and one write. At 1 ms it has (DESIGN: "At 1 ms a 30 ms period has
//! room"). Linux shows the timer at
//! `/sys/bus/usb-serial/devices/<tty>/latency_timer`.

use std::path::{Path, PathBuf};

/// What the check found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Latency {
    /// The timer \[ms\] and its sysfs file.
    Timer {
        /// Milliseconds.
        ms: u32,
        /// Where it is set.
        file: PathBuf,
    },
    /// The port is no USB serial adapter with a latency timer (a
    /// pseudo-terminal, a CDC-ACM board, another OS).
    None,
}

/// The latency timer above which a warning is given \[ms\].
pub const GOOD_MS: u32 = 2;

/// The latency timer of the adapter behind `port` (a symbolic link such as
/// /dev/serial/by-id/… is followed).
pub fn latency(port: &Path) -> Latency {
    let Ok(device) = std::fs::canonicalize(port) else { return Latency::None };
    let Some(name) = device.file_name().and_then(|n| n.to_str()) else { return Latency::None };
    let file = PathBuf::from("/sys/bus/usb-serial/devices").join(name).join("latency_timer");
    match std::fs::read_to_string(&file).ok().and_then(|s| s.trim().parse().ok()) {
        Some(ms) => Latency::Timer { ms, file },
        None => Latency::None,
    }
}

impl Latency {
    /// The timer in ms (0 without one).
    pub fn ms(&self) -> u32 {
        match self {
            Latency::Timer { ms, .. } => *ms,
            Latency::None => 0,
        }
    }

    /// A line for the user: what the timer is, and, if it is too long for
    /// a control period of `period_us`, how to set it.
    pub fn advice(&self, period_us: u32) -> String {
        match self {
            Latency::None => "latency timer: none (not a USB serial adapter)".to_string(),
            Latency::Timer { ms, file } if *ms <= GOOD_MS => format!("latency timer: {ms} ms ({})", file.display()),
            Latency::Timer { ms, file } => format!(
                "latency timer: {ms} ms ({}): each exchange may wait {ms} ms, {} of a {} ms period per read and write; set it to 1 ms: \
                 `echo 1 | sudo tee {}` (until the adapter is unplugged), or for good a udev rule: \
                 ACTION==\"add\", SUBSYSTEM==\"usb-serial\", DRIVER==\"ftdi_sio\", ATTR{{latency_timer}}=\"1\"",
                file.display(),
                if 2 * ms * 1000 >= period_us { "more than half" } else { "a large part" },
                period_us / 1000,
                file.display()
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pty_has_none_and_the_advice_says_how_to_set_one() {
        assert_eq!(latency(Path::new("/dev/null")), Latency::None);
        let t = Latency::Timer { ms: 16, file: PathBuf::from("/sys/bus/usb-serial/devices/ttyUSB0/latency_timer") };
        let a = t.advice(30_000);
        assert!(a.contains("16 ms") && a.contains("echo 1 | sudo tee /sys/bus/usb-serial/devices/ttyUSB0/latency_timer"), "{a}");
        assert!(Latency::Timer { ms: 1, file: PathBuf::new() }.advice(30_000).starts_with("latency timer: 1 ms"));
    }
}
