//! The arguments that `pada capture` and `pada watch` share, with their
//! checks: where the telemetry comes from (a serial port or a recorded
//! stream) and what is kept of it (a CSV of every frame, a time limit, the
//! summary as JSON).

use crate::error::{usage, CliError};
use crate::serial_link::SerialLink;
use clap::Args;
use std::io::{Read, Write};
use std::path::PathBuf;

/// The highest baud rate a USB serial adapter is asked for.
const MAX_BAUD: u32 = 12_000_000;

/// Where telemetry comes from.
#[derive(Debug, Clone, Args)]
pub struct StreamInput {
    /// A serial port with a board on it (e.g. /dev/ttyUSB0, /dev/ttyACM0).
    #[arg(long, value_name = "DEVICE")]
    pub port: Option<PathBuf>,
    /// A recorded byte stream (a board's raw output, `pada run --telemetry
    /// FILE`, `pada sil`'s telemetry.bin); `-` reads standard input.
    #[arg(long, value_name = "FILE")]
    pub file: Option<PathBuf>,
    /// The port's baud rate.
    #[arg(long, value_name = "B", default_value_t = 921_600)]
    pub baud: u32,
}

/// An opened input.
pub enum Opened {
    /// A serial port, reopened when it goes away and comes back.
    Port(SerialLink),
    /// A file or standard input.
    Reader(Box<dyn Read + Send>),
}

impl StreamInput {
    /// Checks the baud rate.
    pub fn check(&self) -> Result<(), CliError> {
        if self.baud == 0 || self.baud > MAX_BAUD {
            return Err(usage(format!("--baud {} is out of range: valid is 1..={MAX_BAUD}", self.baud)));
        }
        Ok(())
    }

    /// Opens `--port` or `--file`, with the input's name for the summary;
    /// `None` when neither was given.
    pub fn open(&self) -> Result<Option<(Opened, String)>, CliError> {
        if let Some(port) = &self.port {
            let p = SerialLink::open(port, self.baud)
                .map_err(|e| usage(format!("--port {}: cannot open: {e}", port.display())))?;
            return Ok(Some((Opened::Port(p), port.display().to_string())));
        }
        let Some(file) = &self.file else { return Ok(None) };
        if file.as_os_str() == "-" {
            return Ok(Some((Opened::Reader(Box::new(std::io::stdin())), "standard input".to_string())));
        }
        if file.is_dir() {
            return Err(usage(format!(
                "--file {}: is a directory; valid is a recorded stream file or - for standard input",
                file.display()
            )));
        }
        let f = std::fs::File::open(file).map_err(|e| usage(format!("--file {}: cannot open: {e}", file.display())))?;
        Ok(Some((Opened::Reader(Box::new(f)), file.display().to_string())))
    }
}

/// What is kept of the stream.
#[derive(Debug, Clone, Args)]
pub struct StreamRecord {
    /// Write every frame, lost frame and sequence gap as a CSV row.
    #[arg(long, value_name = "FILE.csv")]
    pub out: Option<PathBuf>,
    /// Stop after this many wall-clock seconds.
    #[arg(long, value_name = "S")]
    pub seconds: Option<f64>,
    /// Print the final summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

impl StreamRecord {
    /// Checks `--seconds`.
    pub fn check(&self) -> Result<(), CliError> {
        match self.seconds {
            Some(s) if !(s.is_finite() && s > 0.0) => Err(usage(format!("--seconds {s} is out of range: valid is > 0"))),
            _ => Ok(()),
        }
    }

    /// Creates the `--out` CSV, if one was asked for.
    pub fn csv(&self) -> Result<Option<Box<dyn Write + Send>>, CliError> {
        let Some(p) = &self.out else { return Ok(None) };
        let f = std::fs::File::create(p).map_err(|e| usage(format!("--out {}: cannot create: {e}", p.display())))?;
        Ok(Some(Box::new(std::io::BufWriter::new(f))))
    }
}
