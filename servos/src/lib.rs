//! pada's servo emulation: virtual Dynamixel (Protocol 1.0 and 2.0) and
//! Feetech servos, each answering in its own protocol with a simulated
//! robot behind it. Two front ends carry the same servos:
//!
//! - `pada servos` puts them on a pseudo-terminal ([`pty`], [`serve`]), so
//!   that any program (`pada drive`, Feetech's SDK, rustypot, LeRobot) opens
//!   the port as it opens a USB adapter;
//! - `pada sil` puts them on the emulated board's bus ([`board_bus`]),
//!   where the real firmware image in QEMU reads and writes them in lock
//!   step.
//!
//! Both inject the same faults ([`fault`]), and both ask for the same
//! real-time treatment as `pada drive` where a wall clock matters
//! ([`realtime`]). The crate depends on pada-core (the protocols' codecs
//! and control tables), pada-sim (the rigs behind the servos) and the
//! firmware's library (its sensor device); the `pada` command depends on
//! it, never the reverse.
//!
//! | file | its one job |
//! |---|---|
//! | `p1.rs` | one virtual servo on Protocol 1.0's framing (RX-28, STS3215): its table, every instruction they share |
//! | `ft.rs`, `ft_output.rs` | the STS3215's own: its factory table, its position loop, its alarms; its duty-cycle voltage |
//! | `p2.rs` | one virtual X-series servo (Protocol 2.0): its table, every instruction, alerts, the Bus Watchdog |
//! | `sensor.rs` | the sensor device: encoder, foot contacts, the operator's call |
//! | `chain.rs` | `--chain`: a bare chain of servos with no robot behind them |
//! | `bus.rs` | the pseudo-terminal's bus: the decoders, the servos in their turn, time (real time or lock step), faults, the physics |
//! | `pty.rs` | the pseudo-terminal behind a symbolic link |
//! | `serve.rs` | the loop between them, and its summary |
//! | `scan.rs`, `reboot.rs` | `--scan` and `--reboot` on a real port |
//! | `board_bus/` | the emulated board's bus in `pada sil`: the same servos at a 1 Mbps bus's times, with forecasts |
//! | `fault.rs` | `--fault`: what to inject, when, into which servo |
//! | `realtime.rs` | a real-time thread (`SCHED_FIFO`, locked memory), granted or refused with the reason |

#![warn(missing_docs)]

pub mod board_bus;
pub mod bus;
pub mod chain;
pub mod fault;
pub mod ft;
pub mod ft_output;
pub mod p1;
pub mod p2;
pub mod pty;
pub mod realtime;
pub mod reboot;
pub mod scan;
pub mod sensor;
pub mod serve;

pub use bus::{Clock, VirtualBus};
