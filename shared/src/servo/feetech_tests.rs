//! Tests of the Feetech table: the STS3215's motor reproduces its listing,
//! its gearbox follows the estimate rules the other models' do, lookups
//! by name, and `docs/reference/servos.md` equals the data.

extern crate std;

use super::feetech::{feetech_servo, FEETECH_NAMES, FEETECH_SERVOS, STS3215};
use super::*;
use crate::fatigue::{FatigueModel, GearboxParams};
use std::string::{String, ToString};
use std::vec::Vec;

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

#[test]
fn sts3215_motor_reproduces_its_listing() {
    for s in FEETECH_SERVOS.iter() {
        let m = s.motor();
        assert!(m.is_valid(), "{}: {m:?}", s.name);
        let d = &s.datasheet;
        let v = d.rated_voltage_v;
        assert!(rel(m.stall_torque(v) as f64, d.stall_torque_nm as f64) < 1e-5, "{}", s.name);
        assert!(rel(m.current(v, 0.0) as f64, d.stall_current_a as f64) < 1e-5, "{}", s.name);
        assert!(rel(m.no_load_speed(v) as f64, d.no_load_speed_rad_s() as f64) < 1e-5, "{}", s.name);
        assert!(m.efficiency > 0.0 && m.efficiency <= 1.0);
    }
    // 19.5 kgf·cm, 52 rev/min and 2.7 A at 7.4 V.
    let m = STS3215.motor();
    assert!((STS3215.datasheet.stall_torque_nm - 1.9123).abs() < 1e-4);
    assert!((m.resistance_ohm - 2.7407).abs() < 1e-3, "{}", m.resistance_ohm);
    assert!((m.back_emf_constant() - 1.3590).abs() < 1e-3, "{}", m.back_emf_constant());
    assert!((m.efficiency - 0.5212).abs() < 1e-3, "{}", m.efficiency);
    assert_eq!(STS3215.model_number, 777);
    assert_eq!(STS3215.gearbox.name, "STS3215");
    assert!(STS3215.stall_current_source.contains("no Feetech page"));
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
}

#[test]
fn feetech_lookup_by_name() {
    assert_eq!(feetech_servo(" sts3215 ").unwrap().variant, "C001");
    let e = feetech_servo("STS3250").unwrap_err().to_string();
    for n in FEETECH_NAMES.iter() {
        assert!(e.contains(n), "{e}");
    }
    // Kept apart from the Dynamixel table until pada speaks its protocol.
    assert!(servo("STS3215").is_err());
}

// ---- docs/reference/servos.md equals the data ----

const DOC: &str = include_str!("../../../docs/reference/servos.md");

fn table_after(marker: &str) -> Vec<Vec<String>> {
    let start = DOC.find(marker).unwrap_or_else(|| panic!("servos.md has no {marker:?}"));
    DOC[start..]
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .skip(2)
        .map(|l| l.trim().trim_matches('|').split('|').map(|c| c.trim().to_string()).collect())
        .collect()
}

fn num(cell: &str) -> f64 {
    let s: String = cell.trim().chars().take_while(|c| c.is_ascii_digit() || matches!(c, '.' | '-' | 'e')).collect();
    s.parse().unwrap_or_else(|_| panic!("not a number: {cell:?}"))
}

/// Within half a unit of the cell's last printed digit.
fn shows(cell: &str, v: f64) -> bool {
    let text = cell.trim();
    let (mantissa, exponent) = match text.split_once('e') {
        Some((m, e)) => (m, e.parse::<i32>().expect("exponent")),
        None => (text, 0),
    };
    let decimals = mantissa.split_once('.').map_or(0, |(_, f)| f.len() as i32);
    (num(cell) - v).abs() <= 0.5 * libm::pow(10.0, (exponent - decimals) as f64) * (1.0 + 1e-9)
}

#[test]
fn servos_md_feetech_tables_equal_the_data() {
    let rows = table_after("<!-- feetech table -->");
    assert_eq!(rows.len(), FEETECH_SERVOS.len());
    for (r, s) in rows.iter().zip(FEETECH_SERVOS.iter()) {
        let d = &s.datasheet;
        assert_eq!((r[0].as_str(), r[1].as_str()), (s.name, s.variant));
        assert_eq!(num(&r[2]), s.model_number as f64);
        assert_eq!(num(&r[3]) as f32, d.rated_voltage_v);
        assert!(shows(&r[4], d.stall_torque_nm as f64), "{}", r[4]);
        assert_eq!(num(&r[5]) as f32, d.stall_current_a);
        assert_eq!(num(&r[6]) as f32, d.no_load_speed_rpm);
        assert_eq!(num(&r[7]) as f32, d.gear_ratio);
        assert_eq!(num(&r[8]) as f32, d.max_voltage_v);
        assert_eq!(num(&r[9]) as f32, d.backlash_arcmin.unwrap());
        assert_eq!(r[10], d.gear_material);
        assert_eq!(r[11], s.gearbox.name);
    }
    let rows = table_after("<!-- feetech motor table -->");
    assert_eq!(rows.len(), FEETECH_SERVOS.len());
    for (r, s) in rows.iter().zip(FEETECH_SERVOS.iter()) {
        let m = s.motor();
        assert_eq!(r[0], s.name);
        for (cell, v) in [
            (&r[1], m.torque_constant_nm_per_a),
            (&r[2], m.resistance_ohm),
            (&r[3], m.efficiency),
            (&r[4], m.armature_inertia),
            (&r[5], m.dry_friction),
            (&r[6], m.supply_clip),
        ] {
            assert!(shows(cell, v as f64), "{}: {cell} vs {v}", s.name);
        }
    }
}
