//! Blending into and out of contacts (LoA §4.1, E_⊥; a change of the paper's scheme, see the
//! crate docs' SPEC decisions).
//!
//! With contacts, the 3D stage solves twice: once without them (the *free* motion) and once,
//! starting from it, with every contact held on its keyed frames (the *held* motion). The
//! result is the held motion on the frames where a contact holds, the free motion elsewhere,
//! and a blend in rotation space around every run of held frames: at the run's last frame the
//! held pose differs from the free one by a rotation per joint (and a root offset); after it,
//! the free motion plays with that difference added and fading out along a smoothstep (the
//! rotation slerped toward identity), and before the run's first frame the difference fades
//! in. The body keeps the free motion's movement throughout; only the difference decays. A contact the line pulls out of reach thus lets go the way an
//! animator blends out of IK — the limb swings back over several frames — instead of the
//! solver snapping it to the line in one. Each blend lasts the fewest frames, between
//! [`super::DEFAULT_CONTACT_RELEASE`] and [`MAX_CONTACT_RELEASE`], in which no joint turns by
//! more than [`CONTACT_RELEASE_MAX_TURN`] per frame (or by more than the free motion itself
//! turns there).

use glam::DQuat;

use super::solver::Poses;
use super::terms::log;
use super::DEFAULT_CONTACT_RELEASE;
use crate::retarget::Blend;

/// Largest rotation (radians, 8°) of any joint in one frame of a contact's blend.
pub const CONTACT_RELEASE_MAX_TURN: f64 = 8.0 * std::f64::consts::PI / 180.0;
/// Longest blend (frames) before a contact's first key or after its last.
pub const MAX_CONTACT_RELEASE: usize = 24;

/// The held motion on the frames of `windows` (`(first, last)` frame of every contact), the
/// free motion elsewhere, blended around every run of held frames (see the module docs).
pub(crate) fn blend(free: &Poses, held: &Poses, windows: &[(usize, usize)]) -> Poses {
    let frames = free.frames();
    let nj = free.joints;
    let mut is_held = vec![false; frames];
    for &(a, b) in windows {
        for h in is_held.iter_mut().take(b + 1).skip(a) {
            *h = true;
        }
    }
    let mut out = free.clone();
    for f in (0..frames).filter(|&f| is_held[f]) {
        out.rotations[f * nj..(f + 1) * nj].copy_from_slice(held.frame(f));
        out.offsets[f] = held.offsets[f];
    }
    for (a, b) in runs(&is_held) {
        // Release after the run's last frame, engage before its first.
        let release = (b + 1..frames).take_while(|&f| !is_held[f]);
        let engage = (0..a).rev().take_while(|&f| !is_held[f]);
        for (key, span) in [(b, release.collect::<Vec<_>>()), (a, engage.collect())] {
            let span = &span[..span.len().min(MAX_CONTACT_RELEASE + 1)];
            let n = blend_length(&out, free, held, key, span);
            for (i, &f) in span.iter().enumerate().take(n) {
                mix(&mut out, f, free, held, key, weight(i, n));
            }
        }
    }
    out
}

/// Maximal runs `(first, last)` of `true`.
fn runs(flags: &[bool]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = None;
    for (f, &h) in flags.iter().chain([&false]).enumerate() {
        match (h, start) {
            (true, None) => start = Some(f),
            (false, Some(s)) => {
                out.push((s, f - 1));
                start = None;
            }
            _ => {}
        }
    }
    out
}

/// Weight of the held pose at the `i`-th frame (0-based) of a blend of `n` frames.
fn weight(i: usize, n: usize) -> f64 {
    1.0 - Blend::Smoothstep.weight((i + 1) as f64 / (n + 1) as f64)
}

/// Adds the fraction `w` of the difference between frame `key` of `held` and of `free` to
/// frame `f` of `poses`.
fn mix(poses: &mut Poses, f: usize, free: &Poses, held: &Poses, key: usize, w: f64) {
    let nj = poses.joints;
    for ((q, &a), &h) in poses.rotations[f * nj..(f + 1) * nj]
        .iter_mut()
        .zip(free.frame(key))
        .zip(held.frame(key))
    {
        *q = (*q * DQuat::IDENTITY.slerp(a.inverse() * h, w)).normalize();
    }
    poses.offsets[f] += (held.offsets[key] - free.offsets[key]) * w;
}

/// Largest rotation of any joint between two frames' local rotations.
fn step(a: &[DQuat], b: &[DQuat]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| log(q.inverse() * *p).length())
        .fold(0.0, f64::max)
}

/// The fewest frames (see the module docs) of the blend from frame `key` of `held` into the
/// frames `span` of `base` (ordered away from the key).
fn blend_length(base: &Poses, free: &Poses, held: &Poses, key: usize, span: &[usize]) -> usize {
    let nj = base.joints;
    let own = span
        .windows(2)
        .map(|p| step(base.frame(p[0]), base.frame(p[1])))
        .fold(0.0, f64::max);
    let limit = CONTACT_RELEASE_MAX_TURN.max(own);
    let mut best = (f64::INFINITY, MAX_CONTACT_RELEASE);
    let mut trial = base.clone();
    for n in DEFAULT_CONTACT_RELEASE..=MAX_CONTACT_RELEASE {
        let mut prev: Vec<DQuat> = held.frame(key).to_vec();
        let mut worst: f64 = 0.0;
        for (i, &f) in span.iter().enumerate().take(n + 1) {
            trial.rotations[f * nj..(f + 1) * nj].copy_from_slice(base.frame(f));
            if i < n {
                mix(&mut trial, f, free, held, key, weight(i, n));
            }
            worst = worst.max(step(&prev, trial.frame(f)));
            prev.copy_from_slice(trial.frame(f));
        }
        if worst <= limit {
            return n;
        }
        if worst < best.0 {
            best = (worst, n);
        }
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn poses(angles: &[f64]) -> Poses {
        Poses {
            joints: 1,
            rotations: angles.iter().map(|&a| DQuat::from_rotation_z(a)).collect(),
            offsets: vec![DVec3::ZERO; angles.len()],
        }
    }

    #[test]
    fn a_release_turns_at_most_the_limit_per_frame_and_ends_on_the_free_motion() {
        // Held at 0 rad on frames 0..=4; the free motion is at 2 rad (115°) throughout.
        let free = poses(&[2.0; 40]);
        let held = poses(&[0.0; 40]);
        let out = blend(&free, &held, &[(0, 4)]);
        for f in 0..=4 {
            assert!(out.frame(f)[0].angle_between(DQuat::IDENTITY) < 1e-12);
        }
        let mut worst: f64 = 0.0;
        for f in 4..39 {
            worst = worst.max(out.frame(f)[0].angle_between(out.frame(f + 1)[0]));
        }
        assert!(worst <= CONTACT_RELEASE_MAX_TURN + 1e-9, "{worst}");
        assert!(worst > 0.5 * CONTACT_RELEASE_MAX_TURN, "{worst}");
        // 115° at ≤ 8° per frame takes more than the default 6 frames, and it arrives.
        assert!(out.frame(12)[0].angle_between(DQuat::from_rotation_z(2.0)) > 1e-3);
        assert!(out.frame(39)[0].angle_between(DQuat::from_rotation_z(2.0)) < 1e-12);
    }

    #[test]
    fn an_engage_blends_in_before_the_first_key() {
        let free = poses(&[1.0; 30]);
        let held = poses(&[0.0; 30]);
        let out = blend(&free, &held, &[(20, 29)]);
        assert!(out.frame(0)[0].angle_between(DQuat::from_rotation_z(1.0)) < 1e-12);
        let before = out.frame(19)[0].angle_between(DQuat::IDENTITY);
        assert!(
            before > 0.0 && before < CONTACT_RELEASE_MAX_TURN + 1e-9,
            "{before}"
        );
        assert_eq!(
            runs(&[false, true, true, false, true]),
            vec![(1, 2), (4, 4)]
        );
    }
}
