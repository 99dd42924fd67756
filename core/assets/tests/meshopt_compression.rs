//! `EXT_meshopt_compression` (gltfpack's `-c`): a mesh stored with meshoptimizer's codecs loads
//! as the same mesh stored plainly — positions and indices bit for bit, octahedral-filtered
//! 8-bit normals within their quantisation — its fallback buffer is never read, and a damaged
//! or oversized compressed view is a named error.
//!
//! The compressed files are made here with meshoptimizer's encoders from a known mesh; the
//! ground truth is that mesh (and the plain file of it), not the decoder's output.

use phantogram_assets::model::{ModelError, load_gltf};
use phantogram_testkit::{Scratch, glb};

const SIDE: usize = 12;

/// A wavy sheet: positions, unit normals and a triangle list.
fn sheet() -> (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<u32>) {
    let height = |x: f32, z: f32| 0.02 * (x * 9.0).sin() * (z * 7.0).cos();
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    for j in 0..SIDE {
        for i in 0..SIDE {
            let (x, z) = (i as f32 * 0.01, j as f32 * 0.01);
            positions.push([x, height(x, z), z]);
            let (dx, dz) = (
                (height(x + 1e-3, z) - height(x - 1e-3, z)) / 2e-3,
                (height(x, z + 1e-3) - height(x, z - 1e-3)) / 2e-3,
            );
            let n = [-dx, 1.0, -dz];
            let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            normals.push([n[0] / l, n[1] / l, n[2] / l]);
        }
    }
    let mut indices = Vec::new();
    for j in 0..SIDE - 1 {
        for i in 0..SIDE - 1 {
            let v = (j * SIDE + i) as u32;
            let s = SIDE as u32;
            indices.extend_from_slice(&[v, v + s, v + 1, v + 1, v + s, v + s + 1]);
        }
    }
    (positions, normals, indices)
}

fn bytes_of<T: Copy>(items: &[T], each: impl Fn(T) -> Vec<u8>) -> Vec<u8> {
    items.iter().flat_map(|&t| each(t)).collect()
}

fn f32s(v: [f32; 3]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// The sheet stored plainly: float positions and normals, 16-bit indices.
fn plain_glb() -> Vec<u8> {
    let (positions, normals, indices) = sheet();
    let mut bin = bytes_of(&positions, f32s);
    let normals_at = bin.len();
    bin.extend(bytes_of(&normals, f32s));
    let indices_at = bin.len();
    bin.extend(bytes_of(&indices, |i| (i as u16).to_le_bytes().to_vec()));
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"NORMAL":1}},"indices":2}}]}}],
        "accessors":[
          {{"bufferView":0,"componentType":5126,"count":{n},"type":"VEC3"}},
          {{"bufferView":1,"componentType":5126,"count":{n},"type":"VEC3"}},
          {{"bufferView":2,"componentType":5123,"count":{k},"type":"SCALAR"}}],
        "bufferViews":[
          {{"buffer":0,"byteOffset":0,"byteLength":{normals_at}}},
          {{"buffer":0,"byteOffset":{normals_at},"byteLength":{nl}}},
          {{"buffer":0,"byteOffset":{indices_at},"byteLength":{il}}}],
        "buffers":[{{"byteLength":{total}}}]}}"#,
        n = positions.len(),
        k = indices.len(),
        nl = indices_at - normals_at,
        il = indices.len() * 2,
        total = bin.len(),
    );
    glb(&json, &bin)
}

/// How the compressed file is damaged, if at all.
#[derive(Clone, Copy, PartialEq)]
enum Damage {
    None,
    /// The normals' compressed stream cut to half its length.
    CutNormals,
    /// The positions' view claims a count far beyond any budget.
    HugeCount,
}

/// The sheet as gltfpack would store it: positions compressed as floats, normals as 8-bit
/// octahedral (`KHR_mesh_quantization`, stride 4), indices as a triangle list of 16-bit
/// indices; the views point into a fallback buffer that holds nothing (`fallback_uri`, if
/// given, names a file that does not exist: it must not be read).
fn compressed_glb(damage: Damage, fallback_uri: Option<&str>) -> Vec<u8> {
    use meshopt::encoding::{encode_filter_oct, encode_index_buffer, encode_vertex_buffer};
    let (positions, normals, indices) = sheet();
    let positions_c = encode_vertex_buffer(&positions).unwrap();
    let with_w: Vec<[f32; 4]> = normals.iter().map(|n| [n[0], n[1], n[2], 0.0]).collect();
    let octahedral: Vec<[i8; 4]> = encode_filter_oct::<i8>(&with_w, 8);
    let mut normals_c = encode_vertex_buffer(&octahedral).unwrap();
    if damage == Damage::CutNormals {
        normals_c.truncate(normals_c.len() / 2);
    }
    let indices_c = encode_index_buffer(&indices, positions.len()).unwrap();
    let mut bin = Vec::new();
    let mut place = |stream: &[u8]| {
        let at = bin.len();
        bin.extend_from_slice(stream);
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
        (at, stream.len())
    };
    let (p_at, p_len) = place(&positions_c);
    let (n_at, n_len) = place(&normals_c);
    let (i_at, i_len) = place(&indices_c);
    let n = positions.len();
    let k = indices.len();
    let position_count = if damage == Damage::HugeCount { 1usize << 40 } else { n };
    // Where each view would lie in the (absent) fallback buffer.
    let (fp, fnm, fi) = (0, n * 12, n * 12 + n * 4);
    let fallback_len = fi + k * 2;
    let fallback_uri = fallback_uri.map(|u| format!(r#""uri":"{u}","#)).unwrap_or_default();
    let ext = |at: usize, len: usize, stride: usize, count: usize, mode: &str, filter: &str| {
        format!(
            r#""extensions":{{"EXT_meshopt_compression":{{"buffer":0,"byteOffset":{at},"byteLength":{len},"byteStride":{stride},"count":{count},"mode":"{mode}"{filter}}}}}"#
        )
    };
    let json = format!(
        r#"{{"asset":{{"version":"2.0","generator":"meshopt_compression test"}},
        "extensionsUsed":["EXT_meshopt_compression","KHR_mesh_quantization"],
        "extensionsRequired":["EXT_meshopt_compression","KHR_mesh_quantization"],
        "scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"NORMAL":1}},"indices":2}}]}}],
        "accessors":[
          {{"bufferView":0,"componentType":5126,"count":{n},"type":"VEC3"}},
          {{"bufferView":1,"componentType":5120,"normalized":true,"count":{n},"type":"VEC3"}},
          {{"bufferView":2,"componentType":5123,"count":{k},"type":"SCALAR"}}],
        "bufferViews":[
          {{"buffer":1,"byteOffset":{fp},"byteLength":{pl},"byteStride":12,{e0}}},
          {{"buffer":1,"byteOffset":{fnm},"byteLength":{nl},"byteStride":4,{e1}}},
          {{"buffer":1,"byteOffset":{fi},"byteLength":{il},{e2}}}],
        "buffers":[{{"byteLength":{total}}},
                   {{{fallback_uri}"byteLength":{fallback_len},"extensions":{{"EXT_meshopt_compression":{{"fallback":true}}}}}}]}}"#,
        pl = n * 12,
        nl = n * 4,
        il = k * 2,
        e0 = ext(p_at, p_len, 12, position_count, "ATTRIBUTES", ""),
        e1 = ext(n_at, n_len, 4, n, "ATTRIBUTES", r#","filter":"OCTAHEDRAL""#),
        e2 = ext(i_at, i_len, 2, k, "TRIANGLES", ""),
        total = bin.len(),
    );
    glb(&json, &bin)
}

fn write(dir: &Scratch, name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

#[test]
fn a_meshopt_compressed_file_loads_as_the_plain_one() {
    let dir = Scratch::new("meshopt-same");
    let plain = load_gltf(&write(&dir, "plain.glb", &plain_glb())).unwrap();
    for fallback_uri in [None, Some("fallback-not-here.bin")] {
        let packed = load_gltf(&write(&dir, "packed.glb", &compressed_glb(Damage::None, fallback_uri))).unwrap();
        assert!(packed.warnings.is_empty(), "{:?}", packed.warnings);
        assert_eq!(packed.primitives.len(), plain.primitives.len());
        let (a, b) = (&plain.primitives[0].mesh, &packed.primitives[0].mesh);
        assert_eq!(a.indices, b.indices, "indices");
        assert_eq!(a.vertices.len(), b.vertices.len());
        assert_eq!(a.vertices.len(), SIDE * SIDE);
        let mut worst_deg = 0f32;
        for (u, v) in a.vertices.iter().zip(&b.vertices) {
            assert_eq!(u.position, v.position, "positions bit for bit");
            let (nu, nv) = (glam::Vec3::from(u.normal), glam::Vec3::from(v.normal));
            worst_deg = worst_deg.max(nu.angle_between(nv).to_degrees());
        }
        // 8-bit octahedral normals: about a degree of quantisation.
        assert!(worst_deg < 2.0, "normals differ by up to {worst_deg:.2}°");
    }
}

#[test]
fn a_damaged_or_oversized_compressed_view_is_a_named_error() {
    let dir = Scratch::new("meshopt-damaged");
    let cut = load_gltf(&write(&dir, "cut.glb", &compressed_glb(Damage::CutNormals, None))).unwrap_err();
    let message = cut.to_string();
    assert!(
        matches!(cut, ModelError::Data { .. })
            && message.contains("bufferView 1")
            && message.contains("does not decode"),
        "{message}"
    );
    let huge = load_gltf(&write(&dir, "huge.glb", &compressed_glb(Damage::HugeCount, None))).unwrap_err();
    assert!(matches!(huge, ModelError::OverBudget { .. }), "{huge}");
}
