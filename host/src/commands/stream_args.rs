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
    /// Also record the stream as an MCAP file: every record kind on a
    /// channel of its own with its JSON Schema, the board's clock as log
    /// time, the robot drawn on /scene, pada's version and the
    /// configuration hash in its metadata (open it in Foxglove).
    #[arg(long, value_name = "FILE.mcap")]
    pub mcap: Option<PathBuf>,
    /// Serve the stream live in Foxglove's WebSocket protocol on this
    /// address (the channels of --mcap); connect the Foxglove app to
    /// ws://HOST:PORT. Port 0 picks a free one.
    #[arg(long, value_name = "tcp:HOST:PORT")]
    pub foxglove: Option<String>,
    /// Keep the board's streamed checkpoint at PATH (for a board whose
    /// table fits no flash: LEO on f429-sdram) and send it back when the
    /// board asks at boot (with --port; a recording only feeds the file).
    /// Only a complete checkpoint replaces the file, by an atomic rename.
    #[arg(long, value_name = "PATH")]
    pub checkpoint: Option<PathBuf>,
}

/// The `--mcap` file and the `--foxglove` server of a stream, opened.
pub struct Taps {
    /// The tap for the recorder, when either was asked for.
    pub tap: Option<crate::mcap::Tap>,
    /// The live server.
    pub server: Option<crate::foxglove::server::FoxgloveServer>,
}

impl Taps {
    /// Ends the live server (after the recorder closed its tap) and says
    /// on stderr what it served.
    pub fn close(self, command: &str) -> Option<crate::foxglove::server::LiveStats> {
        let server = self.server?;
        let addr = server.addr;
        let stats = server.close();
        crate::console::errln!(
            "{command}: foxglove server ws://{addr}: {} clients, {} messages sent, {} dropped",
            stats.clients,
            stats.sent,
            stats.dropped
        );
        Some(stats)
    }
}

impl StreamRecord {
    /// Checks `--seconds`.
    pub fn check(&self) -> Result<(), CliError> {
        match self.seconds {
            Some(s) if !(s.is_finite() && s > 0.0) => Err(usage(format!("--seconds {s} is out of range: valid is > 0"))),
            _ => Ok(()),
        }
    }

    /// Creates the `--mcap` file and starts the `--foxglove` server, if
    /// asked for (a bad path or address is a usage error).
    pub fn taps(&self, command: &str) -> Result<Taps, CliError> {
        let mut sinks: Vec<Box<dyn crate::mcap::ChannelSink>> = Vec::new();
        if let Some(p) = &self.mcap {
            if p.is_dir() {
                return Err(usage(format!("--mcap {}: is a directory; valid is a file to create", p.display())));
            }
            let f = crate::mcap::writer::McapFile::create(p)
                .map_err(|e| usage(format!("--mcap {}: cannot create: {e}", p.display())))?;
            sinks.push(Box::new(f));
        }
        let mut server = None;
        if let Some(spec) = &self.foxglove {
            let addr = crate::foxglove::parse_addr(spec).map_err(usage)?;
            let s = crate::foxglove::server::FoxgloveServer::start(addr)
                .map_err(|e| usage(format!("--foxglove {spec}: cannot listen: {e}")))?;
            crate::console::errln!("{command}: foxglove: ws://{} (Foxglove: Open connection, Foxglove WebSocket)", s.addr);
            if !s.addr.ip().is_loopback() {
                crate::console::errln!(
                    "{command}: warning: the live view is served on {} beyond this machine, without authentication",
                    s.addr.ip()
                );
            }
            sinks.push(s.sink());
            server = Some(s);
        }
        let tap = (!sinks.is_empty()).then(|| crate::mcap::Tap::new(sinks));
        Ok(Taps { tap, server })
    }

    /// The keeper of `--checkpoint`, if asked for (a directory, or a path
    /// in a directory that does not exist, is a usage error).
    pub fn keeper(&self) -> Result<Option<crate::checkpoint_keeper::KeeperLink>, CliError> {
        let Some(p) = &self.checkpoint else { return Ok(None) };
        if p.is_dir() {
            return Err(usage(format!("--checkpoint {}: is a directory; valid is a file to keep", p.display())));
        }
        let parent = p.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(std::path::Path::new("."));
        if !parent.is_dir() {
            return Err(usage(format!("--checkpoint {}: no directory {}", p.display(), parent.display())));
        }
        let link = crate::checkpoint_keeper::KeeperLink::new(p)
            .map_err(|e| usage(format!("--checkpoint {}: cannot use: {e}", p.display())))?;
        Ok(Some(link))
    }

    /// Creates the `--out` CSV, if one was asked for.
    pub fn csv(&self) -> Result<Option<Box<dyn Write + Send>>, CliError> {
        let Some(p) = &self.out else { return Ok(None) };
        let f = std::fs::File::create(p).map_err(|e| usage(format!("--out {}: cannot create: {e}", p.display())))?;
        Ok(Some(Box::new(std::io::BufWriter::new(f))))
    }
}
