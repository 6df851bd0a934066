//! `[[sections]]`: the cross-section properties of beams, referred to by
//! name.

use super::{num, Builder, Checker};
use crate::elements::beam::{BeamSection, RayleighDamping, SectionStiffness};
use crate::model::input::SectionInput;
use crate::model::ModelErrorKind;
use crate::so3::Vec3;

impl Builder<'_> {
    /// `[[sections]]`.
    pub(super) fn sections(&mut self) {
        for s in &self.input.sections {
            let entity = format!("section \"{}\"", s.name);
            if self.sections.contains_key(&s.name) || self.invalid_sections.contains(&s.name) {
                self.ck.push(
                    ModelErrorKind::DuplicateId,
                    &entity,
                    "duplicate section name",
                );
                continue;
            }
            match section(&mut self.ck, &entity, s) {
                Some(sec) => {
                    self.sections.insert(s.name.clone(), sec);
                }
                None => {
                    self.invalid_sections.insert(s.name.clone());
                }
            }
        }
    }
}

/// Validated section properties.
fn section(ck: &mut Checker, entity: &str, s: &SectionInput) -> Option<BeamSection> {
    let diagonal = [
        ("EA", s.ea),
        ("GA2", s.ga2),
        ("GA3", s.ga3),
        ("GJ", s.gj),
        ("EI2", s.ei2),
        ("EI3", s.ei3),
    ];
    let given: Vec<&str> = diagonal
        .iter()
        .filter(|d| d.1.is_some())
        .map(|d| d.0)
        .collect();
    let stiffness = match (&s.stiffness, given.len()) {
        (Some(_), n) if n > 0 => {
            ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!(
                    "give either the diagonal stiffnesses or `stiffness`, not both (found {})",
                    given.join(", ")
                ),
            );
            return None;
        }
        (Some(c), _) => {
            let m = SectionStiffness::from_fn(|i, j| c[i][j]);
            let flat: Vec<f64> = m.iter().copied().collect();
            if !ck.finite(entity, "stiffness", &flat) {
                return None;
            }
            let asym = (m - m.transpose()).abs().max();
            if asym > 1e-9 * m.abs().max() {
                ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    "the 6×6 stiffness matrix is not symmetric",
                );
                return None;
            }
            if m.cholesky().is_none() {
                ck.push(
                    ModelErrorKind::NonPositive,
                    entity,
                    "the 6×6 stiffness matrix is not positive definite",
                );
                return None;
            }
            m
        }
        (None, 0) => {
            ck.push(
                ModelErrorKind::Missing,
                entity,
                "no stiffness: give EA, GA2, GA3, GJ, EI2, EI3 or a 6×6 `stiffness`",
            );
            return None;
        }
        (None, _) => {
            let missing: Vec<&str> = diagonal
                .iter()
                .filter(|d| d.1.is_none())
                .map(|d| d.0)
                .collect();
            if !missing.is_empty() {
                ck.push(
                    ModelErrorKind::Missing,
                    entity,
                    format!("missing {}", missing.join(", ")),
                );
                return None;
            }
            let mut ok = true;
            for (name, v) in diagonal {
                ok &= ck.positive(entity, name, v.unwrap());
            }
            if !ok {
                return None;
            }
            SectionStiffness::from_diagonal(&nalgebra::Vector6::from_fn(|i, _| {
                diagonal[i].1.unwrap()
            }))
        }
    };
    let mass = s.mass_per_length.unwrap_or(0.0);
    let inertia = s.inertia_per_length.unwrap_or([0.0; 3]);
    let mut ok = true;
    if !(mass.is_finite() && mass >= 0.0) {
        ck.push(
            ModelErrorKind::NonPositive,
            entity,
            format!("mass_per_length must be ≥ 0, got {mass}"),
        );
        ok = false;
    }
    if inertia.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
        ck.push(
            ModelErrorKind::NonPositive,
            entity,
            format!("inertia_per_length must be ≥ 0, got {inertia:?}"),
        );
        ok = false;
    }
    let mut damping = RayleighDamping::default();
    for (key, given, value) in [
        ("rayleigh_alpha", s.rayleigh_alpha, &mut damping.alpha),
        ("rayleigh_beta", s.rayleigh_beta, &mut damping.beta),
    ] {
        let v = given.unwrap_or(0.0);
        if v.is_finite() && v >= 0.0 {
            *value = v;
        } else {
            ck.push(
                ModelErrorKind::NonPositive,
                entity,
                format!(
                    "{key} must be a finite number ≥ 0 (Rayleigh damping, docs/theory.md §11.5), got {}",
                    num(v)
                ),
            );
            ok = false;
        }
    }
    ok.then(|| BeamSection {
        stiffness,
        mass_per_length: mass,
        inertia_per_length: Vec3::from(inertia),
        damping,
    })
}
