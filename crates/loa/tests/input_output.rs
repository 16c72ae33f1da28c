//! Keystroke input (JSON, SVG), output layouts, and robustness on bad or extreme input.

use loa::*;

const JUMP: &str = include_str!("../../../examples/loa/jump.json");
const WHIP: &str = include_str!("../../../examples/loa/whip.json");
const WHIP_SVG: &str = include_str!("../../../examples/loa/whip.svg");

fn max_joint_distance(a: &Chain, b: &Chain) -> f64 {
    a.joints()
        .iter()
        .zip(b.joints())
        .map(|(p, q)| (*p - q).length())
        .fold(0.0, f64::max)
}

#[test]
fn keystroke_input_errors_are_clear() {
    let err = |s: &str| Keystrokes::from_json_str(s).unwrap_err();
    let out_of_order = err(
        r#"{"keystrokes": [{"frame": 5, "points": [[0,0],[1,0]]}, {"frame": 2, "points": [[0,0],[1,1]]}]}"#,
    );
    assert!(matches!(
        out_of_order,
        LoaError::FrameOrder {
            keystroke: 1,
            frame: 2,
            previous: 5
        }
    ));
    assert!(out_of_order.to_string().contains("increasing frame order"));
    let point = err(r#"{"keystrokes": [{"frame": 0, "points": [[3,3],[3,3],[3,3]]}]}"#);
    assert!(matches!(
        point,
        LoaError::Stroke {
            source: StrokeError::Collapsed { .. },
            ..
        }
    ));
    let single = err(r#"{"keystrokes": [{"frame": 0, "points": [[3,3]]}]}"#);
    assert!(matches!(
        single,
        LoaError::Stroke {
            source: StrokeError::TooFewPoints { points: 1 },
            ..
        }
    ));
    let short = err(
        r#"{"keystrokes": [{"frame": 0, "points": [[0,0],[100,0]]}, {"frame": 9, "points": [[0,0],[0.5,0]]}]}"#,
    );
    assert!(matches!(short, LoaError::TooShort { keystroke: 1, .. }));
    assert!(matches!(
        err(r#"{"keystrokes": []}"#),
        LoaError::NoKeystrokes
    ));
    assert!(matches!(
        err(r#"{"keystrokes": [{"frame": 1.5, "points": [[0,0],[1,0]]}]}"#),
        LoaError::InvalidParameter { name: "frame", .. }
    ));
    assert!(matches!(
        err(r#"{"keystrokes": [{"frame": 0, "points": [[0,0],[1,0]], "damping": -1}]}"#),
        LoaError::OutOfRange {
            name: "damping",
            ..
        }
    ));
    assert!(matches!(err("{not json"), LoaError::Json(_)));
    let svg = Keystrokes::from_svg_str(r#"<svg><path d="M0 0 L10 0"/></svg>"#).unwrap_err();
    assert!(svg.to_string().contains("data-frame"), "{svg}");
    let svg_order = Keystrokes::from_svg_str(
        r#"<svg><polyline points="0,0 10,0" data-frame="3"/><polyline points="0,0 10,5" data-frame="1"/></svg>"#,
    )
    .unwrap_err();
    assert!(matches!(svg_order, LoaError::FrameOrder { .. }));
    assert!(matches!(
        Keystrokes::from_svg_str("<svg>").unwrap_err(),
        LoaError::Xml(_)
    ));
    // Odd element counts cannot put the root at a joint.
    let keys = Keystrokes::from_json_str(WHIP).unwrap();
    let odd = LineOptions {
        elements: 7,
        ..Default::default()
    };
    assert!(matches!(
        loa::line(&keys, &odd),
        Err(LoaError::InvalidParameter {
            name: "elements",
            ..
        })
    ));
    let bad_fps = LineOptions {
        physics: PhysicsOptions {
            fps: f64::NAN,
            ..Default::default()
        },
        ..Default::default()
    };
    assert!(loa::line(&keys, &bad_fps).is_err());
}

#[test]
fn svg_whip_matches_json_whip() {
    let json = Keystrokes::from_json_str(WHIP).unwrap();
    let svg = Keystrokes::from_svg_str(WHIP_SVG).unwrap();
    assert_eq!(svg.frames(), json.frames());
    assert_eq!(svg.fps(), Some(24.0));
    for (a, b) in svg.keys().iter().zip(json.keys()) {
        assert_eq!(a.stroke.points()[0], b.stroke.points()[0]);
        assert!(
            (*a.stroke.points().last().unwrap() - *b.stroke.points().last().unwrap()).length()
                < 1e-9
        );
        assert_eq!((a.stiffness, a.damping), (b.stiffness, b.damping));
    }
}

#[test]
fn json_output_follows_the_spec_layout_and_is_deterministic() {
    let keys = Keystrokes::from_json_str(JUMP).unwrap();
    let line = loa::line(&keys, &LineOptions::default()).unwrap();
    let text = line.animation.to_json_string();
    let again = loa::line(&keys, &LineOptions::default())
        .unwrap()
        .animation
        .to_json_string();
    assert_eq!(text, again);
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["fps"], 24.0);
    assert_eq!(
        v["keystroke_frames"],
        serde_json::json!([0, 10, 22, 34, 46])
    );
    let frames = v["frames"].as_array().unwrap();
    // Keystrokes 0..=46 plus the default settle: one key interval (46 - 34 = 12 frames).
    assert_eq!(frames.len(), 47 + 12);
    for (i, f) in frames.iter().enumerate() {
        assert_eq!(f["frame"], i as i64);
        assert_eq!(f["points"].as_array().unwrap().len(), DEFAULT_ELEMENTS + 1);
        assert_eq!(f["points"][0].as_array().unwrap().len(), 2);
        assert_eq!(f["angles"].as_array().unwrap().len(), DEFAULT_ELEMENTS);
        assert_eq!(f["lengths"].as_array().unwrap().len(), DEFAULT_ELEMENTS);
    }
    let svg = to_svg_string(&line.animation, Some(&keys));
    assert_eq!(
        svg.matches("stroke=\"#d62728\"").count(),
        5,
        "keystrokes in red"
    );
    assert_eq!(
        svg.matches("stroke=\"#2a5bd7\"").count(),
        47 + 12 - 5,
        "in-betweens in blue"
    );
    assert!(roxmltree::Document::parse(&svg).is_ok());
}

#[test]
fn extreme_parameters_give_errors_or_defined_results() {
    let whip = Keystrokes::from_json_str(WHIP).unwrap();
    let poses = fit_keystrokes(&whip, DEFAULT_ELEMENTS).unwrap();
    for (stiffness, damping) in [(0.0, 0.0), (1e300, 0.5), (1e-300, 1e300), (60.0, 1e9)] {
        let keys: Vec<KeyPose> = poses
            .iter()
            .cloned()
            .map(|mut k| {
                k.stiffness = stiffness;
                k.damping = damping;
                k
            })
            .collect();
        // Either an error or a line that still lands on every key with finite values.
        if let Ok(p) = interpolate_physics(&keys, &PhysicsOptions::default()) {
            for f in &p.animation.frames {
                assert!(f.chain.joints().iter().all(|q| q.is_finite()));
            }
            for k in &keys {
                let c = p.animation.chain_at(k.frame).unwrap();
                assert!(max_joint_distance(c, &k.chain) < 1e-6);
            }
        }
    }
    let huge_span = r#"{"keystrokes": [{"frame": 0, "points": [[0,0],[1,0]]}, {"frame": 100000000, "points": [[0,0],[1,1]]}]}"#;
    assert!(Keystrokes::from_json_str(huge_span).is_err());
    let options = PhysicsOptions {
        substeps: u32::MAX,
        ..Default::default()
    };
    assert!(interpolate_physics(&poses, &options).is_err());
    let options = PhysicsOptions {
        substeps: 0,
        ..Default::default()
    };
    assert!(interpolate_physics(&poses, &options).is_err());
    // A single keystroke is a one-frame animation in both modes.
    let one = Keystrokes::from_json_str(
        r#"{"keystrokes": [{"frame": 7, "points": [[0,0],[5,5],[10,0]]}]}"#,
    )
    .unwrap();
    for mode in [Mode::Physics, Mode::Hermite] {
        let line = loa::line(
            &one,
            &LineOptions {
                mode,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(line.animation.frames.len(), 1);
        assert_eq!(line.animation.frames[0].frame, 7);
    }
}
