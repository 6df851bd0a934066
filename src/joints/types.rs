//! The joint library: constraint equations and relative coordinates of
//! each kinematic pair, written once over hyper-dual numbers
//! (docs/joints.md gives every equation).
//!
//! Notation: `pA`, `pB` are the joint points carried by bodies A and B,
//! `d = pB − pA`, and `aᵢ`, `bᵢ` the joint axes carried by A and B (global
//! components), equal in the reference configuration; `e₃` is the axis of
//! revolute, prismatic, cylindrical and helical joints and the normal of a
//! planar joint.

use serde::{Deserialize, Serialize};

use super::hyperdual::{HyperDual, Real, V3};
use super::kinematics::{unwrap, Conf, Frames, Pair};

/// The kinematic pairs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum JointType {
    /// Rotation about `e₃` (paper eq. 19).
    #[default]
    Revolute,
    /// Translation along `e₃`.
    Prismatic,
    /// Rotation about and translation along `e₃`.
    Cylindrical,
    /// Free rotation about a common point.
    Spherical,
    /// Motion in the plane normal to `e₃`.
    Planar,
    /// Cardan joint: rotations about `a₁` (on A) and `b₂` (on B).
    Universal,
    /// Screw along `e₃`: translation = pitch × turns.
    Helical,
    /// A node sliding along a curve through a sequence of nodes.
    Slider,
    /// Rigid connection of two nodes (their reference offset kept).
    Rigid,
    /// A node glued to a point of a body at a given offset.
    Glue,
}

impl JointType {
    /// Every joint type.
    pub const ALL: [JointType; 10] = [
        Self::Revolute,
        Self::Prismatic,
        Self::Cylindrical,
        Self::Spherical,
        Self::Planar,
        Self::Universal,
        Self::Helical,
        Self::Slider,
        Self::Rigid,
        Self::Glue,
    ];

    /// The type named `name` ([`Self::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|t| t.name() == name)
    }

    /// Name used in files and messages.
    pub fn name(self) -> &'static str {
        match self {
            Self::Revolute => "revolute",
            Self::Prismatic => "prismatic",
            Self::Cylindrical => "cylindrical",
            Self::Spherical => "spherical",
            Self::Planar => "planar",
            Self::Universal => "universal",
            Self::Helical => "helical",
            Self::Slider => "slider",
            Self::Rigid => "rigid",
            Self::Glue => "glue",
        }
    }

    /// Relative coordinates the joint exposes, in the order of its
    /// results ([`crate::joints::joint::result_names`]).
    pub const fn coordinates(self) -> &'static [Coordinate] {
        use Coordinate::*;
        match self {
            Self::Revolute => &[Angle],
            Self::Prismatic => &[Slide3],
            Self::Cylindrical | Self::Helical => &[Angle, Slide3],
            Self::Planar => &[Slide1, Slide2, Angle],
            Self::Universal => &[Cardan1, Cardan2],
            Self::Slider => &[CurveParameter],
            Self::Spherical | Self::Rigid | Self::Glue => &[],
        }
    }

    /// Kinds of its constraint equations, in order (`glue` as locking
    /// rotations; see [`constraint_kinds`]).
    pub fn equations(self) -> &'static [Equation] {
        use Equation::*;
        match self {
            Self::Revolute => &[Force, Force, Force, Moment, Moment],
            Self::Spherical => &[Force, Force, Force],
            Self::Universal => &[Force, Force, Force, Moment],
            Self::Cylindrical => &[Moment, Moment, Force, Force],
            Self::Prismatic => &[Moment, Moment, Force, Force, Moment],
            Self::Helical => &[Moment, Moment, Force, Force, Force],
            Self::Planar => &[Moment, Moment, Force],
            Self::Rigid | Self::Glue => &[Force, Force, Force, Moment, Moment, Moment],
            Self::Slider => &[Force, Force, Force],
        }
    }
}

/// The constraint kinds of a joint, `glue` without locked rotations
/// keeping only its three point equations.
pub fn constraint_kinds(t: JointType, lock_rotations: bool) -> &'static [Equation] {
    if t == JointType::Glue && !lock_rotations {
        &t.equations()[..3]
    } else {
        t.equations()
    }
}

/// What a constraint equation measures, which sets its scaling: a
/// distance (scaled with the translational stiffness) or a dot product of
/// unit vectors, i.e. an angle (scaled with the rotational stiffness).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Equation {
    /// A distance.
    Force,
    /// An angle.
    Moment,
}

/// A relative coordinate of a joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coordinate {
    /// Rotation of B relative to A about `e₃`: `atan2(b₁·a₂, b₁·a₁)`.
    Angle,
    /// `d·a₁`.
    Slide1,
    /// `d·a₂`.
    Slide2,
    /// `d·a₃`.
    Slide3,
    /// First Cardan angle, about `a₁`: `atan2(b₂·a₃, b₂·a₂)`.
    Cardan1,
    /// Second Cardan angle, about `b₂`: `atan2(a₁·b₃, a₁·b₁)`.
    Cardan2,
    /// Arc-length parameter of a slider on its curve.
    CurveParameter,
}

impl Coordinate {
    /// Every coordinate, in the order of the columns of `joints.csv`
    /// (docs/results.md): the angle of the revolute-like joints, the slide
    /// along their axis, the planar joint's in-plane slides, the universal
    /// joint's two angles, the slider's curve parameter.
    pub const ALL: [Coordinate; 7] = [
        Self::Angle,
        Self::Slide3,
        Self::Slide1,
        Self::Slide2,
        Self::Cardan1,
        Self::Cardan2,
        Self::CurveParameter,
    ];

    /// Whether the coordinate is an angle (unwrapped across turns).
    pub fn is_angle(self) -> bool {
        matches!(self, Self::Angle | Self::Cardan1 | Self::Cardan2)
    }

    /// Name in model files (`coordinate = "slide"`), messages and result
    /// files: the column of `joints.csv` and of the joints' results
    /// ([`crate::model::Model::results`], Python), `<name>_rate` for its
    /// rate in dynamics.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Angle => "angle",
            Self::Slide1 => "slide1",
            Self::Slide2 => "slide2",
            Self::Slide3 => "slide",
            Self::Cardan1 => "angle1",
            Self::Cardan2 => "angle2",
            Self::CurveParameter => "s",
        }
    }

    /// The coordinate for frames `f`; angles are wrapped to (−π, π] (see
    /// [`unwrap`]).
    pub fn value(self, f: &Frames) -> HyperDual {
        let (a, b) = (&f.ea, &f.eb);
        let d = f.pb.sub(&f.pa);
        match self {
            Self::Angle => b.col(0).dot(&a.col(1)).atan2(b.col(0).dot(&a.col(0))),
            Self::Slide1 => d.dot(&a.col(0)),
            Self::Slide2 => d.dot(&a.col(1)),
            Self::Slide3 => d.dot(&a.col(2)),
            Self::Cardan1 => b.col(1).dot(&a.col(2)).atan2(b.col(1).dot(&a.col(1))),
            Self::Cardan2 => a.col(0).dot(&b.col(2)).atan2(a.col(0).dot(&b.col(0))),
            Self::CurveParameter => HyperDual::cst(f64::NAN),
        }
    }

    /// The coordinate, angles unwrapped to the branch nearest `reference`.
    pub fn unwrapped(self, f: &Frames, reference: f64) -> HyperDual {
        let v = self.value(f);
        if self.is_angle() {
            unwrap(v, reference)
        } else {
            v
        }
    }
}

/// Parameters beyond the geometry of the pair.
#[derive(Clone, Debug, PartialEq)]
pub struct JointParameters {
    /// Helical: axial advance per radian, `pitch/(2π)`.
    pub lead: f64,
    /// Glue: whether rotations are locked too.
    pub lock_rotations: bool,
    /// Slider: the curve.
    pub curve: Option<SliderCurve>,
}

/// Writes the constraint equations `Φ` of a joint of type `t`.
/// `angle` is the unwrapped joint angle (helical joints only).
pub fn constraints(
    t: JointType,
    f: &Frames,
    angle: HyperDual,
    p: &JointParameters,
    out: &mut [HyperDual],
) {
    let (a, b) = (&f.ea, &f.eb);
    let d = f.pb.sub(&f.pa);
    let point = |out: &mut [HyperDual]| {
        out[0] = d.0[0];
        out[1] = d.0[1];
        out[2] = d.0[2];
    };
    // a₁·b₃ = a₂·b₃ = 0: the axes e₃ of both bodies stay parallel
    let axis = |out: &mut [HyperDual]| {
        out[0] = a.col(0).dot(&b.col(2));
        out[1] = a.col(1).dot(&b.col(2));
    };
    match t {
        JointType::Spherical => point(out),
        JointType::Revolute => {
            point(out);
            axis(&mut out[3..]);
        }
        JointType::Universal => {
            point(out);
            out[3] = a.col(0).dot(&b.col(1));
        }
        JointType::Cylindrical | JointType::Prismatic | JointType::Helical => {
            axis(out);
            out[2] = d.dot(&a.col(0));
            out[3] = d.dot(&a.col(1));
            match t {
                JointType::Prismatic => out[4] = a.col(0).dot(&b.col(1)),
                JointType::Helical => out[4] = d.dot(&a.col(2)) - angle * p.lead,
                _ => {}
            }
        }
        JointType::Planar => {
            axis(out);
            out[2] = d.dot(&a.col(2));
        }
        JointType::Rigid | JointType::Glue => {
            point(out);
            if t == JointType::Rigid || p.lock_rotations {
                out[3] = a.col(0).dot(&b.col(1));
                out[4] = a.col(1).dot(&b.col(2));
                out[5] = a.col(2).dot(&b.col(0));
            }
        }
        JointType::Slider => unreachable!("slider constraints come from slider_constraints"),
    }
}

/// A slider's curve through its nodes (local nodes 1..): a polyline, or a
/// Catmull–Rom spline parametrised by chord length. Either way the
/// parameter `s` is the distance along the polygon of the nodes, 0 at the
/// first node.
#[derive(Clone, Debug, PartialEq)]
pub struct SliderCurve {
    /// Spline (C¹) instead of polyline (C⁰).
    pub spline: bool,
}

impl SliderCurve {
    /// The point of parameter `s` on the curve through `c` (beyond the ends,
    /// the end segments are extended).
    pub fn point(&self, c: &[V3<HyperDual>], s: HyperDual) -> V3<HyperDual> {
        let n = c.len();
        let len = |k: usize| c[k + 1].sub(&c[k]).norm();
        // segment from the real part
        let mut k = 0;
        let mut start = HyperDual::cst(0.0);
        let mut lk = len(0);
        while k + 2 < n && (start + lk).re <= s.re {
            start = start + lk;
            k += 1;
            lk = len(k);
        }
        let t = (s - start) / lk;
        let chord = c[k + 1].sub(&c[k]);
        // beyond the ends: the straight extension of the end segment (the
        // spline's end tangents are the end chords)
        let outside = (k == 0 && t.re < 0.0) || (k + 2 == n && t.re > 1.0);
        if !self.spline || n < 3 || outside {
            return c[k].add(&chord.scale(t));
        }
        // Hermite segment with chord-length Catmull–Rom tangents (in t):
        // at an interior node i, dC/dt = L_k (c[i+1] − c[i−1])/(L[i−1] + L[i]),
        // which makes dC/ds continuous; end segments use the chord
        let tangent = |i: usize| c[i + 1].sub(&c[i - 1]).scale(lk / (len(i - 1) + len(i)));
        let t0 = if k == 0 { chord } else { tangent(k) };
        let t1 = if k + 2 == n { chord } else { tangent(k + 1) };
        let t2 = t * t;
        let t3 = t2 * t;
        let h00 = t3 * 2.0 - t2 * 3.0 + 1.0;
        let h10 = t3 - t2 * 2.0 + t;
        let h01 = t2 * 3.0 - t3 * 2.0;
        let h11 = t3 - t2;
        c[k].scale(h00)
            .add(&t0.scale(h10))
            .add(&c[k + 1].scale(h01))
            .add(&t1.scale(h11))
    }
}

/// `Φ = pB − C(s)` for a slider: local node 0 is the sliding node (joint
/// point offset `pair.a`), nodes 1.. define the curve, `s` is the first
/// coordinate unknown.
pub fn slider_constraints(pair: &Pair, curve: &SliderCurve, c: &Conf, out: &mut [HyperDual]) {
    let p = c.x[0].add(&c.r[0].apply(&pair.a));
    let on_curve = curve.point(&c.x[1..], c.coords[0]);
    let d = p.sub(&on_curve);
    out[..3].copy_from_slice(&d.0);
}
