//! Checks the vendored rapier's skipped forward kinematics
//! (`Multibody::forward_kinematics_if_changed`, `vendor/rapier3d/PATCH.md`)
//! on LEO itself: whenever a step would skip it, the link poses and body
//! Jacobians already there are, bit for bit, those a fresh forward
//! kinematics computes; and a joint moved or re-framed between steps makes
//! it run. And the body Jacobians' shifts and the accelerations' `Jᵀ·f`,
//! formed over each link's DoFs only, equal upstream's dense products.

use rand_core::SeedableRng;
use rapier3d::dynamics::Multibody;
use rapier3d::math::Vector;

use super::anatomy::InitialPose;
use super::test_drive::random_voltages;
use super::{LeoModel, ModelOptions, NUM_JOINTS};


/// Whether two multibodies hold the same link poses and body Jacobians,
/// bit for bit.
fn same_kinematics(a: &Multibody, b: &Multibody) -> bool {
    let bits = |m: &Multibody| -> Vec<u32> {
        let mut out = Vec::new();
        for (i, link) in m.links().enumerate() {
            let p = link.local_to_world();
            out.extend([p.translation.x, p.translation.y, p.translation.z].map(f32::to_bits));
            out.extend([p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w].map(f32::to_bits));
            out.extend(m.body_jacobian(i).iter().map(|x| x.to_bits()));
        }
        out
    };
    bits(a) == bits(b)
}

#[test]
fn a_skipped_forward_kinematics_leaves_what_a_fresh_one_computes() {
    let mut model = LeoModel::new(ModelOptions::default(), &InitialPose::REFERENCE).unwrap();
    let mut rng = rand_pcg::Pcg32::seed_from_u64(5);
    let mut skipped = 0;
    for step in 0..40 {
        model.set_voltages(random_voltages(&mut rng));
        if model.control_step().is_err() {
            break;
        }
        let world = &mut model.world;
        let mb = world.multibody_joints.get_multibody_mut(model.multibody).unwrap();
        let mut fresh = mb.clone();
        fresh.forward_kinematics(&world.bodies, true);
        if !mb.forward_kinematics_if_changed(&world.bodies, true) {
            skipped += 1;
            assert!(same_kinematics(mb, &fresh), "control step {step}: the skipped kinematics differ from a fresh one");
        }
    }
    assert!(skipped >= 30, "only {skipped} of 40 control steps skipped the forward kinematics");
}

#[test]
fn a_joint_moved_or_reframed_between_steps_is_seen() {
    let mut model = LeoModel::new(ModelOptions::default(), &InitialPose::REFERENCE).unwrap();
    model.set_voltages([3.0; NUM_JOINTS]);
    model.control_step().unwrap();
    let knee = model.dofs[3];
    let link = model.links[3];
    let world = &mut model.world;
    let mb = world.multibody_joints.get_multibody_mut(model.multibody).unwrap();
    assert!(!mb.forward_kinematics_if_changed(&world.bodies, true), "nothing changed, yet it ran");

    // A coordinate: the poses follow.
    let before = *mb.link(link).unwrap().local_to_world();
    let mut displacement = vec![0.0f32; mb.ndofs()];
    displacement[knee] = 0.1;
    mb.apply_displacements(&displacement);
    assert!(mb.forward_kinematics_if_changed(&world.bodies, true), "a moved joint was not seen");
    assert_ne!(*mb.link(link).unwrap().local_to_world(), before);
    assert!(!mb.forward_kinematics_if_changed(&world.bodies, true));

    // A joint frame, through the mutable link.
    let frame = mb.link(link).unwrap().joint.data.local_frame1;
    let mut moved = frame;
    moved.translation += Vector::new(0.0, 0.0, 0.01);
    mb.link_mut(link).unwrap().joint.data.set_local_frame1(moved);
    let mut fresh = mb.clone();
    fresh.forward_kinematics(&world.bodies, true);
    assert!(mb.forward_kinematics_if_changed(&world.bodies, true), "a re-framed joint was not seen");
    assert!(same_kinematics(mb, &fresh));
}

/// The body Jacobians' shifts and the accelerations' `Jᵀ·f`, which the
/// vendored rapier forms over each link's DoFs only, equal upstream's dense
/// products bit for bit, in every pose of a random-voltage run.
#[test]
fn the_jacobian_products_over_each_links_dofs_equal_upstreams() {
    let mut model = LeoModel::new(ModelOptions::default(), &InitialPose::REFERENCE).unwrap();
    let mut rng = rand_pcg::Pcg32::seed_from_u64(9);
    for step in 0..40 {
        let voltages = random_voltages(&mut rng);
        model.set_voltages(voltages);
        if model.control_step().is_err() {
            break;
        }
        let mb = model.world.multibody_joints.get_multibody_mut(model.multibody).unwrap();
        let force = [voltages[0], -voltages[1], voltages[2], 0.5 * voltages[3], voltages[4], -voltages[5]];
        assert!(mb.jacobian_products_match_upstream(force), "control step {step}: the patched products differ");
    }
}
