//! glTF loading on the models in `$PHANTOGRAM_DATA/models` (skipped with a notice without it),
//! and loader behaviour on small files made here.

use std::path::{Path, PathBuf};

use phantogram::glam::Vec3;
use phantogram::model::{LayerSlot, ModelError, load_gltf, load_model};
use phantogram::render::{Gpu, Renderer};
use phantogram::screen::Screen;
use phantogram::{Session, SessionConfig};
use phantogram_integration::{data_subdir, scratch};

fn models_dir() -> Option<PathBuf> {
    data_subdir("models")
}

fn gltf_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            gltf_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "gltf" || e == "glb") {
            out.push(p);
        }
    }
}

#[test]
fn every_shared_model_loads_and_renders() {
    let Some(dir) = models_dir() else { return };
    let mut files = Vec::new();
    gltf_files(&dir, &mut files);
    assert!(files.len() >= 15, "found {} models", files.len());
    let gpu = match Gpu::headless() {
        Ok(g) => Some(g),
        Err(e) if std::env::var_os("CI").is_none() => {
            eprintln!("no GPU ({e}): loading only");
            None
        }
        Err(e) => panic!("{e}"),
    };
    let mut renderer: Option<Renderer> = None;
    let mut gpu = gpu;
    let mut session = Session::new(SessionConfig::default()).unwrap();
    let view = session.frame().unwrap();
    let screen = Screen::default();
    for f in files {
        let name = f.strip_prefix(&dir).unwrap().display().to_string();
        let mut model = load_model(&f).unwrap_or_else(|e| panic!("{e}"));
        assert!(model.triangle_count() > 0, "{name}");
        model.fit_to_diorama(&screen, &Default::default());
        let b = model.bounds().unwrap();
        assert!(b.min.is_finite() && b.max.is_finite(), "{name}: {b:?}");
        println!(
            "{name}: {} triangles, {} materials, {} images{}",
            model.triangle_count(),
            model.materials.len(),
            model.images.len(),
            if model.warnings.is_empty() {
                String::new()
            } else {
                format!(" ({})", model.warnings.join("; "))
            }
        );
        let r = match (&mut renderer, gpu.take()) {
            (Some(r), _) => {
                r.set_model(&model).unwrap_or_else(|e| panic!("{name}: {e}"));
                r
            }
            (None, Some(g)) => renderer.insert(Renderer::new(g, &model).unwrap_or_else(|e| panic!("{name}: {e}"))),
            (None, None) => continue,
        };
        let pixels = r
            .render(
                &phantogram::engine::frame_input(&view, Vec3::ZERO),
                phantogram::anaglyph::Method::Mono,
                90,
                200,
            )
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let background = [pixels[0], pixels[1], pixels[2]];
        let drawn = pixels.chunks(4).filter(|p| p[..3] != background).count();
        assert!(drawn > 200, "{name}: only {drawn} pixels show the model");
    }
}

#[test]
fn draco_turtle_decodes_like_the_reference_decoder() {
    let Some(dir) = models_dir() else { return };
    let t = dir.join("heritage/smithsonian_nmnh_sea_turtle");
    for (draco, plain) in [
        (
            "sea_turtle-150k-1024-low.glb",
            "decoded/sea_turtle-150k-1024-low-nodraco.glb",
        ),
        ("sea_turtle-20k-thumb.glb", "decoded/sea_turtle-20k-thumb-nodraco.glb"),
    ] {
        let a = load_gltf(&t.join(draco)).unwrap();
        let b = load_gltf(&t.join(plain)).unwrap();
        assert_eq!(a.triangle_count(), b.triangle_count(), "{draco}");
        // Both in the file's own frame (load_gltf applies no Voyager orientation).
        let (ba, bb) = (a.bounds().unwrap(), b.bounds().unwrap());
        assert!(
            (ba.min - bb.min).length() < 1e-4 && (ba.max - bb.max).length() < 1e-4,
            "{draco}: bounds {ba:?} vs {bb:?}"
        );
        assert_eq!(a.images.len(), b.images.len());
    }
}

#[test]
fn quantized_duck_matches_the_float_duck() {
    let Some(dir) = models_dir() else { return };
    let a = load_gltf(&dir.join("khronos/Duck/glTF-Binary/Duck.glb")).unwrap();
    let b = load_gltf(&dir.join("khronos/Duck/glTF-Quantized/Duck.gltf")).unwrap();
    assert_eq!(a.triangle_count(), b.triangle_count());
    let (ba, bb) = (a.bounds().unwrap(), b.bounds().unwrap());
    assert!(
        (ba.min - bb.min).length() < 0.05 && (ba.max - bb.max).length() < 0.05,
        "{ba:?} vs {bb:?}"
    );
    // KHR_texture_transform undoes the UV quantization: transformed UVs agree within a texel.
    let ta = a.materials[a.primitives[0].material].base_color_texture.unwrap();
    let tb = b.materials[b.primitives[0].material].base_color_texture.unwrap();
    // The quantized file reorders vertices: match each vertex to those at (nearly) the same
    // position and normal; at a UV seam several share a position, so take the best of them.
    let vb = &b.primitives[0].mesh.vertices;
    let size = (ba.max - ba.min).length();
    let mut worst = 0.0f32;
    for va in a.primitives[0].mesh.vertices.iter().step_by(7) {
        let pa = Vec3::from(va.position);
        let ua = ta.transform.apply([va.uv[0], va.uv[1]]);
        let best = vb
            .iter()
            .filter(|v| {
                pa.distance(Vec3::from(v.position)) < 2e-3 * size
                    && Vec3::from(v.normal).dot(Vec3::from(va.normal)) > 0.9
            })
            .map(|v| {
                let ub = tb.transform.apply([v.uv[0], v.uv[1]]);
                (ua[0] - ub[0]).abs().max((ua[1] - ub[1]).abs())
            })
            .fold(f32::INFINITY, f32::min);
        assert!(best.is_finite(), "no vertex of the quantized duck near {pa}");
        worst = worst.max(best);
    }
    assert!(worst < 2.0 / 512.0, "UVs differ by {worst}");
}

/// A minimal glTF with one triangle; `extra` is spliced into the top-level object.
fn tiny_gltf(dir: &Path, name: &str, extra: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, tiny_gltf_json(extra)).unwrap();
    path
}

/// The text of [`tiny_gltf`].
fn tiny_gltf_json(extra: &str) -> String {
    // Three positions: (0,0,0), (1,0,0), (0,1,0) as little-endian f32.
    let mut bin = Vec::new();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bin.extend_from_slice(&v.to_le_bytes());
    }
    let uri = format!("data:application/octet-stream;base64,{}", base64_encode(&bin));
    format!(
        r#"{{"asset":{{"version":"2.0"}}{extra},
        "buffers":[{{"byteLength":36,"uri":"{uri}"}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
        "nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}],"scene":0}}"#
    )
}

/// A `size`×`size` PNG of one colour as a data URI, for hand-written glTF files.
fn png_data_uri(size: u32, rgba: [u8; 4]) -> String {
    let mut png = Vec::new();
    image::RgbaImage::from_pixel(size, size, image::Rgba(rgba))
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    format!("data:image/png;base64,{}", base64_encode(&png))
}

fn base64_encode(bytes: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                s.push(T[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

#[test]
fn loader_reads_a_minimal_file_and_names_unsupported_extensions() {
    let dir = scratch("gltf");
    let ok = load_gltf(&tiny_gltf(&dir, "tri.gltf", "")).unwrap();
    assert_eq!(ok.triangle_count(), 1);
    // No normals in the file: computed, facing +z.
    assert_eq!(ok.primitives[0].mesh.vertices[0].normal, [0.0, 0.0, 1.0]);

    let needs = tiny_gltf(
        &dir,
        "volume-scatter.gltf",
        r#","extensionsUsed":["KHR_materials_volume_scatter"],"extensionsRequired":["KHR_materials_volume_scatter"]"#,
    );
    match load_gltf(&needs) {
        Err(ModelError::UnsupportedExtension { name, .. }) => assert_eq!(name, "KHR_materials_volume_scatter"),
        other => panic!("expected an unsupported-extension error, got {other:?}"),
    }
    // Merely *used* (optional) extensions are fine.
    let optional = tiny_gltf(
        &dir,
        "optional.gltf",
        r#","extensionsUsed":["KHR_materials_volume_scatter"]"#,
    );
    assert!(load_gltf(&optional).is_ok());

    let broken = dir.join("broken.gltf");
    std::fs::write(&broken, "{ not json").unwrap();
    assert!(matches!(load_gltf(&broken), Err(ModelError::Parse { .. })));
    assert!(matches!(
        load_gltf(&dir.join("missing.glb")),
        Err(ModelError::Io { .. })
    ));
    let text = load_gltf(&needs).unwrap_err().to_string();
    assert!(
        text.contains("volume-scatter.gltf") && text.contains("KHR_materials_volume_scatter"),
        "{text}"
    );
}

/// Glass, gems, varnish, cloth, brushed metal and thin films: each material extension's factors
/// reach the material, and its textures too (each slot its own, with its coordinates; the
/// varnish's normal map with its scale), a texture that does not exist is reported, and a file
/// requiring them loads.
#[test]
fn material_extensions_reach_the_material() {
    let dir = scratch("gltf-layers");
    let image = png_data_uri(1, [255, 0, 0, 255]);
    let path = tiny_gltf(
        &dir,
        "amber.gltf",
        &format!(
            r#","extensionsUsed":["KHR_materials_transmission","KHR_materials_volume","KHR_materials_ior","KHR_materials_specular","KHR_materials_clearcoat","KHR_materials_sheen","KHR_materials_dispersion","KHR_materials_diffuse_transmission","KHR_materials_anisotropy","KHR_materials_iridescence"],
        "extensionsRequired":["KHR_materials_transmission","KHR_materials_sheen"],
        "images":[{{"uri":"{image}"}},{{"uri":"{image}"}}],"textures":[{{"source":0}},{{"source":1}}],
        "materials":[{{"name":"amber","extensions":{{
          "KHR_materials_transmission":{{"transmissionFactor":0.9,"transmissionTexture":{{"index":0,"texCoord":1}}}},
          "KHR_materials_volume":{{"thicknessFactor":0.02,"thicknessTexture":{{"index":0}},"attenuationDistance":0.05,"attenuationColor":[0.9,0.5,0.1]}},
          "KHR_materials_ior":{{"ior":1.54}},
          "KHR_materials_specular":{{"specularFactor":0.8,"specularColorFactor":[1,0.9,0.8],"specularTexture":{{"index":1}},"specularColorTexture":{{"index":0,"texCoord":1}}}},
          "KHR_materials_clearcoat":{{"clearcoatFactor":0.5,"clearcoatRoughnessFactor":0.1,"clearcoatTexture":{{"index":0}},"clearcoatRoughnessTexture":{{"index":1}},"clearcoatNormalTexture":{{"index":0,"scale":0.5}}}},
          "KHR_materials_sheen":{{"sheenColorFactor":[0.3,0.2,0.1],"sheenRoughnessFactor":0.6,"sheenColorTexture":{{"index":1,"texCoord":1}},"sheenRoughnessTexture":{{"index":0}}}},
          "KHR_materials_dispersion":{{"dispersion":0.4}},
          "KHR_materials_anisotropy":{{"anisotropyStrength":0.7,"anisotropyRotation":0.5,"anisotropyTexture":{{"index":1,"texCoord":1}}}},
          "KHR_materials_iridescence":{{"iridescenceFactor":0.9,"iridescenceIOR":1.6,"iridescenceThicknessMinimum":50,"iridescenceThicknessMaximum":650,"iridescenceTexture":{{"index":0}},"iridescenceThicknessTexture":{{"index":1}}}},
          "KHR_materials_diffuse_transmission":{{"diffuseTransmissionFactor":0.25,"diffuseTransmissionColorFactor":[1,0.5,0.5],"diffuseTransmissionTexture":{{"index":1}},"diffuseTransmissionColorTexture":{{"index":9}}}}}}}}]"#
        ),
    );
    let model = load_gltf(&path).unwrap();
    let amber = model
        .materials
        .iter()
        .find(|m| m.name == "amber")
        .expect("the amber material");
    let l = amber.layers;
    assert_eq!(
        (
            l.transmission,
            l.thickness,
            l.attenuation_distance,
            l.ior,
            l.specular,
            l.clear_coat,
            l.clear_coat_roughness
        ),
        (0.9, 0.02, 0.05, 1.54, 0.8, 0.5, 0.1)
    );
    assert_eq!(l.attenuation_color, [0.9, 0.5, 0.1]);
    assert_eq!(l.specular_color, [1.0, 0.9, 0.8]);
    assert_eq!((l.sheen_color, l.sheen_roughness), ([0.3, 0.2, 0.1], 0.6));
    assert_eq!(l.dispersion, 0.4);
    assert_eq!((l.anisotropy, l.anisotropy_rotation_rad), (0.7, 0.5));
    assert_eq!(
        (l.iridescence, l.iridescence_ior, l.iridescence_thickness_nm),
        (0.9, 1.6, [50.0, 650.0])
    );
    assert_eq!(
        (l.diffuse_transmission, l.diffuse_transmission_color),
        (0.25, [1.0, 0.5, 0.5])
    );
    // The transmission and thickness textures are read (which parts are glass, how thick), and
    // the layers' textures, each into its slot; a texture that does not exist is named (left
    // out).
    let texture = amber.transmission_texture.expect("the transmission texture");
    assert_eq!((texture.image, texture.tex_coord), (0, 1));
    let thickness = amber.thickness_texture.expect("the thickness texture");
    assert_eq!((thickness.image, thickness.tex_coord), (0, 0));
    let slot = |t: Option<phantogram::model::TextureRef>| t.map(|t| (t.image, t.tex_coord));
    let t = &amber.layer_textures;
    // In `LayerSlot::ALL`'s order: ClearCoat, ClearCoatRoughness, Specular, SpecularColor,
    // SheenColor, SheenRoughness, DiffuseTransmission, DiffuseTransmissionColor, ClearCoatNormal,
    // Anisotropy, Iridescence, IridescenceThickness.
    assert_eq!(
        LayerSlot::ALL.map(|s| slot(t.get(s))),
        [
            Some((0, 0)),
            Some((1, 0)),
            Some((1, 0)),
            Some((0, 1)),
            Some((1, 1)),
            Some((0, 0)),
            Some((1, 0)),
            None,
            Some((0, 0)),
            Some((1, 1)),
            Some((0, 0)),
            Some((1, 0)),
        ]
    );
    assert_eq!(t.clear_coat_normal_scale, 0.5);
    let named: Vec<&String> = model.warnings.iter().filter(|w| w.contains("amber")).collect();
    assert!(
        named.len() == 1 && named[0].contains("diffuseTransmissionColor"),
        "{:?}",
        model.warnings
    );
    // The plain triangle's default material has none of them.
    assert!(
        model
            .materials
            .iter()
            .filter(|m| m.name != "amber")
            .all(|m| m.layers == Default::default())
    );
}

/// A glass's thickness is in its mesh's units: a node that scales the mesh scales it too, in a
/// copy of the material where another node draws the same material at another scale.
#[test]
fn a_node_scales_the_volume_of_the_glass_it_places() {
    let dir = scratch("gltf-volume-scale");
    let json = tiny_gltf_json(
        r#","extensionsUsed":["KHR_materials_transmission","KHR_materials_volume"],
        "materials":[{"name":"glass","extensions":{
          "KHR_materials_transmission":{"transmissionFactor":1},
          "KHR_materials_volume":{"thicknessFactor":0.02,"attenuationDistance":0.1}}}]"#,
    )
    .replace(
        r#""attributes":{"POSITION":0}"#,
        r#""attributes":{"POSITION":0},"material":0"#,
    )
    .replace(
        r#""nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]"#,
        r#""nodes":[{"mesh":0,"scale":[0.5,0.5,0.5]},{"mesh":0,"translation":[2,0,0]}],"scenes":[{"nodes":[0,1]}]"#,
    );
    let path = dir.join("scaled.gltf");
    std::fs::write(&path, json).unwrap();
    let model = load_gltf(&path).unwrap();
    assert_eq!(model.primitives.len(), 2);
    let mut thicknesses: Vec<(f32, f32)> = model
        .primitives
        .iter()
        .map(|p| {
            let l = model.materials[p.material].layers;
            (l.thickness, l.attenuation_distance)
        })
        .collect();
    thicknesses.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert_eq!(thicknesses, [(0.01, 0.05), (0.02, 0.1)]);
}

/// `KHR_texture_transform` applies to every texture slot, normal and occlusion included (gltf-rs
/// types it only on the other slots' `textureInfo`); a malformed one is reported, not fatal.
#[test]
fn texture_transforms_reach_normal_and_occlusion_textures() {
    let dir = scratch("gltf-transform");
    let image = png_data_uri(1, [128, 128, 255, 255]);
    let materials = |occlusion_transform: &str| {
        format!(
            r#","extensionsUsed":["KHR_texture_transform"],
            "images":[{{"uri":"{image}"}},{{"uri":"{image}"}}],"textures":[{{"source":0}},{{"source":1}}],
            "materials":[{{"name":"relief",
              "normalTexture":{{"index":0,"scale":0.5,"extensions":{{"KHR_texture_transform":
                {{"offset":[0.25,0.5],"rotation":0.3,"scale":[2,3],"texCoord":1}}}}}},
              "occlusionTexture":{{"index":0,"strength":0.7,"extensions":{{"KHR_texture_transform":{occlusion_transform}}}}}}}]"#
        )
    };
    let model = load_gltf(&tiny_gltf(&dir, "relief.gltf", &materials(r#"{"scale":[4,4]}"#))).unwrap();
    let m = &model.materials[0];
    let (normal, scale) = m.normal_texture.unwrap();
    assert_eq!(scale, 0.5);
    assert_eq!(normal.tex_coord, 1);
    assert_eq!(normal.transform.offset, [0.25, 0.5]);
    assert_eq!(normal.transform.rotation_rad, 0.3);
    assert_eq!(normal.transform.scale, [2.0, 3.0]);
    let (occlusion, strength) = m.occlusion_texture.unwrap();
    assert_eq!(strength, 0.7);
    assert_eq!(occlusion.tex_coord, 0);
    assert_eq!(occlusion.transform.scale, [4.0, 4.0]);
    assert_eq!(occlusion.transform.offset, [0.0, 0.0]);
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);

    let bad = load_gltf(&tiny_gltf(&dir, "bad.gltf", &materials(r#"{"scale":"big"}"#))).unwrap();
    let (occlusion, _) = bad.materials[0].occlusion_texture.unwrap();
    assert_eq!(occlusion.transform.scale, [1.0, 1.0]);
    assert!(
        bad.warnings
            .iter()
            .any(|w| w.contains("relief") && w.contains("occlusion") && w.contains("KHR_texture_transform")),
        "{:?}",
        bad.warnings
    );
}

#[test]
fn generated_tangents_match_the_authors_on_the_mirrored_normal_map_test() {
    // Khronos's NormalTangentMirrorTest carries the tangents its normal maps were baked against,
    // mirrored UV islands included. Loaded with them hidden (renamed to an attribute the loader
    // does not read), the tangents the loader makes must be the same: before, every one of its
    // 2770 vertices came back with the opposite handedness (the maps' green channel upside down
    // on every model that does not carry tangents: most scans).
    let Some(dir) = models_dir() else { return };
    let path = dir.join("khronos/NormalTangentMirrorTest/glTF-Binary/NormalTangentMirrorTest.glb");
    let bytes = std::fs::read(&path).unwrap();
    let (json, rest) = split_glb(&bytes).expect("a GLB");
    let text = std::str::from_utf8(json).unwrap();
    assert!(text.contains("\"TANGENT\""), "the file carries tangents");
    // As a second colour set (the same accessor type, which the loader does not read): the
    // glTF crate refuses an application attribute's underscore name.
    let hidden = text.replace("\"TANGENT\"", "\"COLOR_1\"");
    let dir = scratch("tangents");
    let copy = dir.join("no-tangents.glb");
    std::fs::write(&copy, join_glb(hidden.as_bytes(), rest.unwrap_or_default())).unwrap();
    let authored = load_model(&path).unwrap();
    let made = load_model(&copy).unwrap();
    let mut compared = 0;
    let mut worst_cos = 1.0f32;
    let mut handedness_differs = 0;
    for (a, b) in authored.primitives.iter().zip(&made.primitives) {
        assert_eq!(a.mesh.vertices.len(), b.mesh.vertices.len());
        for (x, y) in a.mesh.vertices.iter().zip(&b.mesh.vertices) {
            let cos = Vec3::from_slice(&x.tangent[..3]).dot(Vec3::from_slice(&y.tangent[..3]));
            worst_cos = worst_cos.min(cos);
            handedness_differs += usize::from(x.tangent[3] != y.tangent[3]);
            compared += 1;
        }
    }
    println!("{compared} vertices: worst cosine {worst_cos:.4}, handedness differs at {handedness_differs}");
    assert!(compared > 2000, "{compared}");
    assert_eq!(handedness_differs, 0);
    assert!(worst_cos > 0.99, "{worst_cos}");
}

/// Damaged files fail with an error that says what is wrong, never a panic, a hang or an
/// allocation no phone can make. gltf-rs indexes its arrays unchecked, so before the loader
/// checked a document's structure itself the out-of-range indices here panicked, the cycle
/// looped forever and the huge count aborted the process.
#[test]
fn damaged_structure_is_an_error_not_a_panic() {
    let dir = scratch("gltf-damaged");
    let base = tiny_gltf_json("");
    // (file, text to replace, replacement, what the error must name)
    let cases = [
        (
            "cycle.gltf",
            r#""nodes":[{"mesh":0}]"#,
            r#""nodes":[{"mesh":0,"children":[0]}]"#,
            "node 0 is reached twice",
        ),
        (
            "two-parents.gltf",
            r#""nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]"#,
            r#""nodes":[{"children":[2]},{"children":[2]},{"mesh":0}],"scenes":[{"nodes":[0,1]}]"#,
            "node 2 is reached twice",
        ),
        (
            "child-missing.gltf",
            r#""nodes":[{"mesh":0}]"#,
            r#""nodes":[{"mesh":0,"children":[7]}]"#,
            "nodes[0].children[0]",
        ),
        (
            "scene-missing.gltf",
            r#""scene":0"#,
            r#""scene":3"#,
            "scene: Index out of bounds",
        ),
        (
            "material-missing.gltf",
            r#""attributes":{"POSITION":0}"#,
            r#""attributes":{"POSITION":0},"material":5"#,
            "meshes[0].primitives[0].material",
        ),
        (
            "position-missing.gltf",
            r#""POSITION":0"#,
            r#""POSITION":9"#,
            "accessor 9 does not exist",
        ),
        ("component-type.gltf", "5126", "5999", "accessors[0].componentType"),
        (
            "accessor-offset.gltf",
            r#""bufferView":0,"componentType""#,
            r#""bufferView":0,"byteOffset":18446744073709551615,"componentType""#,
            "accessor 0: extends past the end",
        ),
        (
            "view-offset.gltf",
            r#""buffer":0,"byteLength":36"#,
            r#""buffer":0,"byteOffset":18446744073709551615,"byteLength":36"#,
            "bufferView 0: extends past the end",
        ),
        (
            "stride.gltf",
            r#""buffer":0,"byteLength":36"#,
            r#""buffer":0,"byteLength":36,"byteStride":4"#,
            "byte stride smaller than one element",
        ),
        (
            "zeros-galore.gltf",
            r#""bufferView":0,"componentType":5126,"count":3"#,
            r#""componentType":5126,"count":4294967295"#,
            // Charged to the resource budget before anything is allocated.
            "ResourceBudget::memory_bytes",
        ),
    ];
    for (name, from, to, expected) in cases {
        assert!(base.contains(from), "{name}: the template lacks {from}");
        let path = dir.join(name);
        std::fs::write(&path, base.replace(from, to)).unwrap();
        match load_gltf(&path) {
            Ok(_) => panic!("{name}: loaded"),
            Err(e) => {
                let text = e.to_string();
                assert!(text.contains(name) && text.contains(expected), "{name}: {text}");
            }
        }
    }

    // Without a scene, the roots are the nodes that are nobody's child: the child is drawn
    // once, under its parent's transform.
    let path = dir.join("no-scene.gltf");
    let text = base.replace(
        r#""nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0"#,
        r#""nodes":[{"children":[1],"translation":[0,0,5]},{"mesh":0}]"#,
    );
    assert!(!text.contains("scene"));
    std::fs::write(&path, text).unwrap();
    let model = load_gltf(&path).unwrap();
    assert_eq!(model.triangle_count(), 1);
    assert!(model.primitives[0].mesh.vertices.iter().all(|v| v.position[2] == 5.0));
}

/// Every unsigned number in a glTF file's JSON replaced, one at a time, by a value a damaged or
/// hostile file could hold — small indices, 2³² − 1, 2⁶⁴ − 1 — and, in a GLB, bytes of the
/// binary chunk flipped: each copy loads or fails with an error, and none panics. On a small
/// textured file made here, and with `PHANTOGRAM_DATA` on Khronos' Box as GLB and as Draco.
#[test]
fn mutated_files_load_or_fail_without_panicking() {
    let dir = scratch("gltf-mutants");
    let image = png_data_uri(2, [200, 100, 50, 255]);
    let textured = tiny_gltf_json(&format!(
        r#","images":[{{"uri":"{image}"}}],"samplers":[{{"magFilter":9729}}],"textures":[{{"source":0,"sampler":0}}],
        "materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0}}}},"normalTexture":{{"index":0}}}}]"#
    ))
    .replace(
        r#""attributes":{"POSITION":0}"#,
        r#""attributes":{"POSITION":0},"material":0"#,
    );
    let mut files = vec![("tiny.gltf".to_owned(), textured.into_bytes(), None)];
    if let Some(models) = models_dir() {
        for (name, rel) in [
            ("Box.glb", "khronos/Box/glTF-Binary/Box.glb"),
            ("Box.gltf", "khronos/Box/glTF-Draco/Box.gltf"),
        ] {
            let path = models.join(rel);
            let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            files.push((name.to_owned(), bytes, path.parent().map(Path::to_path_buf)));
        }
    }
    let mut failures = Vec::new();
    let mut tried = 0;
    for (name, bytes, siblings) in files {
        // External buffers (the Draco Box's .bin) sit beside the copy as they did beside the original.
        if let Some(from) = siblings {
            for entry in std::fs::read_dir(&from).unwrap() {
                let entry = entry.unwrap();
                if entry.path().extension().is_some_and(|e| e == "bin") {
                    std::fs::copy(entry.path(), dir.join(entry.file_name())).unwrap();
                }
            }
        }
        let copy = dir.join(&name);
        let mut check = |mutant: &[u8], what: String| {
            std::fs::write(&copy, mutant).unwrap();
            tried += 1;
            if std::panic::catch_unwind(|| load_gltf(&copy)).is_err() {
                failures.push(format!("{name}: {what}"));
            }
        };
        let (json, rest) = split_glb(&bytes).unwrap_or((&bytes[..], None));
        for (at, mutant_json) in number_mutants(json) {
            let mutant = match rest {
                Some(bin) => join_glb(&mutant_json, bin),
                None => mutant_json.clone(),
            };
            check(
                &mutant,
                format!(
                    "number at byte {at} → {}",
                    String::from_utf8_lossy(&mutant_json[at..at + 20.min(mutant_json.len() - at)])
                ),
            );
        }
        if let Some(bin) = rest {
            let mut seed = 0x9E37_79B9_7F4A_7C15u64;
            for k in 0..300 {
                let mut flipped = bin.to_vec();
                for _ in 0..1 + k % 8 {
                    seed = seed
                        .wrapping_mul(6_364_136_223_846_793_005)
                        .wrapping_add(1_442_695_040_888_963_407);
                    // Past the chunk's own 8-byte header.
                    let at = 8 + (seed >> 33) as usize % (flipped.len() - 8);
                    flipped[at] ^= (seed >> 20) as u8 | 1;
                }
                check(&join_glb(json, &flipped), format!("binary chunk, mutant {k}"));
            }
        }
    }
    assert!(tried > 150, "only {tried} mutants");
    assert!(
        failures.is_empty(),
        "{} of {tried} mutants panicked:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// A GLB's JSON chunk content and everything after it (the binary chunk with its header), or
/// None for a text file.
fn split_glb(bytes: &[u8]) -> Option<(&[u8], Option<&[u8]>)> {
    if bytes.len() < 20 || &bytes[..4] != b"glTF" {
        return None;
    }
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().ok()?) as usize;
    let json = bytes.get(20..20 + json_len)?;
    Some((json, Some(&bytes[20 + json_len..])))
}

/// A GLB with this JSON (padded with spaces to 4 bytes, as the format asks) and these chunks after it.
fn join_glb(json: &[u8], rest: &[u8]) -> Vec<u8> {
    let mut json = json.to_vec();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + rest.len();
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(rest);
    out
}

/// Copies of `json` with one unsigned integer (not part of a decimal, exponent or string of
/// base64) replaced by each of a few extreme values, with the byte where it starts.
fn number_mutants(json: &[u8]) -> Vec<(usize, Vec<u8>)> {
    const VALUES: [&str; 9] = [
        "0",
        "1",
        "2",
        "3",
        "7",
        "999",
        "4294967295",
        "4294967296",
        "18446744073709551615",
    ];
    let mut out = Vec::new();
    let mut in_string = false;
    let mut i = 0;
    while i < json.len() {
        let c = json[i];
        if c == b'"' {
            in_string = !in_string;
        }
        let starts = !in_string
            && c.is_ascii_digit()
            && !matches!(
                json.get(i.wrapping_sub(1)),
                Some(b'.' | b'-' | b'e' | b'E' | b'0'..=b'9')
            );
        if !starts {
            i += 1;
            continue;
        }
        let end = i + json[i..].iter().take_while(|b| b.is_ascii_digit()).count();
        if json.get(end).is_some_and(|b| matches!(b, b'.' | b'e' | b'E')) {
            i = end;
            continue;
        }
        for v in VALUES {
            let mut m = json[..i].to_vec();
            m.extend_from_slice(v.as_bytes());
            m.extend_from_slice(&json[end..]);
            out.push((i, m));
        }
        i = end;
    }
    out
}

/// Images decode in parallel, yet a broken one is still reported by its place in the file.
#[test]
fn a_broken_image_is_named_in_the_error() {
    let dir = scratch("gltf-images");
    let good = png_data_uri(2, [10, 20, 30, 255]);
    let bad = format!("data:image/png;base64,{}", base64_encode(b"not a png at all"));
    let images = |second: &str| format!(r#","images":[{{"uri":"{good}"}},{{"uri":"{second}"}},{{"uri":"{good}"}}]"#);
    let model = load_gltf(&tiny_gltf(&dir, "three.gltf", &images(&good))).unwrap();
    assert_eq!(model.images.len(), 3);
    assert!(model.images.iter().all(|i| i.rgba8[..4] == [10, 20, 30, 255]));
    match load_gltf(&tiny_gltf(&dir, "broken-image.gltf", &images(&bad))) {
        Err(ModelError::Data { what, .. }) => assert!(what.starts_with("image 1"), "{what}"),
        other => panic!("expected a data error naming image 1, got {other:?}"),
    }
    // A decodable image of a kind glTF does not allow (a Radiance HDR) is refused by name: the
    // HDR and EXR decoders are there for environments, not for what a model file carries.
    let hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n\x80\x80\x80\x81\x80\x80\x80\x81";
    assert!(image::load_from_memory(hdr).is_ok(), "the HDR itself decodes");
    let hdr = format!("data:image/png;base64,{}", base64_encode(hdr));
    match load_gltf(&tiny_gltf(&dir, "hdr-image.gltf", &images(&hdr))) {
        Err(ModelError::Data { what, message, .. }) => {
            assert!(what.starts_with("image 1"), "{what}");
            assert!(
                message.contains("Hdr data; glTF images must be PNG, JPEG, WebP or KTX 2.0"),
                "{message}"
            );
        }
        other => panic!("expected a data error naming image 1, got {other:?}"),
    }
}

#[test]
fn every_shared_environment_map_loads_into_finite_irradiance() {
    let Some(dir) = data_subdir("env") else {
        return;
    };
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if !path.extension().is_some_and(|e| e == "hdr" || e == "exr") {
            continue;
        }
        let env = phantogram::ibl::Environment::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let sh = phantogram::ibl::IrradianceSh::from_environment(&env);
        let up = sh.irradiance(Vec3::Z);
        println!(
            "{}: {}x{}, irradiance from above {up:?}",
            path.display(),
            env.width,
            env.height
        );
        assert!(
            up.iter().all(|c| c.is_finite() && *c > 0.0),
            "{}: {up:?}",
            path.display()
        );
        n += 1;
    }
    assert!(n >= 9, "found {n} environment maps");
}

/// Where the pixel data of a single-part EXR starts: past the header's attributes (each
/// `name\0type\0size value`, ended by an empty name) and the offset table. `None` if the bytes
/// do not parse that far.
fn exr_first_chunk(bytes: &[u8]) -> Option<usize> {
    let mut at = 8; // magic number and version
    loop {
        let name_end = at + bytes.get(at..)?.iter().position(|&b| b == 0)?;
        if name_end == at {
            at += 1;
            break;
        }
        let type_end = name_end + 1 + bytes.get(name_end + 1..)?.iter().position(|&b| b == 0)?;
        let size = i32::from_le_bytes(bytes.get(type_end + 1..type_end + 5)?.try_into().ok()?);
        at = type_end + 5 + usize::try_from(size).ok()?;
    }
    let first = u64::from_le_bytes(bytes.get(at..at + 8)?.try_into().ok()?);
    usize::try_from(first).ok()
}

/// A small RGB environment written by the `exr` crate with `compression`, in scan lines or tiles.
fn exr_environment(path: &Path, compression: exr::compression::Compression, blocks: exr::image::Blocks) {
    use exr::prelude::*;
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        (
            f16::from_f32(x as f32 / 64.0),
            f16::from_f32(y as f32 / 32.0),
            f16::from_f32(((x * 7 + y * 3) % 11) as f32 / 4.0),
        )
    });
    let encoding = Encoding {
        compression,
        blocks,
        line_order: LineOrder::Increasing,
    };
    Image::from_encoded_channels((64, 32), encoding, channels)
        .write()
        .to_file(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
}

#[test]
fn damaged_environment_maps_are_errors_not_aborts() {
    use exr::compression::Compression;
    use phantogram::ibl::Environment;
    let dir = scratch("exr-mutants");
    let mut files = Vec::new();
    let tiles = exr::image::Blocks::Tiles(exr::math::Vec2(16, 16));
    for (name, compression, blocks) in [
        ("none", Compression::Uncompressed, exr::image::Blocks::ScanLines),
        ("rle", Compression::RLE, exr::image::Blocks::ScanLines),
        ("zip", Compression::ZIP16, exr::image::Blocks::ScanLines),
        ("zips", Compression::ZIP1, exr::image::Blocks::ScanLines),
        ("piz", Compression::PIZ, exr::image::Blocks::ScanLines),
        ("pxr24", Compression::PXR24, exr::image::Blocks::ScanLines),
        ("b44", Compression::B44, exr::image::Blocks::ScanLines),
        ("dwaa", Compression::DWAA(None), exr::image::Blocks::ScanLines),
        ("dwab", Compression::DWAB(None), exr::image::Blocks::ScanLines),
        ("dwab-tiled", Compression::DWAB(None), tiles),
        ("piz-tiled", Compression::PIZ, tiles),
    ] {
        let path = dir.join(format!("{name}.exr"));
        exr_environment(&path, compression, blocks);
        // Each undamaged file loads, with its pixels (f16 holds these values exactly).
        let env = Environment::load(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!((env.width, env.height), (64, 32), "{name}");
        if !matches!(
            compression,
            Compression::B44 | Compression::DWAA(_) | Compression::DWAB(_)
        ) {
            // Texel (x 16, y 8): x/64, y/32, ((7x + 3y) mod 11)/4.
            assert_eq!(env.texels[8 * 64 + 16], [0.25, 0.25, 1.0], "{name}");
        }
        files.push((name.to_owned(), std::fs::read(&path).unwrap()));
    }
    if let Some(env) = data_subdir("env") {
        for entry in std::fs::read_dir(&env).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "exr" || e == "hdr") {
                let name = path.file_name().unwrap().to_string_lossy().into_owned();
                files.push((name, std::fs::read(&path).unwrap()));
            }
        }
    }

    // The two faults that aborted the process before `exr_guard`: a data window 2^26 pixels wide
    // (the image crate bounds memory by the display window only) and a DWA chunk whose AC
    // coefficient count is absurd (exr allocates it as told).
    let (_, dwab) = files.iter().find(|(n, _)| n == "dwab").unwrap();
    let window = dwab.windows(10).position(|w| w == b"dataWindow").unwrap() + 21; // past "box2i\0" and the size
    let mut wide = dwab.clone();
    wide[window + 11] = 0x05; // the high byte of x_max: 83 886 144 pixels wide
    let chunk = exr_first_chunk(dwab).unwrap();
    let mut counted = dwab.clone();
    let ac_count = chunk + 8 + 8 * 8; // past y and size, and eight counters
    counted[ac_count..ac_count + 8].copy_from_slice(&(1u64 << 40).to_le_bytes());
    for (bytes, expected) in [(wide, "data window"), (counted, "AC coefficient count")] {
        let path = dir.join("targeted.exr");
        std::fs::write(&path, bytes).unwrap();
        match Environment::load(&path) {
            Err(e) => assert!(e.to_string().contains(expected), "{e}"),
            Ok(_) => panic!("a damaged file loaded ({expected})"),
        }
    }

    // Random damage: bytes flipped in the header and the first chunk's counters (where sizes
    // live), anywhere, and truncation. A panic is caught and reported; an abort fails the binary.
    let mut failures = Vec::new();
    let mut tried = 0;
    let mut seed = 0x2545_F491_4F6C_DD1Du64;
    let mut next = || {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        seed >> 24
    };
    for (name, bytes) in &files {
        let ext = if name.ends_with(".hdr") { "hdr" } else { "exr" };
        let copy = dir.join(format!("mutant.{ext}"));
        let sizes = exr_first_chunk(bytes).map_or(400, |c| c + 8 + 11 * 8).min(bytes.len());
        for k in 0..120u64 {
            let mut mutant = bytes.clone();
            let span = if k % 3 == 2 { mutant.len() } else { sizes };
            for _ in 0..1 + k % 4 {
                let at = next() as usize % span;
                mutant[at] ^= next() as u8 | 1;
            }
            if k % 10 == 9 {
                mutant.truncate(next() as usize % mutant.len());
            }
            std::fs::write(&copy, &mutant).unwrap();
            tried += 1;
            let started = std::time::Instant::now();
            if std::panic::catch_unwind(|| Environment::load(&copy)).is_err() {
                failures.push(format!("{name} mutant {k}: panicked"));
            }
            // Not a timing assertion: a mutant that loops for minutes would be a hang.
            if started.elapsed().as_secs() > 30 {
                failures.push(format!("{name} mutant {k}: took {:?}", started.elapsed()));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {tried} mutants:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// A Voyager scene turns the scan it lists; a scene that is damaged, or lists other files, is
/// ignored rather than turning the model into NaNs.
#[test]
fn a_voyager_scene_orients_only_what_it_lists_and_only_when_sound() {
    use phantogram::model::voyager_rotation;
    let dir = scratch("voyager");
    let model = tiny_gltf(&dir, "scan.glb", "");
    let scene = |uri: &str, rotation: &str| {
        format!(r#"{{"models":[{{"rotation":{rotation},"derivatives":[{{"assets":[{{"uri":"{uri}"}}]}}]}}]}}"#)
    };
    let half = std::f32::consts::FRAC_1_SQRT_2;
    for (text, expected) in [
        // A quarter turn about x (w last, as Voyager writes it), stored not quite unit length.
        (
            scene("scan.glb", &format!("[{},0,0,{}]", 2.0 * half, 2.0 * half)),
            Some([half, 0.0, 0.0, half]),
        ),
        (scene("other.glb", "[0.7071,0,0,0.7071]"), None),
        (scene("scan.glb", "[1e300,0,0,1]"), None),
        (scene("scan.glb", "[0,0,0,0]"), None),
        (scene("scan.glb", "[0,0,1]"), None),
        (scene("scan.glb", r#""upright""#), None),
        ("{\"models\":[".to_owned(), None),
    ] {
        std::fs::write(dir.join("scene.svx.json"), &text).unwrap();
        let got = voyager_rotation(&model);
        match (got, expected) {
            (Some(q), Some([x, y, z, w])) => {
                assert!(
                    q.dot(phantogram::glam::Quat::from_xyzw(x, y, z, w)).abs() > 0.99999,
                    "{text}: {q:?}"
                )
            }
            (None, None) => {}
            _ => panic!("{text}: {got:?}, expected {expected:?}"),
        }
    }
}

/// A Voyager scene, or the folder holding one (as Smithsonian downloads come), loads the best
/// scan it lists that is present; what it cannot offer is said plainly.
#[test]
fn a_voyager_scene_or_its_folder_loads_its_best_scan_present() {
    use phantogram::model::{ModelError, voyager_scan};
    let dir = scratch("voyager-folder");
    let derivative = |quality: &str, uri: &str| {
        format!(r#"{{"usage":"Web3D","quality":"{quality}","assets":[{{"uri":"{uri}","type":"Model"}}]}}"#)
    };
    let scene = |derivatives: &[String]| {
        format!(
            r#"{{"asset":{{"type":"application/si-dpo-3d.document+json","version":"1.0"}},"models":[{{"derivatives":[{}]}}]}}"#,
            derivatives.join(",")
        )
    };
    for name in ["t-thumb.glb", "t-medium.glb", "t-low.glb"] {
        tiny_gltf(&dir, name, "");
    }
    std::fs::write(
        dir.join("scene.svx.json"),
        scene(&[
            derivative("Thumb", "t-thumb.glb"),
            derivative("High", "t-high.glb"), // listed, not downloaded
            derivative("Medium", "t-medium.glb"),
            derivative("Low", "t-low.glb"),
        ]),
    )
    .unwrap();
    assert_eq!(voyager_scan(&dir).unwrap(), dir.join("t-medium.glb"));
    for given in [dir.to_path_buf(), dir.join("scene.svx.json")] {
        let model = load_model(&given).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(model.name, "t-medium", "{}", given.display());
    }
    // A scene may only name files beside it; one that names nothing loadable is an error.
    std::fs::write(
        dir.join("scene.svx.json"),
        scene(&[derivative("High", "../t-medium.glb")]),
    )
    .unwrap();
    let err = load_model(&dir).unwrap_err();
    assert!(
        matches!(err, ModelError::NotAModel { .. }) && err.to_string().contains("lists no glTF scan"),
        "{err}"
    );
    std::fs::write(dir.join("scene.svx.json"), scene(&[derivative("High", "t-high.glb")])).unwrap();
    let err = load_model(&dir).unwrap_err().to_string();
    assert!(
        err.contains("none of the scans the Voyager scene lists is here (t-high.glb)"),
        "{err}"
    );
    // A folder without a scene, and glTF 1.0, are named for what they are.
    let empty = scratch("voyager-empty");
    let err = load_model(&empty).unwrap_err().to_string();
    assert!(err.contains("a folder without a Voyager scene"), "{err}");
    let old = dir.join("old.gltf");
    std::fs::write(&old, r#"{"asset":{"version":"1.0"},"meshes":{}}"#).unwrap();
    let err = load_model(&old).unwrap_err().to_string();
    assert!(
        err.contains("asset version \"1.0\"; this loader reads glTF 2.0"),
        "{err}"
    );
    let old_glb = dir.join("old.glb");
    let mut glb = b"glTF".to_vec();
    for word in [1u32, 20, 0, 0] {
        glb.extend_from_slice(&word.to_le_bytes());
    }
    std::fs::write(&old_glb, glb).unwrap();
    let err = load_model(&old_glb).unwrap_err().to_string();
    assert!(err.contains("GLB version 1; this loader reads glTF 2.0"), "{err}");

    // The Smithsonian sea turtle's download: High is not there, Medium is.
    if let Some(models) = models_dir() {
        let turtle = models.join("heritage/smithsonian_nmnh_sea_turtle");
        assert_eq!(
            voyager_scan(&turtle).unwrap(),
            turtle.join("sea_turtle-150k-2048-medium.glb")
        );
    }
}
