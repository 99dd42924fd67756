//! What a phone cannot draw as the file has it: images over its texture limit are scaled down
//! (with a warning) instead of failing; extensions the file only *uses* are named in warnings;
//! `KHR_materials_unlit` is read.

use base64::Engine as _;
use phantogram_assets::budget::ResourceBudget;
use phantogram_assets::model::load_gltf_within;
use phantogram_testkit::Scratch;

fn data_uri(mime: &str, bytes: &[u8]) -> String {
    format!(
        "data:{mime};base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bytes)
    )
}

/// One textured triangle: `image` as a PNG data URI, `material` and `extensions` spliced in.
fn textured_triangle(image: &[u8], material_extensions: &str, extensions_used: &str) -> String {
    let positions: Vec<u8> = [
        0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0,
    ]
    .iter()
    .flat_map(|v| v.to_le_bytes())
    .collect();
    format!(
        r#"{{"asset":{{"version":"2.0"}},{extensions_used}
        "buffers":[{{"byteLength":60,"uri":"{}"}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":24}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}},
                     {{"bufferView":1,"componentType":5126,"count":3,"type":"VEC2"}}],
        "images":[{{"uri":"{}"}}],"textures":[{{"source":0}}],
        "materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0}}}}{material_extensions}}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":1}},"material":0}}]}}],
        "nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}],"scene":0}}"#,
        data_uri("application/octet-stream", &positions),
        data_uri("image/png", image),
    )
}

/// A 64×32 PNG: left half red, right half blue.
fn two_colour_png() -> Vec<u8> {
    let img = image::RgbaImage::from_fn(64, 32, |x, _| {
        if x < 32 {
            image::Rgba([255, 0, 0, 255])
        } else {
            image::Rgba([0, 0, 255, 255])
        }
    });
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    png
}

#[test]
fn an_image_over_the_texture_limit_is_scaled_down_not_refused() {
    let dir = Scratch::new("device-limits-scale");
    let path = dir.join("big.gltf");
    std::fs::write(&path, textured_triangle(&two_colour_png(), "", "")).unwrap();
    let small_gpu = ResourceBudget {
        max_image_side_px: 16,
        ..ResourceBudget::PHONE
    };
    let model = load_gltf_within(&path, small_gpu).unwrap();
    let img = &model.images[0];
    assert_eq!((img.width, img.height), (16, 8));
    // The halves keep their colours (a texel of each side, away from the seam).
    assert_eq!(&img.rgba8[0..4], &[255, 0, 0, 255]);
    let right = ((16 - 1) * 4) as usize;
    assert_eq!(&img.rgba8[right..right + 4], &[0, 0, 255, 255]);
    assert!(
        model.warnings.iter().any(|w| w.contains("64×32") && w.contains("16×8")),
        "{:?}",
        model.warnings
    );
    // On a device that draws it as it is: untouched, no warning.
    let model = load_gltf_within(&path, ResourceBudget::PHONE).unwrap();
    assert_eq!((model.images[0].width, model.images[0].height), (64, 32));
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
}

#[test]
fn unlit_materials_are_read_and_extensions_only_used_are_named() {
    let dir = Scratch::new("device-limits-extensions");
    let path = dir.join("unlit.gltf");
    let text = textured_triangle(
        &two_colour_png(),
        r#","extensions":{"KHR_materials_unlit":{}}"#,
        r#""extensionsUsed":["KHR_materials_unlit","EXT_lights_image_based"],"#,
    );
    std::fs::write(&path, text).unwrap();
    let model = load_gltf_within(&path, ResourceBudget::PHONE).unwrap();
    assert!(model.materials[0].unlit);
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
    assert!(
        model.warnings[0].contains("EXT_lights_image_based"),
        "{:?}",
        model.warnings
    );
    // Without the extension, lit.
    let lit = dir.join("lit.gltf");
    std::fs::write(&lit, textured_triangle(&two_colour_png(), "", "")).unwrap();
    assert!(!load_gltf_within(&lit, ResourceBudget::PHONE).unwrap().materials[0].unlit);
}
