//! Hostile and careless glTF files, made here: each is an error naming the file and the reason,
//! never a panic, a read outside the model's folder, or gigabytes of memory.

use std::path::{Path, PathBuf};

use base64::Engine as _;
use phantogram_assets::budget::ResourceBudget;
use phantogram_assets::model::{ModelError, load_gltf, load_gltf_within, load_model};
use phantogram_testkit::Scratch;

fn b64(bytes: &[u8]) -> String {
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// Three positions of one triangle, little-endian f32.
fn triangle_bin(positions: [f32; 9]) -> Vec<u8> {
    positions.iter().flat_map(|v| v.to_le_bytes()).collect()
}

const TRIANGLE: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];

/// One triangle whose buffer is at `uri`; `extra` spliced into the top-level object.
fn gltf_with_buffer_uri(uri: &str, extra: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}}{extra},
        "buffers":[{{"byteLength":36,"uri":"{uri}"}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
        "nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}],"scene":0}}"#
    )
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn data_uri(bytes: &[u8]) -> String {
    format!("data:application/octet-stream;base64,{}", b64(bytes))
}

/// A model may read only files in its own folder: every way out is refused, and the error never
/// carries the foreign file's bytes.
#[test]
fn uris_are_followed_only_inside_the_models_folder() {
    let root = Scratch::new("hostile-uris");
    let model_dir = root.join("model");
    std::fs::create_dir_all(model_dir.join("sub")).unwrap();
    let secret = root.join("secret.bin");
    let mut secret_bytes = b"SECRET-PASSWORD-".repeat(3);
    secret_bytes.truncate(36);
    std::fs::write(&secret, &secret_bytes).unwrap();
    // Inside: plain, in a subfolder, `./`, percent-encoded space.
    std::fs::write(model_dir.join("tri.bin"), triangle_bin(TRIANGLE)).unwrap();
    std::fs::write(model_dir.join("sub/tri.bin"), triangle_bin(TRIANGLE)).unwrap();
    std::fs::write(model_dir.join("a b.bin"), triangle_bin(TRIANGLE)).unwrap();
    for uri in ["tri.bin", "sub/tri.bin", "./tri.bin", "sub/../tri.bin", "a%20b.bin"] {
        let path = write(&model_dir, "inside.gltf", &gltf_with_buffer_uri(uri, ""));
        let result = load_gltf(&path);
        if uri == "sub/../tri.bin" {
            // `..` is refused even where it would come back inside.
            assert!(result.is_err(), "{uri}");
        } else {
            assert_eq!(result.unwrap().triangle_count(), 1, "{uri}");
        }
    }
    #[cfg(unix)]
    std::os::unix::fs::symlink(&secret, model_dir.join("link.bin")).unwrap();
    let absolute = secret.display().to_string();
    let mut outside = vec![
        "../secret.bin".to_owned(),
        "%2e%2e/secret.bin".to_owned(),
        "%2E%2E%2Fsecret.bin".to_owned(),
        "sub/../../secret.bin".to_owned(),
        absolute.clone(),
        format!("file://{absolute}"),
        "/etc/passwd".to_owned(),
        "../../../../../../etc/passwd".to_owned(),
        "/dev/zero".to_owned(),
        "http://example.com/x.bin".to_owned(),
        // Bad percent-encoding and a multi-byte character after `%`: no panic.
        "%aé.bin".to_owned(),
        "%ff%fe.bin".to_owned(),
    ];
    if cfg!(unix) {
        outside.push("link.bin".to_owned());
    }
    for uri in &outside {
        let path = write(&model_dir, "outside.gltf", &gltf_with_buffer_uri(uri, ""));
        let err = load_gltf(&path).expect_err(uri).to_string();
        assert!(!err.contains("SECRET") && !err.contains("root:"), "{uri}: {err}");
        assert!(err.contains("outside.gltf"), "{uri}: {err}");
    }
    // The same for an image URI.
    let image = r#","images":[{"uri":"../secret.bin"}],"textures":[{"source":0}],"materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}]"#;
    let path = write(&model_dir, "image.gltf", &gltf_with_buffer_uri("tri.bin", image));
    let err = load_gltf(&path).unwrap_err().to_string();
    assert!(
        err.contains("leaves the model's folder") && !err.contains("SECRET"),
        "{err}"
    );
}

/// The model file itself must be a regular file: a FIFO would block the loader for ever.
#[cfg(unix)]
#[test]
fn a_pipe_or_a_device_is_not_a_model() {
    let dir = Scratch::new("hostile-fifo");
    let fifo = dir.join("model.glb");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if made.is_ok_and(|s| s.success()) {
        let err = load_model(&fifo).unwrap_err().to_string();
        assert!(err.contains("not a regular file"), "{err}");
    }
    let err = load_model(Path::new("/dev/zero")).unwrap_err().to_string();
    assert!(err.contains("not a regular file"), "{err}");
}

/// A few hundred bytes claiming gigabytes: an accessor without data of count 22 M used by four
/// primitives. Refused by the budget before anything is allocated.
#[test]
fn counts_without_data_are_charged_before_they_are_allocated() {
    let dir = Scratch::new("hostile-zero-filled");
    let text = r#"{"asset":{"version":"2.0"},
        "accessors":[{"componentType":5126,"count":22000000,"type":"VEC3"}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":0}},{"attributes":{"POSITION":0}},
                                 {"attributes":{"POSITION":0}},{"attributes":{"POSITION":0}}]}],
        "nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]}"#;
    let path = write(&dir, "zeros.gltf", text);
    assert!(std::fs::metadata(&path).unwrap().len() < 1000);
    match load_gltf(&path) {
        Err(ModelError::OverBudget { error, .. }) => {
            assert_eq!(error.limit_name, "ResourceBudget::memory_bytes");
            assert!(error.needed > ResourceBudget::PHONE.memory_bytes);
        }
        other => panic!("expected an over-budget error, got {other:?}"),
    }
}

fn png(size: u32) -> Vec<u8> {
    let mut png = Vec::new();
    image::RgbaImage::from_pixel(size, size, image::Rgba([200, 100, 50, 255]))
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    png
}

/// Twelve images naming one file are twelve textures: the budget counts each.
#[test]
fn every_image_is_charged_even_when_they_name_one_file() {
    let dir = Scratch::new("hostile-images");
    std::fs::write(dir.join("tri.bin"), triangle_bin(TRIANGLE)).unwrap();
    std::fs::write(dir.join("big.png"), png(512)).unwrap();
    let images: Vec<String> = (0..12).map(|_| r#"{"uri":"big.png"}"#.to_owned()).collect();
    let extra = format!(r#","images":[{}]"#, images.join(","));
    let path = write(&dir, "images.gltf", &gltf_with_buffer_uri("tri.bin", &extra));
    // 512² RGBA with mips is 1.33 MiB: a 4 MiB budget holds three of them.
    let budget = ResourceBudget {
        memory_bytes: 4 << 20,
        ..ResourceBudget::PHONE
    };
    let err = load_gltf_within(&path, budget).unwrap_err().to_string();
    assert!(err.contains("image 3") && err.contains("memory_bytes"), "{err}");
    // The phone budget holds them.
    assert_eq!(load_gltf(&path).unwrap().images.len(), 12);
}

/// A JPEG header claiming 23000 × 23000 pixels (209 bytes) is refused from its header.
#[test]
fn an_image_header_claiming_too_many_pixels_is_refused_before_decoding() {
    let dir = Scratch::new("hostile-jpeg");
    std::fs::write(dir.join("tri.bin"), triangle_bin(TRIANGLE)).unwrap();
    // Encode a real 8×8 JPEG, then patch its frame header (SOF0) to 23000 × 23000.
    let mut jpeg = Vec::new();
    image::RgbImage::from_pixel(8, 8, image::Rgb([1, 2, 3]))
        .write_to(&mut std::io::Cursor::new(&mut jpeg), image::ImageFormat::Jpeg)
        .unwrap();
    let sof = jpeg.windows(2).position(|w| w == [0xFF, 0xC0]).expect("a SOF0 marker");
    jpeg[sof + 5..sof + 7].copy_from_slice(&23000u16.to_be_bytes());
    jpeg[sof + 7..sof + 9].copy_from_slice(&23000u16.to_be_bytes());
    std::fs::write(dir.join("huge.jpg"), &jpeg).unwrap();
    let extra = r#","images":[{"uri":"huge.jpg"}]"#;
    let path = write(&dir, "jpeg.gltf", &gltf_with_buffer_uri("tri.bin", extra));
    let err = load_gltf(&path).unwrap_err().to_string();
    assert!(
        err.contains("23000×23000") && err.contains("MAX_DECODED_SIDE_PX"),
        "{err}"
    );
}

/// Instancing multiplies: forty nodes drawing one mesh are forty meshes in memory, and a
/// thousands-of-nodes tree is thousands of primitives to read (joined into few draws after).
#[test]
fn instances_and_nodes_are_charged_per_drawn_primitive() {
    let dir = Scratch::new("hostile-instances");
    // A 600-vertex triangle soup (as data: the values do not matter).
    let soup: Vec<f32> = (0..600 * 3).map(|i| (i % 7) as f32).collect();
    let bin: Vec<u8> = soup.iter().flat_map(|v| v.to_le_bytes()).collect();
    let nodes: Vec<String> = (0..40).map(|_| r#"{"mesh":0}"#.to_owned()).collect();
    let roots: Vec<String> = (0..40).map(|i| i.to_string()).collect();
    let text = format!(
        r#"{{"asset":{{"version":"2.0"}},
        "buffers":[{{"byteLength":{len},"uri":"{uri}"}}],
        "bufferViews":[{{"buffer":0,"byteLength":{len}}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":600,"type":"VEC3"}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
        "nodes":[{nodes}],"scenes":[{{"nodes":[{roots}]}}]}}"#,
        len = bin.len(),
        uri = data_uri(&bin),
        nodes = nodes.join(","),
        roots = roots.join(",")
    );
    let path = write(&dir, "instances.gltf", &text);
    // Each instance: 600 × (vertex + index) bytes; a budget for ten of them.
    let one = ResourceBudget::mesh_bytes(600, 600);
    let budget = ResourceBudget {
        memory_bytes: one * 10 + one / 2,
        ..ResourceBudget::PHONE
    };
    let err = load_gltf_within(&path, budget).unwrap_err().to_string();
    assert!(err.contains("memory_bytes") && err.contains("primitive 0"), "{err}");
    // The forty are read (each charged), then joined into one draw: one material, 8 000
    // triangles. A budget of two draws reads at most 32 primitives.
    let budget = ResourceBudget {
        max_primitives: 2,
        ..ResourceBudget::PHONE
    };
    let err = load_gltf_within(&path, budget).unwrap_err().to_string();
    assert!(
        err.contains("max_primitives") && err.contains("33 primitives read"),
        "{err}"
    );
    let model = load_gltf_within(
        &path,
        ResourceBudget {
            max_primitives: 3,
            ..ResourceBudget::PHONE
        },
    )
    .map_err(|e| e.to_string());
    let primitives = model.map(|m| (m.primitives.len(), m.triangle_count()));
    assert_eq!(primitives, Ok((1, 40 * 200)));
}

/// Attribute accessors of the wrong shape (a scalar or matrix `COLOR_0`, a scalar `POSITION`, a
/// `NORMAL` pointing at the index accessor), an empty sparse block, positions that are not
/// finite: errors naming the attribute, not a panic or a blank frame.
#[test]
fn wrong_shapes_and_non_finite_positions_are_errors() {
    let dir = Scratch::new("hostile-shapes");
    // Positions (36 bytes), then three u16 indices (6 bytes, padded to 8), then 48 bytes for a
    // four-component accessor of three elements.
    let mut bin = triangle_bin(TRIANGLE);
    bin.extend([0u8, 0, 1, 0, 2, 0, 0, 0]);
    bin.extend(std::iter::repeat_n(0u8, 48));
    let uri = data_uri(&bin);
    let doc = |accessor_1: &str, attributes: &str| {
        format!(
            r#"{{"asset":{{"version":"2.0"}},
            "buffers":[{{"byteLength":{len},"uri":"{uri}"}}],
            "bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}},
                           {{"buffer":0,"byteOffset":44,"byteLength":48}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}},
                         {{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}},
                         {accessor_1}],
            "meshes":[{{"primitives":[{{"attributes":{{{attributes}}},"indices":1}}]}}],
            "nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}]}}"#,
            len = bin.len()
        )
    };
    let float = |ty: &str| format!(r#"{{"bufferView":2,"componentType":5126,"count":3,"type":"{ty}"}}"#);
    let cases = [
        (doc(&float("SCALAR"), r#""POSITION":0,"COLOR_0":2"#), "COLOR_0"),
        (doc(&float("VEC2"), r#""POSITION":0,"COLOR_0":2"#), "COLOR_0"),
        (doc(&float("MAT2"), r#""POSITION":0,"COLOR_0":2"#), "COLOR_0"),
        (doc(&float("SCALAR"), r#""POSITION":2"#), "POSITION"),
        (doc(&float("VEC4"), r#""POSITION":0,"NORMAL":1"#), "NORMAL"),
        (
            doc(
                r#"{"componentType":5126,"count":3,"type":"VEC3","sparse":{"count":0,"indices":{"bufferView":1,"componentType":5123},"values":{"bufferView":2}}}"#,
                r#""POSITION":2"#,
            ),
            "sparse with a count of 0",
        ),
    ];
    for (i, (text, needle)) in cases.iter().enumerate() {
        let path = write(&dir, &format!("shape{i}.gltf"), text);
        let err = load_gltf(&path).expect_err(needle).to_string();
        assert!(err.contains(needle), "case {i}: {err}");
    }
    // The well-formed document loads (so the cases fail for their reason alone).
    let good = write(&dir, "good.gltf", &doc(&float("VEC4"), r#""POSITION":0,"COLOR_0":2"#));
    assert_eq!(load_gltf(&good).unwrap().triangle_count(), 1);

    for (name, positions, extra) in [
        ("nan", [f32::NAN, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], ""),
        ("inf", [0.0, f32::INFINITY, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], ""),
        ("huge", [3e38, 0.0, 0.0, -3e38, 0.0, 0.0, 0.0, 1.0, 0.0], ""),
        ("scaled", TRIANGLE, r#","nodes":[{"mesh":0,"scale":[1e30,1e30,1e30]}]"#),
    ] {
        let mut text = gltf_with_buffer_uri(&data_uri(&triangle_bin(positions)), "");
        if !extra.is_empty() {
            text = text.replace(r#""nodes":[{"mesh":0}],"#, &extra[1..].replace("]}]", "]}],"));
        }
        let path = write(&dir, &format!("{name}.gltf"), &text);
        let err = load_gltf(&path).expect_err(name).to_string();
        assert!(err.contains("not a finite position"), "{name}: {err}");
    }
}

/// A Voyager scene is named as one in its errors, whatever the download called it.
#[test]
fn a_damaged_voyager_scene_is_called_a_scene() {
    let dir = Scratch::new("hostile-svx");
    let path = write(&dir, "turtle.svx.json", "{ not json");
    let err = load_model(&path).unwrap_err().to_string();
    assert!(
        err.contains("not a valid Voyager scene") && !err.contains("glTF"),
        "{err}"
    );
}

/// Found by `cargo xtask fuzz gltf` in its first seconds: an image with a `bufferView` but no
/// `mimeType`, or with neither a `uri` nor a `bufferView`, panicked inside gltf-rs.
#[test]
fn an_image_without_its_required_fields_is_an_error() {
    let dir = Scratch::new("hostile-image-fields");
    std::fs::write(dir.join("tri.bin"), triangle_bin(TRIANGLE)).unwrap();
    for (image, needle) in [
        (r#"{"bufferView":0}"#, "without a mimeType"),
        (r#"{"name":"nothing"}"#, "neither a uri nor a bufferView"),
    ] {
        let extra = format!(
            r#","images":[{image}],"textures":[{{"source":0}}],"materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0}}}}}}]"#
        );
        let path = write(&dir, "image.gltf", &gltf_with_buffer_uri("tri.bin", &extra));
        let err = load_gltf(&path).unwrap_err().to_string();
        assert!(err.contains(needle), "{err}");
    }
}

/// A valid 16384 × 8192 HDR (here only its header) once failed with a bare "Memory limit
/// exceeded": the size is checked from the header and the message says what the limit is.
#[test]
fn an_oversized_environment_is_refused_by_its_header_with_the_limit() {
    use phantogram_assets::ibl::{Environment, MAX_WIDTH_PX};
    let dir = Scratch::new("hostile-hdr");
    let path = dir.join("big.hdr");
    let mut hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8192 +X 16384\n".to_vec();
    hdr.extend([2, 2, 64, 0]); // the first scanline's RLE header, then nothing
    std::fs::write(&path, &hdr).unwrap();
    let err = Environment::load(&path).unwrap_err().to_string();
    assert!(
        err.contains("16384×8192") && err.contains(&format!("{MAX_WIDTH_PX}×{}", MAX_WIDTH_PX / 2)),
        "{err}"
    );
    #[cfg(unix)]
    {
        let fifo = dir.join("sky.hdr");
        if std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .is_ok_and(|s| s.success())
        {
            let err = Environment::load(&fifo).unwrap_err().to_string();
            assert!(err.contains("not a regular file"), "{err}");
        }
    }
}

/// A file larger than the whole budget is refused by name, before it is read.
#[test]
fn a_file_larger_than_the_budget_is_refused_before_it_is_read() {
    let dir = Scratch::new("hostile-big-file");
    let path = write(
        &dir,
        "big.gltf",
        &format!(
            "{}{}",
            gltf_with_buffer_uri(&data_uri(&triangle_bin(TRIANGLE)), ""),
            " ".repeat(4096)
        ),
    );
    let budget = ResourceBudget {
        memory_bytes: 2048,
        ..ResourceBudget::PHONE
    };
    let err = load_gltf_within(&path, budget).unwrap_err().to_string();
    assert!(
        err.contains("the file needs") && err.contains("ResourceBudget::memory_bytes"),
        "{err}"
    );
}

/// The GPU's layer textures are arrays of one size: one 256² varnish map beside forty 1² sheen
/// colours (a few hundred bytes of JSON) would make forty-one 256² layers. What that takes beyond
/// the images is charged; when it does not fit, the layer textures are left out with a warning
/// and the artifact still opens.
#[test]
fn layer_texture_arrays_are_charged_and_left_out_when_they_do_not_fit() {
    let dir = Scratch::new("hostile-layer-arrays");
    std::fs::write(dir.join("tri.bin"), triangle_bin(TRIANGLE)).unwrap();
    std::fs::write(dir.join("big.png"), png(256)).unwrap();
    std::fs::write(dir.join("tiny.png"), png(1)).unwrap();
    let count = 40;
    let images: Vec<&str> = std::iter::once(r#"{"uri":"big.png"}"#)
        .chain((0..count).map(|_| r#"{"uri":"tiny.png"}"#))
        .collect();
    let textures: Vec<String> = (0..=count).map(|i| format!(r#"{{"source":{i}}}"#)).collect();
    let materials: Vec<String> = (1..=count)
        .map(|i| {
            format!(
                r#"{{"extensions":{{"KHR_materials_clearcoat":{{"clearcoatFactor":1,"clearcoatTexture":{{"index":0}}}},
                "KHR_materials_sheen":{{"sheenColorFactor":[1,1,1],"sheenColorTexture":{{"index":{i}}}}}}}}}"#
            )
        })
        .collect();
    let extra = format!(
        r#","extensionsUsed":["KHR_materials_clearcoat","KHR_materials_sheen"],"images":[{}],"textures":[{}],"materials":[{}]"#,
        images.join(","),
        textures.join(","),
        materials.join(",")
    );
    let text = gltf_with_buffer_uri("tri.bin", &extra).replace(
        r#""attributes":{"POSITION":0}"#,
        r#""attributes":{"POSITION":0},"material":0"#,
    );
    let path = write(&dir, "layers.gltf", &text);
    let layer = ResourceBudget::texture_bytes(256, 256);
    let has_layer_textures = |m: &phantogram_assets::model::Model| m.materials.iter().any(|m| m.layer_textures.any());

    // Room for them: kept, and counted in what the model takes.
    let roomy = ResourceBudget {
        memory_bytes: 64 << 20,
        ..ResourceBudget::PHONE
    };
    let model = load_gltf_within(&path, roomy).unwrap();
    assert!(has_layer_textures(&model));
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let bytes = phantogram_assets::budget::model_bytes(&model);
    assert!(
        bytes >= (count as u64 + 1) * layer && bytes <= roomy.memory_bytes,
        "{bytes}"
    );

    // 4 MiB holds the images (0.33 MiB) but not the 14 MiB of layers: left out, said, and the
    // model within its budget.
    let tight = ResourceBudget {
        memory_bytes: 4 << 20,
        ..ResourceBudget::PHONE
    };
    let model = load_gltf_within(&path, tight).unwrap();
    assert!(!has_layer_textures(&model));
    assert!(
        model
            .warnings
            .iter()
            .any(|w| w.contains("layer textures") && w.contains("memory_bytes") && w.contains("left out")),
        "{:?}",
        model.warnings
    );
    assert!(phantogram_assets::budget::model_bytes(&model) <= tight.memory_bytes);
    assert_eq!(model.triangle_count(), 1);
}
