//! `EXT_mesh_gpu_instancing` (gltfpack's `-mi`, and exporters of scenes with repeated parts): a
//! node's mesh is drawn once per instance, at the node's world transform times the instance's
//! translation · rotation · scale, and not where the node alone would put it. Before, a file
//! requiring the extension was refused by name.

use base64::Engine as _;
use phantogram_assets::budget::ResourceBudget;
use phantogram_assets::model::{Model, ModelError, load_gltf, load_gltf_within};
use phantogram_testkit::Scratch;

/// A triangle, (0,0,0) (1,0,0) (0,1,0), in a node 5 m up z, instanced three times:
/// 0. moved 10 along x;
/// 1. scaled ×2 and turned 90° about z (the rotation as normalised shorts, as gltfpack writes);
/// 2. mirrored in x and moved −3 along y.
///
/// `attributes` is the extension's attribute object; accessors 1–3 are the translations,
/// rotations and scales, accessor 4 the translations of two instances only, accessor 5 the
/// translations of 200 instances, all at the node.
fn instanced(attributes: &str) -> String {
    let f32s = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let positions = f32s(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    let translations = f32s(&[10.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -3.0, 0.0]);
    let rotations: Vec<u8> = [0i16, 0, 0, 32767, 0, 0, 23170, 23170, 0, 0, 0, 32767]
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    let scales = f32s(&[1.0, 1.0, 1.0, 2.0, 2.0, 2.0, -1.0, 1.0, 1.0]);
    let many = vec![0u8; 200 * 12];
    let bin = [positions, translations, rotations, scales, many].concat();
    format!(
        r#"{{"asset":{{"version":"2.0"}},
        "extensionsUsed":["EXT_mesh_gpu_instancing"],"extensionsRequired":["EXT_mesh_gpu_instancing"],
        "buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{}"}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":36}},
                       {{"buffer":0,"byteOffset":72,"byteLength":24}},{{"buffer":0,"byteOffset":96,"byteLength":36}},
                       {{"buffer":0,"byteOffset":132,"byteLength":2400}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}},
                     {{"bufferView":1,"componentType":5126,"count":3,"type":"VEC3"}},
                     {{"bufferView":2,"componentType":5122,"normalized":true,"count":3,"type":"VEC4"}},
                     {{"bufferView":3,"componentType":5126,"count":3,"type":"VEC3"}},
                     {{"bufferView":1,"componentType":5126,"count":2,"type":"VEC3"}},
                     {{"bufferView":4,"componentType":5126,"count":200,"type":"VEC3"}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
        "nodes":[{{"mesh":0,"translation":[0,0,5],"extensions":{{"EXT_mesh_gpu_instancing":{{"attributes":{attributes}}}}}}}],
        "scenes":[{{"nodes":[0]}}],"scene":0}}"#,
        bin.len(),
        base64::engine::general_purpose::STANDARD.encode(&bin)
    )
}

const ALL: &str = r#"{"TRANSLATION":1,"ROTATION":2,"SCALE":3,"_ID":1}"#;

fn load(test: &str, text: &str, budget: ResourceBudget) -> Result<Model, ModelError> {
    let dir = Scratch::new(&format!("instancing-{test}"));
    let path = dir.join("model.gltf");
    std::fs::write(&path, text).expect("write");
    if budget == ResourceBudget::default() {
        load_gltf(&path)
    } else {
        load_gltf_within(&path, budget)
    }
}

/// Each triangle of `model`'s first primitive as its three corners, in index order.
fn triangles(model: &Model) -> Vec<[[f32; 3]; 3]> {
    let mesh = &model.primitives[0].mesh;
    mesh.indices
        .chunks(3)
        .map(|t| [0, 1, 2].map(|k| mesh.vertices[t[k] as usize].position))
        .collect()
}

fn near(a: [[f32; 3]; 3], b: [[f32; 3]; 3]) -> bool {
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .all(|(x, y)| (x - y).abs() < 1e-3)
}

#[test]
fn each_instance_is_drawn_where_its_transform_puts_it_and_the_mesh_alone_is_not() {
    let model = load("all", &instanced(ALL), ResourceBudget::default()).expect("a file requiring the extension loads");
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    assert_eq!(model.primitives.len(), 1, "the copies are one primitive");
    let expected = [
        [[10.0, 0.0, 5.0], [11.0, 0.0, 5.0], [10.0, 1.0, 5.0]],
        // (1,0,0) ×2 → (2,0,0), turned → (0,2,0); (0,1,0) ×2 → (0,2,0), turned → (−2,0,0).
        [[0.0, 0.0, 5.0], [0.0, 2.0, 5.0], [-2.0, 0.0, 5.0]],
        // Mirrored: the winding reversed, so that the triangle still faces +z.
        [[0.0, -3.0, 5.0], [0.0, -2.0, 5.0], [-1.0, -3.0, 5.0]],
    ];
    let got = triangles(&model);
    assert_eq!(got.len(), 3, "{got:?}");
    for (g, e) in got.iter().zip(expected) {
        assert!(near(*g, e), "got {g:?}, expected {e:?}");
    }
}

#[test]
fn attributes_left_out_are_the_identity() {
    let model = load(
        "translation-only",
        &instanced(r#"{"TRANSLATION":1}"#),
        ResourceBudget::default(),
    )
    .expect("loads");
    let got = triangles(&model);
    assert_eq!(got.len(), 3);
    assert!(
        near(got[1], [[0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0]]),
        "{:?}",
        got[1]
    );
}

#[test]
fn malformed_instances_are_the_files_error() {
    for (attributes, expected) in [
        (r#"{"TRANSLATION":1,"SCALE":4}"#, "different counts"),
        (r#"{"TRANSLATION":2}"#, "not Vec3"),
        (r#"{"ROTATION":1}"#, "not Vec4"),
        (r#"{"SCALE":9}"#, "accessor 9 does not exist"),
    ] {
        match load("malformed", &instanced(attributes), ResourceBudget::default()) {
            Err(ModelError::Data { what, message, .. }) => {
                assert!(what.contains("EXT_mesh_gpu_instancing"), "{attributes}: {what}");
                assert!(message.contains(expected), "{attributes}: {message}");
            }
            other => panic!("{attributes}: {other:?}"),
        }
    }
}

#[test]
fn every_copy_is_charged_to_the_budget_before_it_is_made() {
    // 200 instances of the triangle: the 199 copies take far more than the file. The least
    // memory the file loads in (bisected); one byte less fails on the copies, charged as one
    // sum before they are made.
    let within = |memory_bytes: u64| ResourceBudget {
        memory_bytes,
        ..ResourceBudget::default()
    };
    let text = instanced(r#"{"TRANSLATION":5}"#);
    let (mut fails, mut loads) = (0u64, 1u64 << 24);
    assert!(load("budget", &text, within(loads)).is_ok());
    while loads - fails > 1 {
        let mid = (fails + loads) / 2;
        match load("budget", &text, within(mid)) {
            Ok(_) => loads = mid,
            Err(_) => fails = mid,
        }
    }
    match load("budget", &text, within(fails)) {
        Err(ModelError::OverBudget { error, .. }) => {
            assert!(error.what.contains("200 instances"), "{error}");
            assert_eq!(error.needed, ResourceBudget::mesh_bytes(199 * 3, 199 * 3), "{error}");
        }
        other => panic!("{other:?}"),
    }
    let model = load("budget", &text, within(loads)).expect("loads");
    assert_eq!(model.primitives[0].mesh.vertices.len(), 600);
}

#[test]
fn an_instance_count_the_budget_cannot_hold_is_refused_before_the_transforms_are_made() {
    // Four million instances whose translations have no data (zeros, as glTF reads an accessor
    // without a bufferView): 48 MB of translations, but 512 MB of instance and world matrices,
    // over the phone's 384 MiB.
    let text = instanced(r#"{"TRANSLATION":5}"#).replace(
        r#"{"bufferView":4,"componentType":5126,"count":200,"type":"VEC3"}"#,
        r#"{"componentType":5126,"count":4000000,"type":"VEC3"}"#,
    );
    match load("count", &text, ResourceBudget::default()) {
        Err(ModelError::OverBudget { error, .. }) => {
            assert!(error.what.contains("EXT_mesh_gpu_instancing"), "{error}");
            assert_eq!(error.needed, 4_000_000 * 128, "{error}");
        }
        other => panic!("{other:?}"),
    }
}
