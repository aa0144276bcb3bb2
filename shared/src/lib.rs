//! pada-core: the learning core of pada, identical on the host and on the chip.
//!
//! Everything here is `no_std`, allocation-free and fixed-size: capacities are
//! const generics or [`heapless`] types, and running out is an error that is
//! counted, never a panic. The pieces, each in its own module:
//!
//! - [`fixed`]: the fixed-point formats of weights, rates and trace weights;
//! - [`tile_coding`]: state → integer tile coordinates → feature indices
//!   (hashed or exact layout);
//! - [`claim_table`]: the collision-free table of hashed features (a
//!   learning update claims a slot, a read never does, an unclaimed
//!   feature reads its initial weight, a full table refuses and counts);
//! - [`action_space`]: discrete multi-dimensional actions and joint indices;
//! - [`action_tiles`]: optional generalisation over actions (their values
//!   tile-coded, as the paper's LEO learner does);
//! - [`policy`]: the six action policies of Section V (SARSA, low-pass,
//!   Markov low-pass, integrator, Markov integrator, PADA) and four gentler
//!   explorations (ε-PADA, Ornstein–Uhlenbeck and pink noise on the action
//!   levels, an action-change penalty) as one concept;
//! - [`exploration`]: the noise processes of those explorations;
//! - [`governor`]: the wear governor, which moves PADA's Δ or the low-pass
//!   filter's α while learning to hold a stated MTBF;
//! - [`trace`]: bounded eligibility traces;
//! - [`agent`]: SARSA(λ) with ε-greedy selection over the policy's candidates;
//! - [`episodes`]: the episode cycle the chip and the host both drive (test
//!   cadence, the kinds of end, LEO's footstep remap, the step records, the
//!   governor's feed);
//! - [`fatigue`]: backlash re-engagements → damage J → predicted MTBF
//!   (Section IV, Eqs. 1–7);
//! - [`dynamixel`]: the Dynamixel Protocol 1.0 codec and the RX-28 control
//!   table, the Protocol 2.0 codec ([`dynamixel::v2`]) and the control
//!   tables of the X-series servos and the MX-28(2.0)
//!   ([`dynamixel::control_table`]) (both directions, so the host can
//!   emulate servos);
//! - [`wire`]: the telemetry and command protocol between chip and host
//!   (postcard + CRC-32 + COBS), so both ends decode exactly what the other
//!   encodes;
//! - [`checkpoint`]: learned weights and the learner's state (counters, ε,
//!   policy, fatigue counters, generator) in two alternating flash slots
//!   that survive a torn write;
//! - [`crc`]: the CRC-32 of frames and checkpoints and the configuration
//!   hash;
//! - [`rng`]: `rand_pcg::Pcg32` and its state as a checkpoint saves it;
//! - [`safety`]: the Idle → Learning/Testing → Fault state machine that owns
//!   torque enable;
//! - [`limits`]: the capacities, each defined once;
//! - [`rx28`]: the RX-28 servo's voltage-driven motor model (shared by the
//!   LEO simulator and the firmware's torque estimate);
//! - [`servo`]: servos and gearboxes as data: the servo models (datasheet
//!   figures with their sources, the DC motor derived from them) and each
//!   one's last gear for Eqs. 3–7, estimates marked.
//!
//! Section and equation numbers refer to Meijdam, Plooij and Caarls,
//! "Learning while preventing mechanical failure due to random motions".
#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]
// Index loops over several parallel fixed-size arrays read more plainly than
// zipped iterators here.
#![allow(clippy::needless_range_loop)]

pub mod action_space;
pub mod action_tiles;
pub mod agent;
pub mod checkpoint;
pub mod claim_table;
pub mod claims;
pub mod crc;
pub mod dynamixel;
pub mod episodes;
pub mod error;
pub mod exploration;
pub mod fatigue;
pub mod feetech;
pub mod fixed;
pub mod framing;
pub mod governor;
pub mod limits;
pub mod policy;
pub mod profile;
pub mod rng;
pub mod robot;
pub mod rx28;
pub mod safety;
pub mod servo;
pub mod tile_coding;
mod tiling;
pub mod trace;
pub mod weights;
pub mod wire;

/// A value the firmware references so that a link of pada-core is visible in
/// the ELF even before the firmware runs an agent ("PADA" in ASCII).
pub fn linked_marker() -> u32 {
    0x5041_4441
}
