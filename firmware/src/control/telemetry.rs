//! What the controller tells the host besides its step records: the
//! `Hello` of its configuration, the `Policy` report and its part of the
//! `Health` record.

use super::Controller;
use pada_core::robot::RobotRules;
use pada_core::governor::Governor;
use pada_core::weights::WeightStore;
use pada_core::wire;

impl<W, R> Controller<W, R>
where
    W: WeightStore,
    R: RobotRules,
{
    /// The `Hello` of this configuration.
    pub fn hello(&self) -> wire::Hello {
        wire::Hello {
            protocol: wire::PROTOCOL_VERSION,
            // Robot names are at most MAX_NAME bytes (the definitions'
            // tests check it; a longer one would be sent empty).
            robot: heapless::String::try_from(self.spec.name).unwrap_or_default(),
            robot_hash: self.spec.definition_hash(),
            config_hash: self.config_hash,
            weight_count: self.weights().len() as u32,
            period_us: self.spec.period_us,
            state_dims: self.spec.state.len() as u8,
            joints: self.reported_joints().len() as u8,
        }
    }

    /// The `Policy` report of the learner now: the built policy with its
    /// α/Δ and whether it switched back to SARSA(λ).
    pub fn policy_report(&self) -> wire::PolicyReport {
        let policy = self.agent().policy();
        wire::PolicyReport {
            step: self.agent_stats().steps as u32,
            built: policy.built_kind(),
            switched_to_sarsa: policy.switched(),
            governor: self.governor.as_ref().map(Governor::status),
        }
    }

    /// Health fields the controller knows; the caller adds bus, loop and
    /// link counters.
    pub fn health(&self, health: &mut wire::Health) {
        health.servo_temps_c.clear();
        let n = self.spec.joints.len();
        for &t in &self.temps[..n] {
            let _ = health.servo_temps_c.push(t);
        }
        health.min_voltage_dv =
            self.supply[..n].iter().flatten().map(|v| (v * 10.0 + 0.5) as u8).min().unwrap_or(0);
        let stats = self.agent().stats();
        health.trace_drops = stats.trace_drops;
        health.weight_saturations = stats.saturations;
        health.checkpoint_erases = self.flash_wear.most_erases();
        health.saves_refused = self.saves_refused;
        let table = self.weights().occupancy().unwrap_or_default();
        health.table_claimed = table.claimed;
        health.table_slots = table.slots;
        health.claims_refused = table.refused;
    }
}
