//! The STM32F429I-DISC1 (STM32F429ZI): which peripheral does which job, on
//! which pins, at which clocks, and the 38 pins of its SDRAM. Nothing here
//! has run on a real board (the project has none); the pins are UM1670's
//! and the board support of other projects (Zephyr's, NuttX's) agree with
//! them. The table with the reasons is in the [module documentation](super).

use super::sdram::{self, DiscSdram};
use super::{MemoryFault, TableMemory};
use embassy_stm32::fmc::Fmc;
use embassy_stm32::peripherals::*;
use embassy_stm32::{bind_interrupts, dma, usart, Config, Peri, Peripherals};
use pada_core::profile::Memory;
use stm32_fmc::devices::is42s16400j_7::Is42s16400j;

/// Core clock: 8 MHz HSE → PLL → 180 MHz, the F429's maximum (APB1
/// 45 MHz, APB2 90 MHz; the FMC runs on HCLK and clocks the SDRAM at half
/// of it, 90 MHz).
pub const CPU_HZ: u32 = 180_000_000;
// The FMC runs on HCLK (AHB prescaler 1): the SDRAM's timings take it as
// this clock.
const _: () = assert!(sdram::FMC_HZ == CPU_HZ, "sdram.rs's FMC clock must be HCLK, the CPU's clock");

bind_interrupts!(pub struct Irqs {
    UART5 => usart::InterruptHandler<UART5>;
    USART1 => usart::InterruptHandler<USART1>;
    DMA1_STREAM7 => dma::InterruptHandler<DMA1_CH7>;
    DMA1_STREAM0 => dma::InterruptHandler<DMA1_CH0>;
    DMA2_STREAM7 => dma::InterruptHandler<DMA2_CH7>;
    DMA2_STREAM2 => dma::InterruptHandler<DMA2_CH2>;
});

/// The timer that counts the encoder.
pub type EncoderTimer = TIM2;

/// The clocks, from the DISC1's X2 crystal (UM1670; not the ST-LINK's
/// MCO): 8 MHz / 4 = 2 MHz × 180 = 360 MHz VCO; /2 = 180 MHz. No USB, so
/// no 48 MHz output (360 MHz has no integer divider to it). embassy-stm32
/// switches the regulator to scale 1 and over-drive, which 180 MHz needs
/// (RM0090 5.1.4), and sets five flash wait states.
pub fn clock_config() -> Config {
    super::f4_clocks::hse_pll_config(embassy_stm32::rcc::PllMul::MUL180, None)
}

/// Whether the LED lights on a high level (LD3 between PG13 and ground).
pub const LED_ACTIVE_HIGH: bool = true;

/// Every peripheral and pin the firmware uses, by job.
pub struct Resources {
    /// The servo bus's UART.
    pub servo_uart: Peri<'static, UART5>,
    /// Servo bus TX, RX and driver enable.
    pub servo_pins: (Peri<'static, PC12>, Peri<'static, PD2>, Peri<'static, PC11>),
    /// The servo bus's TX and RX DMA.
    pub servo_dma: (Peri<'static, DMA1_CH7>, Peri<'static, DMA1_CH0>),
    /// The telemetry link's USART.
    pub tele_uart: Peri<'static, USART1>,
    /// Telemetry TX and RX.
    pub tele_pins: (Peri<'static, PA9>, Peri<'static, PA10>),
    /// The telemetry link's TX and RX DMA.
    pub tele_dma: (Peri<'static, DMA2_CH7>, Peri<'static, DMA2_CH2>),
    /// The encoder's timer.
    pub encoder_timer: Peri<'static, EncoderTimer>,
    /// Encoder channels A and B.
    pub encoder_pins: (Peri<'static, PA5>, Peri<'static, PB3>),
    /// Foot switches: toe R, heel R, toe L, heel L.
    pub contacts: [Peri<'static, embassy_stm32::gpio::AnyPin>; 4],
    /// Status LED.
    pub led: Peri<'static, embassy_stm32::gpio::AnyPin>,
    /// The flash controller.
    pub flash: Peri<'static, FLASH>,
    /// The independent watchdog.
    pub iwdg: Peri<'static, IWDG>,
}

/// What [`start_table_memory`] needs: the SDRAM, its pins set to the FMC.
pub type TableMemoryPins = DiscSdram;

/// Splits the peripherals by job.
pub fn split(p: Peripherals) -> (Resources, TableMemoryPins) {
    let resources = Resources {
        servo_uart: p.UART5,
        servo_pins: (p.PC12, p.PD2, p.PC11),
        servo_dma: (p.DMA1_CH7, p.DMA1_CH0),
        tele_uart: p.USART1,
        tele_pins: (p.PA9, p.PA10),
        tele_dma: (p.DMA2_CH7, p.DMA2_CH2),
        encoder_timer: p.TIM2,
        encoder_pins: (p.PA5, p.PB3),
        contacts: [p.PE2.into(), p.PE3.into(), p.PE4.into(), p.PE5.into()],
        led: p.PG13.into(),
        flash: p.FLASH,
        iwdg: p.IWDG,
    };
    // The DISC1's IS42S16400J on SDRAM bank 2 (SDNE1, SDCKE1): 12 address
    // lines, 2 bank lines, 16 data lines, 2 byte masks, 6 control lines
    // (UM1670, table 6). The constructor only sets the pins to the FMC.
    let sdram = Fmc::sdram_a12bits_d16bits_4banks_bank2(
        p.FMC,
        // A0–A11
        p.PF0,
        p.PF1,
        p.PF2,
        p.PF3,
        p.PF4,
        p.PF5,
        p.PF12,
        p.PF13,
        p.PF14,
        p.PF15,
        p.PG0,
        p.PG1,
        // BA0, BA1
        p.PG4,
        p.PG5,
        // D0–D15
        p.PD14,
        p.PD15,
        p.PD0,
        p.PD1,
        p.PE7,
        p.PE8,
        p.PE9,
        p.PE10,
        p.PE11,
        p.PE12,
        p.PE13,
        p.PE14,
        p.PE15,
        p.PD8,
        p.PD9,
        p.PD10,
        // NBL0, NBL1
        p.PE0,
        p.PE1,
        // SDCKE1, SDCLK, SDNCAS, SDNE1, SDNRAS, SDNWE
        p.PB5,
        p.PG8,
        p.PG15,
        p.PB6,
        p.PF11,
        p.PC0,
        Is42s16400j {},
    );
    (resources, sdram)
}

/// Starts and checks the SDRAM if the image's table lives there
/// (`table`, its profile's memory: LEO); the pendulum's table is in SRAM
/// and leaves the SDRAM off. (The caller names the memory, so the board
/// layer needs nothing of the table's module.)
pub fn start_table_memory(sdram: TableMemoryPins, table: Memory) -> Result<TableMemory, MemoryFault> {
    if matches!(table, Memory::Sdram) {
        sdram::start(sdram)?;
    }
    Ok(TableMemory::ready())
}
