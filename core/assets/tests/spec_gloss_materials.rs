//! Materials in the specular–glossiness workflow (`KHR_materials_pbrSpecularGlossiness`), in a
//! file made here: each is drawn as the metallic–roughness material it converts to, not glTF's
//! default white metal (which is what a loader without it shows, the scan's colour lost).

use base64::Engine as _;
use image::ImageEncoder;
use phantogram_assets::model::{Model, load_gltf};
use phantogram_testkit::Scratch;

fn png_data_uri(rgba: &[u8], width: u32, height: u32) -> String {
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(rgba, width, height, image::ExtendedColorType::Rgba8)
        .expect("encode");
    format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(png)
    )
}

/// One textured triangle per material of `materials` (JSON objects), over two 2 × 1 images:
/// image 0 a diffuse texture (red, black), image 1 a specular–glossiness texture (grey 4 %
/// specular and glossy; gold and rough).
fn model(name: &str, materials: &[&str]) -> Model {
    let positions = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let uvs = [0.0f32, 0.0, 1.0, 0.0, 0.0, 1.0];
    let bin: Vec<u8> = positions.iter().chain(&uvs).flat_map(|v| v.to_le_bytes()).collect();
    let diffuse = png_data_uri(&[200, 50, 50, 255, 0, 0, 0, 255], 2, 1);
    let spec_gloss = png_data_uri(&[56, 56, 56, 230, 255, 226, 159, 51], 2, 1);
    let meshes: Vec<String> = (0..materials.len())
        .map(|k| format!(r#"{{"primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":1}},"material":{k}}}]}}"#))
        .collect();
    let nodes: Vec<String> = (0..materials.len()).map(|k| format!(r#"{{"mesh":{k}}}"#)).collect();
    let text = format!(
        r#"{{"asset":{{"version":"2.0"}},
        "extensionsUsed":["KHR_materials_pbrSpecularGlossiness"],
        "extensionsRequired":["KHR_materials_pbrSpecularGlossiness"],
        "buffers":[{{"byteLength":60,"uri":"data:application/octet-stream;base64,{}"}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":24}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}},
                     {{"bufferView":1,"componentType":5126,"count":3,"type":"VEC2"}}],
        "images":[{{"uri":"{diffuse}"}},{{"uri":"{spec_gloss}"}}],
        "textures":[{{"source":0}},{{"source":1}}],
        "materials":[{}],"meshes":[{}],"nodes":[{}],
        "scenes":[{{"nodes":[{}]}}],"scene":0}}"#,
        base64::engine::general_purpose::STANDARD.encode(&bin),
        materials.join(","),
        meshes.join(","),
        nodes.join(","),
        (0..nodes.len()).map(|k| k.to_string()).collect::<Vec<_>>().join(",")
    );
    // A folder per test: tests run in parallel, and a scratch folder is its name's alone.
    let dir = Scratch::new(&format!("spec-gloss-{name}"));
    let path = dir.join("sg.gltf");
    std::fs::write(&path, text).expect("write");
    load_gltf(&path).expect("a file requiring the extension loads")
}

fn ext(body: &str) -> String {
    format!(r#"{{"name":"m","extensions":{{"KHR_materials_pbrSpecularGlossiness":{body}}}}}"#)
}

#[test]
fn factors_convert_to_metallic_and_roughness() {
    let m = model(
        "factors",
        &[
            // Gold: no diffuse, gold specular, fairly glossy.
            &ext(r#"{"diffuseFactor":[0,0,0,1],"specularFactor":[1,0.77,0.34],"glossinessFactor":0.8}"#),
            // Red plastic: a dielectric's 4 % specular.
            &ext(r#"{"diffuseFactor":[0.8,0.1,0.1,0.5],"specularFactor":[0.04,0.04,0.04],"glossinessFactor":0.4}"#),
        ],
    );
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
    let (gold, plastic) = (&m.materials[0], &m.materials[1]);
    assert!(gold.metallic > 0.99, "{}", gold.metallic);
    assert!((gold.roughness - 0.2).abs() < 1e-6);
    assert!((gold.base_color[1] - 0.77).abs() < 0.02 && (gold.base_color[2] - 0.34).abs() < 0.02);
    assert_eq!(plastic.metallic, 0.0);
    assert!((plastic.roughness - 0.6).abs() < 1e-6);
    assert!((plastic.base_color[0] - 0.8).abs() < 1e-3 && plastic.base_color[3] == 0.5);
    assert!(gold.base_color_texture.is_none() && gold.metallic_roughness_texture.is_none());
}

#[test]
fn textures_are_converted_texel_by_texel() {
    let m = model(
        "textures",
        &[&ext(
            r#"{"diffuseTexture":{"index":0},"specularGlossinessTexture":{"index":1}}"#,
        )],
    );
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
    let material = &m.materials[0];
    // Two images baked and added to the file's two.
    assert_eq!(m.images.len(), 4);
    let mr = &m.images[material.metallic_roughness_texture.expect("baked").image];
    let base = &m.images[material.base_color_texture.expect("baked").image];
    assert_eq!((material.metallic, material.roughness), (1.0, 1.0));
    // The glossy dielectric texel: roughness 0.1, not metallic, its diffuse red; the rough gold
    // one: roughness 0.8, metallic, gold.
    assert_eq!((mr.rgba8[1], mr.rgba8[2]), (25, 0));
    assert!(mr.rgba8[5] == 204 && mr.rgba8[6] > 250, "{:?}", mr.rgba8);
    assert!(base.rgba8[0] >= 198 && base.rgba8[1] <= 60, "{:?}", base.rgba8);
    assert!(
        base.rgba8[4] > 245 && base.rgba8[5] > 210 && base.rgba8[6] < 180,
        "{:?}",
        base.rgba8
    );
}

#[test]
fn a_malformed_extension_is_ignored_with_a_warning() {
    let m = model("malformed", &[&ext(r#"{"diffuseFactor":"red"}"#)]);
    assert_eq!(m.primitives.len(), 1);
    assert!(
        m.warnings
            .iter()
            .any(|w| w.contains("KHR_materials_pbrSpecularGlossiness ignored")),
        "{:?}",
        m.warnings
    );
}
