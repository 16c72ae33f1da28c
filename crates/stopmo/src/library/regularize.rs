//! The last resort for a solid that still crosses itself: its regularized boundary.
//!
//! The shared back surface keeps most pieces clean, but a cut it was not tuned on can leave
//! crossings where no single-point move helps: the front folding over the wall where a seam
//! meets an eye or mouth opening, lip rims walled where the seam follows the mouth, lips
//! pressed through each other inside one part. A slicer reads such a mesh as the region it
//! winds around at least once and guesses at the rest; here that region is computed exactly
//! instead, so the written file already is what will be printed. The mesh arrangement of the
//! solid's own triangles (exact rational intersections, winding numbers per cell: Zhou,
//! Grinspun, Zorin and Jacobson 2016, as implemented by the `manifold-rust` crate's robust
//! engine) keeps the walls between material (winding ≥ 1) and empty space, retriangulates
//! only the triangles that cross, and leaves every other triangle and vertex bit for bit as
//! built. Material that ends up apart from the piece (a chip cut off where a wall crossed the
//! front) is dropped, and so is a sealed cavity inside it (filled: resin trapped in a closed
//! void spoils a print), so a piece stays one shell.

use anim::{Aabb, Mesh};
use manifold_rust::linalg::Vec3 as MVec3;
use manifold_rust::manifold::Manifold;
use manifold_rust::types::{BooleanEngine, Error as ManifoldError, MeshGL, OpType};

use super::error::{LibraryError, Result};
use super::fabricate::{check_solid, split_fans, volume};
use super::plugs::components;
use crate::segment::Weld;

/// A regularized solid and what was cut off it.
#[derive(Debug, Clone)]
pub struct Regularized {
    /// The boundary of the material the input encloses (winding number ≥ 1), its largest
    /// shell only; closed, oriented and free of self-intersections in exact arithmetic.
    pub mesh: Mesh,
    /// Shells of the regularized material apart from the largest, dropped: chips apart
    /// from the piece, or sealed cavities inside it (filled).
    pub dropped_shells: usize,
    /// Their volume, unsigned (cubic units of the positions).
    pub dropped_volume: f64,
}

/// Replaces a closed, oriented solid that may cross itself by the boundary of the material
/// it encloses: the region it winds around at least once, as a slicer reads it.
///
/// # Arguments
/// * `solid` — a closed, consistently oriented triangle mesh (outward normals); it may cross
///   itself and have inside-out folds.
///
/// # Returns
/// The largest shell of the regularized material (name kept) and what else was dropped.
/// Triangles that cross nothing keep their vertices bit for bit; new vertices (where
/// triangles crossed) are the exact intersections rounded to `f32`.
///
/// # Errors
/// [`LibraryError::Regularization`] when the mesh is not closed and orientable, has
/// non-finite coordinates or encloses no material, or when the regularized surface touches
/// itself along an edge (not a 2-manifold; callers keep the solid as built then).
///
/// # Performance
/// One exact mesh arrangement: ~0.1–0.2 s for a 13–27k-triangle piece of the face whose
/// crossings are local (only crossing triangles reach the rational arithmetic).
pub fn regularize(solid: &Mesh) -> Result<Regularized> {
    exact_difference(solid, None)
}

/// `solid` minus `cutter` (both closed and outward oriented, in the same units), by the same
/// exact arrangement as [`regularize`]: the material `solid` winds around at least once and
/// `cutter` does not cover, its largest shell (name kept) and what else was dropped. `None`
/// subtracts nothing (the regularized solid). A pocket cut this way is as exact as the
/// regularization: no triangles are stitched by hand, and only triangles the cutter crosses
/// are retriangulated.
///
/// # Errors
/// As [`regularize`]; also when the cutter is not a closed, orientable solid.
pub(crate) fn exact_difference(solid: &Mesh, cutter: Option<&Mesh>) -> Result<Regularized> {
    exact_boolean(solid, None, cutter)
}

/// `solid` joined with `added` (a boss that holds a pocket), then minus `cutter`, by the
/// exact arrangement of [`exact_difference`] (same result and errors; `added` must be a
/// closed, orientable solid too).
pub(crate) fn exact_boolean(
    solid: &Mesh,
    added: Option<&Mesh>,
    cutter: Option<&Mesh>,
) -> Result<Regularized> {
    let fail = |reason: String| LibraryError::Regularization {
        mesh: solid.name.clone(),
        reason,
    };
    let mut material = manifold_of(solid).map_err(fail)?;
    if let Some(a) = added {
        let a = manifold_of(a).map_err(|r| fail(format!("the added solid: {r}")))?;
        material = material.boolean_with_engine(&a, OpType::Add, BooleanEngine::Robust);
        if material.status() != ManifoldError::NoError {
            return Err(fail(format!(
                "the exact union failed ({:?})",
                material.status()
            )));
        }
    }
    let cutter = match cutter {
        Some(c) => manifold_of(c).map_err(|r| fail(format!("the cutter: {r}")))?,
        None => {
            // Subtracting a speck far outside makes the engine classify every cell of the
            // arrangement (a clean solid comes back as it was).
            let bounds = material.bounding_box();
            let size = (bounds.max.x - bounds.min.x)
                .max(bounds.max.y - bounds.min.y)
                .max(bounds.max.z - bounds.min.z)
                .max(1.0);
            Manifold::tetrahedron()
                .scale(MVec3::new(size * 1e-3, size * 1e-3, size * 1e-3))
                .translate(MVec3::new(
                    bounds.max.x + size,
                    bounds.max.y + size,
                    bounds.max.z + size,
                ))
        }
    };
    let regular = material.boolean_with_engine(&cutter, OpType::Subtract, BooleanEngine::Robust);
    if regular.status() != ManifoldError::NoError {
        return Err(fail(format!(
            "the exact arrangement failed ({:?})",
            regular.status()
        )));
    }
    let out = regular.get_mesh_gl(-1);
    let stride = (out.num_prop as usize).max(3);
    let mut whole = Mesh::new(
        solid.name.clone(),
        out.vert_properties
            .chunks_exact(stride)
            .map(|c| glam::Vec3::new(c[0], c[1], c[2]))
            .collect(),
        out.tri_verts
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect(),
    );
    separate_touching_fans(&mut whole);
    let mut shells: Vec<(f64, Mesh)> = components(&whole)
        .into_iter()
        .map(|m| (volume(&m), m))
        .collect();
    // Largest volume first; ties (never on a real piece) by triangle count, then order.
    shells.sort_by(|a, b| {
        b.0.total_cmp(&a.0)
            .then(b.1.triangles.len().cmp(&a.1.triangles.len()))
    });
    let mut shells = shells.into_iter();
    let Some((_, mut mesh)) = shells.next().filter(|(v, _)| *v > 0.0) else {
        return Err(fail("it encloses no material".into()));
    };
    mesh.name = solid.name.clone();
    // Touching along an edge (four triangles on it) is not split apart: such a result is
    // refused rather than written as a non-manifold solid.
    let check = check_solid(&mesh);
    if !check.is_closed_manifold() {
        return Err(fail(format!(
            "the regularized surface is not a closed 2-manifold ({check:?})"
        )));
    }
    let rest: Vec<f64> = shells.map(|(v, _)| v).collect();
    Ok(Regularized {
        mesh,
        dropped_shells: rest.len(),
        dropped_volume: rest.iter().fold(0.0, |a, v| a + v.abs()),
    })
}

/// The robust engine's solid of a closed, orientable mesh (it may cross itself), or why not.
fn manifold_of(mesh: &Mesh) -> std::result::Result<Manifold, String> {
    if mesh.positions.iter().any(|p| !p.is_finite()) {
        return Err("a vertex is not finite".into());
    }
    let n = mesh.positions.len() as u32;
    if mesh.triangles.iter().flatten().any(|&i| i >= n) {
        return Err("a triangle indexes a missing vertex".into());
    }
    let gl = MeshGL {
        num_prop: 3,
        vert_properties: mesh.positions.iter().flat_map(|p| p.to_array()).collect(),
        tri_verts: mesh.triangles.iter().flatten().copied().collect(),
        ..MeshGL::default()
    };
    let m = Manifold::from_mesh_gl_robust(&gl);
    if m.status() != ManifoldError::NoError {
        return Err(format!("not a closed, orientable solid ({:?})", m.status()));
    }
    Ok(m)
}

/// How far apart the copies of a vertex where two fans of the regularized surface touch are
/// moved, relative to the solid's bounding-box diagonal (a 60 mm head: 0.6 µm, a hundredth
/// of a resin printer's resolution).
const FAN_SEPARATION: f32 = 1e-5;

/// Where the regularized material touches itself at a single point (two lips meeting at a
/// corner), the boundary passes twice through one point: as one vertex, or as two exact
/// vertices that rounding to `f32` put on the same point (an STL reader welds them). Such
/// points are welded, split into one copy per fan, and each copy moves a hair into its own
/// fan, so the two sheets no longer touch and the surface is a 2-manifold.
fn separate_touching_fans(mesh: &mut Mesh) {
    weld_rounded(mesh);
    let n = mesh.positions.len();
    let (positions, triangles) = split_fans(
        std::mem::take(&mut mesh.positions),
        std::mem::take(&mut mesh.triangles),
    );
    mesh.positions = positions;
    mesh.triangles = triangles;
    if mesh.positions.len() == n {
        return;
    }
    // The vertices that were split: every copy and the vertex it copies.
    let mut split = vec![false; mesh.positions.len()];
    let originals: std::collections::HashSet<[u32; 3]> = mesh.positions[n..]
        .iter()
        .map(|p| p.to_array().map(f32::to_bits))
        .collect();
    for (v, p) in mesh.positions.iter().enumerate() {
        split[v] = v >= n || originals.contains(&p.to_array().map(f32::to_bits));
    }
    let bounds = Aabb::from_points(&mesh.positions);
    let step = (bounds.max - bounds.min).length() * FAN_SEPARATION;
    let mut towards = vec![(glam::Vec3::ZERO, 0u32); mesh.positions.len()];
    for t in &mesh.triangles {
        for k in 0..3 {
            let v = t[k] as usize;
            if split[v] {
                let (a, b) = (t[(k + 1) % 3] as usize, t[(k + 2) % 3] as usize);
                towards[v].0 += mesh.positions[a] + mesh.positions[b];
                towards[v].1 += 2;
            }
        }
    }
    for (v, (sum, count)) in towards.into_iter().enumerate() {
        if count > 0 {
            let p = mesh.positions[v];
            let d = (sum / count as f32 - p).normalize_or_zero();
            mesh.positions[v] = p + d * step;
        }
    }
}

/// Merges vertices with the same `f32` position (the segmentation's exact [`Weld`]) and drops
/// the triangles that collapse.
fn weld_rounded(mesh: &mut Mesh) {
    let weld = Weld::new(&mesh.positions, 0.0);
    if weld.len() == mesh.positions.len() {
        return;
    }
    mesh.triangles = weld
        .triangles(&mesh.triangles)
        .into_iter()
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0])
        .collect();
    mesh.positions = weld.gather(&mesh.positions);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::library::test_shapes::cuboid;
    use crate::library::{check_solid, self_intersecting_triangles};
    use glam::Vec3;

    /// Boxes `(lo, hi)` in one mesh, outward oriented.
    fn boxes(list: &[(Vec3, Vec3)]) -> Mesh {
        boxes_turned(list, &[])
    }

    /// Boxes in one mesh: `outward` ones, then `inside_out` ones (reversed triangles).
    fn boxes_turned(outward: &[(Vec3, Vec3)], inside_out: &[(Vec3, Vec3)]) -> Mesh {
        let (mut pos, mut tris) = (Vec::new(), Vec::new());
        let all = outward.iter().map(|b| (b, false));
        for (&(lo, hi), turned) in all.chain(inside_out.iter().map(|b| (b, true))) {
            let (p, t) = cuboid(lo, hi);
            let base = pos.len() as u32;
            pos.extend(p);
            tris.extend(t.into_iter().map(|[a, b, c]| {
                let t = if turned { [a, c, b] } else { [a, b, c] };
                t.map(|i| i + base)
            }));
        }
        Mesh::new("piece", pos, tris)
    }

    fn crossing(m: &Mesh) -> usize {
        self_intersecting_triangles(&m.positions, &m.triangles)
            .expect("coordinates in range")
            .len()
    }

    /// Two boxes overlapping in one mesh (a wall pushed through the front, in miniature):
    /// the result is their union, one clean shell with the union's volume.
    #[test]
    fn overlapping_boxes_become_their_union() {
        let m = boxes(&[
            (Vec3::ZERO, Vec3::splat(2.0)),
            (Vec3::splat(1.0), Vec3::splat(3.0)),
        ]);
        assert!(crossing(&m) > 0);
        let r = regularize(&m).expect("regularized");
        assert_eq!(crossing(&r.mesh), 0);
        assert!(check_solid(&r.mesh).is_closed_manifold());
        assert_eq!(components(&r.mesh).len(), 1);
        assert_eq!(r.dropped_shells, 0);
        assert!((volume(&r.mesh) - 15.0).abs() < 1e-4, "{}", volume(&r.mesh));
        assert_eq!(r.mesh.name, "piece");
    }

    /// An inside-out shell (a fold that turned the surface over) encloses no material: it
    /// is dropped, not printed as a box.
    #[test]
    fn inside_out_material_is_dropped() {
        let m = boxes_turned(
            &[(Vec3::ZERO, Vec3::splat(2.0))],
            &[(Vec3::splat(-5.0), Vec3::splat(-4.0))],
        );
        let r = regularize(&m).expect("regularized");
        assert_eq!(r.mesh.triangles.len(), 12);
        assert!((volume(&r.mesh) - 8.0).abs() < 1e-5);
    }

    /// A chip apart from the piece is dropped and reported; a clean piece keeps every vertex.
    #[test]
    fn a_detached_chip_is_dropped_and_a_clean_piece_is_kept() {
        let m = boxes(&[
            (Vec3::ZERO, Vec3::splat(2.0)),
            (Vec3::splat(5.0), Vec3::splat(5.5)),
        ]);
        let r = regularize(&m).expect("regularized");
        assert_eq!(r.dropped_shells, 1);
        assert!((r.dropped_volume - 0.125).abs() < 1e-6);
        assert!((volume(&r.mesh) - 8.0).abs() < 1e-6);
        let bits = |m: &Mesh| {
            let mut v: Vec<[u32; 3]> = m
                .positions
                .iter()
                .map(|p| p.to_array().map(f32::to_bits))
                .collect();
            v.sort_unstable();
            v
        };
        let clean = boxes(&[(Vec3::ZERO, Vec3::splat(2.0))]);
        assert_eq!(bits(&regularize(&clean).expect("clean").mesh), bits(&clean));
    }

    /// A sealed cavity (a reversed box inside the piece) is filled: resin trapped in it
    /// would spoil the print.
    #[test]
    fn a_sealed_cavity_is_filled() {
        let m = boxes_turned(
            &[(Vec3::ZERO, Vec3::splat(2.0))],
            &[(Vec3::splat(0.5), Vec3::splat(1.5))],
        );
        let r = regularize(&m).expect("regularized");
        assert_eq!(r.dropped_shells, 1);
        assert!((r.dropped_volume - 1.0).abs() < 1e-6);
        assert!((volume(&r.mesh) - 8.0).abs() < 1e-6);
    }

    /// Two boxes touching at a corner, their corner vertices apart in the input (what
    /// rounding the exact arrangement to `f32` can make of lips meeting at a point): the
    /// touching point is welded, split per fan and moved apart, so no triangle crosses or
    /// touches another and the surface is a 2-manifold; the smaller box is a shell of its
    /// own then, and dropped.
    #[test]
    fn boxes_touching_at_a_corner_come_apart() {
        let m = boxes(&[
            (Vec3::ZERO, Vec3::splat(2.0)),
            (Vec3::splat(2.0), Vec3::splat(3.0)),
        ]);
        assert!(crossing(&m) > 0, "touching counts as crossing");
        let r = regularize(&m).expect("regularized");
        assert_eq!(crossing(&r.mesh), 0);
        assert!(check_solid(&r.mesh).is_closed_manifold());
        assert_eq!(r.dropped_shells, 1);
        assert!((volume(&r.mesh) - 8.0).abs() < 1e-3, "{}", volume(&r.mesh));
    }

    /// Boxes touching along an edge regularize to a surface with four triangles on that edge:
    /// refused (the caller keeps the solid as built), not written as a non-manifold solid.
    #[test]
    fn boxes_touching_along_an_edge_are_refused() {
        let m = boxes(&[
            (Vec3::ZERO, Vec3::splat(2.0)),
            (Vec3::new(2.0, 2.0, 0.0), Vec3::new(3.0, 3.0, 2.0)),
        ]);
        let e = regularize(&m).unwrap_err().to_string();
        assert!(e.contains("piece") && e.contains("2-manifold"), "{e}");
    }

    /// Same input, same bytes.
    #[test]
    fn regularizing_is_deterministic() {
        let m = boxes(&[
            (Vec3::ZERO, Vec3::splat(2.0)),
            (Vec3::new(0.5, 0.5, 1.5), Vec3::new(1.5, 1.5, 2.5)),
        ]);
        let (a, b) = (regularize(&m).unwrap(), regularize(&m).unwrap());
        assert_eq!(a.mesh.positions, b.mesh.positions);
        assert_eq!(a.mesh.triangles, b.mesh.triangles);
    }

    /// Open or broken input is an error naming the mesh, never a panic.
    #[test]
    fn an_open_mesh_is_an_error() {
        let mut m = boxes(&[(Vec3::ZERO, Vec3::ONE)]);
        m.triangles.pop();
        let e = regularize(&m).unwrap_err().to_string();
        assert!(e.contains("piece"), "{e}");
        m.positions[0].x = f32::NAN;
        assert!(regularize(&m).is_err());
        let mut m = boxes(&[(Vec3::ZERO, Vec3::ONE)]);
        m.triangles[0][0] = 99;
        assert!(regularize(&m).is_err());
    }
}
