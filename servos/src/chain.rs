//! `pada servos --chain sts3215:1-6`: a bare chain of servos that move
//! under their own position loops ([`super::ft`]), with no robot behind
//! them: what a client library's test or an SO-101 owner's bring-up
//! script talks to before any robot definition exists (a robot's
//! STS3215s have its physics behind them: [`super::ft::with_robot`]).

use pada_core::dynamixel::table::PresentState;
use pada_sim::rig::{JointState, Rig};

/// The chain's models, as `--chain` names them.
pub const MODELS: [&str; 1] = ["sts3215"];

/// A parsed `--chain MODEL:IDS`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChainSpec {
    /// The model (lower case).
    pub model: String,
    /// The IDs, in order.
    pub ids: Vec<u8>,
}

/// Parses `MODEL:A-B` or `MODEL:A,B,C` (IDs 0–253, each once).
pub fn parse(spec: &str) -> Result<ChainSpec, String> {
    let valid = "valid is MODEL:A-B or MODEL:A,B,… with MODEL sts3215 and IDs 0-253, e.g. sts3215:1-6";
    let (model, ids) = spec.split_once(':').ok_or_else(|| format!("--chain {spec}: {valid}"))?;
    let model = model.to_ascii_lowercase();
    if !MODELS.contains(&model.as_str()) {
        return Err(format!("--chain {spec}: no model {model}; {valid}"));
    }
    let id = |s: &str| s.trim().parse::<u8>().ok().filter(|&i| i <= pada_core::feetech::MAX_ID);
    let list: Option<Vec<u8>> = match ids.split_once('-') {
        Some((a, b)) => id(a).zip(id(b)).filter(|(a, b)| a <= b).map(|(a, b)| (a..=b).collect()),
        None => ids.split(',').map(id).collect(),
    };
    let list = list.filter(|l| !l.is_empty()).ok_or_else(|| format!("--chain {spec}: bad IDs; {valid}"))?;
    if (1..list.len()).any(|i| list[..i].contains(&list[i])) {
        return Err(format!("--chain {spec}: an ID named twice; {valid}"));
    }
    Ok(ChainSpec { model, ids: list })
}

/// No plant: the servos' outputs are their own position loops'.
pub struct NoPlant {
    ids: Vec<u8>,
}

impl NoPlant {
    /// For servos `ids`.
    pub fn new(ids: Vec<u8>) -> Self {
        NoPlant { ids }
    }
}

impl Rig for NoPlant {
    fn servo_ids(&self) -> &[u8] {
        &self.ids
    }
    fn supply_v(&self) -> f64 {
        super::ft::SUPPLY_DV as f64 / 10.0
    }
    fn advance_to(&mut self, _t_us: u64) {}
    fn drive(&mut self, _t_us: u64, _id: u8, _torque: bool, _volts: f64) {}
    fn present(&mut self, _t_us: u64, _id: u8) -> PresentState {
        PresentState::default()
    }
    fn joint_state(&mut self, _t_us: u64, _id: u8) -> JointState {
        JointState::default()
    }
    fn sensors(&mut self, _t_us: u64) -> (u16, u8) {
        (0, 0)
    }
    fn peek_present(&self, _t_us: u64, _id: u8) -> Option<PresentState> {
        None
    }
    fn peek_sensors(&self, _t_us: u64) -> Option<(u16, u8)> {
        None
    }
    fn describe(&self) -> String {
        "no plant: each servo follows its goal under its own position loop".into()
    }
    fn gear_torque(&self, _id: u8) -> f32 {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chains_are_parsed_or_refused_with_the_valid_form() {
        assert_eq!(parse("sts3215:1-6").unwrap().ids, vec![1, 2, 3, 4, 5, 6]);
        assert_eq!(parse("STS3215:3,1").unwrap(), ChainSpec { model: "sts3215".into(), ids: vec![3, 1] });
        for bad in ["sts3215", "xm430:1-2", "sts3215:6-1", "sts3215:1,1", "sts3215:254", "sts3215:"] {
            let e = parse(bad).unwrap_err();
            assert!(e.contains("valid is"), "{bad}: {e}");
        }
    }
}
