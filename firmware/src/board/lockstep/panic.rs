//! Panics and faults: log over semihosting, then end QEMU with a failure
//! code.

pub(super) fn exit_failure() -> ! {
    cortex_m_semihosting::debug::exit(cortex_m_semihosting::debug::EXIT_FAILURE);
    // Only reached if semihosting is off: stop here.
    loop {
        cortex_m::asm::bkpt();
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    defmt::error!("panic: {}", defmt::Display2Format(info));
    exit_failure()
}

#[defmt::panic_handler]
fn defmt_panic() -> ! {
    exit_failure()
}

#[cortex_m_rt::exception]
unsafe fn HardFault(frame: &cortex_m_rt::ExceptionFrame) -> ! {
    let scb = &*cortex_m::peripheral::SCB::PTR;
    defmt::error!(
        "HardFault at pc {=u32:#x} (lr {=u32:#x}, sp {=u32:#x}); HFSR {=u32:#x} CFSR {=u32:#x} MMFAR {=u32:#x} BFAR {=u32:#x}",
        frame.pc(),
        frame.lr(),
        frame as *const _ as u32,
        scb.hfsr.read(),
        scb.cfsr.read(),
        scb.mmfar.read(),
        scb.bfar.read()
    );
    exit_failure()
}
