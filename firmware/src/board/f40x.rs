//! The STM32F405 and F407 boards (one die, one peripheral assignment; the
//! pins differ by board): which peripheral does which job, on which pins,
//! at which clocks. The table with the reasons is in the [module
//! documentation](super).

use super::{MemoryFault, TableMemory};
use embassy_stm32::peripherals::*;
use embassy_stm32::{bind_interrupts, dma, usart, Config, Peri, Peripherals};

/// Core clock: 8 MHz HSE → PLL → 168 MHz (APB1 42 MHz, APB2 84 MHz).
pub const CPU_HZ: u32 = 168_000_000;

bind_interrupts!(pub struct Irqs {
    USART1 => usart::InterruptHandler<USART1>;
    USART2 => usart::InterruptHandler<USART2>;
    DMA2_STREAM7 => dma::InterruptHandler<DMA2_CH7>;
    DMA2_STREAM2 => dma::InterruptHandler<DMA2_CH2>;
    DMA1_STREAM6 => dma::InterruptHandler<DMA1_CH6>;
    DMA1_STREAM5 => dma::InterruptHandler<DMA1_CH5>;
});

/// The timer that counts the encoder.
pub type EncoderTimer = TIM3;

/// The clocks: 8 MHz / 4 = 2 MHz × 168 = 336 MHz VCO; /2 = 168 MHz; /7 =
/// 48 MHz.
pub fn clock_config() -> Config {
    use embassy_stm32::rcc::{PllMul, PllQDiv};
    super::f4_clocks::hse_pll_config(PllMul::MUL168, Some(PllQDiv::DIV7))
}

/// Whether the LED lights on a high level.
#[cfg(feature = "stm32f405")]
pub const LED_ACTIVE_HIGH: bool = false;
/// Whether the LED lights on a high level.
#[cfg(feature = "stm32f407")]
pub const LED_ACTIVE_HIGH: bool = true;

/// The servo bus's pins: TX, RX, driver enable.
#[cfg(feature = "stm32f405")]
type ServoPins = (Peri<'static, PA9>, Peri<'static, PA10>, Peri<'static, PA8>);
/// The servo bus's pins: TX, RX, driver enable.
#[cfg(feature = "stm32f407")]
type ServoPins = (Peri<'static, PB6>, Peri<'static, PB7>, Peri<'static, PB8>);
/// The encoder's channels A and B.
#[cfg(feature = "stm32f405")]
type EncoderPins = (Peri<'static, PA6>, Peri<'static, PA7>);
/// The encoder's channels A and B.
#[cfg(feature = "stm32f407")]
type EncoderPins = (Peri<'static, PB4>, Peri<'static, PB5>);

/// Every peripheral and pin the firmware uses, by job.
pub struct Resources {
    /// The servo bus's USART.
    pub servo_uart: Peri<'static, USART1>,
    /// Servo bus TX, RX and driver enable.
    pub servo_pins: ServoPins,
    /// The servo bus's TX and RX DMA.
    pub servo_dma: (Peri<'static, DMA2_CH7>, Peri<'static, DMA2_CH2>),
    /// The telemetry link's USART.
    pub tele_uart: Peri<'static, USART2>,
    /// Telemetry TX and RX.
    pub tele_pins: (Peri<'static, PA2>, Peri<'static, PA3>),
    /// The telemetry link's TX and RX DMA.
    pub tele_dma: (Peri<'static, DMA1_CH6>, Peri<'static, DMA1_CH5>),
    /// The encoder's timer.
    pub encoder_timer: Peri<'static, EncoderTimer>,
    /// Encoder channels A and B.
    pub encoder_pins: EncoderPins,
    /// Foot switches: toe R, heel R, toe L, heel L.
    pub contacts: [Peri<'static, embassy_stm32::gpio::AnyPin>; 4],
    /// Status LED.
    pub led: Peri<'static, embassy_stm32::gpio::AnyPin>,
    /// The flash controller.
    pub flash: Peri<'static, FLASH>,
    /// The independent watchdog.
    pub iwdg: Peri<'static, IWDG>,
}

/// What [`start_table_memory`] needs: nothing, the table is in internal
/// memory.
pub struct TableMemoryPins;

/// Splits the peripherals by job.
pub fn split(p: Peripherals) -> (Resources, TableMemoryPins) {
    #[cfg(feature = "stm32f405")]
    let (servo_pins, encoder_pins, contacts, led) = (
        (p.PA9, p.PA10, p.PA8),
        (p.PA6, p.PA7),
        [p.PB12.into(), p.PB13.into(), p.PB14.into(), p.PB15.into()],
        p.PC13.into(),
    );
    #[cfg(feature = "stm32f407")]
    let (servo_pins, encoder_pins, contacts, led) = (
        (p.PB6, p.PB7, p.PB8),
        (p.PB4, p.PB5),
        [p.PE7.into(), p.PE8.into(), p.PE10.into(), p.PE12.into()],
        p.PD12.into(),
    );
    let resources = Resources {
        servo_uart: p.USART1,
        servo_pins,
        servo_dma: (p.DMA2_CH7, p.DMA2_CH2),
        tele_uart: p.USART2,
        tele_pins: (p.PA2, p.PA3),
        tele_dma: (p.DMA1_CH6, p.DMA1_CH5),
        encoder_timer: p.TIM3,
        encoder_pins,
        contacts,
        led,
        flash: p.FLASH,
        iwdg: p.IWDG,
    };
    (resources, TableMemoryPins)
}

/// The table's memory (CCM and SRAM) works from reset.
pub fn start_table_memory(_: TableMemoryPins, _table: pada_core::profile::Memory) -> Result<TableMemory, MemoryFault> {
    Ok(TableMemory::ready())
}
