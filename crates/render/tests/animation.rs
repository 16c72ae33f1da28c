//! Point-cache previews: onion skins (smear paper Fig. 3a style), all-frame renders, GIF and
//! contact sheets.

mod common;

use anim::{Mesh, MeshAnimation};
use common::{check_ref, cube};
use glam::Vec3;
use render::{
    animation_bbox, contact_sheet, encode_gif, encode_png, onion_opacity, ColorMap, FrameColors,
    OnionStyle, RenderOptions, Renderer, Shading, SheetOptions, View, ViewDirection,
};

/// A cube translating along +X over `frames` frames, one unit per frame.
fn moving_cube(frames: usize) -> MeshAnimation {
    let (p, t) = cube(Vec3::ZERO, 0.5);
    let mesh = Mesh::new("cube", p.clone(), t);
    let pos: Vec<Vec3> = (0..frames)
        .flat_map(|f| p.iter().map(move |q| *q + Vec3::X * 1.2 * f as f32))
        .collect();
    MeshAnimation::new(mesh, 24.0, pos).unwrap()
}

#[test]
fn onion_opacity_decreases_linearly() {
    assert_eq!(onion_opacity(1, 4, 0.4), 0.4);
    assert!((onion_opacity(4, 4, 0.4) - 0.1).abs() < 1e-6);
    assert_eq!(onion_opacity(5, 4, 0.4), 0.0);
    assert_eq!(onion_opacity(0, 4, 0.4), 0.0);
}

#[test]
fn bouncing_cube_onion_skin() {
    let anim = moving_cube(5);
    let r = Renderer::new(96, 48).unwrap();
    let view = View::fit(animation_bbox(&anim), ViewDirection::Front, r.aspect());
    // Current frame 2 coloured by a per-vertex offset-like field: +1 in front (+X), −1 behind.
    let offsets: Vec<f32> = (0..5)
        .flat_map(|f| {
            anim.frame(f)
                .iter()
                .map(move |q| (q.x - 1.2 * f as f32) * 2.0)
        })
        .collect();
    let colors = ColorMap::Diverging.colors(&offsets);
    let style = OnionStyle::symmetric(2);
    let img = r
        .render_onion(
            &anim,
            2,
            FrameColors::PerFrame(&colors),
            Shading::Unlit,
            &style,
            &view,
        )
        .unwrap();
    // Centres of the cubes along the row y = 24.
    let x_of = |f: usize| {
        view.project(Vec3::new(1.2 * f as f32, 0.0, 0.0), 96, 48)
            .unwrap()
            .x as u32
    };
    // The current cube is opaque: red ahead, blue behind, their linear mix in the middle.
    let mid = img.get(x_of(2), 24).unwrap();
    assert!(mid[0] > 120 && mid[2] > 100 && mid[1] < 100, "{mid:?}");
    let ahead = img.get(x_of(2) + 5, 24).unwrap();
    let behind = img.get(x_of(2) - 5, 24).unwrap();
    assert!(
        ahead[0] > ahead[2] + 60 && behind[2] > behind[0] + 60,
        "{ahead:?} {behind:?}"
    );
    // Ghosts: nearer ones more opaque (darker on white), past cool, future warm.
    let lum = |p: [u8; 4]| p[0] as u32 + p[1] as u32 + p[2] as u32;
    let g = |f| img.get(x_of(f), 24).unwrap();
    assert!(
        lum(g(1)) < lum(g(0)) && lum(g(3)) < lum(g(4)),
        "{:?}",
        (g(0), g(1), g(3), g(4))
    );
    assert!(
        g(1)[2] > g(1)[0] && g(3)[0] > g(3)[2],
        "{:?} {:?}",
        g(1),
        g(3)
    );
    assert!(lum(g(0)) < 765, "farthest ghost still visible");
    check_ref("moving_cube_onion", &img);
}

#[test]
fn animation_gif_and_contact_sheet() {
    let anim = moving_cube(6);
    let r = Renderer::new(48, 32).unwrap();
    let frames = r
        .render_animation(&anim, FrameColors::Mesh, Shading::Flat, &[])
        .unwrap();
    assert_eq!(frames.len(), 6);
    // The cube's centroid in the image moves right frame by frame.
    let cx: Vec<f64> = frames
        .iter()
        .map(|im| {
            let (mut s, mut n) = (0.0, 0.0);
            for (i, p) in im.pixels().iter().enumerate() {
                if p[0] != 255 {
                    s += (i % 48) as f64;
                    n += 1.0;
                }
            }
            s / n
        })
        .collect();
    assert!(cx.windows(2).all(|w| w[1] > w[0] + 4.0), "{cx:?}");
    let gif = encode_gif(&frames, 12.0).unwrap();
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::RGBA);
    let mut dec = opts.read_info(std::io::Cursor::new(&gif)).unwrap();
    let mut k = 0;
    while let Some(f) = dec.read_next_frame().unwrap() {
        // Few colours: the shared palette is exact.
        assert_eq!(&f.buffer[..], frames[k].as_bytes());
        k += 1;
    }
    assert_eq!(k, 6);
    let sheet =
        contact_sheet(&frames, Some(&[0, 1, 2, 3, 4, 5]), &SheetOptions::default()).unwrap();
    assert_eq!((sheet.width(), sheet.height()), (3 * 52 + 4, 2 * 36 + 4));
    check_ref("moving_cube_sheet", &sheet);
}

#[test]
fn gif_of_many_colours_is_close() {
    // A smooth gradient of > 256 colours goes through the NeuQuant palette.
    let anim = moving_cube(3);
    let n = anim.vertex_count();
    let values: Vec<f32> = (0..3 * n)
        .map(|i| (i % n) as f32 / n as f32 * 2.0 - 1.0)
        .collect();
    let colors = ColorMap::Diverging.colors(&values);
    let mut o = RenderOptions::new(64, 48);
    o.supersample = 2;
    let r = Renderer::with_options(o).unwrap();
    let frames = r
        .render_animation(&anim, FrameColors::PerFrame(&colors), Shading::Smooth, &[])
        .unwrap();
    let gif = encode_gif(&frames, 24.0).unwrap();
    let again = encode_gif(&frames, 24.0).unwrap();
    assert_eq!(gif, again, "deterministic");
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::RGBA);
    let mut dec = opts.read_info(std::io::Cursor::new(&gif)).unwrap();
    let f = dec.read_next_frame().unwrap().unwrap();
    let err: f64 = f
        .buffer
        .iter()
        .zip(frames[0].as_bytes())
        .map(|(a, b)| (*a as f64 - *b as f64).abs())
        .sum::<f64>()
        / f.buffer.len() as f64;
    assert!(err < 3.0, "mean channel error {err}");
}

#[test]
fn cube_silhouette_large_for_inspection() {
    let anim = moving_cube(1);
    let mut o = RenderOptions::new(256, 256);
    o.supersample = 2;
    let r = Renderer::with_options(o).unwrap();
    let p = anim.frame(0);
    let list = render::DrawList::new().mesh(
        render::MeshItem::new(p, &anim.mesh.triangles)
            .shading(Shading::Flat)
            .edges(render::EdgeStyle {
                mode: render::EdgeMode::Silhouette,
                color: [0.0, 0.0, 0.0, 1.0],
                width: 2.0,
            }),
    );
    let view = View::fit(list.bbox(), ViewDirection::ThreeQuarter, 1.0);
    let img = r.render(&list, &view).unwrap();
    let dark = img.pixels().iter().filter(|p| p[0] < 60).count();
    std::fs::write(
        format!("{}/cube_sil.png", env!("CARGO_TARGET_TMPDIR")),
        encode_png(&img).unwrap(),
    )
    .unwrap();
    // Six silhouette edges of ~100 px at 2 px width.
    assert!(dark > 600, "{dark}");
}
