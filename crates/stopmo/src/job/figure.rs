//! StopShop Fig. 5 for a segmentation: the parts on the average mesh beside the mean
//! displacement from it.

use crate::segment::Segmentation;

/// Width and height of each of the two panels in pixels.
const PANEL: u32 = 480;

/// The parts (one categorical colour each) on the average mesh, beside the mean displacement
/// from the average mesh (of the output: homogenized seams show as still), front view.
///
/// # Errors
/// Only if the image cannot be allocated.
pub(crate) fn parts_figure(seg: &Segmentation) -> render::Result<render::Image> {
    let out = &seg.animation;
    let avg = out.average_positions();
    let mesh = &out.mesh;
    let part_colors: Vec<render::Color> = seg
        .triangle_part
        .iter()
        .map(|&p| render::categorical(p as usize))
        .collect();
    let frames = out.frame_count() as f32;
    let mut disp = vec![0f32; out.vertex_count()];
    for f in out.frames() {
        for (v, (p, a)) in f.iter().zip(&avg).enumerate() {
            disp[v] += (*p - *a).length() / frames;
        }
    }
    let max = disp.iter().copied().fold(0.0f32, f32::max).max(1e-12);
    let disp_colors: Vec<render::Color> = disp
        .iter()
        .map(|d| render::ColorMap::Sequential.map(d / max))
        .collect();
    let renderer = render::Renderer::new(PANEL, PANEL)?;
    let view = render::View::fit(
        anim::Aabb::from_points(&avg),
        render::ViewDirection::Front,
        renderer.aspect(),
    );
    let item = |colors| render::MeshItem::new(&avg, &mesh.triangles).colors(colors);
    let left = renderer.render(
        &render::DrawList::new().mesh(item(render::MeshColors::PerTriangle(&part_colors))),
        &view,
    )?;
    let right = renderer.render(
        &render::DrawList::new().mesh(item(render::MeshColors::PerVertex(&disp_colors))),
        &view,
    )?;
    render::contact_sheet(
        &[left, right],
        None,
        &render::SheetOptions {
            columns: 2,
            ..Default::default()
        },
    )
}
