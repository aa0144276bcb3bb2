//! Saved learning: the learner's state as a checkpoint record (the
//! agent's, the generator, every servo's fatigue counter, the episode
//! counters, the wear governor), its checks and restore, saving and
//! loading with torque off, and the flash's erase budget (the operating
//! time and the sectors' erase counts).

use super::{Controller, Phase};
use crate::config::MAX_ROBOT_SERVOS;
use pada_core::robot::RobotRules;
use heapless::Vec;
use pada_core::checkpoint::{self, CheckpointStore, FlashWear, LearnerState, LoadOutcome, SaveError, Saved, WearBudget};
use pada_core::error::ConfigError;
use pada_core::fatigue::FatigueError;
use pada_core::governor::Governor;
use pada_core::rng::Pcg32;
use pada_core::weights::WeightStore;

/// A fatigue error as a configuration error (same name and range).
fn fatigue_error(e: FatigueError) -> ConfigError {
    match e {
        FatigueError::InvalidParameter { param, value, valid } => ConfigError::new(param, value as f32, valid),
        _ => ConfigError::new("fatigue", 0.0, "finite torques"),
    }
}

/// The record has room for every servo's fatigue counter.
const _: () = assert!(MAX_ROBOT_SERVOS <= checkpoint::RECORD_JOINTS);

/// Why a checkpoint operation of the controller failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CheckpointError<E> {
    /// Torque is on: checkpoints are saved and loaded only with torque off
    /// (an erase stalls the CPU; a load replaces the learner).
    Busy,
    /// The save failed; the previous checkpoint is intact.
    Save(SaveError<E>),
    /// Reading the store failed.
    Store(E),
}

/// The user counters of the firmware's learner-state record.
mod user {
    /// Episodes started since the first boot (the next episode's index).
    pub const EPISODES: usize = 0;
    /// Learning episodes since the last test episode.
    pub const SINCE_TEST: usize = 1;
}

impl<W, R> Controller<W, R>
where
    W: WeightStore,
    R: RobotRules,
{
    /// The learner's state besides its weights, as a checkpoint saves it:
    /// the agent's ([`pada_core::agent::AgentState`]), the generator, every
    /// servo's fatigue counter, and the episode counters (user counters 0:
    /// episodes started, 1: learning episodes since the last test).
    pub fn learner_state(&self) -> LearnerState {
        let mut user = [0u32; checkpoint::USER_COUNTERS];
        user[user::EPISODES] = self.episodes.started();
        user[user::SINCE_TEST] = self.episodes.since_test();
        LearnerState {
            agent: self.agent().state(),
            rng: self.rng.state(),
            // Fits: MAX_ROBOT_SERVOS <= RECORD_JOINTS (checked at compile time).
            joints: Vec::from_slice(&self.fatigue.state()).unwrap_or_default(),
            user,
            wear: FlashWear { erases: self.flash_wear.erases, operating_s: self.operating_s() },
            governor: self.governor.as_ref().map(Governor::state),
        }
    }

    /// Seconds this board has operated: before this boot (as the
    /// checkpoints carried it) and the control periods since, each the
    /// robot's period in whole µs (no float on the way).
    pub fn operating_s(&self) -> u64 {
        let period_us = u64::from(self.spec.period_us);
        self.operating_before_s.saturating_add(self.periods.saturating_mul(period_us) / 1_000_000)
    }

    /// The checkpoint sectors' erase counts as far as known.
    pub fn flash_wear(&self) -> FlashWear {
        self.flash_wear
    }

    /// Saves refused since boot to keep the flash within its erase budget.
    pub fn saves_refused(&self) -> u32 {
        self.saves_refused
    }

    /// Takes in the wear the store's newest checkpoint recorded (whatever
    /// its configuration): erase counts and the operating time before this
    /// boot.
    pub(super) fn note_stored_wear(&mut self, stored: FlashWear) {
        self.flash_wear = self.flash_wear.max(&stored);
        let since_boot = self.operating_s() - self.operating_before_s;
        self.operating_before_s = self.operating_before_s.max(stored.operating_s.saturating_sub(since_boot));
    }

    /// Checks that `state` can be restored into this controller; the error
    /// names the first field out of range and its valid range: the agent's
    /// ([`pada_core::agent::Agent::check_state`]), the fatigue counters (one
    /// per servo, [`FatigueCounter::check_state`](pada_core::fatigue::FatigueCounter::check_state)), the generator's
    /// increment, learning episodes since the last test within the robot's
    /// test interval, unused user counters 0, and the wear governor's
    /// state for the saved policy and budget
    /// ([`Governor::check_state`]).
    pub fn check_learner_state(&self, state: &LearnerState) -> Result<(), ConfigError> {
        self.agent().check_state(&state.agent)?;
        if let Some(g) = &state.governor {
            self.governor_for(&state.agent.policy.kind, g.budget_s())?.check_state(g)?;
        }
        self.fatigue.check_state(&state.joints).map_err(fatigue_error)?;
        state.rng.check()?;
        let since_test = state.user[user::SINCE_TEST];
        if since_test > self.spec.test_interval {
            return Err(ConfigError::new(
                "since_test",
                since_test as f32,
                "learning episodes since the last test <= the robot's test interval",
            ));
        }
        if let Some(i) = (user::SINCE_TEST + 1..checkpoint::USER_COUNTERS).find(|&i| state.user[i] != 0) {
            return Err(ConfigError::new("user", state.user[i] as f32, "0 (unused)").at(i));
        }
        Ok(())
    }

    /// Restores a state that passed [`check_learner_state`](Self::check_learner_state)
    /// (the caller's to call first: each part below checks itself again, but
    /// only the whole check makes the restore all or nothing). The agent's
    /// episode ends (traces are not saved); the next Start brings the robot
    /// to its start and begins a new one.
    pub(super) fn restore_learner_state(&mut self, state: &LearnerState) -> Result<(), ConfigError> {
        let rng = Pcg32::from_state(state.rng)?;
        let governor = match &state.governor {
            Some(g) => {
                let mut governor = self.governor_for(&state.agent.policy.kind, g.budget_s())?;
                governor.restore(g)?;
                Some(governor)
            }
            None => None,
        };
        self.fatigue.restore(&state.joints).map_err(fatigue_error)?;
        let agent = self.agent_mut();
        agent.restore_state(&state.agent)?;
        // The governor's rung decides the parameter in force.
        if let Some(g) = &governor {
            agent.set_policy_parameter(g.parameter())?;
        }
        let policy = agent.policy().built_kind();
        let previous = agent.policy().learner_space().encode(&agent.policy().previous());
        self.policy = policy;
        self.rng = rng;
        self.episodes.restore(state.user[user::EPISODES], state.user[user::SINCE_TEST], previous);
        self.last_output = [0.0; pada_core::action_space::MAX_ACTION_DIMS];
        self.governor = governor;
        // Torque is off (the callers check): no episode runs.
        self.phase = Phase::Stopped;
        Ok(())
    }

    /// Saves the weights and the learner's state ([`learner_state`](Self::learner_state))
    /// into `store` (the slot not holding the newest checkpoint); only while
    /// torque is off, and only within the flash's erase budget
    /// ([`WearBudget::STM32F4`]: a refused save is
    /// `CheckpointError::Save(SaveError::Wear(..))`, counted in
    /// [`saves_refused`](Self::saves_refused), and erases nothing). A
    /// checkpoint larger than a slot
    /// ([`checkpoint_bytes`](Self::checkpoint_bytes) > `store.capacity()`:
    /// the F429's 8 MiB LEO table against a 128 KiB flash sector) is refused
    /// as `SaveError::TooLarge` before the store is touched; every other
    /// failed save counts in [`saves_failed`](Self::saves_failed), and the
    /// erase of one that failed after erasing ([`SaveError::erased`]) counts
    /// in the [`flash_wear`](Self::flash_wear) the next save records.
    pub fn save_checkpoint<S: CheckpointStore>(&mut self, store: &mut S) -> Result<Saved, CheckpointError<S::Error>> {
        if self.torque_enabled() {
            return Err(CheckpointError::Busy);
        }
        let state = self.learner_state();
        let result = checkpoint::save_within(store, self.config_hash, &state, self.weights(), &WearBudget::STM32F4);
        match result {
            Ok(saved) => {
                let slot = saved.slot as usize & 1;
                self.flash_wear.erases[slot] = self.flash_wear.erases[slot].max(saved.erases);
            }
            Err(SaveError::Wear(_)) => self.saves_refused = self.saves_refused.saturating_add(1),
            Err(ref e) => {
                // A save that failed after its erase leaves no valid record
                // of that erase in the slot: keep the count here, so that
                // the next save records it and the budget sees it.
                if let Some((slot, erases)) = e.erased() {
                    let slot = slot as usize & 1;
                    self.flash_wear.erases[slot] = self.flash_wear.erases[slot].max(erases);
                }
                self.saves_failed = self.saves_failed.saturating_add(1);
            }
        }
        result.map_err(CheckpointError::Save)
    }

    /// Bytes a checkpoint of this learner takes in a slot: header, learner
    /// state and the whole table.
    pub fn checkpoint_bytes(&self) -> usize {
        checkpoint::slot_len(self.weights().len(), self.weights().entry_bytes())
    }

    /// Saves that failed since boot (too large for a slot, the store
    /// failing, or a read-back that did not verify); a save refused because
    /// torque was on, or to spare the flash ([`saves_refused`](Self::saves_refused)),
    /// is not counted here.
    pub fn saves_failed(&self) -> u32 {
        self.saves_failed
    }

    /// Loads the newest checkpoint of `store` — weights and learner state —
    /// if it was saved with this configuration and its state passes
    /// [`check_learner_state`](Self::check_learner_state); only while torque
    /// is off. Otherwise nothing changes and the outcome says why
    /// ([`LoadOutcome::InvalidState`] for a refused state:
    /// [`last_refusal`](Self::last_refusal) names the field); every
    /// checkpoint found but not loaded counts in
    /// [`checkpoints_refused`](Self::checkpoints_refused).
    ///
    /// If the store fails while the weights are copied, the learner is
    /// rebuilt fresh from the seed (as after `SetPolicy`), never left half
    /// loaded.
    pub fn load_checkpoint<S: CheckpointStore>(&mut self, store: &S) -> Result<LoadOutcome, CheckpointError<S::Error>> {
        if self.torque_enabled() {
            return Err(CheckpointError::Busy);
        }
        self.last_refusal = None;
        let stored = checkpoint::stored_wear(store).map_err(CheckpointError::Store)?;
        self.note_stored_wear(stored);
        let weight_count = self.weights().len();
        let found = match checkpoint::find(store, self.config_hash, weight_count).map_err(CheckpointError::Store)? {
            Ok(found) => found,
            Err(outcome) => {
                if outcome != LoadOutcome::NoCheckpoint {
                    self.checkpoints_refused = self.checkpoints_refused.saturating_add(1);
                }
                return Ok(outcome);
            }
        };
        if let Err(e) = self.check_learner_state(&found.state) {
            self.checkpoints_refused = self.checkpoints_refused.saturating_add(1);
            self.last_refusal = Some(e);
            return Ok(LoadOutcome::InvalidState);
        }
        let read = checkpoint::read_weights(store, &found, self.agent_mut().weights_mut());
        self.agent_mut().rehash();
        let outcome = match read {
            Ok(outcome) => outcome,
            Err(e) => {
                self.rebuild();
                return Err(CheckpointError::Store(e));
            }
        };
        if let LoadOutcome::Loaded { .. } = outcome {
            // Checked above, so this restores.
            if let Err(e) = self.restore_learner_state(&found.state) {
                self.last_refusal = Some(e);
            }
        } else {
            self.checkpoints_refused = self.checkpoints_refused.saturating_add(1);
        }
        Ok(outcome)
    }

    /// A fresh learner with the running policy (generator reseeded, weights
    /// initialised).
    pub(super) fn rebuild(&mut self) {
        if let Some(agent) = self.agent.take() {
            // The running policy built before, so it builds again.
            let _ = self.build(self.policy, agent.into_weights());
        }
    }

    /// Checkpoints found but not loaded since boot (another configuration
    /// or size, another format version, corrupt slots, or a learner state
    /// out of range); an empty store is not counted.
    pub fn checkpoints_refused(&self) -> u32 {
        self.checkpoints_refused
    }

    /// Why the last load's learner state was refused by
    /// [`check_learner_state`](Self::check_learner_state) (the field and its
    /// valid range); `None` when the last load refused nothing for that
    /// reason (an undecodable record is [`LoadOutcome::InvalidState`] with
    /// `None` here).
    pub fn last_refusal(&self) -> Option<ConfigError> {
        self.last_refusal
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::test_support::*;
    use crate::config::{Board, TILINGS, TRACE};
    use crate::control::{PeriodOutput, Readings};
    use core::cell::Cell;
    use pada_core::agent::{EpisodeEnd, Mode};
    use pada_core::fixed::Q16;
    use pada_core::policy::PolicyKind;
    use pada_core::profile::config_hash;
    use pada_core::robot::pendulum::EXACT_WEIGHTS as WEIGHTS;
    use pada_core::robot::RobotRules;
    use pada_core::safety::RunMode;
    use pada_core::wire::{self, StepKind};

    #[test]
    fn a_checkpoint_carries_the_governor() {
        let mut store = Store::new();
        let mut a = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Pada { delta: 0.5 }, table(), 5).unwrap();
        assert_eq!(a.command(&wire::ToChip::SetMtbfBudget(Some(TEST_BUDGET_S))).0, Ok(()));
        start(&mut a, RunMode::Learning);
        let mut angle = 0.0;
        run_governed(&mut a, &mut angle, 2000);
        stop(&mut a);
        let governor = a.governor().unwrap().clone();
        assert!(governor.state().steps > 1000);
        a.save_checkpoint(&mut store).unwrap();

        let mut b = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Pada { delta: 0.5 }, table(), 99).unwrap();
        assert_eq!(b.load_checkpoint(&store), Ok(LoadOutcome::Loaded { generation: 1, slot: 0 }));
        assert_eq!(b.governor(), Some(&governor));
        assert_eq!(b.policy(), a.policy(), "the governor's rung is the Δ in force");
        assert_eq!(b.learner_state(), a.learner_state());
        // Both go on the same way (from the pendulum hanging still, as
        // after a reset).
        start(&mut a, RunMode::Learning);
        start(&mut b, RunMode::Learning);
        let (mut x, mut y) = (0.0, 0.0);
        let sa = run_governed(&mut a, &mut x, 1500);
        let sb = run_governed(&mut b, &mut y, 1500);
        assert!(sa.len() > 300);
        assert_eq!(sa.len(), sb.len());
        assert!(b.governor().unwrap().state().steps > governor.state().steps + 300);
        assert_eq!(a.governor(), b.governor());
        assert_eq!(a.agent().weights_checksum(), b.agent().weights_checksum());
    }

    #[test]
    fn a_checkpoint_carries_the_learner_across_a_reset() {
        let mut store = Store::new();
        let mut a = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Pada { delta: 0.5 }, table(), 11).unwrap();
        start(&mut a, RunMode::Learning);
        // Only with torque off.
        assert_eq!(a.save_checkpoint(&mut store), Err(CheckpointError::Busy));
        assert_eq!(a.load_checkpoint(&store), Err(CheckpointError::Busy));
        let mut angle = 0.0;
        let before = run_pendulum(&mut a, &mut angle, 0, 1500);
        assert!(before.len() > 300);
        stop(&mut a);
        assert!(a.fatigue().joint(0).unwrap().reengagements() > 0);
        assert_eq!(a.save_checkpoint(&mut store), Ok(Saved { generation: 1, slot: 0, erases: 1 }));
        let saved = a.learner_state();
        assert_eq!(saved.user[user::EPISODES], a.episodes.started());
        assert!(a.episodes.started() >= 3);

        // The board resets: it boots with SARSA and another seed, and loads.
        let mut b = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 99).unwrap();
        assert_ne!(b.agent().weights_checksum(), a.agent().weights_checksum());
        assert_eq!(b.load_checkpoint(&store), Ok(LoadOutcome::Loaded { generation: 1, slot: 0 }));
        assert_eq!(b.checkpoints_refused(), 0);
        assert_eq!(b.learner_state(), saved);
        assert_eq!(b.weights(), a.weights());
        assert_eq!(b.policy(), PolicyKind::Pada { delta: 0.5 });
        assert_eq!(b.fatigue().state(), a.fatigue().state());

        // It continues: episode numbers go on, and what it does replays on a
        // host agent restored from the same checkpoint.
        start(&mut b, RunMode::Learning);
        let mut angle = 0.0;
        let after = run_pendulum(&mut b, &mut angle, 0, 1500);
        assert!(after.len() > 300);
        assert_eq!(after[0].kind, StepKind::Start);
        assert_eq!(after[0].episode, saved.user[user::EPISODES]);
        assert!(b.agent_stats().steps > saved.agent.stats.steps);

        let mut state = LearnerState::default();
        let mut weights = table();
        assert!(matches!(checkpoint::load(&store, b.config_hash(), &mut state, &mut weights), Ok(LoadOutcome::Loaded { .. })));
        let mut agent = SPEC_33HZ.agent::<_, TILINGS, TRACE>(PolicyKind::Sarsa, profile(&SPEC_33HZ).layout, weights).unwrap();
        agent.restore_state(&state.agent).unwrap();
        let mut rng = Pcg32::from_state(state.rng).unwrap();
        for s in &after {
            agent.set_mode(if s.mode == RunMode::Testing { Mode::Testing } else { Mode::Learning });
            match s.kind {
                StepKind::Start => assert_eq!(agent.start_episode(&s.state, &mut rng).unwrap().action, s.action),
                StepKind::Step => assert_eq!(agent.step(s.reward, &s.state, &mut rng).unwrap().action, s.action),
                StepKind::Absorbing => agent.end_episode(s.reward, EpisodeEnd::Absorbing, &mut rng).unwrap(),
                StepKind::Timeout => agent.end_episode(s.reward, EpisodeEnd::Timeout(&s.state), &mut rng).unwrap(),
            }
        }
        assert_eq!(agent.weights_checksum(), b.agent().weights_checksum());

        // The next save goes to the other slot and carries on the counters.
        stop(&mut b);
        assert_eq!(b.save_checkpoint(&mut store), Ok(Saved { generation: 2, slot: 1, erases: 1 }));
        let mut c = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 5).unwrap();
        assert_eq!(c.load_checkpoint(&store), Ok(LoadOutcome::Loaded { generation: 2, slot: 1 }));
        assert_eq!(c.learner_state(), b.learner_state());
    }

    #[test]
    fn saves_beyond_the_flash_budget_are_refused_counted_and_reported() {
        let mut c = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 3).unwrap();
        let mut store = Store::new();
        assert_eq!(c.save_checkpoint(&mut store).map(|s| s.erases), Ok(1));
        // A store whose sectors were erased 5000 times in under a minute of
        // operation: far ahead of the ten-year budget.
        let mut worn = c.learner_state();
        worn.wear = FlashWear { erases: [5000, 5000], operating_s: 40 };
        checkpoint::save(&mut store, c.config_hash(), &worn, c.weights()).unwrap();
        let mut d = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 3).unwrap();
        assert!(matches!(d.load_checkpoint(&store), Ok(LoadOutcome::Loaded { .. })));
        assert_eq!(d.flash_wear().erases, [5000, 5001]);
        assert_eq!(d.operating_s(), 40, "the operating time carried by the checkpoint");
        let before = store.clone();
        let r = d.save_checkpoint(&mut store);
        assert!(matches!(r, Err(CheckpointError::Save(SaveError::Wear(_)))), "{r:?}");
        assert_eq!(store.slot(0), before.slot(0), "nothing erased");
        assert_eq!(d.saves_refused(), 1);
        let mut health = wire::Health::default();
        d.health(&mut health);
        assert_eq!((health.checkpoint_erases, health.saves_refused), (5001, 1));
    }

    #[test]
    fn the_erase_of_a_save_that_fails_afterwards_is_counted_and_recorded_by_the_next() {
        /// A flash whose writes fail (its erases work).
        struct WritesFail(Store);
        impl CheckpointStore for WritesFail {
            type Error = pada_core::checkpoint::OutOfRange;
            fn capacity(&self) -> usize {
                self.0.capacity()
            }
            fn read(&self, slot: u8, offset: usize, buf: &mut [u8]) -> Result<(), Self::Error> {
                self.0.read(slot, offset, buf)
            }
            fn erase(&mut self, slot: u8) -> Result<(), Self::Error> {
                self.0.erase(slot)
            }
            fn write(&mut self, _: u8, _: usize, _: &[u8]) -> Result<(), Self::Error> {
                Err(pada_core::checkpoint::OutOfRange)
            }
        }
        let mut c = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 3).unwrap();
        let mut flash = WritesFail(Store::new());
        let r = c.save_checkpoint(&mut flash);
        assert!(matches!(r, Err(CheckpointError::Save(SaveError::StoreAfterErase { slot: 0, erases: 1, .. }))), "{r:?}");
        assert_eq!((c.saves_failed(), c.flash_wear().erases), (1, [1, 0]));
        // The next save, on the same flash, records both erases of slot 0.
        let mut store = flash.0;
        assert_eq!(c.save_checkpoint(&mut store), Ok(Saved { generation: 1, slot: 0, erases: 2 }));
        assert_eq!(checkpoint::stored_wear(&store).unwrap().erases, [2, 0]);
    }

    #[test]
    fn refused_checkpoints_are_counted_and_change_nothing() {
        let mut c = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 3).unwrap();
        start(&mut c, RunMode::Learning);
        let mut angle = 0.0;
        run_pendulum(&mut c, &mut angle, 0, 600);
        stop(&mut c);
        let (state, checksum) = (c.learner_state(), c.agent().weights_checksum());
        // The learner is unchanged; the flash wear is the store's to report.
        let unchanged = |c: &Controller<Box<[Q16]>, Pendulum>| {
            assert_eq!(LearnerState { wear: state.wear, ..c.learner_state() }, state);
            assert_eq!(c.agent().weights_checksum(), checksum);
        };

        // Nothing there: not a refusal.
        let mut store = Store::new();
        assert_eq!(c.load_checkpoint(&store), Ok(LoadOutcome::NoCheckpoint));
        assert_eq!(c.checkpoints_refused(), 0);

        // Another robot's checkpoint.
        // (LEO's table of the CCM alone, whose checkpoint fits a sector.)
        let mut leo = Controller::new(Leo::new(), ccm_leo_profile(), PolicyKind::Sarsa, leo_table_of(1 << 14), 1).unwrap();
        leo.save_checkpoint(&mut store).unwrap();
        let expected = LoadOutcome::ConfigMismatch { expected: c.config_hash(), found: leo.config_hash() };
        assert_eq!(c.load_checkpoint(&store), Ok(expected));
        assert_eq!(c.checkpoints_refused(), 1);
        unchanged(&c);

        // The right configuration, a state out of range: refused by name.
        // (An integrator with Δ = 0.5 has the pendulum's −3/0/+3 V levels,
        // so the configuration hash matches; the state record tells them
        // apart.)
        let integrator = SPEC_33HZ
            .agent::<_, TILINGS, TRACE>(PolicyKind::Integrator { delta: 0.5 }, profile(&SPEC_33HZ).layout, table())
            .unwrap();
        assert_eq!(config_hash(&profile(&SPEC_33HZ), &integrator), c.config_hash());
        type Change = fn(&mut LearnerState);
        let cases: [(&str, Change); 6] = [
            ("epsilon", |s| s.agent.epsilon = 2.0),
            ("policy.kind", |s| s.agent.policy.kind = PolicyKind::Integrator { delta: 0.5 }),
            ("joints", |s| {
                s.joints.truncate(1);
            }),
            ("rng.increment", |s| s.rng.increment = 2),
            ("since_test", |s| s.user[user::SINCE_TEST] = 11),
            ("user", |s| s.user[3] = 1),
        ];
        for (i, (field, change)) in cases.iter().enumerate() {
            let mut bad = state.clone();
            change(&mut bad);
            let mut store = Store::new();
            checkpoint::save(&mut store, c.config_hash(), &bad, &vec![Q16(1); WEIGHTS]).unwrap();
            assert_eq!(c.load_checkpoint(&store), Ok(LoadOutcome::InvalidState), "{field}");
            assert_eq!(c.last_refusal().map(|e| e.param), Some(*field));
            assert_eq!(c.checkpoints_refused(), 2 + i as u32);
            unchanged(&c);
        }

        // A format-1 checkpoint (weights without the learner's state).
        let mut store = Store::new();
        let v1 = checkpoint::Header {
            version: 1,
            config_hash: c.config_hash(),
            weight_count: WEIGHTS as u32,
            generation: 4,
            payload_crc: checkpoint::crc32(&[0u8; WEIGHTS * 4]),
            state_len: 0,
            weight_bytes: 4,
        };
        let slot = store.slot_mut(0).unwrap();
        slot[..checkpoint::HEADER_LEN].copy_from_slice(&v1.to_bytes());
        slot[checkpoint::HEADER_LEN..checkpoint::HEADER_LEN + WEIGHTS * 4].fill(0);
        assert_eq!(c.load_checkpoint(&store), Ok(LoadOutcome::UnsupportedVersion { found: 1 }));
        assert_eq!(c.last_refusal(), None);
        assert_eq!(c.checkpoints_refused(), 8);
        unchanged(&c);

        // Garbage.
        store.slot_mut(0).unwrap().fill(0);
        assert_eq!(c.load_checkpoint(&store), Ok(LoadOutcome::Corrupt));
        assert_eq!(c.checkpoints_refused(), 9);
        unchanged(&c);

        // And a good one still loads.
        let mut store = Store::new();
        c.save_checkpoint(&mut store).unwrap();
        assert!(matches!(c.load_checkpoint(&store), Ok(LoadOutcome::Loaded { .. })));
        assert_eq!(c.checkpoints_refused(), 9);
        unchanged(&c);
    }

    /// Bytes of one checkpoint slot on every real board: one 128 KiB flash
    /// sector (`memory.x`: sectors 10–11 of the F405/F407; `memory-f429.x`:
    /// sectors 22–23 of the F429).
    const FLASH_SLOT: usize = 128 * 1024;

    #[test]
    fn the_f429s_leo_table_is_refused_as_too_large_and_counted_and_its_pendulum_saves() {
        // LEO on the F429: a claim table of 2^21 slots, a 16-bit weight and
        // a 16-bit tag each: 8 MiB, all of the SDRAM.
        let f429_leo = Board::F429Sdram.profile(&leo::SPEC).unwrap();
        let weights = f429_leo.weights().unwrap();
        assert_eq!(weights, 1 << 21);
        let mut leo = Controller::new(Leo::new(), f429_leo, PolicyKind::Sarsa, leo_table_of(weights), 1).unwrap();
        let needed = checkpoint::HEADER_LEN + checkpoint::STATE_LEN + 8 * 1024 * 1024;
        assert_eq!(leo.checkpoint_bytes(), needed);
        let mut store = Box::new(pada_core::checkpoint::RamStore::<FLASH_SLOT>::new());
        let too_large = Err(CheckpointError::Save(SaveError::TooLarge { needed, capacity: FLASH_SLOT }));
        assert_eq!(leo.save_checkpoint(&mut *store), too_large);
        assert_eq!(leo.saves_failed(), 1);
        assert_eq!(leo.save_checkpoint(&mut *store), too_large);
        assert_eq!(leo.saves_failed(), 2);
        // Refused before the store was touched: both slots still erased.
        for slot in 0..2 {
            assert!(store.slot_mut(slot).unwrap().iter().all(|&b| b == 0xFF), "slot {slot} written");
        }
        assert_eq!(leo.load_checkpoint(&*store), Ok(LoadOutcome::NoCheckpoint));

        // The F429's pendulum (exact table in SRAM) fits a sector and saves.
        let f429_pendulum = Board::F429Sdram.profile(&SPEC_33HZ).unwrap();
        let mut pendulum = Controller::new(Pendulum::at_33hz(), f429_pendulum, PolicyKind::Sarsa, table(), 1).unwrap();
        assert!(pendulum.checkpoint_bytes() <= FLASH_SLOT, "{}", pendulum.checkpoint_bytes());
        assert_eq!(pendulum.save_checkpoint(&mut *store), Ok(Saved { generation: 1, slot: 0, erases: 1 }));
        assert_eq!(pendulum.saves_failed(), 0);
        // A saved F429 pendulum is not the F405's: the profile is in the hash.
        let mut f405 = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 1).unwrap();
        assert!(matches!(f405.load_checkpoint(&*store), Ok(LoadOutcome::ConfigMismatch { .. })));
    }

    /// A checkpoint's operating time after 10^6 periods of robot `R` on
    /// `weights` weights is the controlled time to the period (10^6
    /// periods are whole seconds), and after 17 more the whole seconds of
    /// it, rounded down.
    fn operating_time_is_the_controlled_time<R: RobotRules, W: WeightStore>(robot: R, profile: pada_core::profile::LearnerProfile, table: W) {
        let spec = robot.spec();
        let mut c = Controller::new(robot, profile, PolicyKind::Sarsa, table, 1).unwrap();
        let mut store = Box::new(pada_core::checkpoint::RamStore::<FLASH_SLOT>::new());
        let (clock, mut out) = (Clock(Cell::new(0)), PeriodOutput::default());
        let period_us = spec.period_us as u64;
        let mut periods = 0;
        for more in [1_000_000, 17] {
            for _ in 0..more {
                c.period(&Readings::default(), &clock, &mut out);
            }
            periods += more;
            c.save_checkpoint(&mut *store).unwrap();
            let operating_s = checkpoint::stored_wear(&*store).unwrap().operating_s;
            let controlled_us = periods * period_us;
            assert_eq!(operating_s, controlled_us / 1_000_000, "{} after {periods} periods of {period_us} µs", spec.name);
        }
    }

    #[test]
    fn a_checkpoints_operating_time_is_the_controlled_time() {
        // 30 000 s of the 33 Hz pendulum, 50 000 s of the 20 Hz one,
        // 33 333 s of LEO (33 333 µs a period).
        operating_time_is_the_controlled_time(Pendulum::at_33hz(), profile(&SPEC_33HZ), table());
        let n20 = profile(&SPEC_20HZ).weights().unwrap();
        operating_time_is_the_controlled_time(Pendulum::at_20hz(), profile(&SPEC_20HZ), vec![Q16::ZERO; n20].into_boxed_slice());
        operating_time_is_the_controlled_time(Leo::new(), ccm_leo_profile(), leo_table_of(1 << 14));
    }

    #[test]
    fn every_f405_checkpoint_fits_a_flash_sector() {
        // Every F405 table fits a 128 KiB sector: the pendulum's exact
        // table (97.5 KiB), LEO's hashed one (2^15 16-bit weights, 64 KiB).
        for robot in pada_core::robot::registry::specs() {
            let p = profile(robot);
            let bytes = checkpoint::slot_len(p.weights().unwrap(), p.entry_bytes());
            assert!(bytes <= FLASH_SLOT, "{}: {bytes}", robot.name);
        }
        let leo = Controller::new(Leo::new(), profile(&leo::SPEC), PolicyKind::Sarsa, leo_table(), 1).unwrap();
        assert!(!leo.host_keeps_checkpoint(FLASH_SLOT), "{} bytes", leo.checkpoint_bytes());
    }
}
