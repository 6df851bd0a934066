//! The assembled tangent equals central finite differences of the
//! assembled residual, on a model that mixes every element kind (beams on
//! an arc, a rigid body with an offset centre of mass under gravity,
//! translational, rotational and axial springs, dead and follower loads)
//! with fixed dofs, in a deformed configuration with large rotations. This
//! checks the scatter maps and dof numbering on top of the element tests.
//!
//! Tolerance: 1e-6 of the largest tangent entry (central differences with
//! h = 1e-6 have a truncation error ~1e-10 and a round-off error ~1e-8
//! relative here).

mod common;

use unfold::analysis::newton::NewtonSolver;
use unfold::model::input::*;
use unfold::model::Model;
use unfold::so3::{self, Vec3};

#[test]
fn assembled_tangent_matches_finite_differences() {
    let mut m = common::example("bend_45.toml");
    m.sections[0].mass_per_length = Some(0.3);
    m.rigid_bodies.push(RigidBodyInput {
        id: 100,
        node: 9,
        mass: 2.0,
        inertia: Some(InertiaInput::Diagonal([0.1, 0.2, 0.3])),
        center_of_mass: Some([1.0, -2.0, 0.5]),
    });
    m.gravity = Some(GravityInput {
        acceleration: [0.0, -9.81, -3.0],
        curve: None,
    });
    for (id, kind, nodes, k) in [
        (
            101,
            SpringKind::Translational,
            vec![5],
            StiffnessInput::PerAxis([10.0, 20.0, 30.0]),
        ),
        (
            102,
            SpringKind::Rotational,
            vec![3, 7],
            StiffnessInput::Isotropic(500.0),
        ),
        (
            103,
            SpringKind::Rotational,
            vec![6],
            StiffnessInput::PerAxis([100.0, 200.0, 300.0]),
        ),
        (
            104,
            SpringKind::Axial,
            vec![2, 8],
            StiffnessInput::Isotropic(50.0),
        ),
    ] {
        m.springs.push(SpringInput {
            id,
            kind,
            nodes,
            stiffness: k,
        });
    }
    m.loads.push(LoadInput {
        node: 4,
        force: Some([10.0, -20.0, 5.0]),
        moment: Some([100.0, 50.0, -80.0]),
        follower: true,
        curve: None,
    });
    m.loads.push(LoadInput {
        node: 6,
        force: None,
        moment: Some([-30.0, 60.0, 90.0]),
        follower: false,
        curve: None,
    });
    m.supports.push(SupportInput {
        node: 5,
        fixed: vec!["y".into(), "rz".into()],
    });
    let model = Model::from_input(&m).unwrap();

    // a deformed state with rotations of order one radian
    let mut state = model.initial_state();
    for (i, (x, q)) in state.x.iter_mut().zip(state.q.iter_mut()).enumerate() {
        let s = i as f64;
        *x += Vec3::new(3.0 * s.sin(), 2.0 * s.cos(), 1.5 * s);
        *q *= so3::exp(&Vec3::new(0.2 * s.sin(), -0.1 * s, 0.15 * s.cos()));
    }
    model.apply_prescribed(&mut state, 0.7);

    let t = 0.7;
    let mut solver = NewtonSolver::new(&model);
    solver.assemble(&model, &state, t, true);
    let k = solver.tangent().clone();
    let scale = k.values().iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let n = solver.dofs.n_equations();
    let h = 1e-6;
    let mut worst = 0.0f64;
    for j in 0..n {
        let (node, c) = solver.dofs.node_component(solver.dofs.dof(j)).unwrap();
        let mut columns = Vec::new();
        for sign in [1.0, -1.0] {
            let mut s = state.clone();
            if c < 3 {
                s.x[node][c] += sign * h;
            } else {
                let mut d = Vec3::zeros();
                d[c - 3] = sign * h;
                s.q[node] *= so3::exp(&d);
            }
            solver.assemble(&model, &s, t, false);
            columns.push(solver.residual().to_vec());
        }
        for i in 0..n {
            let dof = solver.dofs.dof(i);
            let fd = (columns[0][dof] - columns[1][dof]) / (2.0 * h);
            let an = k.position(i, j).map_or(0.0, |p| k.values()[p]);
            worst = worst.max((fd - an).abs() / scale);
        }
    }
    println!("{n} unknowns: largest tangent error {worst:.2e} of the largest entry {scale:.2e}");
    assert!(worst < 1e-6, "{worst:e}");
}
