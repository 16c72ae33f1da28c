//! The Spot cow (shared test asset): a real mesh rendered from several views, written out to
//! look at, with measured coverage and shading properties.

mod common;

use render::{
    encode_png, ColorMap, DrawList, EdgeMode, EdgeStyle, MeshColors, MeshItem, RenderOptions,
    Renderer, View, ViewDirection,
};

const SPOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/meshes/spot.obj");

#[test]
fn spot_three_quarter_preview() {
    let (p, t) = common::read_obj(SPOT);
    assert_eq!(p.len(), 2930);
    let mut o = RenderOptions::new(400, 400);
    o.supersample = 2;
    let r = Renderer::with_options(o).unwrap();
    // Colour by height through the diverging map, with silhouettes.
    let b = anim::Aabb::from_points(&p);
    let h: Vec<f32> = p
        .iter()
        .map(|q| 2.0 * (q.y - b.min.y) / (b.max.y - b.min.y) - 1.0)
        .collect();
    let colors = ColorMap::Diverging.colors(&h);
    let list = DrawList::new().mesh(
        MeshItem::new(&p, &t)
            .colors(MeshColors::PerVertex(&colors))
            .edges(EdgeStyle {
                mode: EdgeMode::Silhouette,
                color: [0.0, 0.0, 0.0, 1.0],
                width: 1.5,
            }),
    );
    let mut sheet = Vec::new();
    for dir in [
        ViewDirection::ThreeQuarter,
        ViewDirection::Front,
        ViewDirection::Side,
        ViewDirection::Top,
    ] {
        let view = View::fit(list.bbox(), dir, r.aspect());
        let img = r.render(&list, &view).unwrap();
        let covered = img
            .pixels()
            .iter()
            .filter(|p| **p != [255, 255, 255, 255])
            .count();
        let frac = covered as f64 / (400.0 * 400.0);
        // The cow fills a good part of the fitted view but not all of it.
        assert!((0.15..0.8).contains(&frac), "{dir:?}: coverage {frac}");
        sheet.push(img);
    }
    let s = render::contact_sheet(&sheet, Some(&[0, 1, 2, 3]), &Default::default()).unwrap();
    let out = format!("{}/spot_views.png", env!("CARGO_TARGET_TMPDIR"));
    std::fs::write(&out, encode_png(&s).unwrap()).unwrap();
    eprintln!("wrote {out}");
}

#[test]
fn spot_onion_skin_preview() {
    use glam::{Quat, Vec3};
    let (p, t) = common::read_obj(SPOT);
    let frames = 7;
    // Spot (facing −Z) hops forward, rising and pitching a little: an arc like the paper's
    // bouncing ball. Seen from +X, forward is to the right.
    let pos: Vec<Vec3> = (0..frames)
        .flat_map(|f| {
            let s = f as f32 / (frames - 1) as f32;
            let rot = Quat::from_rotation_x(0.4 * (s - 0.5));
            let off = Vec3::new(0.0, 1.2 * (1.0 - (2.0 * s - 1.0).powi(2)), -3.0 * s);
            p.iter().map(move |q| rot * *q + off)
        })
        .collect();
    let anim = anim::MeshAnimation::new(anim::Mesh::new("spot", p.clone(), t), 24.0, pos).unwrap();
    // Offset-like field: position along the motion relative to the frame's centroid, in
    // [−1, 1] (front red, back blue).
    let field: Vec<f32> = (0..frames)
        .flat_map(|f| {
            let fr = anim.frame(f);
            let c = fr.iter().map(|q| q.z).sum::<f32>() / fr.len() as f32;
            fr.iter()
                .map(move |q| ((c - q.z) / 0.7).clamp(-1.0, 1.0))
                .collect::<Vec<_>>()
        })
        .collect();
    let colors = ColorMap::Diverging.colors(&field);
    let mut o = RenderOptions::new(480, 240);
    o.supersample = 2;
    let r = Renderer::with_options(o).unwrap();
    let view = View::fit(
        render::animation_bbox(&anim),
        ViewDirection::Side,
        r.aspect(),
    );
    let img = r
        .render_onion(
            &anim,
            3,
            render::FrameColors::PerFrame(&colors),
            render::Shading::Smooth,
            &render::OnionStyle::symmetric(3),
            &view,
        )
        .unwrap();
    let out = format!("{}/spot_onion.png", env!("CARGO_TARGET_TMPDIR"));
    std::fs::write(&out, encode_png(&img).unwrap()).unwrap();
    eprintln!("wrote {out}");
    // Ghosts cover the image left and right of the current frame.
    let cols = |x0: u32, x1: u32| {
        (x0..x1)
            .flat_map(|x| (0..240).map(move |y| (x, y)))
            .filter(|&(x, y)| img.get(x, y).unwrap() != [255, 255, 255, 255])
            .count()
    };
    let (left, mid, right) = (cols(0, 120), cols(180, 300), cols(360, 480));
    assert!(
        left > 2000 && right > 2000 && mid > 2000,
        "{left} {mid} {right}"
    );
}
