//! MCAP recordings of telemetry (`--mcap FILE`): the crate
//! `pada_telemetry`'s `mcap` (channels, schemas, the scene, the writer and
//! the reader), and the command's own two:
//!
//! - [`picture`]: the `/scene` channel drawn as a PNG strip for `pada
//!   capture`'s summary (with the command's figures);
//! - [`tee`]: `--mcap` on a host run, beside its `--telemetry` stream.

pub use pada_telemetry::mcap::*;

pub mod picture;
pub mod tee;
