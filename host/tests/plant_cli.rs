//! `pada run --plant`: learning on a robot that is not its model, seeded
//! and reproducible, and one clear line for every bad input.

mod common;
use common::*;
use std::path::Path;

/// trials.csv of `pada run` with `extra` flags on the physical pendulum.
fn trials_csv(dir: &Path, name: &str, extra: &[&str]) -> String {
    let out = dir.join(name).display().to_string();
    let mut args = vec![
        "run", "--task", "physical-pendulum", "--algo", "pada", "--trials", "2", "--seconds", "30", "--threads", "1", "--seed", "4",
        "--out", &out,
    ];
    args.extend_from_slice(extra);
    ok(&pada(&args));
    std::fs::read_to_string(dir.join(name).join("trials.csv")).unwrap()
}

#[test]
fn a_differing_plant_repeats_with_its_seed_and_learns_otherwise_than_the_model() {
    let dir = tempfile::tempdir().unwrap();
    let model = trials_csv(dir.path(), "model", &[]);
    let drawn = trials_csv(dir.path(), "drawn", &["--plant", "drawn", "--plant-ranges", "motor_constant=0.5..0.6,delay_periods=1"]);
    let again = trials_csv(dir.path(), "again", &["--plant", "drawn", "--plant-ranges", "motor_constant=0.5..0.6,delay_periods=1"]);
    let randomised = trials_csv(dir.path(), "randomised", &["--plant", "randomised", "--plant-ranges", "motor_constant=0.5..0.6,delay_periods=1"]);
    assert_eq!(drawn, again, "the same seed draws the same plants");
    assert_ne!(drawn, model);
    assert_ne!(randomised, drawn);
}

#[test]
fn bad_plant_input_is_one_line() {
    assert_bad_input(&["run", "--task", "leo", "--algo", "pada", "--plant", "drawn"], &["--plant", "LEO"]);
    assert_bad_input(
        &["run", "--task", "physical-pendulum", "--algo", "pada", "--plant", "drawn", "--plant-ranges", "mass=9"],
        &["--plant-ranges", "mass 9", "valid is 0.2 to 5"],
    );
    assert_bad_input(
        &["run", "--task", "physical-pendulum", "--algo", "pada", "--plant", "drawn", "--plant-ranges", "stiffness=1"],
        &["stiffness", "valid are mass, motor_constant, friction_nm, backlash_rad, delay_periods, noise_rad"],
    );
    assert_bad_input(&["run", "--task", "physical-pendulum", "--algo", "pada", "--plant", "drawn", "--board", "f405"], &["--plant", "--board"]);
}
