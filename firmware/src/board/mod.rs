//! The board layer: every pin, peripheral and register the firmware uses,
//! and nothing else.
//!
//! # Pins
//!
//! | function | STM32F405RG (generic LQFP64 board) | STM32F407VG (STM32F4-Discovery) | STM32F429ZI (STM32F429I-DISC1) |
//! |---|---|---|---|
//! | servo bus TX → transceiver DI | PA9 (USART1, AF7) | PB6 (USART1, AF7) | PC12 (UART5, AF8) |
//! | servo bus RX ← transceiver RO | PA10 (USART1, AF7) | PB7 (USART1, AF7) | PD2 (UART5, AF8) |
//! | servo bus driver enable → transceiver DE and /RE | PA8 | PB8 | PC11 |
//! | telemetry TX → host RX | PA2 (USART2, AF7) | PA2 (USART2, AF7) | PA9 (USART1, AF7: the ST-LINK's virtual COM port) |
//! | telemetry RX ← host TX | PA3 (USART2, AF7) | PA3 (USART2, AF7) | PA10 (USART1, AF7: the ST-LINK's virtual COM port) |
//! | encoder A | PA6 (TIM3 CH1, AF2) | PB4 (TIM3 CH1, AF2) | PA5 (TIM2 CH1, AF1) |
//! | encoder B | PA7 (TIM3 CH2, AF2) | PB5 (TIM3 CH2, AF2) | PB3 (TIM2 CH2, AF1) |
//! | foot switch toe R / heel R / toe L / heel L (to GND, pull-up) | PB12 / PB13 / PB14 / PB15 | PE7 / PE8 / PE10 / PE12 | PE2 / PE3 / PE4 / PE5 |
//! | status LED | PC13 (active low) | PD12 (green, active high) | PG13 (LD3, green, active high) |
//! | HSE | 8 MHz crystal | 8 MHz crystal | 8 MHz crystal |
//! | debug | SWDIO PA13, SWCLK PA14 | idem | idem |
//!
//! Why these, on the F405 and F407: USART1 sits on APB2 (84 MHz), where
//! 1 Mbps divides exactly (USARTDIV 5.25); USART2 on APB1 (42 MHz) gives
//! 921 600 baud at −0.9 %, well inside a UART's tolerance. USART1 and
//! USART2 are also the two serial ports QEMU's `netduinoplus2` connects
//! first. TIM2 is embassy's time base (32-bit), TIM3 counts the
//! encoder. On the Discovery, PA9 carries the USB VBUS sense and PA0 the
//! user button, so its servo bus and encoder move to port B.
//!
//! On the F429I-DISC1 the SDRAM, the LCD (LTDC and its SPI), the gyroscope,
//! the touch controller and USB OTG HS take most pins (UM1670, table 6;
//! the SDRAM's 38 pins are in [`f429`]). What is left: USART1 on PA9/PA10
//! is wired to the ST-LINK's virtual COM port, so telemetry needs no
//! adapter; UART5 (PC12/PD2) is the only other UART with both pins free,
//! and on APB1 (45 MHz) it divides 1 Mbps exactly (UARTDIV 2.8125); every
//! TIM3/TIM4 channel pair has a pin on the SDRAM or the LCD, so TIM2
//! counts the encoder on PA5 and PB3 (PB3 is the SWO trace line, which
//! this firmware does not use: defmt goes over RTT) and TIM5 is embassy's
//! time base; PE2–PE5, PC11 and the green LD3 (PG13) are free. USART1 on
//! APB2 (90 MHz) gives 921 600 baud at −0.35 %.
//!
//! | peripheral | F405/F407 | F429I-DISC1 |
//! |---|---|---|
//! | servo bus, 1 Mbps 8N1 | USART1 + DMA2 stream 7 (TX) / stream 2 (RX, circular) | UART5 + DMA1 stream 7 (TX) / stream 0 (RX, circular) |
//! | telemetry and commands, 921 600 8N1 | USART2 + DMA1 stream 6 (TX) / stream 5 (RX, circular) | USART1 + DMA2 stream 7 (TX) / stream 2 (RX, circular) |
//! | embassy-time driver (1 MHz ticks) | TIM2 | TIM5 |
//! | quadrature encoder, ×4 decoding | TIM3 | TIM2 (its 32-bit counter read as 16 bits, as TIM3's) |
//! | independent watchdog, 250 ms (8 s while flash is erased) | IWDG | IWDG |
//! | checkpoint slots A/B (`memory.x`, `memory-f429.x`) | flash sectors 10–11 | flash sectors 22–23 (bank 2) |
//! | the weight table (`crate::table`) | CCM (+ SRAM for the pendulum's exact table) | SDRAM (LEO), SRAM (pendulum) |
//! | external memory | — | FMC SDRAM bank 2: IS42S16400J, 8 MB at 0xD000_0000 ([`sdram`]) |
//! | control-loop and agent-step timing | DWT CYCCNT | DWT CYCCNT |
//!
//! # RS-485
//!
//! The RX-28 speaks RS-485 (half duplex, two wires D+/D−, plus the 12–16 V
//! supply and ground). Any 3.3 V transceiver with separate DE and /RE
//! (MAX3485, SN65HVD72, …): DI ← TX, RO → RX, DE and /RE together ← the
//! driver-enable pin. The STM32F4's USART has no hardware driver-enable
//! output (that arrived with the USART of the F7/L4/G4 families), so the
//! firmware raises the pin, sends, waits for the last stop bit
//! (transmission complete), and lowers it; the servos wait their return
//! delay (50 µs, set at boot) before answering. With /RE tied to DE the
//! receiver is off while sending, so the firmware never hears its own
//! packets; RX has a pull-up so the idle line reads 1.
//!
//! # Variants
//!
//! `hw` is the real board on embassy-stm32, with the chip's pins,
//! peripherals and clocks from one file per board family, chosen by cargo
//! feature: [`f40x`] (F405, F407) or [`f429`] (F429I-DISC1, whose SDRAM
//! [`sdram`] starts). The emulated boards for the software-in-the-loop run
//! are `lockstep` (the lock-step clock, bus, telemetry and checkpoints over
//! semihosting) on one of two QEMU machines: `qemu` (cargo feature `qemu`:
//! `netduinoplus2`, an STM32F405, for the `f405` profile) or `mps2`
//! (feature `mps2`: `mps2-an386`, a Cortex-M4 whose PSRAM stands in for the
//! F429I-DISC1's SDRAM, for the `f429-sdram` profile). They have the same
//! type names (`ServoPort`, `TelemetryTx`, `TelemetryRx`, `BoardSensors`,
//! `FlashStore`, `Watchdog`, `Cycles`, `Led`) implementing the
//! same `pada_firmware::io` traits, handed to the tasks in one
//! [`Parts`] struct (each variant's `Board`); everything above (tasks, controller,
//! agent) stays as it is.

// The weight table's memory: what the board layer and the table both use
// (a leaf, so that neither imports the other).
mod memory;
pub use memory::{MemoryFault, TableMemory};
// What a board hands the tasks, with each variant's own parts.
mod parts;
pub use parts::Parts;

#[cfg(not(emulated))]
mod hw;
#[cfg(not(emulated))]
pub use hw::*;

// The clock tree of both STM32F4 boards.
#[cfg(not(emulated))]
mod f4_clocks;

#[cfg(any(feature = "stm32f405", feature = "stm32f407"))]
mod f40x;
#[cfg(any(feature = "stm32f405", feature = "stm32f407"))]
use f40x as chip;

#[cfg(feature = "stm32f429")]
mod f429;
#[cfg(feature = "stm32f429")]
mod sdram;
#[cfg(feature = "stm32f429")]
use f429 as chip;

// The emulated boards: one lock-step layer, two machines.
#[cfg(emulated)]
mod lockstep;
#[cfg(emulated)]
pub use lockstep::*;
#[cfg(feature = "qemu")]
mod qemu;
#[cfg(feature = "qemu")]
use qemu as machine;
#[cfg(feature = "mps2")]
mod mps2;
#[cfg(feature = "mps2")]
use mps2 as machine;
// The emulated boards' watchdog: mps2-an386's CMSDK watchdog; none on
// netduinoplus2, which models none. And the host's fault injection.
#[cfg(feature = "mps2")]
mod cmsdk_watchdog;
#[cfg(feature = "mps2")]
use cmsdk_watchdog as watchdog;
#[cfg(feature = "qemu")]
mod no_watchdog;
#[cfg(feature = "qemu")]
use no_watchdog as watchdog;
#[cfg(emulated)]
mod injection;
#[cfg(emulated)]
pub use injection::injected_hang;
