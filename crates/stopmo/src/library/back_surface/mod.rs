//! Printable pieces on one shared back surface (StopShop Section 3.4, made robust).
//!
//! The paper prints each piece as its surface offset inward; offsetting every vertex along its
//! own normal folds at eye rims and bursts through noses and ears. Here all pieces of a part
//! share one smooth *back surface*: the part's average surface moved inward along a smoothed
//! normal field, deep enough that every piece keeps at least the minimum wall in front of it,
//! then smoothed (Laplacian steps, each followed by the wall constraint) so that it has no
//! folds. A piece is its animated front, the common back (reversed) and a wall joining the
//! two along the part boundary. Every piece therefore seats identically on one armature/head,
//! and the construction is checked (not assumed) with the exact self-intersection test of
//! [`self_intersecting_triangles`](super::self_intersecting_triangles): where it finds
//! crossings the back surface is relaxed tangentially around them (never thinner) for a few
//! rounds, keeping the state with the fewest ([`ShellStats::self_intersecting_triangles`]
//! reports what is left). The wall rungs (front boundary point to back boundary point) lean
//! at most `RUNG_SLOPE` sideways per millimetre of depth: the boundary curve's smoothing
//! slides the back points along a crooked boundary and the rungs then fan out through the
//! front (ICT face, 8 pieces per part: 538 crossing triangles of 311,968 before this bound
//! and the untangling's relaxation, 308 with both, 247 with one repair round that sets the
//! crossing rungs straight). Last, [`build_shells`] runs a search over single points
//! (`resolve.rs`): back points (a seam's in every part that shares it, a wall quad's two
//! ends, a spike's three) try a fixed set of moves, and front points where the front folds
//! over a wall shift by at most the printer resolution; a move is kept when the exact test
//! of the triangles around it, in every piece, finds fewer crossings and the wall holds
//! (8 pieces: 247 → 20; what is left: a spike of the cut at the lips and the front folding
//! over the seam wall beside the nose wing in two pieces). A written solid that still crosses
//! itself is regularized ([`regularize`](super::regularize)): the construction keeps those
//! places few and small, the exact arrangement removes them. Where a front point still comes
//! closer to the back than the wall, the back is thickened there (`thicken.rs`).

use std::collections::HashMap;
use std::sync::Arc;

use super::error::{LibraryError, Result};
use super::fabricate::{check_solid, DEFAULT_PRINT_HEIGHT_MM};
use anim::Mesh;
use glam::Vec3;

mod caps;
mod direction;
mod envelope;
mod measure;
mod options;
mod pocket;
mod repair;
mod resolve;
mod seams;
mod thicken;
mod topology;
mod untangle;

pub use measure::{first_thinnest, ThinnestWall};
pub use options::{
    DirectionField, ShellOptions, ShellStats, DEFAULT_BACK_SMOOTHING_ITERATIONS,
    DEFAULT_CAP_FRACTION, DEFAULT_EDGE_RING_RADIUS_MM, DEFAULT_ENVELOPE_LATERAL,
    DEFAULT_ENVELOPE_REACH, DEFAULT_NORMAL_SMOOTHING_MM, DEFAULT_REPAIR_ROUNDS,
    DEFAULT_RESOLVE_ROUNDS,
};
pub use pocket::{Boss, Pocket, PocketMiss, PocketSpec};
pub use seams::{build_shells, ShellInput};

/// Largest sideways slide of a back boundary point per millimetre of wall depth.
const RUNG_SLOPE: f32 = 0.3;

/// How far along a seam the neighbours of a shared back point that had to move deeper
/// follow it, in walls.
const SEAM_SPREAD_WALLS: f64 = 3.0;

/// The shared back surface of one part and how pieces are closed onto it.
#[derive(Debug, Clone)]
pub struct PartShell {
    /// For every shell vertex, the input vertex it copies (UV-seam duplicates welded, bow-tie
    /// vertices split per fan).
    source: Vec<u32>,
    /// Capped boundary loops (shell vertices, boundary order); cap `i` adds the shell vertex
    /// `source.len() + i` at the loop's centroid.
    caps: Vec<Vec<u32>>,
    /// Front triangles over shell vertices (outward oriented, like the input).
    triangles: Vec<[u32; 3]>,
    /// Directed boundary edges `a → b` of the front.
    boundary: Vec<(u32, u32)>,
    /// Back surface position of every shell vertex.
    back: Vec<Vec3>,
    /// Smoothed outward direction of the front at every shell vertex (the back lies along
    /// its negative).
    normals: Vec<Vec3>,
    /// Whether a shell vertex lies on the part boundary.
    on_boundary: Vec<bool>,
    /// Vertex adjacency of the front triangles.
    adjacency: Vec<Vec<u32>>,
    /// Deepest the back may sit along the direction field at every shell vertex (the wall
    /// behind every piece: `back · direction ≤ limit`).
    limits: Vec<f32>,
    /// Shift of every piece's front at each shell vertex (mm, at most the printer
    /// resolution; zero but where a front folds over a wall).
    nudge: Vec<Vec3>,
    /// Retraction per round where a piece's front crosses itself (mm, see `untangle`).
    untangle_step_mm: f32,
    /// The part's pieces' fronts, untangled once (shared with the other direction field's shell).
    fronts: Arc<topology::Fronts>,
    /// The crossings among those fronts' own triangles, found once (shared likewise).
    front_crossings: Arc<measure::FrontCrossings>,
    /// Measurements.
    pub stats: ShellStats,
}

/// What [`PartShell::displace_back`] tells about a back vertex.
#[derive(Debug, Clone, Copy)]
pub(super) struct BackVertex {
    /// On the part boundary (walls start there: leave it in place).
    pub is_boundary: bool,
}

/// Front positions of the shell vertices for one piece (input vertex order): welded copies,
/// then one centroid per cap.
fn front_positions(source: &[u32], caps: &[Vec<u32>], piece: &[Vec3]) -> Vec<Vec3> {
    let mut out: Vec<Vec3> = source.iter().map(|&s| piece[s as usize]).collect();
    for lp in caps {
        let c = lp.iter().map(|&v| out[v as usize]).sum::<Vec3>() / lp.len().max(1) as f32;
        out.push(c);
    }
    out
}

/// Triangles of a solid over `m` front vertices (shell vertex `v`) and the back (`v + m`):
/// the front's `triangles`, the back's reversed, then two wall triangles per `boundary` edge.
fn solid_topology(triangles: &[[u32; 3]], boundary: &[(u32, u32)], m: usize) -> Vec<[u32; 3]> {
    let m = m as u32;
    let mut tris = triangles.to_vec();
    tris.extend(triangles.iter().map(|t| [t[0] + m, t[2] + m, t[1] + m]));
    for &(a, b) in boundary {
        tris.push([b, a, a + m]);
        tris.push([b, a + m, b + m]);
    }
    tris
}

/// Exact key of a position (welding, seam matching): its bits.
fn position_key(p: Vec3) -> [u32; 3] {
    p.to_array().map(f32::to_bits)
}

/// Centroid of the points `around` (non-empty) of `points`.
fn centroid(points: &[Vec3], around: &[u32]) -> Vec3 {
    around
        .iter()
        .fold(Vec3::ZERO, |a, &w| a + points[w as usize])
        / around.len() as f32
}

impl PartShell {
    /// Builds the back surface of a part.
    ///
    /// # Arguments
    /// * `topology` — the part's triangles (outward oriented, edge-manifold after welding).
    /// * `average` — the part's average surface, millimetres.
    /// * `pieces` — every piece of the part, millimetres (same vertex count).
    /// * `opts` — wall and smoothing.
    ///
    /// # Errors
    /// [`LibraryError::InvalidParameter`] for bad options or sizes,
    /// [`LibraryError::BadSurface`] when the surface is not an oriented 2-manifold.
    pub fn new(
        topology: &Mesh,
        average: &[Vec3],
        pieces: &[&[Vec3]],
        opts: &ShellOptions,
    ) -> Result<PartShell> {
        Self::new_sharing(topology, average, pieces, opts, &[])
    }

    /// [`PartShell::new`] for a part that meets already built parts along seams: a boundary
    /// vertex whose average position equals the first element of a pair in `shared` (see
    /// [`PartShell::boundary_pairs`]) gets that pair's back position, so the walls of both
    /// parts along their common seam are the same surface and the parts mate face to face.
    ///
    /// # Errors
    /// As [`PartShell::new`].
    pub fn new_sharing(
        topology: &Mesh,
        average: &[Vec3],
        pieces: &[&[Vec3]],
        opts: &ShellOptions,
        shared: &[(Vec3, Vec3)],
    ) -> Result<PartShell> {
        let bad = |reason: String| LibraryError::BadSurface {
            mesh: topology.name.clone(),
            reason,
        };
        if !(opts.wall_mm.is_finite() && opts.wall_mm > 0.0) {
            return Err(LibraryError::InvalidParameter(format!(
                "wall must be finite and > 0 mm, got {}",
                opts.wall_mm
            )));
        }
        if !(opts.model_height_mm.is_finite() && opts.model_height_mm > 0.0) {
            return Err(LibraryError::InvalidParameter(format!(
                "model height must be finite and > 0 mm, got {}",
                opts.model_height_mm
            )));
        }
        if let DirectionField::EdgeRings { radius_mm: w }
        | DirectionField::Geodesic { sigma_mm: w } = opts.direction
        {
            if !(w.is_finite() && w >= 0.0) {
                return Err(LibraryError::InvalidParameter(format!(
                    "normal smoothing must be finite and >= 0 mm, got {w}"
                )));
            }
        }
        let nv = topology.positions.len();
        if average.len() != nv || pieces.iter().any(|p| p.len() != nv) {
            return Err(LibraryError::InvalidParameter(format!(
                "part '{}': average and pieces need {nv} vertices",
                topology.name
            )));
        }
        if topology.triangles.is_empty() {
            return Err(bad("no triangle".into()));
        }
        let frame = topology::PartFrame::new(
            topology,
            average,
            pieces,
            opts.cap_fraction,
            untangle::step_for_height(opts.model_height_mm),
        )?;
        // The fronts' own crossings, whatever the back. A shell's front adds its nudge (zero
        // until the shells are resolved against each other), so these do too.
        let n = frame.topo.front.len();
        let front_crossings = Arc::new(measure::FrontCrossings::new(
            frame
                .fronts
                .untangled
                .iter()
                .map(|f| f.iter().map(|&p| p + Vec3::ZERO).collect())
                .collect(),
            solid_topology(&frame.topo.triangles, &frame.topo.boundary, n),
            frame.topo.triangles.len(),
            n,
        ));
        // Inward direction field (see `DirectionField`); the frame is shared by both fields.
        let (front, tris, adj) = (&frame.topo.front, &frame.topo.triangles, &frame.adj);
        let rings = |radius_mm| direction::edge_ring_directions(front, tris, adj, radius_mm);
        let disc =
            |sigma_mm: f64| direction::smoothed_directions(front, tris, adj, sigma_mm as f32);
        match opts.direction {
            DirectionField::EdgeRings { radius_mm } => Ok(Self::along(
                &frame,
                &front_crossings,
                rings(radius_mm),
                pieces,
                opts,
                shared,
            )),
            DirectionField::Geodesic { sigma_mm } => Ok(Self::along(
                &frame,
                &front_crossings,
                disc(sigma_mm),
                pieces,
                opts,
                shared,
            )),
            DirectionField::Best => {
                let scale = opts.model_height_mm / DEFAULT_PRINT_HEIGHT_MM;
                let (a, b) = rayon::join(
                    || {
                        Self::along(
                            &frame,
                            &front_crossings,
                            rings(DEFAULT_EDGE_RING_RADIUS_MM * scale),
                            pieces,
                            opts,
                            shared,
                        )
                    },
                    || {
                        Self::along(
                            &frame,
                            &front_crossings,
                            disc(DEFAULT_NORMAL_SMOOTHING_MM * scale),
                            pieces,
                            opts,
                            shared,
                        )
                    },
                );
                Ok(direction::better(a, b, opts.wall_mm))
            }
        }
    }

    /// The back surface of the part `frame` along the direction field `normals`: the
    /// envelope, the shared seam points, the smoothing and the repair of [`PartShell::new_sharing`].
    fn along(
        frame: &topology::PartFrame,
        front_crossings: &Arc<measure::FrontCrossings>,
        normals: Vec<Vec3>,
        pieces: &[&[Vec3]],
        opts: &ShellOptions,
        shared: &[(Vec3, Vec3)],
    ) -> PartShell {
        let topology::PartFrame {
            topo,
            adj,
            on_boundary,
            fronts,
            untangle_step_mm,
        } = frame;
        let (front, tris, boundary) = (&topo.front, &topo.triangles, &topo.boundary);
        let n = front.len();
        // Deepest point any piece reaches in a column around the direction field, per
        // vertex, minus the wall.
        let wall = opts.wall_mm as f32;
        let limit = envelope::envelope_limits(
            front,
            &fronts.untangled,
            &normals,
            wall,
            (DEFAULT_ENVELOPE_LATERAL * opts.model_height_mm) as f32,
            (DEFAULT_ENVELOPE_REACH * opts.model_height_mm) as f32,
        );
        let shared_at: HashMap<[u32; 3], Vec3> =
            shared.iter().map(|(a, b)| (position_key(*a), *b)).collect();
        let mut along: Vec<[u32; 2]> = vec![[u32::MAX; 2]; n];
        for &(a, b) in boundary {
            along[a as usize][1] = b;
            along[b as usize][0] = a;
        }
        // This part's boundary vertices on a seam with an earlier part, and their back points
        // (moved deeper where they lie within this part's wall).
        let shared_points: Vec<Option<Vec3>> = (0..n)
            .map(|v| {
                on_boundary[v]
                    .then(|| shared_at.get(&position_key(front[v])).copied())
                    .flatten()
            })
            .collect();
        let fixed = seams::deepen_shared(
            &shared_points,
            front,
            &normals,
            &limit,
            &along,
            (SEAM_SPREAD_WALLS * opts.wall_mm) as f32,
        );
        let enforce = |back: &mut [Vec3]| {
            for v in 0..n {
                if let Some(p) = fixed[v] {
                    back[v] = p;
                    continue;
                }
                let d = normals[v];
                let h = back[v].dot(d);
                if h > limit[v] {
                    back[v] -= d * (h - limit[v]);
                }
                if on_boundary[v] {
                    // Wall rungs stay steep: a back boundary point slid far sideways fans
                    // the rungs out over a crooked boundary, through the front and each other.
                    let e = back[v] - front[v];
                    let depth = (-e.dot(d)).max(0.0);
                    let side = e + d * depth;
                    let (most, l) = (RUNG_SLOPE * depth, side.length());
                    if l > most {
                        back[v] = front[v] - d * depth + side * (most / l);
                    }
                }
            }
        };
        let mut back: Vec<Vec3> = (0..n).map(|v| front[v] - normals[v] * wall).collect();
        enforce(&mut back);
        // Neighbours along the boundary loops: the back's boundary curve is smoothed along
        // them (positions, not only depths) so the wall strip between the front's boundary
        // and it neither zigzags where the depth needed changes nor loops where the boundary
        // bends tighter than the depth (an inward offset curve would: its rungs cross).
        // One smoothing step of a boundary point along its loop (none at a loop's open end).
        let along_loop = |back: &[Vec3], v: usize| {
            let [p, q] = along[v];
            (p != u32::MAX && q != u32::MAX)
                .then(|| back[v] * 0.5 + (back[p as usize] + back[q as usize]) * 0.25)
        };
        let smooth = |back: &mut Vec<Vec3>, mask: Option<&[bool]>| {
            let next: Vec<Vec3> = (0..n)
                .map(|v| {
                    if on_boundary[v] && !opts.smooth_boundary {
                        if fixed[v].is_some() || mask.is_some_and(|m| !m[v]) {
                            return back[v];
                        }
                        return along_loop(back, v).unwrap_or(back[v]);
                    }
                    if mask.is_some_and(|m| !m[v]) || adj[v].is_empty() {
                        return back[v];
                    }
                    let c = centroid(back, &adj[v]);
                    back[v] + (c - back[v]) * 0.5
                })
                .collect();
            *back = next;
        };
        for _ in 0..opts.smoothing_iterations {
            smooth(&mut back, None);
            enforce(&mut back);
        }
        let mut shell = PartShell {
            source: topo.source.clone(),
            caps: topo.caps.clone(),
            triangles: tris.clone(),
            boundary: boundary.clone(),
            back,
            normals: normals.clone(),
            on_boundary: on_boundary.clone(),
            adjacency: adj.clone(),
            limits: limit.clone(),
            nudge: vec![Vec3::ZERO; n],
            untangle_step_mm: *untangle_step_mm,
            fronts: Arc::clone(fronts),
            front_crossings: Arc::clone(front_crossings),
            stats: ShellStats::default(),
        };
        shell.repair(front, &fixed, pieces, opts, &enforce, &along_loop);
        shell
    }

    /// Back surface positions of the shell vertices (millimetres).
    pub fn back(&self) -> &[Vec3] {
        &self.back
    }

    /// Directed boundary edges `a → b` of the front (shell vertices).
    pub fn boundary_edges(&self) -> &[(u32, u32)] {
        &self.boundary
    }

    /// Smoothed outward direction of the front at shell vertex `v`.
    pub fn direction(&self, v: usize) -> Vec3 {
        self.normals[v]
    }

    /// Moves every back vertex `f(info, position)` millimetres out of the solid (against the
    /// smoothed front direction).
    pub(super) fn displace_back(&mut self, f: impl Fn(BackVertex, Vec3) -> f32) {
        for v in 0..self.back.len() {
            let info = BackVertex {
                is_boundary: self.on_boundary[v],
            };
            let d = f(info, self.back[v]);
            if d.is_finite() && d != 0.0 {
                self.back[v] -= self.normals[v] * d;
            }
        }
    }

    /// Triangles of the front that cap openings (the last ones of [`PartShell::triangles`]).
    pub fn cap_triangle_count(&self) -> usize {
        self.caps.iter().map(Vec::len).sum()
    }

    /// Front triangles over the shell vertices.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Input vertex of every shell vertex.
    pub fn sources(&self) -> &[u32] {
        &self.source
    }

    /// Front of `piece` over the shell vertices (caps included), untangled where it
    /// crosses itself.
    fn front(&self, piece: &[Vec3]) -> Vec<Vec3> {
        let laid = front_positions(&self.source, &self.caps, piece);
        // A piece of the part was untangled when the part was laid out; another one (a
        // caller's) is untangled here.
        let mut f = match self.fronts.find(&laid) {
            Some(untangled) => untangled.to_vec(),
            None => {
                let mut f = laid;
                untangle::untangle(
                    &mut f,
                    &self.triangles,
                    &self.adjacency,
                    &self.on_boundary,
                    self.untangle_step_mm,
                );
                f
            }
        };
        for (p, d) in f.iter_mut().zip(&self.nudge) {
            *p += *d;
        }
        f
    }

    /// Triangles of every piece's solid over the front (shell vertex `v`) and the back
    /// (`v + back.len()`): front, back reversed, then two wall triangles per boundary edge.
    fn solid_topology(&self) -> Vec<[u32; 3]> {
        solid_topology(&self.triangles, &self.boundary, self.back.len())
    }

    fn solid_unchecked(&self, piece: &[Vec3], name: &str) -> Mesh {
        let mut positions = self.front(piece);
        positions.extend_from_slice(&self.back);
        Mesh::new(name, positions, self.solid_topology())
    }

    /// Piece `piece` (millimetres, input vertex order) closed onto the back surface: the
    /// printable solid, named `name`.
    ///
    /// # Errors
    /// [`LibraryError::InvalidParameter`] for a wrong vertex count, [`LibraryError::BadSurface`]
    /// if the result is not a closed oriented manifold.
    pub fn solid(&self, piece: &[Vec3], name: &str) -> Result<Mesh> {
        if let Some(&s) = self.source.iter().max() {
            if s as usize >= piece.len() {
                return Err(LibraryError::InvalidParameter(format!(
                    "piece {name}: {} vertices, the part needs more than {s}",
                    piece.len()
                )));
            }
        }
        let solid = self.solid_unchecked(piece, name);
        let check = check_solid(&solid);
        if !check.is_closed_manifold() {
            return Err(LibraryError::BadSurface {
                mesh: name.to_string(),
                reason: format!("shell is not a closed manifold ({check:?})"),
            });
        }
        Ok(solid)
    }
}

#[cfg(test)]
mod tests;
