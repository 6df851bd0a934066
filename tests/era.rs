//! The ERA cell of examples/era.rs (paper §6.2) deployed in dynamics by
//! the tape springs of its six mid-hinges: every latch locks, at its
//! locking angle, one after the other.

#[allow(dead_code)]
#[path = "../examples/era.rs"]
mod era;

use std::f64::consts::PI;

use era::deploy;
use era::design::Design;
use era::geometry::{Geometry, Structure};

#[test]
fn cell_deploys_and_every_mid_hinge_locks() {
    let geometry = Geometry::new(&Design::default(), Structure::Cell);
    let built = deploy::model(&geometry, &era::case(Structure::Cell, 0.0));
    let nominal = deploy::nominal(&geometry).unwrap();
    let run = deploy::run(&built, &nominal, None, 0.1, false).unwrap();
    assert!(run.outcome.error.is_none(), "{:?}", run.outcome.error);
    let f = &run.figures;

    // every one of the six mid-hinges locks within the span
    assert_eq!(f.locks.len(), 6);
    for (k, t) in f.locks.iter().enumerate() {
        assert!(
            t.is_some(),
            "mid-hinge {} did not lock: {:?}",
            k + 1,
            f.locks
        );
    }
    // at the lock the halves are in line: the opening angle is π within
    // the event tolerance of the latches (1e-8 rad, docs/joints.md §6.2)
    // and stays there (the rigid lock holds it to the constraint
    // tolerance, 1e-6 rad by default)
    for lock in &run.outcome.locks {
        let hinge = built
            .parts
            .hinges()
            .find(|h| h.latch.map(|l| l.id()) == Some(lock.latch))
            .unwrap();
        assert!(
            (lock.coordinate - hinge.locking_angle()).abs() <= 1e-8,
            "latch {} locked at {} instead of {}",
            lock.latch,
            lock.coordinate,
            hinge.locking_angle()
        );
    }
    let last = run.records.last().unwrap();
    for h in &last.hinges {
        assert!(h.locked);
        assert!((h.opening - PI).abs() < 1e-5, "opening {}", h.opening);
    }
    // the hinges do not lock at the same instant: the cell is clamped at
    // one longeron, so its faces are not alike
    let mut times: Vec<f64> = f.locks.iter().flatten().copied().collect();
    times.sort_by(f64::total_cmp);
    assert!(times.windows(2).all(|w| w[1] - w[0] > 1e-3), "{times:?}");
    // each lock is a plastic impact: it takes energy out (docs/joints.md
    // §6.2), and the energy it takes is bounded by the work of the tape
    // springs, M_d over the travel of six hinges
    let travel = built.parts.hinges().next().unwrap().locking_angle();
    let work = 6.0 * geometry.design.hinge.deployment_energy(travel);
    assert!(f.impact_loss > 0.0 && f.impact_loss < work);
    // the springs' work, summed by the trapezoidal rule over the steps,
    // is that closed form up to the step that reaches the lock, across
    // which the moment falls from M_d to 0: at most ½ M_d ċ h per hinge,
    // ½·0.2·20 rad/s·0.01 s against M_d·2.94 rad, 3.4 %
    assert!(
        (last.spring_work - work).abs() < 0.034 * work,
        "{} vs {work}",
        last.spring_work
    );
}

/// The platform's plan: a hexagon of side two cell widths on the
/// triangular lattice holds `6 n²` = 24 triangular cells, `3n² + 3n + 1`
/// = 19 longerons and `(3·24 + 6·2)/2` = 42 faces (each inner face shared
/// by two cells, the 12 of the outline by one), as paper figure 5 shows.
#[test]
fn platform_layout_is_the_hexagon_of_24_cells() {
    let layout = era::geometry::Layout::new(Structure::PLATFORM, 1.0);
    assert_eq!(layout.cells.len(), 24);
    assert_eq!(layout.columns.len(), 19);
    assert_eq!(layout.faces.len(), 42);
    assert_eq!(layout.faces.iter().filter(|f| f.boundary).count(), 12);
    // every cell is an equilateral triangle of the cell side
    for cell in &layout.cells {
        for k in 0..3 {
            let (a, b) = (layout.columns[cell[k]], layout.columns[cell[(k + 1) % 3]]);
            assert!(((a[0] - b[0]).hypot(a[1] - b[1]) - 1.0).abs() < 1e-12);
        }
    }
}
