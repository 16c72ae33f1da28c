//! `preview_scene`, what `toonkit render` calls: a synthetic glTF-like scene (a translating
//! cube and a camera) to PNG and GIF bytes.

mod common;

use anim::{
    sample, Channel, Clip, Interpolation, Mesh, Node, Projection, Property, SampleOptions, Scene,
    SceneCamera, SceneMesh, Transform,
};
use glam::Vec3;
use render::{
    decode_png, preview_scene, ColorMap, OutputFormat, PreviewOptions, RenderError, ViewDirection,
    ViewSpec,
};

/// A cube moving 3 units along +X in 1 s, and a camera 6 units in front of the origin.
fn scene() -> Scene {
    let (p, t) = common::cube(Vec3::ZERO, 0.5);
    let cube = Node {
        name: "cube".into(),
        mesh: Some(0),
        ..Node::default()
    };
    let cam = Node {
        name: "cam".into(),
        camera: Some(0),
        transform: Transform {
            translation: Vec3::new(1.5, 0.0, 6.0),
            ..Transform::IDENTITY
        },
        ..Node::default()
    };
    Scene {
        nodes: vec![cube, cam],
        meshes: vec![SceneMesh {
            mesh: Mesh::new("cube", p, t),
            ..SceneMesh::default()
        }],
        skins: vec![],
        cameras: vec![SceneCamera {
            name: "cam".into(),
            projection: Projection::Perspective {
                yfov: 0.8,
                aspect: None,
                znear: 0.1,
                zfar: None,
            },
        }],
        clips: vec![Clip {
            name: "move".into(),
            channels: vec![Channel {
                node: 0,
                property: Property::Translation,
                interpolation: Interpolation::Linear,
                times: vec![0.0, 1.0],
                values: vec![0.0, 0.0, 0.0, 3.0, 0.0, 0.0],
            }],
        }],
    }
}

fn sampled() -> anim::SampledScene {
    sample(
        &scene(),
        &SampleOptions {
            fps: 6.0,
            ..SampleOptions::default()
        },
    )
    .unwrap()
}

/// Mean x of non-background pixels.
fn centroid_x(img: &render::Image) -> f64 {
    let w = img.width() as usize;
    let (mut s, mut n) = (0.0, 0.0);
    for (i, p) in img.pixels().iter().enumerate() {
        if p[..3] != [255, 255, 255] {
            s += (i % w) as f64;
            n += 1.0;
        }
    }
    s / n
}

#[test]
fn camera_png_follows_the_frame() {
    let s = sampled();
    assert_eq!(s.frame_count, 7);
    let mut o = PreviewOptions {
        width: 80,
        height: 60,
        view: ViewSpec::Camera("cam".into()),
        ..PreviewOptions::default()
    };
    let first = decode_png(&preview_scene(&s, &o).unwrap()).unwrap();
    o.frame = 6;
    let last = decode_png(&preview_scene(&s, &o).unwrap()).unwrap();
    assert_eq!((first.width(), first.height()), (80, 60));
    // The cube moves right by 3 units at distance 6 with a 0.8 rad vertical field of view:
    // 3 / (2 · 6 · tan 0.4) of the image height, in pixels.
    let want = 3.0 / (2.0 * 6.0 * (0.4f64).tan()) * 60.0;
    let moved = centroid_x(&last) - centroid_x(&first);
    assert!((moved - want).abs() < 2.0, "moved {moved}, want {want}");
    // The camera looks at x = 1.5: frames 0 and 6 are symmetric about the centre.
    assert!((centroid_x(&first) + centroid_x(&last) - 80.0).abs() < 2.0);
}

/// Number of non-background pixels.
fn coverage(img: &render::Image) -> usize {
    img.pixels()
        .iter()
        .filter(|p| p[..3] != [255, 255, 255])
        .count()
}

#[test]
fn follow_view_keeps_the_travelling_cube_centred_and_large() {
    // The cube travels 3 units (six of its widths): a whole-motion fit shows it small and
    // moving; a following view keeps it in the centre at the same, larger size.
    let s = sampled();
    let png = |view: ViewSpec, frame: usize| {
        let o = PreviewOptions {
            width: 80,
            height: 80,
            view,
            frame,
            supersample: 1,
            ..PreviewOptions::default()
        };
        decode_png(&preview_scene(&s, &o).unwrap()).unwrap()
    };
    let follow = ViewSpec::Follow(ViewDirection::Front);
    let fitted = ViewSpec::Direction(ViewDirection::Front);
    let (f0, f6) = (png(follow.clone(), 0), png(follow, 6));
    let (w0, w6) = (png(fitted.clone(), 0), png(fitted, 6));
    for img in [&f0, &f6] {
        assert!((centroid_x(img) - 40.0).abs() < 1.5, "{}", centroid_x(img));
    }
    assert!((centroid_x(&w6) - centroid_x(&w0)) > 30.0);
    assert_eq!(coverage(&f0), coverage(&f6));
    assert!(
        coverage(&f0) > 4 * coverage(&w0),
        "{} vs {}",
        coverage(&f0),
        coverage(&w0)
    );
}

#[test]
fn gif_with_onion_and_scalar_field() {
    let s = sampled();
    let n = s.vertex_count();
    let field: Vec<f32> = (0..7 * n)
        .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
        .collect();
    let o = PreviewOptions {
        width: 64,
        height: 32,
        view: ViewSpec::Direction(ViewDirection::Front),
        onion: 2,
        scalar: Some((&field, ColorMap::Diverging)),
        format: OutputFormat::Gif,
        ..PreviewOptions::default()
    };
    let gif = preview_scene(&s, &o).unwrap();
    let mut dec = gif::DecodeOptions::new()
        .read_info(std::io::Cursor::new(&gif))
        .unwrap();
    let mut frames = 0;
    while dec.read_next_frame().unwrap().is_some() {
        frames += 1;
    }
    assert_eq!(frames, 7);
    assert_eq!((dec.width(), dec.height()), (64, 32));
}

#[test]
fn bad_requests_are_errors() {
    let s = sampled();
    let o = PreviewOptions {
        frame: 7,
        ..PreviewOptions::default()
    };
    assert!(matches!(
        preview_scene(&s, &o),
        Err(RenderError::FrameOutOfRange {
            frame: 7,
            frames: 7
        })
    ));
    let o = PreviewOptions {
        view: ViewSpec::Camera("nope".into()),
        ..PreviewOptions::default()
    };
    match preview_scene(&s, &o) {
        Err(RenderError::CameraNotFound { available, .. }) => assert_eq!(available, "cam"),
        other => panic!("{other:?}"),
    }
    let short = [0.0f32; 3];
    let o = PreviewOptions {
        scalar: Some((&short, ColorMap::Diverging)),
        ..PreviewOptions::default()
    };
    assert!(matches!(
        preview_scene(&s, &o),
        Err(RenderError::AttributeLength { .. })
    ));
}
