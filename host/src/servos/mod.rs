//! Virtual Dynamixel and Feetech servos: `pada servos`. A robot's servos, each of the
//! model its definition names (or another, `--servo`), answer on a
//! pseudo-terminal in the protocol of their model, with the robot's
//! simulated physics behind them, as `pada sil` answers the firmware; any
//! program can open the port as it opens a USB adapter. And `pada servos
//! --scan`, which finds what answers on a real port.
//!
//! | file | its one job |
//! |---|---|
//! | `p1.rs` | one virtual servo on Protocol 1.0's framing (RX-28, STS3215): its table, every instruction they share |
//! | `ft.rs` | the STS3215's own: its factory table, its position loop, its alarms |
//! | `chain.rs` | `--chain`: a bare chain of servos with no robot behind them |
//! | `p2.rs` | one virtual X-series servo (Protocol 2.0): its table, every instruction, alerts, the Bus Watchdog |
//! | `sensor.rs` | the sensor device: encoder, foot contacts, the operator's call |
//! | `bus.rs` | the bus: both protocols' decoders, the servos in their turn, time (real time or lock step), faults, the physics |
//! | `pty.rs` | the pseudo-terminal behind a symbolic link |
//! | `serve.rs` | the loop between them, and its summary |
//! | `scan.rs` | `--scan`: which IDs and models answer on a port, at which rate and protocol |

pub mod bus;
pub mod chain;
pub mod ft;
pub mod ft_output;
pub mod p1;
pub mod p2;
pub mod pty;
pub mod reboot;
pub mod scan;
pub mod sensor;
pub mod serve;

pub use bus::{Clock, VirtualBus};
