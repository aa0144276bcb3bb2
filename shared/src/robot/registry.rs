//! The robots pada brings, listed once. Everything that offers a choice
//! of built-in robots (the command line's names, the firmware's build, the
//! host's simulations) reads this list; a robot of the user's own is not
//! in it and needs no entry: it comes as a `robot.toml` or as a
//! [`RobotSpec`](super::RobotSpec) and [`RobotRules`](super::RobotRules)
//! of the user's own crate.

use super::{leo, pendulum, RobotSpec};

/// A built-in robot's definition and how a Rust program names its
/// definition and rules (the firmware's build writes these into the
/// image's source).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BuiltIn {
    /// The definition.
    pub spec: &'static RobotSpec,
    /// The short name of its firmware images and `cargo xtask --robot`.
    pub short_name: &'static str,
    /// The Rust module that defines it.
    pub module: &'static str,
    /// The name of its definition's static in that module.
    pub spec_item: &'static str,
    /// The type of its rules in that module.
    pub rules_type: &'static str,
    /// The expression, in that module, that builds its rules.
    pub rules: &'static str,
}

/// Every built-in robot.
pub static BUILT_IN: [BuiltIn; 3] = [
    BuiltIn {
        spec: &pendulum::SPEC_33HZ,
        short_name: "pendulum",
        module: "pada_core::robot::pendulum",
        spec_item: "SPEC_33HZ",
        rules_type: "Pendulum",
        rules: "Pendulum::at_33hz()",
    },
    BuiltIn {
        spec: &pendulum::SPEC_20HZ,
        short_name: "pendulum-20hz",
        module: "pada_core::robot::pendulum",
        spec_item: "SPEC_20HZ",
        rules_type: "Pendulum",
        rules: "Pendulum::at_20hz()",
    },
    BuiltIn {
        spec: &leo::SPEC,
        short_name: "leo",
        module: "pada_core::robot::leo",
        spec_item: "SPEC",
        rules_type: "Leo",
        rules: "Leo::new()",
    },
];

/// Every built-in robot's definition.
pub fn specs() -> impl Iterator<Item = &'static RobotSpec> {
    BUILT_IN.iter().map(|b| b.spec)
}

/// The built-in robot called `name`: its [`RobotSpec::name`] or its short
/// name (`pendulum-33hz` is the 33 Hz pendulum too).
pub fn find(name: &str) -> Option<&'static BuiltIn> {
    let name = if name == "pendulum-33hz" { "pendulum" } else { name };
    BUILT_IN.iter().find(|b| b.spec.name == name || b.short_name == name)
}

/// The names `find` takes, for an error message: each robot's short and
/// full name.
pub fn names() -> impl Iterator<Item = &'static str> {
    BUILT_IN.iter().flat_map(|b| [b.short_name, b.spec.name])
}

impl BuiltIn {
    /// Rust source that names this robot for a program that links
    /// pada-core (the firmware's image): `ThisRobot`, its rules' type;
    /// `this_robot()`, which builds them; and `ROBOT`, its definition.
    pub fn rust_source(&self, out: &mut impl core::fmt::Write) -> core::fmt::Result {
        writeln!(out, "/// The rules of the robot this image drives: `{}`.", self.spec.name)?;
        writeln!(out, "pub type ThisRobot = {}::{};", self.module, self.rules_type)?;
        writeln!(out, "/// The robot's rules, before its first reading.")?;
        writeln!(out, "pub fn this_robot() -> ThisRobot {{\n    {}::{}\n}}", self.module, self.rules)?;
        writeln!(out, "/// The robot's definition.")?;
        writeln!(out, "pub static ROBOT: &pada_core::robot::RobotSpec = &{}::{};", self.module, self.spec_item)
    }
}

/// The built-in robot with this definition, if it is one.
pub fn of_spec(spec: &RobotSpec) -> Option<&'static BuiltIn> {
    BUILT_IN.iter().find(|b| b.spec == spec)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_finds_its_robot() {
        for (b, s) in BUILT_IN.iter().zip(specs()) {
            assert_eq!(b.spec, s);
            assert_eq!(find(b.spec.name).map(|f| f.spec), Some(s));
            assert_eq!(find(b.short_name).map(|f| f.spec), Some(s));
            assert_eq!(of_spec(s).map(|f| f.short_name), Some(b.short_name));
        }
        assert!(find("quadruped").is_none());
        assert_eq!(find("pendulum-33hz").map(|b| b.spec.name), Some("physical-pendulum"));
    }

    #[test]
    fn the_source_names_the_robots_items() {
        let mut s: heapless::String<512> = heapless::String::new();
        find("leo").unwrap().rust_source(&mut s).unwrap();
        assert!(s.contains("pub type ThisRobot = pada_core::robot::leo::Leo;"), "{s}");
        assert!(s.contains("pada_core::robot::leo::Leo::new()"), "{s}");
        assert!(s.contains("= &pada_core::robot::leo::SPEC;"), "{s}");
    }
}
