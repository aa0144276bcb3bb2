//! Tests of the STS3215's entries: the C001's motor reproduces its
//! listing, the leader variants are the C001's motor behind their gears
//! (the stated estimate), every variant speaks Feetech with 4096 counts a
//! turn and runs its own loop, the gearbox follows the estimate rules, and
//! lookups by name and model number.

extern crate std;

use super::feetech::{STS3215, STS3215_C044, STS3215_C046};
use super::*;
use crate::fatigue::{FatigueModel, GearboxParams};
use std::string::ToString;

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

const VARIANTS: [&ServoModel; 3] = [&STS3215, &STS3215_C044, &STS3215_C046];

#[test]
fn sts3215_motor_reproduces_its_listing() {
    // 19.5 kgf·cm, 52 rev/min and 2.7 A at 7.4 V.
    let m = STS3215.motor();
    assert!(m.is_valid(), "{m:?}");
    assert!((STS3215.datasheet.stall_torque_nm - 1.9123).abs() < 1e-4);
    assert!((m.resistance_ohm - 2.7407).abs() < 1e-3, "{}", m.resistance_ohm);
    assert!((m.back_emf_constant() - 1.3590).abs() < 1e-3, "{}", m.back_emf_constant());
    assert!((m.efficiency - 0.5212).abs() < 1e-3, "{}", m.efficiency);
    assert_eq!(STS3215.datasheet.gear_ratio, 345.0);
    assert_eq!(STS3215.gearbox, "STS3215");
    // The stall current is not Feetech's, and the entry says so.
    assert!(STS3215.figure_notes.unwrap().contains("no Feetech page"));
}

#[test]
fn leader_variants_are_the_c001_motor_behind_their_gears() {
    let c001 = STS3215.motor();
    for (s, ratio) in [(&STS3215_C044, 191.0f32), (&STS3215_C046, 147.0)] {
        let m = s.motor();
        assert!(m.is_valid(), "{}: {m:?}", s.name);
        assert_eq!(s.datasheet.gear_ratio, ratio);
        assert_eq!(m.gear_ratio, ratio);
        // The same motor: k, R, η, supply; only G differs.
        assert!(rel(m.torque_constant_nm_per_a as f64, c001.torque_constant_nm_per_a as f64) < 1e-5, "{}", s.name);
        assert!(rel(m.resistance_ohm as f64, c001.resistance_ohm as f64) < 1e-6, "{}", s.name);
        assert!(rel(m.efficiency as f64, c001.efficiency as f64) < 1e-5, "{}", s.name);
        assert_eq!(m.supply_clip, c001.supply_clip);
        // Faster and weaker in proportion to the gears.
        let g = (ratio / 345.0) as f64;
        assert!(rel(s.datasheet.stall_torque_nm as f64, STS3215.datasheet.stall_torque_nm as f64 * g) < 1e-6);
        assert!(rel(s.datasheet.no_load_speed_rpm as f64, STS3215.datasheet.no_load_speed_rpm as f64 / g) < 1e-6);
        // Marked as estimates, metal assumed.
        assert!(s.figure_notes.unwrap().starts_with("estimate"), "{}", s.name);
        assert!(s.datasheet.gear_material.starts_with("Metal") && s.datasheet.gear_material.contains("assumed"));
    }
    // The listed "22 kg" at 1/191 would need η > 1 with the C001's motor:
    // why the estimate does not use it.
    let d = &STS3215_C044.datasheet;
    let eta = 22.0 * 0.0980665 * d.no_load_speed_rad_s() as f64 / (d.rated_voltage_v as f64 * d.stall_current_a as f64);
    assert!(eta > 1.0, "{eta}");
}

#[test]
fn every_variant_speaks_feetech_with_4096_counts_a_turn() {
    for s in VARIANTS {
        assert_eq!(s.protocol, ServoProtocol::Feetech, "{}", s.name);
        assert_eq!(s.protocol.codec(), crate::dynamixel::Protocol::Feetech);
        assert_eq!(s.protocol.name(), "Feetech");
        assert_eq!(s.model_number, 777);
        assert_eq!(s.encoding, encoding::STS3215);
        assert!((s.encoding.position.unit_rad() as f64 - core::f64::consts::TAU / 4096.0).abs() < 1e-9);
        assert_eq!(s.loop_gains, Some(LoopGains::FACTORY));
        assert_eq!(s.position_loop(LoopGains::LEROBOT), Some(PositionLoopSpec::sts3215(LoopGains::LEROBOT)));
        assert_eq!(s.datasheet.max_voltage_v, 7.4);
    }
    // The Dynamixels' position loops are not modelled.
    assert_eq!(XM430_W350.position_loop(LoopGains::FACTORY), None);
    assert_eq!(RX28.loop_gains, None);
    // Model number 777 names the C001: the bus cannot tell the gears.
    assert_eq!(servo_by_model_number(777).unwrap().name, "STS3215");
    assert_eq!(crate::feetech::control_table::by_model_number(777).map(|t| t.model), Some("STS3215"));
}

#[test]
fn sts3215_gearbox_follows_the_estimate_rules() {
    let g = gearbox("sts3215").unwrap();
    assert!(g.estimate);
    g.params.validate().unwrap();
    FatigueModel::new(&g.params).unwrap();
    let t = GearboxParams::TABLE_I;
    let f = STS3215.datasheet.case_mm[0] as f64 / 35.6;
    for (got, table) in [(g.params.d_w_mm, t.d_w_mm), (g.params.b_mm, t.b_mm), (g.params.m_n_mm, t.m_n_mm)] {
        assert!(rel(got, table * f) < 0.005, "{got} vs {}", table * f);
    }
    let bl = STS3215.datasheet.backlash_arcmin.unwrap() as f64 / 60.0 * core::f64::consts::PI / 180.0;
    assert!(rel(g.params.theta_bl_rad, bl) < 1e-9);
    // Metal: Table I's fatigue curve, said to be optimistic for brass.
    assert!(STS3215.datasheet.gear_material.starts_with("Metal"));
    assert_eq!((g.params.d, g.params.sigma_f_mpa), (t.d, t.sigma_f_mpa));
    assert!(g.note.contains("optimistic"));
    assert_eq!((g.params.k_nm_per_rad, g.params.teeth), (t.k_nm_per_rad, t.teeth));
    // One gearbox for the three variants.
    for s in VARIANTS {
        assert_eq!(s.gearbox().unwrap().name, "STS3215");
    }
}

#[test]
fn feetech_lookup_by_name() {
    assert_eq!(servo(" sts3215 ").unwrap().name, "STS3215");
    assert_eq!(servo("sts3215-c044").unwrap().datasheet.gear_ratio, 191.0);
    assert_eq!(servo("STS3215-C046").unwrap().datasheet.gear_ratio, 147.0);
    let e = servo("STS3250").unwrap_err().to_string();
    for s in VARIANTS {
        assert!(e.contains(s.name), "{e}");
    }
}

