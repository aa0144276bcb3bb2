//! The partial file a stream is written into, and its atomic commit: a
//! checkpoint reaches its path whole or not at all.

use std::fs::{self, File};
use std::io::{self, BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use pada_core::checkpoint::stream::ImageSink;

/// An image being received into `PATH.partial`, opened at its first write.
#[derive(Debug)]
pub struct FileSink {
    path: PathBuf,
    len: u64,
    file: Option<BufWriter<File>>,
    pos: u64,
}

impl FileSink {
    /// A sink for an image of `len` bytes at `path` (nothing is created
    /// until the first write, so a refused first chunk leaves no file).
    pub fn new(path: PathBuf, len: u64) -> Self {
        FileSink { path, len, file: None, pos: 0 }
    }

    /// The file, created at its full length on the first write: a new
    /// file (an older partial one is unlinked first, so a stream abandoned
    /// mid-way cannot write into this one), zero-filled, so runs of zero
    /// windows need no writes.
    fn open(&mut self) -> io::Result<&mut BufWriter<File>> {
        if self.file.is_none() {
            match fs::remove_file(&self.path) {
                Err(e) if e.kind() != io::ErrorKind::NotFound => return Err(e),
                _ => {}
            }
            let file = File::options().write(true).create_new(true).open(&self.path)?;
            file.set_len(self.len)?;
            self.pos = 0;
            self.file = Some(BufWriter::with_capacity(1 << 16, file));
        }
        self.file.as_mut().ok_or_else(|| io::Error::other("partial checkpoint file not open"))
    }

    /// Makes the received image the file at `to`: flush, fsync the partial
    /// file, rename it over `to`, fsync the directory. Until the rename
    /// `to` holds the previous checkpoint, whole; after a crash past it,
    /// the new one.
    pub fn commit(self, to: &Path) -> io::Result<()> {
        let Some(writer) = self.file else {
            return Err(io::Error::other("no byte of the checkpoint was written"));
        };
        let file = writer.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        drop(file);
        fs::rename(&self.path, to)?;
        let dir = match to.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        File::open(dir)?.sync_all()
    }
}

impl ImageSink for FileSink {
    type Error = io::Error;

    fn write(&mut self, offset: usize, bytes: &[u8]) -> io::Result<()> {
        let offset = offset as u64;
        let seek = offset != self.pos;
        let file = self.open()?;
        if seek {
            file.seek(SeekFrom::Start(offset))?;
        }
        file.write_all(bytes)?;
        self.pos = offset + bytes.len() as u64;
        Ok(())
    }

    /// The file was created zero-filled at its full length and each byte
    /// is written once: nothing to write.
    fn write_zeros(&mut self, _offset: usize, _len: usize) -> io::Result<()> {
        self.open().map(|_| ())
    }
}
