//! Tests of style parsing, validation and per-object resolution.

use super::*;
use crate::{StyleInput, Stylize};

const FIG16: &str = r#"
# Fig. 16: all three effects at once.
[offsets]
smooth = 3

[elongate]
step = 2
function = { stages = [{ op = "warp", s = 0.5, p = 0.8 }, { op = "speed" }, { op = "scale", by = [[0, 1.0], [10, 3.0]] }] }

[multiples]
past = 2
future = 1
overlap = 1
opacity = { stages = [{ op = "threshold", min_speed = 0.01 }, { op = "warp", s = 0.8, p = 0.5 }, { op = "multiples", m_max = 1 }] }

[lines]
count = 12
seed = 3
length = { expr = "tau * step(speed - vmin) * delta", params = { tau = 10, vmin = 0.01 } }

[objects.Sword]
weights = { expr = "clamp01(y / 2)" }
multiples = { enabled = false }
"#;

#[test]
fn fig16_style_parses_and_resolves_per_object() {
    let style = Style::from_toml_str(FIG16).unwrap();
    assert_eq!(style.offsets.smooth, 3);
    let e = style.elongate.as_ref().unwrap();
    assert_eq!(e.step, 2);
    assert_eq!(e.function.stages.len(), 3);
    let m = style.multiples.as_ref().unwrap();
    let opts = m.options().unwrap();
    // Fig. 1: N∩ = 1, m_p = 2, m_n = 1 → Δf = 1/3.
    assert!((opts.spacing_at(7.0).unwrap() - 1.0 / 3.0).abs() < 1e-6);
    let robot = style.for_object("Robot");
    assert!(robot.multiples.is_some() && robot.weights.is_none());
    let sword = style.for_object("Sword");
    assert!(sword.multiples.is_none() && sword.elongate.is_some() && sword.lines.is_some());
    let Some(WeightSource::Function(w)) = sword.compile(1.0).unwrap().weights else {
        panic!("the sword's weights are a function");
    };
    let w = w.compile().unwrap();
    let at = |y: f32| {
        w.eval(&StyleInput {
            rest: glam::Vec3::new(0.0, y, 0.0),
            ..Default::default()
        })
    };
    assert!((at(1.0) - 0.5).abs() < 1e-6 && at(5.0) == 1.0 && at(-1.0) == 0.0);
    // Keyframed β_max at frame 5 = 2: δ = 0 warps to −0.609375, speed 1 → β = −1.21875.
    let fx = robot.compile(2.0).unwrap();
    let (se, eo) = fx.elongate.unwrap();
    assert_eq!(eo.step, 2);
    let x = StyleInput {
        delta: 0.0,
        speed: 1.0,
        frame: 5.0,
        ..Default::default()
    };
    assert!((se.eval(&x) + 1.218_75).abs() < 1e-5, "{}", se.eval(&x));
    // Line thickness defaults to DEFAULT_LINE_THICKNESS × diagonal.
    let lines = fx.lines.unwrap();
    assert!((lines.thickness.eval(&x) - 2.0 * DEFAULT_LINE_THICKNESS).abs() < 1e-7);
    assert_eq!((lines.count, lines.seed), (12, 3));
    // Default line opacity 1 − t.
    let t = StyleInput { t: 0.25, ..x };
    assert!((lines.opacity.eval(&t) - 0.75).abs() < 1e-6);
}

#[test]
fn toml_round_trip_keeps_the_style() {
    let style = Style::from_toml_str(FIG16).unwrap();
    let text = style.to_toml_string().unwrap();
    let back = Style::from_toml_str(&text).unwrap();
    assert_eq!(back, style, "{text}");
    let empty = Style::from_toml_str("").unwrap();
    assert_eq!(empty, Style::default());
    assert_eq!(
        Style::from_toml_str(&empty.to_toml_string().unwrap()).unwrap(),
        empty
    );
}

#[test]
fn bad_styles_are_errors_naming_the_problem() {
    let cases = [
        ("[elongate]\nfunction = { expr = \"delta *\" }", "delta *"),
        (
            "[elongate]\nfunction = { expr = \"bogus * delta\" }",
            "bogus",
        ),
        ("[elongate]\nfunktion = 3", "funktion"),
        (
            "[elongate]\nfunction = { stages = [{ op = \"warp\", s = 1.5, p = 0.5 }] }",
            "stages[0].s",
        ),
        (
            "[elongate]\nfunction = { stages = [{ op = \"twirl\" }] }",
            "twirl",
        ),
        ("[multiples]\nspacing = 0.5\noverlap = 1", "spacing"),
        ("[multiples]\npast = 1\nfuture = 0\noverlap = 3", "overlap"),
        ("[lines]\nstep = 0", "lines.step"),
        (
            "[objects.Tree.elongate]\nfunction = { stages = [{ op = \"noise\", kappa = 0 }] }",
            "objects.Tree",
        ),
        (
            "[elongate]\nfunction = { stages = [{ op = \"scale\", by = [[3, 1], [1, 2]] }] }",
            "increase",
        ),
        ("[elongate\n", "style"),
    ];
    for (text, needle) in cases {
        let e = Style::from_toml_str(text).expect_err(text).to_string();
        assert!(
            e.contains(needle),
            "{text:?}: '{e}' does not name '{needle}'"
        );
        assert!(!e.contains('\n'), "multi-line error: {e}");
    }
}

#[test]
fn fig15b_weight_sources_and_keyframed_effect_options_parse() {
    // Painted weights from a weight group or a vertex attribute (Fig. 15b), and keyframes on
    // the effects' own options (Section 5.1).
    let style = Style::from_toml_str(
        r#"
weights = { group = ["Head", "ShoulderL"] }
[multiples]
past = [[0, 0], [8, 3]]
spacing = [[0, 0.25], [20, 1.0]]
[lines]
color = [[[0, 0.0], [10, 1.0]], 0.1, 0.1]
count = [[0, 5], [10, 30]]
gap = [[0, 0], [10, 2]]
min_speed = 0.01
[objects.Sword]
weights = { attribute = "_SMEAR_WEIGHT" }
[objects.Cape]
weights = { group = ["Spine"], descendants = false }
"#,
    )
    .unwrap();
    assert_eq!(
        style.weights,
        Some(WeightSource::Group(WeightGroup {
            group: vec!["Head".into(), "ShoulderL".into()],
            descendants: true
        }))
    );
    assert!(matches!(
        style.for_object("Sword").weights,
        Some(WeightSource::Attribute(a)) if a.attribute == "_SMEAR_WEIGHT"
    ));
    assert!(matches!(
        style.for_object("Cape").weights,
        Some(WeightSource::Group(g)) if !g.descendants
    ));
    let m = style.multiples.as_ref().unwrap().options().unwrap();
    assert!((m.spacing_at(10.0).unwrap() - 0.625).abs() < 1e-6);
    let lines = style
        .for_object("Robot")
        .compile(1.0)
        .unwrap()
        .lines
        .unwrap();
    assert_eq!(lines.count, 30, "seeds sampled for the largest keyed count");
    let count = lines.options.count.as_ref().unwrap();
    assert_eq!(count.at(5.0), 17.5);
    assert_eq!(lines.options.gap.at(5.0), 1.0);
    assert_eq!(lines.options.min_speed.at(99.0), 0.01);
    assert_eq!(lines.options.color[0].at(5.0), 0.5);
    assert_eq!(m.indices(), [-3, -2, -1, 1]);
    assert_eq!(m.counts_at(4.0), (2, 1));
    // A constant count draws every sampled seed.
    let constant = Style::from_toml_str("[lines]\ncount = 12").unwrap();
    let l = constant.lines.as_ref().unwrap();
    assert_eq!((l.seed_count(), l.options().count), (12, None));
    let back = Style::from_toml_str(&style.to_toml_string().unwrap()).unwrap();
    assert_eq!(back, style);
    for (text, needle) in [
        ("weights = { group = [] }", "weights.group"),
        ("weights = { attribute = \"_\" }", "weights.attribute"),
        ("weights = { grup = [\"Head\"] }", "weights"),
        ("[lines]\ngap = [[0, 1], [5, -1]]", "lines.gap"),
        ("[lines]\ncount = -3", "lines.count"),
        ("[multiples]\nspacing = [[4, 1], [2, 1]]", "increase"),
        (
            "[multiples]\npast = [[0, 1], [9, 2]]\nfuture = 0\noverlap = [[0, 1], [9, 3]]",
            "frame 9",
        ),
        ("[lines]\ncolor = [1.5, 0, 0]", "lines.color"),
    ] {
        let e = Style::from_toml_str(text).expect_err(text).to_string();
        assert!(
            e.contains(needle),
            "{text:?}: '{e}' does not name '{needle}'"
        );
    }
}

#[test]
fn set_weights_makes_every_preset_chain_read_the_weights_once() {
    let mut style = Style::from_toml_str(FIG16).unwrap();
    style.lines.as_mut().unwrap().length = FunctionSpec::linear(2.0);
    let group = WeightSource::Group(WeightGroup {
        group: vec!["ShoulderR".into()],
        descendants: true,
    });
    style.set_weights(Some(group.clone()));
    assert_eq!(style.weights, Some(group.clone()));
    let stages = &style.elongate.as_ref().unwrap().function.stages;
    assert_eq!(stages.last(), Some(&Stage::Weight), "{stages:?}");
    // In the opacity chain ω goes before S_M (it scales the offset, not the opacity).
    let opacity = &style
        .multiples
        .as_ref()
        .unwrap()
        .opacity
        .as_ref()
        .unwrap()
        .stages;
    assert_eq!(opacity[opacity.len() - 2], Stage::Weight, "{opacity:?}");
    assert!(matches!(opacity.last(), Some(Stage::Multiples { .. })));
    assert!(style
        .lines
        .as_ref()
        .unwrap()
        .length
        .stages
        .contains(&Stage::Weight));
    // Twice adds nothing; an expression is kept as written.
    let once = style.clone();
    style.set_weights(Some(group));
    assert_eq!(style, once);
    let mut expr = Style::from_toml_str("[elongate]\nfunction = { expr = \"2 * delta\" }").unwrap();
    expr.set_weights(Some(WeightSource::Attribute(WeightAttribute {
        attribute: "_SMEAR_WEIGHT".into(),
    })));
    assert_eq!(
        expr.elongate.as_ref().unwrap().function.expr.as_deref(),
        Some("2 * delta")
    );
    // None clears ω (the weight stages then multiply by 1) and the result still validates.
    style.set_weights(None);
    assert_eq!(style.weights, None);
    style.validate().unwrap();
    Style::from_toml_str(&style.to_toml_string().unwrap()).unwrap();
}

#[test]
fn keyframes_survive_the_toml_text_the_studio_shows() {
    // The studio edits keys on the style's data and shows/exports `to_toml_string`.
    let style = Style {
        elongate: Some(ElongateStyle {
            function: FunctionSpec::stages(vec![
                Stage::Speed,
                Stage::Scale {
                    by: Param::Curve(vec![[0.0, 1.0], [40.0, 12.0]]),
                },
            ]),
            ..ElongateStyle::default()
        }),
        multiples: Some(MultiplesStyle {
            past: Param::Curve(vec![[10.0, 0.0], [30.0, 3.0]]),
            ..MultiplesStyle::default()
        }),
        lines: Some(LinesStyle {
            count: Param::Curve(vec![[0.0, 0.0], [20.0, 60.0]]),
            ..LinesStyle::default()
        }),
        ..Style::default()
    };
    style.validate().unwrap();
    let text = style.to_toml_string().unwrap();
    let back = Style::from_toml_str(&text).unwrap();
    assert_eq!(back, style, "{text}");
    let by = match &back.elongate.as_ref().unwrap().function.stages[1] {
        Stage::Scale { by } => by.clone(),
        s => panic!("{s:?}"),
    };
    assert_eq!((by.at(0.0), by.at(20.0), by.at(40.0)), (1.0, 6.5, 12.0));
    assert_eq!(back.lines.as_ref().unwrap().count.at(10.0), 30.0);
}

#[test]
fn units_read_and_survive_the_toml_text() {
    let style = Style::from_toml_str("speed_units = \"scene\"\nsize_reference = \"Body\"").unwrap();
    assert_eq!(style.speed_units, SpeedUnits::Scene);
    assert_eq!(
        style.size_reference,
        Some(SizeReference::Node("Body".into()))
    );
    let text = style.to_toml_string().unwrap();
    assert_eq!(Style::from_toml_str(&text).unwrap(), style, "{text}");
    let size = Style::from_toml_str("size_reference = 1.8").unwrap();
    assert_eq!(size.speed_units, SpeedUnits::Size);
    assert_eq!(size.size_reference, Some(SizeReference::Length(1.8)));
    // The default is not written out.
    assert!(!Style::default()
        .to_toml_string()
        .unwrap()
        .contains("speed_units"));
    for bad in [
        "size_reference = 0",
        "size_reference = -2.0",
        "size_reference = \"\"",
    ] {
        let e = Style::from_toml_str(bad).unwrap_err().to_string();
        assert!(e.contains("size_reference"), "{bad}: {e}");
    }
    assert!(Style::from_toml_str("speed_units = \"metres\"").is_err());
}
