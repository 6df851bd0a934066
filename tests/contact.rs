//! Unilateral contacts (src/joints/stop.rs, src/analysis/impact.rs,
//! docs/joints.md §6.4, docs/theory.md §16.5): a ball dropped on a plane
//! (the impact law, the loss of each impact, rest in persistent contact
//! without chattering, penetration), a ball dropped on a tilted plane
//! (the normal rate reversed, the tangential velocity kept, then sliding),
//! the release of a contact, two spheres colliding head-on (momentum, the
//! relative rate reversed), the results and events files, and the input
//! errors of `[[contacts]]`.

use std::sync::Arc;

use unfold::analysis::{
    AnalysisSettings, ContactInfo, ContactKind, DynamicAnalysis, DynamicOutcome, IncrementInfo,
    Observer,
};
use unfold::model::input::ModelInput;
use unfold::model::Model;
use unfold::so3::Vec3;
use unfold::state::State;

const G: f64 = 9.81;
const MASS: f64 = 2.0;
const RADIUS: f64 = 0.1;

/// The event tolerance of a length in a model of one node (length scale
/// 1 m): 1e-8 m (docs/joints.md §6.3).
const GAP_TOLERANCE: f64 = 1e-8;

/// Every accepted state and every event of a contact.
#[derive(Default)]
struct Record {
    steps: Vec<(IncrementInfo, State)>,
    contacts: Vec<ContactInfo>,
}

impl Observer for Record {
    fn increment(
        &mut self,
        info: &IncrementInfo,
        _: &Model,
        state: &State,
        _: &[f64],
    ) -> std::io::Result<()> {
        self.steps.push((info.clone(), state.clone()));
        Ok(())
    }
    fn contact(&mut self, info: &ContactInfo) {
        self.contacts.push(info.clone());
    }
}

fn parse(text: &str) -> (Arc<Model>, Vec<AnalysisSettings>) {
    let input: ModelInput = toml::from_str(text).expect("valid toml");
    let model = Model::from_input(&input).expect("valid model");
    (Arc::new(model), input.analyses().expect("valid analyses"))
}

fn run(text: &str) -> (Arc<Model>, DynamicOutcome, Record) {
    let (model, analyses) = parse(text);
    let settings = analyses[0].as_dynamic().unwrap().clone();
    let mut a = DynamicAnalysis::new(model.clone(), settings);
    let mut record = Record::default();
    let out = a.run(model.initial_state(), &mut record);
    assert!(out.error.is_none(), "{:?}", out.error);
    (model, out, record)
}

/// A ball of radius 0.1 m and mass 2 kg (a rigid body, inertia
/// 2/5 m r²) on the free node 1 at `x`, under gravity −z, with the
/// contact `contact` and the tables `extra`.
fn ball(end_time: f64, x: [f64; 3], contact: &str, extra: &str) -> String {
    let j = 0.4 * MASS * RADIUS * RADIUS;
    format!(
        r#"
[analysis]
type = "dynamic"
end_time = {end_time}
time_step = 0.01

[[nodes]]
id = 1
x = [{}, {}, {}]

[[rigid_bodies]]
id = 1
node = 1
mass = {MASS}
inertia = [{j}, {j}, {j}]

[[contacts]]
id = 30
{contact}

[gravity]
acceleration = [0.0, 0.0, -{G}]
curve = "constant"
{extra}
"#,
        x[0], x[1], x[2]
    )
}

/// The contact of the model.
fn contact(model: &Model) -> &unfold::joints::Stop {
    model
        .elements
        .iter()
        .find_map(|e| e.as_stop())
        .expect("a contact")
}

/// The contact force `N`, `force` of the contact's results.
fn force(model: &Model, state: &State) -> f64 {
    let ctx = model.context(state.time, unfold::elements::Need::RESIDUAL);
    contact(model).load(&ctx, state)
}

fn translation(s: &State, node: usize) -> Vec3 {
    let v = s.velocity[node];
    Vec3::new(v[0], v[1], v[2])
}

/// The bouncing ball on a plane z = 0 (the sphere's gap is its height
/// minus its radius). Dropped with its lowest point 1 m above the plane,
/// it hits it at t₁ = √(2h/g) with v₀ = √(2gh); each impact returns e
/// times the approach rate (Newton's law, docs/theory.md §16.4) and
/// dissipates (1 − e²) ½ m v⁻² (LK3e; the ball does not spin: the contact
/// force passes through its centre). The rebounds accumulate at
/// t∞ = t₁ + (2 e v₀/g)/(1 − e); once a rebound would be below
/// v_min = √(2 g_tol g) the contact closes and holds the weight.
#[test]
fn a_ball_bounces_on_a_plane_and_comes_to_rest() {
    let e = 0.5;
    let h = 1.0;
    let (model, out, rec) = run(&ball(
        2.0,
        [0.0, 0.0, h + RADIUS],
        &format!(
            "type = \"plane\"\nnode = 1\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\nradius = {RADIUS}\nrestitution = {e}"
        ),
        "",
    ));
    let v0 = (2.0 * G * h).sqrt();
    let t1 = (2.0 * h / G).sqrt();
    for c in &rec.contacts {
        eprintln!(
            "{:?} at t = {:.10}: rate {:.6e} -> {:.6e}, energy lost {:.6e}",
            c.kind, c.time, c.rate_before, c.rate_after, c.energy_lost
        );
    }
    eprintln!(
        "{} steps, {} retried to land on the events",
        out.steps, out.event_retries
    );
    let impacts: Vec<&ContactInfo> = rec
        .contacts
        .iter()
        .filter(|c| c.kind == ContactKind::Impact)
        .collect();
    assert!(impacts.len() >= 5, "{}", impacts.len());
    for c in &rec.contacts {
        // events.csv: the contact, no joint
        assert_eq!(c.stop, 30);
        assert_eq!(c.joint, None);
    }
    // the first impact: time and rate of the free fall (1e-6 relative:
    // the integration's error over the fall)
    assert!(
        (impacts[0].time - t1).abs() <= 1e-6 * t1,
        "{}",
        impacts[0].time
    );
    assert!(
        (impacts[0].rate_before + v0).abs() <= 1e-6 * v0,
        "{}",
        impacts[0].rate_before
    );
    for c in &impacts {
        // Newton's impact law: ġ⁺ = −e ġ⁻ (1e-6 relative, as asked of the
        // rebound)
        assert!(
            (c.rate_after + e * c.rate_before).abs() <= 1e-6 * c.rate_before.abs(),
            "{c:?}"
        );
        // the loss (1 − e²) ½ m v⁻² of the approach's kinetic energy, to
        // round-off (1e-10 relative)
        let loss = (1.0 - e * e) * 0.5 * MASS * c.rate_before.powi(2);
        assert!((c.energy_lost - loss).abs() <= 1e-10 * loss, "{c:?}");
        assert!(
            (c.kinetic_energy_drop - loss).abs() <= 1e-10 * loss,
            "{c:?}"
        );
        // landed on the plane within the event tolerance
        assert!(c.coordinate.abs() <= GAP_TOLERANCE, "{c:?}");
        // the impulse pushes the ball up: m (1 + e) |v⁻| (1e-10)
        let p = MASS * (1.0 + e) * c.rate_before.abs();
        assert!((c.impulse - p).abs() <= 1e-10 * p, "{c:?}");
    }
    // rest without chattering: the rebounds stop once they would be
    // slower than v_min or would not rise above g_tol from where the step
    // landed (docs/theory.md §16.4: log(v₀/v_min)/log(1/e) = 13.3, at
    // most 15 events), then one contact and nothing more
    let v_min = (2.0 * GAP_TOLERANCE * G).sqrt();
    assert!(rec.contacts.len() <= 15, "{}", rec.contacts.len());
    let last = rec.contacts.last().unwrap();
    assert_eq!(last.kind, ContactKind::Close);
    let rebound = e * last.rate_before.abs();
    let top = last.coordinate + rebound * rebound / (2.0 * G);
    assert!(rebound <= v_min || top <= GAP_TOLERANCE, "{rebound} {top}");
    // an impact keeps the ball open only with a rebound above both
    for c in &impacts {
        let rebound = c.rate_after;
        assert!(rebound > v_min && c.coordinate + rebound * rebound / (2.0 * G) > GAP_TOLERANCE);
    }
    // it closes at t∞ (the sum of the flights) within the flights cut
    // off: a rebound cut off is below v_cut = √(2 g · 2 g_tol) (a top
    // below g_tol from a landing at −g_tol at worst), and the flights it
    // would have begun last 2 v_cut/(g (1 − e)) ≈ 2.6e-4 s at most
    let t_rest = t1 + 2.0 * e * v0 / G / (1.0 - e);
    let v_cut = (4.0 * G * GAP_TOLERANCE).sqrt();
    let cut = 2.0 * v_cut / (G * (1.0 - e));
    eprintln!("closed at {}, t∞ = {t_rest}, bound {cut:.3e} s", last.time);
    assert!((last.time - t_rest).abs() <= cut, "{} {t_rest}", last.time);
    // penetration: no accepted state below −g_tol (the event tolerance)
    let c = contact(&model);
    let worst = rec
        .steps
        .iter()
        .fold(0.0f64, |m, (_, s)| m.max(-c.coordinate(s)));
    eprintln!("largest penetration {worst:.3e} m");
    assert!(worst <= GAP_TOLERANCE);
    // at rest: the contact force is the weight (1e-8 relative, the
    // constraint's convergence), the ball stays where it closed
    let after: Vec<_> = rec
        .steps
        .iter()
        .filter(|(i, _)| i.time > last.time)
        .collect();
    assert!(after.len() > 10, "{}", after.len());
    for (i, s) in after {
        let n = force(&model, s);
        assert!(
            (n - MASS * G).abs() <= 1e-8 * MASS * G,
            "t = {}: {n}",
            i.time
        );
        assert!(s.velocity[0][2].abs() <= 1e-8, "t = {}", i.time);
        assert!((c.coordinate(s) - last.coordinate).abs() <= 1e-12);
        assert!(c.coordinate(s).abs() <= GAP_TOLERANCE);
    }
    // the energy balance holds through the impacts (1e-6 of m g h)
    assert!(out.energies.balance_error.abs() <= 1e-6 * MASS * G * h);
}
