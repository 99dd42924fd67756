//! Morph targets at the weights the file gives: glTF draws a mesh with `weights` (on its node, or
//! else on the mesh) at its base shape plus the weighted displacements of its targets, and this
//! viewer plays no animation, so that is the shape it must show. Before, the base shape was
//! drawn whatever the weights.

use base64::Engine as _;
use phantogram_assets::model::{Model, ModelError, load_gltf};
use phantogram_testkit::Scratch;

/// A triangle (0,0,0) (1,0,0) (0,1,0) facing +z with one target that lifts its third corner by
/// 1 along z and tilts that corner's normal (sparse: one displacement stored, the rest zero),
/// and a second target that moves every corner by 1 along x. `mesh` and `node` splice in their
/// `weights`.
fn morphing(mesh: &str, node: &str) -> String {
    let f32s = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let positions = f32s(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    let normals = f32s(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0]);
    let lift = f32s(&[0.0, 0.0, 1.0]);
    let tilt = f32s(&[0.0, -1.0, 0.0]);
    let shift = f32s(&[1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0]);
    let index = vec![2u8, 0, 0, 0];
    let bin = [positions, normals, lift, tilt, shift, index].concat();
    format!(
        r#"{{"asset":{{"version":"2.0"}},
        "buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{}"}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":36}},
                       {{"buffer":0,"byteOffset":72,"byteLength":12}},{{"buffer":0,"byteOffset":84,"byteLength":12}},
                       {{"buffer":0,"byteOffset":96,"byteLength":36}},{{"buffer":0,"byteOffset":132,"byteLength":4}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}},
                     {{"bufferView":1,"componentType":5126,"count":3,"type":"VEC3"}},
                     {{"componentType":5126,"count":3,"type":"VEC3","sparse":{{"count":1,
                        "indices":{{"bufferView":5,"componentType":5125}},"values":{{"bufferView":2}}}}}},
                     {{"componentType":5126,"count":3,"type":"VEC3","sparse":{{"count":1,
                        "indices":{{"bufferView":5,"componentType":5125}},"values":{{"bufferView":3}}}}}},
                     {{"bufferView":4,"componentType":5126,"count":3,"type":"VEC3"}},
                     {{"bufferView":4,"componentType":5126,"count":2,"type":"VEC3"}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"NORMAL":1}},
                     "targets":[{{"POSITION":2,"NORMAL":3}},{{"POSITION":4}}]}}]{mesh}}}],
        "nodes":[{{"mesh":0{node}}}],"scenes":[{{"nodes":[0]}}],"scene":0}}"#,
        bin.len(),
        base64::engine::general_purpose::STANDARD.encode(&bin)
    )
}

fn load(test: &str, text: &str) -> Result<Model, ModelError> {
    let dir = Scratch::new(&format!("morph-{test}"));
    let path = dir.join("model.gltf");
    std::fs::write(&path, text).expect("write");
    load_gltf(&path)
}

fn corner(model: &Model, i: usize) -> ([f32; 3], [f32; 3]) {
    let v = &model.primitives[0].mesh.vertices[i];
    (v.position, v.normal)
}

#[test]
fn the_mesh_weights_pose_the_mesh() {
    let model = load("mesh", &morphing(r#","weights":[0.5, 0.0]"#, "")).expect("loads");
    let (p, n) = corner(&model, 2);
    assert_eq!(p, [0.0, 1.0, 0.5], "half the lift");
    // The normal (0, −0.5, 1) made unit.
    let expected = [0.0, -0.5 / 1.25f32.sqrt(), 1.0 / 1.25f32.sqrt()];
    assert!(n.iter().zip(expected).all(|(a, b)| (a - b).abs() < 1e-5), "{n:?}");
    assert_eq!(
        corner(&model, 0).0,
        [0.0, 0.0, 0.0],
        "the sparse target leaves the others"
    );
}

#[test]
fn the_nodes_weights_take_precedence_over_the_meshes() {
    let model = load(
        "node",
        &morphing(r#","weights":[0.5, 0.0]"#, r#","weights":[1.0, 2.0]"#),
    )
    .expect("loads");
    assert_eq!(corner(&model, 2).0, [2.0, 1.0, 1.0]);
    assert_eq!(corner(&model, 0).0, [2.0, 0.0, 0.0]);
}

#[test]
fn without_weights_the_base_shape_is_drawn() {
    let model = load("none", &morphing("", "")).expect("loads");
    assert_eq!(corner(&model, 2).0, [0.0, 1.0, 0.0]);
}

#[test]
fn a_target_of_the_wrong_size_is_the_files_error() {
    let text = morphing(r#","weights":[0.0, 1.0]"#, "").replace(r#"{"POSITION":4}"#, r#"{"POSITION":5}"#);
    match load("bad", &text) {
        Err(ModelError::Data { what, message, .. }) => {
            assert!(what.contains("morph target 1"), "{what}");
            assert!(message.contains("not 3 VEC3"), "{message}");
        }
        other => panic!("{other:?}"),
    }
}
