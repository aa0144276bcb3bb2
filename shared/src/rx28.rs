//! The Dynamixel RX-28 servo as a voltage-driven DC motor behind a gearbox
//! (`docs/reference/grl.md` §2.1–2.3, the model GRL simulates LEO with).
//!
//! Per sub-step, with commanded voltage `U` and joint rate `q̇` (§2.1):
//!
//! ```text
//! U_c     = clip(U, −U_sup, +U_sup)                 U_sup = 13.6 V
//! τ_m     = G·k·(U_c − G·k·q̇)/R                    motor torque at the output shaft
//! τ_vd    = K_t·(q − q_d) + D_t·(q̇ − q̇_d)           armature ("virtual disc") coupling
//! q̇_d    ← q̇_d + h·τ_vd/J_eff;  q_d ← q_d + h·q̇_d  J_eff = J_a·G²
//! τ_joint = η·(τ_m − τ_vd)
//! ```
//!
//! plus a separate dry friction of 0.2 N·m at the joint (§1.5).
//!
//! Three views of the same motor live here:
//!
//! - [`Rx28`]: the constants and pure functions (motor torque, stall torque,
//!   no-load speed, the 10.69 V thermal limit of §2.2) and
//!   [`Rx28::estimate_joint_torque`], the torque the firmware can compute
//!   from the voltage it commands and the joint speed it measures;
//! - [`Rx28Tracker`]: the stateful per-sub-step model exactly as GRL steps
//!   it, with the armature disc tracking the joint through a stiff
//!   spring-damper. It needs sub-steps of about 0.2 ms (GRL runs at
//!   5010 Hz), because the tracker spring against the light links of LEO is
//!   stiff;
//! - [`ReducedJoint`]: the same motor with the disc rigidly attached to the
//!   joint (the limit `K_t → ∞`). The disc then is a joint-space inertia
//!   `η·J_eff` (the armature), the back-EMF is a joint-space viscous damping
//!   `η·G²k²/R`, and the voltage is a joint torque `η·G·k·U_c/R`. A
//!   simulator that treats the armature and the damping implicitly (as
//!   rapier's multibodies do) is stable with steps 40× longer than the
//!   tracker allows. The tests of this module show that both views agree.
//!
//! All functions are total: a non-finite voltage or rate is read as 0 (the
//! motor is not driven, the joint is not moving), so a corrupted sensor value
//! can never turn into a NaN torque downstream (the fatigue counter refuses
//! non-finite torques).

/// Gear ratio G of the RX-28 (§2.1, LC `dxl_gearratio`, DXL).
pub const GEAR_RATIO: f32 = 193.0;
/// Torque constant k in N·m/A (§2.1, LC `dxl_torqueconstant`).
pub const TORQUE_CONSTANT: f32 = 0.00992;
/// Terminal resistance R in Ω (§2.1, LC).
pub const RESISTANCE: f32 = 8.6;
/// Gearbox efficiency η; it multiplies the whole joint torque including the
/// armature term (§2.1).
pub const EFFICIENCY: f32 = 0.75;
/// Rotor (armature) inertia J_a in kg·m², before the gearbox (§2.1).
pub const ARMATURE_INERTIA: f32 = 0.864e-7;
/// Stiffness K_t of the armature tracker in N·m/rad (§2.1,
/// `dxl_servoinertiatrackerK`).
pub const TRACKER_STIFFNESS: f32 = 500.0;
/// Damping D_t of the armature tracker in N·m·s/rad (§2.1,
/// `dxl_servoinertiatrackerD`).
pub const TRACKER_DAMPING: f32 = 0.07;
/// Dry friction torque at the joint in N·m (§1.5, `dxl_dryfriction`).
pub const DRY_FRICTION: f32 = 0.20;
/// The supply clip applied to every commanded voltage, in V (§2.1,
/// `dxl_supplyvoltage`).
pub const SUPPLY_CLIP: f32 = 13.6;

/// Supply voltage of LEO's servos V_s in V (§2.2, `LEO_SUPPLY_VOLTAGE`).
pub const LEO_SUPPLY_VOLTAGE: f32 = 14.0;
/// Temperature rise from 25 °C to the 75 °C maximum, in K (§2.2).
pub const THERMAL_RISE_K: f32 = 50.0;
/// Temperature coefficient of copper resistance, per K (§2.2).
pub const COPPER_COEFFICIENT: f32 = 0.004;
/// Temperature coefficient of the magnet's flux, per K (§2.2: 0).
pub const MAGNET_COEFFICIENT: f32 = 0.0;
/// Largest braking speed the voltage limit allows for, in rad/s (§2.2).
pub const MAX_BRAKING_SPEED: f32 = 4.0;

/// The voltage limit of §2.2: the largest voltage that keeps the winding
/// current of a hot motor (75 °C) braking at 4 rad/s within what 14 V gives
/// a cold motor at stall:
///
/// `f = (1 + ΔT·c_cu)/(1 + ΔT·c_mag)`,
/// `f_full = f + (−ω_b·k·G/V_s)·((1 + ΔT·c_mag) − f)`, `U_max = V_s/f_full`.
pub const fn thermal_voltage_limit(
    supply: f32,
    rise_k: f32,
    copper: f32,
    magnet: f32,
    braking_speed: f32,
    torque_constant: f32,
    gear_ratio: f32,
) -> f32 {
    let f = (1.0 + rise_k * copper) / (1.0 + rise_k * magnet);
    let f_full = f
        + (-braking_speed * torque_constant * gear_ratio / supply) * ((1.0 + rise_k * magnet) - f);
    supply / f_full
}

/// LEO's servo voltage limit ≈ 10.6919 V (§2.2, `LEO_MAX_DXL_VOLTAGE`); the
/// auto-actuated joints are clipped to it (§3.5).
pub const LEO_MAX_VOLTAGE: f32 = thermal_voltage_limit(
    LEO_SUPPLY_VOLTAGE,
    THERMAL_RISE_K,
    COPPER_COEFFICIENT,
    MAGNET_COEFFICIENT,
    MAX_BRAKING_SPEED,
    TORQUE_CONSTANT,
    GEAR_RATIO,
);

/// A non-finite input is read as 0 (see the module documentation); the
/// servo models of [`crate::servo`] read theirs so too.
#[inline]
pub(crate) fn finite_or_zero(x: f32) -> f32 {
    if x.is_finite() {
        x
    } else {
        0.0
    }
}

/// The constants of one RX-28 and the pure functions of its model (§2.1).
///
/// [`Rx28::LEO`] (also [`Default`]) holds the values GRL uses for LEO.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Rx28 {
    /// Gear ratio G.
    pub gear_ratio: f32,
    /// Torque constant k in N·m/A.
    pub torque_constant: f32,
    /// Terminal resistance R in Ω.
    pub resistance: f32,
    /// Gearbox efficiency η (multiplies the whole joint torque).
    pub efficiency: f32,
    /// Rotor inertia J_a in kg·m² (before the gearbox).
    pub armature_inertia: f32,
    /// Armature tracker stiffness K_t in N·m/rad.
    pub tracker_stiffness: f32,
    /// Armature tracker damping D_t in N·m·s/rad.
    pub tracker_damping: f32,
    /// Dry friction at the joint in N·m.
    pub dry_friction: f32,
    /// Supply clip of the commanded voltage in V.
    pub supply_clip: f32,
}

impl Default for Rx28 {
    fn default() -> Self {
        Self::LEO
    }
}

impl Rx28 {
    /// The RX-28 as GRL simulates it on LEO (§2.1, §1.5).
    pub const LEO: Rx28 = Rx28 {
        gear_ratio: GEAR_RATIO,
        torque_constant: TORQUE_CONSTANT,
        resistance: RESISTANCE,
        efficiency: EFFICIENCY,
        armature_inertia: ARMATURE_INERTIA,
        tracker_stiffness: TRACKER_STIFFNESS,
        tracker_damping: TRACKER_DAMPING,
        dry_friction: DRY_FRICTION,
        supply_clip: SUPPLY_CLIP,
    };

    /// Whether every constant is finite and in its physical range (all
    /// strictly positive except friction ≥ 0, tracker damping ≥ 0 and
    /// 0 < η ≤ 1). The functions below stay total for any parameters, but
    /// only valid ones describe a motor.
    pub fn is_valid(&self) -> bool {
        let pos = |x: f32| x.is_finite() && x > 0.0;
        let nonneg = |x: f32| x.is_finite() && x >= 0.0;
        pos(self.gear_ratio)
            && pos(self.torque_constant)
            && pos(self.resistance)
            && pos(self.efficiency)
            && self.efficiency <= 1.0
            && pos(self.armature_inertia)
            && pos(self.tracker_stiffness)
            && nonneg(self.tracker_damping)
            && nonneg(self.dry_friction)
            && pos(self.supply_clip)
    }

    /// Back-EMF constant at the joint, G·k ≈ 1.91456 V·s/rad (§2.1).
    pub fn back_emf_constant(&self) -> f32 {
        self.gear_ratio * self.torque_constant
    }

    /// Electrical damping at the joint before η, G²k²/R ≈ 0.42623 N·m·s/rad
    /// (§2.1).
    pub fn electrical_damping(&self) -> f32 {
        let gk = self.back_emf_constant();
        gk * gk / self.resistance
    }

    /// Reflected rotor inertia at the joint, J_eff = J_a·G² ≈ 3.2183e-3 kg·m²
    /// (§2.1).
    pub fn reflected_inertia(&self) -> f32 {
        self.armature_inertia * self.gear_ratio * self.gear_ratio
    }

    /// The commanded voltage after the supply clip (§2.1); non-finite → 0.
    pub fn clip_voltage(&self, voltage: f32) -> f32 {
        finite_or_zero(voltage).clamp(-self.supply_clip, self.supply_clip)
    }

    /// Motor torque at the output shaft before η:
    /// τ_m = G·k·(U_c − G·k·q̇)/R (§2.1).
    pub fn motor_torque(&self, voltage: f32, joint_rate: f32) -> f32 {
        let gk = self.back_emf_constant();
        gk * (self.clip_voltage(voltage) - gk * finite_or_zero(joint_rate)) / self.resistance
    }

    /// Winding current I = (U_c − G·k·q̇)/R in A (§2.1; the energy term of
    /// §3.7 uses it).
    pub fn current(&self, voltage: f32, joint_rate: f32) -> f32 {
        (self.clip_voltage(voltage) - self.back_emf_constant() * finite_or_zero(joint_rate))
            / self.resistance
    }

    /// Stall torque before η at `voltage` (q̇ = 0): ≈ 2.3803 N·m at
    /// 10.6919 V (§2.1).
    pub fn stall_torque(&self, voltage: f32) -> f32 {
        self.motor_torque(voltage, 0.0)
    }

    /// No-load speed at `voltage` (τ_m = 0): U_c/(G·k) ≈ 5.5845 rad/s at
    /// 10.6919 V (§2.1).
    pub fn no_load_speed(&self, voltage: f32) -> f32 {
        self.clip_voltage(voltage) / self.back_emf_constant()
    }

    /// The torque the servo applies to its joint in steady motion,
    /// η·τ_m = η·G·k·(U_c − G·k·q̇)/R — what the firmware can estimate from
    /// the voltage it commands and the joint speed it measures (§2.1; the
    /// dry friction of §1.5 acts at the joint and is not part of the gear
    /// torque).
    ///
    /// It leaves out the armature's inertial reaction `η·J_eff·q̈`, which
    /// needs an acceleration the servo does not measure; see
    /// [`Rx28::estimate_joint_torque_with_acceleration`].
    pub fn estimate_joint_torque(&self, voltage: f32, joint_rate: f32) -> f32 {
        self.efficiency * self.motor_torque(voltage, joint_rate)
    }

    /// The joint torque including the armature's reaction when the rotor is
    /// rigidly geared to the joint: η·(τ_m − J_eff·q̈) (§2.1 with K_t → ∞).
    /// A non-finite acceleration is read as 0.
    pub fn estimate_joint_torque_with_acceleration(
        &self,
        voltage: f32,
        joint_rate: f32,
        joint_acceleration: f32,
    ) -> f32 {
        self.efficiency
            * (self.motor_torque(voltage, joint_rate)
                - self.reflected_inertia() * finite_or_zero(joint_acceleration))
    }

    /// The rigid-armature form of this motor (see [`ReducedJoint`]).
    pub fn reduced(&self) -> ReducedJoint {
        ReducedJoint {
            armature: self.efficiency * self.reflected_inertia(),
            damping: self.efficiency * self.electrical_damping(),
            torque_per_volt: self.efficiency * self.back_emf_constant() / self.resistance,
            dry_friction: self.dry_friction,
            supply_clip: self.supply_clip,
        }
    }
}

/// The RX-28 with its rotor rigidly geared to the joint (§2.1 with the
/// tracker stiffness K_t → ∞): everything a simulator with joint-space
/// armature and implicit joint damping needs.
///
/// From τ_joint = η·(τ_m − τ_vd) and J_eff·q̈_d = τ_vd with q_d ≡ q:
/// τ_joint = η·G·k·U_c/R − η·(G²k²/R)·q̇ − η·J_eff·q̈, i.e. a voltage torque,
/// a viscous damping and an added joint inertia. (GRL's η multiplies the
/// armature term as well, §2.1, so the added inertia is η·J_eff.)
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ReducedJoint {
    /// Joint-space inertia added by the rotor, η·J_a·G² in kg·m².
    pub armature: f32,
    /// Joint-space viscous damping from the back-EMF, η·G²k²/R in N·m·s/rad.
    pub damping: f32,
    /// Joint torque per volt, η·G·k/R in N·m/V.
    pub torque_per_volt: f32,
    /// Dry friction at the joint in N·m (§1.5; not scaled by η).
    pub dry_friction: f32,
    /// Supply clip of the commanded voltage in V.
    pub supply_clip: f32,
}

impl ReducedJoint {
    /// The voltage part of the joint torque, η·G·k·U_c/R (constant while
    /// the voltage is held); non-finite → 0.
    pub fn voltage_torque(&self, voltage: f32) -> f32 {
        self.torque_per_volt * finite_or_zero(voltage).clamp(-self.supply_clip, self.supply_clip)
    }

    /// The gear torque for a given voltage, joint rate and joint
    /// acceleration: voltage torque − damping·q̇ − armature·q̈ (non-finite
    /// rate or acceleration → 0).
    pub fn joint_torque(&self, voltage: f32, joint_rate: f32, joint_acceleration: f32) -> f32 {
        self.voltage_torque(voltage)
            - self.damping * finite_or_zero(joint_rate)
            - self.armature * finite_or_zero(joint_acceleration)
    }
}

/// The stateful per-sub-step RX-28 exactly as GRL steps it (§2.1): the
/// voltage is held between [`Rx28Tracker::set_voltage`] calls (zero-order
/// hold over a control period, §1.1), and each sub-step computes the joint
/// torque from the current joint angle and rate, then advances the
/// armature disc.
///
/// Explicit in the tracker spring: stable only for sub-steps well below
/// 2·√(J_link/K_t) (the light links of LEO need ≈ 0.2 ms, GRL uses
/// 1/5010 s). The dry friction of §1.5 is separate (a constraint at the
/// joint) and not included.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Rx28Tracker {
    motor: Rx28,
    voltage: f32,
    disc_angle: f32,
    disc_rate: f32,
}

impl Rx28Tracker {
    /// A tracker at rest at angle 0 with 0 V.
    pub fn new(motor: Rx28) -> Self {
        Self {
            motor,
            voltage: 0.0,
            disc_angle: 0.0,
            disc_rate: 0.0,
        }
    }

    /// The motor constants.
    pub fn motor(&self) -> &Rx28 {
        &self.motor
    }

    /// Resets the disc to the joint state ("motor armature states are reset
    /// to the joint state", §1.8) and the voltage to 0. Non-finite → 0.
    pub fn reset(&mut self, joint_angle: f32, joint_rate: f32) {
        self.disc_angle = finite_or_zero(joint_angle);
        self.disc_rate = finite_or_zero(joint_rate);
        self.voltage = 0.0;
    }

    /// Holds `voltage` (after the supply clip; non-finite → 0) until the
    /// next call.
    pub fn set_voltage(&mut self, voltage: f32) {
        self.voltage = self.motor.clip_voltage(voltage);
    }

    /// The voltage being held.
    pub fn voltage(&self) -> f32 {
        self.voltage
    }

    /// The armature disc's angle and rate (joint coordinates).
    pub fn disc_state(&self) -> (f32, f32) {
        (self.disc_angle, self.disc_rate)
    }

    /// One sub-step of length `h` (s): returns the joint torque
    /// η·(τ_m − τ_vd) for the joint's current angle and rate, then advances
    /// the disc by symplectic Euler as GRL does. Non-finite inputs read as
    /// 0; a non-positive or non-finite `h` leaves the disc where it is.
    pub fn substep(&mut self, joint_angle: f32, joint_rate: f32, h: f32) -> f32 {
        let q = finite_or_zero(joint_angle);
        let qd = finite_or_zero(joint_rate);
        let tau_m = self.motor.motor_torque(self.voltage, qd);
        let tau_vd = self.motor.tracker_stiffness * (q - self.disc_angle)
            + self.motor.tracker_damping * (qd - self.disc_rate);
        if h.is_finite() && h > 0.0 {
            self.disc_rate += h * tau_vd / self.motor.reflected_inertia();
            self.disc_angle += h * self.disc_rate;
        }
        self.motor.efficiency * (tau_m - tau_vd)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f32, b: f32) -> f32 {
        ((a - b) / b).abs()
    }

    #[test]
    fn voltage_limit_matches_section_2_2() {
        assert!(
            rel(LEO_MAX_VOLTAGE, 10.691892) < 1e-5,
            "{}",
            LEO_MAX_VOLTAGE
        );
    }

    #[test]
    fn stall_torque_and_no_load_speed_match_section_2_1() {
        let m = Rx28::LEO;
        let u = LEO_MAX_VOLTAGE;
        assert!(
            rel(m.stall_torque(u), 2.3803) < 0.01,
            "{}",
            m.stall_torque(u)
        );
        assert!(rel(m.estimate_joint_torque(u, 0.0), 1.7852) < 0.01);
        assert!(
            rel(m.no_load_speed(u), 5.5845) < 0.01,
            "{}",
            m.no_load_speed(u)
        );
        // At the no-load speed the motor gives no torque.
        assert!(m.motor_torque(u, m.no_load_speed(u)).abs() < 1e-4);
        // Derived constants of §2.1.
        assert!(rel(m.back_emf_constant(), 1.91456) < 1e-4);
        assert!(rel(m.electrical_damping(), 0.42623) < 1e-4);
        assert!(rel(m.reflected_inertia(), 3.218314e-3) < 1e-4);
        assert!(m.is_valid());
    }

    #[test]
    fn supply_clip_and_bad_input() {
        let m = Rx28::LEO;
        assert_eq!(m.clip_voltage(100.0), SUPPLY_CLIP);
        assert_eq!(m.clip_voltage(-100.0), -SUPPLY_CLIP);
        assert_eq!(m.motor_torque(f32::NAN, 0.0), 0.0);
        assert_eq!(m.motor_torque(0.0, f32::INFINITY), 0.0);
        assert!(m
            .estimate_joint_torque_with_acceleration(5.0, 1.0, f32::NAN)
            .is_finite());
        let mut t = Rx28Tracker::new(m);
        t.set_voltage(f32::NAN);
        assert_eq!(t.voltage(), 0.0);
        assert!(t.substep(f32::NAN, f32::NEG_INFINITY, 1e-4).is_finite());
        assert!(t.substep(0.1, 0.0, f32::NAN).is_finite());
        let bad = Rx28 {
            resistance: -1.0,
            ..Rx28::LEO
        };
        assert!(!bad.is_valid());
    }

    #[test]
    fn back_emf_brakes_a_spinning_joint() {
        let m = Rx28::LEO;
        // 0 V, positive rate → negative torque (braking).
        assert!(m.estimate_joint_torque(0.0, 2.0) < 0.0);
        assert!(m.estimate_joint_torque(0.0, -2.0) > 0.0);
    }

    /// A link of inertia `inertia` about the joint, driven by the motor
    /// with +7 V for 50 ms and −7 V for 50 ms, no gravity: the tracker
    /// model at a GRL-like sub-step (1/5040 s) and the rigid-armature model
    /// (implicit in damping and armature, 1/240 s) must give the same joint
    /// angle at every 1/240 s. Returns the largest angle difference relative
    /// to the largest angle. (Rates are not compared sample by sample: the
    /// tracker rings at a few hundred Hz after each voltage step, with the
    /// light links lightly damped, ζ ≈ 0.16 at 1e-4 kg·m².)
    fn reversal_mismatch(inertia: f32, reduced: ReducedJoint) -> f32 {
        let m = Rx28::LEO;
        let voltage = |t: usize| if t < 12 { 7.0 } else { -7.0 };
        let fine = 21;
        let h = 1.0 / (240.0 * fine as f32);
        let mut t = Rx28Tracker::new(m);
        t.reset(0.0, 0.0);
        let (mut q, mut qd) = (0.0f32, 0.0f32);
        let h2 = 1.0 / 240.0;
        let (mut q2, mut qd2) = (0.0f32, 0.0f32);
        let (mut worst, mut largest) = (0.0f32, 0.0f32);
        for k in 0..24 {
            t.set_voltage(voltage(k));
            for _ in 0..fine {
                let tau = t.substep(q, qd, h);
                qd += h * tau / inertia;
                q += h * qd;
            }
            // (I + a + h·d)·qd⁺ = (I + a)·qd + h·τ_U
            qd2 = ((inertia + reduced.armature) * qd2 + h2 * reduced.voltage_torque(voltage(k)))
                / (inertia + reduced.armature + h2 * reduced.damping);
            q2 += h2 * qd2;
            worst = worst.max((q2 - q).abs());
            largest = largest.max(q.abs());
        }
        worst / largest
    }

    #[test]
    fn reduced_model_agrees_with_the_tracker_model() {
        let reduced = Rx28::LEO.reduced();
        for inertia in [1.0e-4f32, 1.0e-3, 1.0e-2] {
            let e = reversal_mismatch(inertia, reduced);
            assert!(e < 0.05, "I={inertia}: mismatch {e}");
            // The armature matters: without it the same check fails, so
            // the agreement above is not a property of any damped model.
            let e0 = reversal_mismatch(
                inertia,
                ReducedJoint {
                    armature: 0.0,
                    ..reduced
                },
            );
            assert!(e0 > 0.10, "I={inertia}: armature-free mismatch only {e0}");
        }
    }
}
