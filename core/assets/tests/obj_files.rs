//! Wavefront OBJ with MTL materials and textures, as museum download pages offer it: read with
//! its colour texture (coordinates flipped to glTF's top-left origin), its materials per object,
//! and nothing opened outside its folder. Before, OBJ was not read.

use std::io::Write;

use phantogram_assets::budget::ResourceBudget;
use phantogram_assets::library::Library;
use phantogram_assets::model::{AlphaMode, Model, ModelError, load_model};
use phantogram_assets::progress::Progress;
use phantogram_testkit::Scratch;

/// A 2 × 1 PNG: a red texel, then a blue one.
fn texture_png() -> Vec<u8> {
    let img = image::RgbaImage::from_fn(2, 1, |x, _| {
        if x == 0 {
            image::Rgba([255, 0, 0, 255])
        } else {
            image::Rgba([0, 0, 255, 255])
        }
    });
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .expect("encode");
    png
}

/// A unit quad facing +z (one polygon of four corners) textured by `texture`, and beside it a
/// triangle in a second object with a plain green, half-transparent material.
const OBJ: &str = "# a test scan\nmtllib scan.mtl\no quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nusemtl skin\nf 1/1/1 2/2/1 3/3/1 4/4/1\no label\nv 2 0 0\nv 3 0 0\nv 2 1 0\nusemtl paint\nf 5 6 7\n";
const MTL: &str = "newmtl skin\nKd 0.8 0.8 0.8\nmap_Kd -s 1 1 1 skin.png\nnewmtl paint\nKd 0 0.5 0\nd 0.5\n";

fn folder(test: &str, files: &[(&str, &[u8])]) -> Scratch {
    let dir = Scratch::new(&format!("obj-{test}"));
    for (name, bytes) in files {
        std::fs::write(dir.join(name), bytes).expect("write");
    }
    dir
}

fn load(dir: &Scratch) -> Result<Model, ModelError> {
    load_model(&dir.join("scan.obj"))
}

#[test]
fn an_obj_with_its_materials_and_texture_is_drawn_as_published() {
    let png = texture_png();
    let dir = folder(
        "full",
        &[
            ("scan.obj", OBJ.as_bytes()),
            ("scan.mtl", MTL.as_bytes()),
            ("skin.png", &png),
        ],
    );
    let model = load(&dir).expect("loads");
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    assert_eq!(model.primitives.len(), 2);
    assert_eq!(model.triangle_count(), 3, "the quad as two triangles, and the triangle");
    // The quad: textured, white (the texture gives the colour), opaque.
    let quad = &model.primitives[0];
    let skin = &model.materials[quad.material];
    let texture = skin.base_color_texture.expect("textured");
    assert_eq!(model.images[texture.image].rgba8[..4], [255, 0, 0, 255]);
    assert_eq!(skin.base_color, [1.0; 4]);
    assert_eq!(skin.alpha, AlphaMode::Opaque);
    // OBJ's (0, 0) is the image's bottom left, glTF's (0, 1).
    let corner = quad
        .mesh
        .vertices
        .iter()
        .find(|v| v.position == [0.0, 1.0, 0.0])
        .expect("corner");
    assert_eq!(&corner.uv[..2], &[0.0, 0.0]);
    assert_eq!(corner.normal, [0.0, 0.0, 1.0]);
    // The label: its own material, green and half transparent.
    let paint = &model.materials[model.primitives[1].material];
    assert_eq!(paint.base_color, [0.0, 0.5, 0.0, 0.5]);
    assert_eq!(paint.alpha, AlphaMode::Blend);
    assert!(paint.base_color_texture.is_none());
}

#[test]
fn what_is_missing_or_outside_the_folder_is_left_out_with_a_warning() {
    let dir = folder("outside", &[]);
    // A secret beside the folder, which the OBJ names.
    let secret = dir.join("../phantogram-obj-secret.mtl");
    std::fs::write(&secret, "newmtl skin\nKd 1 0 0\n").expect("write");
    let obj = OBJ.replace("mtllib scan.mtl", "mtllib ../phantogram-obj-secret.mtl");
    std::fs::write(dir.join("scan.obj"), obj).expect("write");
    let model = load(&dir).expect("loads without its materials");
    let _ = std::fs::remove_file(&secret);
    assert!(
        model.warnings.iter().any(|w| w.contains("material library")),
        "{:?}",
        model.warnings
    );
    assert!(
        model.materials.iter().all(|m| m.base_color != [1.0, 0.0, 0.0, 1.0]),
        "the file outside the folder was read"
    );
    // The library there, its texture not.
    let dir = folder(
        "no-texture",
        &[("scan.obj", OBJ.as_bytes()), ("scan.mtl", MTL.as_bytes())],
    );
    let model = load(&dir).expect("loads without its texture");
    assert!(
        model.warnings.iter().any(|w| w.contains("skin.png")),
        "{:?}",
        model.warnings
    );
    assert!(
        model.materials[model.primitives[0].material]
            .base_color_texture
            .is_none()
    );
}

#[test]
fn damaged_objs_are_named_errors() {
    for (text, expected) in [
        ("v 0 0 0\nv 1 0 0\nf 1 2 9\n", "out of bounds"),
        ("v 0 0 zero\n", "parse"),
    ] {
        let dir = folder("damaged", &[("scan.obj", text.as_bytes())]);
        match load(&dir) {
            Err(ModelError::Parse { format, message, .. }) => {
                assert!(
                    format == "OBJ" && message.contains(expected),
                    "{text}: {format} {message}"
                )
            }
            other => panic!("{text}: {other:?}"),
        }
    }
    let dir = folder("empty", &[("scan.obj", b"# nothing\nv 0 0 0\n")]);
    assert!(matches!(load(&dir), Err(ModelError::Empty { .. })));
}

#[test]
fn an_obj_zip_opened_from_bytes_is_kept_with_its_texture() {
    let png = texture_png();
    let mut zip = std::io::Cursor::new(Vec::new());
    {
        let mut w = zip::ZipWriter::new(&mut zip);
        for (name, bytes) in [
            ("scan/scan.obj", OBJ.as_bytes()),
            ("scan/scan.mtl", MTL.as_bytes()),
            ("scan/skin.png", &png[..]),
        ] {
            w.start_file(name, zip::write::SimpleFileOptions::default())
                .expect("zip");
            w.write_all(bytes).expect("zip");
        }
        w.finish().expect("zip");
    }
    let dir = Scratch::new("obj-library");
    let lib = Library::new(Some(dir.to_path_buf()), None);
    let imported = lib
        .import("scan.zip", &zip.into_inner(), ResourceBudget::PHONE, &Progress::new())
        .expect("imported");
    assert_eq!(imported.model.triangle_count(), 3);
    assert_eq!(imported.model.images.len(), 1);
    // And a bare OBJ, known by its content.
    let bare = lib
        .import("shared-file", OBJ.as_bytes(), ResourceBudget::PHONE, &Progress::new())
        .expect("imported");
    assert_eq!(bare.model.triangle_count(), 3);
}

/// A scan with vertex colours (`v x y z r g b`, 0–1, sRGB as MeshLab writes a PLY's 8-bit ones),
/// no MTL: the colours linear, as the PLY loader makes them.
#[test]
fn vertex_colours_are_read_as_srgb_like_a_plys() {
    let dir = folder(
        "vertex-colours",
        &[(
            "scan.obj",
            b"v 0 0 0 0.5 0.5 0.5\nv 1 0 0 1 0 0\nv 0 1 0 0 0 1\nf 1 2 3\n",
        )],
    );
    let model = load(&dir).expect("loads");
    let vertices = &model.primitives[0].mesh.vertices;
    let grey = vertices
        .iter()
        .find(|v| v.position == [0.0, 0.0, 0.0])
        .expect("first corner");
    assert!(
        (grey.color[0] - 0.2140).abs() < 1e-3,
        "sRGB 0.5 is linear 0.214: {:?}",
        grey.color
    );
    let red = vertices
        .iter()
        .find(|v| v.position == [1.0, 0.0, 0.0])
        .expect("second corner");
    assert_eq!(red.color, [1.0, 0.0, 0.0, 1.0]);
    // Over a white material, so they show as they are (not tinted by plaster's grey).
    assert_eq!(model.materials[model.primitives[0].material].base_color, [1.0; 4]);
}
