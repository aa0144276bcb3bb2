//! The state of an STS3215's output shaft, which its position loop
//! ([`super::ft`]) moves and a virtual servo ([`super::p1`]) keeps: a leaf
//! module, so that the two import it without importing each other.

use pada_core::feetech::status::ServoStatus;

/// The state of an STS3215's output, for its position loop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Output {
    /// Position \[steps\].
    pub position: f64,
    /// Velocity \[steps/s\].
    pub velocity: f64,
    /// Bus time of the state \[µs\].
    pub at_us: u64,
    /// Conditions injected by faults (kept until the next RECOVERY).
    pub injected: ServoStatus,
}

impl Default for Output {
    fn default() -> Self {
        Output { position: 2048.0, velocity: 0.0, at_us: 0, injected: ServoStatus::NONE }
    }
}

