//! What `pada watch` shows, built frame by frame from the decoded stream:
//! the learning curve (Section VI's test runs), the fatigue per gearbox
//! and the predicted MTBF (Section IV), the last episode's outputs, the
//! link counters, the safety state and fault, and the policy.
//!
//! Everything is bounded: the fatigue history is [`Decimated`], the last
//! episode's trace and the fault history have capacities, and only the
//! learning curve (one point per test run, every 10 learning episodes)
//! grows with the run.

use super::series::Decimated;
use crate::capture::{Latest, MessageCounts};
use crate::experiment::metrics::{end_performance, rise_time};
use pada_core::fatigue::PAPER_WINDOW_STEPS;
use pada_core::wire::{
    Decoded, Hello, LinkStats, PolicyReport, RunMode, StepKind, ToHost, MAX_GEARBOXES,
};
use serde::Serialize;

/// Points kept of the fatigue history (per series, all joints together).
pub const FATIGUE_POINTS: usize = 2000;
/// Steps kept of one episode (LEO's episodes have 750, the pendulum's 60
/// or 100); longer episodes keep their last this many.
pub const EPISODE_STEPS: usize = 20_000;
/// Faults kept, newest last.
pub const FAULTS_KEPT: usize = 32;

/// One test run on the learning curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CurvePoint {
    /// Learning time before the test run \[s\]: the learning episodes'
    /// steps so far times the control period.
    pub learning_time_s: f64,
    /// The test run's return.
    #[serde(rename = "return")]
    pub test_return: f64,
    /// Its episode index.
    pub episode: u32,
}

/// The fatigue counters at one step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FatiguePoint {
    /// Time since boot \[s\] (the step's `time_ms`).
    pub time_s: f64,
    /// Accumulated damage J per learned joint (Eq. 7).
    pub damage: [f64; MAX_GEARBOXES],
    /// Backlash re-engagements per learned joint.
    pub reengagements: [u32; MAX_GEARBOXES],
}

/// One control step of an episode's trace.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TraceStep {
    /// Time since the episode's first step \[s\]: its position in the
    /// episode times the control period (the host runner's `time_ms` does
    /// not advance during test runs), or `time_ms` while the period is
    /// unknown.
    pub t_s: f64,
    /// Output applied per action dimension, after the policy (torque on
    /// the simulated pendulum, voltage on LEO and the physical pendulum).
    pub output: Vec<f32>,
    /// Per joint: whether its backlash re-engaged in this step.
    pub reengaged: Vec<bool>,
}

/// An episode's outputs, step by step.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EpisodeTrace {
    /// Episode index.
    pub episode: u32,
    /// Learning or test run.
    pub mode: &'static str,
    /// Its return, once its `Episode` frame arrived.
    #[serde(rename = "return")]
    pub total_return: Option<f64>,
    /// The steps (the last [`EPISODE_STEPS`]).
    pub steps: Vec<TraceStep>,
    /// Steps dropped from the front for capacity.
    pub dropped: u64,
    #[serde(skip)]
    start_ms: u32,
}

/// Fatigue of one learned joint (gearbox).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JointFatigueView {
    /// Accumulated damage J.
    pub damage: f64,
    /// Backlash re-engagements.
    pub reengagements: u32,
    /// Predicted MTBF over the whole run so far \[s\]: learning time / J
    /// (`None` = infinite or unknown).
    pub mtbf_s: Option<f64>,
    /// The paper's predicted MTBF \[s\]: the first 1200 learning actions'
    /// duration over the damage they did (Section IV); provisional until
    /// 1200 were seen.
    pub window_mtbf_s: Option<f64>,
}

/// The fatigue counters and the predicted MTBF.
#[derive(Debug, Clone, Serialize)]
pub struct FatigueView {
    /// Per learned joint.
    pub joints: Vec<JointFatigueView>,
    /// The robot's MTBF: its weakest gearbox's \[s\].
    pub robot_mtbf_s: Option<f64>,
    /// The robot's MTBF over the paper's window \[s\].
    pub robot_window_mtbf_s: Option<f64>,
    /// Learning actions the window needs (the paper's 1200).
    pub window_actions: u32,
    /// Learning actions seen so far, up to the window.
    pub window_actions_seen: u32,
    /// The history (time since boot).
    pub history: Decimated<FatiguePoint>,
}

/// The policy in force.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PolicyView {
    /// The policy the learner was built with (`sarsa`, `lowpass`, …, `pada`,
    /// `epsilon-pada`, `ou`, `pink`, `action-penalty`).
    pub built: &'static str,
    /// Its first parameter's name: `alpha` (Eq. 8), `delta` (Eq. 9),
    /// `theta`, `sigma` or `weight`.
    pub parameter_name: Option<&'static str>,
    /// Its α, Δ, θ, σ or weight.
    pub parameter: Option<f32>,
    /// Switched back to plain SARSA(λ) (Section VIII).
    pub switched_to_sarsa: bool,
    /// Step at which this took effect.
    pub step: u32,
    /// One line for the page, e.g. `pada Δ=0.5`.
    pub label: String,
    /// The wear governor, when one runs: budget, Δ or α in force, damage
    /// rate and MTBF over its window.
    pub governor: Option<pada_core::governor::GovernorStatus>,
}

impl PolicyView {
    /// The view of a `Policy` report.
    pub fn of(report: &PolicyReport) -> PolicyView {
        let kind = report.built;
        let name = pada_core::policy::PolicyName::of(&kind);
        let mut label = crate::experiment::algo::label(&kind);
        if let Some(g) = &report.governor {
            label += &format!(
                " (wear governor: budget {:.0} s, rung {}/{}, damage rate {:.3e} per s, window MTBF {:.0} s over {} actions)",
                g.budget_s,
                g.rung + 1,
                g.rungs,
                g.damage_rate,
                g.window_mtbf_s,
                g.window_steps
            );
        }
        if report.switched_to_sarsa {
            label = format!("sarsa (switched from {label} at step {})", report.step);
        }
        PolicyView {
            built: kind.name(),
            parameter_name: name.parameter_names().first().copied(),
            parameter: kind.parameter(),
            switched_to_sarsa: report.switched_to_sarsa,
            step: report.step,
            label,
            governor: report.governor,
        }
    }
}

/// A fault the board reported.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FaultView {
    /// Its cause's name (e.g. `servo-timeout`).
    pub cause: String,
    /// The cause in full, with the servo or joint concerned.
    pub detail: String,
    /// Control step.
    pub step: u32,
    /// Time since boot \[ms\].
    pub time_ms: u32,
}

/// The safety state machine as the stream reported it.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct SafetyView {
    /// The current state (`Learning`, `Testing`, `Idle`, `Paused`, `Fault`).
    pub state: Option<String>,
    /// The step of the last state change.
    pub since_step: Option<u32>,
    /// The fault in force (cleared when the state leaves Fault).
    pub fault: Option<FaultView>,
    /// The last faults, newest last.
    pub history: Vec<FaultView>,
}

/// Learning progress and the curve.
#[derive(Debug, Clone, Default, Serialize)]
pub struct LearningView {
    /// Learning steps (the learning episodes' lengths summed).
    pub learning_steps: u64,
    /// Learning time \[s\] (`None` while the control period is unknown).
    pub learning_time_s: Option<f64>,
    /// One point per test run.
    pub curve: Vec<CurvePoint>,
    /// End performance (Section VI): the mean of the last ⌈n/10⌉ test runs.
    pub end_performance: Option<f64>,
    /// Test runs in the end-performance window.
    pub end_window_runs: usize,
    /// Rise time (Section VI) \[s\].
    pub rise_time_s: Option<f64>,
}

/// Everything the page and `/api/state` show. The first fields are those
/// of `pada capture --json`'s summary, with the same names and meaning.
#[derive(Debug, Clone, Serialize)]
pub struct WatchState {
    /// What is read.
    pub source: String,
    /// Why the stream ended; `None` while it goes on.
    pub ended: Option<String>,
    /// Frames, bytes and every kind of loss.
    pub link: LinkStats,
    /// Frames that could not be used (all kinds).
    pub bad_frames: u32,
    /// Frames by message.
    pub messages: MessageCounts,
    /// The latest values, as `pada capture` keeps them.
    pub latest: Latest,
    /// The sender's last `Hello`.
    pub hello: Option<Hello>,
    /// The control period \[s\]: from `Hello`, else the smallest step
    /// between two consecutive `Step` frames (ms resolution).
    pub period_s: Option<f64>,
    /// Where `period_s` came from: `hello` or `steps`.
    pub period_from: Option<&'static str>,
    /// Learning or testing, from the last `Step` (for senders that send no
    /// `State` frames, as `pada run`).
    pub mode: Option<&'static str>,
    /// The policy in force (`Policy` frames).
    pub policy: Option<PolicyView>,
    /// The safety state and faults.
    pub safety: SafetyView,
    /// The learning curve.
    pub learning: LearningView,
    /// Fatigue per gearbox and the predicted MTBF.
    pub fatigue: FatigueView,
    /// The last finished episode.
    pub last_episode: Option<EpisodeTrace>,
    /// Bumped at every change.
    pub version: u64,
    #[serde(skip)]
    current: Option<EpisodeTrace>,
    #[serde(skip)]
    last_step: Option<(u32, u32, [u32; MAX_GEARBOXES])>,
    #[serde(skip)]
    step_period_ms: Option<u32>,
    #[serde(skip)]
    window_start: Option<[f64; MAX_GEARBOXES]>,
    #[serde(skip)]
    window_end: Option<[f64; MAX_GEARBOXES]>,
    #[serde(skip)]
    joints: usize,
}

impl WatchState {
    /// Nothing received yet from `source`.
    pub fn new(source: String) -> Self {
        WatchState {
            source,
            ended: None,
            link: LinkStats::default(),
            bad_frames: 0,
            messages: MessageCounts::default(),
            latest: Latest::default(),
            hello: None,
            period_s: None,
            period_from: None,
            mode: None,
            policy: None,
            safety: SafetyView::default(),
            learning: LearningView::default(),
            fatigue: FatigueView {
                joints: Vec::new(),
                robot_mtbf_s: None,
                robot_window_mtbf_s: None,
                window_actions: PAPER_WINDOW_STEPS,
                window_actions_seen: 0,
                history: Decimated::new(FATIGUE_POINTS),
            },
            last_episode: None,
            version: 0,
            current: None,
            last_step: None,
            step_period_ms: None,
            window_start: None,
            window_end: None,
            joints: 0,
        }
    }

    /// Takes the frames of one chunk and the recorder's counters after it.
    pub fn apply(
        &mut self,
        frames: &[Decoded<ToHost>],
        link: LinkStats,
        messages: MessageCounts,
        latest: &Latest,
    ) {
        for frame in frames {
            self.frame(&frame.msg);
        }
        if !frames.is_empty() || link != self.link {
            self.version += 1;
        }
        self.link = link;
        self.bad_frames = link.bad_frames();
        self.messages = messages;
        self.latest.clone_from(latest);
        self.update_derived();
    }

    /// The stream ended for `reason`.
    pub fn end(&mut self, reason: String) {
        if self.ended.is_none() {
            self.ended = Some(reason);
            self.version += 1;
        }
    }

    fn frame(&mut self, msg: &ToHost) {
        match msg {
            ToHost::Hello(h) => {
                self.hello = Some(h.clone());
                if h.period_us > 0 {
                    self.period_s = Some(h.period_us as f64 / 1e6);
                    self.period_from = Some("hello");
                }
            }
            ToHost::Policy(p) => self.policy = Some(PolicyView::of(p)),
            ToHost::Step(s) => self.step(s),
            ToHost::Episode(e) => {
                let learning = e.mode == RunMode::Learning;
                if learning {
                    self.learning.learning_steps += e.length as u64;
                } else {
                    let t = self.period_s.unwrap_or(0.0) * self.learning.learning_steps as f64;
                    self.learning.curve.push(CurvePoint {
                        learning_time_s: t,
                        test_return: e.total_reward as f64,
                        episode: e.index,
                    });
                }
                if let Some(last) = self.last_episode.as_mut() {
                    if last.episode == e.index {
                        last.total_return = Some(e.total_reward as f64);
                    }
                }
            }
            ToHost::State(s) => {
                self.safety.state = Some(state_name(&s.to).to_string());
                self.safety.since_step = Some(s.step);
                if s.to.fault().is_none() {
                    self.safety.fault = None;
                }
            }
            ToHost::Fault(f) => {
                let view = FaultView {
                    cause: f.cause.name().to_string(),
                    detail: format!("{:?}", f.cause),
                    step: f.step,
                    time_ms: f.time_ms,
                };
                self.safety.fault = Some(view.clone());
                if self.safety.history.len() == FAULTS_KEPT {
                    self.safety.history.remove(0);
                }
                self.safety.history.push(view);
            }
            _ => {}
        }
    }

    fn step(&mut self, s: &pada_core::wire::Step) {
        let n = s.joints.len().min(MAX_GEARBOXES);
        self.joints = self.joints.max(n);
        let mut damage = [0.0; MAX_GEARBOXES];
        let mut reeng = [0u32; MAX_GEARBOXES];
        for (i, j) in s.joints.iter().take(MAX_GEARBOXES).enumerate() {
            damage[i] = j.damage;
            reeng[i] = j.reengagements;
        }
        // The period, when no Hello said it: the smallest positive step
        // between consecutive frames.
        if let Some((prev_step, prev_ms, _)) = self.last_step {
            if s.step == prev_step.wrapping_add(1) && s.time_ms > prev_ms {
                let d = s.time_ms - prev_ms;
                if self.step_period_ms.is_none_or(|p| d < p) {
                    self.step_period_ms = Some(d);
                }
            }
        }
        if self.period_from != Some("hello") {
            if let Some(ms) = self.step_period_ms {
                self.period_s = Some(ms as f64 * 1e-3);
                self.period_from = Some("steps");
            }
        }
        self.mode = Some(crate::capture::mode_name(s.mode));
        let previous = self.last_step.map(|(_, _, r)| r);
        self.last_step = Some((s.step, s.time_ms, reeng));
        self.fatigue.history.push(FatiguePoint {
            time_s: s.time_ms as f64 * 1e-3,
            damage,
            reengagements: reeng,
        });

        // The paper's window: the first 1200 learning actions, each
        // followed by one plant step (a Step frame of kind Step,
        // Absorbing or Timeout), and the damage they did.
        if s.mode == RunMode::Learning {
            if s.kind == StepKind::Start && self.window_start.is_none() {
                self.window_start = Some(damage);
            }
            if s.kind != StepKind::Start && self.window_end.is_none() {
                self.window_start.get_or_insert(damage);
                self.fatigue.window_actions_seen += 1;
                if self.fatigue.window_actions_seen >= PAPER_WINDOW_STEPS {
                    self.window_end = Some(damage);
                }
            }
        }

        // The episode trace.
        if s.kind == StepKind::Start || self.current.is_none() {
            if let Some(done) = self.current.take().filter(|c| !c.steps.is_empty()) {
                self.last_episode = Some(done);
            }
            self.current = Some(EpisodeTrace {
                episode: s.episode,
                mode: crate::capture::mode_name(s.mode),
                total_return: None,
                steps: Vec::new(),
                dropped: 0,
                start_ms: s.time_ms,
            });
        }
        if let Some(cur) = self.current.as_mut() {
            let reengaged = (0..n)
                .map(|i| previous.is_some_and(|p| reeng[i] > p[i]))
                .collect();
            if !s.output.is_empty() || matches!(s.kind, StepKind::Absorbing | StepKind::Timeout) {
                if cur.steps.len() == EPISODE_STEPS {
                    cur.steps.remove(0);
                    cur.dropped += 1;
                }
                let k = cur.steps.len() as u64 + cur.dropped;
                let t_s = match self.period_s {
                    Some(p) => k as f64 * p,
                    None => s.time_ms.wrapping_sub(cur.start_ms) as f64 * 1e-3,
                };
                cur.steps.push(TraceStep {
                    t_s,
                    output: s.output.iter().copied().collect(),
                    reengaged,
                });
            }
        }
        if matches!(s.kind, StepKind::Absorbing | StepKind::Timeout) {
            if let Some(done) = self.current.take() {
                self.last_episode = Some(done);
            }
        }
    }

    fn update_derived(&mut self) {
        let l = &mut self.learning;
        l.learning_time_s = self.period_s.map(|p| p * l.learning_steps as f64);
        let returns: Vec<f64> = l.curve.iter().map(|p| p.test_return).collect();
        let times: Vec<f64> = l.curve.iter().map(|p| p.learning_time_s).collect();
        l.end_performance = end_performance(&returns);
        l.end_window_runs = returns.len().div_ceil(10);
        l.rise_time_s = rise_time(&times, &returns);

        let n = self.joints;
        let last = self.fatigue.history.last;
        let seen = self.fatigue.window_actions_seen as f64;
        let window_time = self.period_s.map(|p| p * seen);
        let mut joints = Vec::with_capacity(n);
        for i in 0..n {
            let (damage, reengagements) =
                last.map_or((0.0, 0), |p| (p.damage[i], p.reengagements[i]));
            let mtbf_s = mtbf(l.learning_time_s, damage);
            let window_damage = match (self.window_start, self.window_end) {
                (Some(a), Some(b)) => Some(b[i] - a[i]),
                (Some(a), None) => Some(damage - a[i]),
                _ => None,
            };
            let window_mtbf_s = window_damage.and_then(|d| mtbf(window_time, d));
            joints.push(JointFatigueView {
                damage,
                reengagements,
                mtbf_s,
                window_mtbf_s,
            });
        }
        let weakest = |f: fn(&JointFatigueView) -> Option<f64>| {
            joints.iter().filter_map(f).min_by(|a, b| a.total_cmp(b))
        };
        self.fatigue.robot_mtbf_s = weakest(|j| j.mtbf_s);
        self.fatigue.robot_window_mtbf_s = weakest(|j| j.window_mtbf_s);
        self.fatigue.joints = joints;
    }

    /// Learned joints seen in `Step` frames.
    pub fn joint_count(&self) -> usize {
        self.joints
    }
}

/// Predicted MTBF from elapsed time and damage (failure at J = 1, Eq. 7):
/// `None` without a time or with no damage yet (infinite).
fn mtbf(time_s: Option<f64>, damage: f64) -> Option<f64> {
    let t = time_s?;
    (damage > 0.0 && t.is_finite()).then(|| t / damage)
}

/// The state's name without the fault's details.
fn state_name(s: &pada_core::safety::State) -> &'static str {
    use pada_core::safety::State;
    match s {
        State::Idle => "Idle",
        State::Learning => "Learning",
        State::Testing => "Testing",
        State::Paused => "Paused",
        State::Fault(_) => "Fault",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pada_core::wire::{Episode, JointFatigue, Step};

    fn step(n: u32, kind: StepKind, mode: RunMode, damage: f64, reeng: u32) -> Decoded<ToHost> {
        Decoded {
            seq: n,
            gap: None,
            msg: ToHost::Step(Step {
                step: n,
                time_ms: n * 50,
                episode: 0,
                mode,
                kind,
                state: Default::default(),
                action: 0,
                output: [1.5f32].into_iter().collect(),
                reward: 0.0,
                td_error: 0,
                explored: false,
                footstep: false,
                joints: [JointFatigue {
                    damage,
                    reengagements: reeng,
                }]
                .into_iter()
                .collect(),
                loop_us: 0,
                agent_cycles: 0,
            }),
        }
    }

    fn feed(s: &mut WatchState, frames: Vec<Decoded<ToHost>>) {
        s.apply(
            &frames,
            LinkStats::default(),
            MessageCounts::default(),
            &Latest::default(),
        );
    }

    #[test]
    fn window_mtbf_is_the_first_1200_learning_actions_over_their_damage() {
        let mut s = WatchState::new("test".into());
        // No Hello: the period comes from the steps (50 ms).
        let mut frames = vec![step(0, StepKind::Start, RunMode::Learning, 0.0, 0)];
        for k in 1..=1500u32 {
            // 1e-6 of damage per action; re-engaging every 10th.
            frames.push(step(
                k,
                StepKind::Step,
                RunMode::Learning,
                k as f64 * 1e-6,
                k / 10,
            ));
        }
        feed(&mut s, frames);
        assert_eq!(s.period_from, Some("steps"));
        assert_eq!(s.fatigue.window_actions_seen, 1200);
        let w = s.fatigue.joints[0].window_mtbf_s.unwrap();
        // 1200 actions · 0.05 s over J = 1200e-6.
        assert!((w - 1200.0 * 0.05 / 1200e-6).abs() < 1e-6 * w, "{w}");
        assert_eq!(s.fatigue.robot_window_mtbf_s, Some(w));
        assert_eq!(s.fatigue.joints[0].reengagements, 150);
        // The trace marks the steps whose count went up.
        let cur = s.current.as_ref().unwrap();
        assert_eq!(cur.steps.iter().filter(|t| t.reengaged[0]).count(), 150);
    }

    #[test]
    fn test_runs_make_the_curve_at_the_learning_time_so_far() {
        let mut s = WatchState::new("test".into());
        let hello = Decoded {
            seq: 0,
            gap: None,
            msg: ToHost::Hello(Hello {
                protocol: 3,
                robot: heapless::String::try_from("physical-pendulum-20hz").unwrap(),
                robot_hash: 0,
                config_hash: 0,
                weight_count: 1,
                period_us: 50_000,
                state_dims: 2,
                joints: 1,
            }),
        };
        let ep = |index, mode, r| Decoded {
            seq: 0,
            gap: None,
            msg: ToHost::Episode(Episode {
                index,
                mode,
                total_reward: r,
                length: 60,
                weights_checksum: 0,
            }),
        };
        let policy = Decoded {
            seq: 0,
            gap: None,
            msg: ToHost::Policy(PolicyReport {
                step: 7,
                built: pada_core::policy::PolicyKind::Pada { delta: 0.5 },
                switched_to_sarsa: true,
                governor: None,
            }),
        };
        feed(
            &mut s,
            vec![
                hello,
                policy,
                ep(0, RunMode::Testing, -900.0),
                ep(1, RunMode::Learning, -950.0),
                ep(2, RunMode::Learning, -940.0),
                ep(3, RunMode::Testing, -800.0),
            ],
        );
        let c = &s.learning.curve;
        assert_eq!(c.len(), 2);
        assert_eq!(c[0].learning_time_s, 0.0);
        assert!((c[1].learning_time_s - 6.0).abs() < 1e-9);
        assert_eq!(s.learning.end_performance, Some(-800.0));
        assert_eq!(s.learning.end_window_runs, 1);
        let p = s.policy.as_ref().unwrap();
        assert_eq!(
            (p.built, p.parameter, p.parameter_name),
            ("pada", Some(0.5), Some("delta"))
        );
        assert!(
            p.label.starts_with("sarsa (switched from pada Δ=0.5"),
            "{}",
            p.label
        );
    }

    #[test]
    fn a_fault_is_shown_with_its_cause_until_the_state_leaves_fault() {
        use pada_core::safety::{FaultCause, State};
        use pada_core::wire::{Fault, StateChange};
        let cause = FaultCause::ServoTimeout {
            servo: 3,
            attempts: 4,
        };
        let msg = |msg| Decoded {
            seq: 0,
            gap: None,
            msg,
        };
        let mut s = WatchState::new("test".into());
        feed(
            &mut s,
            vec![
                msg(ToHost::State(StateChange {
                    step: 10,
                    from: State::Learning,
                    to: State::Fault(cause),
                })),
                msg(ToHost::Fault(Fault {
                    step: 10,
                    time_ms: 500,
                    cause,
                })),
            ],
        );
        assert_eq!(s.safety.state.as_deref(), Some("Fault"));
        let f = s.safety.fault.as_ref().unwrap();
        assert_eq!(f.cause, "servo-timeout");
        assert!(f.detail.contains("servo: 3"), "{}", f.detail);
        assert_eq!((f.step, f.time_ms), (10, 500));
        feed(
            &mut s,
            vec![msg(ToHost::State(StateChange {
                step: 12,
                from: State::Fault(cause),
                to: State::Idle,
            }))],
        );
        assert_eq!(s.safety.state.as_deref(), Some("Idle"));
        assert!(s.safety.fault.is_none());
        assert_eq!(s.safety.history.len(), 1);
        let page = crate::watch::page::live(
            &s,
            crate::watch::page::Clock {
                wall_s: 1.0,
                since_data_s: Some(0.5),
            },
        );
        assert!(page.contains("servo-timeout") && !page.contains("banner fault"));
    }
}
