//! The firmware's build of a robot of files (`cargo xtask qemu|firmware
//! --robot PATH/robot.toml`, read by the firmware's build.rs): a bad file
//! stops the build with the reader's one line, naming the file, the line,
//! the field and the valid values, and no image is made.

mod common;

use std::process::Command;

#[test]
fn a_bad_robot_file_stops_the_firmware_build_with_the_readers_line() {
    let dir = tempfile::tempdir().unwrap();
    let example = common::root().join("examples/robots/arm2");
    let toml = std::fs::read_to_string(example.join("robot.toml")).unwrap();
    assert!(toml.contains("servo = \"XM430-W350\""));
    std::fs::copy(example.join("arm2.urdf"), dir.path().join("arm2.urdf")).unwrap();
    let bad = dir.path().join("robot.toml");
    std::fs::write(&bad, toml.replacen("servo = \"XM430-W350\"", "servo = \"XM999\"", 1)).unwrap();
    // The emulated board's build: its dependencies are the SIL tests'.
    let out = Command::new(env!("CARGO"))
        .current_dir(common::root())
        .args(["xtask", "qemu", "--board", "f405", "--robot"])
        .arg(&bad)
        .output()
        .expect("cannot run cargo xtask qemu");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    let line = format!("{}:", bad.display());
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error: ") && l.contains(&line)).collect();
    assert_eq!(errors.len(), 1, "one line names the file:\n{stderr}");
    for needle in ["joint[0].servo", "XM999", "valid are", "XM430-W350"] {
        assert!(errors[0].contains(needle), "{:?} lacks {needle:?}", errors[0]);
    }
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(!String::from_utf8_lossy(&out.stdout).contains("xtask: firmware ELF:"));
}
