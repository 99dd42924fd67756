//! Rigged models (a skin over joints) are drawn in the pose their node hierarchy holds, each
//! vertex carried by its joints as glTF 2.0 defines skinning, the skinned node's own transform
//! ignored; a vertex bound to a joint the skin does not have is the file's error.

use base64::Engine as _;
use phantogram_assets::model::{Model, ModelError, load_gltf};
use phantogram_testkit::Scratch;

/// A triangle skinned to two joints: joint 0 (node 1, 2 m up) bound where it stands (its inverse
/// bind matrix undoes its place), joint 1 (node 2, a child 3 m out) bound at the origin. Vertex
/// 0 on joint 0, vertex 1 on joint 1, vertex 2 half on each (`joint_of_vertex_1` replaces
/// vertex 1's joint). The mesh's own node is 100 m to the side, which glTF says to ignore.
fn skinned(name: &str, joint_of_vertex_1: u8) -> Result<Model, ModelError> {
    let positions = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let joints: [u8; 12] = [0, 0, 0, 0, joint_of_vertex_1, 0, 0, 0, 0, 1, 0, 0];
    let weights = [1.0f32, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.5, 0.5, 0.0, 0.0];
    let translate = |y: f32| {
        [
            1.0f32, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, y, 0.0, 1.0,
        ]
    };
    let inverse_binds: Vec<f32> = translate(-2.0).into_iter().chain(translate(0.0)).collect();
    let mut bin: Vec<u8> = positions.iter().flat_map(|v| v.to_le_bytes()).collect();
    bin.extend_from_slice(&joints);
    bin.extend(weights.iter().flat_map(|v| v.to_le_bytes()));
    bin.extend(inverse_binds.iter().flat_map(|v| v.to_le_bytes()));
    let text = format!(
        r#"{{"asset":{{"version":"2.0"}},
        "buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{}"}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":12}},
                       {{"buffer":0,"byteOffset":48,"byteLength":48}},{{"buffer":0,"byteOffset":96,"byteLength":128}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}},
                     {{"bufferView":1,"componentType":5121,"count":3,"type":"VEC4"}},
                     {{"bufferView":2,"componentType":5126,"count":3,"type":"VEC4"}},
                     {{"bufferView":3,"componentType":5126,"count":2,"type":"MAT4"}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"JOINTS_0":1,"WEIGHTS_0":2}}}}]}}],
        "skins":[{{"joints":[1,2],"inverseBindMatrices":3}}],
        "nodes":[{{"mesh":0,"skin":0,"translation":[100,0,0]}},
                 {{"translation":[0,2,0],"children":[2]}},
                 {{"translation":[0,0,3]}}],
        "scenes":[{{"nodes":[0,1]}}],"scene":0}}"#,
        bin.len(),
        base64::engine::general_purpose::STANDARD.encode(&bin)
    );
    // A folder per test: tests run in parallel, and a scratch folder is its name's alone.
    let dir = Scratch::new(&format!("skinned-{name}"));
    let path = dir.join("skinned.gltf");
    std::fs::write(&path, text).expect("write");
    load_gltf(&path)
}

#[test]
fn a_skinned_mesh_is_drawn_where_its_joints_carry_it() {
    let model = skinned("posed", 1).expect("a valid rigged file");
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let p: Vec<[f32; 3]> = model.primitives[0].mesh.vertices.iter().map(|v| v.position).collect();
    // Vertex 0: joint 0 in its bind pose (no move). Vertex 1: joint 1's world, (0, 2, 3).
    // Vertex 2: half of each. Never the node's 100 m.
    assert_eq!(p, vec![[0.0, 0.0, 0.0], [1.0, 2.0, 3.0], [0.0, 2.0, 1.5]]);
}

#[test]
fn a_vertex_bound_to_a_joint_the_skin_lacks_is_the_files_error() {
    let error = skinned("bad-joint", 7).expect_err("joint 7 of 2").to_string();
    assert!(error.contains("joint 7"), "{error}");
}
