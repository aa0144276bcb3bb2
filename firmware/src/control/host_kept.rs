//! A checkpoint the host keeps, for a board whose table fits no flash
//! (LEO's 8 MiB claim table on the F429): the controller's side. A save is
//! the learner's image ([`Controller::host_save`]: the same bytes a flash
//! slot would hold, [`pada_core::checkpoint::stream`]) streamed while
//! torque is off; a restore at boot writes the host's chunks straight into
//! the table through a [`RestoreSink`] and restores the learner's state
//! once the image is whole and checked ([`Controller::finish_host_restore`]).
//!
//! Consistency: the learner does not change while its image streams. The
//! host pauses the robot for a save (`Pause`, `SaveCheckpoint`, `Start`),
//! and the control loop takes no command and runs no period until the
//! last chunk is queued, so a restored learner is one that existed.

use super::persist::CheckpointError;
use super::{Controller, Phase};
use pada_core::robot::RobotRules;
use pada_core::checkpoint::stream::ImageSink;
use pada_core::checkpoint::{LearnerState, HEADER_LEN, STATE_LEN};
use pada_core::weights::WeightStore;
use pada_core::wire::RestoreOutcome;

/// A save to the host, ready to stream: its generation and the learner's
/// record (the table is the controller's own, held still meanwhile).
#[derive(Debug, Clone)]
pub struct HostSave {
    /// The checkpoint's generation: one after the last saved or restored.
    pub generation: u32,
    /// The learner-state record, as a slot holds it.
    pub record: [u8; STATE_LEN],
}

/// Why a restore's write does not fit the table: a window not on whole
/// entries (never, for a stream of this board's own image length).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Misaligned {
    /// The image offset of the write.
    pub offset: usize,
    /// Its bytes.
    pub len: usize,
}

/// Where a restored image goes: the header is the assembler's to check,
/// the learner-state record is kept for [`Controller::finish_host_restore`],
/// the entries go straight into the table.
pub struct RestoreSink<'a, W: ?Sized> {
    weights: &'a mut W,
    record: [u8; STATE_LEN],
    /// Some entry was written: a restore that fails now leaves a table
    /// that is neither the old one nor the host's.
    touched: bool,
}

impl<'a, W: WeightStore + ?Sized> RestoreSink<'a, W> {
    /// The learner-state record received.
    pub fn record(&self) -> &[u8; STATE_LEN] {
        &self.record
    }

    /// Whether any table entry was written.
    pub fn touched(&self) -> bool {
        self.touched
    }

    /// Writes `len` bytes at image offset `offset`, each byte from `byte(i)`.
    fn put(&mut self, offset: usize, len: usize, byte: impl Fn(usize) -> u8) -> Result<(), Misaligned> {
        let entries_at = HEADER_LEN + STATE_LEN;
        let end = offset + len;
        // Header bytes: checked by the assembler, nothing to keep. The
        // record's bytes in this write, and only those (a run of zero
        // windows covers megabytes of entries).
        for at in offset.max(HEADER_LEN)..end.min(entries_at) {
            self.record[at - HEADER_LEN] = byte(at - offset);
        }
        if end <= entries_at {
            return Ok(());
        }
        let start = offset.max(entries_at);
        let entry = self.weights.entry_bytes();
        if (start - entries_at) % entry != 0 || (end - start) % entry != 0 {
            return Err(Misaligned { offset, len });
        }
        let mut bytes = [0u8; 8];
        let mut at = start;
        while at < end {
            let index = (at - entries_at) / entry;
            // Past the last entry: the slot's padding to a whole word.
            if index >= self.weights.len() {
                break;
            }
            for (k, b) in bytes[..entry].iter_mut().enumerate() {
                *b = byte(at - offset + k);
            }
            self.weights.load_le(index, &bytes[..entry]);
            self.touched = true;
            at += entry;
        }
        Ok(())
    }
}

impl<'a, W: WeightStore + ?Sized> ImageSink for RestoreSink<'a, W> {
    type Error = Misaligned;

    fn write(&mut self, offset: usize, bytes: &[u8]) -> Result<(), Misaligned> {
        self.put(offset, bytes.len(), |i| bytes[i])
    }

    fn write_zeros(&mut self, offset: usize, len: usize) -> Result<(), Misaligned> {
        self.put(offset, len, |_| 0)
    }
}

impl<W, R> Controller<W, R>
where
    W: WeightStore,
    R: RobotRules,
{
    /// Whether this board's checkpoint is the host's to keep: larger than
    /// a flash slot of `slot_bytes`.
    pub fn host_keeps_checkpoint(&self, slot_bytes: usize) -> bool {
        self.checkpoint_bytes() > slot_bytes
    }

    /// The generation of the last checkpoint saved to or restored from the
    /// host (0: none this boot).
    pub fn host_generation(&self) -> u32 {
        self.host_generation
    }

    /// Starts a save to the host: only while torque is off (the learner
    /// stands still while it streams). The caller streams
    /// `TableImage::new(config_hash, generation, &record, weights)`.
    pub fn host_save(&mut self) -> Result<HostSave, CheckpointError<core::convert::Infallible>> {
        if self.torque_enabled() {
            return Err(CheckpointError::Busy);
        }
        // 0 is never a generation (a fresh board has none).
        let generation = self.host_generation.wrapping_add(1).max(1);
        self.host_generation = generation;
        Ok(HostSave { generation, record: self.learner_state().to_bytes() })
    }

    /// The sink of a restore into this learner's table; only at boot, with
    /// torque off. After it, [`finish_host_restore`](Self::finish_host_restore)
    /// or, if the stream failed, [`abandon_host_restore`](Self::abandon_host_restore).
    pub fn restore_sink(&mut self) -> RestoreSink<'_, W> {
        RestoreSink { weights: self.agent_mut().weights_mut(), record: [0; STATE_LEN], touched: false }
    }

    /// Restores the learner's state from a whole, checked image of
    /// `generation` whose entries are in the table and whose record is
    /// `record` ([`RestoreSink::record`]), received in `chunks` chunks;
    /// a record that does not decode or is out of range for the running
    /// learner leaves a fresh learner, and says so.
    pub fn finish_host_restore(&mut self, record: &[u8; STATE_LEN], generation: u32, chunks: u32) -> RestoreOutcome {
        self.last_refusal = None;
        let state = match LearnerState::from_bytes(record) {
            Ok(state) => state,
            Err(e) => return self.refuse_host_restore(e),
        };
        if let Err(e) = self.check_learner_state(&state) {
            return self.refuse_host_restore(e);
        }
        self.agent_mut().rehash();
        if let Err(e) = self.restore_learner_state(&state) {
            return self.refuse_host_restore(e);
        }
        self.note_stored_wear(state.wear);
        self.host_generation = generation;
        RestoreOutcome::Loaded { generation, chunks }
    }

    /// A whole image whose learner state is refused (`why`): counted, the
    /// field kept for the log, a fresh learner.
    fn refuse_host_restore(&mut self, why: pada_core::error::ConfigError) -> RestoreOutcome {
        self.checkpoints_refused = self.checkpoints_refused.saturating_add(1);
        self.last_refusal = Some(why);
        self.abandon_host_restore(true);
        RestoreOutcome::InvalidState
    }

    /// A restore that did not complete: if it wrote any entry (`touched`),
    /// the learner is rebuilt fresh from the seed, as at boot; never left
    /// half restored.
    pub fn abandon_host_restore(&mut self, touched: bool) {
        if touched {
            self.rebuild();
        }
        self.phase = Phase::Stopped;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::test_support::*;
    use pada_core::checkpoint::stream::{Assembler, Chunk, Chunker, Expect, Order, Progress, TableImage};
    use pada_core::fixed::Q16;
    use pada_core::policy::PolicyKind;
    use pada_core::safety::RunMode;

    type PendulumCtl = Controller<Box<[Q16]>, Pendulum>;

    fn learned(seed: u64) -> PendulumCtl {
        let mut c = PendulumCtl::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Pada { delta: 0.5 }, table(), seed).unwrap();
        start(&mut c, RunMode::Learning);
        let mut angle = 0.0;
        assert!(run_pendulum(&mut c, &mut angle, 0, 1500).len() > 300);
        stop(&mut c);
        c
    }

    /// The chunks of `c`'s next save, header first (as the host sends it
    /// back).
    fn restore_chunks(c: &mut PendulumCtl) -> (u32, std::vec::Vec<Chunk>) {
        let save = c.host_save().unwrap();
        let image = TableImage::new(c.config_hash(), save.generation, &save.record, c.weights()).unwrap();
        (save.generation, Chunker::new(&image, Order::HeaderFirst).unwrap().collect())
    }

    /// Feeds `chunks` into `c` as the boot's restore does.
    fn restore(c: &mut PendulumCtl, chunks: &[Chunk]) -> RestoreOutcome {
        let expect = Expect {
            config_hash: Some(c.config_hash()),
            image_len: Some(c.checkpoint_bytes() as u32),
            newer_than: None,
        };
        let mut assembler = Assembler::new(c.restore_sink(), Order::HeaderFirst, expect);
        for chunk in chunks {
            match assembler.accept(chunk) {
                Ok(Progress::Complete(header)) => {
                    let record = *assembler.sink().record();
                    drop(assembler);
                    return c.finish_host_restore(&record, header.generation, chunks.len() as u32);
                }
                Ok(_) => {}
                Err(_) => {
                    let (offset, touched) = (assembler.expected_offset(), assembler.sink().touched());
                    drop(assembler);
                    c.abandon_host_restore(touched);
                    return RestoreOutcome::ChunkRefused { offset };
                }
            }
        }
        let touched = assembler.sink().touched();
        drop(assembler);
        c.abandon_host_restore(touched);
        RestoreOutcome::NoAnswer { waited_ms: 0 }
    }

    #[test]
    fn a_learner_streamed_to_the_host_and_back_is_the_same_learner() {
        let mut a = learned(11);
        assert_eq!(a.host_generation(), 0);
        let (generation, chunks) = restore_chunks(&mut a);
        assert_eq!((generation, a.host_generation()), (1, 1));
        // Torque on: no save (the learner would change while it streams).
        start(&mut a, RunMode::Learning);
        assert!(matches!(a.host_save(), Err(CheckpointError::Busy)));
        stop(&mut a);

        let mut b = PendulumCtl::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 99).unwrap();
        assert_ne!(b.weights(), a.weights());
        assert_eq!(restore(&mut b, &chunks), RestoreOutcome::Loaded { generation: 1, chunks: chunks.len() as u32 });
        assert_eq!(b.weights(), a.weights());
        assert_eq!(b.agent().weights_checksum(), a.agent().weights_checksum());
        assert_eq!(b.policy(), PolicyKind::Pada { delta: 0.5 });
        assert_eq!(b.host_generation(), 1, "the next save is generation 2");
        let (a_state, b_state) = (a.learner_state(), b.learner_state());
        assert_eq!(b_state.agent, a_state.agent);
        assert_eq!((b_state.rng, b_state.user, b_state.joints), (a_state.rng, a_state.user, a_state.joints));

        // Both learn on the same way.
        start(&mut a, RunMode::Learning);
        start(&mut b, RunMode::Learning);
        let (mut x, mut y) = (0.0, 0.0);
        let sa = run_pendulum(&mut a, &mut x, 0, 900);
        let sb = run_pendulum(&mut b, &mut y, 0, 900);
        assert!(sa.len() > 300);
        // The same steps, but for the board's own step counter and clock
        // (a restored board counts from its boot).
        let what =
            |s: &pada_core::wire::Step| (s.episode, s.mode, s.kind, s.action, s.state.clone(), s.reward, s.td_error);
        assert_eq!(sa.len(), sb.len());
        let first_difference = sa.iter().zip(&sb).position(|(x, y)| what(x) != what(y));
        assert_eq!(first_difference, None);
        assert_eq!(a.agent().weights_checksum(), b.agent().weights_checksum());
    }

    #[test]
    fn a_restore_that_fails_half_way_leaves_a_fresh_learner() {
        let mut a = learned(5);
        let (_, mut chunks) = restore_chunks(&mut a);
        let fresh = PendulumCtl::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 99).unwrap();
        let fresh_checksum = fresh.agent().weights_checksum();

        // Cut short: entries written, never completed.
        let mut b = PendulumCtl::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 99).unwrap();
        assert_eq!(restore(&mut b, &chunks[..chunks.len() / 2]), RestoreOutcome::NoAnswer { waited_ms: 0 });
        assert_eq!(b.agent().weights_checksum(), fresh_checksum);
        assert_eq!(b.weights(), fresh.weights());
        assert_eq!(b.host_generation(), 0);

        // A corrupt chunk in the middle: refused at its offset.
        let k = chunks.len() / 2;
        chunks[k].crc ^= 1;
        let offset = chunks[k].offset;
        let mut c = PendulumCtl::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 99).unwrap();
        assert_eq!(restore(&mut c, &chunks), RestoreOutcome::ChunkRefused { offset });
        assert_eq!(c.weights(), fresh.weights());

        // A record out of range for this learner (ε of 2): a fresh learner,
        // the field named.
        let mut state = a.learner_state();
        state.agent.epsilon = 2.0;
        let record = state.to_bytes();
        let image = TableImage::new(a.config_hash(), 9, &record, a.weights()).unwrap();
        let bad: std::vec::Vec<Chunk> = Chunker::new(&image, Order::HeaderFirst).unwrap().collect();
        let mut d = PendulumCtl::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 99).unwrap();
        assert_eq!(restore(&mut d, &bad), RestoreOutcome::InvalidState);
        assert_eq!(d.last_refusal().map(|e| e.param), Some("epsilon"));
        assert_eq!(d.checkpoints_refused(), 1);
        assert_eq!(d.weights(), fresh.weights());

        // Another configuration's image: refused at the header, nothing
        // written.
        let other = TableImage::new(a.config_hash() ^ 1, 3, &record, a.weights()).unwrap();
        let other: std::vec::Vec<Chunk> = Chunker::new(&other, Order::HeaderFirst).unwrap().collect();
        let mut e = PendulumCtl::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 99).unwrap();
        assert_eq!(restore(&mut e, &other), RestoreOutcome::ChunkRefused { offset: 0 });
        assert_eq!(e.weights(), fresh.weights());
    }
}
