//! Acceptance tests for Section 3 of Guay et al. 2015, named after its figures and scenarios.

use glam::DVec2;
use loa::*;

const JUMP: &str = include_str!("../../../examples/loa/jump.json");
const WHIP: &str = include_str!("../../../examples/loa/whip.json");
const WHIP_SVG: &str = include_str!("../../../examples/loa/whip.svg");

fn examples() -> Vec<(&'static str, Keystrokes)> {
    vec![
        ("jump", Keystrokes::from_json_str(JUMP).unwrap()),
        ("whip", Keystrokes::from_json_str(WHIP).unwrap()),
        ("whip.svg", Keystrokes::from_svg_str(WHIP_SVG).unwrap()),
    ]
}

fn max_joint_distance(a: &Chain, b: &Chain) -> f64 {
    a.joints()
        .iter()
        .zip(b.joints())
        .map(|(p, q)| (*p - q).length())
        .fold(0.0, f64::max)
}

fn with_damping(keys: &[KeyPose], damping: f64) -> Vec<KeyPose> {
    keys.iter()
        .cloned()
        .map(|mut k| {
            k.damping = damping;
            k
        })
        .collect()
}

#[test]
fn fig3_physics_line_lands_on_every_keystroke() {
    for (name, keys) in examples() {
        for frames in [SimulatedFrames::Fixed(40), SimulatedFrames::FrameGap] {
            let options = LineOptions {
                physics: PhysicsOptions {
                    simulated_frames: frames,
                    ..Default::default()
                },
                ..Default::default()
            };
            let line = loa::line(&keys, &options).unwrap();
            let a = &line.animation;
            assert_eq!(a.keystroke_frames, keys.frames());
            // Keystroke span plus the default settle (one key interval).
            let [.., before, last] = keys.frames()[..] else {
                panic!("{name}: fewer than two keystrokes")
            };
            let span = last - keys.frames()[0] + 1 + (last - before);
            assert_eq!(
                a.frames.len() as i64,
                span,
                "{name}: one frame per integer frame"
            );
            for key in &line.keys {
                let chain = a.chain_at(key.frame).unwrap();
                let d = max_joint_distance(chain, &key.chain);
                assert!(
                    d < 1e-6,
                    "{name} {frames:?}: frame {} off by {d}",
                    key.frame
                );
                for (x, y) in chain.angles().iter().zip(key.chain.angles()) {
                    assert!((x - y).abs() < 1e-9);
                }
            }
            // And the line actually moves between keys (it is not a hold).
            let mid = a.frames[a.frames.len() / 2 + 1].chain.clone();
            assert!(line
                .keys
                .iter()
                .all(|k| max_joint_distance(&mid, &k.chain) > 1.0));
        }
    }
}

#[test]
fn hermite_reproduces_keystrokes_and_is_c1_in_angles() {
    let keys = Keystrokes::from_json_str(JUMP).unwrap();
    let poses = fit_keystrokes(&keys, DEFAULT_ELEMENTS).unwrap();
    let animation = interpolate_hermite(&poses, 24.0);
    let line = HermiteLine::new(&poses);
    let mut worst_jump: f64 = 0.0;
    for key in &poses {
        assert!(max_joint_distance(animation.chain_at(key.frame).unwrap(), &key.chain) < 1e-6);
        assert!(max_joint_distance(&line.chain_at(key.frame as f64), &key.chain) < 1e-6);
        // C1: one-sided difference quotients agree at every interior key.
        if key.frame == poses[0].frame || key.frame == poses.last().unwrap().frame {
            continue;
        }
        let (t, eps) = (key.frame as f64, 1e-5);
        let (l, c, r) = (
            line.angles_at(t - eps),
            line.angles_at(t),
            line.angles_at(t + eps),
        );
        for j in 0..DEFAULT_ELEMENTS {
            let left = (c[j] - l[j]) / eps;
            let right = (r[j] - c[j]) / eps;
            worst_jump = worst_jump.max((left - right).abs());
        }
    }
    assert!(
        worst_jump < 1e-4,
        "angle velocity jumps by {worst_jump} rad/frame at a key"
    );
    // The geometric interpolation is smooth between keys too: no frame-to-frame angle jump
    // larger than the largest key-to-key change per frame times 2.
    let max_step = animation
        .frames
        .windows(2)
        .flat_map(|w| {
            w[0].chain
                .angles()
                .iter()
                .zip(w[1].chain.angles())
                .map(|(a, b)| (a - b).abs())
                .collect::<Vec<_>>()
        })
        .fold(0.0, f64::max);
    assert!(max_step < 0.2, "max per-frame angle change {max_step}");
}

/// Progress toward the target in the energy metric: `⟨e(t), e(0)⟩_M / ⟨e(0), e(0)⟩_M`.
/// 1 at the start, 0 on target, negative once the line has swung past the target.
fn progress_curve(from: &KeyPose, target: &[f64], damping: f64, frames: u32) -> Vec<f64> {
    let mut from = from.clone();
    from.damping = damping;
    let n = from.chain.elements();
    let sim = simulate(
        &from,
        target,
        &vec![0.0; n],
        frames,
        &PhysicsOptions::default(),
    )
    .unwrap();
    let mass = ElasticChain::new(&from.chain, 1.0, 0.0)
        .unwrap()
        .mass_matrix()
        .to_vec();
    let e0: Vec<f64> = from
        .chain
        .angles()
        .iter()
        .zip(target)
        .map(|(a, b)| a - b)
        .collect();
    let inner = |x: &[f64], y: &[f64]| -> f64 {
        (0..n)
            .map(|i| (0..n).map(|j| x[i] * mass[i * n + j] * y[j]).sum::<f64>())
            .sum()
    };
    let norm = inner(&e0, &e0);
    (0..sim.states())
        .map(|s| sim.state(s))
        .map(|a| {
            let e: Vec<f64> = a.iter().zip(target).map(|(x, t)| x - t).collect();
            inner(&e, &e0) / norm
        })
        .collect()
}

#[test]
fn critical_damping_has_no_overshoot_while_low_damping_overshoots() {
    let keys = Keystrokes::from_json_str(WHIP).unwrap();
    let poses = fit_keystrokes(&keys, DEFAULT_ELEMENTS).unwrap();
    for pair in poses.windows(2) {
        let target = pair[1].chain.angles();
        let critical = progress_curve(&pair[0], target, 1.0, 120);
        let low = progress_curve(&pair[0], target, 0.1, 120);
        let min_critical = critical.iter().cloned().fold(f64::INFINITY, f64::min);
        let min_low = low.iter().cloned().fold(f64::INFINITY, f64::min);
        println!("overshoot (M-metric): critical {min_critical:.2e}, zeta 0.1 {min_low:.3}");
        assert!(
            min_critical > -1e-9,
            "critical damping overshoots: {min_critical}"
        );
        assert!(
            *critical.last().unwrap() < 0.05,
            "critical damping settles: {:?}",
            critical.last()
        );
        assert!(min_low < -0.3, "low damping must overshoot, got {min_low}");
        // Overdamping is slower than critical damping.
        let over = progress_curve(&pair[0], target, 3.0, 120);
        assert!(over[40 * DEFAULT_SUBSTEPS as usize] > critical[40 * DEFAULT_SUBSTEPS as usize]);
    }
}

#[test]
fn undamped_free_chain_conserves_energy_over_1000_steps() {
    let keys = Keystrokes::from_json_str(JUMP).unwrap();
    let poses = fit_keystrokes(&keys, DEFAULT_ELEMENTS).unwrap();
    let pose = &poses[2].chain;
    for (stiffness, h) in [(0.0, 1.0 / 24.0), (60.0, 1.0 / 192.0), (400.0, 1.0 / 24.0)] {
        let mut chain = ElasticChain::new(pose, stiffness, 0.0).unwrap();
        let target: Vec<f64> = pose.angles().iter().map(|a| a + 0.3).collect();
        chain.set_target(&target);
        chain.apply_impulse(pose, 1.0, DVec2::new(0.0, 400.0));
        chain.apply_impulse(pose, 0.2, DVec2::new(150.0, 0.0));
        let e0 = chain.energy();
        assert!(e0 > 0.0);
        let mut worst: f64 = 0.0;
        for _ in 0..1000 {
            chain.step(h);
            worst = worst.max((chain.energy() - e0).abs() / e0);
        }
        println!("k={stiffness} h={h:.4}: max relative energy drift {worst:.2e}");
        assert!(worst < 0.01, "k={stiffness}: energy drift {worst}");
        assert!(
            worst < 1e-9,
            "implicit midpoint conserves quadratic energy: {worst}"
        );
        // It really moved.
        let moved = chain
            .angles()
            .iter()
            .zip(pose.angles())
            .any(|(a, b)| (a - b).abs() > 0.1);
        assert!(moved);
    }
}

#[test]
fn fig3_underdamped_line_shows_follow_through_and_anticipation() {
    let keys = Keystrokes::from_json_str(WHIP).unwrap();
    let poses = with_damping(&fit_keystrokes(&keys, DEFAULT_ELEMENTS).unwrap(), 0.15);
    let physics = interpolate_physics(&poses, &PhysicsOptions::default()).unwrap();
    let a = &physics.animation;
    let (mut follow_through, mut anticipation): (f64, f64) = (0.0, 0.0);
    for pair in poses.windows(2) {
        let (k0, k1) = (&pair[0], &pair[1]);
        for j in 0..DEFAULT_ELEMENTS {
            let delta = k1.chain.angles()[j] - k0.chain.angles()[j];
            if delta.abs() < 0.1 {
                continue;
            }
            // Anticipation: the first frames move against the key-to-key change.
            let first = a.chain_at(k0.frame + 2).unwrap().angles()[j] - k0.chain.angles()[j];
            anticipation = anticipation.max(-first / delta);
            // Follow-through: the angle swings past the next key's value before landing.
            for f in k0.frame + 1..k1.frame {
                let v = a.chain_at(f).unwrap().angles()[j] - k0.chain.angles()[j];
                follow_through = follow_through.max(v / delta - 1.0);
            }
        }
    }
    println!("anticipation {anticipation:.3}, follow-through {follow_through:.3}");
    assert!(anticipation > 0.2, "anticipation {anticipation}");
    assert!(follow_through > 0.2, "follow-through {follow_through}");
    // With critical damping the swing past the key is much smaller.
    let stiff =
        interpolate_physics(&with_damping(&poses, 1.0), &PhysicsOptions::default()).unwrap();
    let mut critical_ft: f64 = 0.0;
    for pair in poses.windows(2) {
        for j in 0..DEFAULT_ELEMENTS {
            let delta = pair[1].chain.angles()[j] - pair[0].chain.angles()[j];
            if delta.abs() < 0.1 {
                continue;
            }
            for f in pair[0].frame + 1..pair[1].frame {
                let v =
                    stiff.animation.chain_at(f).unwrap().angles()[j] - pair[0].chain.angles()[j];
                critical_ft = critical_ft.max(v / delta - 1.0);
            }
        }
    }
    println!("follow-through with critical damping {critical_ft:.3}");
    assert!(
        critical_ft < 0.5 * follow_through,
        "{critical_ft} vs {follow_through}"
    );
}

#[test]
fn overlapping_action_propagates_from_root_to_tips() {
    // A straight line whose target is the same line turned by 0.6 rad about its root.
    let start = Chain::straight(DVec2::ZERO, 0.0, 10, 10.0).unwrap();
    let turned = Chain::straight(DVec2::ZERO, 0.6, 10, 10.0).unwrap();
    let fit = fit_chain(
        &Stroke::new([DVec2::new(-50.0, 0.0), DVec2::new(50.0, 0.0)]).unwrap(),
        10,
    )
    .unwrap();
    let from = KeyPose {
        frame: 0,
        chain: start,
        stiffness: 60.0,
        damping: 0.5,
        residual: fit.residual,
    };
    let sim = simulate(
        &from,
        turned.angles(),
        &[0.0; 10],
        40,
        &PhysicsOptions::default(),
    )
    .unwrap();
    let direction = |i: usize, e: usize| {
        let c = Chain::new(DVec2::ZERO, sim.frame(i).to_vec(), vec![10.0; 10]).unwrap();
        c.directions()[e]
    };
    // Time for the root element and for the tip element to cover half the turn.
    let half_time = |e: usize| {
        (0..=40)
            .find(|&i| direction(i, e) >= 0.3)
            .unwrap_or(usize::MAX)
    };
    let (root_t, tip_t) = (half_time(5), half_time(9));
    assert!(tip_t > root_t, "tip {tip_t} should lag root {root_t}");
    // Early on the tip bends backward relative to its parent (drag).
    assert!(sim.frame(2)[9] < -1e-3, "tip bend {}", sim.frame(2)[9]);
}

#[test]
fn eq2_t_star_is_the_closest_simulated_frame() {
    let keys = Keystrokes::from_json_str(WHIP).unwrap();
    let poses = fit_keystrokes(&keys, DEFAULT_ELEMENTS).unwrap();
    let options = PhysicsOptions::default();
    let physics = interpolate_physics(&poses, &options).unwrap();
    assert_eq!(physics.retargets.len(), 2);
    // First interval starts at rest: reproduce the simulation and brute-force LoA Eq. 2.
    let r = &physics.retargets[0];
    let sim = simulate(&poses[0], poses[1].chain.angles(), &[0.0; 10], 40, &options).unwrap();
    let target = poses[1].chain.angles();
    let dist = |i: usize| -> f64 {
        sim.frame(i)
            .iter()
            .zip(target)
            .map(|(a, b)| (a - b).powi(2))
            .sum()
    };
    let best = (1..=40)
        .min_by(|&a, &b| dist(a).total_cmp(&dist(b)))
        .unwrap();
    assert_eq!(r.t_star, best);
    assert!((r.correction - dist(best).sqrt()).abs() < 1e-12);
    assert!(
        r.correction < 0.5,
        "t* lands near the key: {}",
        r.correction
    );
}

#[test]
fn eq1_fit_residual_is_small_for_smooth_strokes() {
    for (name, keys) in examples() {
        for pose in fit_keystrokes(&keys, DEFAULT_ELEMENTS).unwrap() {
            let res = pose.residual;
            assert!(
                res.relative_rms < 2e-3,
                "{name} frame {}: {res:?}",
                pose.frame
            );
            assert!((res.sum_squares / DEFAULT_ELEMENTS as f64).sqrt() - res.rms < 1e-12);
        }
    }
    // The root sits at the arc-length midpoint, with equal element lengths.
    let s = Stroke::new((0..=100).map(|i| DVec2::new(i as f64, (i as f64 * 0.1).sin() * 20.0)))
        .unwrap();
    let fit = fit_chain(&s, 10).unwrap();
    assert!((fit.chain.root() - s.point_at(0.5)).length() < 1e-12);
    assert!(fit
        .chain
        .lengths()
        .iter()
        .all(|l| (l - s.length() / 10.0).abs() < 1e-12));
}

#[test]
fn drag_to_wobble_settles_back_to_the_line() {
    let keys = Keystrokes::from_json_str(WHIP).unwrap();
    let line = loa::line(
        &keys,
        &LineOptions {
            mode: Mode::Hermite,
            ..Default::default()
        },
    )
    .unwrap();
    let hit = Wobble::new(20, 1.0, DVec2::new(0.0, -800.0));
    let wobbled = wobble(&line.animation, &hit, DEFAULT_SUBSTEPS).unwrap();
    // Frames up to the hit are untouched; later ones deviate, then the line settles.
    for f in 0..=20 {
        assert_eq!(wobbled.chain_at(f), line.animation.chain_at(f));
    }
    let deviation = |f: i64| {
        let base = line.animation.chain_at(f.min(40)).unwrap();
        max_joint_distance(wobbled.chain_at(f).unwrap(), base)
    };
    let peak = (21..=40).map(deviation).fold(0.0, f64::max);
    assert!(peak > 5.0, "peak deviation {peak}");
    let last = wobbled.frames.last().unwrap().frame;
    assert!(last > 40, "a settling tail is appended");
    assert!(
        deviation(last) < 0.05 * peak,
        "settled: {} vs peak {peak}",
        deviation(last)
    );
    // The root is kinematic: the impulse does not move it.
    assert_eq!(
        wobbled.chain_at(30).unwrap().root(),
        line.animation.chain_at(30).unwrap().root()
    );
}
