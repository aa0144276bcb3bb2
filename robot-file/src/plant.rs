//! How far the robot may differ from its model: the ranges of the
//! `[plant]` table of `robot.toml`, or of `pada run --plant-ranges`. The
//! simulation draws a plant within them (`pada-sim`'s `variation`) to
//! stand in for the real robot, or draws a new one every episode while it
//! pretrains (domain randomisation).
//!
//! Every parameter is a closed range `[low, high]`; `[x, x]` is one value.
//! The model is the identity of each: factors of 1, nothing added.

use crate::error::{Locator, RobotFileError};
use crate::schema::PlantSection;
use toml::Spanned;

/// A closed range of one parameter of the plant.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Span {
    /// Its lower end.
    pub lo: f64,
    /// Its upper end (at least `lo`).
    pub hi: f64,
}

impl Span {
    /// The one value `x`.
    pub const fn at(x: f64) -> Span {
        Span { lo: x, hi: x }
    }

    /// Whether the range is the single value `x`.
    pub fn is(&self, x: f64) -> bool {
        self.lo == x && self.hi == x
    }
}

impl std::fmt::Display for Span {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.lo == self.hi {
            write!(f, "{}", self.lo)
        } else {
            write!(f, "{}..{}", self.lo, self.hi)
        }
    }
}

/// The ranges of the plant's parameters, each with the bounds a value
/// must lie in ([`PlantRanges::FIELDS`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PlantRanges {
    /// Factor on every moving link's mass and inertia (1: the model's).
    pub mass: Span,
    /// Factor on each motor's torque constant, which scales its torque per
    /// volt and its back-EMF's damping (squared) alike (1: the model's).
    pub motor_constant: Span,
    /// Dry (Coulomb) friction added at each joint \[N·m\].
    pub friction_nm: Span,
    /// Play between each joint's sensor and its link \[rad\]: the link
    /// lags the reading by up to half of it either way (backlash).
    pub backlash_rad: Span,
    /// Control periods each command reaches the motor late (whole periods).
    pub delay_periods: Span,
    /// Standard deviation of the noise on each joint's angle reading \[rad\].
    pub noise_rad: Span,
}

/// One parameter's name, its bounds and what it is, for errors and docs.
pub struct Field {
    /// Its name in `[plant]` and `--plant-ranges`.
    pub name: &'static str,
    /// The smallest value allowed.
    pub min: f64,
    /// The largest value allowed.
    pub max: f64,
}

impl PlantRanges {
    /// The model itself: nothing differs.
    pub const MODEL: PlantRanges = PlantRanges {
        mass: Span::at(1.0),
        motor_constant: Span::at(1.0),
        friction_nm: Span::at(0.0),
        backlash_rad: Span::at(0.0),
        delay_periods: Span::at(0.0),
        noise_rad: Span::at(0.0),
    };

    /// The parameters in the order of [`spans_mut`](Self::spans_mut), with
    /// their bounds: a factor from 0.2 to 5, up to 10 N·m of friction, up
    /// to 0.5 rad of play, up to 10 periods of delay, up to 0.5 rad of
    /// noise.
    pub const FIELDS: [Field; 6] = [
        Field { name: "mass", min: 0.2, max: 5.0 },
        Field { name: "motor_constant", min: 0.2, max: 5.0 },
        Field { name: "friction_nm", min: 0.0, max: 10.0 },
        Field { name: "backlash_rad", min: 0.0, max: 0.5 },
        Field { name: "delay_periods", min: 0.0, max: 10.0 },
        Field { name: "noise_rad", min: 0.0, max: 0.5 },
    ];

    /// The ranges, in the order of [`FIELDS`](Self::FIELDS).
    pub fn spans(&self) -> [Span; 6] {
        [self.mass, self.motor_constant, self.friction_nm, self.backlash_rad, self.delay_periods, self.noise_rad]
    }

    fn spans_mut(&mut self) -> [&mut Span; 6] {
        [
            &mut self.mass,
            &mut self.motor_constant,
            &mut self.friction_nm,
            &mut self.backlash_rad,
            &mut self.delay_periods,
            &mut self.noise_rad,
        ]
    }

    /// Whether every range is the model's single value.
    pub fn is_model(&self) -> bool {
        *self == PlantRanges::MODEL
    }

    /// `self` with `name` set to `span`, or why not (an unknown name, a
    /// range out of order or out of the parameter's bounds, a fractional
    /// delay).
    pub fn with(mut self, name: &str, span: Span) -> Result<PlantRanges, String> {
        let k = PlantRanges::FIELDS.iter().position(|f| f.name == name).ok_or_else(|| {
            format!(
                "{name:?} is no parameter of the plant: valid are {}",
                PlantRanges::FIELDS.map(|f| f.name).join(", ")
            )
        })?;
        let f = &PlantRanges::FIELDS[k];
        if !(span.lo.is_finite() && span.hi.is_finite() && span.lo <= span.hi) {
            return Err(format!("{name} {span} is not a range: give low <= high, both finite"));
        }
        if span.lo < f.min || span.hi > f.max {
            return Err(format!("{name} {span} is out of range: valid is {} to {}", f.min, f.max));
        }
        if name == "delay_periods" && (span.lo.fract() != 0.0 || span.hi.fract() != 0.0) {
            return Err(format!("delay_periods {span} is not valid: whole control periods, 0 to 10"));
        }
        *self.spans_mut()[k] = span;
        Ok(self)
    }

    /// `self` with the ranges of a command line's `NAME=VALUE[,NAME=LOW..HIGH]...`
    /// (`pada run --plant-ranges`).
    pub fn with_arg(self, arg: &str) -> Result<PlantRanges, String> {
        let mut r = self;
        for item in arg.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let (name, value) = item
                .split_once('=')
                .ok_or_else(|| format!("{item:?} is not NAME=VALUE or NAME=LOW..HIGH"))?;
            let num = |s: &str| {
                s.trim().parse::<f64>().map_err(|_| format!("{name}: {s:?} is not a number"))
            };
            let span = match value.split_once("..") {
                Some((lo, hi)) => Span { lo: num(lo)?, hi: num(hi)? },
                None => Span::at(num(value)?),
            };
            r = r.with(name.trim(), span)?;
        }
        Ok(r)
    }

    /// The ranges as `NAME=VALUE` items, for reports and command lines.
    pub fn to_arg(&self) -> String {
        PlantRanges::FIELDS
            .iter()
            .zip(self.spans())
            .map(|(f, s)| format!("{}={s}", f.name))
            .collect::<Vec<_>>()
            .join(",")
    }
}

/// `[plant]`, checked: each given range within its bounds.
pub(crate) fn plant(at: &Locator, p: &PlantSection) -> Result<PlantRanges, RobotFileError> {
    let given: [(&str, &Option<Spanned<[f64; 2]>>); 6] = [
        ("mass", &p.mass),
        ("motor_constant", &p.motor_constant),
        ("friction_nm", &p.friction_nm),
        ("backlash_rad", &p.backlash_rad),
        ("delay_periods", &p.delay_periods),
        ("noise_rad", &p.noise_rad),
    ];
    let mut r = PlantRanges::MODEL;
    for (name, v) in given {
        if let Some(v) = v {
            let [lo, hi] = *v.get_ref();
            r = r.with(name, Span { lo, hi }).map_err(|e| at.at(&v.span(), format!("plant.{name}"), e))?;
        }
    }
    Ok(r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_command_line_sets_ranges_and_refuses_with_the_valid_range() {
        let r = PlantRanges::MODEL.with_arg("mass=0.9..1.1, delay_periods=1,noise_rad=0.002").unwrap();
        assert_eq!(r.mass, Span { lo: 0.9, hi: 1.1 });
        assert_eq!(r.delay_periods, Span::at(1.0));
        assert_eq!(r.noise_rad, Span::at(0.002));
        assert_eq!(r.motor_constant, Span::at(1.0));
        assert!(!r.is_model() && PlantRanges::MODEL.is_model());
        assert_eq!(PlantRanges::MODEL.with_arg(&r.to_arg()).unwrap(), r);
        let e = PlantRanges::MODEL.with_arg("mass=9").unwrap_err();
        assert!(e.contains("valid is 0.2 to 5"), "{e}");
        let e = PlantRanges::MODEL.with_arg("weight=1").unwrap_err();
        assert!(e.contains("valid are mass, motor_constant"), "{e}");
        assert!(PlantRanges::MODEL.with_arg("delay_periods=0.5").unwrap_err().contains("whole"));
        assert!(PlantRanges::MODEL.with_arg("mass=1.2..1.1").unwrap_err().contains("low <= high"));
        assert!(PlantRanges::MODEL.with_arg("mass").unwrap_err().contains("NAME=VALUE"));
    }
}
