//! Eye and mouth openings: boundary loops much shorter than the outer boundary are capped
//! (a fan from the loop's centroid) instead of walled, so only the outer boundary (seams,
//! neck, scalp) needs a wall.

use std::collections::HashMap;

use glam::Vec3;

/// Splits the directed boundary edges into loops, removes the loops shorter than
/// `fraction` of the longest one from `boundary` and returns them (vertices in edge order).
pub(super) fn cap_loops(
    front: &[Vec3],
    boundary: &mut Vec<(u32, u32)>,
    fraction: f64,
) -> Vec<Vec<u32>> {
    let next: HashMap<u32, u32> = boundary.iter().copied().collect();
    let mut seen: HashMap<u32, ()> = HashMap::new();
    let mut loops: Vec<(Vec<u32>, f64)> = Vec::new();
    for &(start, _) in boundary.iter() {
        if seen.contains_key(&start) {
            continue;
        }
        let (mut lp, mut len, mut v) = (Vec::new(), 0.0f64, start);
        let mut closed = false;
        while seen.insert(v, ()).is_none() {
            lp.push(v);
            let Some(&w) = next.get(&v) else { break };
            len += f64::from(front[v as usize].distance(front[w as usize]));
            if w == start {
                closed = true;
                break;
            }
            v = w;
        }
        if closed && lp.len() >= 3 {
            loops.push((lp, len));
        }
    }
    let longest = loops.iter().map(|l| l.1).fold(0.0, f64::max);
    let caps: Vec<Vec<u32>> = loops
        .into_iter()
        .filter(|l| l.1 < fraction * longest)
        .map(|l| l.0)
        .collect();
    let capped: std::collections::HashSet<u32> = caps.iter().flatten().copied().collect();
    boundary.retain(|(a, _)| !capped.contains(a));
    caps
}
