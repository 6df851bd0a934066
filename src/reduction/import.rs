//! Import of the stiffness and mass matrices of a flexible body from
//! another finite-element code (docs/model-format.md, "Superelements").
//!
//! Two sources:
//! - **Matrix Market** files (`coordinate` format, `real` or `integer`
//!   values, `symmetric` or `general`; NIST's format, written by most
//!   codes and by SciPy's `mmwrite`), one for `K` and one for `M`, with a
//!   **dof map**: a text file with one line per row of the matrices,
//!   `node component` (component 1–6: x, y, z, rx, ry, rz, as Nastran
//!   numbers them), `#` starting a comment;
//! - a **Nastran DMIG punch** file (`DMIG` bulk entries in small, large or
//!   free field, as written by `EXTSEOUT` or `DMIGPCH`), whose entries
//!   name their grid and component: no dof map.
//!
//! The node coordinates come from a **nodes** file (`id x y z` per line),
//! or, when absent, from the model's nodes of the same ids. An optional
//! **cells** file (`id n1 n2 [n3 [n4]]` per line: a line, triangle or
//! quadrilateral through mesh nodes) gives the mesh drawn in the VTK
//! files.
//!
//! Every file is checked: the sizes agree, the matrices are symmetric
//! (a `general` file to [`SYMMETRY_TOLERANCE`]), every value is finite,
//! the dof map covers every row once, every node has coordinates. A
//! problem is an [`ImportError`] naming the file (and the line) and what
//! is wrong. Rows whose stiffness and mass are both empty (a dof no
//! element touches, as Nastran's AUTOSPC removes) are left out of the
//! body.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use super::body::{from_triplets, FlexibleBody, MeshCell};
use crate::model::Id;
use crate::so3::{Rotation, Vec3};

/// Largest asymmetry of a `general` Matrix Market file accepted:
/// `|aᵢⱼ − aⱼᵢ| ≤ SYMMETRY_TOLERANCE · max(|aᵢⱼ|, |aⱼᵢ|)` above a floor of
/// 1e-12 of the largest entry. Matrices written with 8 significant digits
/// (Nastran's small field) differ by up to 5e-8 relative; 1e-6 leaves room
/// for that and refuses any real asymmetry.
pub const SYMMETRY_TOLERANCE: f64 = 1e-6;

/// A problem with an imported file.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}{}: {message}", path.display(), line.map_or(String::new(), |l| format!(", line {l}")))]
pub struct ImportError {
    /// The file.
    pub path: PathBuf,
    /// The line, when the problem is on one.
    pub line: Option<usize>,
    /// What is wrong.
    pub message: String,
}

fn error(path: &Path, line: Option<usize>, message: impl Into<String>) -> ImportError {
    ImportError {
        path: path.to_path_buf(),
        line,
        message: message.into(),
    }
}

fn read(path: &Path) -> Result<String, ImportError> {
    std::fs::read_to_string(path)
        .map_err(|e| error(path, None, format!("cannot read the file: {e}")))
}

/// A sparse matrix as read: its size and its entries (both triangles of a
/// symmetric file).
#[derive(Clone, Debug, PartialEq)]
pub struct Triplets {
    /// Rows (and columns).
    pub n: usize,
    /// `(row, column, value)`, 0-based, duplicates summed later.
    pub entries: Vec<(usize, usize, f64)>,
}

/// Reads a square Matrix Market `coordinate` file.
pub fn read_matrix_market(path: &Path) -> Result<Triplets, ImportError> {
    let text = read(path)?;
    parse_matrix_market(&text, path)
}

/// Parses Matrix Market text (`path` for messages).
pub fn parse_matrix_market(text: &str, path: &Path) -> Result<Triplets, ImportError> {
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l));
    let (_, header) = lines
        .next()
        .ok_or_else(|| error(path, None, "empty file: not a Matrix Market file"))?;
    let words: Vec<String> = header
        .split_whitespace()
        .map(|w| w.to_lowercase())
        .collect();
    if words.first().map(String::as_str) != Some("%%matrixmarket") || words.len() < 5 {
        return Err(error(
            path,
            Some(1),
            "the header must read `%%MatrixMarket matrix coordinate real symmetric` (or general)",
        ));
    }
    if words[1] != "matrix" || words[2] != "coordinate" {
        return Err(error(
            path,
            Some(1),
            format!(
                "only `matrix coordinate` files are read, not `{} {}`",
                words[1], words[2]
            ),
        ));
    }
    if words[3] != "real" && words[3] != "integer" && words[3] != "double" {
        return Err(error(
            path,
            Some(1),
            format!("values must be real, not `{}`", words[3]),
        ));
    }
    let symmetric = match words[4].as_str() {
        "symmetric" => true,
        "general" => false,
        other => {
            return Err(error(
                path,
                Some(1),
                format!("symmetry must be `symmetric` or `general`, not `{other}`"),
            ))
        }
    };
    // the size line, after comments
    let (size_line, size) = loop {
        match lines.next() {
            None => return Err(error(path, None, "no size line (rows columns entries)")),
            Some((_, l)) if l.trim().is_empty() || l.trim_start().starts_with('%') => continue,
            Some((i, l)) => break (i, l),
        }
    };
    let numbers: Vec<usize> = size
        .split_whitespace()
        .map(|w| w.parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|_| {
            error(
                path,
                Some(size_line),
                "the size line must hold three integers: rows columns entries",
            )
        })?;
    let [rows, cols, nnz] = numbers[..] else {
        return Err(error(
            path,
            Some(size_line),
            "the size line must hold three integers: rows columns entries",
        ));
    };
    if rows != cols {
        return Err(error(
            path,
            Some(size_line),
            format!("the matrix is {rows} × {cols}: not square"),
        ));
    }
    let mut entries = Vec::with_capacity(if symmetric { 2 * nnz } else { nnz });
    let mut count = 0;
    for (i, l) in lines {
        let l = l.trim();
        if l.is_empty() || l.starts_with('%') {
            continue;
        }
        let w: Vec<&str> = l.split_whitespace().collect();
        if w.len() != 3 {
            return Err(error(
                path,
                Some(i),
                format!("an entry is `row column value`, got `{l}`"),
            ));
        }
        let r: usize = w[0].parse().map_err(|_| {
            error(
                path,
                Some(i),
                format!("row `{}` is not a positive integer", w[0]),
            )
        })?;
        let c: usize = w[1].parse().map_err(|_| {
            error(
                path,
                Some(i),
                format!("column `{}` is not a positive integer", w[1]),
            )
        })?;
        let v: f64 = w[2]
            .parse()
            .map_err(|_| error(path, Some(i), format!("value `{}` is not a number", w[2])))?;
        if r == 0 || c == 0 || r > rows || c > cols {
            return Err(error(
                path,
                Some(i),
                format!("entry ({r}, {c}) outside the {rows} × {cols} matrix (indices start at 1)"),
            ));
        }
        if !v.is_finite() {
            return Err(error(
                path,
                Some(i),
                format!("entry ({r}, {c}) is {v}: not finite"),
            ));
        }
        if symmetric && c > r {
            return Err(error(
                path,
                Some(i),
                format!("entry ({r}, {c}) above the diagonal of a symmetric file, which holds the lower triangle only"),
            ));
        }
        entries.push((r - 1, c - 1, v));
        if symmetric && r != c {
            entries.push((c - 1, r - 1, v));
        }
        count += 1;
    }
    if count != nnz {
        return Err(error(
            path,
            None,
            format!("the size line announces {nnz} entries, the file holds {count}"),
        ));
    }
    let t = Triplets { n: rows, entries };
    if !symmetric {
        check_symmetric(&t, path)?;
    }
    Ok(t)
}

/// Checks that `t` is symmetric to [`SYMMETRY_TOLERANCE`].
fn check_symmetric(t: &Triplets, path: &Path) -> Result<(), ImportError> {
    let mut sum: HashMap<(usize, usize), f64> = HashMap::with_capacity(t.entries.len());
    for &(r, c, v) in &t.entries {
        *sum.entry((r, c)).or_insert(0.0) += v;
    }
    let largest = sum.values().fold(0.0f64, |a, v| a.max(v.abs()));
    let floor = 1e-12 * largest;
    let mut worst: Option<(usize, usize, f64, f64)> = None;
    for (&(r, c), &v) in &sum {
        if r >= c {
            continue;
        }
        let w = sum.get(&(c, r)).copied().unwrap_or(0.0);
        let d = (v - w).abs();
        if d > floor && d > SYMMETRY_TOLERANCE * v.abs().max(w.abs()) {
            let worse = worst.is_none_or(|(_, _, a, b)| d > (a - b).abs());
            if worse {
                worst = Some((r, c, v, w));
            }
        }
    }
    match worst {
        None => Ok(()),
        Some((r, c, v, w)) => Err(error(
            path,
            None,
            format!(
                "the matrix is not symmetric: entry ({}, {}) is {v:e}, entry ({}, {}) is {w:e}",
                r + 1,
                c + 1,
                c + 1,
                r + 1
            ),
        )),
    }
}

/// Reads a dof map: `node component` per line (component 1–6), one line
/// per row of the matrices.
pub fn read_dof_map(path: &Path) -> Result<Vec<(Id, usize)>, ImportError> {
    let text = read(path)?;
    let mut map = Vec::new();
    let mut seen: HashMap<(Id, usize), usize> = HashMap::new();
    for (i, l) in text.lines().enumerate() {
        let line = i + 1;
        let l = l.split('#').next().unwrap_or("").trim();
        if l.is_empty() {
            continue;
        }
        let w: Vec<&str> = l.split_whitespace().collect();
        let bad = || {
            error(
                path,
                Some(line),
                format!("a line is `node component` (component 1 to 6), got `{l}`"),
            )
        };
        if w.len() != 2 {
            return Err(bad());
        }
        let node: Id = w[0].parse().map_err(|_| bad())?;
        let c: usize = w[1].parse().map_err(|_| bad())?;
        if !(1..=6).contains(&c) {
            return Err(bad());
        }
        if let Some(first) = seen.insert((node, c - 1), line) {
            return Err(error(
                path,
                Some(line),
                format!("node {node} component {c} is listed twice (line {first} too)"),
            ));
        }
        map.push((node, c - 1));
    }
    Ok(map)
}

/// Reads node coordinates: `id x y z` per line.
pub fn read_nodes(path: &Path) -> Result<HashMap<Id, Vec3>, ImportError> {
    let text = read(path)?;
    let mut nodes = HashMap::new();
    for (i, l) in text.lines().enumerate() {
        let line = i + 1;
        let l = l.split('#').next().unwrap_or("").trim();
        if l.is_empty() {
            continue;
        }
        let w: Vec<&str> = l
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|s| !s.is_empty())
            .collect();
        let bad = || error(path, Some(line), format!("a line is `id x y z`, got `{l}`"));
        if w.len() != 4 {
            return Err(bad());
        }
        let id: Id = w[0].parse().map_err(|_| bad())?;
        let mut x = [0.0f64; 3];
        for k in 0..3 {
            x[k] = w[k + 1].parse().map_err(|_| bad())?;
        }
        if !x.iter().all(|v| v.is_finite()) {
            return Err(error(
                path,
                Some(line),
                format!("node {id} has a coordinate that is not finite"),
            ));
        }
        if nodes.insert(id, Vec3::from(x)).is_some() {
            return Err(error(path, Some(line), format!("node {id} is given twice")));
        }
    }
    Ok(nodes)
}

/// Reads cells: `id n1 n2 [n3 [n4]]` per line (the id is the cell's own,
/// for messages).
pub fn read_cells(path: &Path) -> Result<Vec<(usize, Vec<Id>)>, ImportError> {
    let text = read(path)?;
    let mut cells = Vec::new();
    for (i, l) in text.lines().enumerate() {
        let line = i + 1;
        let l = l.split('#').next().unwrap_or("").trim();
        if l.is_empty() {
            continue;
        }
        let w: Result<Vec<Id>, _> = l
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|s| !s.is_empty())
            .map(str::parse)
            .collect();
        match w {
            Ok(w) if (3..=5).contains(&w.len()) => cells.push((line, w[1..].to_vec())),
            _ => {
                return Err(error(
                    path,
                    Some(line),
                    format!(
                    "a cell is `id n1 n2 [n3 [n4]]` (a line, triangle or quadrilateral), got `{l}`"
                ),
                ))
            }
        }
    }
    Ok(cells)
}

/// A number in Nastran's notations: `1.5E+3`, `1.5D+3`, `1.5+3`,
/// `-.5-2`.
fn nastran_number(field: &str) -> Option<f64> {
    let s = field.trim().replace(['D', 'd'], "E");
    if let Ok(v) = s.parse::<f64>() {
        return Some(v);
    }
    // an exponent without its E: a sign after the first character
    let bytes = s.as_bytes();
    let k = (1..bytes.len()).find(|&k| {
        (bytes[k] == b'+' || bytes[k] == b'-') && bytes[k - 1] != b'E' && bytes[k - 1] != b'e'
    })?;
    format!("{}E{}", &s[..k], &s[k..]).parse().ok()
}

/// The fields of one line of a bulk entry, without its first field (the
/// entry name or continuation marker) and its continuation field
/// (columns 73–80): free field (commas), large field (a `*` in the first
/// field: 16-character fields) or small field (8 characters).
fn line_fields(line: &str) -> (String, Vec<String>) {
    if line.contains(',') {
        let mut f = line.split(',').map(|s| s.trim().to_string());
        let first = f.next().unwrap_or_default();
        return (first, f.collect());
    }
    let chars: Vec<char> = line.chars().collect();
    let take = |a: usize, b: usize| -> String {
        chars[a.min(chars.len())..b.min(chars.len())]
            .iter()
            .collect::<String>()
            .trim()
            .to_string()
    };
    let first = take(0, 8);
    let width = if first.contains('*') { 16 } else { 8 };
    let fields = (0..(64 / width))
        .map(|k| take(8 + k * width, 8 + (k + 1) * width))
        .collect();
    (first, fields)
}

/// The real matrices named in a DMIG punch file, as `(GJ, CJ, GI, CI,
/// value)` entries (components 0-based), both triangles of a symmetric
/// (form 6) matrix.
pub type DmigEntries = Vec<(Id, usize, Id, usize, f64)>;

/// Reads the DMIG matrices `names` from a punch file.
pub fn read_dmig(path: &Path, names: &[&str]) -> Result<Vec<DmigEntries>, ImportError> {
    let text = read(path)?;
    parse_dmig(&text, path, names)
}

/// Parses DMIG punch text (`path` for messages).
pub fn parse_dmig(
    text: &str,
    path: &Path,
    names: &[&str],
) -> Result<Vec<DmigEntries>, ImportError> {
    // logical cards: the fields of an entry and its continuation lines
    let mut cards: Vec<(usize, Vec<String>)> = Vec::new();
    for (i, l) in text.lines().enumerate() {
        let line = i + 1;
        if l.trim().is_empty() || l.trim_start().starts_with('$') {
            continue;
        }
        let (first, fields) = line_fields(l);
        let upper = first.to_uppercase();
        if upper.starts_with("DMIG") {
            cards.push((line, fields));
        } else if upper.is_empty() || upper.starts_with('*') || upper.starts_with('+') {
            match cards.last_mut() {
                Some((_, f)) => f.extend(fields),
                None => {
                    return Err(error(
                        path,
                        Some(line),
                        "a continuation line before any DMIG entry",
                    ))
                }
            }
        } else {
            // another bulk entry: ends the current card
            cards.push((line, vec!["".into()]));
        }
    }
    let mut out: Vec<DmigEntries> = vec![Vec::new(); names.len()];
    let mut form: Vec<Option<u32>> = vec![None; names.len()];
    for (line, f) in &cards {
        let name = f.first().map(|s| s.to_uppercase()).unwrap_or_default();
        let Some(m) = names.iter().position(|n| n.eq_ignore_ascii_case(&name)) else {
            continue;
        };
        let int = |k: usize, what: &str| -> Result<u64, ImportError> {
            let s = f.get(k).map(String::as_str).unwrap_or("");
            s.parse::<u64>().map_err(|_| {
                error(
                    path,
                    Some(*line),
                    format!("DMIG {name}: {what} `{s}` is not an integer"),
                )
            })
        };
        if f.get(1).map(String::as_str) == Some("0") {
            // header: NAME, 0, IFO, TIN, TOUT, POLAR, -, NCOL
            let ifo = int(2, "form")? as u32;
            let tin = int(3, "input type")?;
            if tin > 2 {
                return Err(error(
                    path,
                    Some(*line),
                    format!("DMIG {name}: complex matrices (TIN = {tin}) are not read"),
                ));
            }
            if ifo != 1 && ifo != 6 {
                return Err(error(
                    path,
                    Some(*line),
                    format!("DMIG {name}: form {ifo}; a stiffness or mass is square (1) or symmetric (6)"),
                ));
            }
            form[m] = Some(ifo);
            continue;
        }
        if form[m].is_none() {
            return Err(error(
                path,
                Some(*line),
                format!("DMIG {name}: a column before the header entry"),
            ));
        }
        let gj = int(1, "grid")?;
        let cj = int(2, "component")?;
        if !(1..=6).contains(&cj) {
            return Err(error(path, Some(*line), format!("DMIG {name}: component {cj} of grid {gj}: only grid components 1 to 6 are read")));
        }
        // groups of (G, C, A, B) from field 4 on
        let data = &f[4.min(f.len())..];
        for group in data.chunks(4) {
            if group.iter().all(|s| s.is_empty()) {
                continue;
            }
            let gi: u64 = group[0].parse().map_err(|_| {
                error(
                    path,
                    Some(*line),
                    format!(
                        "DMIG {name} column {gj}-{cj}: grid `{}` is not an integer",
                        group[0]
                    ),
                )
            })?;
            let ci: u64 = group
                .get(1)
                .map(String::as_str)
                .unwrap_or("")
                .parse()
                .map_err(|_| {
                    error(
                        path,
                        Some(*line),
                        format!("DMIG {name} column {gj}-{cj}: component of grid {gi} is missing"),
                    )
                })?;
            if !(1..=6).contains(&ci) {
                return Err(error(path, Some(*line), format!("DMIG {name}: component {ci} of grid {gi}: only grid components 1 to 6 are read")));
            }
            let a = group.get(2).map(String::as_str).unwrap_or("");
            let v = nastran_number(a).ok_or_else(|| {
                error(
                    path,
                    Some(*line),
                    format!("DMIG {name} column {gj}-{cj}: value `{a}` is not a number"),
                )
            })?;
            if !v.is_finite() {
                return Err(error(
                    path,
                    Some(*line),
                    format!("DMIG {name} column {gj}-{cj}: value `{a}` is not finite"),
                ));
            }
            out[m].push((gj, cj as usize - 1, gi, ci as usize - 1, v));
        }
    }
    for (m, name) in names.iter().enumerate() {
        match form[m] {
            None => {
                return Err(error(
                    path,
                    None,
                    format!("no DMIG matrix named {name} in the file"),
                ))
            }
            Some(6) => {
                // one triangle given (either): mirror, refusing a pair
                // given twice with different values
                let mut seen: HashMap<(Id, usize, Id, usize), f64> = HashMap::new();
                for &(gj, cj, gi, ci, v) in &out[m] {
                    seen.insert((gi, ci, gj, cj), v);
                }
                let mut mirrored = Vec::new();
                for &(gj, cj, gi, ci, v) in &out[m] {
                    if (gi, ci) == (gj, cj) {
                        continue;
                    }
                    match seen.get(&(gj, cj, gi, ci)) {
                        None => mirrored.push((gi, ci, gj, cj, v)),
                        Some(&w) if (w - v).abs() > SYMMETRY_TOLERANCE * w.abs().max(v.abs()) => {
                            return Err(error(
                                path,
                                None,
                                format!(
                                    "DMIG {name} is symmetric (form 6) but gives ({gi}-{}, {gj}-{}) = {v:e} and ({gj}-{}, {gi}-{}) = {w:e}",
                                    ci + 1, cj + 1, cj + 1, ci + 1
                                ),
                            ))
                        }
                        Some(_) => {}
                    }
                }
                out[m].extend(mirrored);
            }
            Some(_) => {
                let t = dmig_triplets(&out[m]);
                check_symmetric(&t, path).map_err(|e| ImportError {
                    message: format!("DMIG {name}: {}", e.message),
                    ..e
                })?;
            }
        }
    }
    Ok(out)
}

/// DMIG entries as triplets on the dofs in order of appearance (for the
/// symmetry check).
fn dmig_triplets(entries: &DmigEntries) -> Triplets {
    let mut index: HashMap<(Id, usize), usize> = HashMap::new();
    let mut t = Vec::with_capacity(entries.len());
    for &(gj, cj, gi, ci, v) in entries {
        let n = index.len();
        let j = *index.entry((gj, cj)).or_insert(n);
        let n = index.len();
        let i = *index.entry((gi, ci)).or_insert(n);
        t.push((i, j, v));
    }
    Triplets {
        n: index.len(),
        entries: t,
    }
}

/// The files of an imported body.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImportedFiles {
    /// Matrix Market stiffness.
    pub stiffness: Option<PathBuf>,
    /// Matrix Market mass.
    pub mass: Option<PathBuf>,
    /// Dof map of the Matrix Market files.
    pub dofs: Option<PathBuf>,
    /// DMIG punch file, with the names of its stiffness and mass.
    pub dmig: Option<(PathBuf, String, String)>,
    /// Node coordinates (else the model's nodes).
    pub nodes: Option<PathBuf>,
    /// Cells to draw.
    pub cells: Option<PathBuf>,
}

/// Builds the body from imported files; `model_node` gives the position
/// of a node the nodes file lacks (the model's node of that id), or none.
pub fn import_body(
    files: &ImportedFiles,
    model_node: &dyn Fn(Id) -> Option<Vec3>,
) -> Result<FlexibleBody, ImportError> {
    // the matrices on a list of (node id, component) dofs
    let (dofs, k, m, source): (Vec<(Id, usize)>, Triplets, Triplets, PathBuf) =
        match (&files.dmig, &files.stiffness, &files.mass, &files.dofs) {
            (Some((path, kn, mn)), _, _, _) => {
                let [kd, md]: [DmigEntries; 2] = read_dmig(path, &[kn, mn])?
                    .try_into()
                    .expect("two matrices asked");
                let mut index: HashMap<(Id, usize), usize> = HashMap::new();
                let mut all: Vec<(Id, usize)> = kd
                    .iter()
                    .chain(&md)
                    .flat_map(|&(gj, cj, gi, ci, _)| [(gj, cj), (gi, ci)])
                    .collect();
                all.sort_unstable();
                all.dedup();
                for (k, d) in all.iter().enumerate() {
                    index.insert(*d, k);
                }
                let triplets = |e: &DmigEntries| Triplets {
                    n: all.len(),
                    entries: e
                        .iter()
                        .map(|&(gj, cj, gi, ci, v)| (index[&(gi, ci)], index[&(gj, cj)], v))
                        .collect(),
                };
                let (k, m) = (triplets(&kd), triplets(&md));
                (all, k, m, path.clone())
            }
            (None, Some(kp), Some(mp), Some(dp)) => {
                let k = read_matrix_market(kp)?;
                let m = read_matrix_market(mp)?;
                let map = read_dof_map(dp)?;
                if k.n != m.n {
                    return Err(error(
                        mp,
                        None,
                        format!(
                            "the mass is {} × {}, the stiffness ({}) {} × {}",
                            m.n,
                            m.n,
                            kp.display(),
                            k.n,
                            k.n
                        ),
                    ));
                }
                if map.len() != k.n {
                    return Err(error(
                        dp,
                        None,
                        format!(
                            "the dof map has {} lines, the matrices {} rows: one line per row",
                            map.len(),
                            k.n
                        ),
                    ));
                }
                (map, k, m, kp.clone())
            }
            _ => return Err(error(
                Path::new("superelement"),
                None,
                "imported matrices need `stiffness`, `mass` and `dofs` (Matrix Market), or `dmig`",
            )),
        };

    // nodes in order of first appearance, their coordinates
    let mut node_ids: Vec<Id> = Vec::new();
    let mut node_index: HashMap<Id, usize> = HashMap::new();
    for &(n, _) in &dofs {
        node_index.entry(n).or_insert_with(|| {
            node_ids.push(n);
            node_ids.len() - 1
        });
    }
    let table = match &files.nodes {
        Some(p) => Some((read_nodes(p)?, p)),
        None => None,
    };
    let mut positions = Vec::with_capacity(node_ids.len());
    for &id in &node_ids {
        let x = match &table {
            Some((t, _)) => t.get(&id).copied(),
            None => model_node(id),
        };
        match x {
            Some(x) => positions.push(x),
            None => {
                let (path, where_) = match &table {
                    Some((_, p)) => ((*p).clone(), "in the nodes file"),
                    None => (source.clone(), "in the model (give a `nodes` file)"),
                };
                return Err(error(
                    &path,
                    None,
                    format!("node {id} of the matrices has no coordinates {where_}"),
                ));
            }
        }
    }

    // rows without stiffness and mass leave the body
    let mut used = vec![false; dofs.len()];
    for &(r, c, v) in k.entries.iter().chain(&m.entries) {
        if v != 0.0 {
            used[r] = true;
            used[c] = true;
        }
    }
    let mut row_of = vec![usize::MAX; dofs.len()];
    let mut kept = Vec::new();
    for (r, &(n, c)) in dofs.iter().enumerate() {
        if used[r] {
            row_of[r] = kept.len();
            kept.push((node_index[&n], c));
        }
    }
    let matrix = |t: &Triplets| {
        let e: Vec<(usize, usize, f64)> = t
            .entries
            .iter()
            .filter(|e| e.2 != 0.0)
            .map(|&(r, c, v)| (row_of[r], row_of[c], v))
            .collect();
        from_triplets(kept.len(), &e)
    };
    let (stiffness, mass) = (matrix(&k), matrix(&m));

    let mut cells = Vec::new();
    if let Some(p) = &files.cells {
        for (line, ns) in read_cells(p)? {
            let nodes: Result<Vec<usize>, ImportError> = ns
                .iter()
                .map(|id| {
                    node_index.get(id).copied().ok_or_else(|| {
                        error(
                            p,
                            Some(line),
                            format!("node {id} is not a node of the matrices"),
                        )
                    })
                })
                .collect();
            cells.push(MeshCell {
                nodes: nodes?,
                element: None,
            });
        }
    }
    Ok(FlexibleBody {
        orientations: vec![Rotation::identity(); node_ids.len()],
        node_ids,
        positions,
        dofs: kept,
        stiffness,
        mass,
        cells,
        elements: None,
        placement: (Vec3::zeros(), Rotation::identity()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The numbers of Nastran's fields.
    #[test]
    fn nastran_numbers_are_read() {
        for (s, v) in [
            ("1.5", 1.5),
            ("1.5E+3", 1500.0),
            ("1.5D+03", 1500.0),
            ("1.5+3", 1500.0),
            ("-.5-2", -0.005),
            ("2.", 2.0),
            ("7", 7.0),
        ] {
            assert_eq!(nastran_number(s), Some(v), "{s}");
        }
        assert_eq!(nastran_number("abc"), None);
    }

    /// A symmetric Matrix Market file: the lower triangle mirrored; a
    /// general one that is not symmetric, an entry above the diagonal of
    /// a symmetric file, a NaN and a wrong count are refused, naming the
    /// file and the line.
    #[test]
    fn matrix_market_files_are_read_and_checked() {
        let p = Path::new("k.mtx");
        let ok = "%%MatrixMarket matrix coordinate real symmetric\n% a comment\n2 2 3\n1 1 4.0\n2 1 -1.0\n2 2 3.0\n";
        let t = parse_matrix_market(ok, p).unwrap();
        assert_eq!(t.n, 2);
        assert_eq!(
            t.entries,
            vec![(0, 0, 4.0), (1, 0, -1.0), (0, 1, -1.0), (1, 1, 3.0)]
        );
        let general =
            "%%MatrixMarket matrix coordinate real general\n2 2 3\n1 1 4.0\n2 1 -1.0\n1 2 -1.5\n";
        let e = parse_matrix_market(general, p).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("k.mtx: the matrix is not symmetric"),
            "{e}"
        );
        let upper = "%%MatrixMarket matrix coordinate real symmetric\n2 2 1\n1 2 4.0\n";
        let e = parse_matrix_market(upper, p).unwrap_err();
        assert!(
            e.to_string()
                .contains("line 3: entry (1, 2) above the diagonal"),
            "{e}"
        );
        let nan = "%%MatrixMarket matrix coordinate real symmetric\n2 2 1\n1 1 NaN\n";
        let e = parse_matrix_market(nan, p).unwrap_err();
        assert!(
            e.to_string()
                .contains("line 3: entry (1, 1) is NaN: not finite"),
            "{e}"
        );
        let count = "%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 1.0\n";
        let e = parse_matrix_market(count, p).unwrap_err();
        assert!(
            e.to_string()
                .contains("announces 2 entries, the file holds 1"),
            "{e}"
        );
        let array = "%%MatrixMarket matrix array real general\n2 2\n1\n2\n3\n4\n";
        assert!(parse_matrix_market(array, p).is_err());
    }

    /// DMIG in small field with implicit exponents, in large field with D
    /// exponents and `*` continuations, and in free field give the same
    /// symmetric matrix.
    #[test]
    fn dmig_in_small_large_and_free_field() {
        let p = Path::new("k.pch");
        let small = "\
DMIG    KAAX           0       6       2       0                       2
DMIG    KAAX         101       1             101       1   4.0+3
DMIG    KAAX         102       1             101       1  -1.0+3        
             102       1   3.0+3
";
        let large = "\
DMIG    KAAX           0       6       2       0                       2
DMIG*   KAAX                         101               1
*                    101               1 4.000000000D+03
DMIG*   KAAX                         102               1
*                    101               1-1.000000000D+03
*                    102               1 3.000000000D+03
";
        let free = "\
DMIG,KAAX,0,6,2,0,,2
DMIG,KAAX,101,1,,101,1,4000.
DMIG,KAAX,102,1,,101,1,-1000.,,102,1,3000.
";
        let mut expected = vec![
            (101, 0, 101, 0, 4000.0),
            (102, 0, 101, 0, -1000.0),
            (102, 0, 102, 0, 3000.0),
            (101, 0, 102, 0, -1000.0),
        ];
        expected.sort_by(|a, b| a.partial_cmp(b).unwrap());
        for text in [small, large, free] {
            let mut e = parse_dmig(text, p, &["KAAX"]).unwrap().remove(0);
            e.sort_by(|a, b| a.partial_cmp(b).unwrap());
            assert_eq!(e, expected, "{text}");
        }
        let e = parse_dmig(small, p, &["MAAX"]).unwrap_err();
        assert!(e.to_string().contains("no DMIG matrix named MAAX"), "{e}");
    }
}
