//! Every primitive mode glTF 2.0 allows, in one file made here (as Khronos's MeshPrimitiveModes
//! sample lays them out): triangle strips and fans are drawn as the triangles they stand for,
//! wound as the triangle list of the same surface; points are drawn as discs (a point cloud);
//! lines are not drawn, and say so.

use base64::Engine as _;
use glam::Vec3;
use phantogram_assets::model::{Model, load_gltf};
use phantogram_testkit::Scratch;

/// A file of six vertices across the z = 0 plane (0, 2, 4 along y = 0; 1, 3, 5 along y = 1) and
/// one mesh per `(mode, indices)` over them, each in its own node.
fn model_with(name: &str, sequences: &[(u32, Vec<u16>)]) -> Model {
    let positions: Vec<u8> = (0..6)
        .flat_map(|i| [(i / 2) as f32, (i % 2) as f32, 0.0])
        .flat_map(f32::to_le_bytes)
        .collect();
    let mut bin = positions.clone();
    let mut views = vec![format!(r#"{{"buffer":0,"byteLength":{}}}"#, positions.len())];
    let mut accessors =
        vec![r#"{"bufferView":0,"componentType":5126,"count":6,"type":"VEC3","min":[0,0,0],"max":[2,1,0]}"#.to_owned()];
    let mut meshes = Vec::new();
    for (k, (mode, indices)) in sequences.iter().enumerate() {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        views.push(format!(
            r#"{{"buffer":0,"byteOffset":{},"byteLength":{}}}"#,
            bin.len(),
            indices.len() * 2
        ));
        bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
        accessors.push(format!(
            r#"{{"bufferView":{},"componentType":5123,"count":{},"type":"SCALAR"}}"#,
            k + 1,
            indices.len()
        ));
        meshes.push(format!(
            r#"{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":{},"mode":{mode}}}]}}"#,
            k + 1
        ));
    }
    let nodes: Vec<String> = (0..meshes.len()).map(|k| format!(r#"{{"mesh":{k}}}"#)).collect();
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bin)
    );
    let gltf = format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":{},"uri":"{uri}"}}],
        "bufferViews":[{}],"accessors":[{}],"meshes":[{}],"nodes":[{}],
        "scenes":[{{"nodes":[{}]}}],"scene":0}}"#,
        bin.len(),
        views.join(","),
        accessors.join(","),
        meshes.join(","),
        nodes.join(","),
        (0..nodes.len()).map(|k| k.to_string()).collect::<Vec<_>>().join(",")
    );
    let dir = Scratch::new(&format!("primitive-modes-{name}"));
    let path = dir.join(format!("{name}.gltf"));
    std::fs::write(&path, gltf).expect("write");
    load_gltf(&path).expect("a valid file")
}

/// Each triangle's normal (unnormalised: twice its area long).
fn normals(mesh: &phantogram_assets::model::Mesh) -> Vec<Vec3> {
    mesh.indices
        .chunks(3)
        .map(|t| {
            let p = |k: usize| Vec3::from(mesh.vertices[t[k] as usize].position);
            (p(1) - p(0)).cross(p(2) - p(0))
        })
        .collect()
}

/// The strip's triangles in glTF's order, as a list: the surface the other modes must give.
fn strip_as_list() -> Vec<u16> {
    vec![0, 1, 2, 1, 3, 2, 2, 3, 4, 3, 5, 4]
}

#[test]
fn strips_and_fans_are_drawn_as_triangles_points_as_discs_and_lines_say_they_are_not() {
    let one = |name: &str, mode: u32, indices: Vec<u16>| {
        let model = model_with(name, &[(mode, indices)]);
        assert!(model.warnings.is_empty(), "{name}: {:?}", model.warnings);
        assert_eq!(model.primitives.len(), 1, "{name}");
        model.primitives[0].mesh.clone()
    };
    let list = one("list", 4, strip_as_list());
    let strip = one("strip", 5, vec![0, 1, 2, 3, 4, 5]);
    // A fan about vertex 2 (the middle of the lower edge) over 4, 5, 3, 1, 0: wound the other way
    // round from the list, as its vertices go.
    let fan = one("fan", 6, vec![2, 4, 5, 3, 1, 0]);
    // The strip is exactly the list.
    assert_eq!(strip.indices, list.indices);
    // The fan: four triangles covering the same 2 × 1 rectangle, every one wound the same way.
    let (list_n, fan_n) = (normals(&list), normals(&fan));
    assert_eq!(fan_n.len(), 4);
    let area = |n: &[Vec3]| n.iter().map(|n| n.length() / 2.0).sum::<f32>();
    assert!((area(&fan_n) - 2.0).abs() < 1e-6 && (area(&list_n) - 2.0).abs() < 1e-6);
    assert!(list_n.iter().all(|n| n.z < 0.0), "{list_n:?}");
    assert!(fan_n.iter().all(|n| n.z > 0.0), "{fan_n:?}");
    // Lines: nothing drawn, and a warning naming each; points: a disc each, in the points'
    // plane, under a double-sided copy of their material; the triangles beside them kept.
    let mixed = model_with(
        "mixed",
        &[
            (0, vec![0, 1, 2, 3, 4, 5]),
            (1, vec![0, 1, 2, 3]),
            (2, vec![0, 1, 3, 2]),
            (3, vec![0, 1, 3, 2]),
            (4, strip_as_list()),
        ],
    );
    assert_eq!(mixed.primitives.len(), 2);
    assert_eq!(mixed.warnings.len(), 3, "{:?}", mixed.warnings);
    for mode in ["Lines", "LineLoop", "LineStrip"] {
        assert!(
            mixed
                .warnings
                .iter()
                .any(|w| w.contains(&format!("{mode} primitives are not drawn"))),
            "{mode}: {:?}",
            mixed.warnings
        );
    }
    let (discs, triangles) = match &mixed.primitives[..] {
        [a, b] if a.mesh.vertices.len() == 36 => (a, b),
        [a, b] => (b, a),
        _ => unreachable!(),
    };
    assert_eq!(discs.mesh.vertices.len(), 6 * 6);
    assert_eq!(discs.mesh.indices.len(), 6 * 12);
    for (k, disc) in discs.mesh.vertices.chunks(6).enumerate() {
        let centre = disc.iter().map(|v| Vec3::from(v.position)).sum::<Vec3>() / 6.0;
        assert!(centre.distance(Vec3::new((k / 2) as f32, (k % 2) as f32, 0.0)) < 1e-5);
        assert!(
            disc.iter()
                .all(|v| v.position[2].abs() < 1e-6 && v.normal[2].abs() > 0.999)
        );
    }
    assert!(mixed.materials[discs.material].double_sided);
    assert!(!mixed.materials[triangles.material].double_sided);
    // A strip too short for a triangle is not drawn either, and says so.
    let short = model_with("short", &[(5, vec![0, 1]), (4, strip_as_list())]);
    assert_eq!(short.primitives.len(), 1);
    assert!(
        short.warnings.iter().any(|w| w.contains("without a triangle")),
        "{:?}",
        short.warnings
    );
}
