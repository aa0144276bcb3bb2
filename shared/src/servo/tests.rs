//! Tests of the servo and gearbox tables: the RX-28 entry is GRL's motor bit
//! for bit, every datasheet-derived motor reproduces its datasheet, every
//! gearbox is valid and says where it is an estimate, lookups by name, and
//! `docs/reference/servos.md` equals the data.

extern crate std;

use super::gearbox::GEARBOX_NAMES;
use super::*;
use crate::fatigue::{FatigueModel, GearboxParams};
use crate::rx28::Rx28;
use std::string::{String, ToString};
use std::vec::Vec;

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

#[test]
fn rx28_motor_is_rx28_rs_constants_exactly() {
    let m = RX28.motor();
    assert_eq!(m, DcMotor::RX28);
    assert_eq!(m.gear_ratio, crate::rx28::GEAR_RATIO);
    assert_eq!(m.torque_constant_nm_per_a, crate::rx28::TORQUE_CONSTANT);
    assert_eq!(m.resistance_ohm, crate::rx28::RESISTANCE);
    assert_eq!(m.efficiency, crate::rx28::EFFICIENCY);
    assert_eq!(m.armature_inertia, crate::rx28::ARMATURE_INERTIA);
    assert_eq!(m.dry_friction, crate::rx28::DRY_FRICTION);
    assert_eq!(m.supply_clip, crate::rx28::SUPPLY_CLIP);
    // The Rx28 form is LEO's, tracker included.
    assert_eq!(m.to_rx28(), Rx28::LEO);
    // The published motor constants are the same numbers.
    assert_eq!(RX28.resistance_ohm, Some(crate::rx28::RESISTANCE));
    assert_eq!(RX28.torque_constant_nm_per_a, Some(crate::rx28::TORQUE_CONSTANT));
}

#[test]
fn rx28_joint_torque_is_bit_for_bit_rx28_rs() {
    let m = RX28.motor();
    let leo = Rx28::LEO;
    let volts = [-20.0f32, -13.6, -10.691892, -3.3, 0.0, 0.1, 7.25, 10.691892, 13.6, 99.0, f32::NAN];
    let rates = [-9.0f32, -1.25, 0.0, 0.3, 4.0, 12.5, f32::INFINITY];
    for &u in &volts {
        assert_eq!(m.clip_voltage(u).to_bits(), leo.clip_voltage(u).to_bits());
        assert_eq!(m.no_load_speed(u).to_bits(), leo.no_load_speed(u).to_bits());
        for &w in &rates {
            assert_eq!(
                m.joint_torque(u, w).to_bits(),
                leo.estimate_joint_torque(u, w).to_bits(),
                "U = {u}, rate = {w}"
            );
            assert_eq!(m.current(u, w).to_bits(), leo.current(u, w).to_bits());
        }
        // Stall torque here is after η; Rx28's is before.
        assert_eq!(
            m.stall_torque(u).to_bits(),
            (leo.efficiency * leo.stall_torque(u)).to_bits()
        );
    }
}

#[test]
fn datasheet_motors_reproduce_their_datasheets() {
    let mut derived = 0;
    for s in SERVOS.iter() {
        let m = s.motor();
        assert!(m.is_valid(), "{}: {m:?}", s.name);
        if s.motor_source != MotorSource::Datasheet {
            continue;
        }
        derived += 1;
        let d = &s.datasheet;
        let v = d.rated_voltage_v;
        assert!(v <= m.supply_clip, "{}: rated voltage above the clip", s.name);
        assert!(
            rel(m.stall_torque(v) as f64, d.stall_torque_nm as f64) < 1e-5,
            "{}: stall torque {} vs {}",
            s.name,
            m.stall_torque(v),
            d.stall_torque_nm
        );
        assert!(
            rel(m.no_load_speed(v) as f64, d.no_load_speed_rad_s() as f64) < 1e-5,
            "{}: no-load speed {} vs {}",
            s.name,
            m.no_load_speed(v),
            d.no_load_speed_rad_s()
        );
        assert!(
            rel(m.current(v, 0.0) as f64, d.stall_current_a as f64) < 1e-5,
            "{}: stall current",
            s.name
        );
        // At the no-load speed the torque vanishes.
        assert!(m.joint_torque(v, m.no_load_speed(v)).abs() < 1e-5 * d.stall_torque_nm);
        assert_eq!(m.gear_ratio, d.gear_ratio);
        assert_eq!(m.supply_clip, d.max_voltage_v);
        // The estimated rotor keeps the RX-28's mechanical time constant, the
        // friction the RX-28's fraction of the stall torque.
        let k = m.torque_constant_nm_per_a as f64;
        let tau = m.armature_inertia as f64 * m.resistance_ohm as f64 / (k * k);
        assert!(rel(tau, rx28_mechanical_time_constant_s()) < 1e-5, "{}", s.name);
        assert!(
            rel(m.dry_friction as f64 / d.stall_torque_nm as f64, rx28_friction_fraction()) < 1e-5
        );
    }
    assert_eq!(derived, SERVOS.len() - 1, "every model but the RX-28 is derived");
    assert!((rx28_mechanical_time_constant_s() - 7.55e-3).abs() < 1e-5);
}

#[test]
fn grl_rx28_differs_from_the_rx28_datasheet_as_documented() {
    // The module documentation states these figures; keep them true.
    let m = RX28.motor();
    let d = &RX28.datasheet;
    let mut wide = m;
    wide.supply_clip = 100.0; // the datasheet's 18.5 V is above GRL's clip
    let rpm = wide.no_load_speed(d.rated_voltage_v) as f64 * 30.0 / core::f64::consts::PI;
    assert!((rpm - 92.3).abs() < 0.05, "{rpm}");
    assert!((wide.stall_torque(d.rated_voltage_v) - 3.09).abs() < 0.005);
    assert!((wide.current(d.rated_voltage_v, 0.0) - 2.15).abs() < 0.005);
}

#[test]
fn model_numbers_protocols_and_lookup() {
    assert_eq!(RX28.model_number, crate::dynamixel::table::RX28_MODEL);
    for s in SERVOS.iter() {
        assert_eq!(servo(s.name).unwrap().name, s.name);
        assert_eq!(servo(&s.name.to_ascii_lowercase()).unwrap().name, s.name);
        // A model number names one model; the STS3215's gear variants
        // share theirs (the bus cannot tell the gears) and it names the
        // first of them, the C001.
        let by_number = servo_by_model_number(s.model_number).unwrap();
        assert_eq!(by_number.model_number, s.model_number);
        let sts = |m: &ServoModel| m.name.starts_with("STS3215");
        assert!(by_number.name == s.name || (sts(s) && by_number.name == "STS3215"), "{}", s.name);
        let g = s.gearbox().expect("every servo's gearbox exists");
        assert_eq!(g.name, s.gearbox);
        let (expected, number) = match s.name.as_bytes()[0] {
            b'X' => (ServoProtocol::V2, 2),
            b'S' => (ServoProtocol::Feetech, 1),
            _ => (ServoProtocol::V1, 1),
        };
        assert_eq!(s.protocol, expected, "{}", s.name);
        assert_eq!(s.protocol.number(), number, "{}", s.name);
        // Every Dynamixel figure is its e-Manual page's; a Feetech entry
        // names the page of docs/reference that lists its sources.
        match s.protocol {
            ServoProtocol::Feetech => assert!(s.source.contains("docs/reference/feetech.md"), "{}", s.name),
            _ => {
                assert!(s.source.starts_with("https://emanual.robotis.com/docs/en/dxl/"));
                assert_eq!(s.figure_notes, None, "{}", s.name);
            }
        }
    }
    let mut numbers: Vec<u16> = SERVOS.iter().filter(|s| s.name == "STS3215" || !s.name.starts_with("STS3215")).map(|s| s.model_number).collect();
    let models = numbers.len();
    numbers.sort();
    numbers.dedup();
    assert_eq!(numbers.len(), models);
    let e = servo("XM430-W999").unwrap_err().to_string();
    assert_eq!(
        e,
        "unknown servo model \"XM430-W999\": valid are RX-28, MX-28, XM430-W350, XL430-W250, XL330-M288, STS3215, STS3215-C044, STS3215-C046"
    );
    assert!(servo_by_model_number(1).is_none());
}

#[test]
fn gearboxes_are_valid_and_marked() {
    assert_eq!(gearbox("rx-28").unwrap().params, GearboxParams::TABLE_I);
    assert!(!gearbox("RX-28").unwrap().estimate, "Table I is measured");
    for g in GEARBOXES.iter() {
        g.params.validate().unwrap_or_else(|e| panic!("{}: {e}", g.name));
        FatigueModel::new(&g.params).unwrap();
        if g.name != "RX-28" {
            assert!(g.estimate, "{} is not measured", g.name);
            assert!(g.sources.geometry.starts_with("estimate"), "{}", g.name);
        }
        assert!(!g.note.is_empty());
    }
    let e = gearbox("nope").unwrap_err().to_string();
    for n in GEARBOX_NAMES.iter() {
        assert!(e.contains(n), "{e}");
    }
}

#[test]
fn estimated_gearboxes_follow_their_stated_rules() {
    let t = GearboxParams::TABLE_I;
    // Geometry: Table I's × case width / 35.6 mm, to three significant figures.
    for s in SERVOS.iter().filter(|s| s.datasheet.case_mm[0] != 35.6) {
        let g = s.gearbox().unwrap().params;
        let f = s.datasheet.case_mm[0] as f64 / 35.6;
        for (got, table) in [(g.d_w_mm, t.d_w_mm), (g.b_mm, t.b_mm), (g.m_n_mm, t.m_n_mm)] {
            assert!(rel(got, table * f) < 0.005, "{}: {got} vs {}", s.name, table * f);
        }
        assert_eq!((g.y_fa, g.y_sa, g.y_epsilon, g.y_beta, g.teeth), (t.y_fa, t.y_sa, t.y_epsilon, t.y_beta, t.teeth));
        assert_eq!(g.k_nm_per_rad, t.k_nm_per_rad);
        // Backlash: the datasheet's where published, else Table I's.
        match s.datasheet.backlash_arcmin {
            Some(a) => assert!(rel(g.theta_bl_rad, a as f64 / 60.0 * core::f64::consts::PI / 180.0) < 1e-6),
            None => assert_eq!(g.theta_bl_rad, t.theta_bl_rad),
        }
        // Fatigue: metal keeps Table I's; plastic passes 19 MPa at 1e7 cycles.
        let plastic = s.datasheet.gear_material.contains("Plastic");
        assert_eq!(g.d, t.d);
        if plastic {
            let at_1e7 = g.sigma_f_mpa * libm::pow(2.0e7, g.d);
            assert!((at_1e7 - 19.0).abs() < 0.01, "{}: {at_1e7}", s.name);
        } else {
            assert_eq!(g.sigma_f_mpa, t.sigma_f_mpa);
        }
    }
}

// ---- docs/reference/servos.md equals the data ----

const DOC: &str = include_str!("../../../docs/reference/servos.md");

/// The rows of the markdown table that follows the line `marker`, as cells.
fn table_after(marker: &str) -> Vec<Vec<String>> {
    let start = DOC.find(marker).unwrap_or_else(|| panic!("servos.md has no {marker:?}"));
    DOC[start..]
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .skip(2) // header and separator
        .map(|l| l.trim().trim_matches('|').split('|').map(|c| c.trim().to_string()).collect())
        .collect()
}

/// A number in a cell: the leading number of `12.0 V`, `[…](…)` links removed.
fn num(cell: &str) -> f64 {
    let s: String = cell
        .trim()
        .chars()
        .take_while(|c| c.is_ascii_digit() || matches!(c, '.' | '-' | 'e' | '−'))
        .map(|c| if c == '−' { '-' } else { c })
        .collect();
    s.parse().unwrap_or_else(|_| panic!("not a number: {cell:?}"))
}

/// The cell shows `v` rounded to the digits it prints: within half a unit
/// of its last digit (`0.0043633` shows 0.004363323, `1556` does not show
/// 1555).
fn shows(cell: &str, v: f64) -> bool {
    let n = num(cell);
    let text = cell.trim().replace('−', "-");
    let (mantissa, exponent) = match text.split_once('e') {
        Some((m, e)) => (m.to_string(), e.parse::<i32>().expect("exponent")),
        None => (text.clone(), 0),
    };
    let decimals = mantissa.split_once('.').map_or(0, |(_, f)| f.len() as i32);
    let unit = libm::pow(10.0, (exponent - decimals) as f64);
    (n - v).abs() <= 0.5 * unit * (1.0 + 1e-9)
}

#[test]
fn servos_md_servo_table_equals_the_data() {
    let rows = table_after("<!-- servo table -->");
    assert_eq!(rows.len(), SERVOS.len(), "one row per servo model");
    for (r, s) in rows.iter().zip(SERVOS.iter()) {
        let d = &s.datasheet;
        assert_eq!(r[0], s.name);
        assert_eq!(r[1], s.protocol.name(), "{}", s.name);
        assert_eq!(num(&r[2]), s.model_number as f64, "{}", s.name);
        assert_eq!(num(&r[3]) as f32, d.rated_voltage_v, "{}", s.name);
        // The e-Manual's figures are printed as given; the STS3215's
        // stall torque is converted from kgf·cm and its leader variants'
        // speeds are estimates: printed rounded.
        let exact = s.protocol != ServoProtocol::Feetech;
        let same = |cell: &str, v: f32| if exact { num(cell) as f32 == v } else { shows(cell, v as f64) };
        assert!(same(&r[4], d.stall_torque_nm), "{}: {}", s.name, r[4]);
        assert_eq!(num(&r[5]) as f32, d.stall_current_a, "{}", s.name);
        assert!(same(&r[6], d.no_load_speed_rpm), "{}: {}", s.name, r[6]);
        assert_eq!(num(&r[7]) as f32, d.gear_ratio, "{}", s.name);
        assert_eq!(num(&r[8]) as f32, d.max_voltage_v, "{}", s.name);
        match d.backlash_arcmin {
            Some(b) => assert_eq!(num(&r[9]) as f32, b, "{}", s.name),
            None => assert_eq!(r[9], "—", "{}", s.name),
        }
        assert_eq!(r[10], d.gear_material, "{}", s.name);
        assert_eq!(r[11], s.gearbox, "{}", s.name);
        assert!(r[12].contains(s.source), "{}: source {}", s.name, r[12]);
    }
}

#[test]
fn servos_md_motor_table_equals_the_data() {
    let rows = table_after("<!-- motor table -->");
    assert_eq!(rows.len(), SERVOS.len(), "one row per servo model");
    for (r, s) in rows.iter().zip(SERVOS.iter()) {
        let m = s.motor();
        assert_eq!(r[0], s.name);
        assert!(shows(&r[1], m.torque_constant_nm_per_a as f64), "{}: k {}", s.name, r[1]);
        assert!(shows(&r[2], m.resistance_ohm as f64), "{}: R {}", s.name, r[2]);
        assert!(shows(&r[3], m.efficiency as f64), "{}: η {}", s.name, r[3]);
        assert!(shows(&r[4], m.armature_inertia as f64), "{}: J_a {}", s.name, r[4]);
        assert!(shows(&r[5], m.dry_friction as f64), "{}: friction {}", s.name, r[5]);
        assert!(shows(&r[6], m.supply_clip as f64), "{}: clip {}", s.name, r[6]);
        let given = matches!(s.motor_source, MotorSource::Given(_));
        assert_eq!(r[7].starts_with("GRL"), given, "{}: source {}", s.name, r[7]);
    }
}

#[test]
fn servos_md_gearbox_table_equals_the_data() {
    let rows = table_after("<!-- gearbox table -->");
    assert_eq!(rows.len(), GEARBOXES.len(), "one row per gearbox");
    for (r, g) in rows.iter().zip(GEARBOXES.iter()) {
        let p = &g.params;
        assert_eq!(r[0], g.name);
        assert_eq!(r[1], if g.estimate { "estimate" } else { "measured" }, "{}", g.name);
        let want = [
            p.theta_bl_rad,
            p.k_nm_per_rad,
            p.d,
            p.sigma_f_mpa,
            p.b_mm,
            p.m_n_mm,
            p.d_w_mm,
            p.y_fa,
            p.y_sa,
            p.y_epsilon,
            p.y_beta,
            p.teeth as f64,
        ];
        for (i, w) in want.iter().enumerate() {
            assert!(shows(&r[2 + i], *w), "{}: column {} shows {} for {w}", g.name, 2 + i, r[2 + i]);
        }
    }
}
