//! Textures in WebP (`EXT_texture_webp`), as web tools (gltf-transform's `webp`, for one) write
//! them, often with no PNG or JPEG beside: the WebP image is decoded and drawn. A texture naming
//! no image we read loads without it and says so; a WebP image index out of range is the file's
//! error.

use base64::Engine as _;
use image::ImageEncoder;
use phantogram_assets::model::{ModelError, load_gltf};
use phantogram_testkit::Scratch;

/// 2 × 2 texels, each a different colour (one half transparent).
const TEXELS: [u8; 16] = [255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 128];

fn webp_bytes() -> Vec<u8> {
    let mut out = Vec::new();
    image::codecs::webp::WebPEncoder::new_lossless(&mut out)
        .write_image(&TEXELS, 2, 2, image::ExtendedColorType::Rgba8)
        .expect("encode");
    out
}

fn b64(bytes: &[u8]) -> String {
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// One textured triangle whose texture is `texture` (a JSON object) over one WebP image.
fn gltf_with_texture(texture: &str) -> String {
    let positions = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let uvs = [0.0f32, 0.0, 1.0, 0.0, 0.0, 1.0];
    let bin: Vec<u8> = positions.iter().chain(&uvs).flat_map(|v| v.to_le_bytes()).collect();
    format!(
        r#"{{"asset":{{"version":"2.0"}},
        "extensionsUsed":["EXT_texture_webp"],"extensionsRequired":["EXT_texture_webp"],
        "buffers":[{{"byteLength":60,"uri":"data:application/octet-stream;base64,{}"}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":24}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}},
                     {{"bufferView":1,"componentType":5126,"count":3,"type":"VEC2"}}],
        "images":[{{"uri":"data:image/webp;base64,{}"}}],
        "textures":[{texture}],
        "materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0}}}}}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":1}},"material":0}}]}}],
        "nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}],"scene":0}}"#,
        b64(&bin),
        b64(&webp_bytes())
    )
}

fn load(name: &str, text: &str) -> Result<phantogram_assets::model::Model, ModelError> {
    // A folder per file: tests run in parallel, and a scratch folder is its name's alone.
    let dir = Scratch::new(&format!("webp-{}", name.replace('.', "-")));
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write");
    load_gltf(&path)
}

#[test]
fn a_webp_only_texture_is_decoded_and_drawn() {
    let model = load(
        "webp.gltf",
        &gltf_with_texture(r#"{"extensions":{"EXT_texture_webp":{"source":0}}}"#),
    )
    .expect("a file requiring EXT_texture_webp loads");
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    assert_eq!(model.images.len(), 1);
    let image = &model.images[0];
    assert_eq!((image.width, image.height), (2, 2));
    assert_eq!(image.rgba8, TEXELS, "lossless WebP comes back texel for texel");
    let material = &model.materials[model.primitives[0].material];
    assert_eq!(material.base_color_texture.as_ref().map(|t| t.image), Some(0));
}

#[test]
fn a_texture_without_an_image_we_read_is_left_out_with_a_warning() {
    // Some other extension's image only: the triangle is drawn untextured.
    let model = load(
        "other.gltf",
        &gltf_with_texture(r#"{"extensions":{"EXT_texture_avif":{"source":0}}}"#),
    )
    .expect("loads");
    let material = &model.materials[model.primitives[0].material];
    assert!(material.base_color_texture.is_none());
    assert!(
        model
            .warnings
            .iter()
            .any(|w| w.contains("base colour texture") && w.contains("no image")),
        "{:?}",
        model.warnings
    );
}

#[test]
fn a_webp_image_index_out_of_range_is_the_files_error() {
    for source in ["1", "-1", "\"0\""] {
        let text = gltf_with_texture(&format!(
            r#"{{"extensions":{{"EXT_texture_webp":{{"source":{source}}}}}}}"#
        ));
        let error = load("bad.gltf", &text).expect_err(source).to_string();
        assert!(error.contains("EXT_texture_webp.source"), "{source}: {error}");
    }
}
