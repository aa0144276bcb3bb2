//! Saved learning: the weight table in two alternating slots, so that a
//! reset or power cut during a save keeps the last good checkpoint.
//!
//! # Slot layout (little endian)
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 4 | magic `"PDCK"` |
//! | 4 | 2 | format version ([`FORMAT_VERSION`]) |
//! | 6 | 2 | header length (32) |
//! | 8 | 4 | configuration hash ([`config_hash`] of the caller's description) |
//! | 12 | 4 | weight count `n` |
//! | 16 | 4 | generation (1 for the first save, +1 per save) |
//! | 20 | 4 | CRC-32 of the payload |
//! | 24 | 4 | reserved, 0 |
//! | 28 | 4 | CRC-32 of bytes 0–27 |
//! | 32 | 4·n | the weights, raw [`Q16`] as little-endian `i32` |
//!
//! # Why a torn write is harmless
//!
//! [`save`] writes into the slot that does *not* hold the newest valid
//! checkpoint: it erases that slot, writes the payload, and writes the
//! header last. Until the header's last byte (its own CRC) is written the
//! slot has no valid header, so [`load`] ignores it and takes the other
//! slot. An erased slot reads `0xFF`, which never forms a valid header.
//! Every write is 4-byte aligned and a multiple of 4 bytes long, which suits
//! STM32F4 flash programming.
//!
//! [`load`] checks the header's magic, version and CRC, then the payload's
//! CRC, picks the valid slot with the higher generation, and only then
//! compares the configuration hash and size; the caller's weights are
//! written only when the outcome is [`LoadOutcome::Loaded`].
//!
//! CRC-32 is CRC-32/ISO-HDLC (the zlib/Ethernet CRC) from the `crc` crate,
//! one 1 KB table in flash, shared with the telemetry frames.

use crate::fixed::Q16;

/// CRC-32/ISO-HDLC (polynomial 0x04C11DB7 reflected, init and xor-out
/// 0xFFFFFFFF), used by checkpoints and telemetry frames.
pub static CRC32: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);

/// CRC-32 of `bytes` (see [`CRC32`]).
pub fn crc32(bytes: &[u8]) -> u32 {
    CRC32.checksum(bytes)
}

/// `"PDCK"` read as a little-endian `u32`.
pub const MAGIC: u32 = u32::from_le_bytes(*b"PDCK");
/// The format version this code writes and reads.
pub const FORMAT_VERSION: u16 = 1;
/// Bytes of the header.
pub const HEADER_LEN: usize = 32;
/// Number of slots.
pub const SLOTS: u8 = 2;
/// Bytes per weight in the payload.
pub const WEIGHT_BYTES: usize = 4;

/// Bytes a slot needs for `weights` weights.
pub const fn slot_len(weights: usize) -> usize {
    HEADER_LEN + weights * WEIGHT_BYTES
}

/// Where checkpoints live: two slots of equal size, read and written at byte
/// offsets. On the chip, two flash sectors; in tests, RAM ([`RamStore`]).
pub trait CheckpointStore {
    /// What the medium reports when an operation fails.
    type Error;
    /// Bytes in each slot.
    fn capacity(&self) -> usize;
    /// Reads `buf.len()` bytes of `slot` from `offset`.
    fn read(&self, slot: u8, offset: usize, buf: &mut [u8]) -> Result<(), Self::Error>;
    /// Erases `slot` (to `0xFF`, as flash).
    fn erase(&mut self, slot: u8) -> Result<(), Self::Error>;
    /// Writes `data` into `slot` at `offset` (only erased bytes are written).
    fn write(&mut self, slot: u8, offset: usize, data: &[u8]) -> Result<(), Self::Error>;
}

/// The header of a checkpoint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Header {
    /// Format version.
    pub version: u16,
    /// Hash of the configuration the weights were learned with.
    pub config_hash: u32,
    /// Number of weights in the payload.
    pub weight_count: u32,
    /// Save counter: the newer of two valid slots has the higher one.
    pub generation: u32,
    /// CRC-32 of the payload bytes.
    pub payload_crc: u32,
}

/// Why a slot's header is not valid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum HeaderError {
    /// Every byte is `0xFF`: an erased slot.
    Erased,
    /// Wrong magic, header length or header CRC.
    Corrupt,
    /// A valid header of a format this code does not read.
    UnsupportedVersion {
        /// The version found.
        found: u16,
    },
}

impl Header {
    /// The 32 header bytes, CRC included.
    pub fn to_bytes(&self) -> [u8; HEADER_LEN] {
        let mut b = [0u8; HEADER_LEN];
        b[0..4].copy_from_slice(&MAGIC.to_le_bytes());
        b[4..6].copy_from_slice(&self.version.to_le_bytes());
        b[6..8].copy_from_slice(&(HEADER_LEN as u16).to_le_bytes());
        b[8..12].copy_from_slice(&self.config_hash.to_le_bytes());
        b[12..16].copy_from_slice(&self.weight_count.to_le_bytes());
        b[16..20].copy_from_slice(&self.generation.to_le_bytes());
        b[20..24].copy_from_slice(&self.payload_crc.to_le_bytes());
        // 24..28 reserved, zero.
        let crc = crc32(&b[..28]);
        b[28..32].copy_from_slice(&crc.to_le_bytes());
        b
    }

    /// Parses and checks 32 header bytes.
    pub fn parse(b: &[u8; HEADER_LEN]) -> Result<Header, HeaderError> {
        if b.iter().all(|&x| x == 0xFF) {
            return Err(HeaderError::Erased);
        }
        let u32_at = |i: usize| u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
        let u16_at = |i: usize| u16::from_le_bytes([b[i], b[i + 1]]);
        if u32_at(0) != MAGIC || u16_at(6) as usize != HEADER_LEN || u32_at(28) != crc32(&b[..28]) {
            return Err(HeaderError::Corrupt);
        }
        let version = u16_at(4);
        if version != FORMAT_VERSION {
            return Err(HeaderError::UnsupportedVersion { found: version });
        }
        Ok(Header {
            version,
            config_hash: u32_at(8),
            weight_count: u32_at(12),
            generation: u32_at(16),
            payload_crc: u32_at(20),
        })
    }
}

/// What [`load`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LoadOutcome {
    /// The weights were loaded from the newest valid checkpoint.
    Loaded {
        /// Its generation.
        generation: u32,
        /// The slot it was in.
        slot: u8,
    },
    /// Both slots are erased.
    NoCheckpoint,
    /// The newest valid checkpoint was learned with another configuration;
    /// weights unchanged.
    ConfigMismatch {
        /// The hash of the running configuration.
        expected: u32,
        /// The hash in the checkpoint.
        found: u32,
    },
    /// The newest valid checkpoint has another number of weights than the
    /// table; weights unchanged.
    SizeMismatch {
        /// The table's number of weights.
        expected: u32,
        /// The checkpoint's.
        found: u32,
    },
    /// The newest readable header is of another format version.
    UnsupportedVersion {
        /// The version found.
        found: u16,
    },
    /// No slot holds a valid checkpoint, and not both are erased.
    Corrupt,
}

/// Why [`save`] failed. The previous checkpoint is intact in every case.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SaveError<E> {
    /// The weights do not fit a slot.
    TooLarge {
        /// Bytes needed.
        needed: usize,
        /// Bytes per slot.
        capacity: usize,
    },
    /// The store failed.
    Store(E),
    /// Reading back the written checkpoint did not give a valid one.
    VerifyFailed {
        /// The slot written.
        slot: u8,
    },
}

/// A successful save.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Saved {
    /// Generation written.
    pub generation: u32,
    /// Slot written.
    pub slot: u8,
}

/// What one slot holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SlotStatus {
    /// A checkpoint with a valid header and payload.
    Valid(Header),
    /// No valid checkpoint (the header error, or `Corrupt` for a payload
    /// whose CRC does not match or does not fit the slot).
    Invalid(HeaderError),
}

/// Bytes read at a time while checking a payload.
const CHUNK: usize = 64;

/// Reads and checks `slot`: its header and its payload CRC.
pub fn inspect<S: CheckpointStore>(store: &S, slot: u8) -> Result<SlotStatus, S::Error> {
    let mut hb = [0u8; HEADER_LEN];
    if store.capacity() < HEADER_LEN {
        return Ok(SlotStatus::Invalid(HeaderError::Corrupt));
    }
    store.read(slot, 0, &mut hb)?;
    let header = match Header::parse(&hb) {
        Ok(h) => h,
        Err(e) => return Ok(SlotStatus::Invalid(e)),
    };
    let len = (header.weight_count as usize).checked_mul(WEIGHT_BYTES).and_then(|n| n.checked_add(HEADER_LEN));
    match len {
        Some(l) if l <= store.capacity() => {}
        _ => return Ok(SlotStatus::Invalid(HeaderError::Corrupt)),
    }
    let mut digest = CRC32.digest();
    let mut remaining = header.weight_count as usize * WEIGHT_BYTES;
    let mut offset = HEADER_LEN;
    let mut buf = [0u8; CHUNK];
    while remaining > 0 {
        let n = remaining.min(CHUNK);
        store.read(slot, offset, &mut buf[..n])?;
        digest.update(&buf[..n]);
        offset += n;
        remaining -= n;
    }
    if digest.finalize() != header.payload_crc {
        return Ok(SlotStatus::Invalid(HeaderError::Corrupt));
    }
    Ok(SlotStatus::Valid(header))
}

/// The slot and header of the newest valid checkpoint, if any.
type Newest = Option<(u8, Header)>;

/// Both slots' status and the newest valid checkpoint.
fn newest<S: CheckpointStore>(store: &S) -> Result<([SlotStatus; 2], Newest), S::Error> {
    let status = [inspect(store, 0)?, inspect(store, 1)?];
    let mut best: Newest = None;
    for (i, s) in status.iter().enumerate() {
        if let SlotStatus::Valid(h) = s {
            if best.is_none_or(|(_, b)| h.generation > b.generation) {
                best = Some((i as u8, *h));
            }
        }
    }
    Ok((status, best))
}

/// Saves `weights` with `config_hash` into the slot not holding the newest
/// valid checkpoint, header last, then reads it back to verify.
pub fn save<S: CheckpointStore>(
    store: &mut S,
    config_hash: u32,
    weights: &[Q16],
) -> Result<Saved, SaveError<S::Error>> {
    let needed = slot_len(weights.len());
    if needed > store.capacity() || weights.len() > u32::MAX as usize {
        return Err(SaveError::TooLarge { needed, capacity: store.capacity() });
    }
    let (_, best) = newest(store).map_err(SaveError::Store)?;
    let (slot, generation) = match best {
        Some((s, h)) => (1 - s, h.generation.saturating_add(1)),
        None => (0, 1),
    };
    store.erase(slot).map_err(SaveError::Store)?;
    let mut digest = CRC32.digest();
    let mut buf = [0u8; CHUNK];
    let mut offset = HEADER_LEN;
    for chunk in weights.chunks(CHUNK / WEIGHT_BYTES) {
        let n = chunk.len() * WEIGHT_BYTES;
        for (dst, w) in buf.chunks_exact_mut(WEIGHT_BYTES).zip(chunk) {
            dst.copy_from_slice(&w.0.to_le_bytes());
        }
        digest.update(&buf[..n]);
        store.write(slot, offset, &buf[..n]).map_err(SaveError::Store)?;
        offset += n;
    }
    let header = Header {
        version: FORMAT_VERSION,
        config_hash,
        weight_count: weights.len() as u32,
        generation,
        payload_crc: digest.finalize(),
    };
    store.write(slot, 0, &header.to_bytes()).map_err(SaveError::Store)?;
    match inspect(store, slot).map_err(SaveError::Store)? {
        SlotStatus::Valid(h) if h == header => Ok(Saved { generation, slot }),
        _ => Err(SaveError::VerifyFailed { slot }),
    }
}

/// Loads the newest valid checkpoint into `weights` if it was saved with
/// `config_hash` and has `weights.len()` weights; otherwise leaves `weights`
/// unchanged and says why.
pub fn load<S: CheckpointStore>(store: &S, config_hash: u32, weights: &mut [Q16]) -> Result<LoadOutcome, S::Error> {
    let (status, best) = newest(store)?;
    let Some((slot, header)) = best else {
        let version = status.iter().find_map(|s| match s {
            SlotStatus::Invalid(HeaderError::UnsupportedVersion { found }) => Some(*found),
            _ => None,
        });
        let erased = status.iter().all(|s| *s == SlotStatus::Invalid(HeaderError::Erased));
        return Ok(match (version, erased) {
            (Some(found), _) => LoadOutcome::UnsupportedVersion { found },
            (None, true) => LoadOutcome::NoCheckpoint,
            (None, false) => LoadOutcome::Corrupt,
        });
    };
    if header.config_hash != config_hash {
        return Ok(LoadOutcome::ConfigMismatch { expected: config_hash, found: header.config_hash });
    }
    if header.weight_count as usize != weights.len() {
        return Ok(LoadOutcome::SizeMismatch { expected: weights.len() as u32, found: header.weight_count });
    }
    // The payload was checked by `inspect`; copy it.
    let mut buf = [0u8; CHUNK];
    let mut offset = HEADER_LEN;
    for chunk in weights.chunks_mut(CHUNK / WEIGHT_BYTES) {
        let n = chunk.len() * WEIGHT_BYTES;
        store.read(slot, offset, &mut buf[..n])?;
        for (w, src) in chunk.iter_mut().zip(buf.chunks_exact(WEIGHT_BYTES)) {
            *w = Q16(i32::from_le_bytes([src[0], src[1], src[2], src[3]]));
        }
        offset += n;
    }
    Ok(LoadOutcome::Loaded { generation: header.generation, slot })
}

/// FNV-1a (32 bit) of a configuration's byte description: the value stored
/// in a checkpoint's header and compared at load.
pub fn config_hash(bytes: &[u8]) -> u32 {
    let mut h = ConfigHasher::new();
    h.write(bytes);
    h.finish()
}

/// Incremental FNV-1a (32 bit), to describe a configuration field by field
/// without building a byte buffer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ConfigHasher(u32);

impl Default for ConfigHasher {
    fn default() -> Self {
        Self::new()
    }
}

impl ConfigHasher {
    const OFFSET: u32 = 0x811C_9DC5;
    const PRIME: u32 = 0x0100_0193;

    /// A hasher at FNV-1a's offset basis.
    pub const fn new() -> Self {
        ConfigHasher(Self::OFFSET)
    }
    /// Adds bytes.
    pub fn write(&mut self, bytes: &[u8]) -> &mut Self {
        for &b in bytes {
            self.0 = (self.0 ^ b as u32).wrapping_mul(Self::PRIME);
        }
        self
    }
    /// Adds a `u32`, little endian.
    pub fn write_u32(&mut self, v: u32) -> &mut Self {
        self.write(&v.to_le_bytes())
    }
    /// Adds an `f32` by its bit pattern, little endian.
    pub fn write_f32(&mut self, v: f32) -> &mut Self {
        self.write_u32(v.to_bits())
    }
    /// Adds a string's bytes and its length (so `"ab","c"` ≠ `"a","bc"`).
    pub fn write_str(&mut self, s: &str) -> &mut Self {
        self.write_u32(s.len() as u32).write(s.as_bytes())
    }
    /// The hash.
    pub fn finish(&self) -> u32 {
        self.0
    }
}

/// A [`CheckpointStore`] in RAM: two slots of `SLOT` bytes, erased to
/// `0xFF`. For tests and host-side runs.
#[derive(Debug, Clone)]
pub struct RamStore<const SLOT: usize> {
    slots: [[u8; SLOT]; 2],
}

/// An access outside a [`RamStore`]'s slots.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct OutOfRange;

impl<const SLOT: usize> Default for RamStore<SLOT> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const SLOT: usize> RamStore<SLOT> {
    /// Two erased slots.
    pub const fn new() -> Self {
        RamStore { slots: [[0xFF; SLOT]; 2] }
    }

    /// The raw bytes of a slot (for tests that corrupt them).
    pub fn slot_mut(&mut self, slot: u8) -> Option<&mut [u8; SLOT]> {
        self.slots.get_mut(slot as usize)
    }

    /// The raw bytes of a slot.
    pub fn slot(&self, slot: u8) -> Option<&[u8; SLOT]> {
        self.slots.get(slot as usize)
    }

    fn range(&self, slot: u8, offset: usize, len: usize) -> Result<(usize, core::ops::Range<usize>), OutOfRange> {
        let end = offset.checked_add(len).ok_or(OutOfRange)?;
        if (slot as usize) < self.slots.len() && end <= SLOT {
            Ok((slot as usize, offset..end))
        } else {
            Err(OutOfRange)
        }
    }
}

impl<const SLOT: usize> CheckpointStore for RamStore<SLOT> {
    type Error = OutOfRange;
    fn capacity(&self) -> usize {
        SLOT
    }
    fn read(&self, slot: u8, offset: usize, buf: &mut [u8]) -> Result<(), OutOfRange> {
        let (s, r) = self.range(slot, offset, buf.len())?;
        buf.copy_from_slice(&self.slots[s][r]);
        Ok(())
    }
    fn erase(&mut self, slot: u8) -> Result<(), OutOfRange> {
        let s = self.slots.get_mut(slot as usize).ok_or(OutOfRange)?;
        s.fill(0xFF);
        Ok(())
    }
    fn write(&mut self, slot: u8, offset: usize, data: &[u8]) -> Result<(), OutOfRange> {
        let (s, r) = self.range(slot, offset, data.len())?;
        // As flash: programming can only clear bits of erased bytes.
        for (dst, src) in self.slots[s][r].iter_mut().zip(data) {
            *dst &= *src;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a_reference_values() {
        assert_eq!(config_hash(b""), 0x811C_9DC5);
        assert_eq!(config_hash(b"a"), 0xE40C_292C);
        assert_eq!(config_hash(b"foobar"), 0xBF9C_F968);
        let mut h = ConfigHasher::new();
        h.write(b"foo").write(b"bar");
        assert_eq!(h.finish(), config_hash(b"foobar"));
        let (mut a, mut b) = (ConfigHasher::new(), ConfigHasher::new());
        a.write_str("ab").write_str("c");
        b.write_str("a").write_str("bc");
        assert_ne!(a.finish(), b.finish());
    }

    #[test]
    fn crc32_check_value() {
        // The catalogue's check value of CRC-32/ISO-HDLC.
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    }

    #[test]
    fn header_round_trip_and_rejections() {
        let h = Header { version: FORMAT_VERSION, config_hash: 7, weight_count: 3, generation: 9, payload_crc: 1 };
        let b = h.to_bytes();
        assert_eq!(Header::parse(&b), Ok(h));
        assert_eq!(Header::parse(&[0xFF; HEADER_LEN]), Err(HeaderError::Erased));
        for i in 0..HEADER_LEN {
            let mut c = b;
            c[i] ^= 0x04;
            assert!(Header::parse(&c).is_err(), "bit flip at {i}");
        }
        let h2 = Header { version: 2, ..h };
        assert_eq!(Header::parse(&h2.to_bytes()), Err(HeaderError::UnsupportedVersion { found: 2 }));
    }
}
