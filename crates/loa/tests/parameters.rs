//! Issue 20 acceptance, the line: parameters that do what an animator expects (timing stays
//! the animator's, stiffness = speed toward the next pose + wobble frequency, damping =
//! overshoot, never strobing), settles and moving holds — measured on `examples/loa/`.

mod common;

use common::{example, max_jump, with_params};
use glam::DVec2;
use loa::{Animation, Keystrokes, LineOptions, PhysicsOptions, Settle};

/// Documented ranges (crate docs, "Parameters").
const STIFFNESS_RANGE: [f64; 2] = [*loa::STIFFNESS_RANGE.start(), *loa::STIFFNESS_RANGE.end()];
const DAMPING_RANGE: [f64; 2] = [*loa::DAMPING_RANGE.start(), *loa::DAMPING_RANGE.end()];

fn physics_line(keys: &Keystrokes, settle: u32) -> loa::Line {
    let options = LineOptions {
        physics: PhysicsOptions {
            settle: Settle::Frames(settle),
            fps: keys.fps().unwrap_or(24.0),
            ..Default::default()
        },
        ..Default::default()
    };
    loa::line(keys, &options).unwrap()
}

fn points(a: &Animation, frame: i64) -> Vec<DVec2> {
    a.chain_at(frame).unwrap().joints()
}

/// Progress of the line from keystroke `k0` toward `k1` at `frame`, projected on the
/// key-to-key displacement of every chain point: −1 on `k0`, 0 on `k1`, > 0 past `k1`.
fn progress(a: &Animation, k0: i64, k1: i64, frame: i64) -> f64 {
    let (p0, p1, p) = (points(a, k0), points(a, k1), points(a, frame));
    let (mut num, mut den) = (0.0, 0.0);
    for ((a0, a1), x) in p0.iter().zip(&p1).zip(&p) {
        let d = *a1 - *a0;
        num += (*x - *a1).dot(d);
        den += d.length_squared();
    }
    num / den
}

/// Largest overshoot of the line's shape past the next keystroke over every interval: the
/// chain's angles projected on the key-to-key change, minus 1. (The root follows its
/// Hermite curve in real time, LoA §3.2, so the points' projection mixes in the root's
/// travel, which never overshoots; the swing is the shape's.)
fn overshoot(a: &Animation) -> f64 {
    let k = &a.keystroke_frames;
    let angles = |f: i64| a.chain_at(f).unwrap().angles().to_vec();
    k.windows(2)
        .flat_map(|w| (w[0] + 1..w[1]).map(move |f| (w[0], w[1], f)))
        .map(|(k0, k1, f)| {
            let (g0, g1, g) = (angles(k0), angles(k1), angles(f));
            let (mut num, mut den) = (0.0, 0.0);
            for ((x0, x1), x) in g0.iter().zip(&g1).zip(&g) {
                num += (x - x0) * (x1 - x0);
                den += (x1 - x0) * (x1 - x0);
            }
            num / den - 1.0
        })
        .fold(0.0, f64::max)
}

/// Fractional frames after the first keystroke until the line has covered 90 % of the way
/// to the second.
fn arrival(a: &Animation) -> f64 {
    let (k0, k1) = (a.keystroke_frames[0], a.keystroke_frames[1]);
    let mut prev = -1.0;
    for f in k0 + 1..=k1 {
        let s = progress(a, k0, k1, f);
        if s >= -0.1 {
            return (f - 1 - k0) as f64 + (-0.1 - prev) / (s - prev);
        }
        prev = s;
    }
    (k1 - k0) as f64
}

/// Wobble frequency (Hz) in the settle tail: the peak of the spectrum of the line's mean
/// element direction relative to the last keystroke (0.02 Hz grid up to 4 Hz).
fn settle_frequency(a: &Animation) -> f64 {
    let last = *a.keystroke_frames.last().unwrap();
    let mean = |c: &loa::Chain| c.directions().iter().sum::<f64>() / c.elements() as f64;
    let key = mean(a.chain_at(last).unwrap());
    let e: Vec<f64> = a
        .frames
        .iter()
        .filter(|f| f.frame > last)
        .map(|f| mean(&f.chain) - key)
        .collect();
    let power = |hz: f64| {
        let w = 2.0 * std::f64::consts::PI * hz / a.fps;
        let (c, s) = e.iter().enumerate().fold((0.0, 0.0), |(c, s), (i, v)| {
            (c + v * (w * i as f64).cos(), s + v * (w * i as f64).sin())
        });
        c * c + s * s
    };
    // The lowest spectral peak holding at least 5 % of the strongest (the slowest mode
    // the settle excites; every mode's frequency scales with √k).
    let spectrum: Vec<f64> = (0..=201).map(|i| power(0.02 * i as f64)).collect();
    let strongest = spectrum.iter().cloned().fold(0.0, f64::max);
    (1..=200)
        .find(|&i| {
            spectrum[i] >= 0.05 * strongest
                && spectrum[i] >= spectrum[i - 1]
                && spectrum[i] >= spectrum[i + 1]
        })
        .map_or(0.0, |i| 0.02 * i as f64)
}

fn strictly_increasing(v: &[f64]) -> bool {
    v.windows(2).all(|w| w[1] > w[0])
}

#[test]
fn keystrokes_stay_at_their_frames_for_every_setting() {
    let whip = example("whip.json");
    for k in [5.0, 60.0, 100.0] {
        for z in [0.05, 0.35, 0.5] {
            let line = physics_line(&with_params(&whip, Some(k), Some(z)), 0);
            for key in &line.keys {
                let c = line.animation.chain_at(key.frame).unwrap();
                for (a, b) in c.joints().iter().zip(key.chain.joints()) {
                    assert!((*a - b).length() < 1e-6, "k={k} ζ={z} frame {}", key.frame);
                }
            }
        }
    }
}

#[test]
fn damping_sets_the_overshoot_monotonically() {
    let whip = example("whip.json");
    let values: Vec<f64> = [0.05, 0.1, 0.25, 0.5]
        .iter()
        .map(|&z| overshoot(&physics_line(&with_params(&whip, Some(100.0), Some(z)), 0).animation))
        .collect();
    println!(
        "whip overshoot (fraction of the key-to-key change) at ζ = 0.05, 0.1, 0.25, 0.5: {values:.3?}"
    );
    assert!(values.windows(2).all(|w| w[1] < w[0]), "{values:?}");
    assert!(values[0] > 0.0, "low damping overshoots: {values:?}");
}

#[test]
fn stiffness_sets_arrival_and_wobble_frequency_monotonically() {
    let whip = example("whip.json");
    let ks = [20.0, 25.0, 35.0, 50.0];
    let mut arrivals = Vec::new();
    let mut frequencies = Vec::new();
    for k in ks {
        let line = physics_line(&with_params(&whip, Some(k), Some(0.15)), 240);
        arrivals.push(arrival(&line.animation));
        frequencies.push(settle_frequency(&line.animation));
    }
    println!(
        "whip k = {ks:?}: arrival (frames) {arrivals:.2?}, settle frequency (Hz) {frequencies:.3?}"
    );
    let earlier: Vec<f64> = arrivals.iter().map(|a| -a).collect();
    assert!(strictly_increasing(&earlier), "{arrivals:?}");
    assert!(strictly_increasing(&frequencies), "{frequencies:?}");
}

#[test]
fn no_setting_in_the_documented_ranges_strobes() {
    let mut worst: (f64, &str, f64, f64) = (0.0, "", 0.0, 0.0);
    for name in ["whip.json", "jump.json"] {
        let keys = example(name);
        for i in 0..=6 {
            let k =
                STIFFNESS_RANGE[0] * (STIFFNESS_RANGE[1] / STIFFNESS_RANGE[0]).powf(i as f64 / 6.0);
            for z in [DAMPING_RANGE[0], 0.15, 0.25, 0.35, DAMPING_RANGE[1]] {
                let line = physics_line(&with_params(&keys, Some(k), Some(z)), 24);
                let j = max_jump(&line.animation);
                println!("{name} k={k:.0} ζ={z}: max jump {:.1} %", 100.0 * j);
                if j > worst.0 {
                    worst = (j, name, k, z);
                }
            }
        }
    }
    println!(
        "largest per-frame motion: {:.1} % of the line length ({} k={:.0} ζ={})",
        100.0 * worst.0,
        worst.1,
        worst.2,
        worst.3
    );
    assert!(worst.0 <= 0.15, "{worst:?}");
}

#[test]
fn a_repeated_keystroke_is_a_moving_hold_and_settle_ends_at_rest() {
    // jump.json's first two strokes; the second repeated at frame 34 (a hold from 10 to 34).
    let jump = example("jump.json");
    let k = jump.keys();
    let mut hold = k[1].clone();
    hold.frame = 34;
    let keys = Keystrokes::new(vec![k[0].clone(), k[1].clone(), hold], jump.fps()).unwrap();
    let line = physics_line(&keys, 24);
    let a = &line.animation;
    let key = points(a, 10);
    let length = a.chain_at(10).unwrap().total_length();
    let deviation = |f: i64| {
        points(a, f)
            .iter()
            .zip(&key)
            .map(|(p, q)| (*p - *q).length())
            .fold(0.0, f64::max)
            / length
    };
    let swing = (11..34).map(deviation).fold(0.0, f64::max);
    let before_end = deviation(33);
    println!(
        "hold 10..34: overshoot {:.1} % of the line length, deviation at frame 33 {:.3} %",
        100.0 * swing,
        100.0 * before_end
    );
    assert!(swing > 0.0);
    assert!(before_end < 0.01);
    // --settle 24: 24 more frames that end on the last keystroke, at rest.
    assert_eq!(a.frames.len(), 35 + 24);
    let last = a.frames.len() - 1;
    let step = |i: usize| {
        let (p, q) = (a.frames[i - 1].chain.joints(), a.frames[i].chain.joints());
        p.iter()
            .zip(&q)
            .map(|(x, y)| (*x - *y).length())
            .fold(0.0, f64::max)
            / length
    };
    let end = a.frames[last].chain.joints();
    assert!(end.iter().zip(&key).all(|(p, q)| (*p - *q).length() < 1e-9));
    println!("settle: last step {:.2e} of the line length", step(last));
    assert!(step(last) < 1e-3);
    let settle_swing = (35..=last)
        .map(|i| deviation(a.frames[i].frame))
        .fold(0.0, f64::max);
    println!(
        "settle: swing {:.2} % of the line length",
        100.0 * settle_swing
    );
}

#[test]
fn a_reversed_stroke_is_oriented_with_a_warning() {
    let jump = example("jump.json");
    let mut ks = jump.keys().to_vec();
    ks[2].stroke = ks[2].stroke.reversed();
    let flipped = Keystrokes::new(ks, jump.fps()).unwrap();
    let a = physics_line(&jump, 0);
    let b = physics_line(&flipped, 0);
    assert_eq!(b.reversed, vec![22]);
    assert_eq!(b.warnings.len(), 1);
    println!("{}", b.warnings[0]);
    assert!(b.warnings[0].contains("frame 22"), "{:?}", b.warnings);
    // The warning states the rule with the distances it compared.
    assert!(
        b.warnings[0].contains("crossed against"),
        "{:?}",
        b.warnings
    );
    assert!(b.warnings[0].contains("more than 90°"), "{:?}", b.warnings);
    assert!(a.warnings.is_empty());
    // The same motion as the correctly drawn strokes.
    for (x, y) in a.animation.frames.iter().zip(&b.animation.frames) {
        for (p, q) in x.chain.joints().iter().zip(y.chain.joints()) {
            assert!((*p - q).length() < 1e-6);
        }
    }
}

#[test]
fn wobble_option_hits_the_line() {
    let whip = example("whip.json");
    let plain = physics_line(&whip, 0);
    let options = LineOptions {
        wobbles: vec!["20:1:0,-800".parse().unwrap()],
        ..Default::default()
    };
    let wobbled = loa::line(&whip, &options).unwrap();
    let d = (21..=40)
        .map(|f| {
            let (p, q) = (points(&plain.animation, f), points(&wobbled.animation, f));
            p.iter()
                .zip(&q)
                .map(|(a, b)| (*a - *b).length())
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max);
    assert!(d > 5.0, "{d}");
    assert!("20:1.5:0,1".parse::<loa::Wobble>().is_err());
}

#[test]
fn values_outside_the_documented_ranges_are_rejected_naming_the_range() {
    let stroke = r#""points": [[0, 0], [50, -30], [100, 0]]"#;
    for (field, value, range) in [
        ("stiffness", "540", "[5, 100]"),
        ("stiffness", "4.9", "[5, 100]"),
        ("damping", "0.6", "[0.05, 0.5]"),
        ("damping", "0", "[0.05, 0.5]"),
    ] {
        let text = format!(
            r#"{{"keystrokes": [{{"frame": 0, {stroke}}}, {{"frame": 12, {stroke}, "{field}": {value}}}]}}"#
        );
        let e = Keystrokes::from_json_str(&text).unwrap_err();
        let message = e.to_string();
        println!("{message}");
        assert!(matches!(
            e,
            loa::LoaError::OutOfRange {
                keystroke: 1,
                frame: 12,
                ..
            }
        ));
        assert!(
            message.contains(field) && message.contains(range),
            "{message}"
        );
    }
    // The ends of the ranges are accepted.
    let text = format!(
        r#"{{"stiffness": 100, "damping": 0.05, "keystrokes": [{{"frame": 0, {stroke}}}, {{"frame": 12, {stroke}, "stiffness": 5, "damping": 0.5}}]}}"#
    );
    assert!(Keystrokes::from_json_str(&text).is_ok());
}

#[test]
fn a_stroke_continuing_the_previous_direction_is_never_reversed() {
    let key = |frame, points: &[[f64; 2]]| {
        let stroke = loa::Stroke::new(points.iter().map(|p| DVec2::new(p[0], p[1]))).unwrap();
        loa::Keystroke::new(frame, stroke)
    };
    // The second stroke starts next to the first one's end and heads on (84° from its
    // direction): its ends pair better crossed (10 + 1020 against 90 + 1005 as drawn), but it
    // continues the previous direction, so it is kept as drawn.
    let first = key(0, &[[0.0, 0.0], [50.0, 0.0], [100.0, 0.0]]);
    let second = key(12, &[[90.0, 0.0], [145.0, 500.0], [200.0, 1000.0]]);
    let line = physics_line(&Keystrokes::new(vec![first, second], None).unwrap(), 0);
    assert!(line.reversed.is_empty(), "{:?}", line.warnings);
    assert!(line.warnings.is_empty(), "{:?}", line.warnings);
}
