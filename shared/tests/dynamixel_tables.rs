//! The Protocol 2.0 control tables: lookups, layout, the write checks a
//! virtual servo makes, and docs/reference/dynamixel.md's tables, which
//! must be exactly what the data in the code prints (regenerate them with
//! `PADA_WRITE_DOCS=1 cargo test -p pada-core --test dynamixel_tables`).

use pada_core::dynamixel::control_table::x_series::{self, HardwareError, PresentState};
use pada_core::dynamixel::control_table::*;
use pada_core::dynamixel::v2::ErrorNumber;
use pada_core::dynamixel::Protocol;

#[test]
fn tables_are_found_by_the_model_number_a_ping_returns() {
    let want = [(1020, "XM430-W350"), (1060, "XL430-W250"), (1200, "XL330-M288"), (30, "MX-28(2.0)")];
    for (n, model) in want {
        let t = by_model_number(n).unwrap();
        assert_eq!((t.model, t.model_number, t.protocol), (model, n, Protocol::V2));
        // Model Number is the first item, two bytes at 0, read only.
        assert_eq!(t.items[0].name, "Model Number");
        assert_eq!((t.items[0].address, t.items[0].size, t.items[0].access), (0, 2, Access::R));
    }
    assert!(by_model_number(28).is_none(), "the RX-28 speaks Protocol 1.0 and has no table here");
    assert_eq!(x_series::XM430_W350.baud_rate_bps(3), Some(1_000_000));
    assert_eq!(x_series::XM430_W350.baud_rate_bps(7), Some(4_500_000));
    assert_eq!(x_series::XL330_M288.baud_rate_bps(7), None);
    assert_eq!(x_series::XL330_M288.baud_rate_bps(1), Some(57_600));
}

#[test]
fn items_are_sorted_whole_and_inside_the_table() {
    for t in TABLES {
        let mut end = 0;
        for i in t.items {
            assert!(i.address >= end, "{}: {} overlaps the item before", t.model, i.name);
            assert!([1, 2, 4].contains(&i.size), "{}: {}", t.model, i.name);
            assert!(i.end() <= t.end, "{}: {}", t.model, i.name);
            assert_eq!(i.memory == Memory::Eeprom, i.address < 64, "{}: {} EEPROM is 0–63", t.model, i.name);
            end = i.end();
            if let Valid::Range(lo, hi) = i.valid {
                assert!(lo <= hi);
                let bits = 8 * i.size as u32;
                let (min, max) = if i.signed { (-(1i64 << (bits - 1)), (1i64 << (bits - 1)) - 1) } else { (0, (1i64 << bits) - 1) };
                assert!(lo >= min && hi <= max, "{}: {} range does not fit its size", t.model, i.name);
            }
        }
        assert_eq!(t.item_at(t.torque_enable).map(|i| i.name), Some("Torque Enable"));
        assert_eq!(t.item_at(t.operating_mode).map(|i| i.name), Some("Operating Mode"));
    }
}

#[test]
fn the_address_constants_name_the_same_items_in_every_table() {
    let consts = [
        (x_series::MODEL_NUMBER, "Model Number"),
        (x_series::FIRMWARE_VERSION, "Firmware Version"),
        (x_series::ID, "ID"),
        (x_series::BAUD_RATE, "Baud Rate"),
        (x_series::RETURN_DELAY_TIME, "Return Delay Time"),
        (x_series::DRIVE_MODE, "Drive Mode"),
        (x_series::OPERATING_MODE, "Operating Mode"),
        (x_series::HOMING_OFFSET, "Homing Offset"),
        (x_series::TEMPERATURE_LIMIT, "Temperature Limit"),
        (x_series::MAX_VOLTAGE_LIMIT, "Max Voltage Limit"),
        (x_series::MIN_VOLTAGE_LIMIT, "Min Voltage Limit"),
        (x_series::PWM_LIMIT, "PWM Limit"),
        (x_series::CURRENT_LIMIT, "Current Limit"),
        (x_series::VELOCITY_LIMIT, "Velocity Limit"),
        (x_series::MAX_POSITION_LIMIT, "Max Position Limit"),
        (x_series::MIN_POSITION_LIMIT, "Min Position Limit"),
        (x_series::SHUTDOWN, "Shutdown"),
        (x_series::TORQUE_ENABLE, "Torque Enable"),
        (x_series::LED, "LED"),
        (x_series::STATUS_RETURN_LEVEL, "Status Return Level"),
        (x_series::REGISTERED_INSTRUCTION, "Registered Instruction"),
        (x_series::HARDWARE_ERROR_STATUS, "Hardware Error Status"),
        (x_series::BUS_WATCHDOG, "Bus Watchdog"),
        (x_series::GOAL_PWM, "Goal PWM"),
        (x_series::GOAL_CURRENT, "Goal Current"),
        (x_series::GOAL_VELOCITY, "Goal Velocity"),
        (x_series::GOAL_POSITION, "Goal Position"),
        (x_series::PRESENT_PWM, "Present PWM"),
        (x_series::PRESENT_CURRENT, "Present Current"),
        (x_series::PRESENT_LOAD, "Present Load"),
        (x_series::PRESENT_VELOCITY, "Present Velocity"),
        (x_series::PRESENT_POSITION, "Present Position"),
        (x_series::PRESENT_INPUT_VOLTAGE, "Present Input Voltage"),
        (x_series::PRESENT_TEMPERATURE, "Present Temperature"),
    ];
    for t in TABLES {
        for (address, name) in consts {
            if let Some(i) = t.item_named(name) {
                assert_eq!(i.address, address, "{}: {name}", t.model);
            }
        }
    }
    // Every model has every item pada's control loop needs.
    for t in TABLES {
        for name in ["Goal PWM", "Present Position", "Present Velocity", "Bus Watchdog", "Hardware Error Status", "Operating Mode"] {
            assert!(t.item_named(name).is_some(), "{} lacks {name}", t.model);
        }
        // PWM Control Mode (16) everywhere.
        assert!(t.item_named("Operating Mode").unwrap().valid.contains(x_series::mode::PWM as i64));
    }
    // Current where there is a sensor, Load where there is none.
    let has = |t: &ControlTable, n: &str| t.item_named(n).is_some();
    assert!(has(&x_series::XM430_W350, "Present Current") && has(&x_series::XL330_M288, "Goal Current"));
    assert!(has(&x_series::XL430_W250, "Present Load") && !has(&x_series::XL430_W250, "Current Limit"));
    assert!(has(&mx28::MX28_V2, "Present Load") && !has(&mx28::MX28_V2, "Goal Current"));
    assert_eq!(x_series::PRESENT_BLOCK_LEN, 23);
}

/// A servo's table image with the e-Manual's defaults for the limits.
fn memory(t: &ControlTable) -> Vec<u8> {
    let mut m = vec![0u8; t.end as usize];
    let mut set = |at: u16, bytes: &[u8]| m[at as usize..at as usize + bytes.len()].copy_from_slice(bytes);
    set(x_series::OPERATING_MODE, &[x_series::mode::POSITION]);
    set(x_series::PWM_LIMIT, &885u16.to_le_bytes());
    set(x_series::CURRENT_LIMIT, &1193u16.to_le_bytes());
    set(x_series::VELOCITY_LIMIT, &200u32.to_le_bytes());
    set(x_series::MAX_POSITION_LIMIT, &4095u32.to_le_bytes());
    m
}

#[test]
fn writes_are_checked_as_a_servo_checks_them() {
    let t = &x_series::XM430_W350;
    let mut m = memory(t);
    let ok = |m: &[u8], at: u16, data: &[u8]| t.check_write(at, data, m);
    let number = |r: Result<(), TableError>| r.err().map(|e| e.error_number());
    assert_eq!(ok(&m, x_series::GOAL_PWM, &(-885i16).to_le_bytes()), Ok(()));
    // Goal PWM and Goal Current in one write.
    assert_eq!(ok(&m, x_series::GOAL_PWM, &[0x10, 0, 0x20, 0]), Ok(()));
    assert_eq!(number(ok(&m, x_series::PRESENT_POSITION, &[0; 4])), Some(ErrorNumber::Access));
    assert_eq!(ok(&m, 71, &[0]), Err(TableError::Undefined { address: 71 }));
    assert_eq!(ok(&m, 700, &[0]), Err(TableError::Undefined { address: 700 }));
    assert_eq!(number(ok(&m, x_series::GOAL_POSITION, &[0; 2])), Some(ErrorNumber::DataLength));
    assert_eq!(number(ok(&m, x_series::GOAL_POSITION + 1, &[0; 4])), Some(ErrorNumber::DataLength));
    assert_eq!(number(ok(&m, x_series::OPERATING_MODE, &[2])), Some(ErrorNumber::DataRange));
    assert_eq!(ok(&m, x_series::OPERATING_MODE, &[16]), Ok(()));
    assert_eq!(number(ok(&m, x_series::DRIVE_MODE, &[0x02])), Some(ErrorNumber::DataRange));
    assert_eq!(number(ok(&m, x_series::BUS_WATCHDOG, &[0xFF])), Some(ErrorNumber::DataRange), "-1 is the servo's to set");
    assert_eq!(ok(&m, x_series::BUS_WATCHDOG, &[127]), Ok(()));
    // Goal PWM beyond PWM Limit: a Data Limit error, not a range error.
    m[x_series::PWM_LIMIT as usize..][..2].copy_from_slice(&400u16.to_le_bytes());
    assert_eq!(ok(&m, x_series::GOAL_PWM, &500i16.to_le_bytes()), Err(TableError::OverLimit { address: 100, value: 500 }));
    assert_eq!(number(ok(&m, x_series::GOAL_PWM, &(-401i16).to_le_bytes())), Some(ErrorNumber::DataLimit));
    assert_eq!(number(ok(&m, x_series::GOAL_PWM, &900i16.to_le_bytes())), Some(ErrorNumber::DataRange));
    // Goal Position is bound to the position limits in Position Control
    // Mode only.
    assert_eq!(number(ok(&m, x_series::GOAL_POSITION, &5000i32.to_le_bytes())), Some(ErrorNumber::DataLimit));
    m[x_series::OPERATING_MODE as usize] = x_series::mode::EXTENDED_POSITION;
    assert_eq!(ok(&m, x_series::GOAL_POSITION, &5000i32.to_le_bytes()), Ok(()));
    // EEPROM is locked while the torque is on.
    assert_eq!(ok(&m, x_series::ID, &[9]), Ok(()));
    m[x_series::TORQUE_ENABLE as usize] = 1;
    assert_eq!(ok(&m, x_series::ID, &[9]), Err(TableError::EepromLocked { address: 7 }));
    assert_eq!(ok(&m, x_series::LED, &[1]), Ok(()));
    // Indirect addresses point into RAM only.
    assert_eq!(ok(&m, 170, &64u16.to_le_bytes()), Ok(()));
    assert_eq!(number(ok(&m, 170, &7u16.to_le_bytes())), Some(ErrorNumber::DataRange));
    assert_eq!(number(ok(&m, 169, &[0, 0])), Some(ErrorNumber::DataLength));
    assert_eq!(ok(&m, 224, &[1, 2, 3, 4]), Ok(()));
    // The XL430 has no Goal Current.
    assert_eq!(x_series::XL430_W250.check_write(102, &[0, 0], &memory(&x_series::XL430_W250)), Err(TableError::Undefined { address: 102 }));
    assert_eq!(t.check_read(0, 662), Ok(()));
    assert_eq!(t.check_read(600, 100).map_err(|e| e.error_number()), Err(ErrorNumber::Access));
    assert_eq!(t.value(&m, x_series::PWM_LIMIT), Some(400));
}

#[test]
fn values_decode_with_their_sign() {
    let t = &x_series::XM430_W350;
    let vel = t.item_named("Present Velocity").unwrap();
    assert_eq!(vel.decode(&(-5i32).to_le_bytes()), Some(-5));
    let volts = t.item_named("Present Input Voltage").unwrap();
    assert_eq!(volts.decode(&[0xFF, 0xFF]), Some(65535));
    assert_eq!(volts.decode(&[0xFF]), None);
    let s = PresentState { pwm: -300, current: 12, velocity: -7, position: 2048, velocity_trajectory: 1, position_trajectory: 2, input_voltage: 120, temperature: 41 };
    assert_eq!(PresentState::from_bytes(&s.to_bytes()), Some(s));
    assert_eq!(PresentState::from_bytes(&[0; 22]), None);
    let names: Vec<_> = HardwareError(0x24).names().collect();
    assert_eq!(names, vec!["overheating", "overload"]);
    assert!(HardwareError::ALL.contains(HardwareError::OVERLOAD));
}

#[test]
fn the_reference_page_holds_the_tables_of_the_code() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/reference/dynamixel.md");
    let mut doc = std::fs::read_to_string(&path).expect("docs/reference/dynamixel.md");
    let write = std::env::var_os("PADA_WRITE_DOCS").is_some();
    for t in TABLES {
        let open = format!("<!-- control table {} (generated by shared/tests/dynamixel_tables.rs) -->\n", t.model);
        let close = "<!-- end of control table -->";
        let start = doc.find(&open).unwrap_or_else(|| panic!("no `{}` marker in {}", open.trim(), path.display())) + open.len();
        let end = start + doc[start..].find(close).expect("end marker");
        let want = t.markdown().to_string();
        if write {
            doc.replace_range(start..end, &want);
        } else {
            assert_eq!(doc[start..end], want, "{}'s table in docs/reference/dynamixel.md differs from the code's; PADA_WRITE_DOCS=1 regenerates it", t.model);
        }
    }
    if write {
        std::fs::write(&path, doc).unwrap();
    }
}
