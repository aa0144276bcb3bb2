//! Checkpoints: round trip, alternating slots, torn writes at every byte,
//! configuration and size mismatches, corruption.

use pada_core::checkpoint::*;
use pada_core::fixed::Q16;

const N: usize = 100;
const SLOT: usize = slot_len(N) + 16;
type Store = RamStore<SLOT>;

fn weights(seed: i32) -> Vec<Q16> {
    (0..N as i32).map(|i| Q16(i.wrapping_mul(0x0101_0101).wrapping_add(seed) ^ (seed << 7))).collect()
}

#[test]
fn save_then_load_round_trips() {
    let mut store = Store::new();
    let w = weights(1);
    assert_eq!(save(&mut store, 42, &w), Ok(Saved { generation: 1, slot: 0 }));
    let mut out = vec![Q16::ZERO; N];
    assert_eq!(load(&store, 42, &mut out), Ok(LoadOutcome::Loaded { generation: 1, slot: 0 }));
    assert_eq!(out, w);
}

#[test]
fn saves_alternate_slots_and_load_takes_the_newest() {
    let mut store = Store::new();
    let mut out = vec![Q16::ZERO; N];
    for g in 1..=6u32 {
        let w = weights(g as i32);
        let saved = save(&mut store, 42, &w).unwrap();
        assert_eq!(saved, Saved { generation: g, slot: ((g - 1) % 2) as u8 });
        assert_eq!(load(&store, 42, &mut out), Ok(LoadOutcome::Loaded { generation: g, slot: saved.slot }));
        assert_eq!(out, w);
    }
}

#[test]
fn empty_store_has_no_checkpoint_and_weights_stay() {
    let store = Store::new();
    let mut out = vec![Q16(5); N];
    assert_eq!(load(&store, 42, &mut out), Ok(LoadOutcome::NoCheckpoint));
    assert!(out.iter().all(|w| *w == Q16(5)));
}

#[test]
fn config_mismatch_is_reported_and_weights_stay() {
    let mut store = Store::new();
    save(&mut store, config_hash(b"pendulum; tilings 16"), &weights(1)).unwrap();
    let mut out = vec![Q16(5); N];
    let running = config_hash(b"pendulum; tilings 8");
    assert_eq!(
        load(&store, running, &mut out),
        Ok(LoadOutcome::ConfigMismatch { expected: running, found: config_hash(b"pendulum; tilings 16") })
    );
    assert!(out.iter().all(|w| *w == Q16(5)));
}

#[test]
fn size_mismatch_is_reported() {
    let mut store = Store::new();
    save(&mut store, 42, &weights(1)[..50]).unwrap();
    let mut out = vec![Q16(5); N];
    assert_eq!(load(&store, 42, &mut out), Ok(LoadOutcome::SizeMismatch { expected: N as u32, found: 50 }));
    assert!(out.iter().all(|w| *w == Q16(5)));
}

#[test]
fn too_large_is_refused_before_touching_the_store() {
    let mut store = RamStore::<64>::new();
    assert_eq!(save(&mut store, 1, &weights(1)), Err(SaveError::TooLarge { needed: slot_len(N), capacity: 64 }));
    assert!(store.slot(0).unwrap().iter().all(|&b| b == 0xFF));
}

#[test]
fn a_corrupted_payload_is_rejected() {
    // The only checkpoint: every single-bit flip of its payload is caught.
    for byte in [HEADER_LEN, HEADER_LEN + 1, HEADER_LEN + 200, slot_len(N) - 1] {
        let mut store = Store::new();
        save(&mut store, 42, &weights(1)).unwrap();
        store.slot_mut(0).unwrap()[byte] ^= 0x10;
        let mut out = vec![Q16(5); N];
        assert_eq!(load(&store, 42, &mut out), Ok(LoadOutcome::Corrupt), "flip at {byte}");
        assert!(out.iter().all(|w| *w == Q16(5)));
        assert_eq!(inspect(&store, 0), Ok(SlotStatus::Invalid(HeaderError::Corrupt)));
    }
}

#[test]
fn a_corrupted_newest_checkpoint_falls_back_to_the_older() {
    let mut store = Store::new();
    let (w1, w2) = (weights(1), weights(2));
    save(&mut store, 42, &w1).unwrap();
    save(&mut store, 42, &w2).unwrap();
    store.slot_mut(1).unwrap()[HEADER_LEN + 17] ^= 0x01;
    let mut out = vec![Q16::ZERO; N];
    assert_eq!(load(&store, 42, &mut out), Ok(LoadOutcome::Loaded { generation: 1, slot: 0 }));
    assert_eq!(out, w1);
    // The next save overwrites the corrupted slot, not the good one.
    assert_eq!(save(&mut store, 42, &w2), Ok(Saved { generation: 2, slot: 1 }));
}

#[test]
fn a_future_format_is_reported() {
    let mut store = Store::new();
    let h = Header { version: FORMAT_VERSION + 1, config_hash: 1, weight_count: 0, generation: 1, payload_crc: 0 };
    store.write_bytes(0, &h.to_bytes());
    let mut out = vec![Q16::ZERO; N];
    assert_eq!(load(&store, 1, &mut out), Ok(LoadOutcome::UnsupportedVersion { found: FORMAT_VERSION + 1 }));
}

/// Helper: raw writes into a RAM store.
trait WriteBytes {
    fn write_bytes(&mut self, slot: u8, data: &[u8]);
}
impl WriteBytes for Store {
    fn write_bytes(&mut self, slot: u8, data: &[u8]) {
        self.slot_mut(slot).unwrap()[..data.len()].copy_from_slice(data);
    }
}

/// A store that loses power after `budget` more bytes have been written:
/// the write in progress is cut at that byte and every later operation fails.
struct TornStore {
    inner: Store,
    budget: usize,
    dead: bool,
}

#[derive(Debug, PartialEq)]
struct PowerLost;

impl CheckpointStore for TornStore {
    type Error = PowerLost;
    fn capacity(&self) -> usize {
        self.inner.capacity()
    }
    fn read(&self, slot: u8, offset: usize, buf: &mut [u8]) -> Result<(), PowerLost> {
        self.inner.read(slot, offset, buf).map_err(|_| PowerLost)
    }
    fn erase(&mut self, slot: u8) -> Result<(), PowerLost> {
        if self.dead {
            return Err(PowerLost);
        }
        self.inner.erase(slot).map_err(|_| PowerLost)
    }
    fn write(&mut self, slot: u8, offset: usize, data: &[u8]) -> Result<(), PowerLost> {
        if self.dead {
            return Err(PowerLost);
        }
        let n = data.len().min(self.budget);
        self.inner.write(slot, offset, &data[..n]).map_err(|_| PowerLost)?;
        self.budget -= n;
        if n < data.len() || self.budget == 0 {
            self.dead = true;
            if n < data.len() {
                return Err(PowerLost);
            }
        }
        Ok(())
    }
}

#[test]
fn a_torn_second_save_at_every_byte_keeps_the_first() {
    let (w1, w2) = (weights(1), weights(2));
    let total = slot_len(N);
    for budget in 0..total {
        let mut base = Store::new();
        save(&mut base, 42, &w1).unwrap();
        let mut torn = TornStore { inner: base, budget, dead: false };
        let r = save(&mut torn, 42, &w2);
        assert!(r.is_err(), "budget {budget}: a torn save must not report success");
        // After the power cut: the first checkpoint loads.
        let mut out = vec![Q16::ZERO; N];
        assert_eq!(
            load(&torn.inner, 42, &mut out),
            Ok(LoadOutcome::Loaded { generation: 1, slot: 0 }),
            "budget {budget}"
        );
        assert_eq!(out, w1, "budget {budget}");
        // And the next save goes to the torn slot again and succeeds.
        let mut store = torn.inner;
        assert_eq!(save(&mut store, 42, &w2), Ok(Saved { generation: 2, slot: 1 }), "budget {budget}");
    }
    // With the whole budget the save completes.
    let mut base = Store::new();
    save(&mut base, 42, &w1).unwrap();
    let mut full = TornStore { inner: base, budget: total, dead: false };
    assert_eq!(save(&mut full, 42, &w2), Ok(Saved { generation: 2, slot: 1 }));
}

#[test]
fn a_torn_third_save_keeps_the_second() {
    // The same from the other slot: torn writes into slot 0 while slot 1
    // holds the newest.
    let total = slot_len(N);
    for budget in (0..total).step_by(7) {
        let mut base = Store::new();
        save(&mut base, 42, &weights(1)).unwrap();
        save(&mut base, 42, &weights(2)).unwrap();
        let mut torn = TornStore { inner: base, budget, dead: false };
        assert!(save(&mut torn, 42, &weights(3)).is_err());
        let mut out = vec![Q16::ZERO; N];
        assert_eq!(load(&torn.inner, 42, &mut out), Ok(LoadOutcome::Loaded { generation: 2, slot: 1 }));
        assert_eq!(out, weights(2));
    }
}

#[test]
fn garbage_slots_are_corrupt_not_empty() {
    let mut store = Store::new();
    store.slot_mut(0).unwrap().fill(0x00);
    let mut out = vec![Q16::ZERO; N];
    assert_eq!(load(&store, 1, &mut out), Ok(LoadOutcome::Corrupt));
    // A valid checkpoint next to garbage still loads.
    save(&mut store, 1, &weights(9)).unwrap();
    assert!(matches!(load(&store, 1, &mut out), Ok(LoadOutcome::Loaded { generation: 1, .. })));
}

#[test]
fn header_claiming_more_weights_than_fit_is_corrupt() {
    let mut store = Store::new();
    let h = Header { version: FORMAT_VERSION, config_hash: 1, weight_count: u32::MAX, generation: 5, payload_crc: 0 };
    store.write_bytes(0, &h.to_bytes());
    assert_eq!(inspect(&store, 0), Ok(SlotStatus::Invalid(HeaderError::Corrupt)));
}
