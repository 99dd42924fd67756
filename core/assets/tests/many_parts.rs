//! Files of many parts (a CAD export, a kit of pieces): thousands of nodes, each a small mesh.
//! They load within the phone's budget of draw calls, their small parts of one material joined
//! (`model::join`), every triangle where the file puts it.

use std::path::PathBuf;

use base64::Engine as _;
use phantogram_assets::budget::ResourceBudget;
use phantogram_assets::model::{Model, load_gltf_within};
use phantogram_testkit::Scratch;

/// A closed box of 12 triangles, corners at 0 and 1.
fn box_bin() -> Vec<u8> {
    let corners: Vec<[f32; 3]> = (0..8)
        .map(|i| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32])
        .collect();
    let indices: [u16; 36] = [
        0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5,
    ];
    let mut bin: Vec<u8> = corners.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    bin
}

/// `parts` boxes of 1 mm on a grid, 2 mm apart, part k of material k mod `materials` (each
/// material its own mesh, as exporters write them).
fn many_parts(dir: &Scratch, parts: usize, materials: usize) -> PathBuf {
    let bin = box_bin();
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bin)
    );
    let meshes: Vec<String> = (0..materials)
        .map(|m| format!(r#"{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1,"material":{m}}}]}}"#))
        .collect();
    let mats: Vec<String> = (0..materials)
        .map(|m| {
            format!(
                r#"{{"pbrMetallicRoughness":{{"baseColorFactor":[{},0.5,0.5,1]}}}}"#,
                m as f32 / materials as f32
            )
        })
        .collect();
    let side = (parts as f64).cbrt().ceil() as usize;
    let nodes: Vec<String> = (0..parts)
        .map(|k| {
            let [x, y, z] = [k % side, (k / side) % side, k / (side * side)].map(|c| c as f32 * 0.002);
            format!(
                r#"{{"mesh":{},"translation":[{x},{y},{z}],"scale":[0.001,0.001,0.001]}}"#,
                k % materials
            )
        })
        .collect();
    let roots: Vec<String> = (0..parts).map(|k| k.to_string()).collect();
    let text = format!(
        r#"{{"asset":{{"version":"2.0"}},
        "buffers":[{{"byteLength":{len},"uri":"{uri}"}}],
        "bufferViews":[{{"buffer":0,"byteLength":96}},{{"buffer":0,"byteOffset":96,"byteLength":72}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":8,"type":"VEC3","min":[0,0,0],"max":[1,1,1]}},
                     {{"bufferView":1,"componentType":5123,"count":36,"type":"SCALAR"}}],
        "meshes":[{meshes}],"materials":[{mats}],
        "nodes":[{nodes}],"scenes":[{{"nodes":[{roots}]}}],"scene":0}}"#,
        len = bin.len(),
        meshes = meshes.join(","),
        mats = mats.join(","),
        nodes = nodes.join(","),
        roots = roots.join(",")
    );
    let path = dir.join(format!("parts-{parts}.gltf"));
    std::fs::write(&path, text).unwrap();
    path
}

/// Each box's lowest corner, sorted: where the file put the parts.
fn box_corners(model: &Model) -> Vec<[i32; 3]> {
    let mut corners: Vec<[i32; 3]> = model
        .primitives
        .iter()
        .flat_map(|p| {
            p.mesh.vertices.chunks(8).map(|v| {
                v.iter().fold([i32::MAX; 3], |lo, v| {
                    let mm = v.position.map(|c| (c * 1000.0).round() as i32);
                    [lo[0].min(mm[0]), lo[1].min(mm[1]), lo[2].min(mm[2])]
                })
            })
        })
        .collect();
    corners.sort_unstable();
    corners
}

#[test]
fn twenty_thousand_parts_are_drawn_in_a_few_calls() {
    let dir = Scratch::new("many-parts");
    let path = many_parts(&dir, 20_000, 8);
    // Was refused: 20 000 primitives against the phone's 4096 draws.
    let model = load_gltf_within(&path, ResourceBudget::PHONE).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(model.triangle_count(), 20_000 * 12);
    // 2 500 boxes a material, 30 000 triangles: one draw each.
    assert_eq!(model.primitives.len(), 8);
    let mut materials: Vec<usize> = model.primitives.iter().map(|p| p.material).collect();
    materials.sort_unstable();
    assert_eq!(materials, (0..8).collect::<Vec<_>>());
    // Every box is where its node put it (the vertices of a box are its 8 corners, unwelded).
    let side = 28; // ⌈20 000^⅓⌉
    let mut expected: Vec<[i32; 3]> = (0..20_000)
        .map(|k| [k % side, (k / side) % side, k / (side * side)].map(|c| c * 2))
        .collect();
    expected.sort_unstable();
    assert_eq!(box_corners(&model), expected);
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
}

#[test]
fn more_parts_than_sixteen_per_draw_are_refused_while_read() {
    let dir = Scratch::new("too-many-parts");
    let path = many_parts(&dir, 65, 1);
    let budget = ResourceBudget {
        max_primitives: 4,
        ..ResourceBudget::PHONE
    };
    let err = load_gltf_within(&path, budget).unwrap_err().to_string();
    assert!(err.contains("65 primitives read, over the budget of 64"), "{err}");
    // 64 read are joined into one draw.
    let path = many_parts(&dir, 64, 1);
    let model = load_gltf_within(&path, budget).map(|m| m.primitives.len());
    assert_eq!(model.map_err(|e| e.to_string()), Ok(1));
}

#[test]
fn parts_that_cannot_be_joined_are_still_held_to_the_draw_budget() {
    // Five materials, one part each: five draws over a budget of four.
    let dir = Scratch::new("distinct-parts");
    let path = many_parts(&dir, 5, 5);
    let budget = ResourceBudget {
        max_primitives: 4,
        ..ResourceBudget::PHONE
    };
    let err = load_gltf_within(&path, budget).unwrap_err().to_string();
    assert!(err.contains("needs 5 drawn primitives, over the budget of 4"), "{err}");
}
