//! The emulated boards' common layer: the lock-step clock, the servo bus,
//! telemetry and the checkpoint slots, all carried to the host over one
//! semihosting channel ([`pada_firmware::sil`]), for the software-in-the-loop
//! run (`pada sil`). The machine underneath — QEMU's `netduinoplus2`
//! ([`super::qemu`], an STM32F405) or `mps2-an386` ([`super::mps2`], a
//! Cortex-M4 with 16 MB of PSRAM) — adds only its instruction counter and
//! its clock rate.
//!
//! The same type names as the real board ([`hw`](super)), implementing the
//! same `pada_firmware::io` traits, so `tasks.rs` and everything above it
//! (control loop, agent, fatigue counter, codec, telemetry, safety machine)
//! are the real board's code. What differs, and why:
//!
//! | here | real board | why |
//! |---|---|---|
//! | servo bus and telemetry bytes in clock frames over semihosting | USARTs with DMA | QEMU's serial models move one received byte per main-loop turn (~60 µs) and one system call per sent byte; no RCC/PWR either, so `embassy_stm32::init` never returns |
//! | lock-step time driver: the host advances the clock | TIM2/TIM5 at 1 MHz | deterministic runs, faster than real time |
//! | an executor loop that reports when it is idle | thread-mode executor (WFE/SEV) | the idle moment is when the clock may advance |
//! | encoder and foot switches: device [`SENSOR_ID`] on the servo bus | timer in encoder mode, GPIO | QEMU emulates neither |
//! | cycle counter: lock-step time × the real chip's clock + instructions executed (`-icount`) | DWT CYCCNT | QEMU has no DWT; instructions stand in for cycles |
//! | checkpoints in a file on the host, in slots of one flash sector | flash sectors | QEMU's flash is read-only |
//! | the learner's seed from the host ([`ToBoard::Configure`]) | `DEFAULT_SEED` | a run chooses its seed, as `pada run --seed` does |
//! | mps2-an386: the CMSDK watchdog (`cmsdk_watchdog.rs`); netduinoplus2: none (QEMU models none) | IWDG | a hung loop spins, and QEMU's clock counts its instructions |
//! | defmt and panics over semihosting, exit code 1 on a panic | RTT, probe-rs | no debug probe |
//!
//! Forecasts ([`pada_firmware::sil`], "Forecasts"): a bus request that is
//! byte for byte the host's forecast, sent at its instant with nothing else
//! written since the last report, is answered here without an exchange;
//! and while nothing but such requests is unreported, a timer that expires
//! before the host's next event fires without one.
//!
//! | file | its one job |
//! |---|---|
//! | `mod.rs` | the board: boot, the Boot message and the host's configuration |
//! | `semi.rs` | semihosting operations |
//! | `link.rs` | the link to the host: clock frames, buffered bytes, forecasts |
//! | `executor.rs` | the lock-step time driver and the executor's idle exchange |
//! | `peripherals.rs` | servo bus, telemetry, sensors, cycle counter, LED |
//! | `flash.rs` | the checkpoint file |
//! | `panic.rs` | panics and faults end QEMU with a failure code |

mod executor;
mod flash;
mod link;
mod panic;
mod peripherals;
mod semi;

pub use executor::Executor;
pub use flash::FlashStore;
pub use peripherals::{BoardSensors, Cycles, Led, ServoPort, TelemetryRx, TelemetryTx};
pub(super) use peripherals::lockstep_now_us;
pub use super::watchdog::Watchdog;

use super::machine;
use super::{Parts, TableMemory};
use crate::table::PROFILE;
use core::sync::atomic::Ordering;
use executor::LINK_OPEN;
use heapless::Deque;
use link::{link, Inbox, CLOCK_IN, CLOCK_OUT};
use panic::exit_failure;
use pada_core::wire::FrameDecoder;
use pada_firmware::bus::{BusConfig, ServoBus};
use pada_firmware::sil::{self, FromBoard, ToBoard};

pub use machine::CPU_HZ;

/// Everything the tasks get from the board ([`Parts`]).
pub type Board = Parts<ServoPort, TelemetryTx, TelemetryRx, BoardSensors, FlashStore, Watchdog, Cycles, Led>;

impl Board {
    /// Counter, clock link, the Boot message and the host's configuration.
    /// Call once. (`_table`, the weight table's memory, is the real boards'
    /// concern: emulated memory works from reset.)
    pub fn init(_table: pada_core::profile::Memory) -> Board {
        // Before anything writes RAM the record lives in.
        let reset = super::watchdog::reset_cause();
        machine::start_counter();
        let (to_host, from_host) = match (semi::open(CLOCK_OUT, semi::WRITE), semi::open(CLOCK_IN, semi::READ)) {
            (Some(a), Some(b)) => (a, b),
            _ => {
                defmt::error!("cannot open the lock-step clock FIFOs (run this image with `pada sil`)");
                exit_failure()
            }
        };
        let calibration = calibrate();
        let robot = PROFILE.robot;
        let boot = FromBoard::Boot {
            protocol: sil::CLOCK_PROTOCOL,
            robot: heapless::String::try_from(robot.name).unwrap_or_default(),
            robot_hash: robot.definition_hash(),
            board: heapless::String::try_from(PROFILE.board.name()).unwrap_or_default(),
            machine: heapless::String::try_from(machine::MACHINE).unwrap_or_default(),
            calibration,
            resolution: machine::INSTRUCTIONS_PER_COUNT as u16,
            watchdog_ms: super::watchdog::PERIOD_MS,
            reset,
        };
        link(|l| {
            l.to_host = to_host;
            l.from_host = from_host;
            l.queue(&boot);
            l.flush_writes();
        });
        let mut inbox = Inbox { decoder: FrameDecoder::new(), pending: Deque::new() };
        let seed = match link(|l| l.receive(&mut inbox.decoder, &mut inbox.pending)) {
            ToBoard::Configure { seed, now_us } => {
                link(|l| {
                    l.now_us = now_us;
                    l.horizon_us = now_us;
                });
                seed
            }
            _ => {
                defmt::error!("lock-step clock: the host did not answer Boot with Configure");
                exit_failure()
            }
        };
        LINK_OPEN.store(true, Ordering::SeqCst);
        link(|l| l.resume());

        Board {
            servo_port: ServoPort(()),
            telemetry_tx: TelemetryTx(()),
            telemetry_rx: TelemetryRx(()),
            sensors: BoardSensors { bus: ServoBus::new(ServoPort(()), BusConfig::default()), contacts: 0 },
            flash: FlashStore::open(),
            watchdog: Watchdog::new(),
            cycles: Cycles(()),
            led: Led(()),
            watchdog_reset: matches!(reset, sil::ResetCause::Watchdog { .. }),
            table_memory: Ok(TableMemory::ready()),
            seed,
        }
    }
}


/// Instructions counted over a loop of [`sil::CALIBRATION_INSTRUCTIONS`]
/// instructions (two per iteration: subtract, branch).
fn calibrate() -> u32 {
    let t0 = machine::counter();
    // SAFETY: a register-only countdown loop.
    unsafe {
        core::arch::asm!(
            "2:",
            "subs {n}, {n}, #1",
            "bne 2b",
            n = inout(reg) sil::CALIBRATION_INSTRUCTIONS / 2 => _,
            options(nomem, nostack),
        );
    }
    machine::counter().wrapping_sub(t0) * machine::INSTRUCTIONS_PER_COUNT
}
