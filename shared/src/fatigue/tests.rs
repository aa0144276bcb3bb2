//! Tests of the fatigue model and counters against hand calculations, the
//! paper's figures and properties.

extern crate std;

use super::*;
use proptest::prelude::*;
use std::vec::Vec;

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

/// Hand calculation for T_m = 1.5 N·m with Table I:
///
/// - Eq. 3: 2·T_m·θ_bl·k = 2·1.5·0.01·106 = 3.18; T_m² = 2.25;
///   √5.43 = 2.330236; T_e,max = 1.5 + 2.330236 = 3.830236 N·m.
/// - Eq. 4: d_w·b·m_n = 18.5·4·0.4 = 29.6 mm³; ΠY = 2.15·2·1.22·1 = 5.246;
///   σ_max = 2·3830.236 N·mm / 29.6 mm³ · 5.246 = 258.800·5.246
///   = 1357.663 MPa.
/// - Eq. 5: σ_ar = 1357.663 / √2 = 960.013 MPa.
/// - Eq. 6: σ_ar/σ'_f = 960.013/4402 = 0.218086; 1/d = −3.816794;
///   ln(0.218086) = −1.522882; ·(−3.816794) = 5.812527; e^… = 334.445;
///   N_f = 167.222 cycles.
/// - Eq. 7 term: 1/(45·167.222) = 1.32890·10⁻⁴.
#[test]
fn hand_calculation_table_i_at_1_5_nm() {
    let p = GearboxParams::default();
    let t_e = p.t_e_max(1.5);
    assert!((t_e - 3.830236).abs() < 1e-6, "T_e,max = {t_e}");
    let s_max = p.sigma_max(t_e);
    assert!((s_max - 1357.663).abs() < 1e-3, "sigma_max = {s_max}");
    let s_ar = sigma_ar(s_max);
    assert!((s_ar - 960.013).abs() < 1e-3, "sigma_ar = {s_ar}");
    let n_f = p.cycles_to_failure(s_ar);
    assert!((n_f - 167.222).abs() < 1e-3, "N_f = {n_f}");
    let dj = p.damage_per_reengagement(1.5);
    assert!(rel(dj, 1.32890e-4) < 1e-5, "1/(45 N_f) = {dj}");
    // The precomputed form agrees with the step-by-step chain.
    let m = FatigueModel::new(&p).unwrap();
    assert!(rel(m.damage(1.5), dj) < 1e-13);
    assert!(rel(m.damage(-1.5), dj) < 1e-13);
}

#[test]
fn model_matches_chain_over_torques() {
    let p = GearboxParams::default();
    let m = FatigueModel::new(&p).unwrap();
    for i in 1..=2000 {
        let t = i as f64 * 0.005;
        assert!(rel(m.damage(t), p.damage_per_reengagement(t)) < 1e-12, "t = {t}");
    }
    assert_eq!(m.damage(0.0), 0.0);
    assert_eq!(p.damage_per_reengagement(0.0), 0.0);
}

#[test]
fn zero_torques_never_count() {
    let mut j = JointFatigue::new(&GearboxParams::default(), None).unwrap();
    for _ in 0..100 {
        assert_eq!(j.update(0.0), Ok(None));
        assert_eq!(j.update(-0.0), Ok(None));
    }
    assert_eq!((j.steps(), j.reengagements(), j.damage_raw()), (200, 0, 0));
    // Zeros between equal signs do not count either.
    for t in [1.0, 0.0, 1.0, 0.0, 0.0, 2.0] {
        assert_eq!(j.update(t), Ok(None));
    }
    assert_eq!(j.reengagements(), 0);
    assert_eq!(j.damage(), 0.0);
}

#[test]
fn sign_sequence_counts_two_reengagements_with_new_torque() {
    let p = GearboxParams::default();
    let mut j = JointFatigue::new(&p, None).unwrap();
    // +, 0, −, −, +: the first non-zero is not a re-engagement; + → −
    // across the zero is one (T_m = 0.7, the new torque), − → − is none,
    // − → + is the second (T_m = 1.2).
    assert_eq!(j.update(1.5), Ok(None));
    assert_eq!(j.update(0.0), Ok(None));
    let e1 = j.update(-0.7).unwrap().expect("re-engagement");
    assert_eq!(j.update(-1.5), Ok(None));
    let e2 = j.update(1.2).unwrap().expect("re-engagement");
    assert_eq!(e1.t_m, 0.7);
    assert_eq!(e2.t_m, 1.2);
    assert_eq!((j.steps(), j.reengagements()), (5, 2));
    let d1 = p.damage_per_reengagement(0.7f32 as f64);
    let d2 = p.damage_per_reengagement(1.2f32 as f64);
    assert!(rel(e1.damage, d1) < 1e-13 && rel(e2.damage, d2) < 1e-13);
    assert!(rel(j.damage(), d1 + d2) < 1e-10);
}

#[test]
fn non_finite_torque_is_an_error_and_changes_nothing() {
    let mut j = JointFatigue::new(&GearboxParams::default(), Some(10)).unwrap();
    j.update(1.0).unwrap();
    j.update(-1.0).unwrap();
    let before = j.clone();
    for t in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        assert_eq!(j.update(t), Err(FatigueError::NonFiniteTorque));
        assert_eq!(j, before);
    }
    let mut c = FatigueCounter::<3>::new(GearboxParams::default(), 0.05, None).unwrap();
    c.update(&[1.0, 1.0, 1.0]).unwrap();
    let before = c.clone();
    assert_eq!(c.update(&[-1.0, f32::NAN, -1.0]), Err(FatigueError::NonFiniteJointTorque { joint: 1 }));
    assert_eq!(c, before);
}

/// 3 million re-engagements at 1.5 N·m (increment 1.3289·10⁻⁴) must sum to
/// 3·10⁶·increment ≈ 398.67 within 10⁻⁹ relative. The Q16.48 accumulator
/// errs by at most 2⁻⁴⁹ per event (1.3·10⁻¹¹ relative). An f32 accumulator
/// fails this badly: near 400 its ulp is 3·10⁻⁵, a quarter of the
/// increment, so every addition rounds by up to ~10 % — checked below.
#[test]
fn three_million_small_increments_are_not_lost() {
    const N: u64 = 3_000_000;
    let p = GearboxParams::default();
    let mut j = JointFatigue::new(&p, None).unwrap();
    j.update(1.5).unwrap();
    for i in 0..N {
        let t = if i % 2 == 0 { -1.5 } else { 1.5 };
        j.update(t).unwrap();
    }
    assert_eq!(j.reengagements(), N);
    let inc = j.model().damage(1.5);
    let exact = N as f64 * inc;
    assert!(rel(j.damage(), exact) < 1e-9, "J = {}, exact {exact}", j.damage());
    assert!(rel(j.damage(), N as f64 * p.damage_per_reengagement(1.5)) < 1e-9);

    let mut naive = 0.0f32;
    for _ in 0..N {
        naive += inc as f32;
    }
    assert!(rel(naive as f64, exact) > 1e-3, "an f32 sum would fail: {naive}");
}

#[test]
fn window_stops_accumulating_after_n_steps_while_total_continues() {
    let p = GearboxParams::default();
    let mut j = JointFatigue::new(&p, Some(10)).unwrap();
    // Steps 1..=10: +, then 9 alternations → 9 re-engagements in window.
    for i in 0..10 {
        j.update(if i % 2 == 0 { 1.0 } else { -1.0 }).unwrap();
    }
    let wd = j.window_damage().unwrap();
    assert_eq!(j.window_reengagements(), Some(9));
    assert_eq!(j.damage(), wd);
    for i in 0..20 {
        j.update(if i % 2 == 0 { 1.0 } else { -1.0 }).unwrap();
    }
    assert_eq!(j.steps(), 30);
    assert_eq!(j.window_steps(), Some(10));
    assert_eq!(j.window_reengagements(), Some(9));
    assert_eq!(j.window_damage(), Some(wd));
    assert_eq!(j.reengagements(), 29);
    assert!(rel(j.damage(), 29.0 * p.damage_per_reengagement(1.0)) < 1e-10);
    assert!(rel(wd, 9.0 * p.damage_per_reengagement(1.0)) < 1e-10);
    // Windowed MTBF uses only the window's 10 steps.
    assert!(rel(j.window_mtbf_s(0.05).unwrap(), 10.0 * 0.05 / wd) < 1e-15);
    // No window: no window figures.
    let k = JointFatigue::new(&p, None).unwrap();
    assert_eq!((k.window_damage(), k.window_mtbf_s(0.05), k.report(0.05).window), (None, None, None));
}

#[test]
fn mtbf_is_elapsed_over_damage() {
    let mut c = FatigueCounter::<1>::new(GearboxParams::default(), 0.05, None).unwrap();
    assert_eq!(c.predicted_mtbf_s(0), Some(f64::INFINITY));
    for t in [1.0, -1.0, 0.0, 0.5, 0.0, 0.0, -2.0] {
        c.update(&[t]).unwrap();
    }
    let j = c.joint(0).unwrap();
    assert_eq!(j.reengagements(), 3);
    assert_eq!(c.elapsed_s(), 7.0 * 0.05);
    assert_eq!(c.predicted_mtbf_s(0), Some(c.elapsed_s() / j.damage()));
    assert_eq!(c.predicted_mtbf_s(1), None);
    let r = c.report(0).unwrap();
    assert_eq!((r.steps, r.reengagements, r.damage, r.mtbf_s), (7, 3, j.damage(), c.elapsed_s() / j.damage()));
    c.reset();
    assert_eq!((c.steps(), c.robot_mtbf_s()), (0, f64::INFINITY));
}

#[test]
fn robot_mtbf_is_min_over_joints() {
    let mut c = FatigueCounter::<3>::new(GearboxParams::default(), 0.05, Some(100)).unwrap();
    // Joint 0 never re-engages, joint 1 at 0.5 N·m, joint 2 at 1.5 N·m.
    for i in 0..50 {
        let s = if i % 2 == 0 { 1.0 } else { -1.0 };
        c.update(&[1.0, 0.5 * s, 1.5 * s]).unwrap();
    }
    let m: Vec<f64> = (0..3).map(|j| c.predicted_mtbf_s(j).unwrap()).collect();
    assert_eq!(m[0], f64::INFINITY);
    assert!(m[2] < m[1]);
    assert_eq!(c.robot_mtbf_s(), m[2]);
    assert_eq!(c.robot_windowed_mtbf_s(), c.windowed_mtbf_s(2));
    assert_eq!(c.reports()[2], c.report(2).unwrap());
    let none = FatigueCounter::<2>::new(GearboxParams::default(), 0.05, None).unwrap();
    assert_eq!((none.robot_mtbf_s(), none.robot_windowed_mtbf_s()), (f64::INFINITY, None));
}

#[test]
fn parameter_validation_names_the_parameter() {
    fn param_of(p: GearboxParams) -> &'static str {
        match p.validate() {
            Err(FatigueError::InvalidParameter { param, .. }) => param,
            other => panic!("expected an error, got {other:?}"),
        }
    }
    let t1 = GearboxParams::default();
    assert_eq!(t1.validate(), Ok(()));
    assert_eq!(param_of(GearboxParams { theta_bl_rad: -0.1, ..t1 }), "theta_bl_rad");
    assert_eq!(param_of(GearboxParams { k_nm_per_rad: 0.0, ..t1 }), "k_nm_per_rad");
    assert_eq!(param_of(GearboxParams { d: 0.0, ..t1 }), "d");
    assert_eq!(param_of(GearboxParams { d: 0.3, ..t1 }), "d");
    assert_eq!(param_of(GearboxParams { d: f64::NAN, ..t1 }), "d");
    assert_eq!(param_of(GearboxParams { sigma_f_mpa: -4402.0, ..t1 }), "sigma_f_mpa");
    assert_eq!(param_of(GearboxParams { b_mm: 0.0, ..t1 }), "b_mm");
    assert_eq!(param_of(GearboxParams { m_n_mm: f64::INFINITY, ..t1 }), "m_n_mm");
    assert_eq!(param_of(GearboxParams { d_w_mm: -1.0, ..t1 }), "d_w_mm");
    assert_eq!(param_of(GearboxParams { y_fa: f64::NAN, ..t1 }), "y_fa");
    assert_eq!(param_of(GearboxParams { y_sa: 0.0, ..t1 }), "y_sa");
    assert_eq!(param_of(GearboxParams { y_epsilon: -1.0, ..t1 }), "y_epsilon");
    assert_eq!(param_of(GearboxParams { y_beta: 0.0, ..t1 }), "y_beta");
    assert_eq!(param_of(GearboxParams { teeth: 0, ..t1 }), "teeth");
    assert_eq!(GearboxParams { theta_bl_rad: 0.0, ..t1 }.validate(), Ok(()));

    let e = GearboxParams { k_nm_per_rad: -3.0, ..t1 }.validate().unwrap_err();
    let msg = std::format!("{e}");
    assert!(msg.contains("k_nm_per_rad") && msg.contains("-3") && msg.contains("0 < k_nm_per_rad"), "{msg}");

    let err = |r: Result<FatigueCounter<2>, FatigueError>| match r {
        Err(FatigueError::InvalidParameter { param, .. }) => param,
        _ => panic!("expected an error"),
    };
    assert_eq!(err(FatigueCounter::new(t1, 0.0, None)), "control_period_s");
    assert_eq!(err(FatigueCounter::new(t1, f64::NAN, None)), "control_period_s");
    assert_eq!(err(FatigueCounter::new(t1, f64::INFINITY, None)), "control_period_s");
    assert_eq!(err(FatigueCounter::new(t1, 0.05, Some(0))), "window_steps");
    assert_eq!(err(FatigueCounter::new(GearboxParams { teeth: 0, ..t1 }, 0.05, None)), "teeth");
}

/// Section VII: SARSA(λ) on the pendulum (±1.5 or 0 N·m at 20 Hz) has an
/// MTBF of 1596 s over the first 1200 actions. Window time = 1200·0.05 s
/// = 60 s, so J = 60/1596 = 0.0375940; each 1.5 N·m re-engagement adds
/// 1/(45·167.222) = 1.32890·10⁻⁴, so p = 0.0375940/1.32890·10⁻⁴ = 282.9
/// re-engagements (282 → MTBF 1601.1 s, +0.32 %; 283 → 1595.4 s).
#[test]
fn paper_sarsa_pendulum_mtbf_1596_s() {
    for p in [282u32, 283] {
        let mut c =
            FatigueCounter::<1>::new(GearboxParams::default(), 1.0 / 20.0, Some(PAPER_WINDOW_STEPS)).unwrap();
        // The first +1.5 is no re-engagement; then p alternations; then zeros.
        for step in 0..PAPER_WINDOW_STEPS {
            let t = if step <= p {
                if step % 2 == 0 {
                    1.5
                } else {
                    -1.5
                }
            } else {
                0.0
            };
            c.update(&[t]).unwrap();
        }
        // Steps after the window do not change the paper's figure.
        for step in 0..500 {
            c.update(&[if step % 2 == 0 { 1.5 } else { -1.5 }]).unwrap();
        }
        let j = c.joint(0).unwrap();
        assert_eq!(j.window_reengagements(), Some(p as u64));
        let mtbf = c.windowed_mtbf_s(0).unwrap();
        assert!(rel(mtbf, 1596.0) < 0.01, "p = {p}: MTBF {mtbf} s");
        assert_eq!(c.robot_windowed_mtbf_s(), Some(mtbf));
    }
}

proptest! {
    #[test]
    fn damage_monotone_and_reengagements_bounded(
        torques in proptest::collection::vec(
            prop_oneof![Just(0.0f32), Just(-0.0f32), -3.0f32..3.0, any::<f32>()],
            0..300,
        ),
        window in proptest::option::of(1u32..100),
    ) {
        let mut j = JointFatigue::new(&GearboxParams::default(), window).unwrap();
        let mut last = (j.damage_raw(), j.window_damage_raw());
        for t in torques {
            let before = j.clone();
            match j.update(t) {
                Ok(_) => {}
                Err(e) => {
                    prop_assert!(!t.is_finite());
                    prop_assert_eq!(e, FatigueError::NonFiniteTorque);
                    prop_assert_eq!(&j, &before);
                }
            }
            prop_assert!(j.damage_raw() >= last.0);
            prop_assert!(j.window_damage_raw() >= last.1);
            prop_assert!(j.damage() >= 0.0);
            prop_assert!(j.reengagements() <= j.steps().saturating_sub(1));
            prop_assert!(j.window_reengagements().unwrap_or(0) <= j.reengagements());
            last = (j.damage_raw(), j.window_damage_raw());
        }
    }

    #[test]
    fn larger_torque_gives_larger_damage(a in 0.001f64..50.0, f in 1.0001f64..10.0) {
        let p = GearboxParams::default();
        let m = FatigueModel::new(&p).unwrap();
        let b = a * f;
        prop_assert!(p.damage_per_reengagement(b) > p.damage_per_reengagement(a));
        prop_assert!(m.damage(b) > m.damage(a));
        prop_assert!(m.damage(-b) > m.damage(a));
    }
}
