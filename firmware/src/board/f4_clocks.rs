//! The clock tree both STM32F4 boards share: the 8 MHz crystal (HSE)
//! through the main PLL, divided by 4 to 2 MHz, the core clock its P
//! output divided by 2, AHB undivided (the FMC runs on HCLK), APB1 a
//! quarter of it and APB2 a half. What differs by chip is the
//! multiplier (the VCO) and whether the 48 MHz Q output is wanted.

use embassy_stm32::rcc::{
    AHBPrescaler, APBPrescaler, Hse, HseMode, Pll, PllMul, PllPDiv, PllPreDiv, PllQDiv, PllSource, Sysclk,
};
use embassy_stm32::time::Hertz;
use embassy_stm32::Config;

/// The clocks: 8 MHz HSE / 4 = 2 MHz × `mul` = the VCO; its P output / 2
/// is the core clock, its Q output `divq` (None: off).
pub fn hse_pll_config(mul: PllMul, divq: Option<PllQDiv>) -> Config {
    let mut config = Config::default();
    config.rcc.hse = Some(Hse { freq: Hertz(8_000_000), mode: HseMode::Oscillator });
    config.rcc.pll_src = PllSource::HSE;
    config.rcc.pll = Some(Pll { prediv: PllPreDiv::DIV4, mul, divp: Some(PllPDiv::DIV2), divq, divr: None });
    config.rcc.sys = Sysclk::PLL1_P;
    config.rcc.ahb_pre = AHBPrescaler::DIV1;
    config.rcc.apb1_pre = APBPrescaler::DIV4;
    config.rcc.apb2_pre = APBPrescaler::DIV2;
    config
}
