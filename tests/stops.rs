//! Unilateral stops (src/joints/stop.rs, src/analysis/impact.rs,
//! docs/joints.md §6.3, docs/theory.md §16.4): a ball on a vertical slider
//! dropped on a stop (the bouncing ball: flight times, rebound heights,
//! the loss of each impact, rest in persistent contact), a ball shuttling
//! between two stops with e = 1, a hinged bar falling on a stop (the
//! impact law of a rotation with the hinge's constraints active), the
//! release of a contact, and the input errors of `[[stops]]`.

mod common;

use common::events::{error_of, run, Record};
use common::pendulum;
use unfold::analysis::{ContactInfo, ContactKind};
use unfold::model::input::ModelInput;
use unfold::model::Model;
use unfold::state::State;

const G: f64 = common::ball::G;
const MASS: f64 = common::ball::MASS;

/// A point mass on node 1 at the origin, on a prismatic joint to the
/// ground along z (its `slide` is the height), under gravity −z
/// (tests/common/ball.rs), with the stop `stop` and the tables `extra`.
fn ball(end_time: f64, stop: &str, extra: &str) -> String {
    common::ball::dropped(
        end_time,
        &format!(
            r#"[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[point_masses]]
id = 1
node = 1
mass = {MASS}

[[joints]]
id = 10
type = "prismatic"
nodes = [1]
axis = [0.0, 0.0, 1.0]
position = [0.0, 0.0, 0.0]

[[stops]]
id = 20
joint = 10
{stop}"#
        ),
        extra,
    )
}

/// The stop's gap at every accepted state (`gap` of its results).
fn gaps(model: &Model, rec: &Record) -> Vec<(f64, f64)> {
    let e = model
        .elements
        .iter()
        .find(|e| e.as_stop().is_some())
        .unwrap();
    let stop = e.as_stop().unwrap();
    rec.steps
        .iter()
        .map(|(i, s)| (i.time, stop.gap(s).0))
        .collect()
}

/// The contact load of the stop, `load` of its results.
fn load(model: &Model, state: &State) -> f64 {
    let e = model
        .elements
        .iter()
        .find(|e| e.as_stop().is_some())
        .unwrap();
    let ctx = model.context(state.time, unfold::elements::Need::RESIDUAL);
    e.as_stop().unwrap().load(&ctx, state)
}

/// The event tolerance of a length in a model of one node at the origin
/// (length scale 1 m): 1e-8 m (docs/joints.md §6.3).
const GAP_TOLERANCE: f64 = 1e-8;

/// The bouncing ball. Dropped from h = 1 m above the stop, it hits it at
/// t₁ = √(2h/g) with v₀ = √(2gh); each impact returns e times the
/// approach rate, so the flights last T_k = 2 e^k v₀/g (ratio e) and rise
/// to h_k = g T_k²/8 (ratio e²), and the impacts accumulate at
/// t∞ = t₁ + (2 e v₀/g)/(1 − e) (the sum of the flights). Each impact
/// dissipates (1 − e²) ½ m v⁻² (docs/theory.md §16, LK3 with restitution).
/// When the rebound rate falls below v_min = √(2 g_tol g) (4.4e-4 m/s) the
/// stop closes: a persistent contact whose load is the weight m g.
#[test]
fn a_ball_bounces_on_a_stop_and_comes_to_rest() {
    let e = 0.5;
    let (model, out, rec) = run(&ball(2.0, "lower = -1.0\nrestitution = 0.5", ""));
    let h = 1.0;
    let v0 = (2.0 * G * h).sqrt();
    let t1 = (2.0 * h / G).sqrt();
    let impacts: Vec<&ContactInfo> = rec
        .contacts
        .iter()
        .filter(|c| c.kind == ContactKind::Impact)
        .collect();
    for c in &rec.contacts {
        eprintln!(
            "{:?} at t = {:.10}: rate {:.6e} -> {:.6e}, energy lost {:.6e}",
            c.kind, c.time, c.rate_before, c.rate_after, c.energy_lost
        );
    }
    eprintln!(
        "{} steps, {} retried to land on the events, {} rejected by the error estimate",
        out.steps, out.event_retries, out.error_rejections
    );
    // the first impact: time and rate of the free fall (1e-6)
    assert!((impacts[0].time - t1).abs() <= 1e-6 * t1);
    assert!((impacts[0].rate_before + v0).abs() <= 1e-6 * v0);
    for c in &impacts {
        // the impact law: ċ⁺ = −e ċ⁻ (1e-6 relative)
        assert!(
            (c.rate_after + e * c.rate_before).abs() <= 1e-6 * c.rate_before.abs(),
            "{c:?}"
        );
        // the loss, (1 − e²) ½ m v⁻², to round-off (1e-10)
        let loss = (1.0 - e * e) * 0.5 * MASS * c.rate_before.powi(2);
        assert!((c.energy_lost - loss).abs() <= 1e-10 * loss, "{c:?}");
        // landed on the stop within the event tolerance
        assert!((c.coordinate + 1.0).abs() <= GAP_TOLERANCE);
    }
    // successive flights: T_{k+1}/T_k = e, h_{k+1}/h_k = e² (1e-6), over
    // the first four (T ≥ 0.056 s): an impact is landed within
    // g_tol/v in time, which is 2.6e-6 of the fifth flight (0.028 s)
    let flights: Vec<f64> = impacts.windows(2).map(|w| w[1].time - w[0].time).collect();
    for k in 0..4 {
        let (ta, tb) = (flights[k], flights[k + 1]);
        let (ha, hb) = (G * ta * ta / 8.0, G * tb * tb / 8.0);
        assert!((tb / ta - e).abs() <= 1e-6, "flight {k}: {}", tb / ta);
        assert!((hb / ha - e * e).abs() <= 1e-6, "height {k}: {}", hb / ha);
    }
    assert!((flights[0] - 2.0 * e * v0 / G).abs() <= 1e-6 * flights[0]);

    // at rest: the impacts stop once the rebound would be below v_min
    // (log(v₀/v_min)/log(1/e) = 13.3: at most 15 events), then one
    // contact and nothing more
    let v_min = (2.0 * GAP_TOLERANCE * G).sqrt();
    assert!(rec.contacts.len() <= 15, "{}", rec.contacts.len());
    let last = rec.contacts.last().unwrap();
    assert_eq!(last.kind, ContactKind::Close);
    assert!(e * last.rate_before.abs() <= v_min);
    assert_eq!(last.rate_after, 0.0);
    // it closes at t∞ (the sum of the flights), within the flights left
    // out, shorter than 2 v_min/(g (1 − e)) ≈ 2e-4 s
    let t_rest = t1 + 2.0 * e * v0 / G / (1.0 - e);
    assert!((last.time - t_rest).abs() <= 2e-4, "{} {t_rest}", last.time);
    // penetration: every accepted state within the event tolerance
    let worst = gaps(&model, &rec)
        .iter()
        .fold(0.0f64, |m, &(_, g)| m.max(-g));
    eprintln!("largest penetration {worst:.3e} m");
    assert!(worst <= GAP_TOLERANCE);
    // the contact holds the weight at every step after it closed (1e-8
    // relative: the constraint's convergence) and the ball stays on the
    // stop, at rest
    let after: Vec<_> = rec
        .steps
        .iter()
        .filter(|(i, _)| i.time > last.time)
        .collect();
    eprintln!(
        "{} steps at rest; contact load at the end {} (weight {})",
        after.len(),
        load(&model, &after.last().unwrap().1),
        MASS * G
    );
    assert!(!after.is_empty());
    for (i, s) in after {
        let n = load(&model, s);
        assert!(
            (n - MASS * G).abs() <= 1e-8 * MASS * G,
            "t = {}: {n}",
            i.time
        );
        assert!(s.velocity[0][2].abs() <= 1e-8, "t = {}", i.time);
        assert!(
            (s.x[0].z - last.coordinate).abs() <= 1e-12,
            "t = {}",
            i.time
        );
    }
    // the energy balance holds through the impacts
    assert!(out.energies.balance_error.abs() <= 1e-6 * MASS * G * h);
}

/// e = 0: the first impact closes the stop; it dissipates the whole
/// kinetic energy ½ m v₀² (to round-off) and the load is the weight.
#[test]
fn a_plastic_stop_closes_at_the_first_impact() {
    let (model, _, rec) = run(&ball(0.8, "lower = -1.0", ""));
    let v0 = (2.0 * G).sqrt();
    assert_eq!(rec.contacts.len(), 1, "{:?}", rec.contacts);
    let c = &rec.contacts[0];
    assert_eq!(c.kind, ContactKind::Close);
    let loss = 0.5 * MASS * c.rate_before.powi(2);
    assert!((c.rate_before + v0).abs() <= 1e-6 * v0);
    assert!((c.energy_lost - loss).abs() <= 1e-10 * loss);
    // the impulse stops the ball: m v⁻ (1e-10)
    assert!((c.impulse - MASS * v0).abs() <= 1e-6 * MASS * v0);
    for (_, s) in rec.steps.iter().filter(|(i, _)| i.time > c.time) {
        assert!((load(&model, s) - MASS * G).abs() <= 1e-8 * MASS * G);
    }
}

/// No gravity, e = 1: the ball shuttles between the stops at −0.25 and
/// +0.25 with its speed v = 1 m/s; impacts every 0.5 s from t = 0.25
/// (first at the upper stop), energy kept (loss 0, to round-off).
#[test]
fn an_elastic_ball_shuttles_between_two_stops() {
    let text = ball(
        1.9,
        "lower = -0.25\nupper = 0.25\nrestitution = 1.0",
        "[[initial_motion]]\nnodes = [1]\nvelocity = [0.0, 0.0, 1.0]\n",
    )
    .replace(
        "[gravity]\nacceleration = [0.0, 0.0, -9.81]\ncurve = \"constant\"\n",
        "",
    );
    let (_, out, rec) = run(&text);
    let times: Vec<f64> = rec.contacts.iter().map(|c| c.time).collect();
    eprintln!("impacts at {times:?}; {} steps", out.steps);
    assert_eq!(rec.contacts.len(), 4, "{:?}", rec.contacts);
    for (k, c) in rec.contacts.iter().enumerate() {
        assert_eq!(c.kind, ContactKind::Impact);
        // constant speed between the stops: t_k = 0.25 + 0.5 k (1e-8,
        // the event tolerance over the speed)
        assert!((c.time - (0.25 + 0.5 * k as f64)).abs() <= 1e-7, "{c:?}");
        let upper = k % 2 == 0;
        let limit = if upper { 0.25 } else { -0.25 };
        assert!((c.coordinate - limit).abs() <= GAP_TOLERANCE);
        assert!((c.rate_before.abs() - 1.0).abs() <= 1e-8);
        assert!((c.rate_after + c.rate_before).abs() <= 1e-12);
        assert!(c.energy_lost.abs() <= 1e-12);
        // the impulse pushes back into the range: 2 m v
        assert!((c.impulse - 2.0 * MASS).abs() <= 1e-8, "{c:?}");
    }
}

/// A bar hinged to the ground at its end (node 1 fixed, revolute about z
/// at the origin; its centre of mass, node 2, at distance d, inertia J
/// about it) falls from the horizontal under gravity −y onto a stop at
/// −60°. From the energy, the approach rate is ω⁻ = −√(2 m g d sin 60°/I_O),
/// I_O = J + m d²; the impact returns −e ω⁻ (1e-6) and dissipates
/// (1 − e²) ½ (Bv⁻)ᵀ(B M⁻¹ Bᵀ)⁻¹(Bv⁻) = (1 − e²) ½ I_O ω⁻² (with the
/// hinge's constraints, the reduced inertia of the angle is I_O), to
/// round-off.
#[test]
fn a_hinged_bar_rebounds_from_a_stop() {
    let (m, d, j, e) = (pendulum::MASS, pendulum::DISTANCE, pendulum::INERTIA, 0.6);
    let text = pendulum::onto_a_stop(
        r#"
[analysis]
type = "dynamic"
end_time = 0.8
time_step = 0.005
error_tolerance = 1e-6"#,
        e,
    );
    let (_, out, rec) = run(&text);
    let io = j + m * d * d;
    let theta = 60f64.to_radians();
    let omega = (2.0 * m * G * d * theta.sin() / io).sqrt();
    let c = &rec.contacts[0];
    eprintln!(
        "{:?} at t = {}: {} -> {} (exact {}); energy lost {}; {} steps, {} retries",
        c.kind,
        c.time,
        c.rate_before,
        c.rate_after,
        -omega,
        c.energy_lost,
        out.steps,
        out.event_retries
    );
    assert_eq!(c.kind, ContactKind::Impact);
    assert!((c.coordinate + theta).abs() <= 1e-8);
    // the approach rate from the energy: within the integration's error
    // (error_tolerance 1e-6: 1e-5 measured against the closed form)
    assert!(
        (c.rate_before + omega).abs() <= 1e-4 * omega,
        "{}",
        c.rate_before
    );
    assert!((c.rate_after + e * c.rate_before).abs() <= 1e-6 * omega);
    let loss = (1.0 - e * e) * 0.5 * io * c.rate_before.powi(2);
    assert!(
        (c.energy_lost - loss).abs() <= 1e-10 * loss,
        "{} {loss}",
        c.energy_lost
    );
    assert!(
        (c.kinetic_energy_drop - loss).abs() <= 1e-10 * loss,
        "{} {loss}",
        c.kinetic_energy_drop
    );
}

/// The ball resting on a stop at its start (closed without impact) is
/// pulled up by a force growing as 2 m g t: the contact load
/// N = m g (1 − 2t) falls to zero at t = 0.5, where the stop opens (a
/// release event, located on N = 0 within 1e-6 of the largest load); the
/// ball then rises with z̈ = g (2t − 1): z = g (t − ½)³/3.
#[test]
fn a_contact_is_released_when_its_load_vanishes() {
    let text = ball(
        0.7,
        "lower = 0.0",
        &format!(
            "[[loads]]\nnode = 1\nforce = [0.0, 0.0, {}]\ncurve = \"ramp\"\n",
            2.0 * MASS * G
        ),
    );
    let (model, out, rec) = run(&text);
    assert_eq!(rec.contacts.len(), 1, "{:?}", rec.contacts);
    let c = &rec.contacts[0];
    assert_eq!(c.kind, ContactKind::Release);
    let step = rec
        .steps
        .iter()
        .find(|(i, _)| i.time == c.time)
        .map(|(i, _)| i.step)
        .unwrap();
    eprintln!(
        "released at t = {} (step {step}); {} steps",
        c.time, out.steps
    );
    // N is linear in t: located to round-off (1e-9)
    assert!((c.time - 0.5).abs() <= 1e-9, "{}", c.time);
    // before: at rest on the stop, the load m g (1 − 2t) within 1e-6 of
    // the weight
    for (i, s) in rec.steps.iter().filter(|(i, _)| i.time < 0.45) {
        let n = load(&model, s);
        assert!(
            (n - MASS * G * (1.0 - 2.0 * i.time)).abs() <= 1e-6 * MASS * G,
            "t = {}: {n}",
            i.time
        );
        assert!(s.x[0].z.abs() <= GAP_TOLERANCE);
    }
    // after: z(0.7) = g (0.2)³/3 within the integration's error (1e-3
    // relative, error_tolerance left at its default 1e-4 of the motion)
    let s = &rec.steps.last().unwrap().1;
    let z = G * 0.2f64.powi(3) / 3.0;
    eprintln!("z(0.7) = {} (closed form {z})", s.x[0].z);
    assert!((s.x[0].z - z).abs() <= 1e-3 * z, "{} {z}", s.x[0].z);
}

/// Input errors name the stop and say what is wrong; `unfold check`
/// refuses them with exit code 2.
#[test]
fn stop_input_errors_name_the_stop() {
    let cases = [
        (
            "lower = 1.0\nupper = -1.0",
            "lower (1) must be below upper (-1)",
        ),
        (
            "lower = -1.0\nrestitution = 1.5",
            "restitution must be in [0, 1], got 1.5",
        ),
        (
            "lower = -1.0\nrestitution = -0.1",
            "restitution must be in [0, 1]",
        ),
        ("restitution = 0.5", "a stop needs `lower`, `upper` or both"),
        ("lower = -1.0\ncoordinate = \"angle\"", "angle"),
    ];
    let dir = std::env::temp_dir().join(format!("unfold-stops-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (k, (stop, expected)) in cases.iter().enumerate() {
        let text = ball(1.0, stop, "");
        let message = error_of(&text);
        assert!(message.contains("stop 20"), "{message}");
        assert!(message.contains(expected), "{message}");
        let file = dir.join(format!("case{k}.toml"));
        std::fs::write(&file, &text).unwrap();
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_unfold"))
            .arg("check")
            .arg(&file)
            .output()
            .unwrap();
        assert_eq!(
            o.status.code(),
            Some(2),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(String::from_utf8_lossy(&o.stderr).contains("stop 20"));
    }
    // an unknown joint
    let text = ball(1.0, "lower = -1.0", "").replace("joint = 10\nlower", "joint = 11\nlower");
    let message = error_of(&text);
    assert!(
        message.contains("stop 20") && message.contains("joint 11 does not exist"),
        "{message}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The builder writes `[[stops]]`; the stop's results in the reference
/// configuration: open, the gap to the nearer limit.
#[test]
fn the_builder_writes_the_stop_entry() {
    use unfold::elements::ElementKind;
    use unfold::model::builder::*;
    let mut m = ModelBuilder::new("hinge with stops");
    let a = m.node([-0.5, 0.0, 0.0]);
    let b = m.node([0.0, -0.5, 0.0]);
    m.add(RigidBody::at(a, 2.0).inertia([0.1, 0.1, 0.1]));
    m.add(RigidBody::at(b, 1.0).inertia([0.1, 0.1, 0.1]));
    m.fix(a, Dofs::ALL);
    let hinge = m.add(
        Joint::revolute(a, b)
            .axis([0.0, 0.0, 1.0])
            .at([0.0, 0.0, 0.0]),
    );
    let stop = m.add(
        Stop::on(hinge)
            .lower(-10.0)
            .upper(95.0)
            .unit(AngleUnit::Deg)
            .restitution(0.3),
    );
    let model = m.build().unwrap();
    assert_eq!(model.element(stop).kind(), ElementKind::Stop);
    let r = model.results(stop, &model.initial_state());
    assert_eq!(r.get("contact"), Some(0.0));
    assert_eq!(r.get("load"), Some(0.0));
    // c = 0: the nearer limit is −10°, 10° away (round-off)
    assert!((r.get("gap").unwrap() - 10f64.to_radians()).abs() < 1e-12);
    let text = m.to_toml().unwrap();
    assert!(
        text.contains("[[stops]]") && text.contains("restitution = 0.3"),
        "{text}"
    );
    let input: ModelInput = toml::from_str(&text).unwrap();
    assert_eq!(input.stops.len(), 1);
    assert!(Model::from_input(&input).is_ok());
}
