//! `pada servos --scan --port DEVICE`: which IDs and models answer on a
//! bus, at which baud rate, in which protocol — a box of servos' first
//! question. At each rate: one Protocol 2.0 PING to the broadcast ID
//! (every X-series servo answers in turn with its model and firmware),
//! then a Protocol 1.0 PING to each ID (Protocol 1.0 has no broadcast
//! PING) and a READ of the model number of each that answers. Feetech's
//! servos answer that PING too (their framing is Protocol 1.0's): a READ
//! of addresses 0–4 tells them apart, as Dynamixel 1.0 keeps its model
//! number at 0 and Feetech at 3 (the STS3215 reads 777 there).
//!
//! Time: a Protocol 1.0 PING waits `timeout` for its answer (the USB
//! adapter's latency and the return delay, 250 × 2 µs out of the box);
//! 254 of them at 5 ms take 1.3 s per rate.

use pada_core::dynamixel::v2::{self as dxl2, PingReply};
use pada_core::dynamixel::{self as dxl1, table};
use pada_core::feetech::control_table::sts3215 as feetech_table;
use serde::Serialize;
use std::path::Path;
use std::time::{Duration, Instant};

/// The rates a scan tries by default, most likely first: the X series'
/// factory 57,600, the 1 Mbps pada sets, and the rest of the X series'
/// table (the RX-28's factory 57,142 bps is within 1 % of 57,600).
pub const RATES: [u32; 7] = [57_600, 1_000_000, 115_200, 2_000_000, 3_000_000, 4_000_000, 9_600];

/// One servo that answered.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Found {
    /// The rate \[bps\].
    pub baud: u32,
    /// 1 or 2 (a Feetech servo: 1, the framing it shares).
    pub protocol: u8,
    /// Who makes it: "ROBOTIS" or "Feetech".
    pub vendor: &'static str,
    /// Its ID.
    pub id: u8,
    /// Its Model Number (`None` if the READ of it failed).
    pub model_number: Option<u16>,
    /// The model's name, if pada knows it.
    pub model: Option<&'static str>,
    /// Its firmware version (Protocol 2.0's PING).
    pub firmware: Option<u8>,
}

/// What to scan.
#[derive(Debug, Clone)]
pub struct ScanConfig {
    /// The rates.
    pub rates: Vec<u32>,
    /// The protocols (1, 2).
    pub protocols: Vec<u8>,
    /// The IDs asked on Protocol 1.0.
    pub ids: std::ops::RangeInclusive<u8>,
    /// How long to wait for an answer.
    pub timeout: Duration,
}

/// Scans the port at `path`; `progress` hears each rate and protocol as it
/// starts.
pub fn scan(path: &Path, cfg: &ScanConfig, progress: &mut dyn FnMut(u32, u8)) -> std::io::Result<Vec<Found>> {
    let mut found = Vec::new();
    for &baud in &cfg.rates {
        let mut port = serialport::new(path.to_string_lossy(), baud).timeout(Duration::from_millis(1)).open()?;
        for &protocol in &cfg.protocols {
            progress(baud, protocol);
            match protocol {
                2 => found.extend(scan2(port.as_mut(), baud, cfg.timeout)?),
                _ => found.extend(scan1(port.as_mut(), baud, cfg)?),
            }
        }
    }
    Ok(found)
}

/// Reads what arrives until `timeout` passes without a byte.
pub(crate) fn listen(port: &mut dyn serialport::SerialPort, timeout: Duration) -> std::io::Result<Vec<u8>> {
    let mut got = Vec::new();
    let mut buf = [0u8; 512];
    let mut quiet_since = Instant::now();
    while quiet_since.elapsed() < timeout {
        match port.read(&mut buf) {
            Ok(0) => {}
            Ok(n) => {
                got.extend_from_slice(&buf[..n]);
                quiet_since = Instant::now();
            }
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
            Err(e) => return Err(e),
        }
    }
    Ok(got)
}

pub(crate) fn send(port: &mut dyn serialport::SerialPort, bytes: &[u8]) -> std::io::Result<()> {
    let _ = port.clear(serialport::ClearBuffer::Input);
    port.write_all(bytes)?;
    port.flush()
}

fn scan2(port: &mut dyn serialport::SerialPort, baud: u32, timeout: Duration) -> std::io::Result<Vec<Found>> {
    let mut tx = [0u8; 16];
    let Ok(ping) = dxl2::encoders::ping(dxl2::BROADCAST_ID, &mut tx) else { return Ok(Vec::new()) };
    send(port, ping)?;
    // Every servo answers after the previous one: wait until the line is
    // quiet for the timeout.
    let bytes = listen(port, timeout)?;
    let mut dec: dxl2::StatusDecoder<64> = dxl2::StatusDecoder::new();
    let mut found = Vec::new();
    for packet in dec.feed(&bytes).flatten() {
        if let Some(reply) = PingReply::from_params(&packet.params) {
            found.push(Found {
                baud,
                protocol: 2,
                vendor: "ROBOTIS",
                id: packet.id,
                model_number: Some(reply.model_number),
                model: model_name(reply.model_number, 2),
                firmware: Some(reply.firmware),
            });
        }
    }
    Ok(found)
}

fn scan1(port: &mut dyn serialport::SerialPort, baud: u32, cfg: &ScanConfig) -> std::io::Result<Vec<Found>> {
    let mut found = Vec::new();
    let mut tx = [0u8; 16];
    for id in cfg.ids.clone() {
        if id == dxl1::BROADCAST_ID {
            continue;
        }
        let Ok(ping) = dxl1::ping(id, &mut tx) else { continue };
        send(port, ping)?;
        let bytes = listen(port, cfg.timeout)?;
        let mut dec: dxl1::StatusDecoder<64> = dxl1::StatusDecoder::new();
        dec.expect(Some(dxl1::Reply { id, params: 0 }));
        if !dec.feed(&bytes).any(|r| r.is_ok()) {
            continue;
        }
        let Ok(read) = dxl1::read_data(id, table::MODEL_NUMBER, 5, &mut tx) else { continue };
        send(port, read)?;
        let bytes = listen(port, cfg.timeout)?;
        let mut dec: dxl1::StatusDecoder<64> = dxl1::StatusDecoder::new();
        dec.expect(Some(dxl1::Reply { id, params: 5 }));
        let head = dec.feed(&bytes).flatten().next();
        let feetech = head.as_ref().and_then(|p| p.u16_at(feetech_table::MODEL_NUMBER as usize)).filter(|&m| {
            pada_core::feetech::control_table::by_model_number(m).is_some() && model_name(head_u16(&head), 1).is_none()
        });
        let (vendor, model_number, model) = match feetech {
            Some(m) => ("Feetech", Some(m), pada_core::feetech::control_table::by_model_number(m).map(|t| t.model)),
            None => {
                let m = head.as_ref().and_then(|p| p.u16_at(0));
                ("ROBOTIS", m, m.and_then(|m| model_name(m, 1)))
            }
        };
        found.push(Found { baud, protocol: 1, vendor, id, model_number, model, firmware: None });
    }
    Ok(found)
}

/// The little-endian value at address 0 of a READ of addresses 0–4.
fn head_u16(head: &Option<dxl1::StatusPacket<64>>) -> u16 {
    head.as_ref().and_then(|p| p.u16_at(0)).unwrap_or(0)
}

/// The name of the model with this number in `protocol`, if pada knows it
/// (the MX-28 reads 29 on 1.0 and 30 on 2.0).
pub fn model_name(model_number: u16, protocol: u8) -> Option<&'static str> {
    if protocol == 2 && model_number == 30 {
        return Some("MX-28(2.0)");
    }
    pada_core::servo::servo_by_model_number(model_number).map(|m| m.name)
}
