//! Dry friction of a servo joint as stick and slip (`docs/reference/grl.md` §1.5:
//! the RX-28's 0.2 N m), in a form an implicit integrator solves at any
//! step size.
//!
//! GRL gives each hinge an ODE motor with target velocity 0 and maximum
//! torque 0.2 N m: a velocity constraint the LCP solver keeps at rest while
//! the load stays below 0.2 N m. Rapier's per-DoF "friction loss" is the
//! same constraint, but its projected Gauss–Seidel sweep solves the joints
//! once, before the contacts, without warm start, so the contacts' impulses
//! leave every joint a residual velocity of order h·(acceleration): the
//! standing robot's hip, held by 50 N m, still crept at 0.18 rad/s with
//! 11 ms steps and 0.04 rad/s with 1.4 ms steps (measured; `README.md`). Here the friction is instead a small state machine per
//! joint that rapier's multibody integrates implicitly:
//!
//! - **stick**: the joint is tied to an anchor angle by a stiff spring and
//!   damper (the gearbox's pre-sliding compliance), both in rapier's
//!   implicit per-DoF spring and damping, so the joint holds at every step
//!   size and never creeps; the torque the tie carries is read after each
//!   step, and above the friction torque the joint breaks away;
//! - **slip**: a constant torque of the friction's size against the
//!   direction of motion; when the joint's velocity reverses within a step
//!   it has stopped inside the step, so its velocity is brought back to 0
//!   (by a generalized impulse on that DoF alone) and it sticks where it is.
//!
//! The state machine is pure (no rapier types) so that each rule is tested
//! on its own; `model.rs` applies it.

/// Pre-sliding stiffness of a held joint (N m/rad). At the full friction
/// torque the tie deflects 0.2/1e4 = 0.02 mrad, 250× less than one count
/// of the RX-28's position sensor (300°/1024 = 5.1 mrad), so the servo
/// could not tell the tie from a rigid hold. Rapier adds h²·k to the mass
/// matrix (0.7 at 8.3 ms steps against link inertias of 1e-3…0.2), which
/// stays well conditioned.
pub const STICK_STIFFNESS: f32 = 1.0e4;

/// Damping of the tie (N m s/rad): at least critical, 2·√(k·J), for every
/// inertia J a joint carries, up to the whole robot about its stance ankle
/// (≈ 0.155 kg m² in the start pose, which needs 79). Over-damped, a held
/// joint never rings on its tie, so the tie's torque does not overshoot the
/// load and a load below the friction torque never breaks it: with 1e3
/// N m/rad and critical damping for the armature alone, a 0.19 N m step on
/// the arm rang past 0.2 N m and slipped at 40 physics steps per period
/// (measured). The price is a lag of c/k = 10 ms before a tie carries a new
/// load in full.
pub const STICK_DAMPING: f32 = 100.0;

/// What one joint's friction is doing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FrictionState {
    /// Held at `anchor` (rad) by the tie.
    Stick {
        /// The joint angle the tie pulls toward.
        anchor: f32,
    },
    /// Sliding in `direction` (+1 or −1, the sign of the joint rate).
    Slip {
        /// +1 or −1.
        direction: f32,
    },
}

/// What the integrator applies to one joint during the next physics step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrictionLoad {
    /// Implicit spring stiffness (N m/rad) toward `rest`.
    pub stiffness: f32,
    /// The spring's rest angle (rad).
    pub rest: f32,
    /// Implicit damping added to the joint (N m s/rad).
    pub damping: f32,
    /// Constant joint torque (N m).
    pub torque: f32,
}

/// What happened to one joint's friction over a physics step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrictionUpdate {
    /// The state for the next step.
    pub state: FrictionState,
    /// The joint stopped inside the step: its rate must be set to 0.
    pub stop: bool,
}

/// Coulomb dry friction with stiction at one joint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stiction {
    /// Friction torque (N m): the largest torque a held joint resists and
    /// the torque against a sliding one.
    pub max_torque: f32,
    /// Tie stiffness while held (N m/rad).
    pub stiffness: f32,
    /// Tie damping while held (N m s/rad).
    pub damping: f32,
}

impl Stiction {
    /// A friction of `max_torque` with the tie of
    /// [`STICK_STIFFNESS`] and [`STICK_DAMPING`].
    pub fn new(max_torque: f32) -> Self {
        Self {
            max_torque,
            stiffness: STICK_STIFFNESS,
            damping: STICK_DAMPING,
        }
    }

    /// Whether there is any friction (0 N m switches it off).
    pub fn is_active(&self) -> bool {
        self.max_torque > 0.0
    }

    /// The spring, damping and torque to apply over the next step.
    pub fn load(&self, state: FrictionState) -> FrictionLoad {
        match state {
            _ if !self.is_active() => FrictionLoad {
                stiffness: 0.0,
                rest: 0.0,
                damping: 0.0,
                torque: 0.0,
            },
            FrictionState::Stick { anchor } => FrictionLoad {
                stiffness: self.stiffness,
                rest: anchor,
                damping: self.damping,
                torque: 0.0,
            },
            FrictionState::Slip { direction } => FrictionLoad {
                stiffness: 0.0,
                rest: 0.0,
                damping: 0.0,
                torque: -self.max_torque * direction,
            },
        }
    }

    /// The torque the tie carries at angle `q` and rate `rate` while held
    /// (the friction torque on the joint, N m).
    pub fn holding_torque(&self, anchor: f32, q: f32, rate: f32) -> f32 {
        -self.stiffness * (q - anchor) - self.damping * rate
    }

    /// The state for the next step when the torque driving a held joint
    /// changes by `load_change` (N m) at a step's start (a new voltage):
    /// the tie then has to carry its present torque minus the change, and
    /// if that exceeds the friction torque the joint breaks away now,
    /// sliding the way the load pushes it. Without this the break-away is
    /// seen only after a step held by the tie, and a driven joint loses one
    /// physics step of motion at every voltage change: a first-order error
    /// in the step (`sim/src/leo/README.md`, the A/B table). A sliding
    /// joint, or a held one whose tie keeps up, is left as it is.
    pub fn at_load_change(
        &self,
        state: FrictionState,
        q: f32,
        rate: f32,
        load_change: f32,
    ) -> FrictionState {
        if !self.is_active() || !(q.is_finite() && rate.is_finite() && load_change.is_finite()) {
            return state;
        }
        match state {
            FrictionState::Stick { anchor } => {
                let held = self.holding_torque(anchor, q, rate) - load_change;
                if held.abs() > self.max_torque {
                    FrictionState::Slip {
                        direction: -held.signum(),
                    }
                } else {
                    state
                }
            }
            FrictionState::Slip { .. } => state,
        }
    }

    /// The state after a step that ended at angle `q` and rate `rate`.
    ///
    /// - held, and the tie carries more than the friction torque: the
    ///   joint breaks away, sliding the way the load pushes it;
    /// - sliding, and the rate no longer points in the sliding direction:
    ///   the joint stopped within the step and is held where it is (a rate
    ///   that reversed is to be set to 0: `stop`);
    /// - otherwise unchanged.
    ///
    /// A non-finite angle or rate leaves the state as it is (the model's
    /// blow-up check ends such an episode).
    pub fn update(&self, state: FrictionState, q: f32, rate: f32) -> FrictionUpdate {
        let unchanged = FrictionUpdate { state, stop: false };
        if !self.is_active() || !(q.is_finite() && rate.is_finite()) {
            return unchanged;
        }
        match state {
            FrictionState::Stick { anchor } => {
                let held = self.holding_torque(anchor, q, rate);
                if held.abs() > self.max_torque {
                    FrictionUpdate {
                        // The tie pulls against the load: the joint goes
                        // the other way.
                        state: FrictionState::Slip {
                            direction: -held.signum(),
                        },
                        stop: false,
                    }
                } else {
                    unchanged
                }
            }
            FrictionState::Slip { direction } => {
                if rate * direction > 0.0 {
                    unchanged
                } else {
                    FrictionUpdate {
                        state: FrictionState::Stick { anchor: q },
                        stop: rate != 0.0,
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const F: Stiction = Stiction {
        max_torque: 0.2,
        stiffness: STICK_STIFFNESS,
        damping: STICK_DAMPING,
    };

    #[test]
    fn a_held_joint_gets_a_tie_and_no_torque() {
        let l = F.load(FrictionState::Stick { anchor: 0.3 });
        assert_eq!(l.stiffness, STICK_STIFFNESS);
        assert_eq!(l.rest, 0.3);
        assert_eq!(l.damping, STICK_DAMPING);
        assert_eq!(l.torque, 0.0);
    }

    #[test]
    fn a_sliding_joint_gets_the_friction_torque_against_its_motion() {
        let l = F.load(FrictionState::Slip { direction: 1.0 });
        assert_eq!((l.stiffness, l.damping, l.torque), (0.0, 0.0, -0.2));
        let l = F.load(FrictionState::Slip { direction: -1.0 });
        assert_eq!(l.torque, 0.2);
    }

    #[test]
    fn the_tie_holds_up_to_the_friction_torque_and_breaks_beyond() {
        let anchor = 0.1;
        // 0.19 N m of load deflects the tie by 0.19/k: still held.
        let q = anchor + 0.19 / STICK_STIFFNESS;
        let u = F.update(FrictionState::Stick { anchor }, q, 0.0);
        assert_eq!(u.state, FrictionState::Stick { anchor });
        // 0.21 N m: breaks away in the direction of the deflection.
        let q = anchor + 0.21 / STICK_STIFFNESS;
        let u = F.update(FrictionState::Stick { anchor }, q, 0.0);
        assert_eq!(u.state, FrictionState::Slip { direction: 1.0 });
        let q = anchor - 0.21 / STICK_STIFFNESS;
        let u = F.update(FrictionState::Stick { anchor }, q, 0.0);
        assert_eq!(u.state, FrictionState::Slip { direction: -1.0 });
        assert!(!u.stop);
    }

    #[test]
    fn a_held_joint_breaks_away_at_a_load_change_beyond_the_friction_torque() {
        let held = FrictionState::Stick { anchor: 0.0 };
        // The tie carries nothing; a +0.3 N m drive breaks it, forward.
        assert_eq!(
            F.at_load_change(held, 0.0, 0.0, 0.3),
            FrictionState::Slip { direction: 1.0 }
        );
        assert_eq!(
            F.at_load_change(held, 0.0, 0.0, -0.3),
            FrictionState::Slip { direction: -1.0 }
        );
        // 0.19 N m stays held; so does a change that unloads a loaded tie
        // (the tie carries +0.15 N m, the drive adds +0.1 N m: 0.05 left).
        assert_eq!(F.at_load_change(held, 0.0, 0.0, 0.19), held);
        let loaded_q = -0.15 / STICK_STIFFNESS;
        assert_eq!(F.at_load_change(held, loaded_q, 0.0, 0.1), held);
        // A sliding joint is left to its own rule.
        let sliding = FrictionState::Slip { direction: -1.0 };
        assert_eq!(F.at_load_change(sliding, 0.0, 0.0, 5.0), sliding);
        // Non-finite input changes nothing.
        assert_eq!(F.at_load_change(held, 0.0, 0.0, f32::NAN), held);
    }

    #[test]
    fn a_sliding_joint_sticks_where_its_rate_reverses() {
        let s = FrictionState::Slip { direction: 1.0 };
        let u = F.update(s, 0.5, 0.3);
        assert_eq!(
            u,
            FrictionUpdate {
                state: s,
                stop: false
            }
        );
        let u = F.update(s, 0.5, -0.01);
        assert_eq!(u.state, FrictionState::Stick { anchor: 0.5 });
        assert!(u.stop);
        let u = F.update(s, 0.5, 0.0);
        assert_eq!(u.state, FrictionState::Stick { anchor: 0.5 });
        assert!(!u.stop);
    }

    #[test]
    fn no_friction_applies_nothing_and_never_changes_state() {
        let off = Stiction::new(0.0);
        let s = FrictionState::Stick { anchor: 0.0 };
        let l = off.load(s);
        assert_eq!((l.stiffness, l.damping, l.torque), (0.0, 0.0, 0.0));
        assert_eq!(off.update(s, 5.0, 3.0).state, s);
    }

    #[test]
    fn non_finite_readings_leave_the_state_alone() {
        let s = FrictionState::Stick { anchor: 0.0 };
        assert_eq!(F.update(s, f32::NAN, 0.0).state, s);
        assert_eq!(F.update(s, 0.0, f32::INFINITY).state, s);
    }
}
