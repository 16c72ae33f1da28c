//! Connectivity of a (welded) triangle mesh: edges, triangle adjacency, vertex rings.

/// An edge shared by two triangles (a link of the dual graph).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct DualEdge {
    /// First triangle.
    pub a: u32,
    /// Second triangle (`a < b`).
    pub b: u32,
    /// The two shared (welded) vertices, `v[0] < v[1]`.
    pub v: [u32; 2],
}

/// Compressed adjacency lists (`offsets.len() = n + 1`).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub(crate) struct Csr {
    /// Start of every row in `items`.
    pub offsets: Vec<u32>,
    /// Concatenated rows.
    pub items: Vec<u32>,
}

impl Csr {
    /// Row `i`.
    pub(crate) fn row(&self, i: usize) -> &[u32] {
        &self.items[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    /// Number of rows.
    pub(crate) fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    fn from_pairs(n: usize, pairs: &mut [(u32, u32)]) -> Csr {
        pairs.sort_unstable();
        let mut offsets = vec![0u32; n + 1];
        let mut items = Vec::with_capacity(pairs.len());
        let mut last = None;
        for &(r, c) in pairs.iter() {
            if last == Some((r, c)) {
                continue;
            }
            last = Some((r, c));
            offsets[r as usize + 1] += 1;
            items.push(c);
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        Csr { offsets, items }
    }
}

/// Edges, dual graph and vertex one-rings of a triangle mesh.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Topology {
    /// Unique undirected edges `(a, b)`, `a < b`, sorted.
    pub edges: Vec<[u32; 2]>,
    /// Pairs of triangles sharing an edge. Non-manifold edges link every pair of their
    /// triangles; degenerate triangles (repeated corners) link nothing.
    pub dual: Vec<DualEdge>,
    /// Vertex one-rings (neighbours through an edge), sorted.
    pub neighbors: Csr,
    /// Triangles around every vertex.
    pub vertex_triangles: Csr,
}

impl Topology {
    /// Builds the connectivity of `triangles` over `vertices` vertices.
    ///
    /// # Performance
    /// O(k log k) for k triangles (sorting).
    pub(crate) fn new(vertices: usize, triangles: &[[u32; 3]]) -> Topology {
        let mut half: Vec<([u32; 2], u32)> = Vec::with_capacity(triangles.len() * 3);
        let mut vt: Vec<(u32, u32)> = Vec::with_capacity(triangles.len() * 3);
        for (t, tri) in triangles.iter().enumerate() {
            let degenerate = tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2];
            for k in 0..3 {
                vt.push((tri[k], t as u32));
                if !degenerate {
                    let (a, b) = (tri[k], tri[(k + 1) % 3]);
                    half.push(([a.min(b), a.max(b)], t as u32));
                }
            }
        }
        half.sort_unstable();
        let mut edges = Vec::new();
        let mut dual = Vec::new();
        let mut nb = Vec::with_capacity(half.len() * 2);
        let mut i = 0;
        while i < half.len() {
            let mut j = i;
            while j < half.len() && half[j].0 == half[i].0 {
                j += 1;
            }
            let e = half[i].0;
            edges.push(e);
            nb.push((e[0], e[1]));
            nb.push((e[1], e[0]));
            for p in i..j {
                for q in p + 1..j {
                    let (a, b) = (half[p].1, half[q].1);
                    if a != b {
                        dual.push(DualEdge {
                            a: a.min(b),
                            b: a.max(b),
                            v: e,
                        });
                    }
                }
            }
            i = j;
        }
        Topology {
            edges,
            dual,
            neighbors: Csr::from_pairs(vertices, &mut nb),
            vertex_triangles: Csr::from_pairs(vertices, &mut vt),
        }
    }
}

/// Connected components of the vertex graph (component id per vertex, and the count).
pub(super) fn vertex_components(neighbors: &Csr) -> (Vec<u32>, usize) {
    let n = neighbors.len();
    let mut comp = vec![u32::MAX; n];
    let mut count = 0u32;
    let mut stack = Vec::new();
    for s in 0..n {
        if comp[s] != u32::MAX {
            continue;
        }
        comp[s] = count;
        stack.push(s as u32);
        while let Some(v) = stack.pop() {
            for &w in neighbors.row(v as usize) {
                if comp[w as usize] == u32::MAX {
                    comp[w as usize] = count;
                    stack.push(w);
                }
            }
        }
        count += 1;
    }
    (comp, count as usize)
}

/// Vertices on an edge used by a single triangle (open mesh borders) of `tris` over `n`
/// vertices.
pub(crate) fn open_border(n: usize, tris: &[[u32; 3]]) -> Vec<bool> {
    let mut count: std::collections::HashMap<(u32, u32), u32> =
        std::collections::HashMap::with_capacity(tris.len() * 3);
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut out = vec![false; n];
    for (&(a, b), &c) in &count {
        if c == 1 {
            out[a as usize] = true;
            out[b as usize] = true;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_has_one_dual_edge() {
        let t = Topology::new(4, &[[0, 1, 2], [0, 2, 3]]);
        assert_eq!(t.edges.len(), 5);
        assert_eq!(
            t.dual,
            vec![DualEdge {
                a: 0,
                b: 1,
                v: [0, 2]
            }]
        );
        assert_eq!(t.neighbors.row(0), &[1, 2, 3]);
        assert_eq!(t.vertex_triangles.row(2), &[0, 1]);
        let (c, n) = vertex_components(&t.neighbors);
        assert_eq!((c, n), (vec![0; 4], 1));
    }
}
