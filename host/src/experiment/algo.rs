//! The six algorithms of Section V by their command-line names, with their
//! parameter (α of Eq. 8 or Δ of Eq. 9), checked before anything runs.
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

/// The policy of `algo` with `alpha` / `delta` (defaults
/// [`DEFAULT_ALPHA`], [`DEFAULT_DELTA`]). A parameter the algorithm does not
/// take, or one outside its range, is an error.
pub fn policy_kind(
    algo: Algo,
    alpha: Option<f32>,
    delta: Option<f32>,
) -> Result<PolicyKind, AlgoError> {
    if alpha.is_some() && !algo.takes_alpha() {
        return Err(AlgoError(format!(
            "--alpha applies only to lowpass and markov-lowpass, not to {algo}"
        )));
    }
    if delta.is_some() && !algo.takes_delta() {
        return Err(AlgoError(format!(
            "--delta applies only to integrator, markov-integrator and pada, not to {algo}"
        )));
    }
    let a = alpha.unwrap_or(DEFAULT_ALPHA);
    let d = delta.unwrap_or(DEFAULT_DELTA);
    if algo.takes_alpha() && !(a.is_finite() && a > 0.0 && a <= 1.0) {
        return Err(AlgoError(format!(
            "--alpha {a} is out of range: valid is 0 < alpha <= 1"
        )));
    }
    if algo.takes_delta() && !(d.is_finite() && d > 0.0 && d <= 1.0) {
        return Err(AlgoError(format!(
            "--delta {d} is out of range: valid is 0 < delta <= 1 (relative to the action range)"
        )));
    }
    Ok(algo.with_parameter(if algo.takes_alpha() { a } else { d }))
}

/// The algorithm of a policy.
pub fn algo_of(kind: &PolicyKind) -> Algo {
    Algo::of(kind)
}

/// The policy's parameter (α or Δ), if it has one.
pub fn parameter_of(kind: &PolicyKind) -> Option<f32> {
    kind.parameter()
}

/// A short label: `sarsa`, `lowpass α=0.834`, `pada Δ=0.5`.
pub fn label(kind: &PolicyKind) -> String {
    let algo = algo_of(kind);
    match parameter_of(kind) {
        None => algo.name().to_string(),
        Some(p) if algo.takes_alpha() => format!("{} α={}", algo.name(), p),
        Some(p) => format!("{} Δ={}", algo.name(), p),
    }
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
        assert!(e.contains("--alpha applies only"), "{e}");
        assert!(policy_kind(Algo::LowPass, None, Some(0.5)).is_err());
    }

    #[test]
    fn labels() {
        assert_eq!(label(&PolicyKind::Pada { delta: 0.5 }), "pada Δ=0.5");
        assert_eq!(
            label(&PolicyKind::LowPass { alpha: 0.834 }),
            "lowpass α=0.834"
        );
        assert_eq!(label(&PolicyKind::Sarsa), "sarsa");
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
