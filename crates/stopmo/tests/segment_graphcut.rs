//! Boykov–Kolmogorov max-flow and the Potts solvers against brute force on small graphs.

use stopmo::segment::solver::{minimize_potts, MaxFlow, PottsProblem};

/// Deterministic xorshift generator.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

struct Graph {
    n: usize,
    t: Vec<(f64, f64)>,
    e: Vec<(usize, usize, f64, f64)>,
}

fn random_graph(rng: &mut Rng, n: usize, edges: usize, integer: bool) -> Graph {
    let v = |rng: &mut Rng| {
        let x = rng.unit() * 10.0;
        if integer {
            x.floor()
        } else {
            x
        }
    };
    let t = (0..n)
        .map(|_| {
            (
                if rng.below(3) == 0 { 0.0 } else { v(rng) },
                if rng.below(3) == 0 { 0.0 } else { v(rng) },
            )
        })
        .collect();
    let e = (0..edges)
        .map(|_| {
            let a = rng.below(n);
            let b = (a + 1 + rng.below(n - 1)) % n;
            (a, b, v(rng), if rng.below(2) == 0 { 0.0 } else { v(rng) })
        })
        .collect();
    Graph { n, t, e }
}

fn cut_value(g: &Graph, sink: &[bool]) -> f64 {
    let mut c = 0.0;
    for i in 0..g.n {
        c += if sink[i] { g.t[i].0 } else { g.t[i].1 };
    }
    for &(a, b, cap, rev) in &g.e {
        if !sink[a] && sink[b] {
            c += cap;
        }
        if sink[a] && !sink[b] {
            c += rev;
        }
    }
    c
}

fn brute_min_cut(g: &Graph) -> f64 {
    (0..1u32 << g.n)
        .map(|mask| {
            let sink: Vec<bool> = (0..g.n).map(|i| mask >> i & 1 == 1).collect();
            cut_value(g, &sink)
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn maxflow_equals_brute_force_min_cut() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut checked = 0;
    for round in 0..400 {
        let n = 2 + round % 10;
        let edges = rng.below(3 * n) + 1;
        let g = random_graph(&mut rng, n, edges, round % 2 == 0);
        let mut mf = MaxFlow::new(n);
        for (i, &(s, t)) in g.t.iter().enumerate() {
            mf.add_tweights(i, s, t);
        }
        for &(a, b, c, r) in &g.e {
            mf.add_edge(a, b, c, r);
        }
        let flow = mf.solve();
        let best = brute_min_cut(&g);
        let sink: Vec<bool> = (0..n).map(|i| mf.is_sink_side(i)).collect();
        let ours = cut_value(&g, &sink);
        assert!(
            (flow - best).abs() <= 1e-9 * best.max(1.0),
            "round {round}: flow {flow} vs min cut {best}"
        );
        assert!(
            (ours - best).abs() <= 1e-9 * best.max(1.0),
            "round {round}: cut {ours} vs {best}"
        );
        checked += 1;
    }
    assert_eq!(checked, 400);
}

#[test]
fn maxflow_grid_matches_brute_force() {
    // A 3×4 grid with terminal links on the borders: many augmenting paths and orphans.
    let mut rng = Rng(7);
    let (w, h) = (4, 3);
    let n = w * h;
    let mut g = Graph {
        n,
        t: vec![(0.0, 0.0); n],
        e: Vec::new(),
    };
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            g.t[i] = (
                if x == 0 { 5.0 + rng.unit() } else { rng.unit() },
                if x == w - 1 { 5.0 } else { rng.unit() * 0.5 },
            );
            if x + 1 < w {
                g.e.push((i, i + 1, rng.unit() * 3.0, rng.unit() * 3.0));
            }
            if y + 1 < h {
                g.e.push((i, i + w, rng.unit() * 3.0, rng.unit() * 3.0));
            }
        }
    }
    let mut mf = MaxFlow::new(n);
    for (i, &(s, t)) in g.t.iter().enumerate() {
        mf.add_tweights(i, s, t);
    }
    for &(a, b, c, r) in &g.e {
        mf.add_edge(a, b, c, r);
    }
    let flow = mf.solve();
    let best = brute_min_cut(&g);
    assert!((flow - best).abs() < 1e-9, "flow {flow} vs {best}");
}

fn brute_potts(p: &PottsProblem) -> f64 {
    let n = p.nodes();
    let total = p.labels.pow(n as u32);
    (0..total)
        .map(|mut code| {
            let labels: Vec<u32> = (0..n)
                .map(|_| {
                    let l = code % p.labels;
                    code /= p.labels;
                    l as u32
                })
                .collect();
            p.energy(&labels)
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn potts_two_labels_exact_and_expansion_within_factor_two() {
    let mut rng = Rng(12345);
    let mut worst_ratio: f64 = 1.0;
    for round in 0..200 {
        let labels = 2 + round % 3;
        let n = 3 + rng.below(4);
        let unary: Vec<f64> = (0..n * labels)
            .map(|_| {
                if rng.below(10) == 0 {
                    f64::INFINITY
                } else {
                    rng.unit() * 4.0
                }
            })
            .collect();
        // Keep one allowed label per node.
        let mut unary = unary;
        for p in 0..n {
            unary[p * labels + rng.below(labels)] = rng.unit();
        }
        let edges: Vec<(u32, u32, f64)> = (0..2 * n)
            .map(|_| {
                let a = rng.below(n);
                let b = (a + 1 + rng.below(n - 1)) % n;
                (a as u32, b as u32, rng.unit() * 3.0)
            })
            .collect();
        let problem = PottsProblem {
            labels,
            unary: &unary,
            edges: &edges,
        };
        let best = brute_potts(&problem);
        let got = problem.energy(&minimize_potts(&problem, 20));
        assert!(got.is_finite(), "round {round}: hard constraint violated");
        assert!(
            got >= best - 1e-9,
            "round {round}: {got} below optimum {best}"
        );
        if labels == 2 {
            assert!(
                (got - best).abs() < 1e-9,
                "round {round}: two labels not exact: {got} vs {best}"
            );
        } else {
            assert!(
                got <= 2.0 * best + 1e-9,
                "round {round}: {got} > 2 × {best}"
            );
            worst_ratio = worst_ratio.max(got / best.max(1e-12));
        }
    }
    assert!(worst_ratio <= 2.0, "worst α-expansion ratio {worst_ratio}");
}
