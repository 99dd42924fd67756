//! Textures in KTX 2.0 with Basis Universal (`KHR_texture_basisu`), as gltfpack's `-tc` and
//! glTF-Transform's `etc1s`/`uastc` write them, often with no PNG or JPEG beside: transcoded and
//! drawn. The textures were made by the reference encoder from two PNGs (`tests/data/ktx2`,
//! whose README says how), and each test compares what the loader reads with the PNG it was made
//! from, within the codec's own loss.

use base64::Engine as _;
use phantogram_assets::budget::ResourceBudget;
use phantogram_assets::model::{Image, Model, ModelError, load_gltf, load_gltf_within};
use phantogram_testkit::Scratch;

const ETC1S: &[u8] = include_bytes!("data/ktx2/pattern-rgba-etc1s.ktx2");
const UASTC: &[u8] = include_bytes!("data/ktx2/pattern-rgb-uastc.ktx2");
const RGBA_PNG: &[u8] = include_bytes!("data/ktx2/pattern-rgba.png");
const RGB_PNG: &[u8] = include_bytes!("data/ktx2/pattern-rgb.png");

fn b64(bytes: &[u8]) -> String {
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// One textured triangle whose texture is `texture` (a JSON object) over `images` (JSON image
/// objects); `required` is spliced in after `extensionsUsed`. Image `i` of `blobs` is bufferView
/// `2 + i`.
fn gltf_with(texture: &str, images: &str, blobs: &[&[u8]], required: bool) -> String {
    let positions = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let uvs = [0.0f32, 0.0, 1.0, 0.0, 0.0, 1.0];
    let mut bin: Vec<u8> = positions.iter().chain(&uvs).flat_map(|v| v.to_le_bytes()).collect();
    let mut views = vec![
        r#"{"buffer":0,"byteLength":36}"#.to_owned(),
        r#"{"buffer":0,"byteOffset":36,"byteLength":24}"#.to_owned(),
    ];
    for blob in blobs {
        views.push(format!(
            r#"{{"buffer":0,"byteOffset":{},"byteLength":{}}}"#,
            bin.len(),
            blob.len()
        ));
        bin.extend_from_slice(blob);
    }
    format!(
        r#"{{"asset":{{"version":"2.0"}},
        "extensionsUsed":["KHR_texture_basisu"]{},
        "buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{}"}}],
        "bufferViews":[{}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}},
                     {{"bufferView":1,"componentType":5126,"count":3,"type":"VEC2"}}],
        "images":[{images}],
        "textures":[{texture}],
        "materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0}}}}}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":1}},"material":0}}]}}],
        "nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}],"scene":0}}"#,
        if required {
            r#","extensionsRequired":["KHR_texture_basisu"]"#
        } else {
            ""
        },
        bin.len(),
        b64(&bin),
        views.join(",")
    )
}

/// A file whose only texture is the KTX 2.0 `ktx2`, in a bufferView (as in a GLB).
fn basis_only(ktx2: &[u8]) -> String {
    gltf_with(
        r#"{"extensions":{"KHR_texture_basisu":{"source":0}}}"#,
        r#"{"bufferView":2,"mimeType":"image/ktx2"}"#,
        &[ktx2],
        true,
    )
}

fn write(test: &str, text: &str) -> (Scratch, std::path::PathBuf) {
    // A folder per test: tests run in parallel, and a scratch folder is its name's alone.
    let dir = Scratch::new(&format!("ktx2-{test}"));
    let path = dir.join("model.gltf");
    std::fs::write(&path, text).expect("write");
    (dir, path)
}

fn load(test: &str, text: &str) -> Result<Model, ModelError> {
    let (_dir, path) = write(test, text);
    load_gltf(&path)
}

fn png(bytes: &[u8]) -> image::RgbaImage {
    image::load_from_memory(bytes).expect("a test PNG").into_rgba8()
}

/// Peak signal-to-noise ratio of `channels` of `got` against `want`, in dB.
fn psnr(got: &Image, want: &image::RgbaImage, channels: std::ops::Range<usize>) -> f64 {
    assert_eq!((got.width, got.height), want.dimensions(), "size");
    let (mut sum, mut n) = (0.0f64, 0usize);
    for (g, w) in got.rgba8.chunks_exact(4).zip(want.as_raw().chunks_exact(4)) {
        for c in channels.clone() {
            sum += (f64::from(g[c]) - f64::from(w[c])).powi(2);
            n += 1;
        }
    }
    10.0 * (255.0f64.powi(2) / (sum / n as f64).max(1e-9)).log10()
}

#[test]
fn an_etc1s_texture_with_alpha_is_the_picture_it_was_made_from() {
    let model = load("etc1s", &basis_only(ETC1S)).expect("a file requiring KHR_texture_basisu loads");
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let material = &model.materials[model.primitives[0].material];
    assert_eq!(material.base_color_texture.as_ref().map(|t| t.image), Some(0));
    let want = png(RGBA_PNG);
    let (colour, alpha) = (psnr(&model.images[0], &want, 0..3), psnr(&model.images[0], &want, 3..4));
    println!("ETC1S: colour {colour:.1} dB, alpha {alpha:.1} dB");
    // The reference tool's own decode is 25.5 dB in colour (ETC1S is coarse); a picture read
    // upside down, mirrored or with its channels swapped is under 15 dB.
    assert!(colour > 24.0, "colour {colour:.1} dB");
    assert!(alpha > 30.0, "alpha {alpha:.1} dB");
}

#[test]
fn a_uastc_texture_under_zstandard_is_the_picture_it_was_made_from() {
    let model = load("uastc", &basis_only(UASTC)).expect("loads");
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let image = &model.images[0];
    assert_eq!(
        (image.width, image.height),
        (64, 48),
        "not square: a transposed read shows"
    );
    let colour = psnr(image, &png(RGB_PNG), 0..3);
    println!("UASTC: colour {colour:.1} dB");
    assert!(colour > 40.0, "colour {colour:.1} dB (the reference decode: 41.9 dB)");
    assert!(
        image.rgba8.chunks_exact(4).all(|t| t[3] == 255),
        "no alpha in the file: opaque"
    );
}

#[test]
fn a_damaged_ktx2_image_is_the_files_error_never_a_panic() {
    // Cut short anywhere, or with bytes flipped anywhere (a fixed pseudo-random walk): the load
    // either fails naming the image or, where the damage misses what is read, loads.
    let mut cases: Vec<Vec<u8>> = (1..40).map(|k| ETC1S[..ETC1S.len() * k / 40].to_vec()).collect();
    let mut state = 0x2545_f491_4f6c_dd1du64;
    for source in [ETC1S, UASTC] {
        for _ in 0..150 {
            let mut bytes = source.to_vec();
            for _ in 0..3 {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                let at = (state % bytes.len() as u64) as usize;
                bytes[at] ^= (state >> 32) as u8 | 1;
            }
            cases.push(bytes);
        }
    }
    let (_dir, path) = write("damaged", "");
    let mut refused = 0;
    for (i, bytes) in cases.iter().enumerate() {
        std::fs::write(&path, basis_only(bytes)).expect("write");
        match load_gltf(&path) {
            Ok(model) => {
                let image = &model.images[0];
                assert_eq!(
                    image.rgba8.len(),
                    image.width as usize * image.height as usize * 4,
                    "case {i}"
                );
            }
            Err(ModelError::Data { what, .. }) => {
                assert!(what.contains("image 0"), "case {i}: {what}");
                refused += 1;
            }
            // A damaged header that claims more texels than the device draws.
            Err(ModelError::OverBudget { error, .. }) => {
                assert!(error.what.contains("image 0"), "case {i}: {error}");
                refused += 1;
            }
            Err(other) => panic!("case {i}: {other}"),
        }
    }
    // Every cut short must be refused (39), and many flips with them.
    assert!(refused >= 39, "{refused} of {} refused", cases.len());
}

#[test]
fn with_a_png_fallback_beside_the_png_is_drawn() {
    // Image 0 is the PNG the texture's `source` names, image 1 the KTX 2.0 its extension names;
    // the PNG is the lossless copy, and every texture is uploaded as RGBA8 anyway.
    let text = gltf_with(
        r#"{"source":0,"extensions":{"KHR_texture_basisu":{"source":1}}}"#,
        r#"{"bufferView":2,"mimeType":"image/png"},{"bufferView":3,"mimeType":"image/ktx2"}"#,
        &[RGB_PNG, UASTC],
        false,
    );
    let model = load("fallback", &text).expect("loads");
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let material = &model.materials[model.primitives[0].material];
    let image = material.base_color_texture.as_ref().map(|t| t.image).expect("textured");
    assert_eq!(image, 0);
    assert_eq!(
        model.images[0].rgba8,
        png(RGB_PNG).into_raw(),
        "the PNG, texel for texel"
    );
}

#[test]
fn over_the_devices_texture_limit_the_files_own_mip_level_is_drawn() {
    let (_dir, path) = write("limit", &basis_only(ETC1S));
    let small_gpu = ResourceBudget {
        max_image_side_px: 32,
        ..ResourceBudget::default()
    };
    let model = load_gltf_within(&path, small_gpu).expect("scaled, not refused");
    let image = &model.images[0];
    assert_eq!((image.width, image.height), (32, 32));
    assert!(
        model.warnings.iter().any(|w| w.contains("scaled down to 32×32")),
        "{:?}",
        model.warnings
    );
    let half = image::imageops::resize(&png(RGBA_PNG), 32, 32, image::imageops::FilterType::Triangle);
    let colour = psnr(image, &half, 0..3);
    println!("ETC1S level 1 against the PNG halved: colour {colour:.1} dB");
    // 22.4 dB: the encoder halves with its own filter before compressing, and ETC1S's blocks
    // are twice as coarse against the picture at this size; upside down it is under 15 dB.
    assert!(colour > 20.0, "colour {colour:.1} dB");
}

#[test]
fn a_ktx2_image_index_out_of_range_is_the_files_error() {
    for source in ["1", "-1", "\"0\""] {
        let text = gltf_with(
            &format!(r#"{{"extensions":{{"KHR_texture_basisu":{{"source":{source}}}}}}}"#),
            r#"{"bufferView":2,"mimeType":"image/ktx2"}"#,
            &[UASTC],
            true,
        );
        let error = load("index", &text).expect_err(source).to_string();
        assert!(error.contains("KHR_texture_basisu.source"), "{source}: {error}");
    }
}
