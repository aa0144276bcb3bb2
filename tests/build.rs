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
    words(&manifest, &out);
}

/// The same arm with the words arm2 does not use: a squared-distance term
/// and an elbow with voltage levels of its own, written to
/// `$OUT_DIR/words/robot.toml` and generated into `$OUT_DIR/words_robot.rs`
/// (tests/one_definition.rs compiles it and compares it with the file).
fn words(manifest: &std::path::Path, out: &std::path::Path) {
    let arm = manifest.join("../examples/robots/arm2");
    let text = std::fs::read_to_string(arm.join("robot.toml")).unwrap();
    let edited = text
        .replace("term = \"distance\"", "term = \"distance_squared\"")
        .replace("id = 2\nzero_count = 2048\nstart_rad = 0.0", "id = 2\nzero_count = 2048\nstart_rad = 0.0\nlevels_v = [-1.0, 0.0, 1.0]");
    assert!(edited.contains("distance_squared") && edited.contains("levels_v = [-1.0, 0.0, 1.0]"), "arm2's robot.toml moved");
    let dir = out.join("words");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("robot.toml"), edited).unwrap();
    std::fs::copy(arm.join("arm2.urdf"), dir.join("arm2.urdf")).unwrap();
    let file = pada_robot_file::load(&dir.join("robot.toml")).unwrap_or_else(|e| panic!("{e}"));
    let source = pada_robot_file::rust_source(file.spec, "words/robot.toml").unwrap_or_else(|e| panic!("{e}"));
    std::fs::write(out.join("words_robot.rs"), source).unwrap();
}
