//! The ball dropped on a stop or a contact (tests/stops.rs,
//! tests/contact.rs): a body of mass `MASS` on node 1 under a constant
//! gravity `G` along −z, in a dynamic analysis in steps of 0.01 s.

/// Mass of the ball (kg).
pub const MASS: f64 = 2.0;
/// Acceleration of gravity (m/s²).
pub const G: f64 = 9.81;

/// The model text: a dynamic analysis to `end_time`, the ball's tables
/// `ball` (its node 1, its mass and what holds it), gravity, then the
/// tables `extra`.
pub fn dropped(end_time: f64, ball: &str, extra: &str) -> String {
    format!(
        r#"
[analysis]
type = "dynamic"
end_time = {end_time}
time_step = 0.01

{ball}

[gravity]
acceleration = [0.0, 0.0, -{G}]
curve = "constant"
{extra}
"#
    )
}
