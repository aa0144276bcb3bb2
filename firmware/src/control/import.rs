//! Weights brought in from outside the board: a table learned elsewhere
//! (on the host, in simulation) and exported into this board's format,
//! written over the fresh learner's table before its first episode.

use super::Controller;
use pada_core::error::ConfigError;
use pada_core::robot::RobotRules;
use pada_core::weights::WeightStore;

impl<W, R> Controller<W, R>
where
    W: WeightStore,
    R: RobotRules,
{
    /// Writes `entries` — every entry of the table in its stored form
    /// (`WeightStore::stored_le`: the weight, then a claim table's tag),
    /// as a checkpoint holds them — over the learner's table; only while
    /// torque is off. A claim table counts its claimed slots again and
    /// keeps its own initial weights for the features that hold none; the
    /// rest of the learner (generator, counters, policy) is untouched, so
    /// the next Start continues as a fresh learner would, from these
    /// weights.
    ///
    /// Errors: torque on, or `entries` not the table's length times its
    /// entry size; nothing changes then.
    pub fn import_entries(&mut self, entries: &[u8]) -> Result<(), ConfigError> {
        if self.torque_enabled() {
            return Err(ConfigError::new("torque", 1.0, "off while weights are imported"));
        }
        let eb = self.weights().entry_bytes();
        let n = self.weights().len();
        if eb == 0 || entries.len() != n * eb {
            return Err(ConfigError::new("entries", entries.len() as f32, "the table's entries times its entry size"));
        }
        let agent = self.agent_mut();
        for (i, src) in entries.chunks_exact(eb).enumerate() {
            agent.weights_mut().load_le(i, src);
        }
        // Restoring the agent's own state recounts a claim table's slots
        // under its initial weights; then the checksum follows the table.
        let state = agent.state();
        agent.restore_state(&state)?;
        agent.rehash();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::test_support::*;
    use pada_core::fixed::Q16;
    use pada_core::policy::PolicyKind;
    use pada_core::safety::RunMode;

    fn entries_of(n: usize, f: impl Fn(usize) -> i32) -> std::vec::Vec<u8> {
        (0..n).flat_map(|i| f(i).to_le_bytes()).collect()
    }

    #[test]
    fn imported_entries_become_the_table_and_its_checksum() {
        let mut c = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 5).unwrap();
        let n = c.weights().len();
        let fresh = c.agent().weights_checksum();
        c.import_entries(&entries_of(n, |i| i as i32 * 3 - 7)).unwrap();
        assert!((0..n).all(|i| c.weights().get(i) == Q16(i as i32 * 3 - 7)));
        // The kept checksum follows the imported table.
        assert_eq!(c.agent().weights_checksum(), c.weights().checksum());
        assert_ne!(c.agent().weights_checksum(), fresh);
    }

    #[test]
    fn entries_of_another_length_or_with_torque_on_change_nothing() {
        let mut c = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 5).unwrap();
        let n = c.weights().len();
        let before = c.weights().checksum();
        assert_eq!(c.import_entries(&entries_of(n - 1, |_| 1)).unwrap_err().param, "entries");
        assert_eq!(c.weights().checksum(), before);
        start(&mut c, RunMode::Learning);
        assert_eq!(c.import_entries(&entries_of(n, |_| 1)).unwrap_err().param, "torque");
        assert_eq!(c.weights().checksum(), before);
    }
}
