//! Male/female plugs across a seam (StopShop Section 3.4, Fig. 13) on a synthetic dome split
//! into two parts whose seam vertices are copies, as `segment` writes them.

use anim::Mesh;
use glam::Vec3;
use stopmo::library::{
    add_plugs, check_solid, components, plan_plugs, solidify, volume, LibraryError, Plug,
    PlugOptions,
};

/// A 40 × 40 mm dome `z = −0.01 (x² + y²)` (outward normal +z) cut at `x = 0`: part 0 has
/// `x ≤ 0`, part 1 `x ≥ 0`, the seam column duplicated in both.
fn dome_parts() -> Vec<Mesh> {
    let n = 20; // cells per side
    let h = 2.0; // mm per cell
    let z = |x: f32, y: f32| -0.01 * (x * x + y * y);
    let part = |name: &str, i0: usize, i1: usize| {
        let w = i1 - i0 + 1;
        let mut pos = Vec::new();
        for j in 0..=n {
            for i in i0..=i1 {
                let (x, y) = (
                    (i as f32 - n as f32 / 2.0) * h,
                    (j as f32 - n as f32 / 2.0) * h,
                );
                pos.push(Vec3::new(x, y, z(x, y)));
            }
        }
        let mut tris = Vec::new();
        for j in 0..n {
            for i in 0..w - 1 {
                let a = (j * w + i) as u32;
                let (b, c, d) = (a + 1, a + 1 + w as u32, a + w as u32);
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            }
        }
        Mesh::new(name, pos, tris)
    };
    vec![part("left", 0, n / 2), part("right", n / 2, n)]
}

/// Depth of `q` below the dome's outer surface, measured along +z.
fn depth_below(q: Vec3) -> f32 {
    -0.01 * (q.x * q.x + q.y * q.y) - q.z
}

fn distance_to_axis(q: Vec3, origin: Vec3, axis: Vec3) -> f32 {
    let r = q - origin;
    (r - axis * r.dot(axis)).length()
}

fn plug() -> (Vec<Mesh>, Plug, PlugOptions) {
    let parts = dome_parts();
    let opts = PlugOptions::default();
    let plugs = plan_plugs(&parts, &opts).unwrap();
    assert_eq!(plugs.len(), 1, "{plugs:?}");
    (parts, plugs[0], opts)
}

#[test]
fn fig13_plug_axis_lies_in_the_seam_tangent_plane_and_crosses_the_seam() {
    let (_, p, _) = plug();
    assert_eq!((p.male, p.female, p.seam_vertices), (0, 1, 21));
    let (n, t, d) = (
        Vec3::from(p.normal),
        Vec3::from(p.tangent),
        Vec3::from(p.axis),
    );
    // The anchor is the middle seam vertex (0, 0, 0); the dome's normal there is +z.
    assert!(Vec3::from(p.anchor).length() < 1e-5, "{:?}", p.anchor);
    assert!(n.dot(Vec3::Z) > 0.9999, "normal {n}");
    assert!(t.y.abs() > 0.9999, "seam tangent {t}");
    assert!(
        d.dot(n).abs() < 1e-5,
        "axis leaves the tangent plane: {d}·{n}"
    );
    assert!(d.dot(t).abs() < 1e-5);
    assert!(d.x > 0.9999, "axis must run from left (male) to right: {d}");
}

#[test]
fn fig13_peg_and_socket_are_coaxial_closed_solids_with_clearance() {
    let (_, p, opts) = plug();
    let (male, female) = (p.male_solid(24), p.female_solid(24));
    for (name, m) in [("male", &male), ("female", &female)] {
        let c = check_solid(m);
        assert!(c.is_closed_manifold(), "{name}: {c:?}");
        assert!(volume(m) > 0.0, "{name} is inside out");
    }
    // The male's two cap centres (on the axis) define the measured axis.
    let origin = Vec3::from(p.center);
    let axis = Vec3::from(p.axis);
    let caps: Vec<Vec3> = male
        .positions
        .iter()
        .copied()
        .filter(|q| distance_to_axis(*q, origin, axis) < 1e-4)
        .collect();
    assert_eq!(caps.len(), 2);
    let measured = (caps[1] - caps[0]).normalize();
    assert!(measured.dot(axis).abs() > 0.99999);
    let radii = |m: &Mesh| {
        let mut r: Vec<f32> = m
            .positions
            .iter()
            .map(|q| distance_to_axis(*q, caps[0], measured))
            .filter(|&r| r > 1e-4)
            .collect();
        r.sort_by(f32::total_cmp);
        (r[0], r[r.len() - 1])
    };
    let ((pin, boss), (bore, outer)) = (radii(&male), radii(&female));
    assert!((pin - 1.0).abs() < 1e-4, "pin radius {pin}");
    assert!(
        (bore - pin - opts.clearance_mm as f32).abs() < 1e-4,
        "bore {bore} vs pin {pin}"
    );
    assert!((boss - outer).abs() < 1e-4 && (outer - 1.95).abs() < 1e-4);
    // Volumes of the 24-gon prisms: boss + pin L/2 each, tube ring over L/2 + clearance/2.
    let area = |r: f32| 12.0 * r * r * (std::f32::consts::TAU / 24.0).sin();
    let l = opts.length_mm as f32;
    let c = opts.clearance_mm as f32;
    let expect_male = area(boss) * (l / 2.0 - c / 2.0) + area(pin) * (l / 2.0 + c / 2.0);
    let expect_female = (area(outer) - area(bore)) * (l / 2.0 + c / 2.0);
    assert!((volume(&male) as f32 / expect_male - 1.0).abs() < 1e-3);
    assert!((volume(&female) as f32 / expect_female - 1.0).abs() < 1e-3);
}

#[test]
fn fig13_boss_fuses_into_the_shell_and_the_pin_clears_the_other_shell() {
    let (_, p, opts) = plug();
    let t = opts.thickness_mm as f32;
    let origin = Vec3::from(p.center);
    let (n, d) = (Vec3::from(p.normal), Vec3::from(p.axis));
    // Top of the boss under the male part: inside the shell (between outer and inner surface).
    let boss_top = depth_below(origin - d * 2.0 + n * p.outer_radius_mm);
    assert!(
        boss_top > 0.0 && boss_top < t,
        "boss top at depth {boss_top}"
    );
    // Top of the socket: inside the female shell; its bore stays below the inner surface.
    let socket_top = depth_below(origin + d * 2.0 + n * p.outer_radius_mm);
    assert!(socket_top > 0.0 && socket_top < t, "{socket_top}");
    let bore_top = depth_below(origin + d * 2.0 + n * p.socket_radius_mm);
    assert!(
        bore_top > t,
        "bore top {bore_top} cuts the shell of thickness {t}"
    );
}

#[test]
fn fig13_plugged_pieces_are_closed_manifold_per_component() {
    let (parts, p, opts) = plug();
    for (i, part) in parts.iter().enumerate() {
        let solid = solidify(part, opts.thickness_mm as f32).unwrap();
        let plugged = add_plugs(&solid, i, &[p], 24);
        let comps = components(&plugged);
        assert_eq!(comps.len(), 2, "part {i}");
        for c in &comps {
            let check = check_solid(c);
            assert!(check.is_closed_manifold(), "part {i}: {check:?}");
            assert!(volume(c) > 0.0);
        }
        assert!(check_solid(&plugged).is_closed_manifold());
        let added = volume(&plugged) - volume(&solid);
        let shell = if i == 0 {
            p.male_solid(24)
        } else {
            p.female_solid(24)
        };
        assert!(
            (added - volume(&shell)).abs() < 1e-3 * volume(&shell),
            "{added}"
        );
    }
}

#[test]
fn parts_without_a_common_seam_get_no_plug_and_bad_options_fail() {
    let mut parts = dome_parts();
    parts[1]
        .positions
        .iter_mut()
        .for_each(|q| *q += Vec3::X * 0.5);
    assert!(plan_plugs(&parts, &PlugOptions::default())
        .unwrap()
        .is_empty());
    // One part, or NaN geometry: defined results, no plug.
    assert!(plan_plugs(&parts[..1], &PlugOptions::default())
        .unwrap()
        .is_empty());
    let mut nan = dome_parts();
    nan.iter_mut().for_each(|m| m.positions[0] = Vec3::NAN);
    nan[1].positions.iter_mut().for_each(|q| q.z = f32::NAN);
    assert!(plan_plugs(&nan, &PlugOptions::default())
        .unwrap()
        .is_empty());
    let bad = PlugOptions {
        radius_mm: f64::NAN,
        ..PlugOptions::default()
    };
    assert!(matches!(
        plan_plugs(&parts, &bad),
        Err(LibraryError::InvalidParameter(_))
    ));
}
