//! A robot of your own for pada: a `robot.toml` (its joints and their
//! servos, what it observes, its actions, its reward and its ends, how it
//! learns) and a URDF (its body). This crate reads and checks both — each
//! error names the file, the line, the field and the valid values — and
//! makes of them the definition pada-core takes: a [`RobotSpec`] whose
//! rules are said in pada-core's vocabulary
//! (`pada_core::robot::vocabulary`). The host simulates and learns on it
//! (`pada run --robot`); the firmware's build makes Rust source of it
//! ([`rust_source`]), so the chip learns on the same definition, bit for
//! bit.
//!
//! | file | its one job |
//! |---|---|
//! | `schema.rs` | `robot.toml`'s tables and fields, as serde reads them |
//! | `urdf.rs` | the URDF: its joints, links and kinematic chains |
//! | `definition.rs` | the checks, and the [`RobotSpec`] they make |
//! | `codegen.rs` | the definition as Rust source for the firmware |
//! | `plant.rs` | `[plant]`: how far the real robot may differ from its model |
//! | `template.rs` | a new robot's files, commented field by field (`pada new-robot`) |
//! | `error.rs` | one error in one line, pointing at the line of the file |
//! | `type_error.rs` | toml's type and length errors, reworded with the field and the valid values |
//!
//! [`RobotSpec`]: pada_core::robot::RobotSpec

mod codegen;
mod definition;
mod error;
/// Gearbox files: the Table I fields of a gearbox by name or from TOML.
pub mod gearbox_file;
pub mod plant;
pub mod schema;
pub mod template;
mod type_error;
pub mod urdf;

pub use codegen::rust_source;
pub use definition::{load, RobotFile};
pub use error::RobotFileError;
