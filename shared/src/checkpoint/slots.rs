//! The two alternating slots: the header, checking a slot, finding the
//! newest valid checkpoint, saving into the other slot, loading.

use super::record::{put_wear, wear_of, LearnerState, STATE_LEN, WEAR_END};
use super::store::CheckpointStore;
use super::wear::{FlashWear, WearBudget, WearRefusal};
use crate::crc::{crc32, CRC32};
use crate::weights::WeightStore;

/// `"PDCK"` read as a little-endian `u32`.
pub const MAGIC: u32 = u32::from_le_bytes(*b"PDCK");
/// The format version this code writes and reads (1 held weights only, 2
/// only 4-byte weights, 3 no claim tags; 4 stores each table entry as its
/// weight and its claim tag, if any, and a record of version 4).
pub const FORMAT_VERSION: u16 = 4;
/// Bytes of the header.
pub const HEADER_LEN: usize = 32;
/// Number of slots.
pub const SLOTS: u8 = 2;
/// Whether a slot can store entries of `entry_bytes` bytes: 2, 4 or 8 (a
/// 16-bit or Q16 weight alone, a 16-bit weight with a 16-bit tag, a Q16
/// weight with a 32-bit tag). The header's width field is read as one of
/// these ([`Header::slot_bytes`]), so [`save`] and a streamed image refuse
/// any other before they write.
pub const fn valid_entry_bytes(entry_bytes: usize) -> bool {
    matches!(entry_bytes, 2 | 4 | 8)
}

/// Bytes a slot needs for `weights` weights of `weight_bytes` bytes each
/// (header, state record, weights padded to a multiple of 4).
pub const fn slot_len(weights: usize, weight_bytes: usize) -> usize {
    HEADER_LEN + STATE_LEN + (weights * weight_bytes).div_ceil(4) * 4
}

/// Whether generation `a` is newer than `b`, in serial-number arithmetic
/// (RFC 1982): the generation wraps from `u32::MAX` to 0, and of two
/// generations the one less than 2³¹ saves ahead is the newer. The two
/// slots are never more than a few saves apart, so this never misorders
/// them, and saving goes on forever instead of stopping at `u32::MAX`.
pub fn is_newer(a: u32, b: u32) -> bool {
    a != b && a.wrapping_sub(b) < 1 << 31
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
    /// CRC-32 of the payload bytes (state record and weights).
    pub payload_crc: u32,
    /// Bytes of the learner-state record ([`STATE_LEN`]).
    pub state_len: u32,
    /// Bytes per stored table entry: the weight's (4 or 2,
    /// [`crate::weights::WeightFormat`]) and a claim table's tag (0, 2 or
    /// 4; [`WeightStore::entry_bytes`]): 2, 4 or 8 in all.
    pub weight_bytes: u16,
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
    /// A valid header of a format this code does not read (1: weights
    /// without the learner's state).
    UnsupportedVersion {
        /// The version found.
        found: u16,
    },
}

/// One line naming the cause and what is valid (for logs and refusals).
impl core::fmt::Display for HeaderError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            HeaderError::Erased => write!(f, "header erased (all 0xFF)"),
            HeaderError::Corrupt => write!(f, "header corrupt: wrong magic, header length or header CRC"),
            HeaderError::UnsupportedVersion { found } => {
                write!(f, "header of format version {found}: valid is {FORMAT_VERSION}")
            }
        }
    }
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
        b[24..26].copy_from_slice(&(self.state_len.min(u16::MAX as u32) as u16).to_le_bytes());
        b[26..28].copy_from_slice(&self.weight_bytes.to_le_bytes());
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
            state_len: u16_at(24) as u32,
            weight_bytes: u16_at(26),
        })
    }

    /// Bytes of the slot this header describes, if that fits a `usize`:
    /// also the length of a streamed image ([`super::stream`]).
    pub fn slot_bytes(&self) -> Option<usize> {
        if !valid_entry_bytes(self.weight_bytes as usize) {
            return None;
        }
        (self.weight_count as usize)
            .checked_mul(self.weight_bytes as usize)?
            .checked_next_multiple_of(4)?
            .checked_add(self.state_len as usize)?
            .checked_add(HEADER_LEN)
    }
}

/// What [`load`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LoadOutcome {
    /// The weights and the learner's state were loaded from the newest
    /// valid checkpoint.
    Loaded {
        /// Its generation.
        generation: u32,
        /// The slot it was in.
        slot: u8,
    },
    /// Both slots are erased.
    NoCheckpoint,
    /// The newest valid checkpoint was learned with another configuration;
    /// weights and state unchanged.
    ConfigMismatch {
        /// The hash of the running configuration.
        expected: u32,
        /// The hash in the checkpoint.
        found: u32,
    },
    /// The newest valid checkpoint has another number of weights than the
    /// table; weights and state unchanged.
    SizeMismatch {
        /// The table's number of weights.
        expected: u32,
        /// The checkpoint's.
        found: u32,
    },
    /// The newest readable header is of another format version (1: a
    /// checkpoint of weights only, from before the learner's state was
    /// saved); weights and state unchanged.
    UnsupportedVersion {
        /// The version found.
        found: u16,
    },
    /// No slot holds a valid checkpoint, and not both are erased.
    Corrupt,
    /// The newest valid checkpoint's learner-state record was refused: a
    /// record of another length or version, a code it cannot hold, or a
    /// field out of range for the running learner; weights and state
    /// unchanged. (Appended last, so the earlier variants keep their wire
    /// encoding.)
    InvalidState,
}

/// Why [`save`] failed. The previous checkpoint is intact in every case.
///
/// A failure after the slot's sector was erased ([`StoreAfterErase`],
/// [`VerifyFailed`]) carries that sector's erase count, this erase
/// included ([`erased`](Self::erased)): the slot holds no valid record to
/// keep it, so the caller keeps it (in the [`FlashWear`] it saves next),
/// and every erase that happened is counted. The other variants erased
/// nothing.
///
/// [`StoreAfterErase`]: Self::StoreAfterErase
/// [`VerifyFailed`]: Self::VerifyFailed
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SaveError<E> {
    /// The weights do not fit a slot; nothing erased.
    TooLarge {
        /// Bytes needed.
        needed: usize,
        /// Bytes per slot.
        capacity: usize,
    },
    /// The store failed before the erase (reading the slots); nothing
    /// erased.
    Store(E),
    /// Reading back the written checkpoint did not give a valid one.
    VerifyFailed {
        /// The slot written.
        slot: u8,
        /// Erases of its sector, this save's included.
        erases: u32,
    },
    /// Refused before anything was erased: the slot's sector would exceed
    /// its erase budget ([`save_within`]).
    Wear(WearRefusal),
    /// Refused before anything was erased: the table's entries are of a
    /// width no header describes. A slot stores 2, 4 or 8 bytes an entry
    /// (a 16-bit or [`crate::fixed::Q16`] weight alone, a 16-bit weight
    /// with a 16-bit tag, a Q16 weight with a 32-bit tag); a Q16 weight
    /// with a 16-bit tag, or a 16-bit weight with a 32-bit tag, is 6.
    EntryBytes {
        /// The table's bytes per entry ([`WeightStore::entry_bytes`]).
        found: usize,
    },
    /// The store failed while erasing the slot's sector or writing it (the
    /// erase counted, as it may have begun).
    StoreAfterErase {
        /// The slot.
        slot: u8,
        /// Erases of its sector, this save's included.
        erases: u32,
        /// The store's error.
        error: E,
    },
}

impl<E> SaveError<E> {
    /// The slot whose sector this failed save erased and that sector's
    /// erase count, this erase included; `None` if nothing was erased.
    pub fn erased(&self) -> Option<(u8, u32)> {
        match *self {
            SaveError::VerifyFailed { slot, erases } | SaveError::StoreAfterErase { slot, erases, .. } => {
                Some((slot, erases))
            }
            SaveError::TooLarge { .. } | SaveError::Store(_) | SaveError::Wear(_) | SaveError::EntryBytes { .. } => {
                None
            }
        }
    }
}

/// One line naming the cause and what is valid (for logs and refusals).
impl<E: core::fmt::Debug> core::fmt::Display for SaveError<E> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            SaveError::TooLarge { needed, capacity } => {
                write!(f, "checkpoint of {needed} bytes not saved: a slot holds at most {capacity}")
            }
            SaveError::Store(e) => write!(f, "checkpoint not saved: the store failed before erasing: {e:?}"),
            SaveError::VerifyFailed { slot, erases } => write!(
                f,
                "checkpoint written to slot {slot} did not read back as valid (its sector erased {erases} times)"
            ),
            SaveError::Wear(r) => write!(f, "checkpoint not saved to spare the flash: {r:?}"),
            SaveError::EntryBytes { found } => write!(
                f,
                "table entry of {found} bytes cannot be checkpointed: valid are 2, 4 or 8 (a weight alone, a \
                 16-bit weight with a 16-bit tag, a Q16 weight with a 32-bit tag)"
            ),
            SaveError::StoreAfterErase { slot, erases, error } => write!(
                f,
                "checkpoint not saved: the store failed erasing or writing slot {slot} (its sector erased \
                 {erases} times): {error:?}"
            ),
        }
    }
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
    /// Erases of that slot's sector, this save's included.
    pub erases: u32,
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

/// Reads and checks `slot`: its header and its payload CRC (state record
/// and weights).
pub fn inspect<S: CheckpointStore>(store: &S, slot: u8) -> Result<SlotStatus, S::Error> {
    let mut hb = [0xFFu8; HEADER_LEN];
    let capacity = store.capacity();
    if capacity < HEADER_LEN {
        // Too small for any checkpoint: erased if it reads as erased flash,
        // so that a never-written small store is empty, not corrupt.
        let part = &mut hb[..capacity];
        store.read(slot, 0, part)?;
        let erased = part.iter().all(|&b| b == 0xFF);
        return Ok(SlotStatus::Invalid(if erased { HeaderError::Erased } else { HeaderError::Corrupt }));
    }
    store.read(slot, 0, &mut hb)?;
    let header = match Header::parse(&hb) {
        Ok(h) => h,
        Err(e) => return Ok(SlotStatus::Invalid(e)),
    };
    let end = match header.slot_bytes() {
        Some(l) if l <= store.capacity() => l,
        _ => return Ok(SlotStatus::Invalid(HeaderError::Corrupt)),
    };
    let mut digest = CRC32.digest();
    let mut offset = HEADER_LEN;
    let mut buf = [0u8; CHUNK];
    while offset < end {
        let n = (end - offset).min(CHUNK);
        store.read(slot, offset, &mut buf[..n])?;
        digest.update(&buf[..n]);
        offset += n;
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
            if best.is_none_or(|(_, b)| is_newer(h.generation, b.generation)) {
                best = Some((i as u8, *h));
            }
        }
    }
    Ok((status, best))
}

/// The flash wear the newest valid checkpoint recorded (whatever its
/// configuration), or none if no slot is valid. A record of version 1 (from
/// before the wear was counted) gives a lower bound from its generation:
/// every save erased one slot, alternating from slot 0.
pub fn stored_wear<S: CheckpointStore>(store: &S) -> Result<FlashWear, S::Error> {
    let (_, best) = newest(store)?;
    wear_in(store, best)
}

fn wear_in<S: CheckpointStore>(store: &S, best: Newest) -> Result<FlashWear, S::Error> {
    let Some((slot, header)) = best else {
        return Ok(FlashWear::default());
    };
    // Records of versions 2 (512 bytes) to 4 keep the wear at the same
    // offsets; a version-1 record (496 bytes) has none.
    if (header.state_len as usize) < WEAR_END {
        let g = header.generation;
        return Ok(FlashWear { erases: [g - g / 2, g / 2], operating_s: 0 });
    }
    let mut record = [0u8; WEAR_END];
    store.read(slot, HEADER_LEN, &mut record)?;
    Ok(wear_of(&record))
}

/// Saves the learner's `state` and `weights` with `config_hash` into the
/// slot not holding the newest valid checkpoint — state record and weights
/// first, header last — then reads it back to verify. The record's wear is
/// the higher of the store's ([`stored_wear`]) and `state.wear`, with this
/// save's erase counted; no budget is applied (see [`save_within`]).
///
/// A table whose entries no header describes is refused with
/// [`SaveError::EntryBytes`] before anything is erased; a save that fails
/// after its erase says so with the count ([`SaveError::erased`]), for the
/// caller to carry into its next save's `state.wear`.
pub fn save<S: CheckpointStore, W: WeightStore + ?Sized>(
    store: &mut S,
    config_hash: u32,
    state: &LearnerState,
    weights: &W,
) -> Result<Saved, SaveError<S::Error>> {
    save_checked(store, config_hash, state, weights, None)
}

/// [`save`], refused with [`SaveError::Wear`] — before anything is erased —
/// if the erase would take the slot's sector beyond `budget` at the
/// operating time `state.wear.operating_s`.
pub fn save_within<S: CheckpointStore, W: WeightStore + ?Sized>(
    store: &mut S,
    config_hash: u32,
    state: &LearnerState,
    weights: &W,
    budget: &WearBudget,
) -> Result<Saved, SaveError<S::Error>> {
    save_checked(store, config_hash, state, weights, Some(budget))
}

fn save_checked<S: CheckpointStore, W: WeightStore + ?Sized>(
    store: &mut S,
    config_hash: u32,
    state: &LearnerState,
    weights: &W,
    budget: Option<&WearBudget>,
) -> Result<Saved, SaveError<S::Error>> {
    let bytes = weights.entry_bytes();
    // Only widths a header describes (Header::slot_bytes): any other would
    // be erased and written, then never read back as a checkpoint.
    if !valid_entry_bytes(bytes) {
        return Err(SaveError::EntryBytes { found: bytes });
    }
    let needed = slot_len(weights.len(), bytes);
    if needed > store.capacity() || weights.len() > u32::MAX as usize {
        return Err(SaveError::TooLarge { needed, capacity: store.capacity() });
    }
    let (_, best) = newest(store).map_err(SaveError::Store)?;
    let (slot, generation) = match best {
        Some((s, h)) => (1 - s, h.generation.wrapping_add(1)),
        None => (0, 1),
    };
    let mut wear = wear_in(store, best).map_err(SaveError::Store)?.max(&state.wear);
    if let Some(budget) = budget {
        budget.check(wear.erases[slot as usize], wear.operating_s).map_err(SaveError::Wear)?;
    }
    wear.erases[slot as usize] = wear.erases[slot as usize].saturating_add(1);
    let erases = wear.erases[slot as usize];
    // From here on the slot's sector is (being) erased: a failure reports
    // the count, since the slot will hold no valid record of it.
    let after_erase = |error| SaveError::StoreAfterErase { slot, erases, error };
    store.erase(slot).map_err(after_erase)?;
    let mut digest = CRC32.digest();
    let mut record = state.to_bytes();
    put_wear(&mut record, &wear);
    digest.update(&record);
    store.write(slot, HEADER_LEN, &record).map_err(after_erase)?;
    let mut buf = [0u8; CHUNK];
    let mut offset = HEADER_LEN + STATE_LEN;
    let per_chunk = CHUNK / bytes;
    let mut i = 0;
    while i < weights.len() {
        let count = (weights.len() - i).min(per_chunk);
        for (k, dst) in buf.chunks_exact_mut(bytes).take(count).enumerate() {
            weights.stored_le(i + k, dst);
        }
        // The last chunk is padded with zeros to a multiple of 4 bytes.
        let used = count * bytes;
        let n = used.div_ceil(4) * 4;
        buf[used..n].fill(0);
        digest.update(&buf[..n]);
        store.write(slot, offset, &buf[..n]).map_err(after_erase)?;
        offset += n;
        i += count;
    }
    let header = Header {
        version: FORMAT_VERSION,
        config_hash,
        weight_count: weights.len() as u32,
        generation,
        payload_crc: digest.finalize(),
        state_len: STATE_LEN as u32,
        weight_bytes: bytes as u16,
    };
    store.write(slot, 0, &header.to_bytes()).map_err(after_erase)?;
    match inspect(store, slot).map_err(after_erase)? {
        SlotStatus::Valid(h) if h == header => Ok(Saved { generation, slot, erases }),
        _ => Err(SaveError::VerifyFailed { slot, erases }),
    }
}

/// The newest valid checkpoint of the running configuration, with its
/// learner state decoded; nothing of the caller's is written yet
/// ([`find`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Found {
    /// The slot it is in.
    pub slot: u8,
    /// Its header.
    pub header: Header,
    /// Its learner state, decoded ([`LearnerState::from_bytes`]) but not yet
    /// checked against the running learner.
    pub state: LearnerState,
}

/// Finds the newest valid checkpoint and, if it was saved with
/// `config_hash` and `weight_count` weights, decodes its learner state.
/// Writes nothing: the caller checks the state against its learner, then
/// copies the weights with [`read_weights`] (what [`load`] does without
/// the check). The inner `Err` is the outcome when there is nothing to
/// load.
pub fn find<S: CheckpointStore>(
    store: &S,
    config_hash: u32,
    weight_count: usize,
) -> Result<Result<Found, LoadOutcome>, S::Error> {
    let (status, best) = newest(store)?;
    let Some((slot, header)) = best else {
        let version = status.iter().find_map(|s| match s {
            SlotStatus::Invalid(HeaderError::UnsupportedVersion { found }) => Some(*found),
            _ => None,
        });
        let erased = status.iter().all(|s| *s == SlotStatus::Invalid(HeaderError::Erased));
        return Ok(Err(match (version, erased) {
            (Some(found), _) => LoadOutcome::UnsupportedVersion { found },
            (None, true) => LoadOutcome::NoCheckpoint,
            (None, false) => LoadOutcome::Corrupt,
        }));
    };
    if header.config_hash != config_hash {
        return Ok(Err(LoadOutcome::ConfigMismatch { expected: config_hash, found: header.config_hash }));
    }
    if header.weight_count as usize != weight_count {
        return Ok(Err(LoadOutcome::SizeMismatch { expected: weight_count as u32, found: header.weight_count }));
    }
    if header.state_len as usize != STATE_LEN {
        return Ok(Err(LoadOutcome::InvalidState));
    }
    // The record was checked by `inspect` (CRC); decode it.
    let mut record = [0u8; STATE_LEN];
    store.read(slot, HEADER_LEN, &mut record)?;
    match LearnerState::from_bytes(&record) {
        Ok(state) => Ok(Ok(Found { slot, header, state })),
        Err(_) => Ok(Err(LoadOutcome::InvalidState)),
    }
}

/// Copies the weights of a checkpoint [`find`] found into `weights`;
/// [`LoadOutcome::SizeMismatch`] (and nothing written) if `weights` has
/// another length than the checkpoint.
pub fn read_weights<S: CheckpointStore, W: WeightStore + ?Sized>(
    store: &S,
    found: &Found,
    weights: &mut W,
) -> Result<LoadOutcome, S::Error> {
    let header = &found.header;
    let bytes = weights.entry_bytes();
    if header.weight_count as usize != weights.len() || header.weight_bytes as usize != bytes {
        return Ok(LoadOutcome::SizeMismatch { expected: weights.len() as u32, found: header.weight_count });
    }
    // The payload was checked by `inspect`; copy it.
    let mut buf = [0u8; CHUNK];
    let mut offset = HEADER_LEN + header.state_len as usize;
    let per_chunk = CHUNK / bytes;
    let mut i = 0;
    while i < weights.len() {
        let count = (weights.len() - i).min(per_chunk);
        let n = count * bytes;
        store.read(found.slot, offset, &mut buf[..n])?;
        for (k, src) in buf[..n].chunks_exact(bytes).enumerate() {
            weights.load_le(i + k, src);
        }
        offset += n;
        i += count;
    }
    Ok(LoadOutcome::Loaded { generation: header.generation, slot: found.slot })
}

/// Loads the newest valid checkpoint into `state` and `weights` if it was
/// saved with `config_hash` and has `weights.len()` weights and a state
/// record this code reads; otherwise leaves both unchanged and says why.
///
/// The state is only decoded here, not checked against a learner: a caller
/// that restores it should use [`find`], check the state
/// ([`crate::agent::Agent::check_state`] and friends), then
/// [`read_weights`], so that a refused state leaves the weights as they
/// were too.
pub fn load<S: CheckpointStore, W: WeightStore + ?Sized>(
    store: &S,
    config_hash: u32,
    state: &mut LearnerState,
    weights: &mut W,
) -> Result<LoadOutcome, S::Error> {
    let found = match find(store, config_hash, weights.len())? {
        Ok(found) => found,
        Err(outcome) => return Ok(outcome),
    };
    let outcome = read_weights(store, &found, weights)?;
    if let LoadOutcome::Loaded { .. } = outcome {
        *state = found.state;
    }
    Ok(outcome)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_round_trip_and_rejections() {
        let h = Header {
            version: FORMAT_VERSION,
            config_hash: 7,
            weight_count: 3,
            generation: 9,
            payload_crc: 1,
            state_len: STATE_LEN as u32,
            weight_bytes: 4,
        };
        let b = h.to_bytes();
        assert_eq!(Header::parse(&b), Ok(h));
        assert_eq!(Header::parse(&[0xFF; HEADER_LEN]), Err(HeaderError::Erased));
        for i in 0..HEADER_LEN {
            let mut c = b;
            c[i] ^= 0x04;
            assert!(Header::parse(&c).is_err(), "bit flip at {i}");
        }
        let h1 = Header { version: 1, state_len: 0, ..h };
        assert_eq!(Header::parse(&h1.to_bytes()), Err(HeaderError::UnsupportedVersion { found: 1 }));
        let h2 = Header { version: 2, ..h };
        assert_eq!(Header::parse(&h2.to_bytes()), Err(HeaderError::UnsupportedVersion { found: 2 }));
        let h3 = Header { version: 3, ..h };
        assert_eq!(Header::parse(&h3.to_bytes()), Err(HeaderError::UnsupportedVersion { found: 3 }));
        let h5 = Header { version: 5, ..h };
        assert_eq!(Header::parse(&h5.to_bytes()), Err(HeaderError::UnsupportedVersion { found: 5 }));
        // An entry of 8 bytes (a Q16 weight and a 32-bit tag) is a slot;
        // a width other than 2, 4 or 8 bytes describes none.
        assert_eq!(Header { weight_bytes: 8, ..h }.slot_bytes(), Some(HEADER_LEN + STATE_LEN + 24));
        let mut store = super::super::store::RamStore::<{ slot_len(3, 4) }>::new();
        let odd = Header { weight_bytes: 3, ..h };
        let _ = store.write(0, 0, &odd.to_bytes());
        assert_eq!(inspect(&store, 0), Ok(SlotStatus::Invalid(HeaderError::Corrupt)));
    }
}
