//! The drawn shape of a rigid body: a box, a plate, a cylinder (or a point),
//! carried by the body's node, for the VTK files and the viewer. It plays
//! no part in the mechanics, which take the body's mass and inertia alone.
//!
//! A shape lies in its own frame: centre `c` and axes `Q` (columns: the
//! shape's axes 1, 2, 3) in the node's material frame. A point `p` of the
//! shape (shape frame) is at `x + R (c + Q p)` in the global frame, `x`
//! and `R` the node's position and orientation, so the shape moves with
//! the body.
//!
//! **The shape of a body's inertia** ([`BodyShape::from_inertia`]): the box
//! of uniform density with the body's mass `m` and principal moments
//! `J₁, J₂, J₃` about its centre of mass, along the principal axes. A box
//! of edges `a₁, a₂, a₃` has `J₁ = m (a₂² + a₃²)/12` and cyclically, so
//! that `a₁² = 6 (J₂ + J₃ − J₁)/m` and cyclically. An edge whose square
//! vanishes (within [`FLAT`] of the largest) leaves a plate (one moment the
//! sum of the other two, `J₃ = J₁ + J₂`), a line (a slender rod) or a point
//! (no inertia); an inertia no body has (one moment larger than the sum of
//! the other two) gives a negative square, also taken as a zero edge.

use crate::so3::{Mat3, Vec3};

/// Facets around a cylinder: its sides are this many quadrilaterals (a
/// regular polygon of 24 sides is within 0.9 % of the circle's radius).
pub const CYLINDER_SIDES: usize = 24;

/// An edge of the box of an inertia whose square is below this fraction of
/// the largest one is taken as zero (a plate, a line or a point): the
/// round-off of `J₁ + J₂ − J₃` for a plate is a few ε of the moments.
pub const FLAT: f64 = 1e-9;

/// VTK cell type of a vertex.
pub const VTK_VERTEX: u8 = 1;
/// VTK cell type of a line.
pub const VTK_LINE: u8 = 3;
/// VTK cell type of a polygon.
pub const VTK_POLYGON: u8 = 7;
/// VTK cell type of a quadrilateral.
pub const VTK_QUAD: u8 = 9;
/// VTK cell type of a hexahedron.
pub const VTK_HEXAHEDRON: u8 = 12;

/// The solid of a [`BodyShape`], in its own frame (centred on the origin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Solid {
    /// A point: drawn as a vertex at the centre.
    Point,
    /// A segment of this length along axis 1 (a slender rod).
    Line {
        /// Length.
        length: f64,
    },
    /// A box of these edges along axes 1, 2, 3.
    Box {
        /// Edge lengths.
        size: [f64; 3],
    },
    /// A rectangular plate of these edges along axes 1 and 2, normal to
    /// axis 3; of zero thickness it is drawn as one quadrilateral.
    Plate {
        /// Edge lengths along axes 1 and 2.
        size: [f64; 2],
        /// Thickness along axis 3 (zero or positive).
        thickness: f64,
    },
    /// A circular cylinder about axis 3.
    Cylinder {
        /// Radius.
        radius: f64,
        /// Length along axis 3 (zero for a disc).
        length: f64,
    },
}

/// The drawn shape of a rigid body: a solid placed in the node's material
/// frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyShape {
    /// The solid, in the shape's frame.
    pub solid: Solid,
    /// Centre of the solid, in the node's material frame.
    pub center: Vec3,
    /// Axes of the shape (columns) in the node's material frame: a
    /// rotation matrix.
    pub axes: Mat3,
}

/// A cell of an [`Outline`]: its VTK type and its points.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OutlineCell {
    /// VTK cell type ([`VTK_VERTEX`], [`VTK_LINE`], [`VTK_POLYGON`],
    /// [`VTK_QUAD`] or [`VTK_HEXAHEDRON`]).
    pub vtk_type: u8,
    /// Indices into [`Outline::points`], in VTK's order for the type.
    pub points: Vec<usize>,
}

/// A shape as points (in the node's material frame) and the cells through
/// them.
#[derive(Clone, Debug, PartialEq)]
pub struct Outline {
    /// The points, node material frame.
    pub points: Vec<Vec3>,
    /// The cells.
    pub cells: Vec<OutlineCell>,
}

impl BodyShape {
    /// A solid at `center` with its axes along `axes` (node material
    /// frame).
    pub fn new(solid: Solid, center: Vec3, axes: Mat3) -> Self {
        Self {
            solid,
            center,
            axes,
        }
    }

    /// The box of uniform density with mass `mass` and the inertia tensor
    /// `inertia` about the centre of mass (node material frame), centred
    /// on the centre of mass `offset`, along the principal axes (the
    /// node's axes for a diagonal tensor); a plate, a line or a point when
    /// edges vanish (module documentation).
    pub fn from_inertia(mass: f64, inertia: &Mat3, offset: Vec3) -> Self {
        let diagonal = (0..3).all(|i| (0..3).all(|j| i == j || inertia[(i, j)] == 0.0));
        let (moments, mut axes) = if diagonal {
            (inertia.diagonal(), Mat3::identity())
        } else {
            let e = inertia.symmetric_eigen();
            (e.eigenvalues, e.eigenvectors)
        };
        if axes.determinant() < 0.0 {
            axes.set_column(2, &(-axes.column(2)));
        }
        // a₁² = 6 (J₂ + J₃ − J₁)/m and cyclically
        let square = |i: usize| {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            if mass > 0.0 {
                6.0 * (moments[j] + moments[k] - moments[i]) / mass
            } else {
                0.0
            }
        };
        let squares = [square(0), square(1), square(2)];
        let largest = squares.iter().fold(0.0f64, |a, &s| a.max(s));
        let edges = squares.map(|s| {
            if s > FLAT * largest && s.is_finite() {
                s.sqrt()
            } else {
                0.0
            }
        });
        let thin: Vec<usize> = (0..3).filter(|&i| edges[i] == 0.0).collect();
        // the shape's axis 3 along a vanishing edge (plate normal), axis 1
        // along the one edge left (a line): a cyclic permutation keeps the
        // axes right-handed
        let permuted = |first: usize| {
            let order = [first, (first + 1) % 3, (first + 2) % 3];
            let mut q = Mat3::zeros();
            for (c, &i) in order.iter().enumerate() {
                q.set_column(c, &axes.column(i));
            }
            (q, order.map(|i| edges[i]))
        };
        let (solid, axes) = match thin.len() {
            0 => (Solid::Box { size: edges }, axes),
            1 => {
                let (q, e) = permuted((thin[0] + 1) % 3);
                (
                    Solid::Plate {
                        size: [e[0], e[1]],
                        thickness: 0.0,
                    },
                    q,
                )
            }
            2 => {
                let long = (0..3).find(|i| !thin.contains(i)).unwrap_or(0);
                let (q, e) = permuted(long);
                (Solid::Line { length: e[0] }, q)
            }
            _ => (Solid::Point, Mat3::identity()),
        };
        Self::new(solid, offset, axes)
    }

    /// The points (node material frame) and cells that draw the shape:
    /// a vertex, a line, a hexahedron (box, thick plate), a quadrilateral
    /// (plate of zero thickness), or a cylinder as [`CYLINDER_SIDES`]
    /// quadrilaterals and two polygons (one for a disc). Faces are ordered
    /// so that their normals point out of the solid (right-hand rule).
    pub fn outline(&self) -> Outline {
        let mut local: Vec<Vec3> = Vec::new();
        let mut cells = Vec::new();
        let cell = |vtk_type: u8, points: Vec<usize>| OutlineCell { vtk_type, points };
        // the corners of a box of half-edges h: 0–3 the face at −h₃
        // counter-clockwise about axis 3, 4–7 above them (VTK_HEXAHEDRON)
        let corners = |h: [f64; 3]| -> Vec<Vec3> {
            let square = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
            [-h[2], h[2]]
                .into_iter()
                .flat_map(|z| square.map(|(s, t)| Vec3::new(s * h[0], t * h[1], z)))
                .collect()
        };
        match self.solid {
            Solid::Point => {
                local.push(Vec3::zeros());
                cells.push(cell(VTK_VERTEX, vec![0]));
            }
            Solid::Line { length } => {
                local.push(Vec3::new(-0.5 * length, 0.0, 0.0));
                local.push(Vec3::new(0.5 * length, 0.0, 0.0));
                cells.push(cell(VTK_LINE, vec![0, 1]));
            }
            Solid::Box { size } => {
                local = corners(size.map(|a| 0.5 * a));
                cells.push(cell(VTK_HEXAHEDRON, (0..8).collect()));
            }
            Solid::Plate { size, thickness } if thickness > 0.0 => {
                local = corners([0.5 * size[0], 0.5 * size[1], 0.5 * thickness]);
                cells.push(cell(VTK_HEXAHEDRON, (0..8).collect()));
            }
            Solid::Plate { size, .. } => {
                local = corners([0.5 * size[0], 0.5 * size[1], 0.0])[..4].to_vec();
                cells.push(cell(VTK_QUAD, vec![0, 1, 2, 3]));
            }
            Solid::Cylinder { radius, length } => {
                let n = CYLINDER_SIDES;
                let ring = |z: f64| {
                    (0..n).map(move |k| {
                        let a = std::f64::consts::TAU * k as f64 / n as f64;
                        Vec3::new(radius * a.cos(), radius * a.sin(), z)
                    })
                };
                if length > 0.0 {
                    local.extend(ring(-0.5 * length));
                    local.extend(ring(0.5 * length));
                    for k in 0..n {
                        let next = (k + 1) % n;
                        cells.push(cell(VTK_QUAD, vec![k, next, n + next, n + k]));
                    }
                    // the bottom face clockwise about axis 3 (normal −3),
                    // the top one counter-clockwise
                    cells.push(cell(VTK_POLYGON, (0..n).rev().collect()));
                    cells.push(cell(VTK_POLYGON, (n..2 * n).collect()));
                } else {
                    local.extend(ring(0.0));
                    cells.push(cell(VTK_POLYGON, (0..n).collect()));
                }
            }
        }
        Outline {
            points: local.iter().map(|p| self.center + self.axes * p).collect(),
            cells,
        }
    }

    /// Whether the shape is drawn as more than a vertex.
    pub fn is_solid(&self) -> bool {
        self.solid != Solid::Point
    }

    /// Points spread over the solid (node material frame), for the checks
    /// of bodies ending inside one another: the centres of the cells of a
    /// regular grid ([`SAMPLES_PER_EDGE`] along each edge of a box or a
    /// plate, rings and sectors of a cylinder), so that none lies on the
    /// solid's boundary, where bodies that touch meet.
    pub fn samples(&self) -> Vec<Vec3> {
        let n = SAMPLES_PER_EDGE;
        // cell centres of [−a/2, a/2] in n cells (one cell for a = 0)
        let centres = |a: f64, n: usize| -> Vec<f64> {
            let n = if a > 0.0 { n } else { 1 };
            (0..n)
                .map(|k| a * ((k as f64 + 0.5) / n as f64 - 0.5))
                .collect()
        };
        let grid = |a: [f64; 3]| -> Vec<Vec3> {
            let (u, v, w) = (centres(a[0], n), centres(a[1], n), centres(a[2], n));
            let mut out = Vec::with_capacity(u.len() * v.len() * w.len());
            for &z in &w {
                for &y in &v {
                    for &x in &u {
                        out.push(Vec3::new(x, y, z));
                    }
                }
            }
            out
        };
        let local = match self.solid {
            Solid::Point => vec![Vec3::zeros()],
            Solid::Line { length } => grid([length, 0.0, 0.0]),
            Solid::Box { size } => grid(size),
            Solid::Plate { size, thickness } => grid([size[0], size[1], thickness]),
            Solid::Cylinder { radius, length } => {
                let sectors = 2 * n;
                let mut out = Vec::new();
                for z in centres(length, n) {
                    for ring in 0..n / 2 {
                        let r = radius * (ring as f64 + 0.5) / (n / 2) as f64;
                        for k in 0..sectors {
                            let a = std::f64::consts::TAU * (k as f64 + 0.5) / sectors as f64;
                            out.push(Vec3::new(r * a.cos(), r * a.sin(), z));
                        }
                    }
                }
                out
            }
        };
        local.iter().map(|p| self.center + self.axes * p).collect()
    }

    /// The distance from the node to the farthest point of the solid.
    pub fn reach(&self) -> f64 {
        self.outline()
            .points
            .iter()
            .fold(0.0f64, |m, p| m.max(p.norm()))
    }

    /// Where a point `p` (node material frame) lies relative to the solid:
    /// [`Side::Inside`] its volume (boxes, thick plates, cylinders of some
    /// length: solids of no volume have no inside), or, for a plate, above
    /// or below its faces within its outline ([`Side::Above`],
    /// [`Side::Below`]); [`Side::Outside`] otherwise.
    pub fn side(&self, p: &Vec3) -> Side {
        let local = self.axes.transpose() * (p - self.center);
        let within = |x: f64, a: f64| x.abs() < 0.5 * a;
        match self.solid {
            Solid::Box { size } => {
                if (0..3).all(|i| within(local[i], size[i])) {
                    Side::Inside
                } else {
                    Side::Outside
                }
            }
            Solid::Plate { size, thickness } => {
                if !(within(local.x, size[0]) && within(local.y, size[1])) {
                    Side::Outside
                } else if local.z >= 0.5 * thickness {
                    Side::Above
                } else if local.z <= -0.5 * thickness {
                    Side::Below
                } else {
                    Side::Inside
                }
            }
            Solid::Cylinder { radius, length } => {
                if local.xy().norm() < radius && within(local.z, length) {
                    Side::Inside
                } else {
                    Side::Outside
                }
            }
            Solid::Point | Solid::Line { .. } => Side::Outside,
        }
    }
}

/// Sample points along each edge of a solid ([`BodyShape::samples`]).
pub const SAMPLES_PER_EDGE: usize = 8;

/// Where a point lies relative to a solid ([`BodyShape::side`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// Inside its volume.
    Inside,
    /// Within a plate's outline, on the side of its axis 3.
    Above,
    /// Within a plate's outline, on the other side.
    Below,
    /// Anywhere else.
    Outside,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::so3;
    use approx::assert_relative_eq;

    /// The inertia about its centre of a uniform box of `mass` with
    /// `edges` along the columns of `axes`.
    fn box_inertia(mass: f64, edges: [f64; 3], axes: &Mat3) -> Mat3 {
        let [a, b, c] = edges.map(|e| e * e);
        let principal = Mat3::from_diagonal(&Vec3::new(b + c, a + c, a + b)) * (mass / 12.0);
        axes * principal * axes.transpose()
    }

    /// The box of a box's inertia is that box, in any orientation: its
    /// edges to round-off, its axes along the box's (up to their sign),
    /// and its inertia the same tensor.
    #[test]
    fn the_box_of_a_boxs_inertia_is_that_box() {
        let edges = [0.3, 0.12, 0.05];
        let mass = 2.5;
        for psi in [
            Vec3::zeros(),
            Vec3::new(0.3, -0.7, 1.1),
            Vec3::new(0.0, 0.0, 0.4),
        ] {
            let axes = so3::exp_matrix(&psi);
            let j = box_inertia(mass, edges, &axes);
            let offset = Vec3::new(0.1, 0.0, -0.2);
            let shape = BodyShape::from_inertia(mass, &j, offset);
            let Solid::Box { size } = shape.solid else {
                panic!("{:?}", shape.solid)
            };
            // the same inertia from the shape found (edges and axes
            // together, whatever their order)
            assert_relative_eq!(
                box_inertia(mass, size, &shape.axes),
                j,
                max_relative = 1e-12,
                epsilon = 1e-15
            );
            let mut found = size;
            found.sort_by(|a, b| b.total_cmp(a));
            for (f, e) in found.iter().zip(edges) {
                assert_relative_eq!(*f, e, max_relative = 1e-12);
            }
            assert_relative_eq!(shape.axes.determinant(), 1.0, epsilon = 1e-12);
            assert_eq!(shape.center, offset);
        }
        // a diagonal tensor keeps the node's axes and their order
        let j = box_inertia(mass, edges, &Mat3::identity());
        let shape = BodyShape::from_inertia(mass, &j, Vec3::zeros());
        assert_eq!(shape.axes, Mat3::identity());
        let Solid::Box { size } = shape.solid else {
            panic!()
        };
        for (f, e) in size.iter().zip(edges) {
            assert_relative_eq!(*f, e, max_relative = 1e-12);
        }
    }

    /// A plate's moments (`J₃ = J₁ + J₂`) give a plate of zero thickness
    /// normal to the axis of the largest moment; a rod's a line along its
    /// axis; no inertia a point.
    #[test]
    fn plates_rods_and_points_from_their_inertia() {
        let (m, a, b) = (1.5, 0.8, 0.5);
        // the plate in the node's 2–3 plane: normal along node axis 1
        let j = Mat3::from_diagonal(&Vec3::new(a * a + b * b, b * b, a * a)) * (m / 12.0);
        let shape = BodyShape::from_inertia(m, &j, Vec3::zeros());
        let Solid::Plate { size, thickness } = shape.solid else {
            panic!("{:?}", shape.solid)
        };
        assert_eq!(thickness, 0.0);
        assert_relative_eq!(shape.axes.column(2).into_owned(), Vec3::x());
        // edges along the shape's axes 1 and 2: node axes 2 and 3
        assert_relative_eq!(size[0], a, max_relative = 1e-12);
        assert_relative_eq!(size[1], b, max_relative = 1e-12);
        assert_relative_eq!(shape.axes.column(0).into_owned(), Vec3::y());
        let outline = shape.outline();
        assert_eq!(outline.cells.len(), 1);
        assert_eq!(outline.cells[0].vtk_type, VTK_QUAD);

        // a rod of length 2 along node axis 2
        let j = Mat3::from_diagonal(&Vec3::new(4.0, 0.0, 4.0)) * (m / 12.0);
        let shape = BodyShape::from_inertia(m, &j, Vec3::zeros());
        assert_eq!(shape.solid, Solid::Line { length: 2.0 });
        assert_relative_eq!(shape.axes.column(0).into_owned(), Vec3::y());

        // no inertia: a point, drawn as a vertex
        let shape = BodyShape::from_inertia(m, &Mat3::zeros(), Vec3::x());
        assert_eq!(shape.solid, Solid::Point);
        assert!(!shape.is_solid());
        assert_eq!(shape.outline().cells[0].vtk_type, VTK_VERTEX);
        assert_eq!(shape.outline().points, vec![Vec3::x()]);
    }

    /// The faces of a box and of a cylinder point out of the solid: the
    /// normal of each face (right-hand rule on its points, for the
    /// hexahedron VTK's face list) is along the direction from the centre
    /// to the face's centre.
    #[test]
    fn faces_point_outwards() {
        let normal = |p: &[Vec3]| {
            let mut n = Vec3::zeros();
            for k in 0..p.len() {
                n += p[k].cross(&p[(k + 1) % p.len()]);
            }
            n
        };
        let centre = |p: &[Vec3]| p.iter().sum::<Vec3>() / p.len() as f64;
        let shape = BodyShape::new(
            Solid::Cylinder {
                radius: 0.2,
                length: 0.5,
            },
            Vec3::new(1.0, 2.0, 3.0),
            so3::exp_matrix(&Vec3::new(0.2, 0.5, -0.3)),
        );
        let outline = shape.outline();
        assert_eq!(outline.cells.len(), CYLINDER_SIDES + 2);
        for c in &outline.cells {
            let p: Vec<Vec3> = c.points.iter().map(|&i| outline.points[i]).collect();
            let out = centre(&p) - shape.center;
            assert!(normal(&p).dot(&out) > 0.0, "{c:?}");
        }
        // the hexahedron's faces, as VTK lists them (vtkHexahedron)
        let shape = BodyShape::new(
            Solid::Box {
                size: [0.3, 0.2, 0.1],
            },
            Vec3::zeros(),
            Mat3::identity(),
        );
        let outline = shape.outline();
        let faces = [
            [0, 4, 7, 3],
            [1, 2, 6, 5],
            [0, 1, 5, 4],
            [3, 7, 6, 2],
            [0, 3, 2, 1],
            [4, 5, 6, 7],
        ];
        for f in faces {
            let p: Vec<Vec3> = f.iter().map(|&i| outline.points[i]).collect();
            assert!(normal(&p).dot(&centre(&p)) > 0.0, "{f:?}");
        }
    }
}
