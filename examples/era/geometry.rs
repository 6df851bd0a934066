//! The geometry of the cells: the plan layout of the longerons and faces
//! (one cell, or the hexagon of 24 cells), and every hinge point in a
//! configuration between folded and deployed.
//!
//! The mechanism has one degree of freedom (`examples/era.md`): in each
//! face the hinges of the top horizontal are vertical and those of the
//! bottom one normal to the face, so that the two longerons of a face
//! can only move apart along the face, without turning. Its
//! configurations are the deployed layout scaled towards the centre by
//! `s` (`s = 1` deployed), every longeron keeping its orientation; every
//! face is then in the same state, so that one opening angle of the
//! mid-hinges corresponds to one scale ([`Geometry::scale_at`]).
//!
//! Frames: `z` is the longeron direction (up); the bottom corner bodies'
//! centres are at `z = 0`, the top ones' at `z = h`.

use std::f64::consts::PI;

use unfold::so3::Vec3;

use super::design::Design;

/// A face: two longerons and the members between them (a top and a
/// bottom horizontal, two diagonals), shared by the cells on either side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Face {
    /// The longerons at its ends, `a` then `b`.
    pub columns: [usize; 2],
    /// The side its mid-hinges fold to: `+1` to the left of `a → b` seen
    /// from above, `−1` to the right.
    pub fold: f64,
    /// Whether it lies on the outline (it belongs to one cell only).
    pub boundary: bool,
}

/// The plan of a set of triangular cells side by side.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    /// Plan positions of the longeron axes, deployed (m), centred on the
    /// origin; a hexagon's central longeron first.
    pub columns: Vec<[f64; 2]>,
    /// Faces.
    pub faces: Vec<Face>,
    /// Cells: their three longerons, counter-clockwise.
    pub cells: Vec<[usize; 3]>,
}

/// Which structure.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Structure {
    /// One cell.
    Cell,
    /// A hexagon of triangular cells whose side is `rings` cell widths:
    /// `6 rings²` cells (24 for the platform of the paper, `rings = 2`).
    Hexagon {
        /// Cell widths per side of the hexagon.
        rings: i32,
    },
    /// A triangle of triangular cells whose side is `rings` cell widths:
    /// `rings²` cells (4 for `rings = 2`: three cells around a central
    /// one, each sharing a face with it).
    Triangle {
        /// Cell widths per side of the triangle.
        rings: i32,
    },
}

impl Structure {
    /// The ERA platform: 24 cells in a hexagon of side two cell widths.
    pub const PLATFORM: Self = Self::Hexagon { rings: 2 };

    /// The platform reduced: 4 cells in a triangle of side two cell
    /// widths, three around a central one (the same faces shared, every
    /// longeron but the corners' carrying three or four faces).
    pub const REDUCED: Self = Self::Triangle { rings: 2 };

    /// A name for files and titles.
    pub fn name(self) -> String {
        match self {
            Self::Cell => "cell".into(),
            Self::PLATFORM => "platform".into(),
            Self::Hexagon { rings } => format!("hexagon{rings}"),
            Self::Triangle { rings } => format!("triangle{rings}"),
        }
    }
}

impl Layout {
    /// The layout of `structure` for cells of side `side`.
    pub fn new(structure: Structure, side: f64) -> Self {
        match structure {
            Structure::Cell => Self::cell(side),
            Structure::Hexagon { rings } => Self::hexagon(side, rings),
            Structure::Triangle { rings } => Self::triangle(side, rings),
        }
    }

    /// One cell: an equilateral triangle of side `side` centred on the
    /// origin; its mid-hinges fold outwards.
    pub fn cell(side: f64) -> Self {
        let r = side / 3f64.sqrt();
        let columns = (0..3)
            .map(|k| {
                let a = PI / 2.0 + 2.0 * PI * k as f64 / 3.0;
                [r * a.cos(), r * a.sin()]
            })
            .collect();
        // counter-clockwise: the left of each face is the inside
        let faces = (0..3)
            .map(|k| Face {
                columns: [k, (k + 1) % 3],
                fold: -1.0,
                boundary: true,
            })
            .collect();
        Self {
            columns,
            faces,
            cells: vec![[0, 1, 2]],
        }
    }

    /// The hexagon of side `rings` cell widths on the triangular lattice
    /// of spacing `side`: longerons at `side (i + j/2, j √3/2)` with
    /// `|i|, |j|, |i + j| ≤ rings`. Boundary faces fold outwards, the
    /// others to the left of the face directed from its lower-numbered
    /// longeron to the other.
    pub fn hexagon(side: f64, rings: i32) -> Self {
        let n = rings;
        let inside = |i: i32, j: i32| i.abs() <= n && j.abs() <= n && (i + j).abs() <= n;
        let mut lattice = Vec::new();
        for j in -n..=n {
            for i in -n..=n {
                if inside(i, j) {
                    lattice.push((i, j));
                }
            }
        }
        // by rings about the centre, so that the central longeron comes
        // first (the one clamped)
        lattice.sort_by_key(|&(i, j)| i.abs().max(j.abs()).max((i + j).abs()));
        Self::lattice(side, &lattice)
    }

    /// The triangle of side `rings` cell widths on the triangular lattice
    /// of spacing `side`: longerons at `side (i + j/2, j √3/2)` with
    /// `i, j ≥ 0`, `i + j ≤ rings`, centred on the origin; the longeron
    /// nearest the centre first (the one clamped). Faces fold as in
    /// [`Layout::hexagon`].
    pub fn triangle(side: f64, rings: i32) -> Self {
        let n = rings;
        let mut lattice = Vec::new();
        for j in 0..=n {
            for i in 0..=n - j {
                lattice.push((i, j));
            }
        }
        // distance from the centroid (n/3, n/3), in units of side²/3
        let distance = |&(i, j): &(i32, i32)| {
            let (x, y) = (3 * i - n, 3 * j - n);
            x * x + x * y + y * y
        };
        lattice.sort_by_key(distance);
        let mut layout = Self::lattice(side, &lattice);
        let centre = layout.columns.iter().fold([0.0, 0.0], |c, p| {
            let k = lattice.len() as f64;
            [c[0] + p[0] / k, c[1] + p[1] / k]
        });
        for p in &mut layout.columns {
            *p = [p[0] - centre[0], p[1] - centre[1]];
        }
        layout
    }

    /// The cells and faces of the longerons at the lattice points
    /// `lattice` (`(i, j)` at `side (i + j/2, j √3/2)`): every triangle
    /// of neighbouring points is a cell.
    fn lattice(side: f64, lattice: &[(i32, i32)]) -> Self {
        let n = lattice
            .iter()
            .map(|&(i, j)| i.abs().max(j.abs()))
            .max()
            .unwrap_or(0);
        let index = |i: i32, j: i32| lattice.iter().position(|&p| p == (i, j));
        let columns = lattice
            .iter()
            .map(|&(i, j)| {
                let (i, j) = (i as f64, j as f64);
                [side * (i + 0.5 * j), side * 0.5 * 3f64.sqrt() * j]
            })
            .collect();
        // cells: (i, j), (i+1, j), (i, j+1) pointing up and (i+1, j),
        // (i+1, j+1), (i, j+1) pointing down, counter-clockwise, each with
        // its three longerons inside (a down cell's anchor (i, j) may lie
        // outside: `6 rings²` cells in all)
        let mut cells = Vec::new();
        for j in -n - 1..=n {
            for i in -n - 1..=n {
                let up = [index(i, j), index(i + 1, j), index(i, j + 1)];
                let down = [index(i + 1, j), index(i + 1, j + 1), index(i, j + 1)];
                for t in [up, down] {
                    if let [Some(a), Some(b), Some(c)] = t {
                        cells.push([a, b, c]);
                    }
                }
            }
        }
        // faces: the edges of the cells, each once, with the cells on it
        let mut edges: Vec<([usize; 2], Vec<usize>)> = Vec::new();
        for (c, cell) in cells.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (cell[k], cell[(k + 1) % 3]);
                let key = [a.min(b), a.max(b)];
                match edges.iter_mut().find(|e| e.0 == key) {
                    Some(e) => e.1.push(c),
                    None => edges.push((key, vec![c])),
                }
            }
        }
        let mut layout = Self {
            columns,
            faces: Vec::new(),
            cells,
        };
        layout.faces = edges
            .iter()
            .map(|(key, on)| {
                let boundary = on.len() == 1;
                let fold = if boundary {
                    // away from the cell's centre
                    let centre = layout.centroid(on[0]);
                    let (a, b) = (layout.columns[key[0]], layout.columns[key[1]]);
                    let left = [-(b[1] - a[1]), b[0] - a[0]];
                    let out = [a[0] - centre[0], a[1] - centre[1]];
                    if left[0] * out[0] + left[1] * out[1] > 0.0 {
                        1.0
                    } else {
                        -1.0
                    }
                } else {
                    1.0
                };
                Face {
                    columns: *key,
                    fold,
                    boundary,
                }
            })
            .collect();
        layout
    }

    /// Plan centroid of cell `c`.
    pub fn centroid(&self, c: usize) -> [f64; 2] {
        let p = self.cells[c].map(|k| self.columns[k]);
        [
            (p[0][0] + p[1][0] + p[2][0]) / 3.0,
            (p[0][1] + p[1][1] + p[2][1]) / 3.0,
        ]
    }

    /// Faces at longeron `k`.
    pub fn faces_at(&self, k: usize) -> usize {
        self.faces.iter().filter(|f| f.columns.contains(&k)).count()
    }
}

/// The hinge points of a face in one configuration (global coordinates).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FacePoints {
    /// Corner hinges of the top horizontal, at longerons `a` and `b`.
    pub top: [Vec3; 2],
    /// The top mid-hinge.
    pub top_mid: Vec3,
    /// Corner hinges of the bottom horizontal.
    pub bottom: [Vec3; 2],
    /// The bottom mid-hinge.
    pub bottom_mid: Vec3,
    /// Bottom hinges of the diagonals (their top ends are at the top
    /// mid-hinge): on the bottom corner bodies, on the vertical through
    /// the top horizontal's corner hinges.
    pub diagonal: [Vec3; 2],
}

/// One configuration of the structure.
#[derive(Clone, Debug, PartialEq)]
pub struct Configuration {
    /// The scale of the layout (1 deployed).
    pub scale: f64,
    /// Plan positions of the longeron axes.
    pub columns: Vec<[f64; 2]>,
    /// Hinge points of every face.
    pub faces: Vec<FacePoints>,
    /// Opening angle of every mid-hinge (rad; equal in every face).
    pub opening: f64,
}

/// The design applied to a layout.
#[derive(Clone, Debug)]
pub struct Geometry {
    /// Which structure ("cell", "platform").
    pub name: String,
    /// Dimensions.
    pub design: Design,
    /// Plan.
    pub layout: Layout,
    /// Length of a half horizontal, between its corner hinge and its
    /// mid-hinge (m).
    pub half_length: f64,
}

fn v(p: [f64; 2], z: f64) -> Vec3 {
    Vec3::new(p[0], p[1], z)
}

fn direction(angle: f64) -> [f64; 2] {
    [angle.cos(), angle.sin()]
}

impl Geometry {
    /// `design` on the layout of `structure`.
    pub fn new(design: &Design, structure: Structure) -> Self {
        let mut g = Self {
            name: structure.name(),
            design: design.clone(),
            layout: Layout::new(structure, design.side),
            half_length: 0.0,
        };
        // every face has the same deployed chord
        let [p, q] = g.clevises(&g.layout.columns, 0, Clevis::Top);
        g.half_length = 0.5 * (q - p).norm();
        g
    }

    /// Unit normal of face `f` in plan, to the left of `a → b` seen from
    /// above (horizontal; the same in every configuration, since the
    /// configurations scale the layout).
    pub fn face_normal(&self, f: usize) -> Vec3 {
        let [a, b] = self.layout.faces[f].columns;
        let (pa, pb) = (self.layout.columns[a], self.layout.columns[b]);
        let t = Vec3::new(pb[0] - pa[0], pb[1] - pa[1], 0.0).normalize();
        Vec3::new(-t.y, t.x, 0.0)
    }

    /// The two clevis points of `kind` on face `f` (at longerons `a` and
    /// `b`) with the longerons at `columns`: at the clevis radius from
    /// each longeron's axis towards the other longeron (the corner bodies
    /// never turn, so that these directions are those of the deployed
    /// layout).
    fn clevises(&self, columns: &[[f64; 2]], f: usize, kind: Clevis) -> [Vec3; 2] {
        let d = &self.design;
        let [a, b] = self.layout.faces[f].columns;
        let (pa, pb) = (self.layout.columns[a], self.layout.columns[b]);
        let theta = (pb[1] - pa[1]).atan2(pb[0] - pa[0]);
        let z = match kind {
            Clevis::Top => d.height,
            Clevis::Bottom => 0.0,
            Clevis::Diagonal => d.diagonal_clevis_height,
        };
        let at = |column: [f64; 2], angle: f64| {
            let e = direction(angle);
            v(
                [
                    column[0] + d.clevis_radius * e[0],
                    column[1] + d.clevis_radius * e[1],
                ],
                z,
            )
        };
        [at(columns[a], theta), at(columns[b], theta + PI)]
    }

    /// The mid-hinge of a horizontal between the corner hinges `p` and
    /// `q`, at a half length from both: for the top horizontal in the
    /// horizontal plane on the side `fold` of `p → q` (seen from above),
    /// for the bottom one in the face plane, above the chord.
    fn mid_hinge(&self, p: Vec3, q: Vec3, fold: f64, top: bool) -> Vec3 {
        let chord = q - p;
        let w = chord.norm();
        let rise = (self.half_length * self.half_length - 0.25 * w * w)
            .max(0.0)
            .sqrt();
        let out = if top {
            fold * Vec3::new(-chord.y, chord.x, 0.0) / w
        } else {
            Vec3::new(0.0, 0.0, 1.0)
        };
        0.5 * (p + q) + rise * out
    }

    /// The configuration at scale `s`.
    pub fn at(&self, s: f64) -> Configuration {
        let columns: Vec<[f64; 2]> = self
            .layout
            .columns
            .iter()
            .map(|c| [s * c[0], s * c[1]])
            .collect();
        let faces: Vec<FacePoints> = (0..self.layout.faces.len())
            .map(|f| {
                let fold = self.layout.faces[f].fold;
                let top = self.clevises(&columns, f, Clevis::Top);
                let bottom = self.clevises(&columns, f, Clevis::Bottom);
                FacePoints {
                    top,
                    top_mid: self.mid_hinge(top[0], top[1], fold, true),
                    bottom,
                    bottom_mid: self.mid_hinge(bottom[0], bottom[1], fold, false),
                    diagonal: self.clevises(&columns, f, Clevis::Diagonal),
                }
            })
            .collect();
        let chord = (faces[0].top[1] - faces[0].top[0]).norm();
        Configuration {
            scale: s,
            columns,
            faces,
            opening: self.opening_at_chord(chord),
        }
    }

    /// The deployed configuration.
    pub fn deployed(&self) -> Configuration {
        self.at(1.0)
    }

    /// The folded configuration.
    pub fn folded(&self) -> Configuration {
        self.at(self.design.folded_scale)
    }

    /// Opening angle of a mid-hinge whose horizontal spans `chord`:
    /// `γ = 2 asin(w / 2l)`.
    fn opening_at_chord(&self, chord: f64) -> f64 {
        2.0 * (0.5 * chord / self.half_length).min(1.0).asin()
    }

    /// The scale at which the mid-hinges are open by `gamma`: the chord
    /// `w = 2 l sin(γ/2)` of a face whose longerons are `s a` apart is
    /// `w = s a − 2 r` (the clevises at radius `r` on the face line).
    pub fn scale_at(&self, gamma: f64) -> f64 {
        let d = &self.design;
        let w = 2.0 * self.half_length * (0.5 * gamma).sin();
        (w + 2.0 * d.clevis_radius) / d.side
    }

    /// The signed angle from `u` to `w` about the unit vector `axis`
    /// (rad).
    fn signed_angle(u: Vec3, w: Vec3, axis: Vec3) -> f64 {
        u.cross(&w).dot(&axis).atan2(u.dot(&w))
    }

    /// The axis of the hinges of the top horizontal of face `f` (the
    /// vertical: its halves fold in plan) or of the bottom one (the face
    /// normal: its halves fold in the face plane).
    pub fn hinge_axis(&self, f: usize, top: bool) -> Vec3 {
        if top {
            Vec3::new(0.0, 0.0, 1.0)
        } else {
            self.face_normal(f)
        }
    }

    /// The sense of [`Geometry::hinge_axis`] about which the second half
    /// of a horizontal turns, relative to the first, when its mid-hinge
    /// opens: `+1` or `−1`. Measured in the folded configuration (in the
    /// deployed one the halves are aligned).
    pub fn opening_sense(&self, f: usize, top: bool) -> f64 {
        let c = self.folded();
        let face = &c.faces[f];
        let (p, q, m) = if top {
            (face.top[0], face.top[1], face.top_mid)
        } else {
            (face.bottom[0], face.bottom[1], face.bottom_mid)
        };
        Self::signed_angle(p - m, q - m, self.hinge_axis(f, top)).signum()
    }

    /// Length of a diagonal: from its bottom hinge to the top mid-hinge
    /// (the same in every configuration, `examples/era.md`).
    pub fn diagonal_length(&self) -> f64 {
        let c = self.deployed();
        (c.faces[0].top_mid - c.faces[0].diagonal[0]).norm()
    }
}

/// The three clevis positions on the corner bodies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Clevis {
    /// A top horizontal's corner hinge (top corner body).
    Top,
    /// A bottom horizontal's corner hinge (bottom corner body).
    Bottom,
    /// A diagonal's bottom hinge (bottom corner body, below a top clevis).
    Diagonal,
}
