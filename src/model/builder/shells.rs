//! Ply materials, laminates, shells and panels.
//!
//! ```
//! use unfold::model::builder::*;
//!
//! // a 1 m × 0.8 m sandwich panel: aluminium faces on a honeycomb core,
//! // clamped along its west side, under a pressure of 100 Pa
//! let mut m = ModelBuilder::new("panel");
//! let al = m.add(PlyMaterial::isotropic(70e9, 0.33).density(2800.0));
//! let face = m.add(Laminate::plies([(al, 0.3e-3, 0.0)]));
//! let core = Core::new(20e-3, 190e6, 90e6).density(32.0);
//! let sandwich = m.add(Laminate::sandwich(face, core, face));
//! let panel = m.add(Panel::new([1.0, 0.8], [10, 8], sandwich).pressure(100.0));
//! for n in panel.side(PanelSide::West) {
//!     m.fix(n, Dofs::ALL);
//! }
//! let model = m.build().unwrap();
//! assert_eq!(model.n_nodes(), 11 * 9);
//! // the named nodes, for joints
//! let corner = panel.point(PanelPoint::NorthEast);
//! assert_eq!(model.reference_position(corner).x, 1.0);
//! assert_eq!(model.reference_position(panel.point(PanelPoint::East)).y, 0.4);
//! ```

use super::{CurveHandle, Entity, ModelBuilder, SectionHandle};
use crate::model::handles::{BeamHandle, NodeHandle, PanelHandle, ShellHandle};
use crate::model::input::{
    AngleUnit, CoreInput, LaminateInput, PanelInput, PanelNodeIds, PanelPoint, PanelSide,
    PanelZoneInput, PlyInput, PlyMaterialInput, ShellInput, StiffenerInput,
};
use crate::model::Id;

/// A ply material: orthotropic (a unidirectional lamina) or isotropic.
#[derive(Clone, Debug, PartialEq)]
pub struct PlyMaterial {
    input: PlyMaterialInput,
}

/// A ply material of the model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PlyMaterialHandle(usize);

impl PlyMaterial {
    /// An orthotropic material: moduli `E₁` (fibres), `E₂`, Poisson's
    /// ratio `ν₁₂`, shear moduli `G₁₂`, `G₁₃`, `G₂₃`.
    pub fn orthotropic(e1: f64, e2: f64, nu12: f64, g12: f64, g13: f64, g23: f64) -> Self {
        Self {
            input: PlyMaterialInput {
                e1: Some(e1),
                e2: Some(e2),
                nu12: Some(nu12),
                g12: Some(g12),
                g13: Some(g13),
                g23: Some(g23),
                ..PlyMaterialInput::default()
            },
        }
    }

    /// An isotropic material of Young's modulus `e` and Poisson's ratio
    /// `nu`.
    pub fn isotropic(e: f64, nu: f64) -> Self {
        Self {
            input: PlyMaterialInput {
                e: Some(e),
                nu: Some(nu),
                ..PlyMaterialInput::default()
            },
        }
    }

    /// Its density (mass per volume).
    pub fn density(mut self, density: f64) -> Self {
        self.input.density = Some(density);
        self
    }

    /// Its name in the model file (default `ply_material_N`).
    pub fn named(mut self, name: impl Into<String>) -> Self {
        self.input.name = name.into();
        self
    }
}

impl Entity for PlyMaterial {
    type Handle = PlyMaterialHandle;
    fn add_to(mut self, m: &mut ModelBuilder) -> PlyMaterialHandle {
        let k = m.input.ply_materials.len();
        if self.input.name.is_empty() {
            self.input.name = format!("ply_material_{}", k + 1);
        }
        m.input.ply_materials.push(self.input);
        PlyMaterialHandle(k)
    }
}

/// The core of a sandwich.
#[derive(Clone, Debug, PartialEq)]
pub struct Core {
    input: CoreInput,
}

impl Core {
    /// A core of `thickness` with transverse shear moduli `g13` (its
    /// direction 1, a honeycomb's ribbon direction) and `g23`.
    pub fn new(thickness: f64, g13: f64, g23: f64) -> Self {
        Self {
            input: CoreInput {
                thickness,
                g13,
                g23,
                ..CoreInput::default()
            },
        }
    }

    /// Its density.
    pub fn density(mut self, density: f64) -> Self {
        self.input.density = Some(density);
        self
    }

    /// Its in-plane modulus and Poisson's ratio (a foam; zero for a
    /// honeycomb by default).
    pub fn in_plane(mut self, e: f64, nu: f64) -> Self {
        self.input.e = Some(e);
        self.input.nu = Some(nu);
        self
    }

    /// The angle of its direction 1 from the shell's material axis (in
    /// the laminate's unit).
    pub fn angle(mut self, angle: f64) -> Self {
        self.input.angle = Some(angle);
        self
    }
}

/// A laminate: a stack of plies, or a sandwich.
#[derive(Clone, Debug, PartialEq)]
pub struct Laminate {
    plies: Vec<(PlyMaterialHandle, f64, f64)>,
    sandwich: Option<(LaminateHandle, Core, LaminateHandle)>,
    unit: Option<AngleUnit>,
    name: String,
}

/// A laminate of the model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LaminateHandle(usize);

impl Laminate {
    /// A stack of plies `(material, thickness, angle)` from the bottom up,
    /// angles in radians (see [`Laminate::unit`]).
    pub fn plies(plies: impl IntoIterator<Item = (PlyMaterialHandle, f64, f64)>) -> Self {
        Self {
            plies: plies.into_iter().collect(),
            sandwich: None,
            unit: None,
            name: String::new(),
        }
    }

    /// A sandwich: the face sheets `bottom` and `top` (stacks, each listed
    /// from the core outward) on `core`.
    pub fn sandwich(bottom: LaminateHandle, core: Core, top: LaminateHandle) -> Self {
        Self {
            plies: Vec::new(),
            sandwich: Some((bottom, core, top)),
            unit: None,
            name: String::new(),
        }
    }

    /// The unit of its angles (radians by default).
    pub fn unit(mut self, unit: AngleUnit) -> Self {
        self.unit = Some(unit);
        self
    }

    /// Its name in the model file (default `laminate_N`).
    pub fn named(mut self, name: impl Into<String>) -> Self {
        self.name = name.into();
        self
    }
}

impl Entity for Laminate {
    type Handle = LaminateHandle;
    fn add_to(self, m: &mut ModelBuilder) -> LaminateHandle {
        let k = m.input.laminates.len();
        let name = if self.name.is_empty() {
            format!("laminate_{}", k + 1)
        } else {
            self.name
        };
        let plies = self
            .plies
            .iter()
            .map(|&(material, thickness, angle)| PlyInput {
                material: m.input.ply_materials[material.0].name.clone(),
                thickness,
                angle: Some(angle),
            })
            .collect();
        let (core, bottom_face, top_face) = match self.sandwich {
            Some((b, core, t)) => (
                Some(core.input),
                Some(m.laminate_name(b)),
                Some(m.laminate_name(t)),
            ),
            None => (None, None, None),
        };
        m.input.laminates.push(LaminateInput {
            name,
            plies,
            core,
            faces: None,
            bottom_face,
            top_face,
            unit: self.unit,
        });
        LaminateHandle(k)
    }
}

impl ModelBuilder {
    /// The name of a laminate in the model file.
    fn laminate_name(&self, l: LaminateHandle) -> String {
        self.input.laminates[l.0].name.clone()
    }
}

/// A four-node shell element.
#[derive(Clone, Debug, PartialEq)]
pub struct Shell {
    nodes: [NodeHandle; 4],
    laminate: LaminateHandle,
    material_axis: Option<[f64; 3]>,
    pressure: Option<f64>,
    pressure_curve: Option<CurveHandle>,
    id: Option<Id>,
}

impl Shell {
    /// A shell of `laminate` on four nodes listed in order around it (its
    /// normal follows them by the right-hand rule).
    pub fn new(nodes: [NodeHandle; 4], laminate: LaminateHandle) -> Self {
        Self {
            nodes,
            laminate,
            material_axis: None,
            pressure: None,
            pressure_curve: None,
            id: None,
        }
    }

    /// The direction whose projection on the element is its material axis
    /// (default global x, or y for an element normal to x).
    pub fn material_axis(mut self, axis: impl Into<[f64; 3]>) -> Self {
        self.material_axis = Some(axis.into());
        self
    }

    /// A load per unit area along its normal, following the default curve
    /// of loads unless [`Shell::pressure_curve`] is given.
    pub fn pressure(mut self, p: f64) -> Self {
        self.pressure = Some(p);
        self
    }

    /// The curve of its pressure.
    pub fn pressure_curve(mut self, curve: CurveHandle) -> Self {
        self.pressure_curve = Some(curve);
        self
    }

    /// Its id (default: the next free element id).
    pub fn id(mut self, id: Id) -> Self {
        self.id = Some(id);
        self
    }
}

impl Entity for Shell {
    type Handle = ShellHandle;
    fn add_to(self, m: &mut ModelBuilder) -> ShellHandle {
        let id = m.element_id(self.id, 1);
        let input = ShellInput {
            id,
            nodes: self.nodes.map(|n| n.0),
            laminate: m.laminate_name(self.laminate),
            material_axis: self.material_axis,
            pressure: self.pressure,
            pressure_curve: self.pressure_curve.map(|c| m.curve_name(c)),
        };
        m.input.shells.push(input);
        ShellHandle(id)
    }
}

/// A flat rectangular panel meshed into shells (docs/model-format.md,
/// `[[panels]]`): `size = [a, b]`, `elements = [nx, ny]` (both even).
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    size: [f64; 2],
    elements: [usize; 2],
    laminate: LaminateHandle,
    origin: Option<[f64; 3]>,
    axes: Option<([f64; 3], [f64; 3])>,
    zones: Vec<([f64; 2], [f64; 2], LaminateHandle)>,
    stiffeners: Vec<(PanelSide, SectionHandle, f64)>,
    pressure: Option<f64>,
    pressure_curve: Option<CurveHandle>,
    node_ids: PanelNodeIds,
    name: String,
}

impl Panel {
    /// A panel of sides `size = [a, b]` along global x and y from the
    /// origin, `elements = [nx, ny]` shells of `laminate`.
    pub fn new(size: [f64; 2], elements: [usize; 2], laminate: LaminateHandle) -> Self {
        Self {
            size,
            elements,
            laminate,
            origin: None,
            axes: None,
            zones: Vec::new(),
            stiffeners: Vec::new(),
            pressure: None,
            pressure_curve: None,
            node_ids: PanelNodeIds::default(),
            name: String::new(),
        }
    }

    /// Its corner `south_west`.
    pub fn origin(mut self, x: impl Into<[f64; 3]>) -> Self {
        self.origin = Some(x.into());
        self
    }

    /// The direction of side `a` (its material axis too) and a direction
    /// in its plane across it (side `b` is its part normal to `a`).
    pub fn axes(mut self, a: impl Into<[f64; 3]>, b: impl Into<[f64; 3]>) -> Self {
        self.axes = Some((a.into(), b.into()));
        self
    }

    /// A zone `[from, to]` (panel coordinates) of `laminate`; later zones
    /// override earlier ones.
    pub fn zone(mut self, from: [f64; 2], to: [f64; 2], laminate: LaminateHandle) -> Self {
        self.zones.push((from, to, laminate));
        self
    }

    /// A stiffener of `section` along `side`, its axis at `offset` from
    /// the mid-surface along the normal.
    pub fn stiffener(mut self, side: PanelSide, section: SectionHandle, offset: f64) -> Self {
        self.stiffeners.push((side, section, offset));
        self
    }

    /// A load per unit area along its normal `a × b`.
    pub fn pressure(mut self, p: f64) -> Self {
        self.pressure = Some(p);
        self
    }

    /// The curve of its pressure.
    pub fn pressure_curve(mut self, curve: CurveHandle) -> Self {
        self.pressure_curve = Some(curve);
        self
    }

    /// The id of a named node (default: its grid id).
    pub fn node_id(mut self, point: PanelPoint, id: Id) -> Self {
        self.node_ids.set(point, id);
        self
    }

    /// Its name in messages (default `panel_N`).
    pub fn named(mut self, name: impl Into<String>) -> Self {
        self.name = name.into();
        self
    }
}

impl Entity for Panel {
    type Handle = PanelHandle;
    fn add_to(self, m: &mut ModelBuilder) -> PanelHandle {
        let k = m.input.panels.len();
        let [nx, ny] = self.elements;
        let name = if self.name.is_empty() {
            format!("panel_{}", k + 1)
        } else {
            self.name
        };
        for p in PanelPoint::ALL {
            if let Some(id) = self.node_ids.get(p) {
                m.node_id(Some(id), 1);
            }
        }
        let first_node = m.node_id(None, (nx + 1).saturating_mul(ny + 1));
        let beams: Vec<usize> = self
            .stiffeners
            .iter()
            .map(|(side, ..)| match side {
                PanelSide::South | PanelSide::North => nx,
                PanelSide::East | PanelSide::West => ny,
            })
            .collect();
        let shells = nx.saturating_mul(ny);
        let first_element = m.element_id(None, shells + beams.iter().sum::<usize>());
        let input = PanelInput {
            name,
            size: self.size,
            elements: self.elements,
            laminate: m.laminate_name(self.laminate),
            origin: self.origin,
            axis_a: self.axes.map(|a| a.0),
            axis_b: self.axes.map(|a| a.1),
            zones: self
                .zones
                .iter()
                .map(|(from, to, l)| PanelZoneInput {
                    from: *from,
                    to: *to,
                    laminate: m.laminate_name(*l),
                })
                .collect(),
            stiffeners: self
                .stiffeners
                .iter()
                .map(|(side, section, offset)| StiffenerInput {
                    side: *side,
                    section: m.section_name(*section),
                    offset: Some(*offset),
                })
                .collect(),
            pressure: self.pressure,
            pressure_curve: self.pressure_curve.map(|c| m.curve_name(c)),
            first_node: Some(first_node),
            first_element: Some(first_element),
            node_ids: (self.node_ids != PanelNodeIds::default()).then_some(self.node_ids.clone()),
        };
        m.input.panels.push(input);
        let mut next = first_element + shells as Id;
        let stiffeners = beams
            .iter()
            .map(|&n| {
                let line = (0..n as Id).map(|i| BeamHandle(next + i)).collect();
                next += n as Id;
                line
            })
            .collect();
        PanelHandle {
            elements: self.elements,
            first_node,
            named: PanelPoint::ALL.map(|p| self.node_ids.get(p)),
            shells: (0..shells as Id)
                .map(|i| ShellHandle(first_element + i))
                .collect(),
            stiffeners,
        }
    }
}
