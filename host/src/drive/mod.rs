//! `pada drive`: learning on a real robot from a PC. The same controller
//! the firmware runs (`pada_firmware::control`, as `pada run --board`
//! builds it for the host) and the same bus transactions
//! (`pada_firmware::bus`), over a serial port: a USB adapter to the
//! robot's servos, or `pada servos`' pseudo-terminal.
//!
//! | file | its one job |
//! |---|---|
//! | `port.rs` | the serial port as the firmware's bus port; the permission check |
//! | `latency.rs` | the USB adapter's latency timer, and how to set it |
//! | `clock.rs` | the period clock: ticks, jitter, overruns |
//! | `realtime.rs` | the control thread under SCHED_FIFO with locked memory; what was granted |
//! | `store.rs` | checkpoints in a file, in the board's two slots |
//! | `telemetry.rs` | the telemetry a board sends, framed and recorded on a thread |
//! | `session.rs` | one run: boot, periods, the ways out |

pub mod clock;
pub mod latency;
pub mod port;
/// A real-time thread: `pada_servos`'s, which `pada servos` shares.
pub use pada_servos::realtime;
pub mod session;
pub mod store;
pub mod telemetry;
