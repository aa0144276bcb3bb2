//! Checkpoints on disk: the controller's two alternating slots
//! (`pada_core::checkpoint`) in one file, as a board keeps them in two
//! flash sectors, so that `pada drive` saves and loads through the same
//! code and a torn save keeps the previous checkpoint. The file is written
//! in place, synced after an erase and around the header (each save's
//! last write); a slot is erased to 0xFF as flash is.

use pada_core::checkpoint::CheckpointStore;
use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// Two checkpoint slots in a file.
pub struct FileStore {
    file: File,
    path: PathBuf,
    slot: usize,
}

impl FileStore {
    /// The file at `path` with slots of at least `slot` bytes (an existing
    /// file of larger slots keeps its size; a new one is erased).
    pub fn open(path: &Path, slot: usize) -> std::io::Result<FileStore> {
        let file = OpenOptions::new().read(true).write(true).create(true).truncate(false).open(path)?;
        let have = file.metadata()?.len() as usize / 2;
        let mut store = FileStore { file, path: path.to_path_buf(), slot: have.max(slot) };
        if have < slot {
            for s in 0..2 {
                store.erase(s)?;
            }
        }
        Ok(store)
    }

    /// Its path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn at(&self, slot: u8, offset: usize, len: usize) -> std::io::Result<u64> {
        if slot > 1 || offset + len > self.slot {
            return Err(std::io::Error::new(std::io::ErrorKind::InvalidInput, "outside the checkpoint slot"));
        }
        Ok((slot as usize * self.slot + offset) as u64)
    }
}

impl CheckpointStore for FileStore {
    type Error = std::io::Error;

    fn capacity(&self) -> usize {
        self.slot
    }

    fn read(&self, slot: u8, offset: usize, buf: &mut [u8]) -> std::io::Result<()> {
        let at = self.at(slot, offset, buf.len())?;
        let mut f = &self.file;
        f.seek(SeekFrom::Start(at))?;
        f.read_exact(buf)
    }

    fn erase(&mut self, slot: u8) -> std::io::Result<()> {
        let at = self.at(slot, 0, self.slot)?;
        self.file.seek(SeekFrom::Start(at))?;
        self.file.write_all(&vec![0xFF; self.slot])?;
        self.file.sync_data()
    }

    /// The header (offset 0) is the save's last write
    /// (`pada_core::checkpoint::slots`): everything before it is synced
    /// first and it after, so a torn save never has a header over unsynced
    /// weights. The chunks in between are not synced one by one: a sync per
    /// chunk made the host learner's 3.8 MB save take about a minute.
    fn write(&mut self, slot: u8, offset: usize, data: &[u8]) -> std::io::Result<()> {
        let at = self.at(slot, offset, data.len())?;
        if offset == 0 {
            self.file.sync_data()?;
        }
        self.file.seek(SeekFrom::Start(at))?;
        self.file.write_all(data)?;
        if offset == 0 {
            self.file.sync_data()?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slots_in_a_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("ckpt.bin");
        let mut s = FileStore::open(&p, 64).unwrap();
        let mut b = [0u8; 4];
        s.read(1, 60, &mut b).unwrap();
        assert_eq!(b, [0xFF; 4]);
        s.write(1, 60, &[1, 2, 3, 4]).unwrap();
        assert!(s.write(1, 62, &[1, 2, 3, 4]).is_err());
        drop(s);
        let s = FileStore::open(&p, 32).unwrap();
        assert_eq!(s.capacity(), 64);
        s.read(1, 60, &mut b).unwrap();
        assert_eq!(b, [1, 2, 3, 4]);
    }
}
