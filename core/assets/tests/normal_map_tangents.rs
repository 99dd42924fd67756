//! A glTF mesh without tangents gets them from the texture coordinates its normal map is read
//! with — the set its `normalTexture` names and that texture's `KHR_texture_transform` — as the
//! glTF specification asks; the first set only where the material has no normal map or names a
//! set the mesh lacks. (Made from the first set always, a map read through the second set or
//! turned by its transform shaded as if lit from another side.)

use base64::Engine as _;
use image::ImageEncoder;
use phantogram_assets::model::{Model, load_gltf};
use phantogram_testkit::Scratch;

fn b64(bytes: &[u8]) -> String {
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// A flat normal map of one texel, as PNG.
fn png() -> Vec<u8> {
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(&[128, 128, 255, 255], 1, 1, image::ExtendedColorType::Rgba8)
        .expect("encode");
    out
}

/// One triangle facing +z at (0,0), (1,0), (0,1) in x, y, with normals. Its first set stands
/// upright on it (u = x, v = 1 − y: the image's top at +y), its second set is turned a quarter
/// (u = y, v = 1 − x: the image's top at +x); `second_set` leaves that one out. `material` is the
/// one material's JSON.
fn gltf(material: &str, second_set: bool) -> String {
    let corners = [[0.0f32, 0.0], [1.0, 0.0], [0.0, 1.0]];
    let positions: Vec<f32> = corners.iter().flat_map(|&[x, y]| [x, y, 0.0]).collect();
    let normals: Vec<f32> = corners.iter().flat_map(|_| [0.0, 0.0, 1.0]).collect();
    let uv0: Vec<f32> = corners.iter().flat_map(|&[x, y]| [x, 1.0 - y]).collect();
    let uv1: Vec<f32> = corners.iter().flat_map(|&[x, y]| [y, 1.0 - x]).collect();
    let bin: Vec<u8> = [positions, normals, uv0, uv1]
        .concat()
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let second = if second_set { r#","TEXCOORD_1":3"# } else { "" };
    format!(
        r#"{{"asset":{{"version":"2.0"}},"extensionsUsed":["KHR_texture_transform"],
        "buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{}"}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":36}},
                       {{"buffer":0,"byteOffset":72,"byteLength":24}},{{"buffer":0,"byteOffset":96,"byteLength":24}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
                     {{"bufferView":1,"componentType":5126,"count":3,"type":"VEC3"}},
                     {{"bufferView":2,"componentType":5126,"count":3,"type":"VEC2"}},
                     {{"bufferView":3,"componentType":5126,"count":3,"type":"VEC2"}}],
        "images":[{{"uri":"data:image/png;base64,{}"}}],
        "textures":[{{"source":0}}],
        "materials":[{material}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"NORMAL":1,"TEXCOORD_0":2{second}}},"material":0}}]}}],
        "nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}],"scene":0}}"#,
        bin.len(),
        b64(&bin),
        b64(&png())
    )
}

fn load(name: &str, text: &str) -> Model {
    // A folder per file: tests run in parallel, and a scratch folder is its name's alone.
    let dir = Scratch::new(&format!("tangents-{}", name.replace('.', "-")));
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write");
    load_gltf(&path).expect("the triangle loads")
}

/// Every vertex's tangent (xyz and handedness) is `expected`.
fn assert_tangents(model: &Model, expected: [f32; 4]) {
    assert_eq!(model.primitives.len(), 1);
    for v in &model.primitives[0].mesh.vertices {
        let t = v.tangent;
        assert!(
            t.iter().zip(expected).all(|(a, b)| (a - b).abs() < 1e-4),
            "tangent {t:?} at {:?}, expected {expected:?}",
            v.position
        );
    }
}

#[test]
fn tangents_come_from_the_set_the_normal_map_reads() {
    let model = load(
        "second.gltf",
        &gltf(r#"{"normalTexture":{"index":0,"texCoord":1}}"#, true),
    );
    // The second set's u grows along +y; its image's top (its +Y, green) is at +x:
    // cross(+z, +y)·w = +x needs w = −1.
    assert_tangents(&model, [0.0, 1.0, 0.0, -1.0]);
}

#[test]
fn tangents_come_from_the_normal_maps_turned_coordinates() {
    let model = load(
        "turned.gltf",
        &gltf(
            r#"{"normalTexture":{"index":0,"extensions":{"KHR_texture_transform":{"rotation":1.5707964}}}}"#,
            true,
        ),
    );
    // A quarter turn of the first set: u' = v = 1 − y grows along −y, the image's top towards
    // +x: cross(+z, −y)·w = +x needs w = +1.
    assert_tangents(&model, [0.0, -1.0, 0.0, 1.0]);
}

#[test]
fn without_a_normal_map_or_its_set_the_first_set_gives_the_tangents() {
    // No normal map, though the base colour reads the second set.
    let model = load(
        "plain.gltf",
        &gltf(
            r#"{"pbrMetallicRoughness":{"baseColorTexture":{"index":0,"texCoord":1}}}"#,
            true,
        ),
    );
    assert_tangents(&model, [1.0, 0.0, 0.0, 1.0]);
    // A normal map naming a second set the mesh lacks.
    let model = load(
        "lacking.gltf",
        &gltf(r#"{"normalTexture":{"index":0,"texCoord":1}}"#, false),
    );
    assert_tangents(&model, [1.0, 0.0, 0.0, 1.0]);
}
