//! `pada run --mcap FILE`: the messages a run streams (`--telemetry`'s
//! frames) recorded as MCAP through the same path as `pada capture
//! --mcap`: each message framed as the firmware frames it, decoded by a
//! [`Recorder`] and handed to its tap, so a run's recording and a capture
//! of its `--telemetry` stream are the same file.

use super::writer::McapFile;
use super::Tap;
use crate::capture::Recorder;
use crate::error::{usage, CliError};
use pada_core::wire::{FrameEncoder, ToHost, MAX_FRAME_LEN};
use std::path::{Path, PathBuf};

/// A run's telemetry on its way into an MCAP file.
pub struct McapTee {
    encoder: FrameEncoder,
    recorder: Recorder,
    path: PathBuf,
    error: Option<String>,
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
        Ok(McapTee { encoder: FrameEncoder::new(), recorder, path: path.to_path_buf(), error: None })
    }

    /// Records one message.
    pub fn send(&mut self, msg: &ToHost) {
        if self.error.is_some() {
            return;
        }
        let mut buf = [0u8; MAX_FRAME_LEN];
        match self.encoder.encode(msg, &mut buf) {
            Ok(frame) => {
                let mut frames = Vec::new();
                if let Err(e) = self.recorder.feed(frame, 0.0, &mut frames) {
                    self.error = Some(e.to_string());
                }
            }
            Err(e) => self.error = Some(format!("cannot encode a frame: {e:?}")),
        }
    }

    /// Closes the file: its summary and metadata; an error if any write
    /// failed. Returns the messages recorded.
    pub fn finish(mut self) -> anyhow::Result<(u64, PathBuf)> {
        let closed = self.recorder.close_tap();
        if let Some(e) = self.error {
            anyhow::bail!("the MCAP file {} failed: {e}", self.path.display());
        }
        closed.map_err(|e| anyhow::anyhow!("the MCAP file {} failed: {e}", self.path.display()))?;
        Ok((self.recorder.stats().frames as u64, self.path))
    }
}
