//! pada's telemetry on the host, usable without the `pada` command: the
//! decoder and recorder of [`capture`] read the frames of
//! `pada_core::wire` from a board's serial port, a recorded file, a SIL run
//! or a host simulation's `--telemetry` stream, count every loss, and write
//! the CSV that `pada capture` writes. The `pada` command (its `capture`,
//! `sil`, `drive` and `watch`) and the Python package's `read_telemetry`
//! both use it. With the feature `mcap` (the `pada` command's), the same
//! frames become MCAP recordings ([`mcap`]) and Foxglove's live WebSocket
//! channels ([`foxglove`]); the Python package builds without them.

pub mod capture;
#[cfg(feature = "mcap")]
pub mod foxglove;
#[cfg(feature = "mcap")]
pub mod mcap;
