//! Several texture-coordinate sets (glTF `TEXCOORD_0`, `TEXCOORD_1`, …) survive
//! `toonkit convert` from glTF to glTF: every set is read, sampled with the mesh and
//! written again with its values.

mod common;

use common::{data, ok, s};

fn scene_of(path: &std::path::Path) -> anim::Scene {
    match tkio::load(path, &tkio::LoadOptions::default()).unwrap() {
        tkio::Loaded::Scene(scene) => *scene,
        _ => panic!("{}: not a scene", path.display()),
    }
}

#[test]
fn convert_keeps_every_uv_set() {
    let dir = tempfile::tempdir().unwrap();
    let mut scene = scene_of(&data("characters/CesiumMan.glb"));
    assert_eq!(scene.meshes.len(), 1);
    let mesh = &mut scene.meshes[0].mesh;
    let uvs = mesh.uvs.clone().expect("CesiumMan has TEXCOORD_0");
    // Two more sets: a planar layout from the rest positions and a constant one.
    let planar: Vec<[f32; 2]> = mesh.positions.iter().map(|p| [p.x, p.z]).collect();
    let constant = vec![[0.25, 0.75]; mesh.vertex_count()];
    mesh.extra_uvs = vec![planar.clone(), constant.clone()];
    let input = dir.path().join("three_sets.glb");
    std::fs::write(&input, tkio::gltf::write_glb(&scene).unwrap()).unwrap();

    // Read back: three sets.
    let read = scene_of(&input);
    assert_eq!(read.meshes[0].mesh.uvs.as_ref(), Some(&uvs));
    assert_eq!(
        read.meshes[0].mesh.extra_uvs,
        vec![planar.clone(), constant.clone()]
    );

    // Through convert (sampled, written as a flipbook): every frame keeps the three sets.
    let output = dir.path().join("converted.glb");
    ok(&["convert", s(&input), s(&output)]);
    let out = scene_of(&output);
    assert!(out.meshes.len() > 1, "one mesh per frame");
    for sm in &out.meshes {
        assert_eq!(sm.mesh.uvs.as_ref(), Some(&uvs), "{}", sm.mesh.name);
        assert_eq!(sm.mesh.extra_uvs, vec![planar.clone(), constant.clone()]);
    }
}
