//! The example robot of files (`examples/robots/arm2`) as Rust source, by
//! the generator the firmware's build.rs runs for `PADA_ROBOT=…/robot.toml`
//! (`pada_robot_file::rust_source`), into `$OUT_DIR/arm2_robot.rs`: the
//! configuration-hash test (tests/one_definition.rs) compiles the very
//! constants an arm2 image holds and compares their learner with the
//! host's.
//!
//! (The build-dependency on syn in Cargo.toml only aligns its features
//! with the Python wheel's build; see there.)

use std::path::PathBuf;

fn main() {
    let manifest = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").unwrap());
    let toml = manifest.join("../examples/robots/arm2/robot.toml");
    let file = pada_robot_file::load(&toml).unwrap_or_else(|e| panic!("{e}"));
    println!("cargo:rerun-if-changed={}", toml.display());
    println!("cargo:rerun-if-changed={}", file.urdf.path.display());
    let source = pada_robot_file::rust_source(file.spec, "examples/robots/arm2/robot.toml").unwrap_or_else(|e| panic!("{e}"));
    let out = PathBuf::from(std::env::var_os("OUT_DIR").unwrap());
    std::fs::write(out.join("arm2_robot.rs"), source).unwrap();
}
