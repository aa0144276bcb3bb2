//! The emulated board's peripherals over the link, with the real board's
//! type names and `pada_firmware::io` traits: the servo bus, telemetry
//! out and in, the sensors (a device on the servo bus), the cycle counter
//! (lock-step time plus instructions), no LED; and the board's clock.

use super::link::link;
use crate::board::machine::CPU_HZ;
use embassy_time::{with_deadline, Instant};
use pada_firmware::bus::ServoBus;
use pada_firmware::io::{self, PortError};
use pada_firmware::sil::{self, SENSOR_ID};

/// Cycles per microsecond of lock-step time.
const CYCLES_PER_US: u64 = CPU_HZ as u64 / 1_000_000;

/// The servo bus. Two handles share it (the servo-bus task's and the
/// sensors'); the control loop never runs their transactions at the same
/// time (it reads the sensors after the servo bus has answered).
pub struct ServoPort(pub(super) ());

impl io::BusPort for ServoPort {
    fn discard_input(&mut self) {
        link(|l| l.bus_rx.bytes.clear());
    }

    async fn send(&mut self, bytes: &[u8]) -> Result<(), PortError> {
        link(|l| {
            l.pause();
            l.bus_write(bytes);
            l.resume();
        });
        Ok(())
    }

    async fn receive(&mut self, buf: &mut [u8], deadline_us: u64) -> Result<usize, PortError> {
        let ready = core::future::poll_fn(|cx| link(|l| l.bus_rx.poll(cx.waker())));
        match with_deadline(Instant::from_micros(deadline_us), ready).await {
            Ok(()) => Ok(link(|l| l.bus_rx.take(buf))),
            Err(_) => Ok(0),
        }
    }

    fn now_us(&self) -> u64 {
        Instant::now().as_micros()
    }
}

/// Telemetry out.
pub struct TelemetryTx(pub(super) ());

impl io::ByteSink for TelemetryTx {
    async fn write_all(&mut self, bytes: &[u8]) -> Result<(), PortError> {
        link(|l| {
            l.pause();
            l.telemetry_write(bytes);
            l.resume();
        });
        Ok(())
    }
}

/// Commands in.
pub struct TelemetryRx(pub(super) ());

impl io::ByteSource for TelemetryRx {
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, PortError> {
        core::future::poll_fn(|cx| link(|l| l.telemetry_rx.poll(cx.waker()))).await;
        Ok(link(|l| l.telemetry_rx.take(buf)))
    }
}

/// The encoder and the foot switches: device [`SENSOR_ID`] on the servo
/// bus, read with one READ per period.
pub struct BoardSensors {
    pub(super) bus: ServoBus<ServoPort>,
    pub(super) contacts: u8,
}

impl io::Sensors for BoardSensors {
    async fn encoder_count(&mut self) -> Option<u16> {
        let exchange = self.bus.read(SENSOR_ID, sil::sensor_table::ENCODER_COUNT, sil::sensor_table::READ_LEN).await;
        let (count, contacts) = exchange.status.as_ref().and_then(|s| sil::parse_sensor_read(&s.params))?;
        self.contacts = contacts;
        Some(count)
    }

    async fn contacts(&mut self) -> u8 {
        // Read together with the encoder, just before.
        self.contacts
    }
}

/// Lock-step time in cycles of [`CPU_HZ`] plus the instructions executed
/// outside the transport (QEMU's `-icount`): the agent step's count is its
/// instruction count, a period's count its time on the bus plus its work.
pub struct Cycles(pub(super) ());

impl io::CycleCounter for Cycles {
    fn cycles(&self) -> u32 {
        link(|l| l.now_us.wrapping_mul(CYCLES_PER_US).wrapping_add(l.instructions_now()) as u32)
    }
}

/// The board's clock \[µs\].
pub(in crate::board) fn lockstep_now_us() -> u64 {
    link(|l| l.now_us)
}

/// No LED.
pub struct Led(pub(super) ());

impl Led {
    /// Nothing to light.
    pub fn set(&mut self, _on: bool) {}
}
