//! pada-sim: pada's simulator, a library of its own, used by the `pada`
//! command, the Python package and the software-in-the-loop run alike,
//! and by anyone who wants pada's robots without the command's
//! dependencies (web server, plotting, serial ports).
//!
//! | module | what |
//! |---|---|
//! | [`task`] | what the experiment runner needs from a learning task ([`task::Task`]) and the simulated systems it drives ([`task::Plant`]) |
//! | [`pendulum`] | the pendulums of Section VII: the simulated one and the physical one's model |
//! | [`leo`] | LEO in rapier3d (Section VIII), its RX-28 servos, the walking task |
//! | [`rig`] | the robot behind a board's servos and sensors, for `pada run --board` and `pada sil` |
//! | [`robots`] | which body and rules each of pada's robots has |
//! | [`urdf`] | a robot of the user's own: its URDF in rapier, driven through its rules and servos |
//! | [`variation`] | a robot that is not its model: plants drawn within ranges, per trial or per episode |
//! | [`integrator`] | RK4 for the pendulums |
//! | [`model_presets`] | settings of LEO's model that its checks share |
//! | [`world_state`] | a rapier world's state, copied and put back (LEO's snapshots, a URDF body's reset) |
//!
//! The robots' definitions (their rules, servos and gearboxes) are
//! pada-core's (`pada_core::robot`, `pada_core::servo`), shared with the
//! firmware.

pub mod integrator;
pub mod leo;
pub mod model_presets;
pub mod pendulum;
pub mod rig;
pub mod robots;
pub mod task;
pub mod urdf;
pub mod variation;
pub mod world_state;
