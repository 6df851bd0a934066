#[allow(dead_code)]
#[path = "../examples/era.rs"]
mod era;
use era::*;
use era::geometry::{Geometry, Structure};
use unfold::model::Model;

#[test]
fn soft() {
    for alpha in [15.0f64, 30.0, 45.0] {
        for r in [0.06, 0.12] {
            let mut d = design::Design::default();
            d.clocking = alpha.to_radians();
            d.clevis_radius = r;
            let g = Geometry::new(&d, Structure::Cell);
            let built = deploy::deployed(&g);
            let model = Model::from_input(&built.input).unwrap();
            let sol = checks::zero_modes(&model, 3).unwrap();
            println!("alpha {alpha} r {r}: {:?}", sol.modes.iter().map(|m| m.omega_squared).collect::<Vec<_>>());
        }
    }
}
