//! A differing plant against its model: each parameter moves the plant the
//! way it should, and a seed repeats its plants.

use super::*;
use crate::pendulum::{PhysicalPendulumParams, PhysicalPendulumTask};
use crate::task::{Plant, Task};
use crate::urdf::{UrdfBody, UrdfModel, UrdfTask};
use pada_core::limits::MAX_SERVOS;
use rand_core::SeedableRng;
use std::path::Path;

fn ranges(arg: &str) -> PlantRanges {
    PlantRanges::MODEL.with_arg(arg).unwrap()
}

/// The angles the plant reads over `steps` of `command` from its start.
fn readings<P: Plant>(plant: &mut P, command: &[f32], steps: usize, seed: u64) -> Vec<f32> {
    observed(plant, command, steps, seed, 0)
}

/// Observation `k` over `steps` of `command` from the plant's start.
fn observed<P: Plant>(plant: &mut P, command: &[f32], steps: usize, seed: u64, k: usize) -> Vec<f32> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let mut obs = [0.0f32; 8];
    plant.reset(&mut rng, &mut obs);
    let mut out = vec![obs[k]];
    for _ in 0..steps {
        plant.step(command, &mut obs);
        out.push(obs[k]);
    }
    out
}

#[test]
fn a_pendulum_whose_motor_is_weaker_swings_less_and_the_model_is_untouched() {
    // The rates after 5 periods of 3 V from hanging at rest.
    let model = PhysicalPendulumTask::default();
    let nominal = observed(&mut model.plant(), &[3.0], 5, 1, 1);
    // Ranges of single values: the model's values give the model's plant.
    let same = Varied::new(PhysicalPendulumTask::default(), PlantRanges::MODEL, Redraw::PerTrial);
    assert_eq!(observed(&mut same.plant(), &[3.0], 5, 1, 1), nominal);
    let weak = Varied::new(PhysicalPendulumTask::default(), ranges("motor_constant=0.5"), Redraw::PerTrial);
    let w = observed(&mut weak.plant(), &[3.0], 5, 1, 1);
    let (dn, dw) = (nominal[5].abs(), w[5].abs());
    assert!(dw < 0.7 * dn && dw > 0.0, "{dw} rad/s vs the model's {dn}");
    // Friction thrice the motor's stall torque holds it nearly still
    // (the sign is smoothed: it creeps).
    let stuck = Varied::new(PhysicalPendulumTask::default(), ranges("friction_nm=0.05"), Redraw::PerTrial);
    let s = observed(&mut stuck.plant(), &[3.0], 5, 1, 1);
    assert!(s[5].abs() < 0.1 * dn, "{s:?} vs the model's {dn}");
}

#[test]
fn a_delayed_command_arrives_whole_periods_late() {
    let late = Varied::new(PhysicalPendulumTask::default(), ranges("delay_periods=2"), Redraw::PerTrial);
    let mut p = late.plant();
    let r = readings(&mut p, &[3.0], 4, 1);
    // Two periods of nothing (hanging at rest), then the voltage.
    assert_eq!(&r[..3], &[r[0]; 3]);
    assert_ne!(r[3], r[0]);
    // The torque counted is the applied one: none in the first periods.
    let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
    let mut obs = [0.0f32; 2];
    p.reset(&mut rng, &mut obs);
    p.step(&[3.0], &mut obs);
    assert_eq!(p.commanded_torques(&[3.0])[0], 0.0);
}

#[test]
fn plants_repeat_with_the_seed_and_redraw_per_episode_only_when_asked() {
    let r = ranges("mass=0.8..1.2,motor_constant=0.8..1.2,noise_rad=0.001");
    let draws = |redraw, seed| {
        let task = Varied::new(PhysicalPendulumTask::default(), r, redraw);
        let mut p = task.plant();
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let mut obs = [0.0f32; 2];
        (0..3)
            .map(|_| {
                p.reset(&mut rng, &mut obs);
                *p.draw()
            })
            .collect::<Vec<_>>()
    };
    let once = draws(Redraw::PerTrial, 9);
    assert!(once.iter().all(|d| *d == once[0]) && once[0] != PlantDraw::MODEL);
    let every = draws(Redraw::PerEpisode, 9);
    assert!(every[0] != every[1] && every[1] != every[2]);
    assert_eq!(draws(Redraw::PerEpisode, 9), every);
    assert_ne!(draws(Redraw::PerEpisode, 10), every);
}

fn reacher() -> pada_robot_file::RobotFile {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../robot-file/tests/data/reacher/robot.toml");
    pada_robot_file::load(&path).unwrap()
}

/// The shoulder's angle after 3 periods of 2 V on `model`'s body.
fn swung(model: &UrdfModel) -> f32 {
    let mut body = UrdfBody::new(model).unwrap();
    let mut volts = [0.0; MAX_SERVOS];
    volts[0] = 2.0;
    body.set_voltages(&volts);
    let start = body.angles()[0];
    for _ in 0..3 {
        body.step_period().unwrap();
    }
    body.angles()[0] - start
}

#[test]
fn a_robot_of_files_varies_in_mass_motor_and_friction() {
    let model = UrdfModel::load(&reacher()).unwrap();
    let nominal = swung(&model);
    assert!(nominal.abs() > 1e-3, "{nominal}");
    // The model's own values build the model's body, bit for bit.
    assert_eq!(swung(&model.varied(&PlantDraw::MODEL)), nominal);
    let d = |mass, motor_constant, friction_nm| PlantDraw { mass, motor_constant, friction_nm, ..PlantDraw::MODEL };
    // A larger constant: more torque per volt but more back-EMF; the
    // servo's no-load speed U/(G·k) is what the arm reaches within a period.
    let strong = swung(&model.varied(&d(1.0, 2.0, 0.0)));
    assert!(strong.abs() < 0.8 * nominal.abs() && strong.abs() > 0.3 * nominal.abs(), "{strong} vs {nominal}");
    assert!(swung(&model.varied(&d(1.0, 1.0, 5.0))).abs() < 0.05 * nominal.abs());
    let heavy = swung(&model.varied(&d(3.0, 1.0, 0.0)));
    assert!(heavy != nominal, "a heavier arm moves otherwise: {heavy} vs {nominal}");
    // And a task's plant reads its joints through the drawn sensor.
    let task = UrdfTask::new(&reacher()).unwrap();
    let noisy = Varied::new(task, ranges("noise_rad=0.01"), Redraw::PerTrial);
    let r = readings(&mut noisy.plant(), &[0.0, 0.0], 3, 2);
    assert!(r.windows(2).any(|w| w[0] != w[1]), "{r:?}");
}

#[test]
fn the_model_params_are_the_model() {
    // A varied copy with the model's draw is equal to the model's constants.
    use crate::pendulum::PendulumModel;
    let p = PhysicalPendulumParams::default();
    assert_eq!(p.varied(&PlantDraw::MODEL), p);
}
