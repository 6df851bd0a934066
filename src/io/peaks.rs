//! The largest load each latch, stop and contact carried over a run, for
//! `summary.json` (docs/results.md, "Peak loads"): the load of the
//! element's result file (`latches.csv`, `stops.csv`, `contacts.csv`) at
//! every converged increment, output or not, of every analysis of the
//! run.
//!
//! - a rigid latch: the reaction of its constraint `kλ − pΦ` (J8,
//!   docs/joints.md §6.2), the moment or force that holds the lock;
//! - a spring latch: its spring and dashpot, `−(f_s + d ċ)`;
//! - a stop: its contact load `N`; a contact: its normal force.
//!
//! The loads are sampled at the converged increments: a peak between two
//! of them is missed by the amount the load changes over a step, and an
//! impact's impulse (an instantaneous load, `events.csv`) is not a load.
//! A spring latch that releases carries its unlatch load on the step that
//! landed on the release, whose state the analysis reports released: that
//! load is taken from the event ([`PeakLoads::unlatched`]).

use serde::Serialize;

use crate::analysis::{LatchEventKind, LockInfo};
use crate::elements::{Element, ElementKind, Need};
use crate::joints::latch::SpringLatch;
use crate::model::{Id, Model};
use crate::state::State;

/// The largest load of a latch over the run (`summary.json`, `latches`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LatchPeak {
    /// The latch.
    pub latch: Id,
    /// The joint whose coordinate it locks.
    pub joint: Id,
    /// `rigid` or `spring`.
    pub mode: &'static str,
    /// `moment` (an angle's latch, model force × length) or `force`.
    pub quantity: &'static str,
    /// The time of the first converged increment at which it was locked
    /// (`null`: never locked).
    pub locked_at: Option<f64>,
    /// The impulse of its first lock along the coordinate (N·m·s for an
    /// angle in SI), as `impulse` in `events.csv` (`null`: never locked;
    /// 0 for a spring latch, which locks without impact).
    pub lock_impulse: Option<f64>,
    /// The energy its first lock dissipated (`null`: never locked).
    pub lock_energy_lost: Option<f64>,
    /// Its load of largest magnitude, with its sign (positive pushing the
    /// coordinate up, as `load` in `latches.csv`).
    #[serde(flatten)]
    pub peak: Peak,
    /// Whether `peak_load` may be read as a design load: false for a rigid
    /// latch whose lock was an impact (a non-zero impulse) onto deformable
    /// members (beams, shells) and whose peak came at or after that lock:
    /// the loads after such a lock follow a velocity jump imposed in one
    /// step on members with distributed mass, and depend on the step and
    /// on the damping of the highest modes, not on the structure alone;
    /// false also for a latch that never locked.
    pub design_load: bool,
    /// Why `design_load` is false (absent when it is true).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// The largest load of a stop or contact over the run (`summary.json`,
/// `stops` and `contacts`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StopPeak {
    /// The stop (absent for a contact).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stop: Option<Id>,
    /// The contact (absent for a stop).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact: Option<Id>,
    /// The joint whose coordinate the stop limits (absent for a contact).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub joint: Option<Id>,
    /// `moment` (a stop on an angle) or `force`.
    pub quantity: &'static str,
    /// The time of the first converged increment at which it was closed
    /// (`null`: never; an impact that rebounds does not close it).
    pub closed_at: Option<f64>,
    /// Its load of largest magnitude, with its sign (positive pushing the
    /// coordinate back into its range, as `load` in `stops.csv`; for a
    /// contact pushing the bodies apart, as `force` in `contacts.csv`).
    #[serde(flatten)]
    pub peak: Peak,
}

/// The load of largest magnitude over the converged increments so far.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Peak {
    /// The load, with its sign; 0 if none was carried.
    pub peak_load: f64,
    /// The time of the increment at which it was carried (the first, if
    /// several carried it; `null` if no load was).
    pub peak_time: Option<f64>,
    /// That increment, numbered across the run as in `steps.csv`.
    pub peak_increment: Option<usize>,
}

impl Peak {
    /// Keeps `load`, at `time` and `increment`, if its magnitude is above
    /// the peak's.
    fn take(&mut self, load: f64, time: f64, increment: usize) {
        if load.abs() > self.peak_load.abs() {
            *self = Self {
                peak_load: load,
                peak_time: Some(time),
                peak_increment: Some(increment),
            };
        }
    }
}

/// A peak being followed: the element's index, the place of its load and
/// of its lock or contact flag among its results; for a spring latch, its
/// spring and locking value (its load at a release).
#[derive(Clone, Debug)]
struct Followed {
    element: usize,
    load: usize,
    flag: usize,
    spring: Option<(SpringLatch, f64)>,
    /// The increment (numbered across the run) of a latch's first lock.
    lock_increment: Option<usize>,
}

/// The largest value of a result of the original elements of a
/// superelement over the run (`summary.json`, `superelements[].peaks`):
/// a beam's section force, a shell's skin stress.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ResultPeak {
    /// The result's name (`N`, `M3`...).
    pub quantity: &'static str,
    /// Its value of largest magnitude, with its sign.
    pub value: f64,
    /// Where: the original element (its id in the body).
    pub element: Id,
    /// Its kind.
    pub kind: &'static str,
    /// Its nodes (ids in the body).
    pub nodes: Vec<Id>,
    /// For a skin stress of a shell: the layer of its laminate (from the
    /// bottom, 0) where it is.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub layer: Option<usize>,
    /// When (`null` if never reached: a body at rest).
    pub time: Option<f64>,
    /// At which increment, numbered across the run as in `steps.csv`.
    pub increment: Option<usize>,
}

/// A superelement in `summary.json` (docs/results.md, "Superelements"):
/// its reduction and the peak results of its original elements.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SuperelementRecord {
    /// The superelement.
    pub superelement: Id,
    /// Its boundary nodes (model ids).
    pub boundary_nodes: Vec<Id>,
    /// The node of its floating frame.
    pub frame_node: Id,
    /// Fixed-interface modes kept.
    pub modes: usize,
    /// Their frequencies (Hz).
    pub mode_frequencies: Vec<f64>,
    /// `consistent` or `lumped`.
    pub inertia: &'static str,
    /// What the reduction found.
    pub reduction: crate::reduction::ReductionReport,
    /// The largest value of each result of the original elements over
    /// the run (empty for imported matrices).
    pub peaks: Vec<ResultPeak>,
}

/// The skin stresses of a shell followed over a run, `[bottom, top]`:
/// von Mises and the principal stresses where it is largest.
const SKIN_QUANTITIES: [[&str; 3]; 2] = [
    [
        "bottom_skin_von_mises",
        "bottom_skin_sigma1",
        "bottom_skin_sigma2",
    ],
    ["top_skin_von_mises", "top_skin_sigma1", "top_skin_sigma2"],
];

/// Follows the loads of a model's latches, stops and contacts over a run,
/// and the results of the original elements of its superelements.
#[derive(Clone, Debug, Default)]
pub struct PeakLoads {
    latches: Vec<(Followed, LatchPeak)>,
    stops: Vec<(Followed, StopPeak)>,
    superelements: Vec<(usize, SuperelementRecord)>,
    /// The model has deformable members (beams, shells).
    deformable: bool,
}

impl PeakLoads {
    /// The latches, stops and contacts of `model`, none loaded yet.
    pub fn of(model: &Model) -> Self {
        let place = |e: &dyn Element, name: &str| {
            e.result_names()
                .iter()
                .position(|n| *n == name)
                .unwrap_or(0)
        };
        let mut peaks = Self::default();
        for (element, e) in model.elements.iter().enumerate() {
            if matches!(e.kind(), ElementKind::Beam | ElementKind::Shell) {
                peaks.deformable = true;
            }
            let e = e.as_ref();
            if let Some(l) = e.as_latch() {
                let followed = Followed {
                    element,
                    load: place(e, "load"),
                    flag: place(e, "locked"),
                    spring: l.spring().map(|s| (*s, l.value())),
                    lock_increment: None,
                };
                peaks.latches.push((
                    followed,
                    LatchPeak {
                        latch: e.id(),
                        joint: l.joint(),
                        mode: if l.spring().is_some() {
                            "spring"
                        } else {
                            "rigid"
                        },
                        quantity: quantity(l.is_angle()),
                        locked_at: None,
                        lock_impulse: None,
                        lock_energy_lost: None,
                        peak: Peak::default(),
                        design_load: true,
                        note: None,
                    },
                ));
            } else if let Some(s) = e.as_stop() {
                let contact = s.joint().is_none();
                let followed = if contact {
                    Followed {
                        element,
                        load: place(e, "force"),
                        flag: place(e, "closed"),
                        spring: None,
                        lock_increment: None,
                    }
                } else {
                    Followed {
                        element,
                        load: place(e, "load"),
                        flag: place(e, "contact"),
                        spring: None,
                        lock_increment: None,
                    }
                };
                peaks.stops.push((
                    followed,
                    StopPeak {
                        stop: (!contact).then(|| e.id()),
                        contact: contact.then(|| e.id()),
                        joint: s.joint(),
                        quantity: quantity(s.is_angle()),
                        closed_at: None,
                        peak: Peak::default(),
                    },
                ));
            }
        }
        for (element, e) in model.elements.iter().enumerate() {
            let Some(se) = e.as_superelement() else {
                continue;
            };
            let body = se.body();
            let record = SuperelementRecord {
                superelement: e.id(),
                boundary_nodes: e.nodes().iter().map(|&n| model.node_ids[n]).collect(),
                frame_node: model.node_ids[e.nodes()[se.frame_node()]],
                modes: body.n_modes(),
                mode_frequencies: body
                    .omega_squared
                    .iter()
                    .map(|w2| w2.sqrt() / std::f64::consts::TAU)
                    .collect(),
                inertia: body.inertia.name(),
                reduction: body.report.clone(),
                peaks: Vec::new(),
            };
            peaks.superelements.push((element, record));
        }
        peaks.superelements.sort_by_key(|(_, r)| r.superelement);
        // in increasing id, as the rows of the result files
        peaks.latches.sort_by_key(|(_, p)| p.latch);
        peaks.stops.sort_by_key(|(_, p)| p.stop.or(p.contact));
        peaks
    }

    /// Whether the model has nothing to follow.
    pub fn is_empty(&self) -> bool {
        self.latches.is_empty() && self.stops.is_empty() && self.superelements.is_empty()
    }

    /// Takes the loads at the converged increment `increment` (numbered
    /// across the run) of `model`, at `state`.
    pub fn sample(&mut self, model: &Model, state: &State, increment: usize) {
        if self.is_empty() {
            return;
        }
        let ctx = model.context(state.time, Need::RESIDUAL);
        let mut values = [0.0; 8];
        let mut take = |f: &Followed| -> Option<(f64, bool)> {
            let e = model.elements.get(f.element)?;
            let n = e.result_names().len().min(values.len());
            let v = &mut values[..n];
            v.fill(0.0);
            e.results(&ctx, state, v);
            Some((v[f.load], v[f.flag] != 0.0))
        };
        let time = state.time;
        for (f, p) in &mut self.latches {
            if let Some((load, locked)) = take(f) {
                if locked && p.locked_at.is_none() {
                    p.locked_at = Some(time);
                }
                p.peak.take(load, time, increment);
            }
        }
        for (f, p) in &mut self.stops {
            if let Some((load, closed)) = take(f) {
                if closed && p.closed_at.is_none() {
                    p.closed_at = Some(time);
                }
                p.peak.take(load, time, increment);
            }
        }
    }

    /// Takes the results of the original elements of the superelements
    /// (a beam's section forces, a shell's skin stresses) at the output
    /// step `increment` (numbered as in [`PeakLoads::sample`]): the mesh
    /// recovered at output steps only, where the results are written.
    pub fn sample_recovered(&mut self, model: &Model, state: &State, increment: usize) {
        let time = state.time;
        for (element, record) in &mut self.superelements {
            let Some(se) = model
                .elements
                .get(*element)
                .and_then(|e| e.as_superelement())
            else {
                continue;
            };
            let Some(originals) = &se.body().body.elements else {
                continue;
            };
            let mesh = se.recovered_mesh(state);
            let results = se.element_results(&mesh);
            let skins = se.skin_stresses(&mesh);
            let mut take =
                |e: &dyn Element, quantity: &'static str, value: f64, layer: Option<usize>| {
                    let at = match record.peaks.iter().position(|p| p.quantity == quantity) {
                        Some(at) => at,
                        None => {
                            record.peaks.push(ResultPeak {
                                quantity,
                                value: 0.0,
                                element: e.id(),
                                kind: e.kind().name(),
                                nodes: e.nodes().iter().map(|&n| originals.node_ids[n]).collect(),
                                layer,
                                time: None,
                                increment: None,
                            });
                            record.peaks.len() - 1
                        }
                    };
                    let p = &mut record.peaks[at];
                    if value.abs() > p.value.abs() {
                        p.value = value;
                        p.element = e.id();
                        p.kind = e.kind().name();
                        p.nodes = e.nodes().iter().map(|&n| originals.node_ids[n]).collect();
                        p.layer = layer;
                        p.time = Some(time);
                        p.increment = Some(increment);
                    }
                };
            for (e, values) in originals.elements.iter().zip(&results) {
                for (&quantity, &value) in e.result_names().iter().zip(values) {
                    take(e.as_ref(), quantity, value, None);
                }
            }
            for (e, skin) in originals.elements.iter().zip(&skins) {
                let Some(skin) = skin else {
                    continue;
                };
                for (s, names) in skin.iter().zip(SKIN_QUANTITIES) {
                    let values = [s.von_mises, s.principal[0], s.principal[1]];
                    for (quantity, value) in names.into_iter().zip(values) {
                        take(e.as_ref(), quantity, value, Some(s.layer));
                    }
                }
            }
        }
    }

    /// The superelements' records, in increasing id.
    pub fn superelements(&self) -> Vec<SuperelementRecord> {
        self.superelements.iter().map(|(_, r)| r.clone()).collect()
    }

    /// A latch event `event` (numbered across the run as `increment`):
    /// the impulse and energy lost of the latch's first lock are kept, and
    /// a spring latch's release load is taken ([`Self::unlatched`]).
    pub fn event(&mut self, event: &LockInfo, increment: usize) {
        if event.kind == LatchEventKind::Lock {
            for (f, p) in &mut self.latches {
                if p.latch == event.latch && p.lock_impulse.is_none() {
                    p.lock_impulse = Some(event.impulse);
                    p.lock_energy_lost = Some(event.energy_lost);
                    f.lock_increment = Some(increment);
                }
            }
        }
        self.unlatched(event, increment);
    }

    /// Marks the peaks of the rigid latches whose first lock was an impact
    /// (a non-zero impulse) and whose peak load came at or after it, in a
    /// model with deformable members (beams, shells): not design loads
    /// ([`LatchPeak::design_load`]). Returns a warning for each.
    pub fn mark_impact_peaks(&mut self) -> Vec<String> {
        let mut warnings = Vec::new();
        // a latch that never locked held nothing: its peak is no load of
        // a lock (the run warns of the latch itself)
        for (_, p) in &mut self.latches {
            if p.locked_at.is_none() {
                p.design_load = false;
                p.note = Some("it never locked: its peak is not the load of a lock".to_string());
            }
        }
        if !self.deformable {
            return warnings;
        }
        for (f, p) in &mut self.latches {
            let (Some(lock), Some(at), Some(impulse)) =
                (f.lock_increment, p.peak.peak_increment, p.lock_impulse)
            else {
                continue;
            };
            if p.mode != "rigid" || impulse == 0.0 || at < lock {
                continue;
            }
            let (unit, impulse_unit) = if p.quantity == "moment" {
                ("N·m", "N·m·s")
            } else {
                ("N", "N·s")
            };
            let note = format!(
                "the peak follows the rigid lock, an impact onto deformable members (impulse {impulse:.4e} {impulse_unit}, energy lost {:.4e} J, in SI units): the loads after it answer a velocity jump imposed in one step and depend on the step and on the damping of the highest modes; it is not a design load: give the latch a stiffness (mode = \"spring\") for the load the hinge carries",
                p.lock_energy_lost.unwrap_or(0.0)
            );
            warnings.push(format!(
                "latch {}: peak load {:.4e} {unit} at t = {}: {note}",
                p.latch,
                p.peak.peak_load,
                p.peak.peak_time.unwrap_or(0.0)
            ));
            p.design_load = false;
            p.note = Some(note);
        }
        warnings
    }

    /// A spring latch released at `event` (numbered across the run as
    /// `increment`): the load it carried at the release, on the state the
    /// step landed on, which [`Self::sample`] sees released (the latch
    /// reached its unlatch load there), `−(f_s(x) + d ċ)`.
    pub fn unlatched(&mut self, event: &LockInfo, increment: usize) {
        if event.kind != LatchEventKind::Unlatch {
            return;
        }
        for (f, p) in &mut self.latches {
            if let (true, Some((spring, value))) = (p.latch == event.latch, f.spring) {
                let x = event.coordinate - value;
                let load = -(spring.spring_force(x).0 + spring.dashpot(x) * event.rate_before);
                p.peak.take(load, event.time, increment);
            }
        }
    }

    /// The latches' peaks, in increasing id.
    pub fn latches(&self) -> Vec<LatchPeak> {
        self.latches.iter().map(|(_, p)| p.clone()).collect()
    }

    /// The stops' peaks (contacts excluded), in increasing id.
    pub fn stops(&self) -> Vec<StopPeak> {
        self.stops
            .iter()
            .filter(|(_, p)| p.stop.is_some())
            .map(|(_, p)| p.clone())
            .collect()
    }

    /// The contacts' peaks, in increasing id.
    pub fn contacts(&self) -> Vec<StopPeak> {
        self.stops
            .iter()
            .filter(|(_, p)| p.contact.is_some())
            .map(|(_, p)| p.clone())
            .collect()
    }
}

/// The name of the load along an angle or a length.
fn quantity(angle: bool) -> &'static str {
    if angle {
        "moment"
    } else {
        "force"
    }
}
