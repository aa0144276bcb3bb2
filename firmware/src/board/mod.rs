//! The board layer: every pin, peripheral and register the firmware uses,
//! and nothing else.
//!
//! # Pins
//!
//! | function | STM32F405RG (generic LQFP64 board) | STM32F407VG (STM32F4-Discovery) | STM32F446RE (Nucleo-F446RE) |
//! |---|---|---|---|
//! | servo bus TX (USART1, AF7) → transceiver DI | PA9 | PB6 | PA9 (D8) |
//! | servo bus RX (USART1, AF7) ← transceiver RO | PA10 | PB7 | PA10 (D2) |
//! | servo bus driver enable → transceiver DE and /RE | PA8 | PB8 | PA8 (D7) |
//! | telemetry TX (USART2, AF7) → host RX | PA2 | PA2 | PA2 (ST-LINK virtual COM port) |
//! | telemetry RX (USART2, AF7) ← host TX | PA3 | PA3 | PA3 (ST-LINK virtual COM port) |
//! | encoder A (TIM3 CH1, AF2) | PA6 | PB4 | PA6 (D12) |
//! | encoder B (TIM3 CH2, AF2) | PA7 | PB5 | PA7 (D11) |
//! | foot switch toe R / heel R / toe L / heel L (to GND, pull-up) | PB12 / PB13 / PB14 / PB15 | PE7 / PE8 / PE10 / PE12 | PB12 / PB13 / PB14 / PB15 |
//! | status LED | PC13 (active low) | PD12 (green, active high) | PA5 (LD2, active high) |
//! | HSE | 8 MHz crystal | 8 MHz crystal | 8 MHz from the ST-LINK (bypass) |
//! | debug | SWDIO PA13, SWCLK PA14 | idem | idem |
//!
//! Why these: USART1 sits on APB2 (84 MHz), where 1 Mbps divides exactly
//! (USARTDIV 5.25); USART2 on APB1 (42 MHz) gives 921 600 baud at −0.9 %,
//! well inside a UART's tolerance. USART1 and USART2 are also the two
//! serial ports QEMU's `netduinoplus2` connects first (issue 6). TIM2 is
//! embassy's time base (32-bit), TIM3 counts the encoder. On the
//! Discovery, PA9 carries the USB VBUS sense and PA0 the user button, so its
//! servo bus and encoder move to port B. On the Nucleo, USART2 is wired to
//! the ST-LINK, so telemetry needs no extra adapter.
//!
//! | peripheral | use |
//! |---|---|
//! | USART1 + DMA2 stream 7 (TX) / stream 2 (RX, circular) | servo bus, 1 Mbps 8N1 |
//! | USART2 + DMA1 stream 6 (TX) / stream 5 (RX, circular) | telemetry and commands, 921 600 8N1 |
//! | TIM2 | embassy-time driver (1 MHz ticks) |
//! | TIM3 | quadrature encoder, ×4 decoding |
//! | IWDG | independent watchdog, 250 ms (8 s while flash is erased) |
//! | FLASH sectors 10–11 (F405/F407) or 6–7 (F446) | checkpoint slots A/B (`memory.x`) |
//! | CCM RAM (F405/F407) | the weight table, 64 KiB |
//! | DWT CYCCNT | control-loop and agent-step timing |
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
//! `hw` is the real board on embassy-stm32. `qemu` (cargo feature `qemu`)
//! is the emulated board of QEMU's `netduinoplus2` for the
//! software-in-the-loop run: the same type names (`ServoPort`,
//! `TelemetryTx`, `TelemetryRx`, `BoardSensors`, `FlashStore`, `Watchdog`,
//! `Cycles`, `Led`, `Board`) implementing the same `pada_firmware::io`
//! traits, built on a few PAC register accesses, with a lock-step time
//! driver; everything above (tasks, controller, agent) stays as it is.

#[cfg(not(feature = "qemu"))]
mod hw;
#[cfg(not(feature = "qemu"))]
pub use hw::*;

#[cfg(feature = "qemu")]
mod qemu;
#[cfg(feature = "qemu")]
pub use qemu::*;

/// Pins of the generic STM32F405RG board.
#[cfg(feature = "stm32f405")]
pub mod pins {
    use embassy_stm32::peripherals::*;
    use embassy_stm32::Peri;

    /// This board's pins, by function.
    pub struct Pins {
        /// Servo bus TX.
        pub servo_tx: Peri<'static, PA9>,
        /// Servo bus RX.
        pub servo_rx: Peri<'static, PA10>,
        /// Servo bus driver enable.
        pub servo_de: Peri<'static, PA8>,
        /// Telemetry TX.
        pub tele_tx: Peri<'static, PA2>,
        /// Telemetry RX.
        pub tele_rx: Peri<'static, PA3>,
        /// Encoder channel A.
        pub enc_a: Peri<'static, PA6>,
        /// Encoder channel B.
        pub enc_b: Peri<'static, PA7>,
        /// Foot switches: toe R, heel R, toe L, heel L.
        pub contacts: [Peri<'static, embassy_stm32::gpio::AnyPin>; 4],
        /// Status LED.
        pub led: Peri<'static, embassy_stm32::gpio::AnyPin>,
    }

    /// Whether the LED lights on a high level.
    pub const LED_ACTIVE_HIGH: bool = false;
    /// Whether the 8 MHz HSE is an external clock (bypass) rather than a crystal.
    pub const HSE_BYPASS: bool = false;

    /// Moves this board's pins out of the peripherals `$p`.
    macro_rules! take_pins {
        ($p:ident) => {
            $crate::board::pins::Pins {
                servo_tx: $p.PA9,
                servo_rx: $p.PA10,
                servo_de: $p.PA8,
                tele_tx: $p.PA2,
                tele_rx: $p.PA3,
                enc_a: $p.PA6,
                enc_b: $p.PA7,
                contacts: [$p.PB12.into(), $p.PB13.into(), $p.PB14.into(), $p.PB15.into()],
                led: $p.PC13.into(),
            }
        };
    }
    pub(crate) use take_pins;
}

/// Pins of the STM32F4-Discovery (STM32F407VG).
#[cfg(feature = "stm32f407")]
pub mod pins {
    use embassy_stm32::peripherals::*;
    use embassy_stm32::Peri;

    /// This board's pins, by function.
    pub struct Pins {
        /// Servo bus TX.
        pub servo_tx: Peri<'static, PB6>,
        /// Servo bus RX.
        pub servo_rx: Peri<'static, PB7>,
        /// Servo bus driver enable.
        pub servo_de: Peri<'static, PB8>,
        /// Telemetry TX.
        pub tele_tx: Peri<'static, PA2>,
        /// Telemetry RX.
        pub tele_rx: Peri<'static, PA3>,
        /// Encoder channel A.
        pub enc_a: Peri<'static, PB4>,
        /// Encoder channel B.
        pub enc_b: Peri<'static, PB5>,
        /// Foot switches: toe R, heel R, toe L, heel L.
        pub contacts: [Peri<'static, embassy_stm32::gpio::AnyPin>; 4],
        /// Status LED.
        pub led: Peri<'static, embassy_stm32::gpio::AnyPin>,
    }

    /// Whether the LED lights on a high level.
    pub const LED_ACTIVE_HIGH: bool = true;
    /// Whether the 8 MHz HSE is an external clock (bypass) rather than a crystal.
    pub const HSE_BYPASS: bool = false;

    /// Moves this board's pins out of the peripherals `$p`.
    macro_rules! take_pins {
        ($p:ident) => {
            $crate::board::pins::Pins {
                servo_tx: $p.PB6,
                servo_rx: $p.PB7,
                servo_de: $p.PB8,
                tele_tx: $p.PA2,
                tele_rx: $p.PA3,
                enc_a: $p.PB4,
                enc_b: $p.PB5,
                contacts: [$p.PE7.into(), $p.PE8.into(), $p.PE10.into(), $p.PE12.into()],
                led: $p.PD12.into(),
            }
        };
    }
    pub(crate) use take_pins;
}

/// Pins of the Nucleo-F446RE.
#[cfg(feature = "stm32f446")]
pub mod pins {
    use embassy_stm32::peripherals::*;
    use embassy_stm32::Peri;

    /// This board's pins, by function.
    pub struct Pins {
        /// Servo bus TX.
        pub servo_tx: Peri<'static, PA9>,
        /// Servo bus RX.
        pub servo_rx: Peri<'static, PA10>,
        /// Servo bus driver enable.
        pub servo_de: Peri<'static, PA8>,
        /// Telemetry TX.
        pub tele_tx: Peri<'static, PA2>,
        /// Telemetry RX.
        pub tele_rx: Peri<'static, PA3>,
        /// Encoder channel A.
        pub enc_a: Peri<'static, PA6>,
        /// Encoder channel B.
        pub enc_b: Peri<'static, PA7>,
        /// Foot switches: toe R, heel R, toe L, heel L.
        pub contacts: [Peri<'static, embassy_stm32::gpio::AnyPin>; 4],
        /// Status LED.
        pub led: Peri<'static, embassy_stm32::gpio::AnyPin>,
    }

    /// Whether the LED lights on a high level.
    pub const LED_ACTIVE_HIGH: bool = true;
    /// Whether the 8 MHz HSE is an external clock (bypass) rather than a crystal.
    pub const HSE_BYPASS: bool = true;

    /// Moves this board's pins out of the peripherals `$p`.
    macro_rules! take_pins {
        ($p:ident) => {
            $crate::board::pins::Pins {
                servo_tx: $p.PA9,
                servo_rx: $p.PA10,
                servo_de: $p.PA8,
                tele_tx: $p.PA2,
                tele_rx: $p.PA3,
                enc_a: $p.PA6,
                enc_b: $p.PA7,
                contacts: [$p.PB12.into(), $p.PB13.into(), $p.PB14.into(), $p.PB15.into()],
                led: $p.PA5.into(),
            }
        };
    }
    pub(crate) use take_pins;
}
