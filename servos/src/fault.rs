//! `--fault` specifications: what the bus emulator does wrong, when, and
//! for how long.
//!
//! ```text
//! KIND[:at=SECONDS][:for=SECONDS][:servo=ID][:ms=MILLISECONDS][:bits=NAME]
//! ```
//!
//! | kind | the servo's answers during the window |
//! |---|---|
//! | `drop` | are lost: no byte reaches the firmware |
//! | `corrupt` | arrive with one byte flipped (a bad checksum) |
//! | `delay` | arrive `ms` late (default 5 ms, well past the 1 ms reply timeout) |
//! | `error-bits` | carry error bits `bits` (`overheating` by default; `overload`, `input-voltage`) |
//! | `past-limit` | read the servo's joint past its soft limit: the plant drives the joint [`PAST_LIMIT_RAD`] beyond the upper end of the limit the firmware enforces (a joint with a soft limit only: LEO's) |
//!
//! `at` is the emulated time since boot at which the window opens (default
//! 10 s), `for` its length (default 1 s), `servo` the Dynamixel ID whose
//! answers are affected (default 1).

use pada_core::dynamixel::ErrorFlags;
use std::fmt;

/// How far past its soft limit a `past-limit` fault drives a joint \[rad\]:
/// ten of the servo's position counts, so the reading is past the limit
/// whatever the rounding. (Here, beside the fault, so that `pada servos`'
/// bus takes it without importing the SIL's bus, which imports it back.)
pub const PAST_LIMIT_RAD: f32 = 10.0 * pada_core::robot::hardware::POSITION_UNIT_RAD;

/// What goes wrong.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaultKind {
    /// Answers lost.
    Drop,
    /// One byte of every answer flipped.
    Corrupt,
    /// Answers late by this many µs.
    Delay {
        /// The delay \[µs\].
        us: u64,
    },
    /// Answers carry these error bits.
    ErrorBits {
        /// The bits.
        bits: ErrorFlags,
    },
    /// The joint reads past its soft limit.
    PastLimit,
}

impl FaultKind {
    /// The kind's name on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            FaultKind::Drop => "drop",
            FaultKind::Corrupt => "corrupt",
            FaultKind::Delay { .. } => "delay",
            FaultKind::ErrorBits { .. } => "error-bits",
            FaultKind::PastLimit => "past-limit",
        }
    }
}

/// One injected fault.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FaultSpec {
    /// What goes wrong.
    pub kind: FaultKind,
    /// The window's start, emulated time since boot \[µs\].
    pub start_us: u64,
    /// The window's end (exclusive) \[µs\].
    pub end_us: u64,
    /// The servo whose answers are affected.
    pub servo: u8,
}

impl FaultSpec {
    /// Whether an answer sent at `t_us` by `servo` is affected.
    pub fn applies(&self, t_us: u64, servo: u8) -> bool {
        servo == self.servo && (self.start_us..self.end_us).contains(&t_us)
    }
}

impl fmt::Display for FaultSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:at={}:for={}:servo={}",
            self.kind.name(),
            self.start_us as f64 * 1e-6,
            (self.end_us - self.start_us) as f64 * 1e-6,
            self.servo
        )?;
        match self.kind {
            FaultKind::Delay { us } => write!(f, ":ms={}", us as f64 * 1e-3),
            FaultKind::ErrorBits { bits } => write!(f, ":bits={}", bits_name(bits)),
            _ => Ok(()),
        }
    }
}

fn bits_name(bits: ErrorFlags) -> &'static str {
    match bits {
        ErrorFlags::OVERLOAD => "overload",
        ErrorFlags::INPUT_VOLTAGE => "input-voltage",
        _ => "overheating",
    }
}

/// Parses one `--fault` value; the error says what is wrong.
pub fn parse(spec: &str) -> Result<FaultSpec, String> {
    let mut parts = spec.split(':');
    let kind_name = parts.next().unwrap_or_default();
    let mut at = 10.0f64;
    let mut len = 1.0f64;
    let mut servo = 1u8;
    let mut ms: Option<f64> = None;
    let mut bits: Option<ErrorFlags> = None;
    let number = |key: &str, v: &str| -> Result<f64, String> {
        v.parse::<f64>()
            .ok()
            .filter(|x| x.is_finite() && *x >= 0.0)
            .ok_or_else(|| format!("--fault {spec}: {key}={v} is not a number >= 0"))
    };
    for part in parts {
        let (key, value) = part.split_once('=').ok_or_else(|| {
            format!("--fault {spec}: `{part}` is not key=value (at, for, servo, ms, bits)")
        })?;
        match key {
            "at" => at = number(key, value)?,
            "for" => len = number(key, value)?,
            "ms" => ms = Some(number(key, value)?),
            "servo" => {
                servo = value
                    .parse::<u8>()
                    .ok()
                    .filter(|id| (1..=253).contains(id))
                    .ok_or_else(|| format!("--fault {spec}: servo={value} is not an ID 1..253"))?
            }
            "bits" => {
                bits = Some(match value {
                    "overheating" => ErrorFlags::OVERHEATING,
                    "overload" => ErrorFlags::OVERLOAD,
                    "input-voltage" => ErrorFlags::INPUT_VOLTAGE,
                    other => {
                        return Err(format!(
                            "--fault {spec}: bits={other} is unknown: valid are overheating, overload, input-voltage"
                        ))
                    }
                })
            }
            other => return Err(format!("--fault {spec}: unknown key `{other}`: valid are at, for, servo, ms, bits")),
        }
    }
    if len <= 0.0 {
        return Err(format!("--fault {spec}: for={len} must be > 0"));
    }
    let kind = match kind_name {
        "drop" => FaultKind::Drop,
        "corrupt" => FaultKind::Corrupt,
        "delay" => {
            let ms = ms.unwrap_or(5.0);
            if ms <= 0.0 {
                return Err(format!("--fault {spec}: ms={ms} must be > 0"));
            }
            FaultKind::Delay {
                us: (ms * 1000.0).round() as u64,
            }
        }
        "error-bits" => FaultKind::ErrorBits {
            bits: bits.unwrap_or(ErrorFlags::OVERHEATING),
        },
        "past-limit" => FaultKind::PastLimit,
        other => {
            return Err(format!(
            "--fault {spec}: unknown kind `{other}`: valid are drop, corrupt, delay, error-bits, past-limit"
        ))
        }
    };
    if ms.is_some() && !matches!(kind, FaultKind::Delay { .. }) {
        return Err(format!("--fault {spec}: ms= applies to delay only"));
    }
    if bits.is_some() && !matches!(kind, FaultKind::ErrorBits { .. }) {
        return Err(format!("--fault {spec}: bits= applies to error-bits only"));
    }
    if at > 1e6 || len > 1e6 {
        return Err(format!("--fault {spec}: at and for must be at most 1e6 s"));
    }
    let start_us = (at * 1e6).round() as u64;
    Ok(FaultSpec {
        kind,
        start_us,
        end_us: start_us + (len * 1e6).round().max(1.0) as u64,
        servo,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_and_options() {
        let f = parse("drop").unwrap();
        assert_eq!(
            f,
            FaultSpec {
                kind: FaultKind::Drop,
                start_us: 10_000_000,
                end_us: 11_000_000,
                servo: 1
            }
        );
        let f = parse("delay:at=2.5:for=0.1:ms=3").unwrap();
        assert_eq!(f.kind, FaultKind::Delay { us: 3000 });
        assert_eq!((f.start_us, f.end_us), (2_500_000, 2_600_000));
        assert_eq!(
            parse("error-bits:bits=overload:servo=3").unwrap().kind,
            FaultKind::ErrorBits {
                bits: ErrorFlags::OVERLOAD
            }
        );
        assert_eq!(parse("delay").unwrap().kind, FaultKind::Delay { us: 5000 });
        for s in [
            "corrupt",
            "drop:at=1:for=2",
            "delay:ms=7",
            "error-bits:bits=input-voltage",
            "past-limit:servo=4:at=3",
        ] {
            assert_eq!(
                parse(&parse(s).unwrap().to_string()).unwrap(),
                parse(s).unwrap(),
                "{s}"
            );
        }
        assert!(f.applies(2_500_000, 1) && !f.applies(2_600_000, 1) && !f.applies(2_550_000, 2));
    }

    #[test]
    fn bad_specs_say_why() {
        for (s, want) in [
            ("melt", "unknown kind"),
            ("drop:at=-1", "not a number"),
            ("drop:for=0", "must be > 0"),
            ("drop:when=3", "unknown key"),
            ("drop:ms=3", "delay only"),
            ("corrupt:bits=overload", "error-bits only"),
            ("error-bits:bits=hot", "unknown"),
            ("drop:servo=0", "ID"),
            ("drop:at", "key=value"),
        ] {
            let e = parse(s).unwrap_err();
            assert!(e.contains(want), "{s}: {e}");
        }
    }
}
