//! The algorithms by their command-line names — Section V's six and the
//! four gentle explorations — with their parameters (α of Eq. 8, Δ of
//! Eq. 9, OU's θ and σ, pink noise's σ, the penalty's weight), checked
//! before anything runs.
//!
//! The names are the learning core's ([`pada_core::policy::PolicyName`]):
//! one list for the learner, the checkpoint codes, the wire and the
//! command line. This module adds what only the command line needs: the
//! clap parser, the defaults and the parameter checks with their messages.

use pada_core::policy::PolicyKind;
pub use pada_core::policy::PolicyName as Algo;

/// The clap parser of `--algo`: exactly the core's names, listed in the
/// help and in the error for an unknown one.
pub fn algo_parser() -> impl clap::builder::TypedValueParser<Value = Algo> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(Algo::ALL.map(Algo::name))
        .try_map(|name| Algo::from_name(&name).ok_or("unknown algorithm"))
}

/// A bad algorithm parameter: the message names it and its valid range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct AlgoError(pub String);

/// Default α when none is given: the smallest α the paper found to meet
/// its objective (Section VII).
pub const DEFAULT_ALPHA: f32 = 0.834;
/// Default Δ when none is given: the paper's PADA Δ (Section VII).
pub const DEFAULT_DELTA: f32 = 0.5;
/// Default OU θ: DDPG's (Lillicrap et al., ICLR 2016), whose OU
/// exploration GRL's samplers follow.
pub const DEFAULT_THETA: f32 = 0.15;
/// Default OU σ: DDPG's 0.2, in units of the largest distance from 0 to a
/// bound (the stationary deviation is then 0.2/√(1 − 0.85²) = 0.38).
pub const DEFAULT_OU_SIGMA: f32 = 0.2;
/// Default pink-noise σ: the default OU's stationary deviation, so the two
/// explore with the same amplitude and differ in their spectrum.
pub const DEFAULT_PINK_SIGMA: f32 = 0.38;
/// Default penalty weight: a full-range action change costs 1 per step,
/// the order of the pendulum's torque cost −a² at 1.5 N·m (Section VII).
pub const DEFAULT_PENALTY_WEIGHT: f32 = 1.0;

/// The policy parameters given on the command line, each `None` when not
/// given.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PolicyFlags {
    /// `--alpha`.
    pub alpha: Option<f32>,
    /// `--delta`.
    pub delta: Option<f32>,
    /// `--theta`.
    pub theta: Option<f32>,
    /// `--sigma`.
    pub sigma: Option<f32>,
    /// `--weight`.
    pub weight: Option<f32>,
}

impl PolicyFlags {
    /// The flag named `name` (as [`Algo::parameter_names`] spells it).
    fn get(&self, name: &str) -> Option<f32> {
        match name {
            "alpha" => self.alpha,
            "delta" => self.delta,
            "theta" => self.theta,
            "sigma" => self.sigma,
            "weight" => self.weight,
            _ => None,
        }
    }

    /// Every flag with its name.
    fn all(&self) -> [(&'static str, Option<f32>); 5] {
        [
            ("alpha", self.alpha),
            ("delta", self.delta),
            ("theta", self.theta),
            ("sigma", self.sigma),
            ("weight", self.weight),
        ]
    }
}

/// The default of parameter `name` of `algo`.
fn default_of(algo: Algo, name: &str) -> f32 {
    match (algo, name) {
        (_, "alpha") => DEFAULT_ALPHA,
        (_, "delta") => DEFAULT_DELTA,
        (_, "theta") => DEFAULT_THETA,
        (Algo::PinkNoise, "sigma") => DEFAULT_PINK_SIGMA,
        (_, "sigma") => DEFAULT_OU_SIGMA,
        _ => DEFAULT_PENALTY_WEIGHT,
    }
}

/// The algorithms that take parameter `name`, for the error message.
fn takers(name: &str) -> String {
    let names: Vec<&str> =
        Algo::ALL.iter().filter(|a| a.parameter_names().contains(&name)).map(|a| a.name()).collect();
    match names.split_last() {
        Some((last, [])) => last.to_string(),
        Some((last, rest)) => format!("{} and {last}", rest.join(", ")),
        None => String::new(),
    }
}

/// The policy of `algo` with the given flags (defaults for those not
/// given: [`DEFAULT_ALPHA`], [`DEFAULT_DELTA`], [`DEFAULT_THETA`], …). A
/// parameter the algorithm does not take, or one outside its range, is an
/// error naming the flag and its valid range.
pub fn policy_kind_of(algo: Algo, flags: &PolicyFlags) -> Result<PolicyKind, AlgoError> {
    let names = algo.parameter_names();
    for (name, value) in flags.all() {
        if value.is_some() && !names.contains(&name) {
            return Err(AlgoError(format!("--{name} applies only to {}, not to {algo}", takers(name))));
        }
    }
    let mut parameters = [0.0f32; 2];
    for (i, name) in names.iter().enumerate() {
        parameters[i] = flags.get(name).unwrap_or_else(|| default_of(algo, name));
    }
    // The command line's Δ is at most the full range (the core accepts
    // PADA's Δ ≥ 1 as "everything"; here that is SARSA by another name).
    if algo.takes_delta() && !(parameters[0].is_finite() && parameters[0] > 0.0 && parameters[0] <= 1.0) {
        return Err(AlgoError(format!(
            "--delta {} is out of range: valid is 0 < delta <= 1 (relative to the action range)",
            parameters[0]
        )));
    }
    let kind = algo.with_parameters(parameters);
    kind.validate().map_err(|e| {
        let flag = match e.param {
            "lowpass alpha" => "alpha",
            p => p,
        };
        let value = parameters[names.iter().position(|n| *n == flag).unwrap_or(0)];
        AlgoError(format!("--{flag} {value} is out of range: valid is {}", e.valid))
    })?;
    Ok(kind)
}

/// [`policy_kind_of`] with only `--alpha` and `--delta` (the commands that
/// offer no other flag).
pub fn policy_kind(algo: Algo, alpha: Option<f32>, delta: Option<f32>) -> Result<PolicyKind, AlgoError> {
    policy_kind_of(algo, &PolicyFlags { alpha, delta, ..PolicyFlags::default() })
}

/// The algorithm of a policy.
pub fn algo_of(kind: &PolicyKind) -> Algo {
    Algo::of(kind)
}

/// The policy's first parameter (α, Δ, θ, σ or the weight), if it has one.
pub fn parameter_of(kind: &PolicyKind) -> Option<f32> {
    kind.parameter()
}

/// The symbol of parameter `name` in labels.
fn symbol(name: &str) -> &'static str {
    match name {
        "alpha" => "α",
        "delta" => "Δ",
        "theta" => "θ",
        "sigma" => "σ",
        _ => "w",
    }
}

/// A short label: `sarsa`, `lowpass α=0.834`, `pada Δ=0.5`, `ou θ=0.15
/// σ=0.2`.
pub fn label(kind: &PolicyKind) -> String {
    label_with(kind, |v| v.to_string())
}

/// [`label`] with each parameter value written by `value` (the figures
/// write Δ = 1/6 where the plans and reports write 0.16666667).
pub fn label_with(kind: &PolicyKind, value: impl Fn(f32) -> String) -> String {
    let algo = algo_of(kind);
    let values = kind.parameters();
    let mut s = algo.name().to_string();
    for (i, name) in algo.parameter_names().iter().enumerate() {
        s += &format!(" {}={}", symbol(name), value(values[i]));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameters_map_and_are_checked() {
        assert_eq!(
            policy_kind(Algo::Pada, None, Some(0.5)),
            Ok(PolicyKind::Pada { delta: 0.5 })
        );
        assert_eq!(
            policy_kind(Algo::LowPass, None, None),
            Ok(PolicyKind::LowPass { alpha: 0.834 })
        );
        assert_eq!(policy_kind(Algo::Sarsa, None, None), Ok(PolicyKind::Sarsa));
        let e = policy_kind(Algo::LowPass, Some(1.5), None).unwrap_err().0;
        assert!(e.contains("0 < alpha <= 1"), "{e}");
        let e = policy_kind(Algo::Integrator, None, Some(0.0))
            .unwrap_err()
            .0;
        assert!(e.contains("0 < delta <= 1"), "{e}");
        assert!(policy_kind(Algo::Pada, None, Some(f32::NAN)).is_err());
        let e = policy_kind(Algo::Sarsa, Some(0.5), None).unwrap_err().0;
        assert!(e.contains("--alpha applies only to lowpass and markov-lowpass"), "{e}");
        assert!(policy_kind(Algo::LowPass, None, Some(0.5)).is_err());
    }

    #[test]
    fn the_gentle_explorations_take_their_own_flags() {
        let flags = |theta, sigma, weight| PolicyFlags { theta, sigma, weight, ..PolicyFlags::default() };
        assert_eq!(
            policy_kind_of(Algo::OrnsteinUhlenbeck, &flags(None, Some(0.5), None)),
            Ok(PolicyKind::OrnsteinUhlenbeck { theta: DEFAULT_THETA, sigma: 0.5 })
        );
        assert_eq!(
            policy_kind_of(Algo::PinkNoise, &PolicyFlags::default()),
            Ok(PolicyKind::PinkNoise { sigma: DEFAULT_PINK_SIGMA })
        );
        assert_eq!(
            policy_kind(Algo::EpsilonPada, None, Some(1.0 / 3.0)),
            Ok(PolicyKind::EpsilonPada { delta: 1.0 / 3.0 })
        );
        for (algo, f, says) in [
            (Algo::OrnsteinUhlenbeck, flags(Some(0.0), None, None), "--theta 0 is out of range: valid is 0 < theta <= 1"),
            (Algo::OrnsteinUhlenbeck, flags(None, Some(9.0), None), "--sigma 9 is out of range: valid is 0 < sigma <= 4"),
            (Algo::PinkNoise, flags(None, Some(f32::NAN), None), "--sigma NaN is out of range"),
            (Algo::ActionPenalty, flags(None, None, Some(-2.0)), "--weight -2 is out of range: valid is 0 < weight <= 10000"),
            (Algo::Pada, flags(Some(0.1), None, None), "--theta applies only to ou, not to pada"),
            (Algo::Sarsa, flags(None, Some(0.1), None), "--sigma applies only to ou and pink, not to sarsa"),
            (Algo::LowPass, flags(None, None, Some(1.0)), "--weight applies only to action-penalty, not to lowpass"),
        ] {
            let e = policy_kind_of(algo, &f).unwrap_err().0;
            assert!(e.starts_with(says), "{algo}: {e}");
        }
        let e = policy_kind(Algo::EpsilonPada, None, Some(1.5)).unwrap_err().0;
        assert!(e.contains("0 < delta <= 1"), "{e}");
    }

    #[test]
    fn labels() {
        assert_eq!(label(&PolicyKind::Pada { delta: 0.5 }), "pada Δ=0.5");
        assert_eq!(
            label(&PolicyKind::LowPass { alpha: 0.834 }),
            "lowpass α=0.834"
        );
        assert_eq!(label(&PolicyKind::Sarsa), "sarsa");
        assert_eq!(label(&PolicyKind::OrnsteinUhlenbeck { theta: 0.15, sigma: 0.2 }), "ou θ=0.15 σ=0.2");
        assert_eq!(label(&PolicyKind::ActionPenalty { weight: 3.0 }), "action-penalty w=3");
        for a in Algo::ALL {
            assert_eq!(algo_of(&policy_kind(a, None, None).unwrap()), a);
        }
    }

    #[test]
    fn the_command_line_names_are_the_cores_and_serialise_as_them() {
        for a in Algo::ALL {
            assert_eq!(
                serde_json::to_string(&a).unwrap(),
                format!("\"{}\"", a.name())
            );
        }
        use clap::builder::TypedValueParser;
        let cmd = clap::Command::new("t");
        let parsed = algo_parser().parse_ref(&cmd, None, std::ffi::OsStr::new("markov-lowpass"));
        assert_eq!(parsed.unwrap(), Algo::MarkovLowPass);
        assert!(algo_parser()
            .parse_ref(&cmd, None, std::ffi::OsStr::new("lowpas"))
            .is_err());
    }
}

/// Checks `--mtbf-budget` against the other flags, for `pada run` and `pada
/// sil` alike: the governor moves PADA's Δ or the low-pass filter's α, so
/// it needs one of those policies and excludes choosing the parameter; the
/// budget lies in `0 < b <= MAX_BUDGET_S` (the wire command's range).
pub fn check_mtbf_budget(algo: Algo, alpha_given: bool, delta_given: bool, budget: f32) -> Result<(), String> {
    if !matches!(algo, Algo::Pada | Algo::LowPass) {
        return Err(format!(
            "--mtbf-budget applies only to pada and lowpass (the governor moves their delta or alpha), not to {algo}"
        ));
    }
    for (flag, given) in [("--delta", delta_given), ("--alpha", alpha_given)] {
        if given {
            return Err(format!(
                "{flag} and --mtbf-budget exclude each other: the governor chooses the {} while learning",
                &flag[2..]
            ));
        }
    }
    let max = pada_core::governor::MAX_BUDGET_S;
    if !(budget.is_finite() && budget > 0.0 && budget <= max) {
        return Err(format!("--mtbf-budget {budget} is out of range: valid is 0 < budget <= {max:e} s"));
    }
    Ok(())
}
