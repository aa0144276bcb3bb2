//! Exported weights as a board keeps them: a checkpoint image (one slot
//! of `pada_core::checkpoint`, the file the host keeps for a board and
//! the flash slot a board reads at boot) of a fresh learner whose table
//! holds the exported entries. A board that boots from it continues as
//! `pada run --board B --weights` does ([`super::trial::BoardStart`]).

use super::image_store::VecStore;
use super::trial::{command, with_table, TableVisitor};
use crate::robots::SimRobot;
use anyhow::anyhow;
use pada_core::policy::PolicyKind;
use pada_core::profile::LearnerProfile;
use pada_core::weights::WeightStore;
use pada_core::wire::ToChip;
use pada_firmware::control::Controller;

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
            Ok(store.take_slot(saved.slot))
        }
    }
    with_table(&profile, n, Save { profile, robot, policy, budget: mtbf_budget_s, seed, entries })
}
