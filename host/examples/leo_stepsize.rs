//! Step-size study for the LEO model (README.md table): for each
//! (physics steps per control period, rapier solver iterations) it measures
//! the passive fall against the same settings at half the step (the
//! convergence criterion of sim/src/leo/README.md), accuracy under random actions against a fine
//! reference, the sanity checks, then speed.
//!
//! cargo run --release -p pada --example leo_stepsize [-- quick]
use pada::leo::constants::*;
use pada::leo::model::*;
use pada::leo::passive::passive_rollout;
use pada::leo::*;
use rand_core::{RngCore, SeedableRng};

const LEVELS: [f32; 7] = [-10.7, -7.1333, -3.5667, 0.0, 3.5667, 7.1333, 10.7];

fn cfg(sub: u32, it: usize) -> LeoConfig {
    LeoConfig {
        model: ModelOptions {
            substeps: sub,
            solver_iterations: it,
            ..Default::default()
        },
        ..Default::default()
    }
}

fn sequences(n: usize, len: usize, seed: u64) -> Vec<Vec<[f32; 3]>> {
    let mut rng = rand_pcg::Pcg32::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            (0..len)
                .map(|_| [0, 1, 2].map(|_| LEVELS[(rng.next_u32() % 7) as usize]))
                .collect()
        })
        .collect()
}

/// Torso pitch and the seven joint angles (unmirrored) after each step of
/// each sequence (NaN after a terminal).
fn rollouts(c: LeoConfig, seqs: &[Vec<[f32; 3]>]) -> Vec<Vec<[f32; 8]>> {
    let mut env = LeoEnv::new(c).unwrap();
    let mut rng = rand_pcg::Pcg32::seed_from_u64(0);
    seqs.iter()
        .map(|s| {
            env.reset(&mut rng);
            let mut done = false;
            s.iter()
                .map(|a| {
                    if done {
                        return [f32::NAN; 8];
                    }
                    let r = env.step(*a);
                    done = r.terminal != Terminal::None;
                    let s = env.model().state();
                    let mut x = [s.torso_pitch; 8];
                    x[1..].copy_from_slice(&s.angles);
                    x
                })
                .collect()
        })
        .collect()
}

/// RMS angle error (rad, torso pitch and joints) after 3 and after 6
/// control steps (0.1 s and 0.2 s), over the sequences alive in both.
fn error(reference: &[Vec<[f32; 8]>], test: &[Vec<[f32; 8]>]) -> (f64, f64) {
    let at = |k: usize| {
        let (mut se, mut n) = (0.0f64, 0usize);
        for (a, b) in reference.iter().zip(test) {
            if a[k][0].is_nan() || b[k][0].is_nan() {
                continue;
            }
            n += 8;
            se += a[k]
                .iter()
                .zip(&b[k])
                .map(|(x, y)| ((x - y) as f64).powi(2))
                .sum::<f64>();
        }
        (se / n.max(1) as f64).sqrt()
    };
    (at(2), at(5))
}

fn model(sub: u32, it: usize, f: impl FnOnce(&mut ModelOptions)) -> LeoModel {
    let mut o = ModelOptions {
        substeps: sub,
        solver_iterations: it,
        ..Default::default()
    };
    f(&mut o);
    LeoModel::new(o, &InitialPose::REFERENCE).unwrap()
}

/// Energy drift (J, max |E − E0|) of the torso-welded robot swinging its
/// limbs under gravity for 10 s, contacts/friction/back-EMF/stop damping off.
fn energy_drift(sub: u32, it: usize) -> (f32, f32) {
    let mut m = model(sub, it, pada::model_presets::lossless_fixed_torso);
    m.set_velocities([3.0, 2.0, -2.0, -3.0, 3.0, 4.0, -4.0], [0.0; 3]);
    let e0 = m.energy().total();
    let mut worst = 0.0f32;
    for _ in 0..300 {
        if m.control_step().is_err() {
            return (f32::NAN, f32::NAN);
        }
        worst = worst.max((m.energy().total() - e0).abs());
    }
    (worst, m.energy().kinetic)
}

/// The passive rollout (0 V on the learned joints, held joints on) at
/// these settings and at half the step: fall time (task's, s), |φ| = 1
/// crossing (interpolated, s), its change at half the step (%), and the
/// largest torso-angle difference until the fall (rad).
fn passive_fall(sub: u32, it: usize) -> (f32, f32, f32, f32) {
    let o = ModelOptions {
        substeps: sub,
        solver_iterations: it,
        ..Default::default()
    };
    let half = ModelOptions {
        substeps: 2 * sub,
        ..o
    };
    let (Ok(a), Ok(b)) = (passive_rollout(o, 2.0), passive_rollout(half, 2.0)) else {
        return (f32::NAN, f32::NAN, f32::NAN, f32::NAN);
    };
    let cross = |r: &pada::leo::passive::PassiveRollout| {
        r.torso_crossing_time(FALL_TORSO_ANGLE).unwrap_or(f32::NAN)
    };
    (
        a.fall_time_s.unwrap_or(f32::NAN),
        cross(&a),
        100.0 * (cross(&a) / cross(&b) - 1.0),
        a.largest_torso_angle_difference(&b),
    )
}

/// 0 V on every joint (no P controllers), on the floor: largest energy gain over the start (J), kinetic
/// energy after 5 s (J), deepest penetration of any foot sphere (mm).
fn passive(sub: u32, it: usize) -> (f32, f32, f32) {
    let mut m = model(sub, it, |_| {});
    let e0 = m.energy().total();
    let (mut gain, mut pen) = (f32::MIN, 0.0f32);
    for _ in 0..150 {
        if m.control_step().is_err() {
            return (f32::NAN, f32::NAN, f32::NAN);
        }
        gain = gain.max(m.energy().total() - e0);
        pen = pen.max(-m.foot_clearances().iter().cloned().fold(f32::MAX, f32::min));
    }
    (gain, m.energy().kinetic, pen * 1000.0)
}

/// Joint limits: torso welded, no floor, every joint driven at +10.7 V
/// for 1 s then −10.7 V for 1 s. Largest excursion beyond a limit (rad).
fn limits(sub: u32, it: usize) -> f32 {
    let mut m = model(sub, it, |o| {
        o.contacts = false;
        o.fixed_torso = true;
    });
    let mut worst = 0.0f32;
    for u in [10.7f32, -10.7] {
        m.set_voltages([u; NUM_JOINTS]);
        for _ in 0..30 {
            if m.control_step().is_err() {
                return f32::NAN;
            }
            let (q, _) = m.joint_state();
            for j in JOINTS {
                if let Some([lo, hi]) = joint_limits(j) {
                    worst = worst.max(q[j as usize] - hi).max(lo - q[j as usize]);
                }
            }
        }
    }
    worst
}

/// Shoulder speed after one control period from rest at 10.6919 V (torso
/// welded, no gravity, no dry friction), relative error against the exact
/// first-order response v∞·(1 − exp(−T·d/J)).
fn motor_response(sub: u32, it: usize) -> f32 {
    let servo = pada_core::rx28::Rx28::LEO.reduced();
    let r2 = ARM_COM[0] * ARM_COM[0] + ARM_COM[1] * ARM_COM[1];
    let j = ARM_IYY + ARM_MASS * r2 + servo.armature;
    let u = pada_core::rx28::LEO_MAX_VOLTAGE;
    let expect = servo.voltage_torque(u) / servo.damping
        * (1.0 - (-CONTROL_PERIOD * servo.damping / j).exp());
    let mut m = model(sub, it, pada::model_presets::servo_bench);
    let mut v = [0.0; NUM_JOINTS];
    v[Joint::Shoulder as usize] = u;
    m.set_voltages(v);
    if m.control_step().is_err() {
        return f32::NAN;
    }
    m.joint_state().1[Joint::Shoulder as usize] / expect - 1.0
}

/// Random-action statistics: mean episode length (steps), mean return, blow-ups,
/// and the real-time factor (min of 3 runs) over `secs` simulated seconds.
fn random(sub: u32, it: usize, secs: f32) -> (f64, f64, u64, f64) {
    let mut best = 0.0f64;
    let mut stats = (0.0, 0.0, 0);
    for rep in 0..3 {
        let mut env = LeoEnv::new(cfg(sub, it)).unwrap();
        let mut rng = rand_pcg::Pcg32::seed_from_u64(1);
        let steps = (secs * 30.0) as usize;
        let t0 = std::time::Instant::now();
        env.reset(&mut rng);
        let (mut eps, mut ret) = (0u64, 0.0f64);
        for _ in 0..steps {
            let a = [0, 1, 2].map(|_| LEVELS[(rng.next_u32() % 7) as usize]);
            let r = env.step(a);
            ret += r.reward as f64;
            if r.terminal != Terminal::None {
                eps += 1;
                env.reset(&mut rng);
            }
        }
        best = best.max(secs as f64 / t0.elapsed().as_secs_f64());
        if rep == 0 {
            stats = (steps as f64 / eps as f64, ret / eps as f64, env.blow_ups());
        }
    }
    (stats.0, stats.1, stats.2, best)
}

fn main() {
    let quick = std::env::args().any(|a| a == "quick");
    let seqs = sequences(if quick { 40 } else { 200 }, 10, 42);
    let (rs, ri) = (48u32, 1usize);
    println!(
        "reference: {rs} steps x {ri} iterations (h = {:.3} ms per solver sub-step)\n",
        1000.0 / (30.0 * (rs as f32) * ri as f32)
    );
    let reference = rollouts(cfg(rs, ri), &seqs);
    println!("| steps/period | iterations | h (ms) | passive fall (s) | \\|φ\\| = 1 at (s) | at half the step | max \\|Δφ\\| vs half step (rad) | angle err 0.1 s (rad) | angle err 0.2 s (rad) | energy drift 10 s (J) | 0 V: max gain (J) | KE after 5 s (J) | max foot penetration (mm) | limit overshoot (rad) | motor response error | mean episode (steps) | mean return | blow-ups | RTF |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let configs: &[(u32, usize)] = &[
        (1, 1),
        (2, 1),
        (3, 1),
        (4, 1),
        (6, 1),
        (8, 1),
        (12, 1),
        (16, 1),
        (24, 1),
        (48, 1),
        (96, 1),
        (3, 2),
        (4, 2),
    ];
    for &(s, i) in configs {
        let (fall, cross, dcross, dphi) = passive_fall(s, i);
        let (ea, er) = error(&reference, &rollouts(cfg(s, i), &seqs));
        let (drift, _) = energy_drift(s, i);
        let (gain, ke, pen) = passive(s, i);
        let lim = limits(s, i);
        let resp = motor_response(s, i);
        let (len, ret, blow, rtf) = random(s, i, if quick { 30.0 } else { 120.0 });
        println!("| {s} | {i} | {:.2} | {fall:.3} | {cross:.4} | {dcross:+.2}% | {dphi:.4} | {ea:.3} | {er:.3} | {drift:.4} | {gain:.4} | {ke:.1e} | {pen:.2} | {lim:.4} | {:+.1}% | {len:.1} | {ret:.1} | {blow} | {rtf:.0} |", 1000.0 * CONTROL_PERIOD / s as f32, 100.0 * resp);
    }
}
