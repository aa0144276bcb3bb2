//! Checks the vendored rapier's mass-matrix assembly (`vendor/rapier3d/PATCH.md`)
//! on LEO itself: the matrix rapier factorises must be Σ Jᵢᵀ·Mᵢ·Jᵢ plus the
//! armature, formed densely here from rapier's public body Jacobians and the
//! bodies' masses and world inertias, in a pose the robot moved into.

use rand_core::SeedableRng;
use rapier3d::na::{DMatrix, DVector, Matrix3};

use super::anatomy::InitialPose;
use super::test_drive::random_voltages;
use super::{LeoModel, ModelOptions};


#[test]
fn rapier_factorises_the_dense_joint_space_mass_matrix() {
    let mut model = LeoModel::new(ModelOptions::default(), &InitialPose::REFERENCE).unwrap();
    let mut rng = rand_pcg::Pcg32::seed_from_u64(7);
    // Random voltages for a few control periods: bent joints, a pitched
    // torso, every body moving, so that no Jacobian column is trivial.
    for _ in 0..6 {
        model.set_voltages(random_voltages(&mut rng));
        model.control_step().unwrap();
    }
    let world = &mut model.world;
    let mb = world.multibody_joints.get_multibody_mut(model.multibody).unwrap();
    // Re-runs the forward kinematics and assembles M + armature (dt = 0).
    mb.dof_inverse_inertia(&world.bodies);
    let n = mb.ndofs();

    let mut dense = DMatrix::<f32>::zeros(n, n);
    for (i, link) in mb.links().enumerate() {
        let rb = &world.bodies[link.rigid_body_handle()];
        let mass = rb.mass_properties().effective_mass();
        // A symmetric 3 × 3 matrix (parry's `SdpMatrix3`, upper triangle).
        let s = rb.mass_properties().effective_angular_inertia();
        let inertia = Matrix3::new(s.m11, s.m12, s.m13, s.m12, s.m22, s.m23, s.m13, s.m23, s.m33);
        let j = mb.body_jacobian(i);
        let (j_v, j_w) = (j.fixed_rows::<3>(0), j.fixed_rows::<3>(3));
        let m_j_v = DMatrix::from_fn(3, n, |r, c| [mass.x, mass.y, mass.z][r] * j_v[(r, c)]);
        dense += j_v.transpose() * m_j_v + j_w.transpose() * (inertia * j_w);
    }
    for k in 0..n {
        dense[(k, k)] += mb.armature()[k];
    }
    assert!(dense.iter().all(|x| x.is_finite()));
    // Off-diagonal coupling is present (a leg's joints move the torso).
    assert!(dense[(0, n - 1)].abs() > 1e-6 || dense[(3, n - 1)].abs() > 1e-6);

    // rapier's factorisation inverts exactly this matrix: A⁻¹·(A·eₖ) = eₖ.
    for k in 0..n {
        let mut column: DVector<f32> = dense.column(k).into_owned();
        assert!(mb.inv_augmented_mass().solve_mut(&mut column));
        for r in 0..n {
            let expected = if r == k { 1.0 } else { 0.0 };
            assert!(
                (column[r] - expected).abs() < 2e-3,
                "DoF {k}: entry {r} of A⁻¹·A·e is {} (expected {expected})",
                column[r]
            );
        }
    }
}
/// The patched assembly against upstream's own (kept in the vendored crate
/// as the oracle), both matrices, over 2 s of random voltages: equal to
/// rounding, including the gyroscopic and Coriolis part, which must be
/// present for the comparison to mean anything. (LEO moves in a plane, so
/// the terms of out-of-plane rotation are zero in both and not compared:
/// flipping the sign of the joint-rate term is invisible here, flipping the
/// centre-of-mass shift term fails.)
#[test]
fn the_patched_mass_matrices_equal_upstreams() {
    let mut model = LeoModel::new(ModelOptions::default(), &InitialPose::REFERENCE).unwrap();
    let mut rng = rand_pcg::Pcg32::seed_from_u64(11);
    let dt = model.options.dt();
    let mut largest_coriolis = 0.0f32;
    for step in 0..60 {
        model.set_voltages(random_voltages(&mut rng));
        if model.control_step().is_err() {
            break;
        }
        let world = &mut model.world;
        let mb = world.multibody_joints.get_multibody_mut(model.multibody).unwrap();
        let [augmented, accelerations, scale, coriolis] = mb.mass_matrices_against_upstream(dt, &world.bodies);
        largest_coriolis = largest_coriolis.max(coriolis);
        assert!(
            augmented <= 1e-6 * scale && accelerations <= 1e-6 * scale,
            "control step {step}: the patched matrices differ from upstream's by {augmented:e} and \
             {accelerations:e} (largest entry {scale:e})"
        );
    }
    assert!(largest_coriolis > 1e-3, "the gyroscopic and Coriolis part was never exercised");
}
