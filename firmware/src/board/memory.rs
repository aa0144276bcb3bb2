//! The weight table's memory, as the board layer reports it: the proof
//! that it works ([`TableMemory`], which `crate::table::take` needs) or
//! the fault its check at boot found ([`MemoryFault`]). A leaf: the board
//! layer makes these and the table takes them, and neither imports the
//! other for it.

/// Proof that the memory the weight table lives in works: only the board
/// layer makes one, after it started that memory (the F429's SDRAM, which
/// reads garbage and ignores writes before its power-up sequence) and
/// checked it. `crate::table::take` needs one, so nothing touches the table
/// before.
pub struct TableMemory(());

impl TableMemory {
    /// Memory that works from reset (internal SRAM and CCM), or external
    /// memory the board layer has started and checked.
    pub(super) fn ready() -> TableMemory {
        TableMemory(())
    }
}

/// The table's memory failed its check at boot: a word read back other
/// than written (a data, byte-lane or address line stuck or shorted, or
/// wrong timings).
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub struct MemoryFault {
    /// The address that read back wrong.
    pub address: u32,
    /// What was written there (or, for the address-line check, what the
    /// word should still hold).
    pub wrote: u32,
    /// What was read.
    pub read: u32,
}
