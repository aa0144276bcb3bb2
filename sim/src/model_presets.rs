//! Settings of the LEO model's options ([`crate::leo::model::ModelOptions`])
//! that the model's checks and step-size study share (`host/tests/`,
//! `host/examples/`), named once here.

use crate::leo::model::ModelOptions;

/// The lossless robot of the energy checks: the torso welded in place, no
/// contacts, no dry friction, no back-EMF, no joint stops — only the
/// limbs swinging under gravity (or not), so energy must be conserved.
pub fn lossless_fixed_torso(o: &mut ModelOptions) {
    o.fixed_torso = true;
    o.contacts = false;
    o.dry_friction = false;
    o.back_emf = false;
    o.joint_stops = false;
}

/// The servo bench of the motor-model checks: the torso welded, no
/// gravity, no contacts, no dry friction (back-EMF and the joint stops
/// stay), so a driven joint follows the RX-28 model alone.
pub fn servo_bench(o: &mut ModelOptions) {
    o.fixed_torso = true;
    o.gravity = false;
    o.contacts = false;
    o.dry_friction = false;
}
