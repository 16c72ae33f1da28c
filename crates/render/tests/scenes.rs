//! Small synthetic scenes: direct pixel properties and stored reference images.

mod common;

use common::{check_ref, cube, quad};
use glam::{Mat4, Vec2, Vec3};
use render::{
    srgb8_to_linear, to_srgb8, ColorMap, Coords, DrawList, EdgeMode, EdgeStyle, MeshColors,
    MeshItem, Overlay, RenderOptions, Renderer, Shading, View, ViewDirection, DEFAULT_AMBIENT,
    DEFAULT_LIGHT,
};

const RED: [f32; 4] = [1.0, 0.0, 0.0, 1.0];
const BLUE: [f32; 4] = [0.0, 0.0, 1.0, 1.0];

fn front(list: &DrawList, r: &Renderer) -> View {
    View::fit(list.bbox(), ViewDirection::Front, r.aspect())
}

/// A fixed orthographic front view of the square [−2, 2]² (depth −10..10).
fn ortho4() -> View {
    View::new(
        Mat4::IDENTITY,
        glam::camera::rh::proj::opengl::orthographic(-2.0, 2.0, -2.0, 2.0, -10.0, 10.0),
    )
}

#[test]
fn red_triangle_centre_is_red() {
    let p = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let t = [[0u32, 1, 2]];
    let r = Renderer::new(64, 64).unwrap();
    let unlit = DrawList::new().mesh(MeshItem::new(&p, &t).color(RED).shading(Shading::Unlit));
    let img = r.render(&unlit, &front(&unlit, &r)).unwrap();
    assert_eq!(img.get(32, 36), Some([255, 0, 0, 255]));
    assert_eq!(img.get(1, 1), Some([255, 255, 255, 255]));
    // Lit: Lambert with the face normal +Z and the default light.
    let lit = DrawList::new().mesh(MeshItem::new(&p, &t).color(RED));
    let img = r.render(&lit, &front(&lit, &r)).unwrap();
    let i = DEFAULT_AMBIENT + (1.0 - DEFAULT_AMBIENT) * DEFAULT_LIGHT.normalize().z;
    assert_eq!(img.get(32, 36), Some(to_srgb8([i, 0.0, 0.0, 1.0])));
    check_ref("red_triangle", &img);
}

#[test]
fn occlusion_order_is_by_depth_not_submission() {
    let (pa, ta) = quad(-0.5, 0.0, 0.0, 1.0);
    let (pb, tb) = quad(0.5, 0.0, 0.5, 1.0); // nearer to a front view
    let r = Renderer::new(64, 64).unwrap();
    let red = MeshItem::new(&pa, &ta).color(RED).shading(Shading::Unlit);
    let blue = MeshItem::new(&pb, &tb).color(BLUE).shading(Shading::Unlit);
    for list in [
        DrawList::new().mesh(red).mesh(blue),
        DrawList::new().mesh(blue).mesh(red),
    ] {
        let img = r.render(&list, &ortho4()).unwrap();
        assert_eq!(
            img.get(32, 32),
            Some([0, 0, 255, 255]),
            "overlap shows the nearer quad"
        );
        assert_eq!(img.get(14, 32), Some([255, 0, 0, 255]));
        assert_eq!(img.get(50, 32), Some([0, 0, 255, 255]));
    }
}

#[test]
fn alpha_blend_value() {
    let (pa, ta) = quad(0.0, 0.0, 0.0, 1.0);
    let (pb, tb) = quad(0.0, 0.0, 0.5, 1.5);
    let r = Renderer::new(64, 64).unwrap();
    let list = DrawList::new()
        .mesh(
            MeshItem::new(&pb, &tb)
                .color(BLUE)
                .opacity(0.5)
                .shading(Shading::Unlit),
        )
        .mesh(MeshItem::new(&pa, &ta).color(RED).shading(Shading::Unlit));
    let img = r.render(&list, &ortho4()).unwrap();
    // Half blue over red, in linear light: (0.5, 0, 0.5) → sRGB 188.
    assert_eq!(img.get(32, 32), Some([188, 0, 188, 255]));
    // Half blue over the white background: (0.5, 0.5, 1).
    assert_eq!(img.get(32, 12), Some([188, 188, 255, 255]));
    // A translucent quad behind an opaque one is hidden.
    let (pc, tc) = quad(0.0, 0.0, -0.5, 1.5);
    let list = DrawList::new()
        .mesh(MeshItem::new(&pa, &ta).color(RED).shading(Shading::Unlit))
        .mesh(
            MeshItem::new(&pc, &tc)
                .color(BLUE)
                .opacity(0.5)
                .shading(Shading::Unlit),
        );
    let img = r.render(&list, &ortho4()).unwrap();
    assert_eq!(img.get(32, 32), Some([255, 0, 0, 255]));
}

#[test]
fn translucent_quad_is_watertight() {
    // Two triangles share a diagonal: every covered pixel is blended exactly once.
    let (p, t) = quad(0.0, 0.0, 0.0, 1.3);
    let r = Renderer::new(61, 47).unwrap();
    let list = DrawList::new().mesh(
        MeshItem::new(&p, &t)
            .color(BLUE)
            .opacity(0.5)
            .shading(Shading::Unlit),
    );
    let img = r.render(&list, &ortho4()).unwrap();
    let covered: Vec<[u8; 4]> = img
        .pixels()
        .iter()
        .copied()
        .filter(|p| *p != [255, 255, 255, 255])
        .collect();
    assert!(covered.len() > 200, "{}", covered.len());
    assert!(
        covered.iter().all(|p| *p == [188, 188, 255, 255]),
        "double-blended pixels on the diagonal"
    );
}

#[test]
fn back_faces_are_lit_or_culled() {
    // Clockwise seen from the front: a back face.
    let p = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
    ];
    let t = [[0u32, 1, 2]];
    let list = DrawList::new().mesh(MeshItem::new(&p, &t).color(RED).shading(Shading::Flat));
    let two_sided = Renderer::new(32, 32).unwrap();
    let img = two_sided.render(&list, &ortho4()).unwrap();
    let i = DEFAULT_AMBIENT + (1.0 - DEFAULT_AMBIENT) * DEFAULT_LIGHT.normalize().z;
    assert_eq!(img.get(16, 17), Some(to_srgb8([i, 0.0, 0.0, 1.0])));
    let mut o = RenderOptions::new(32, 32);
    o.cull_back_faces = true;
    let img = Renderer::with_options(o)
        .unwrap()
        .render(&list, &ortho4())
        .unwrap();
    assert_eq!(img.get(16, 17), Some([255, 255, 255, 255]));
}

#[test]
fn perspective_camera_and_near_clipping() {
    let cam = anim::Camera {
        name: "cam".into(),
        projection: anim::Projection::Perspective {
            yfov: std::f32::consts::FRAC_PI_2,
            aspect: None,
            znear: 0.1,
            zfar: Some(100.0),
        },
        world: vec![Mat4::from_translation(Vec3::new(0.0, 0.0, 2.0))],
    };
    let r = Renderer::new(64, 64).unwrap();
    let view = View::camera(&cam, 0, r.aspect());
    // A unit square 2 units in front with a 90° field of view spans half the image.
    let (p, t) = quad(0.0, 0.0, 0.0, 1.0);
    let list = DrawList::new().mesh(MeshItem::new(&p, &t).color(RED).shading(Shading::Unlit));
    let img = r.render(&list, &view).unwrap();
    let n = img.pixels().iter().filter(|p| p[1] == 0).count();
    assert_eq!(n, 32 * 32);
    // A floor crossing the camera plane is clipped at the near plane, not dropped.
    let floor = [
        Vec3::new(-50.0, -1.0, 50.0),
        Vec3::new(50.0, -1.0, 50.0),
        Vec3::new(0.0, -1.0, -50.0),
    ];
    let ft = [[0u32, 1, 2]];
    let list = DrawList::new().mesh(
        MeshItem::new(&floor, &ft)
            .color(BLUE)
            .shading(Shading::Unlit),
    );
    let img = r.render(&list, &view).unwrap();
    assert_eq!(img.get(32, 63), Some([0, 0, 255, 255]));
    assert_eq!(img.get(32, 2), Some([255, 255, 255, 255]));
    let blue = img.pixels().iter().filter(|p| p[0] == 0).count();
    // The horizon is at the image centre: about the lower half is floor.
    assert!((blue as i64 - 32 * 64).abs() < 3 * 64, "{blue}");
}

#[test]
fn cube_three_quarter_reference() {
    let (p, t) = cube(Vec3::ZERO, 1.0);
    let mut o = RenderOptions::new(64, 64);
    o.supersample = 2;
    let r = Renderer::with_options(o).unwrap();
    let list = DrawList::new().mesh(
        MeshItem::new(&p, &t)
            .color([0.8, 0.5, 0.2, 1.0])
            .shading(Shading::Flat)
            .edges(EdgeStyle {
                mode: EdgeMode::Silhouette,
                color: [0.0, 0.0, 0.0, 1.0],
                width: 1.0,
            }),
    );
    let view = View::fit(list.bbox(), ViewDirection::ThreeQuarter, r.aspect());
    let img = r.render(&list, &view).unwrap();
    // Three faces visible with three different brightnesses.
    let mut shades: Vec<u8> = [(32, 18), (22, 38), (42, 38)]
        .iter()
        .map(|&(x, y)| img.get(x, y).unwrap()[0])
        .collect();
    shades.sort();
    shades.dedup();
    assert_eq!(shades.len(), 3, "{shades:?}");
    check_ref("cube_three_quarter", &img);
}

#[test]
fn diverging_triangle_reference() {
    let p = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let t = [[0u32, 1, 2]];
    let c = ColorMap::Diverging.colors(&[-1.0, 1.0, 0.0]);
    let r = Renderer::new(64, 64).unwrap();
    let list = DrawList::new().mesh(
        MeshItem::new(&p, &t)
            .colors(MeshColors::PerVertex(&c))
            .shading(Shading::Unlit),
    );
    let img = r.render(&list, &front(&list, &r)).unwrap();
    // Left corner blue, right corner red, the midpoint of the bottom edge between them.
    let left = img.get(6, 59).unwrap();
    let right = img.get(57, 59).unwrap();
    assert!(left[2] > left[0] + 80, "{left:?}");
    assert!(right[0] > right[2] + 80, "{right:?}");
    let mid = img.get(32, 59).unwrap();
    let lin = |c: u8| srgb8_to_linear(c);
    // Linear interpolation of the two linear colours.
    let want = (lin(202) + lin(5)) * 0.5;
    assert!((lin(mid[0]) - want).abs() < 0.03, "{mid:?}");
    check_ref("diverging_triangle", &img);
}

#[test]
fn overlays_reference_and_depth_test() {
    let (p, t) = quad(0.0, 0.0, 0.0, 1.0);
    let r = Renderer::new(64, 64).unwrap();
    let line = Overlay::polyline(
        Coords::World(vec![Vec3::new(-1.8, 0.0, -1.0), Vec3::new(1.8, 0.0, -1.0)]),
        [0.0, 0.6, 0.0, 1.0],
        3.0,
    );
    let list = DrawList::new()
        .mesh(
            MeshItem::new(&p, &t)
                .color([0.7, 0.7, 0.7, 1.0])
                .shading(Shading::Unlit),
        )
        .overlay(line.clone().with_depth_test(true))
        .overlay(Overlay::points(
            Coords::Pixel(vec![Vec2::new(8.0, 8.0), Vec2::new(56.0, 8.0)]),
            RED,
            6.0,
        ))
        .overlay(Overlay::polyline(
            Coords::Pixel(vec![
                Vec2::new(4.0, 60.0),
                Vec2::new(32.0, 50.0),
                Vec2::new(60.0, 60.0),
            ]),
            BLUE,
            2.0,
        ));
    let img = r.render(&list, &ortho4()).unwrap();
    // The line passes behind the quad: hidden in the middle, visible outside it.
    assert_eq!(img.get(32, 32), Some(to_srgb8([0.7, 0.7, 0.7, 1.0])));
    let g = img.get(4, 31).unwrap();
    assert!(g[1] > g[0] + 50, "{g:?}");
    assert_eq!(img.get(8, 8), Some([255, 0, 0, 255]));
    check_ref("overlays", &img);
    // Without the depth test the line is drawn over the quad.
    let list2 = DrawList::new()
        .mesh(
            MeshItem::new(&p, &t)
                .color([0.7, 0.7, 0.7, 1.0])
                .shading(Shading::Unlit),
        )
        .overlay(line);
    let img2 = r.render(&list2, &ortho4()).unwrap();
    let c = img2.get(32, 31).unwrap();
    assert!(c[1] > c[0] + 50, "{c:?}");
}

#[test]
fn render_is_deterministic_across_thread_counts() {
    let (p, t) = cube(Vec3::ZERO, 1.0);
    let r = Renderer::new(48, 40).unwrap();
    let list = DrawList::new().mesh(MeshItem::new(&p, &t).opacity(0.6));
    let view = View::fit(list.bbox(), ViewDirection::ThreeQuarter, r.aspect());
    let a = r.render(&list, &view).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let b = pool.install(|| r.render(&list, &view)).unwrap();
    assert_eq!(a, b);
    assert!(a.pixels().iter().any(|p| p[0] != 255));
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let p = [Vec3::ZERO, Vec3::X];
    let t = [[0u32, 1, 2]];
    let r = Renderer::new(8, 8).unwrap();
    let list = DrawList::new().mesh(MeshItem::new(&p, &t));
    assert!(matches!(
        r.render(&list, &ortho4()),
        Err(render::RenderError::IndexOutOfRange { index: 2, .. })
    ));
    let c = [RED];
    let p3 = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let list = DrawList::new().mesh(MeshItem::new(&p3, &t).colors(MeshColors::PerVertex(&c)));
    assert!(matches!(
        r.render(&list, &ortho4()),
        Err(render::RenderError::AttributeLength { .. })
    ));
    // NaN vertices drop their triangles.
    let pn = [Vec3::NAN, Vec3::X, Vec3::Y];
    let list = DrawList::new().mesh(MeshItem::new(&pn, &t));
    let img = r.render(&list, &ortho4()).unwrap();
    assert!(img.pixels().iter().all(|p| *p == [255; 4]));
}
