//! `pada run --mcap FILE`: the messages a run streams recorded as MCAP
//! through the same path as `pada capture --mcap`: a
//! [`TelemetrySink`] frames each message as the firmware frames it, into a
//! [`Recorder`] that decodes the frames and hands them to its tap, so a
//! run's recording and a capture of its `--telemetry` stream are the same
//! file.

use super::writer::McapFile;
use super::Tap;
use crate::capture::Recorder;
use crate::error::{usage, CliError};
use crate::telemetry::TelemetrySink;
use pada_core::wire::ToHost;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// Bytes written here are decoded by the recorder.
struct Feed(Arc<Mutex<Recorder>>);

impl Write for Feed {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        let mut frames = Vec::new();
        self.0.lock().unwrap_or_else(|e| e.into_inner()).feed(bytes, 0.0, &mut frames)?;
        Ok(bytes.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// A run's telemetry on its way into an MCAP file.
pub struct McapTee {
    sink: TelemetrySink,
    recorder: Arc<Mutex<Recorder>>,
    path: PathBuf,
}

impl McapTee {
    /// Creates the file (a bad path is a usage error naming `flag`).
    pub fn create(path: &Path, flag: &str) -> Result<McapTee, CliError> {
        if path.is_dir() {
            return Err(usage(format!("{flag} {}: is a directory; valid is a file to create", path.display())));
        }
        let file =
            McapFile::create(path).map_err(|e| usage(format!("{flag} {}: cannot create: {e}", path.display())))?;
        let mut recorder = Recorder::new(None).map_err(|e| CliError::Runtime(e.into()))?;
        recorder.set_tap(Tap::new(vec![Box::new(file)]));
        let recorder = Arc::new(Mutex::new(recorder));
        let sink = TelemetrySink::to_writer(Box::new(Feed(recorder.clone())), path.display().to_string());
        Ok(McapTee { sink, recorder, path: path.to_path_buf() })
    }

    /// Records one message.
    pub fn send(&mut self, msg: &ToHost) {
        self.sink.send(msg);
    }

    /// Closes the file (its summary and metadata); an error if any write
    /// failed. Returns the frames recorded and the file.
    pub fn finish(self) -> anyhow::Result<(u64, PathBuf)> {
        let totals = self.sink.finish()?;
        let closed = {
            let mut rec = self.recorder.lock().unwrap_or_else(|e| e.into_inner());
            // A checkpoint transfer cut short by the end gets its message.
            rec.end().and_then(|()| rec.close_tap())
        };
        closed.map_err(|e| anyhow::anyhow!("the MCAP file {} failed: {e}", self.path.display()))?;
        Ok((totals.frames, self.path))
    }
}
