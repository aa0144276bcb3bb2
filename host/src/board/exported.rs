//! Exported weights as a board keeps them: a checkpoint image (one slot
//! of `pada_core::checkpoint`, the file the host keeps for a board and
//! the flash slot a board reads at boot) of a fresh learner whose table
//! holds the exported entries. A board that boots from it continues as
//! `pada run --board B --weights` does ([`super::trial::BoardStart`]).

use super::trial::{command, with_table, TableVisitor};
use crate::robots::SimRobot;
use anyhow::{anyhow, bail};
use pada_core::checkpoint::{CheckpointStore, LoadOutcome};
use pada_core::policy::PolicyKind;
use pada_core::profile::LearnerProfile;
use pada_core::robot::RobotRules;
use pada_core::weights::WeightStore;
use pada_core::wire::ToChip;
use pada_firmware::control::Controller;

/// Two checkpoint slots in memory, of any size (a board's table may be
/// megabytes), erased to `0xFF` as flash is.
pub struct VecStore {
    slots: [Vec<u8>; 2],
}

/// An access outside a [`VecStore`]'s slots.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OutOfSlot;

impl VecStore {
    /// Two erased slots of `len` bytes.
    pub fn erased(len: usize) -> VecStore {
        VecStore { slots: [vec![0xFF; len], vec![0xFF; len]] }
    }

    /// Slot 0 holding `image`, slot 1 erased.
    pub fn holding(image: &[u8]) -> VecStore {
        VecStore { slots: [image.to_vec(), vec![0xFF; image.len()]] }
    }

    fn range(&self, slot: u8, offset: usize, len: usize) -> Result<(usize, core::ops::Range<usize>), OutOfSlot> {
        let end = offset.checked_add(len).ok_or(OutOfSlot)?;
        let s = slot as usize;
        if s < 2 && end <= self.slots[s].len() {
            Ok((s, offset..end))
        } else {
            Err(OutOfSlot)
        }
    }
}

impl CheckpointStore for VecStore {
    type Error = OutOfSlot;
    fn capacity(&self) -> usize {
        self.slots[0].len()
    }
    fn read(&self, slot: u8, offset: usize, buf: &mut [u8]) -> Result<(), OutOfSlot> {
        let (s, r) = self.range(slot, offset, buf.len())?;
        buf.copy_from_slice(&self.slots[s][r]);
        Ok(())
    }
    fn erase(&mut self, slot: u8) -> Result<(), OutOfSlot> {
        self.slots.get_mut(slot as usize).ok_or(OutOfSlot)?.fill(0xFF);
        Ok(())
    }
    fn write(&mut self, slot: u8, offset: usize, data: &[u8]) -> Result<(), OutOfSlot> {
        let (s, r) = self.range(slot, offset, data.len())?;
        for (dst, src) in self.slots[s][r].iter_mut().zip(data) {
            *dst &= *src;
        }
        Ok(())
    }
}

/// Loads `image` into `ctl` as the firmware loads its checkpoint at boot;
/// anything but a loaded checkpoint is an error naming the outcome.
pub fn load_image<W: WeightStore, R: RobotRules>(ctl: &mut Controller<W, R>, image: &[u8]) -> anyhow::Result<()> {
    let store = VecStore::holding(image);
    match ctl.load_checkpoint(&store).map_err(|e| anyhow!("the checkpoint image: {e:?}"))? {
        LoadOutcome::Loaded { .. } => Ok(()),
        other => bail!(
            "the checkpoint image was not loaded: {other:?}{}",
            ctl.last_refusal().map(|e| format!(" ({e})")).unwrap_or_default()
        ),
    }
}

/// The checkpoint image of board trial `seed`'s learner with `policy` (and
/// the wear budget, if any) after `entries` were imported: what a board
/// keeps to start from exported weights.
pub fn image_of(
    profile: LearnerProfile,
    robot: &SimRobot,
    policy: PolicyKind,
    mtbf_budget_s: Option<f32>,
    seed: u64,
    n: usize,
    entries: &[u8],
) -> anyhow::Result<Vec<u8>> {
    struct Save<'a> {
        profile: LearnerProfile,
        robot: &'a SimRobot,
        policy: PolicyKind,
        budget: Option<f32>,
        seed: u64,
        entries: &'a [u8],
    }
    impl TableVisitor for Save<'_> {
        type Output = Vec<u8>;
        fn visit<W: WeightStore>(self, table: W) -> anyhow::Result<Vec<u8>> {
            let rules = self.robot.rules();
            let mut ctl = Controller::new(rules, self.profile, PolicyKind::Sarsa, table, self.seed).map_err(|e| anyhow!("{e}"))?;
            command(&mut ctl, ToChip::SetPolicy(self.policy))?;
            if let Some(b) = self.budget {
                command(&mut ctl, ToChip::SetMtbfBudget(Some(b)))?;
            }
            ctl.import_entries(self.entries).map_err(|e| anyhow!("the exported weights: {e}"))?;
            let mut store = VecStore::erased(ctl.checkpoint_bytes());
            let saved = ctl.save_checkpoint(&mut store).map_err(|e| anyhow!("saving the checkpoint image: {e:?}"))?;
            Ok(std::mem::take(&mut store.slots[saved.slot as usize & 1]))
        }
    }
    with_table(&profile, n, Save { profile, robot, policy, budget: mtbf_budget_s, seed, entries })
}
