//! Printable pieces: a surface offset inward and closed along its boundary (Section 3.4).

use std::collections::HashMap;

use rustc_hash::FxHashMap;

use anim::Mesh;
use glam::Vec3;
use serde::Serialize;

use super::error::{LibraryError, Result};

/// Wall thickness of a printed piece in millimetres.
pub const DEFAULT_THICKNESS_MM: f64 = 1.5;
/// Printed height of the whole model in millimetres: 60 mm, a head the size of a 1:4–1:6
/// stop-motion puppet's (the model includes neck and scalp, so the face itself is ~40 mm).
/// At 25 mm the expressions of a talking face shrink below a resin printer's precision
/// (0.035–0.05 mm pixels): many pieces would print identically to a sibling; at 60 mm
/// a 1.5 mm wall and millimetre-sized keys also leave the features their shape.
pub const DEFAULT_PRINT_HEIGHT_MM: f64 = 60.0;
/// Density of PLA in grams per cubic millimetre (1.24 g/cm³).
pub const PLA_DENSITY_G_PER_MM3: f64 = 1.24e-3;

/// Turns an open surface into a watertight solid of the given thickness.
///
/// Every vertex is copied inward along its (area-weighted) normal by `thickness`; the inner
/// copy gets the reversed orientation, and every boundary edge `a → b` of the surface is
/// stitched to its inner copy by the quad `(b, a, a′, b′)`. For an edge-manifold, consistently
/// oriented surface the result is a closed 2-manifold with consistent orientation whose
/// outside is the original surface (a closed surface gives a hollow shell). Unreferenced
/// vertices are dropped. Self-intersections where `thickness` exceeds the local radius of
/// curvature are not resolved.
///
/// # Errors
/// [`LibraryError::BadSurface`] for no triangle, an out-of-range index, or an edge used
/// more than twice or twice in the same direction; [`LibraryError::InvalidParameter`] for a
/// non-positive or non-finite thickness.
pub fn solidify(surface: &Mesh, thickness: f32) -> Result<Mesh> {
    if !(thickness.is_finite() && thickness > 0.0) {
        return Err(LibraryError::InvalidParameter(format!(
            "thickness must be finite and > 0, got {thickness}"
        )));
    }
    let bad = |reason: String| LibraryError::BadSurface {
        mesh: surface.name.clone(),
        reason,
    };
    if surface.triangles.is_empty() {
        return Err(bad("no triangle".into()));
    }
    let nv = surface.positions.len();
    // Compact to referenced vertices.
    let mut remap = vec![u32::MAX; nv];
    let mut positions = Vec::new();
    let mut tris = Vec::with_capacity(surface.triangles.len());
    for t in &surface.triangles {
        let mut out = [0u32; 3];
        for (o, &i) in out.iter_mut().zip(t) {
            let i = i as usize;
            if i >= nv {
                return Err(bad(format!("index {i} out of range ({nv} vertices)")));
            }
            if remap[i] == u32::MAX {
                remap[i] = positions.len() as u32;
                positions.push(surface.positions[i]);
            }
            *o = remap[i];
        }
        if out[0] != out[1] && out[1] != out[2] && out[0] != out[2] {
            tris.push(out);
        }
    }
    // A vertex where two boundary loops touch (a "bow tie") would give its inner edge four
    // wall triangles: give every fan of triangles around a vertex its own copy first.
    let (positions, tris) = split_fans(positions, tris);
    let mut directed: HashMap<(u32, u32), u32> = HashMap::with_capacity(tris.len() * 3);
    for t in &tris {
        for k in 0..3 {
            let e = (t[k], t[(k + 1) % 3]);
            if directed.insert(e, 1).is_some() {
                return Err(bad(format!(
                    "edge {}–{} used twice in the same direction",
                    e.0, e.1
                )));
            }
        }
    }
    let m = positions.len() as u32;
    let base = Mesh::new("", positions.clone(), tris.clone());
    let normals = base.vertex_normals(&positions);
    let mut out_pos = positions.clone();
    out_pos.extend(
        positions
            .iter()
            .zip(&normals)
            .map(|(p, n)| *p - *n * thickness),
    );
    let mut out_tris = tris.clone();
    out_tris.extend(tris.iter().map(|t| [t[0] + m, t[2] + m, t[1] + m]));
    for t in &tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if !directed.contains_key(&(b, a)) {
                out_tris.push([b, a, a + m]);
                out_tris.push([b, a + m, b + m]);
            }
        }
    }
    let solid = Mesh::new(surface.name.clone(), out_pos, out_tris);
    let check = check_solid(&solid);
    if !check.is_closed_manifold() {
        return Err(bad(format!(
            "stitched result is not a closed manifold ({check:?})"
        )));
    }
    Ok(solid)
}

fn find(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

/// Splits every vertex into one copy per edge-connected fan of its triangles (corners of two
/// triangles sharing an edge through the vertex belong to the same fan).
pub(super) fn split_fans(positions: Vec<Vec3>, tris: Vec<[u32; 3]>) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut parent: Vec<usize> = (0..tris.len() * 3).collect();
    let mut edges: HashMap<(u32, u32), (usize, usize)> = HashMap::with_capacity(tris.len() * 3);
    for (t, tri) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            // Corners of a and b in this triangle.
            let (ca, cb) = (3 * t + k, 3 * t + (k + 1) % 3);
            let key = (a.min(b), a.max(b));
            let (ka, kb) = if a < b { (ca, cb) } else { (cb, ca) };
            match edges.get(&key) {
                Some(&(oa, ob)) => {
                    let (r1, r2) = (find(&mut parent, ka), find(&mut parent, oa));
                    parent[r1] = r2;
                    let (r1, r2) = (find(&mut parent, kb), find(&mut parent, ob));
                    parent[r1] = r2;
                }
                None => {
                    edges.insert(key, (ka, kb));
                }
            }
        }
    }
    let mut copy: HashMap<usize, u32> = HashMap::new();
    let mut first_root: Vec<Option<usize>> = vec![None; positions.len()];
    let mut out_pos = positions.clone();
    let mut out_tris = tris.clone();
    for (t, tri) in tris.iter().enumerate() {
        for k in 0..3 {
            let v = tri[k] as usize;
            let root = find(&mut parent, 3 * t + k);
            match first_root[v] {
                None => first_root[v] = Some(root),
                Some(r) if r == root => {}
                Some(_) => {
                    let id = *copy.entry(root).or_insert_with(|| {
                        out_pos.push(positions[v]);
                        (out_pos.len() - 1) as u32
                    });
                    out_tris[t][k] = id;
                }
            }
        }
    }
    (out_pos, out_tris)
}

/// Topological check of a solid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct SolidCheck {
    /// Edges with a single triangle.
    pub boundary_edges: usize,
    /// Edges with more than two triangles.
    pub non_manifold_edges: usize,
    /// Edges whose two triangles traverse them in the same direction.
    pub inconsistent_edges: usize,
    /// Vertices whose triangle fan is not a single disk (a "bow tie").
    pub non_manifold_vertices: usize,
}

impl SolidCheck {
    /// True for a closed, consistently oriented 2-manifold.
    pub fn is_closed_manifold(&self) -> bool {
        self.boundary_edges == 0
            && self.non_manifold_edges == 0
            && self.inconsistent_edges == 0
            && self.non_manifold_vertices == 0
    }
}

/// Counts the defects that keep a triangle mesh from being a closed, oriented 2-manifold.
///
/// # Performance
/// Two hash maps keyed by vertex pairs, with a fast non-cryptographic hash (the keys are the
/// mesh's own indices): every printed piece is checked.
pub fn check_solid(mesh: &Mesh) -> SolidCheck {
    let mut edges: FxHashMap<(u32, u32), (usize, usize)> = FxHashMap::default();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let e = edges.entry((a.min(b), a.max(b))).or_default();
            if a < b {
                e.0 += 1;
            } else {
                e.1 += 1;
            }
        }
    }
    let mut c = SolidCheck {
        boundary_edges: 0,
        non_manifold_edges: 0,
        inconsistent_edges: 0,
        non_manifold_vertices: 0,
    };
    for &(f, b) in edges.values() {
        match f + b {
            1 => c.boundary_edges += 1,
            2 if f != 1 => c.inconsistent_edges += 1,
            2 => {}
            _ => c.non_manifold_edges += 1,
        }
    }
    // Vertex fans: the triangles around v, linked through shared edges, must form one cycle.
    let mut next: FxHashMap<(u32, u32), u32> = FxHashMap::default(); // (v, a) -> b for v→a→b
    let mut fan = vec![0usize; mesh.positions.len()];
    for t in &mesh.triangles {
        for k in 0..3 {
            let (v, a, b) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            next.insert((v, a), b);
            if let Some(n) = fan.get_mut(v as usize) {
                *n += 1;
            }
        }
    }
    let mut seen = vec![false; mesh.positions.len()];
    for t in &mesh.triangles {
        let v = t[0];
        if std::mem::replace(&mut seen[v as usize], true) {
            continue;
        }
        let start = t[1];
        let (mut a, mut steps) = (start, 0usize);
        while let Some(&b) = next.get(&(v, a)) {
            steps += 1;
            a = b;
            if a == start || steps > fan[v as usize] {
                break;
            }
        }
        if steps != fan[v as usize] {
            c.non_manifold_vertices += 1;
        }
    }
    c
}

/// Enclosed volume by the divergence theorem, `Σ a·(b × c) / 6` (units³ of the positions;
/// positive for outward-oriented closed meshes).
pub fn volume(mesh: &Mesh) -> f64 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize].as_dvec3());
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

/// Scales a mesh (e.g. model units to millimetres).
pub fn scaled(mesh: &Mesh, factor: f32) -> Mesh {
    let mut m = mesh.clone();
    m.positions.iter_mut().for_each(|p| *p *= factor);
    m.normals = None;
    m
}

/// Printed material of a set of solids in millimetres.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MaterialEstimate {
    /// Total volume in mm³.
    pub volume_mm3: f64,
    /// Mass in grams at [`PLA_DENSITY_G_PER_MM3`].
    pub grams_pla: f64,
}

/// Sums the volumes of solids given in millimetres.
pub fn material<'a>(solids_mm: impl IntoIterator<Item = &'a Mesh>) -> MaterialEstimate {
    let v: f64 = solids_mm.into_iter().map(volume).sum();
    MaterialEstimate {
        volume_mm3: v,
        grams_pla: v * PLA_DENSITY_G_PER_MM3,
    }
}
