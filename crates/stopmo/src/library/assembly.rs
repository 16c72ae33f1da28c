//! Assembly sheets and a proposed shooting order (Section 3.4; the paper's future work).

use std::collections::HashMap;

use serde::Serialize;

/// Passes of 2-opt improvement over the shooting order.
pub const DEFAULT_TWO_OPT_PASSES: usize = 20;
/// Above this many distinct assemblies the 2-opt pass is skipped (it is quadratic).
pub const DEFAULT_TWO_OPT_LIMIT: usize = 4000;

/// Identifier of piece `k` of a part: `<part>_<NN>`, zero-padded to at least two digits (the
/// file stem of `DIR/pieces/<part>_<NN>.stl`).
pub fn piece_id(part: &str, k: usize, pieces: usize) -> String {
    let width = pieces.saturating_sub(1).max(1).to_string().len().max(2);
    format!("{part}_{k:0width$}")
}

/// Which piece of each part goes on each frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Assembly {
    /// Part names (columns).
    pub parts: Vec<String>,
    /// Library size of each part.
    pub pieces: Vec<usize>,
    /// Per frame, the piece index of every part.
    pub frames: Vec<Vec<u32>>,
}

impl Assembly {
    /// Builds the table from per-part labels (all parts with the same frame count).
    pub fn new(parts: Vec<String>, pieces: Vec<usize>, labels: &[&[u32]]) -> Assembly {
        let n = labels.first().map_or(0, |l| l.len());
        let frames = (0..n)
            .map(|f| labels.iter().map(|l| l[f]).collect())
            .collect();
        Assembly {
            parts,
            pieces,
            frames,
        }
    }

    /// Piece identifiers of frame `f` (see [`piece_id`]).
    pub fn frame_ids(&self, f: usize) -> Vec<String> {
        self.frames[f]
            .iter()
            .enumerate()
            .map(|(p, &k)| piece_id(&self.parts[p], k as usize, self.pieces[p]))
            .collect()
    }
}

/// One shot of the proposed order: an assembly and the frames photographed with it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Shot {
    /// Piece index per part.
    pub pieces: Vec<u32>,
    /// Frames to photograph with this assembly (ascending).
    pub frames: Vec<usize>,
}

/// A proposed shooting order.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShootingOrder {
    /// Shots in order.
    pub shots: Vec<Shot>,
    /// Piece swaps along the proposed order (Hamming distances between consecutive shots).
    pub swaps: usize,
    /// Piece swaps when shooting frames in sequence, for comparison.
    pub sequential_swaps: usize,
}

fn hamming(a: &[u32], b: &[u32]) -> usize {
    a.iter().zip(b).filter(|(x, y)| x != y).count()
}

/// Proposes an order to shoot the frames that minimizes piece swaps.
///
/// Frames with identical piece tuples form one shot. Shots are ordered as an open travelling
/// salesman path under the Hamming distance (number of parts whose piece changes): greedy
/// nearest neighbour from the shot of frame 0 (ties: earliest frame), then 2-opt segment
/// reversals while they lower the total (at most [`DEFAULT_TWO_OPT_PASSES`] passes; skipped
/// above [`DEFAULT_TWO_OPT_LIMIT`] shots).
///
/// # Performance
/// `O(S² · parts)` per pass for `S` distinct assemblies.
pub fn shooting_order(assembly: &Assembly) -> ShootingOrder {
    let mut index: HashMap<&[u32], usize> = HashMap::new();
    let mut shots: Vec<Shot> = Vec::new();
    for (f, tuple) in assembly.frames.iter().enumerate() {
        let i = *index.entry(tuple.as_slice()).or_insert_with(|| {
            shots.push(Shot {
                pieces: tuple.clone(),
                frames: Vec::new(),
            });
            shots.len() - 1
        });
        shots[i].frames.push(f);
    }
    let sequential_swaps = assembly
        .frames
        .windows(2)
        .map(|w| hamming(&w[0], &w[1]))
        .sum::<usize>();
    let s = shots.len();
    let dist = |a: usize, b: usize| hamming(&shots[a].pieces, &shots[b].pieces);
    // Greedy nearest neighbour.
    let mut path = Vec::with_capacity(s);
    let mut used = vec![false; s];
    if s > 0 {
        path.push(0);
        used[0] = true;
    }
    while path.len() < s {
        let cur = *path.last().expect("non-empty");
        let next = (0..s)
            .filter(|&j| !used[j])
            .min_by_key(|&j| (dist(cur, j), j))
            .expect("left");
        used[next] = true;
        path.push(next);
    }
    // 2-opt on the open path (the first shot stays first).
    if s <= DEFAULT_TWO_OPT_LIMIT {
        for _ in 0..DEFAULT_TWO_OPT_PASSES {
            let mut improved = false;
            for i in 0..s.saturating_sub(2) {
                for j in i + 2..s {
                    let before = dist(path[i], path[i + 1])
                        + if j + 1 < s {
                            dist(path[j], path[j + 1])
                        } else {
                            0
                        };
                    let after = dist(path[i], path[j])
                        + if j + 1 < s {
                            dist(path[i + 1], path[j + 1])
                        } else {
                            0
                        };
                    if after < before {
                        path[i + 1..=j].reverse();
                        improved = true;
                    }
                }
            }
            if !improved {
                break;
            }
        }
    }
    let swaps = path.windows(2).map(|w| dist(w[0], w[1])).sum();
    let mut slots: Vec<Option<Shot>> = shots.into_iter().map(Some).collect();
    let shots = path
        .iter()
        .map(|&i| slots[i].take().expect("each shot once"))
        .collect();
    ShootingOrder {
        shots,
        swaps,
        sequential_swaps,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_are_zero_padded() {
        assert_eq!(piece_id("mouth", 3, 20), "mouth_03");
        assert_eq!(piece_id("mouth", 7, 150), "mouth_007");
        assert_eq!(piece_id("brow", 0, 1), "brow_00");
    }

    #[test]
    fn shooting_order_groups_and_saves_swaps() {
        // Two parts alternating between two assemblies every frame: 10 frames, 9 × 2 swaps in
        // sequence; grouped, only one change of both parts.
        let a: Vec<u32> = (0..10).map(|f| f % 2).collect();
        let b: Vec<u32> = (0..10).map(|f| (f + 1) % 2).collect();
        let asm = Assembly::new(vec!["a".into(), "b".into()], vec![2, 2], &[&a, &b]);
        let order = shooting_order(&asm);
        assert_eq!(order.shots.len(), 2);
        assert_eq!(order.sequential_swaps, 18);
        assert_eq!(order.swaps, 2);
        let frames: usize = order.shots.iter().map(|s| s.frames.len()).sum();
        assert_eq!(frames, 10);
    }

    #[test]
    fn two_opt_finds_the_gray_code_path() {
        // Four assemblies of 2 parts; Hamming path 00-01-11-10 costs 3.
        let a = [0u32, 1, 1, 0, 0, 1];
        let b = [0u32, 1, 0, 1, 0, 0];
        let asm = Assembly::new(vec!["a".into(), "b".into()], vec![2, 2], &[&a, &b]);
        let order = shooting_order(&asm);
        assert_eq!(order.shots.len(), 4);
        assert_eq!(order.swaps, 3);
        assert!(order.swaps < order.sequential_swaps);
    }
}
