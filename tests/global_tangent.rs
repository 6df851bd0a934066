//! The assembled tangent equals central finite differences of the
//! assembled residual, on a model that mixes every element kind (beams on
//! an arc, a rigid body with an offset centre of mass under gravity,
//! translational, rotational and axial springs, dead and follower loads,
//! a panel of shells with an unsymmetric laminate under pressure)
//! with fixed dofs, in a deformed configuration with large rotations. This
//! checks the scatter maps and dof numbering on top of the element tests.
//!
//! Tolerance: 1e-6 of the largest tangent entry (central differences with
//! h = 1e-6 have a truncation error ~1e-10 and a round-off error ~1e-8
//! relative here).

mod common;

use unfold::analysis::newton::NewtonSolver;
use unfold::assembly::Assembler;
use unfold::dofs::DofMap;
use unfold::elements::{EvalContext, Need};
use unfold::linalg::SparseMatrix;
use unfold::model::input::*;
use unfold::model::Model;
use unfold::so3::Vec3;
use unfold::state::State;

/// A 2 × 2 panel of shells (an unsymmetric two-ply laminate, so that
/// every block of the shell's matrices is filled) beside the bend, under
/// a pressure, held at its corner node 500.
fn add_panel(m: &mut ModelInput, density: f64) {
    m.ply_materials.push(PlyMaterialInput {
        name: "sheet".into(),
        e: Some(1e7),
        nu: Some(0.3),
        density: Some(density),
        ..Default::default()
    });
    m.laminates.push(LaminateInput {
        name: "two plies".into(),
        plies: vec![
            PlyInput {
                material: "sheet".into(),
                thickness: 0.5,
                angle: None,
            },
            PlyInput {
                material: "sheet".into(),
                thickness: 0.2,
                angle: Some(0.7),
            },
        ],
        ..Default::default()
    });
    m.panels.push(PanelInput {
        name: "panel".into(),
        size: [10.0, 8.0],
        elements: [2, 2],
        laminate: "two plies".into(),
        origin: Some([0.0, -20.0, 0.0]),
        axis_a: Some([1.0, 0.2, 0.0]),
        axis_b: Some([0.0, 0.3, 1.0]),
        zones: Vec::new(),
        stiffeners: Vec::new(),
        pressure: Some(3.0),
        pressure_curve: None,
        first_node: Some(500),
        first_element: Some(500),
        node_ids: None,
    });
    m.fix(500, &["all"]);
}

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
        shape: None,
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
            damping: None,
            damping_ratio: None,
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
    add_panel(&mut m, 0.0);
    let model = Model::from_input(&m).unwrap();
    assert!(model
        .elements
        .iter()
        .any(|e| e.kind() == unfold::elements::ElementKind::Shell));

    // a deformed state with rotations of order one radian
    let mut state = model.initial_state();
    for i in 0..model.n_nodes() {
        let s = i as f64;
        let dx = Vec3::new(3.0 * s.sin(), 2.0 * s.cos(), 1.5 * s);
        state.displace_node(i, &dx, &Vec3::new(0.2 * s.sin(), -0.1 * s, 0.15 * s.cos()));
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
    let mut delta = vec![0.0; n];
    for j in 0..n {
        let mut columns = Vec::new();
        for sign in [1.0, -1.0] {
            // unknown j moved along the update rule
            let mut s = state.clone();
            delta[j] = sign * h;
            s.update(&solver.dofs, &delta);
            delta[j] = 0.0;
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

/// The bend of the test above with inertia on every element that has it:
/// beams with mass and rotational inertia per length and Rayleigh damping
/// (docs/theory.md §11.5), a rigid body with
/// its centre of mass off its node, a point mass, the springs, and a link
/// (a second beam) hinged to the tip by a revolute joint carrying a spring
/// and a damper, driven by a driver on the same hinge, and a panel of
/// shells with their consistent mass.
fn dynamic_model() -> Model {
    let mut m = common::example("bend_45.toml");
    m.sections[0].mass_per_length = Some(0.3);
    m.sections[0].inertia_per_length = Some([0.02, 0.01, 0.015]);
    m.sections[0].rayleigh_alpha = Some(0.5);
    m.sections[0].rayleigh_beta = Some(2e-3);
    m.rigid_bodies.push(RigidBodyInput {
        id: 100,
        node: 9,
        mass: 2.0,
        inertia: Some(InertiaInput::Diagonal([0.1, 0.2, 0.3])),
        center_of_mass: Some([1.0, -2.0, 0.5]),
        shape: None,
    });
    m.point_masses.push(PointMassInput {
        id: 101,
        node: 5,
        mass: 0.7,
    });
    m.gravity = Some(GravityInput {
        acceleration: [0.0, -9.81, -3.0],
        curve: None,
    });
    for (id, kind, nodes, k) in [
        (
            102,
            SpringKind::Translational,
            vec![5],
            StiffnessInput::PerAxis([10.0, 20.0, 30.0]),
        ),
        (
            103,
            SpringKind::Rotational,
            vec![3, 7],
            StiffnessInput::Isotropic(500.0),
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
            // dampers in parallel: their K and C blocks are checked too
            damping: Some(StiffnessInput::Isotropic(1.5)),
            damping_ratio: None,
        });
    }
    // the link: nodes 20 (at the tip) and 21, hinged to the tip about z
    m.add_node(20, [70.71067811865476, 29.28932188134524, 0.0]);
    m.add_node(21, [80.0, 35.0, 5.0]);
    m.add_beam(200, [20, 21], "square", Some([0.0, 0.0, 1.0]));
    m.joints.push(JointInput {
        id: 300,
        kind: unfold::joints::JointType::Revolute,
        nodes: vec![9, 20],
        axis: Some([0.0, 0.0, 1.0]),
        ..Default::default()
    });
    m.joint_springs.push(JointSpringInput {
        id: 301,
        joint: 300,
        stiffness: Some(40.0),
        damping: Some(3.0),
        ..Default::default()
    });
    m.drivers.push(DriverInput {
        id: 302,
        joint: Some(300),
        value: 0.3,
        ..Default::default()
    });
    m.add_load(4, [10.0, -20.0, 5.0], [100.0, 50.0, -80.0]);
    m.supports.push(SupportInput {
        node: 5,
        fixed: vec!["y".into(), "rz".into()],
    });
    add_panel(&mut m, 0.8);
    Model::from_input(&m).unwrap()
}

/// A deformed state of `model` with rotations of order one radian,
/// velocities, spins of tens of rad/s, accelerations and multipliers.
fn moving_state(model: &Model) -> State {
    let mut state = model.initial_state();
    for i in 0..model.n_nodes() {
        let s = i as f64;
        let dx = Vec3::new(3.0 * s.sin(), 2.0 * s.cos(), 1.5 * s);
        state.displace_node(i, &dx, &Vec3::new(0.2 * s.sin(), -0.1 * s, 0.15 * s.cos()));
        for c in 0..3 {
            let f = (s + c as f64).sin();
            state.velocity[i][c] = 5.0 * f;
            state.velocity[i][c + 3] = 30.0 * (1.3 * s - c as f64).cos();
            state.acceleration[i][c] = 80.0 * (0.7 * s + c as f64).cos();
            state.acceleration[i][c + 3] = 400.0 * f;
        }
    }
    for (k, l) in state.multipliers.iter_mut().enumerate() {
        *l = 0.01 * (k as f64 + 1.0);
    }
    model.apply_prescribed(&mut state, 0.7);
    state
}

/// Largest entry of a matrix, in magnitude.
fn largest(m: &SparseMatrix) -> f64 {
    m.values().iter().fold(0.0f64, |a, v| a.max(v.abs()))
}

/// Acceptance: assembling the stiffness K and the inertia matrix
/// D = γ′C + β′M of every element into two matrices (one evaluation of each
/// element, the split assembly of modal analysis) and adding them gives the
/// combined assembly (the iteration matrix of the integrator) to round-off:
/// each entry sums the same few element entries in another order, within
/// 1e-14 of the largest entry. The residual is the same, bit for bit, and
/// the inertia matrix is far from negligible.
#[test]
fn split_and_combined_assembly_agree() {
    let model = dynamic_model();
    let state = moving_state(&model);
    let dofs = DofMap::new(&model);
    let mut assembler = Assembler::new(&model, &dofs);
    // γ′ and β′ of a step h = 1e-2 with ρ∞ = 0.8
    let ctx = EvalContext {
        dynamics: true,
        ..model.context(0.7, Need::with_inertia(222.2, 24691.0))
    };
    let (mut k, mut d) = (assembler.matrix.clone(), assembler.matrix.clone());
    assembler.assemble_split(&model, &ctx, &state, &mut k, &mut d);
    let residual = assembler.residual.clone();
    assembler.assemble(&model, &ctx, &state);
    assert_eq!(assembler.residual, residual);
    let scale = largest(&k).max(largest(&d));
    let worst = assembler
        .matrix
        .values()
        .iter()
        .zip(k.values().iter().zip(d.values()))
        .fold(0.0f64, |w, (c, (k, d))| w.max((c - (k + d)).abs()));
    println!(
        "{} unknowns: |K + D − combined| ≤ {worst:.2e}, largest K {:.2e}, largest D {:.2e}",
        dofs.n_equations(),
        largest(&k),
        largest(&d)
    );
    assert!(worst <= 1e-14 * scale, "{worst:e} of {scale:e}");
    assert!(largest(&d) > 1e-3 * largest(&k));
}

/// The assembled matrices of the dynamic model against central finite
/// differences of the assembled residual with inertia forces: the
/// stiffness in q (along the update rule, h = 1e-6), the inertia matrix
/// with weights (1, 0) in the velocities and (0, 1) in the accelerations
/// (h = 0.1: the residual is quadratic in v and linear in v̇, so central
/// differences are exact but for round-off, which a large step keeps
/// small). Tolerance
/// 1e-6 of the largest entry of each, as for the static tangent above.
#[test]
fn assembled_dynamic_matrices_match_finite_differences() {
    let model = dynamic_model();
    let state = moving_state(&model);
    let dofs = DofMap::new(&model);
    let mut assembler = Assembler::new(&model, &dofs);
    let n = dofs.n_equations();
    let context = |need| EvalContext {
        dynamics: true,
        ..model.context(0.7, need)
    };
    let (mut k, mut c) = (assembler.matrix.clone(), assembler.matrix.clone());
    assembler.assemble_split(
        &model,
        &context(Need::with_inertia(1.0, 0.0)),
        &state,
        &mut k,
        &mut c,
    );
    let (mut k2, mut m) = (assembler.matrix.clone(), assembler.matrix.clone());
    assembler.assemble_split(
        &model,
        &context(Need::with_inertia(0.0, 1.0)),
        &state,
        &mut k2,
        &mut m,
    );
    assert_eq!(k.values(), k2.values());

    // the residual at a state moved by `h` along equation j's unknown
    let residual_ctx = context(Need::RESIDUAL);
    let mut column = |s: &State| {
        assembler.assemble(&model, &residual_ctx, s);
        (0..n)
            .map(|i| assembler.residual[dofs.dof(i)])
            .collect::<Vec<f64>>()
    };
    let mut delta = vec![0.0; n];
    let mut errors = [0.0f64; 3];
    for (which, matrix, h) in [(0, &k, 1e-6), (1, &c, 0.1), (2, &m, 0.1)] {
        let scale = largest(matrix);
        for j in 0..n {
            let dof = dofs.dof(j);
            let mut moved = |sign: f64| {
                let mut s = state.clone();
                match (which, dofs.node_component(dof)) {
                    (0, _) => {
                        delta[j] = sign * h;
                        s.update(&dofs, &delta);
                        delta[j] = 0.0;
                    }
                    (1, Some((node, comp))) => s.velocity[node][comp] += sign * h,
                    (2, Some((node, comp))) => s.acceleration[node][comp] += sign * h,
                    // multipliers have no rates
                    _ => {}
                }
                s
            };
            let (plus, minus) = (moved(1.0), moved(-1.0));
            let (rp, rm) = (column(&plus), column(&minus));
            for i in 0..n {
                let fd = (rp[i] - rm[i]) / (2.0 * h);
                let an = matrix.position(i, j).map_or(0.0, |p| matrix.values()[p]);
                errors[which] = errors[which].max((fd - an).abs() / scale);
            }
        }
    }
    println!(
        "{n} unknowns: errors of K, C, M against finite differences {:.2e}, {:.2e}, {:.2e}",
        errors[0], errors[1], errors[2]
    );
    assert!(errors.iter().all(|&e| e < 1e-6), "{errors:?}");
}
