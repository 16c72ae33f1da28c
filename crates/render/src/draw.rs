//! What to draw: meshes with colours and shading, polylines and points.

use anim::Mesh;
use glam::{Vec2, Vec3};

use crate::color::Color;

/// Default surface colour (light grey, linear).
pub const DEFAULT_MESH_COLOR: Color = [0.62, 0.62, 0.62, 1.0];

/// Colours of a mesh (linear RGBA, straight alpha).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MeshColors<'a> {
    /// One colour for the whole mesh.
    Uniform(Color),
    /// One colour per vertex, interpolated across triangles.
    PerVertex(&'a [Color]),
    /// One colour per triangle (part labels).
    PerTriangle(&'a [Color]),
}

/// How a mesh is lit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Shading {
    /// Lambert lighting with interpolated vertex normals.
    #[default]
    Smooth,
    /// Lambert lighting with one normal per triangle.
    Flat,
    /// Colours as given, no lighting (scalar fields read exactly).
    Unlit,
}

/// Which mesh edges to draw on top of the surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EdgeMode {
    /// Every triangle edge.
    Wireframe,
    /// Boundary edges and edges between a front- and a back-facing triangle.
    Silhouette,
}

/// Edge overlay of a mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeStyle {
    /// Which edges.
    pub mode: EdgeMode,
    /// Line colour.
    pub color: Color,
    /// Line width in pixels.
    pub width: f32,
}

/// One mesh to draw: borrowed positions and triangles plus appearance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshItem<'a> {
    /// Name used in error messages.
    pub label: &'a str,
    /// World-space positions.
    pub positions: &'a [Vec3],
    /// Triangles (counter-clockwise seen from outside).
    pub triangles: &'a [[u32; 3]],
    /// Surface colours.
    pub colors: MeshColors<'a>,
    /// World-space vertex normals; computed (area-weighted) when `None`.
    pub normals: Option<&'a [Vec3]>,
    /// Multiplies every alpha; below 1 the mesh is drawn in the translucent pass.
    pub opacity: f32,
    /// Lighting model.
    pub shading: Shading,
    /// Optional edge overlay.
    pub edges: Option<EdgeStyle>,
}

impl<'a> MeshItem<'a> {
    /// A grey, opaque, smooth-shaded mesh.
    pub fn new(positions: &'a [Vec3], triangles: &'a [[u32; 3]]) -> MeshItem<'a> {
        MeshItem {
            label: "mesh",
            positions,
            triangles,
            colors: MeshColors::Uniform(DEFAULT_MESH_COLOR),
            normals: None,
            opacity: 1.0,
            shading: Shading::Smooth,
            edges: None,
        }
    }

    /// A static mesh with its own vertex colours (when present); its stored normals are used
    /// only when they match the vertex count.
    pub fn from_mesh(mesh: &'a Mesh) -> MeshItem<'a> {
        let mut item = MeshItem::new(&mesh.positions, &mesh.triangles).label(&mesh.name);
        if let Some(c) = mesh.colors.as_deref() {
            item.colors = MeshColors::PerVertex(c);
        }
        item.normals = mesh
            .normals
            .as_deref()
            .filter(|n| n.len() == mesh.positions.len());
        item
    }

    /// Frame `frame` of a point cache (clamped to the last frame), with the mesh's vertex
    /// colours when present. Normals are recomputed from the frame's positions.
    pub fn from_animation(animation: &'a anim::MeshAnimation, frame: usize) -> MeshItem<'a> {
        let f = frame.min(animation.frame_count().saturating_sub(1));
        let mesh = &animation.mesh;
        let positions = if mesh.vertex_count() == 0 {
            &[][..]
        } else {
            animation.frame(f)
        };
        let mut item = MeshItem::new(positions, &mesh.triangles).label(&mesh.name);
        if let Some(c) = mesh.colors.as_deref() {
            item.colors = MeshColors::PerVertex(c);
        }
        item
    }

    /// Sets the label used in errors.
    pub fn label(mut self, label: &'a str) -> Self {
        self.label = label;
        self
    }

    /// Sets the colours.
    pub fn colors(mut self, colors: MeshColors<'a>) -> Self {
        self.colors = colors;
        self
    }

    /// Sets one colour.
    pub fn color(mut self, color: Color) -> Self {
        self.colors = MeshColors::Uniform(color);
        self
    }

    /// Sets the opacity.
    pub fn opacity(mut self, opacity: f32) -> Self {
        self.opacity = opacity;
        self
    }

    /// Sets the lighting model.
    pub fn shading(mut self, shading: Shading) -> Self {
        self.shading = shading;
        self
    }

    /// Sets world-space vertex normals.
    pub fn normals(mut self, normals: &'a [Vec3]) -> Self {
        self.normals = Some(normals);
        self
    }

    /// Draws edges on top.
    pub fn edges(mut self, edges: EdgeStyle) -> Self {
        self.edges = Some(edges);
        self
    }
}

/// Point coordinates of an overlay.
#[derive(Debug, Clone, PartialEq)]
pub enum Coords {
    /// Pixel coordinates (x right, y down, pixel centres at `k + 0.5`) of the final image.
    Pixel(Vec<Vec2>),
    /// World coordinates, projected by the view.
    World(Vec<Vec3>),
}

impl Coords {
    /// Number of points.
    pub fn len(&self) -> usize {
        match self {
            Coords::Pixel(p) => p.len(),
            Coords::World(p) => p.len(),
        }
    }

    /// True when there is no point.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Whether an overlay is a connected line or separate dots.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OverlayKind {
    /// A polyline through the points (round joins and caps).
    Polyline,
    /// One disc per point.
    Points,
}

/// A 2D overlay drawn after the meshes: a polyline or points, anti-aliased.
#[derive(Debug, Clone, PartialEq)]
pub struct Overlay {
    /// Line or dots.
    pub kind: OverlayKind,
    /// The points.
    pub coords: Coords,
    /// One colour for all, or one per point (interpolated along segments); linear RGBA.
    pub colors: Vec<Color>,
    /// Line width (or dot diameter) in pixels of the final image.
    pub width: f32,
    /// Hide parts behind meshes (world coordinates only).
    pub depth_test: bool,
}

impl Overlay {
    /// A polyline of one colour.
    pub fn polyline(coords: Coords, color: Color, width: f32) -> Overlay {
        Overlay {
            kind: OverlayKind::Polyline,
            coords,
            colors: vec![color],
            width,
            depth_test: false,
        }
    }

    /// Dots of one colour and diameter `width`.
    pub fn points(coords: Coords, color: Color, width: f32) -> Overlay {
        Overlay {
            kind: OverlayKind::Points,
            coords,
            colors: vec![color],
            width,
            depth_test: false,
        }
    }

    /// One colour per point (ignored unless it has one entry per point).
    pub fn with_colors(mut self, colors: Vec<Color>) -> Self {
        self.colors = colors;
        self
    }

    /// Hides parts behind meshes.
    pub fn with_depth_test(mut self, on: bool) -> Self {
        self.depth_test = on;
        self
    }

    /// Colour of point `i`.
    pub(crate) fn color_at(&self, i: usize) -> Color {
        if self.colors.len() == self.coords.len() {
            self.colors[i]
        } else {
            self.colors.first().copied().unwrap_or([0.0, 0.0, 0.0, 1.0])
        }
    }
}

/// Everything drawn in one image: meshes first (opaque, then translucent back to front), then
/// overlays in order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DrawList<'a> {
    /// Meshes.
    pub meshes: Vec<MeshItem<'a>>,
    /// Overlays, drawn in order on top.
    pub overlays: Vec<Overlay>,
}

impl<'a> DrawList<'a> {
    /// An empty list.
    pub fn new() -> Self {
        DrawList::default()
    }

    /// Adds a mesh.
    pub fn mesh(mut self, item: MeshItem<'a>) -> Self {
        self.meshes.push(item);
        self
    }

    /// Adds an overlay.
    pub fn overlay(mut self, overlay: Overlay) -> Self {
        self.overlays.push(overlay);
        self
    }

    /// Bounding box of every mesh position and world-space overlay point.
    pub fn bbox(&self) -> anim::Aabb {
        let mut b = anim::Aabb::EMPTY;
        for m in &self.meshes {
            b = b.union(anim::Aabb::from_points(m.positions));
        }
        for o in &self.overlays {
            if let Coords::World(p) = &o.coords {
                b = b.union(anim::Aabb::from_points(p));
            }
        }
        b
    }
}
