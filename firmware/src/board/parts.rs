//! What a board hands the tasks at boot, real or emulated: one struct,
//! whose parts are each variant's own types (`hw.rs` on embassy-stm32,
//! `lockstep/` over semihosting), each implementing one of
//! `pada_firmware::io`'s traits or `CheckpointStore`.

use super::{MemoryFault, TableMemory};

/// Everything the tasks get from the board. A variant names its types
/// once, as `pub type Board = Parts<…>`, and builds it in `Board::init`.
pub struct Parts<ServoPort, TelemetryTx, TelemetryRx, Sensors, Flash, Watchdog, Cycles, Led> {
    /// The servo bus.
    pub servo_port: ServoPort,
    /// Telemetry out.
    pub telemetry_tx: TelemetryTx,
    /// Commands in.
    pub telemetry_rx: TelemetryRx,
    /// Encoder and foot switches (on an emulated board, a device on the
    /// servo bus).
    pub sensors: Sensors,
    /// The checkpoint slots (flash sectors, or a file on the host).
    pub flash: Flash,
    /// The independent watchdog, not started yet (the emulated machine's
    /// own, or none where QEMU models none).
    pub watchdog: Watchdog,
    /// The cycle counter (DWT CYCCNT, or lock-step time plus instructions).
    pub cycles: Cycles,
    /// The status LED (none on an emulated board).
    pub led: Led,
    /// Whether the last reset came from the watchdog.
    pub watchdog_reset: bool,
    /// The weight table's memory, started and checked (the F429's SDRAM,
    /// the mps2's PSRAM), or why not.
    pub table_memory: Result<TableMemory, MemoryFault>,
    /// The learner's seed: `DEFAULT_SEED` on a real board, the run's on an
    /// emulated one.
    pub seed: u64,
}
