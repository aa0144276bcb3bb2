//! Flash wear: how often the checkpoint sectors have been erased, and the
//! budget that keeps them from wearing out within a stated lifetime.
//!
//! Every save erases one of the two sectors (they alternate), so each
//! sector sees half the saves. The STM32F4's flash is specified for 10 000
//! erase cycles per sector ([`SECTOR_ENDURANCE`]). [`WearBudget`] lets a
//! sector be erased `reserve` times at any pace and then no faster than its
//! remaining endurance spread over the lifetime:
//!
//! ```text
//! allowed erases after t seconds of operation = min(endurance, reserve + (endurance − reserve) · t / lifetime)
//! ```
//!
//! so no sector reaches its endurance before `lifetime` seconds of
//! operation, at any save cadence. Time is operating time — what the board
//! was powered for, as the checkpoints carry it forward ([`FlashWear`]) —
//! which is never more than calendar time, so the guarantee holds in
//! calendar time too. Time since the last save is lost on a reset, which
//! only makes the budget stricter.
//!
//! [`WearBudget::STM32F4`] (ten years of round-the-clock operation, a
//! reserve of 1 000 erases per sector) allows 2 000 saves at any pace and,
//! sustained, one save per 4 h 52 min of operation: the documented cadence.

/// Erase cycles one STM32F4 flash sector is specified for: N_END, 10
/// kcycles minimum over −40…+85 °C (STM32F405/407 datasheet DS8626 and
/// STM32F446 datasheet DS10693, "Flash memory endurance and data
/// retention").
pub const SECTOR_ENDURANCE: u32 = 10_000;

/// Seconds in ten years of 365.25 days.
pub const TEN_YEARS_S: u64 = 10 * 36_525 * 864;

use crate::error::ConfigError;

/// The checkpoint sectors' erase counts, carried in every learner-state
/// record, and the operating time they were reached in.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FlashWear {
    /// Erases of slot 0's and slot 1's sector.
    pub erases: [u32; 2],
    /// Seconds the board has operated (been powered) in total, as far as
    /// the checkpoints know.
    pub operating_s: u64,
}

impl FlashWear {
    /// Each field the higher of the two: erase counts only grow, and of two
    /// records of the same sectors the higher count is the truer one.
    pub fn max(&self, other: &FlashWear) -> FlashWear {
        FlashWear {
            erases: [self.erases[0].max(other.erases[0]), self.erases[1].max(other.erases[1])],
            operating_s: self.operating_s.max(other.operating_s),
        }
    }

    /// Erases of the more worn sector.
    pub fn most_erases(&self) -> u32 {
        self.erases[0].max(self.erases[1])
    }
}

/// Why a save was refused to spare the flash.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WearRefusal {
    /// The sector has had its specified erase cycles; no more saves go to
    /// it.
    WornOut {
        /// Its erases.
        erases: u32,
    },
    /// The sector is ahead of its budget: saving now would wear it out
    /// before the lifetime.
    TooSoon {
        /// Its erases.
        erases: u32,
        /// Erases its budget allows at this operating time.
        allowed: u32,
        /// Seconds of operation until the next erase is allowed.
        retry_in_s: u64,
    },
}

/// An erase budget per sector (module documentation). Made by
/// [`WearBudget::new`], which refuses a budget that could not be kept: a
/// lifetime of 0 s (every save would be refused "until 0 s from now") or
/// an endurance of 0 erases.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WearBudget {
    endurance: u32,
    reserve: u32,
    lifetime_s: u64,
}

impl WearBudget {
    /// The firmware's budget: [`SECTOR_ENDURANCE`] over ten years of
    /// operation, 10% of it as a reserve for the first sessions' frequent
    /// saves.
    pub const STM32F4: WearBudget =
        WearBudget { endurance: SECTOR_ENDURANCE, reserve: SECTOR_ENDURANCE / 10, lifetime_s: TEN_YEARS_S };

    /// A budget of `endurance` erase cycles per sector over `lifetime_s`
    /// seconds of operation, `reserve` of them allowed at any pace first.
    /// Valid: `endurance >= 1`, `reserve <= endurance`, `lifetime_s >= 1`.
    pub const fn new(endurance: u32, reserve: u32, lifetime_s: u64) -> Result<WearBudget, ConfigError> {
        if endurance == 0 {
            return Err(ConfigError::new("endurance", 0.0, "1 <= endurance (erase cycles per sector)"));
        }
        if reserve > endurance {
            return Err(ConfigError::new("reserve", reserve as f32, "0 <= reserve <= endurance"));
        }
        if lifetime_s == 0 {
            return Err(ConfigError::new("lifetime_s", 0.0, "1 <= lifetime_s (seconds of operation)"));
        }
        Ok(WearBudget { endurance, reserve, lifetime_s })
    }

    /// Erase cycles a sector is specified for.
    pub const fn endurance(&self) -> u32 {
        self.endurance
    }

    /// Erases allowed at any pace before the budget applies.
    pub const fn reserve(&self) -> u32 {
        self.reserve
    }

    /// Operating seconds the endurance must last.
    pub const fn lifetime_s(&self) -> u64 {
        self.lifetime_s
    }

    /// Erases a sector may have had after `operating_s` seconds of
    /// operation.
    pub fn allowed(&self, operating_s: u64) -> u32 {
        let reserve = self.reserve.min(self.endurance);
        let spread = (self.endurance - reserve) as u128 * operating_s as u128 / self.lifetime_s.max(1) as u128;
        (reserve as u128 + spread).min(self.endurance as u128) as u32
    }

    /// Whether a sector erased `erases` times may be erased once more after
    /// `operating_s` seconds of operation.
    pub fn check(&self, erases: u32, operating_s: u64) -> Result<(), WearRefusal> {
        if erases >= self.endurance {
            return Err(WearRefusal::WornOut { erases });
        }
        let allowed = self.allowed(operating_s);
        if erases < allowed {
            return Ok(());
        }
        // The first operating time at which `erases + 1` are allowed.
        let above = (erases + 1 - self.reserve.min(self.endurance)) as u128;
        let span = (self.endurance - self.reserve.min(self.endurance)).max(1) as u128;
        let at = (above * self.lifetime_s as u128).div_ceil(span);
        let retry_in_s = (at.saturating_sub(operating_s as u128)).min(u64::MAX as u128) as u64;
        Err(WearRefusal::TooSoon { erases, allowed, retry_in_s })
    }

    /// Seconds of operation per save that the budget sustains once the
    /// reserve is spent (the two sectors alternate, so a save every half
    /// of a sector's erase interval).
    pub fn sustained_save_interval_s(&self) -> u64 {
        let per_sector = self.lifetime_s / (self.endurance - self.reserve.min(self.endurance)).max(1) as u64;
        per_sector / 2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_documented_cadence() {
        let b = WearBudget::STM32F4;
        // One save per 4 h 52 min of operation, sustained.
        assert_eq!(b.sustained_save_interval_s() / 60, 4 * 60 + 52);
        assert_eq!(b.allowed(0), 1000);
        assert_eq!(b.allowed(TEN_YEARS_S), SECTOR_ENDURANCE);
        assert_eq!(b.allowed(u64::MAX), SECTOR_ENDURANCE);
    }

    #[test]
    fn a_sector_cannot_wear_out_before_its_lifetime() {
        // Save as fast as allowed, one erase per sector per check, with
        // time advancing by a minute between tries: the count never passes
        // the budget, and reaches the endurance only at the lifetime.
        let b = WearBudget::new(100, 10, 90_000).unwrap();
        let mut erases = 0u32;
        let mut t = 0u64;
        while t <= 2 * b.lifetime_s {
            match b.check(erases, t) {
                Ok(()) => erases += 1,
                Err(WearRefusal::TooSoon { retry_in_s, allowed, .. }) => {
                    assert_eq!(allowed, erases);
                    // Exactly then, and not a second before, it is allowed.
                    assert!(b.check(erases, t + retry_in_s).is_ok());
                    assert!(retry_in_s == 0 || b.check(erases, t + retry_in_s - 1).is_err());
                }
                Err(WearRefusal::WornOut { erases: e }) => {
                    assert_eq!(e, 100);
                    assert!(t >= b.lifetime_s, "worn out at {t} s");
                }
            }
            assert!(erases <= b.allowed(t));
            t += 60;
        }
        assert_eq!(erases, 100);
    }

    #[test]
    fn a_budget_that_cannot_be_kept_is_refused_where_it_is_made() {
        // Regression: lifetime 0 said "retry in 0 s" and refused every save.
        let e = WearBudget::new(100, 10, 0).unwrap_err();
        assert_eq!(e.param, "lifetime_s");
        assert!(e.valid.contains("1 <= lifetime_s"));
        assert_eq!(WearBudget::new(0, 0, 10).unwrap_err().param, "endurance");
        assert_eq!(WearBudget::new(10, 11, 10).unwrap_err().param, "reserve");
        let b = WearBudget::new(1, 0, 1).unwrap();
        assert!(b.check(0, 1).is_ok());
        assert_eq!((b.endurance(), b.reserve(), b.lifetime_s()), (1, 0, 1));
        assert_eq!(WearBudget::new(SECTOR_ENDURANCE, SECTOR_ENDURANCE / 10, TEN_YEARS_S), Ok(WearBudget::STM32F4));
    }
}
