//! A bounding-volume hierarchy over a triangle soup for nearest-point queries (median split
//! on the longest axis; leaves of up to [`LEAF`] triangles).

use anim::Aabb;
use glam::Vec3;

/// Most triangles in a leaf.
const LEAF: usize = 4;

/// One node: a box and either two children or a range of [`Bvh::order`].
#[derive(Debug, Clone)]
struct Node {
    bounds: Aabb,
    /// Children (`left`, `left + 1`) when `count == 0`, else the first triangle in `order`.
    first: u32,
    count: u32,
}

/// The hierarchy; triangles are referred to by index.
#[derive(Debug, Clone, Default)]
pub(super) struct Bvh {
    nodes: Vec<Node>,
    order: Vec<u32>,
}

/// Squared distance from `p` to box `b` (0 inside).
fn distance_squared(b: &Aabb, p: Vec3) -> f32 {
    (b.min - p).max(p - b.max).max(Vec3::ZERO).length_squared()
}

impl Bvh {
    /// Builds the hierarchy of triangles given by their corner boxes.
    pub(super) fn new(boxes: &[Aabb]) -> Bvh {
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(2 * boxes.len() / LEAF + 1),
            order: (0..boxes.len() as u32).collect(),
        };
        if !boxes.is_empty() {
            bvh.nodes.push(Node {
                bounds: Aabb::EMPTY,
                first: 0,
                count: 0,
            });
            bvh.split(0, 0, boxes.len(), boxes);
        }
        bvh
    }

    fn split(&mut self, node: usize, lo: usize, hi: usize, boxes: &[Aabb]) {
        let mut bounds = Aabb::EMPTY;
        for &t in &self.order[lo..hi] {
            bounds.grow(boxes[t as usize].min);
            bounds.grow(boxes[t as usize].max);
        }
        self.nodes[node].bounds = bounds;
        if hi - lo <= LEAF {
            self.nodes[node].first = lo as u32;
            self.nodes[node].count = (hi - lo) as u32;
            return;
        }
        let size = bounds.max - bounds.min;
        let axis = if size.x >= size.y && size.x >= size.z {
            0
        } else if size.y >= size.z {
            1
        } else {
            2
        };
        let centre = |t: &u32| {
            let b = &boxes[*t as usize];
            (b.min[axis] + b.max[axis]) * 0.5
        };
        let mid = (lo + hi) / 2;
        self.order[lo..hi].select_nth_unstable_by(mid - lo, |x, y| centre(x).total_cmp(&centre(y)));
        let left = self.nodes.len();
        for _ in 0..2 {
            self.nodes.push(Node {
                bounds: Aabb::EMPTY,
                first: 0,
                count: 0,
            });
        }
        self.nodes[node].first = left as u32;
        self.split(left, lo, mid, boxes);
        self.split(left + 1, mid, hi, boxes);
    }

    /// The triangle nearest to `p` by `nearest(t, p) -> (squared distance, payload)`, with
    /// its payload; `None` when there are no triangles.
    pub(super) fn nearest<T>(
        &self,
        p: Vec3,
        nearest: impl Fn(u32) -> (f32, T),
    ) -> Option<(u32, f32, T)> {
        let mut best: Option<(u32, f32, T)> = None;
        let mut stack = Vec::with_capacity(64);
        if !self.nodes.is_empty() {
            stack.push(0usize);
        }
        while let Some(k) = stack.pop() {
            let node = &self.nodes[k];
            let bound = best.as_ref().map_or(f32::INFINITY, |b| b.1);
            if distance_squared(&node.bounds, p) > bound {
                continue;
            }
            if node.count > 0 {
                let range = node.first as usize..(node.first + node.count) as usize;
                for &t in &self.order[range] {
                    let (d, payload) = nearest(t);
                    if best.as_ref().is_none_or(|b| d < b.1) {
                        best = Some((t, d, payload));
                    }
                }
                continue;
            }
            // Nearer child last, so it is visited first.
            let (l, r) = (node.first as usize, node.first as usize + 1);
            let (dl, dr) = (
                distance_squared(&self.nodes[l].bounds, p),
                distance_squared(&self.nodes[r].bounds, p),
            );
            if dl < dr {
                stack.extend([r, l]);
            } else {
                stack.extend([l, r]);
            }
        }
        best
    }
}
