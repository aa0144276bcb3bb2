//! The host's side of the forecasts (`pada_firmware::sil`, "Forecasts"):
//! which bus request the firmware sends next, the answers to send ahead
//! with an `Advance`, and the check that every answer the board took from
//! a forecast is the one the bus emulator gives when the request is
//! reported.
//!
//! What follows what is learned, not told: the request the firmware sent
//! right after an answer (at the instant the answer was in), or right
//! after a wake without bus bytes (its control tick: the key is empty), is
//! what it is expected to send the next time. The firmware's period reads
//! its servos in a fixed order, so after one period every read of the next
//! is forecast; anything else (a retry, a write) simply ends the chain.

use super::bus::{BusEmulator, Reply};
use crate::rig::Rig;
use pada_firmware::sil::{MAX_REPLY, MAX_REQUEST};
use serde::Serialize;
use std::collections::{HashMap, VecDeque};

/// Most forecasts sent with one `Advance` (what the board holds).
pub const MAX_CHAIN: usize = 16;

/// One forecast: if `request` is sent at `request_at_us`, `reply`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Forecast {
    /// When the request would be sent \[µs\].
    pub request_at_us: u64,
    /// The request.
    pub request: Vec<u8>,
    /// Its answer.
    pub reply: Reply,
}

/// Counters of the forecasts.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct ForecastStats {
    /// Whether forecasts were made (`--no-forecast` turns them off).
    pub enabled: bool,
    /// Forecasts sent.
    pub sent: u64,
    /// Answers the board took from them (each one exchange saved).
    pub used: u64,
}

/// What the host expects and has promised.
#[derive(Debug, Default)]
pub struct Forecaster {
    enabled: bool,
    next: HashMap<Vec<u8>, Vec<u8>>,
    outstanding: VecDeque<Forecast>,
    stats: ForecastStats,
}

impl Forecaster {
    /// A forecaster; with `enabled` false it forecasts nothing.
    pub fn new(enabled: bool) -> Self {
        Forecaster { enabled, stats: ForecastStats { enabled, ..ForecastStats::default() }, ..Forecaster::default() }
    }

    /// Counters so far.
    pub fn stats(&self) -> ForecastStats {
        self.stats
    }

    /// The board sent `request` right after the answer to `after` (empty:
    /// after a wake without bus bytes).
    pub fn observe(&mut self, after: &[u8], request: &[u8]) {
        if self.enabled && request.len() <= MAX_REQUEST {
            if self.next.get(after).is_none_or(|r| r.as_slice() != request) {
                self.next.insert(after.to_vec(), request.to_vec());
            }
        } else {
            self.next.remove(after);
        }
    }

    /// The chain of forecasts from `now_us`, when the board goes on after
    /// the answer to `after` (empty: after a wake without bus bytes),
    /// answered before `horizon_us`; remembered as outstanding.
    pub fn plan(&mut self, bus: &BusEmulator, rig: &dyn Rig, now_us: u64, after: &[u8], horizon_us: u64) -> Vec<Forecast> {
        self.outstanding.clear();
        if !self.enabled {
            return Vec::new();
        }
        let mut key = after.to_vec();
        let mut t = now_us;
        let mut chain = Vec::new();
        while chain.len() < MAX_CHAIN {
            let Some(request) = self.next.get(&key) else { break };
            let Some(reply) = bus.forecast(t, request, rig) else { break };
            if reply.at_us >= horizon_us || reply.bytes.len() > MAX_REPLY {
                break;
            }
            // The firmware sends its next request the instant an answer is
            // in (computation takes no lock-step time).
            let request_at_us = t;
            t = reply.at_us;
            key = request.clone();
            chain.push(Forecast { request_at_us, request: request.clone(), reply });
        }
        self.stats.sent += chain.len() as u64;
        self.outstanding.extend(chain.iter().cloned());
        chain
    }

    /// The board reports `request`, sent at `at_us`, as answered from a
    /// forecast; `replies` is what the bus emulator answered it now. Both
    /// must be the next outstanding forecast's.
    pub fn confirm(&mut self, at_us: u64, request: &[u8], replies: &[Reply]) -> Result<(), String> {
        let Some(f) = self.outstanding.pop_front() else {
            return Err(format!("the board took an answer at {at_us} us from a forecast the host did not send"));
        };
        if f.request_at_us != at_us || f.request != request {
            return Err(format!(
                "the board took the forecast for {:02x?} at {} us for {request:02x?} at {at_us} us",
                f.request, f.request_at_us
            ));
        }
        if replies != [f.reply.clone()] {
            return Err(format!(
                "forecast and answer differ for {request:02x?} at {at_us} us: forecast {:?}, answer {replies:?}",
                f.reply
            ));
        }
        self.stats.used += 1;
        Ok(())
    }

    /// The board reported and waits: forecasts not used are void.
    pub fn void(&mut self) {
        self.outstanding.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pendulum::PhysicalPendulumParams;
    use crate::rig::PendulumRig;
    use pada_core::dynamixel::{self, table};
    use pada_firmware::sil::{sensor_table, SENSOR_ID};

    fn read(id: u8, addr: u8, len: u8) -> Vec<u8> {
        let mut buf = [0u8; 16];
        dynamixel::read_data(id, addr, len, &mut buf).unwrap().to_vec()
    }

    #[test]
    fn learns_the_period_s_reads_and_chains_their_answers() {
        let mut rig = PendulumRig::new(PhysicalPendulumParams::default());
        let mut bus = BusEmulator::new(&rig, &pada_core::robot::pendulum::SPEC_33HZ, vec![]).unwrap();
        let servo = read(1, table::PRESENT_BLOCK, table::PRESENT_BLOCK_LEN);
        let sensor = read(SENSOR_ID, sensor_table::ENCODER_COUNT, sensor_table::READ_LEN);
        let mut f = Forecaster::new(true);
        assert!(f.plan(&bus, &rig, 0, &[], u64::MAX).is_empty(), "nothing learned yet");
        f.observe(&[], &servo);
        f.observe(&servo, &sensor);
        let chain = f.plan(&bus, &rig, 30_000, &[], u64::MAX);
        assert_eq!(chain.len(), 2);
        assert_eq!((chain[0].request_at_us, chain[1].request_at_us), (30_000, chain[0].reply.at_us));
        // Confirmed as the bus answers them when they come.
        let first = bus.receive(30_000, &servo, &mut rig);
        f.confirm(30_000, &servo, &first).unwrap();
        let at = first[0].at_us;
        let second = bus.receive(at, &sensor, &mut rig);
        f.confirm(at, &sensor, &second).unwrap();
        assert_eq!(f.stats(), ForecastStats { enabled: true, sent: 2, used: 2 });
        // A horizon before the second answer cuts the chain.
        let chain = f.plan(&bus, &rig, 60_000, &[], 60_000 + 800);
        assert_eq!(chain.len(), 1);
        // A wrong claim is an error, not a silent pass.
        assert!(f.confirm(60_001, &servo, &[]).is_err());
        f.void();
        assert!(f.confirm(60_000, &servo, &[]).is_err());
        // Off: nothing.
        let mut off = Forecaster::new(false);
        off.observe(&[], &servo);
        assert!(off.plan(&bus, &rig, 90_000, &[], u64::MAX).is_empty());
    }
}
