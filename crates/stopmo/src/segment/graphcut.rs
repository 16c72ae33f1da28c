//! Multi-label Potts energies on a graph: exact min-cut for two labels, α-expansion
//! (Boykov, Veksler, Zabih 2001) beyond, with the graph construction of Kolmogorov and
//! Zabih 2004 ("What energy functions can be minimized via graph cuts?").

use super::maxflow::MaxFlow;

/// Default cap on α-expansion cycles (one cycle tries every label once).
pub const DEFAULT_MAX_EXPANSION_CYCLES: usize = 20;

/// A Potts labeling problem: `E(l) = Σ_p D_p(l_p) + Σ_(p,q) w_pq [l_p ≠ l_q]` (StopShop Eq. 1 shape).
#[derive(Debug, Clone, Copy)]
pub struct PottsProblem<'a> {
    /// Number of labels `s ≥ 1`.
    pub labels: usize,
    /// Node-major unary costs `D_p(l)` at `p * labels + l`; `f64::INFINITY` forbids a label
    /// (hard constraint). Every node must allow at least one label.
    pub unary: &'a [f64],
    /// Pairwise links `(p, q, w_pq)` with `w_pq ≥ 0`.
    pub edges: &'a [(u32, u32, f64)],
}

impl PottsProblem<'_> {
    /// Number of nodes.
    pub fn nodes(&self) -> usize {
        self.unary.len() / self.labels.max(1)
    }

    /// Energy of a labeling (infinite when a hard constraint is violated).
    pub fn energy(&self, labels: &[u32]) -> f64 {
        let s = self.labels;
        let unary: f64 = labels
            .iter()
            .enumerate()
            .map(|(p, &l)| self.unary[p * s + l as usize])
            .sum();
        let pair: f64 = self
            .edges
            .iter()
            .filter(|(p, q, _)| labels[*p as usize] != labels[*q as usize])
            .map(|e| e.2)
            .sum();
        unary + pair
    }

    /// A finite stand-in for infinite costs that exceeds the energy of every labeling that
    /// respects the hard constraints.
    fn big(&self) -> f64 {
        let s = self.labels;
        let mut total = 1.0;
        for p in 0..self.nodes() {
            let row = &self.unary[p * s..(p + 1) * s];
            total += row
                .iter()
                .copied()
                .filter(|c| c.is_finite())
                .fold(0.0, f64::max);
        }
        total + self.edges.iter().map(|e| e.2.max(0.0)).sum::<f64>()
    }
}

/// Adds a two-variable term `E(x, y)` with table `[[e00, e01], [e10, e11]]`, regular
/// (`e00 + e11 ≤ e01 + e10`); node on the source side ⇔ variable = 0.
fn add_term2(g: &mut MaxFlow, x: usize, y: usize, e00: f64, e01: f64, e10: f64, e11: f64) {
    g.add_tweights(x, e11, e00);
    let (b, c) = (e01 - e00, e10 - e11);
    if b < 0.0 {
        g.add_tweights(x, 0.0, b);
        g.add_tweights(y, 0.0, -b);
        g.add_edge(x, y, 0.0, b + c);
    } else if c < 0.0 {
        g.add_tweights(x, 0.0, -c);
        g.add_tweights(y, 0.0, c);
        g.add_edge(x, y, b + c, 0.0);
    } else {
        g.add_edge(x, y, b, c);
    }
}

fn finite(c: f64, big: f64) -> f64 {
    if c.is_finite() {
        c
    } else {
        big
    }
}

/// Exact minimum of a two-label Potts energy by one minimum cut.
///
/// # Returns
/// Labels in `{0, 1}`.
///
/// # Performance
/// One Boykov–Kolmogorov max-flow on `nodes` nodes and `edges` links.
pub fn solve_two_labels(problem: &PottsProblem) -> Vec<u32> {
    debug_assert_eq!(problem.labels, 2);
    let n = problem.nodes();
    let big = problem.big();
    let mut g = MaxFlow::new(n);
    for p in 0..n {
        // Label 1 = sink side: pay D(1) when on the sink side, D(0) on the source side.
        g.add_tweights(
            p,
            finite(problem.unary[2 * p + 1], big),
            finite(problem.unary[2 * p], big),
        );
    }
    for &(p, q, w) in problem.edges {
        g.add_edge(p as usize, q as usize, w, w);
    }
    g.solve();
    (0..n).map(|p| g.is_sink_side(p) as u32).collect()
}

/// Minimizes a Potts energy: exactly for two labels, by α-expansion for more (within a
/// factor 2 of the optimum for Potts energies).
///
/// # Arguments
/// * `problem` — costs and links.
/// * `max_cycles` — cap on expansion cycles ([`DEFAULT_MAX_EXPANSION_CYCLES`]).
///
/// # Returns
/// One label per node; starts from the per-node cheapest label and stops when a full cycle
/// over all labels lowers the energy no more.
pub fn minimize_potts(problem: &PottsProblem, max_cycles: usize) -> Vec<u32> {
    let s = problem.labels;
    let n = problem.nodes();
    if s <= 1 {
        return vec![0; n];
    }
    if s == 2 {
        return solve_two_labels(problem);
    }
    let mut labels: Vec<u32> = (0..n)
        .map(|p| {
            let row = &problem.unary[p * s..(p + 1) * s];
            (0..s)
                .min_by(|&a, &b| row[a].total_cmp(&row[b]))
                .unwrap_or(0) as u32
        })
        .collect();
    let big = problem.big();
    let mut energy = problem.energy(&labels);
    for _ in 0..max_cycles {
        let mut improved = false;
        for alpha in 0..s as u32 {
            let proposal = expansion_move(problem, &labels, alpha, big);
            let e = problem.energy(&proposal);
            if e < energy - 1e-12 * energy.abs().max(1.0) {
                energy = e;
                labels = proposal;
                improved = true;
            }
        }
        if !improved {
            break;
        }
    }
    labels
}

/// One α-expansion move: every node keeps its label (variable 0) or switches to α (1).
fn expansion_move(problem: &PottsProblem, labels: &[u32], alpha: u32, big: f64) -> Vec<u32> {
    let s = problem.labels;
    let n = labels.len();
    let mut g = MaxFlow::new(n);
    let cost = |p: usize, l: u32| finite(problem.unary[p * s + l as usize], big);
    for p in 0..n {
        if labels[p] != alpha {
            g.add_tweights(p, cost(p, alpha), cost(p, labels[p]));
        }
    }
    for &(p, q, w) in problem.edges {
        let (p, q) = (p as usize, q as usize);
        let (lp, lq) = (labels[p], labels[q]);
        let v = |a: u32, b: u32| if a == b { 0.0 } else { w };
        add_term2(&mut g, p, q, v(lp, lq), v(lp, alpha), v(alpha, lq), 0.0);
    }
    g.solve();
    (0..n)
        .map(|p| if g.is_sink_side(p) { alpha } else { labels[p] })
        .collect()
}
