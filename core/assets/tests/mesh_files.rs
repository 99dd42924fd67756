//! Scans published as bare meshes: STL (binary and ASCII, millimetres, +Z up, as 3D printing
//! writes them) and PLY (metres, +Y up, with vertex colours) load as models in glTF's frame
//! (metres, +Y up), with smooth outward normals, and open from the library as glTF does.
//! Before, neither was read.

use glam::Vec3;
use phantogram_assets::budget::ResourceBudget;
use phantogram_assets::library::Library;
use phantogram_assets::model::{Model, ModelError, load_model};
use phantogram_assets::progress::Progress;
use phantogram_testkit::Scratch;

/// A box 10 mm wide (x), 20 mm deep (y) and 30 mm tall (z), its corner at the origin: twelve
/// triangles wound counter-clockwise seen from outside.
fn box_triangles() -> Vec<[[f32; 3]; 3]> {
    let (w, d, h) = (10.0, 20.0, 30.0);
    let c = |i: usize| [[0.0, w][i & 1], [0.0, d][(i >> 1) & 1], [0.0, h][(i >> 2) & 1]];
    // Faces as corner quads, counter-clockwise from outside.
    let quads = [
        [0, 2, 3, 1], // z = 0, facing −z
        [4, 5, 7, 6], // z = h
        [0, 1, 5, 4], // y = 0
        [2, 6, 7, 3], // y = d
        [0, 4, 6, 2], // x = 0
        [1, 3, 7, 5], // x = w
    ];
    quads
        .iter()
        .flat_map(|q| [[c(q[0]), c(q[1]), c(q[2])], [c(q[0]), c(q[2]), c(q[3])]])
        .collect()
}

fn binary_stl(triangles: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut out = b"solid but binary".to_vec();
    out.resize(80, 0);
    out.extend((triangles.len() as u32).to_le_bytes());
    for t in triangles {
        out.extend([0u8; 12]);
        for c in t.iter().flatten() {
            out.extend(c.to_le_bytes());
        }
        out.extend([0u8; 2]);
    }
    out
}

fn ascii_stl(triangles: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut out = String::from("solid box\n");
    for t in triangles {
        out += "  facet normal 0 0 0\n    outer loop\n";
        for p in t {
            out += &format!("      vertex {} {} {}\n", p[0], p[1], p[2]);
        }
        out += "    endloop\n  endfacet\n";
    }
    out += "endsolid box\n";
    out.into_bytes()
}

fn load(test: &str, name: &str, bytes: &[u8]) -> Result<Model, ModelError> {
    let dir = Scratch::new(&format!("mesh-files-{test}"));
    let path = dir.join(name);
    std::fs::write(&path, bytes).expect("write");
    load_model(&path)
}

/// The box as loaded: one primitive of the eight corners, in metres, +Y up, normals outward.
fn assert_is_the_box(model: &Model) {
    assert_eq!(model.primitives.len(), 1);
    let mesh = &model.primitives[0].mesh;
    assert_eq!(mesh.vertices.len(), 8, "the corners welded");
    assert_eq!(mesh.indices.len(), 36);
    let bounds = mesh.bounds().expect("bounds");
    // x stays, z (up) becomes y, y becomes −z; millimetres become metres.
    let (min, max) = (bounds.min, bounds.max);
    assert!((min - Vec3::new(0.0, 0.0, -0.02)).length() < 1e-6, "{min}");
    assert!((max - Vec3::new(0.01, 0.03, 0.0)).length() < 1e-6, "{max}");
    let centre = (min + max) / 2.0;
    for v in &mesh.vertices {
        let out = Vec3::from(v.position) - centre;
        assert!(
            Vec3::from(v.normal).dot(out) > 0.0,
            "an inward normal at {:?}",
            v.position
        );
    }
    // Every triangle still faces outward after the turn (its winding against its centre).
    for t in mesh.indices.chunks(3) {
        let p = |k: usize| Vec3::from(mesh.vertices[t[k] as usize].position);
        let n = (p(1) - p(0)).cross(p(2) - p(0));
        assert!(n.dot((p(0) + p(1) + p(2)) / 3.0 - centre) > 0.0, "{t:?}");
    }
    let material = &model.materials[model.primitives[0].material];
    assert_eq!(material.metallic, 0.0, "a scan without colour is not shown as metal");
}

#[test]
fn a_binary_stl_is_the_box_in_metres_standing_up() {
    let model = load("binary", "box.stl", &binary_stl(&box_triangles())).expect("loads");
    assert_is_the_box(&model);
    assert_eq!(model.name, "box");
}

#[test]
fn an_ascii_stl_is_the_same_box() {
    let model = load("ascii", "box.STL", &ascii_stl(&box_triangles())).expect("loads");
    assert_is_the_box(&model);
}

#[test]
fn a_ply_keeps_its_frame_and_shows_its_vertex_colours() {
    // A quad in metres, +Y up, facing +z; the second corner a mid grey in sRGB (128 → 0.216).
    let ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 255 0 0\n0.1 0 0 128 128 128\n0.1 0.2 0 0 0 255\n0 0.2 0 255 255 255\n4 0 1 2 3\n";
    let model = load("ply", "quad.ply", ply.as_bytes()).expect("loads");
    let mesh = &model.primitives[0].mesh;
    assert_eq!(mesh.indices, [0, 1, 2, 0, 2, 3]);
    assert_eq!(mesh.vertices[2].position, [0.1, 0.2, 0.0]);
    assert!(mesh.vertices.iter().all(|v| v.normal == [0.0, 0.0, 1.0]));
    assert_eq!(mesh.vertices[0].color, [1.0, 0.0, 0.0, 1.0]);
    let grey = mesh.vertices[1].color[0];
    assert!((grey - 0.2158).abs() < 1e-3, "sRGB 128 is linear 0.216, not {grey}");
    let material = &model.materials[model.primitives[0].material];
    assert_eq!(material.base_color, [1.0; 4], "white, so the colours show as they are");
}

#[test]
fn damaged_mesh_files_are_named_errors() {
    let mut cut = binary_stl(&box_triangles());
    cut.truncate(cut.len() - 7);
    match load("damaged", "cut.stl", &cut) {
        Err(error @ ModelError::Parse { .. }) => {
            // The message names the file's own format, not glTF's.
            let text = error.to_string();
            assert!(
                text.contains("not a valid STL file") && text.contains("12 triangles"),
                "{text}"
            );
        }
        other => panic!("{other:?}"),
    }
    // A cloud of one point (or of points all in one place) has nothing to show.
    assert!(matches!(
        load(
            "damaged",
            "points.ply",
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n"
        ),
        Err(ModelError::Empty { .. })
    ));
    // Only degenerate triangles: nothing to draw.
    let flat = [[[1.0f32, 1.0, 1.0]; 3]];
    assert!(matches!(
        load("damaged", "flat.stl", &binary_stl(&flat)),
        Err(ModelError::Empty { .. })
    ));
    let nan = [[[f32::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]];
    assert!(matches!(
        load("damaged", "nan.stl", &binary_stl(&nan)),
        Err(ModelError::Data { .. })
    ));
    // Finite, but beyond the ±1e9 m every model's vertices are held to (10^15 mm).
    let far = [[[1e15f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]];
    match load("damaged", "far.stl", &binary_stl(&far)) {
        Err(ModelError::Data { message, .. }) => assert!(message.contains("within ±1e9"), "{message}"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn an_stl_over_the_budget_is_refused_before_the_mesh_is_built() {
    let dir = Scratch::new("mesh-files-budget");
    let path = dir.join("box.stl");
    let bytes = binary_stl(&box_triangles());
    std::fs::write(&path, &bytes).expect("write");
    let small = ResourceBudget {
        memory_bytes: bytes.len() as u64,
        ..ResourceBudget::default()
    };
    match phantogram_assets::model::load_model_within(&path, small) {
        Err(ModelError::OverBudget { error, .. }) => assert!(error.what.contains("the mesh"), "{error}"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn an_stl_opened_from_bytes_is_kept_and_loaded_whatever_its_name() {
    let dir = Scratch::new("mesh-files-library");
    let lib = Library::new(Some(dir.to_path_buf()), None);
    let stl = binary_stl(&box_triangles());
    // A share may arrive without its extension: the content says it is STL.
    let imported = lib
        .import("document.bin", &stl, ResourceBudget::PHONE, &Progress::new())
        .expect("imported");
    assert_eq!(imported.model.triangle_count(), 12);
    let again = lib
        .load(&imported.entry.id, ResourceBudget::PHONE, &Progress::new())
        .expect("loads again");
    assert_eq!(again.model.triangle_count(), 12);
}

/// The colour of the first vertex of `mesh` at a height (+y) that `at` accepts.
fn colour_where(mesh: &phantogram_assets::model::Mesh, at: impl Fn(f32) -> bool) -> [f32; 4] {
    mesh.vertices
        .iter()
        .find(|v| at(v.position[1]))
        .map(|v| v.color)
        .expect("a vertex there")
}

/// A file of `core/assets/tests/data` (its READMEs say where each came from).
fn test_data(file: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(file)
}

/// `model` as a cloud of `n` points on a sphere of radius 0.1 m whose top half (+z in the file)
/// is sRGB 200 red and the rest dark: a disc per point, about the sphere's centre, the file's +z
/// as glTF's +y, in the file's colours.
fn assert_is_the_red_topped_sphere(what: &str, model: &Model, n: usize) {
    let mesh = &model.primitives[0].mesh;
    assert_eq!(mesh.vertices.len(), n * 6, "{what}: a hexagon per point");
    let bounds = mesh.bounds().expect("bounds");
    for k in 0..3 {
        assert!(
            (bounds.max[k] - 0.1).abs() < 0.01 && (bounds.min[k] + 0.1).abs() < 0.01,
            "{what}: about its centre, {bounds:?}"
        );
    }
    let (top, bottom) = (colour_where(mesh, |y| y > 0.09), colour_where(mesh, |y| y < -0.09));
    assert!((top[0] - 0.578).abs() < 0.01, "{what}: sRGB 200 on top: {top:?}");
    assert!(bottom[0] < 0.1, "{what}: {bottom:?}");
}

/// `bytes` opened on a phone as a share without a name: kept in the library and loaded as a
/// cloud of `n` discs (four triangles each).
fn assert_imports_from_a_share(test: &str, bytes: &[u8], n: usize) {
    let dir = Scratch::new(&format!("mesh-files-{test}-library"));
    let lib = Library::new(Some(dir.to_path_buf()), None);
    let imported = lib
        .import("document.bin", bytes, ResourceBudget::PHONE, &Progress::new())
        .expect("imported");
    assert_eq!(imported.model.triangle_count(), n * 4);
}

/// A scanner's point cloud: a PLY of coloured vertices on a sphere of radius 0.1 m, no faces.
fn point_cloud_ply(n: usize) -> String {
    let mut text = format!(
        "ply\nformat ascii 1.0\nelement vertex {n}\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n"
    );
    for p in phantogram_geometry::sphere::fibonacci(n) {
        let red = if p.z > 0.0 { 200 } else { 40 };
        text.push_str(&format!("{} {} {} {red} 90 60\n", 0.1 * p.x, 0.1 * p.z, 0.1 * p.y));
    }
    text
}

#[test]
fn a_point_cloud_ply_is_drawn_as_discs_that_close_its_surface() {
    let model = load("cloud", "sphere.ply", point_cloud_ply(3000).as_bytes()).expect("loads");
    assert_eq!(model.primitives.len(), 1);
    let mesh = &model.primitives[0].mesh;
    assert_eq!(mesh.vertices.len(), 3000 * 6, "a hexagon per point");
    assert_eq!(mesh.indices.len(), 3000 * 12);
    let material = &model.materials[model.primitives[0].material];
    assert!(material.double_sided, "a disc turned the wrong way still draws");
    // The colours of the file, linear; the discs facing out from the centre.
    let top = colour_where(mesh, |y| y > 0.09);
    assert!((top[0] - 0.578).abs() < 0.01, "sRGB 200 is linear 0.578: {top:?}");
    for disc in mesh.vertices.chunks(6) {
        let centre = disc.iter().map(|v| Vec3::from(v.position)).sum::<Vec3>() / 6.0;
        assert!(Vec3::from(disc[0].normal).dot(centre.normalize()) > 0.98);
    }
    // Opened on a phone (a share of its bytes): kept in the library and loaded the same.
    let dir = Scratch::new("mesh-files-cloud-library");
    let lib = Library::new(Some(dir.to_path_buf()), None);
    let imported = lib
        .import(
            "scan.ply",
            point_cloud_ply(3000).as_bytes(),
            ResourceBudget::PHONE,
            &Progress::new(),
        )
        .expect("imported");
    assert_eq!(imported.model.triangle_count(), 3000 * 4);
    // The bounds are the sphere's, grown by at most a disc.
    let bounds = mesh.bounds().expect("bounds");
    assert!(
        (bounds.max.y - 0.1).abs() < 0.01 && (bounds.min.y + 0.1).abs() < 0.01,
        "{bounds:?}"
    );
}

#[test]
fn a_point_cloud_over_the_budget_is_thinned_to_fit() {
    let dir = Scratch::new("mesh-files-cloud-budget");
    let path = dir.join("sphere.ply");
    std::fs::write(&path, point_cloud_ply(3000)).expect("write");
    // Room for the file and about 1000 discs (528 bytes each).
    let file_bytes = std::fs::metadata(&path).expect("size").len();
    let small = ResourceBudget {
        memory_bytes: file_bytes.max(1000 * 528 + 1000),
        ..ResourceBudget::default()
    };
    let model = phantogram_assets::model::load_model_within(&path, small).expect("loads thinned");
    let discs = model.primitives[0].mesh.vertices.len() / 6;
    assert!((500..=1001).contains(&discs), "{discs} discs");
    // A budget with room for a small file but not for one disc (528 bytes): the budget is
    // named, not an empty model.
    let small_file = dir.join("four.ply");
    std::fs::write(&small_file, point_cloud_ply(4)).expect("write");
    let tiny = ResourceBudget {
        memory_bytes: std::fs::metadata(&small_file).expect("size").len(),
        ..ResourceBudget::default()
    };
    assert!(tiny.memory_bytes < 528);
    match phantogram_assets::model::load_model_within(&small_file, tiny) {
        Err(ModelError::OverBudget { error, .. }) => assert!(error.what.contains("point cloud"), "{error}"),
        other => panic!("{other:?}"),
    }
}

/// A scanner's point cloud as text (`.xyz`, CloudCompare's export: x y z r g b, metres with +Z
/// up): a georeferenced sphere of radius 0.1 m whose top (+z) half is red, loaded as discs in
/// glTF's frame (its top up, +Y), about its centre, coloured by the file; a Leica `.pts` of the
/// same points (count, then x y z intensity r g b) alike; and opened from a share without a name.
#[test]
fn a_point_cloud_as_text_is_drawn_as_discs_the_right_way_up() {
    let points = phantogram_geometry::sphere::fibonacci(2000);
    let (east, north) = (512_345.678, 5_412_345.678);
    let mut xyz = String::from("// x y z r g b\n");
    let mut pts = format!("{}\n", points.len());
    for p in &points {
        let (x, y, z) = (
            east + 0.1 * f64::from(p.x),
            north + 0.1 * f64::from(p.y),
            200.0 + 0.1 * f64::from(p.z),
        );
        let red = if p.z > 0.0 { 200 } else { 40 };
        xyz.push_str(&format!("{x:.4} {y:.4} {z:.4} {red} 90 60\n"));
        pts.push_str(&format!("{x:.4} {y:.4} {z:.4} -512 {red} 90 60\n"));
    }
    for (name, text) in [("scan.xyz", &xyz), ("scan.pts", &pts)] {
        let model = load("text-cloud", name, text.as_bytes()).expect("loads");
        assert_is_the_red_topped_sphere(name, &model, points.len());
    }
    assert_imports_from_a_share("text-cloud", xyz.as_bytes(), points.len());
    // A line that is not a point is named.
    let err = load("text-cloud-bad", "bad.xyz", b"0 0 0\n1 1 one\n")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("not a valid point cloud file") && err.contains("line 2") && err.contains("\"one\""),
        "{err}"
    );
}

/// A georeferenced sphere of radius 0.1 m (its top, +z, red) as LAS point format 2, written by
/// the `las` crate's writer, LAZ-compressed or not, in metres (no coordinate system named).
fn las_sphere(points: &[Vec3], compressed: bool) -> Vec<u8> {
    let (east, north, up) = (512_345.678, 5_412_345.678, 200.0);
    las_sphere_in(
        points,
        compressed,
        ([east, north, up], [0.0001; 3]),
        |p| [east + 0.1 * p[0], north + 0.1 * p[1], up + 0.1 * p[2]],
        Vec::new(),
    )
}

/// The sphere of [`las_sphere`] with each point at `at(point on the unit sphere)` in the file's
/// own units, stored about `offset` to `scale`, with `records` (a coordinate system's).
fn las_sphere_in(
    points: &[Vec3],
    compressed: bool,
    (offset, scale): ([f64; 3], [f64; 3]),
    at: impl Fn([f64; 3]) -> [f64; 3],
    records: Vec<las::Vlr>,
) -> Vec<u8> {
    let mut builder = las::Builder::from((1, 2));
    builder.point_format = las::point::Format::new(2).expect("format 2");
    builder.point_format.is_compressed = compressed;
    builder.vlrs = records;
    let axis = |k: usize| las::Transform {
        scale: scale[k],
        offset: offset[k],
    };
    builder.transforms = las::Vector {
        x: axis(0),
        y: axis(1),
        z: axis(2),
    };
    let header = builder.into_header().expect("header");
    let mut writer = las::Writer::new(std::io::Cursor::new(Vec::new()), header).expect("writer");
    for p in points {
        let red = if p.z > 0.0 { 200 << 8 } else { 40 << 8 };
        let [x, y, z] = at(p.as_dvec3().to_array());
        writer
            .write_point(las::Point {
                x,
                y,
                z,
                color: Some(las::Color::new(red, 90 << 8, 60 << 8)),
                ..las::Point::default()
            })
            .expect("point");
    }
    writer.into_inner().expect("written").into_inner()
}

/// A coordinate system's record of a LAS file.
fn crs_record(record_id: u16, data: Vec<u8>) -> las::Vlr {
    las::Vlr {
        user_id: "LASF_Projection".to_owned(),
        record_id,
        description: String::new(),
        data,
    }
}

/// A scan in Oregon's state-plane feet (a compound system as WKT, its heights in US survey feet)
/// or in degrees of longitude and latitude (GeoTIFF keys) comes out in metres: the same discs as
/// the scan in metres, to 0.2 mm (each file rounds its points to 0.05 mm at most).
#[test]
fn a_las_scan_in_feet_or_degrees_comes_out_in_metres() {
    let points = phantogram_geometry::sphere::fibonacci(500);
    let metres = load("las-units", "metres.las", &las_sphere(&points, false)).expect("loads");
    let (foot_m, us_foot_m) = (0.3048, 1200.0 / 3937.0);
    let wkt = "COMPD_CS[\"NAD83 / Oregon GIC Lambert (ft) + NAVD88 height (ftUS)\",PROJCS[\"NAD83 / Oregon GIC Lambert (ft)\",GEOGCS[\"NAD83\",DATUM[\"North_American_Datum_1983\",SPHEROID[\"GRS 1980\",6378137,298.257222101]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]],PROJECTION[\"Lambert_Conformal_Conic_2SP\"],PARAMETER[\"false_easting\",1312335.958],UNIT[\"foot\",0.3048],AXIS[\"Easting\",EAST],AXIS[\"Northing\",NORTH]],VERT_CS[\"NAVD88 height (ftUS)\",VERT_DATUM[\"North American Vertical Datum 1988\",2005],UNIT[\"US survey foot\",0.304800609601219],AXIS[\"Gravity-related height\",UP]]]";
    let (east_ft, north_ft, up_ft) = (1_680_000.0, 870_000.0, 400.0);
    let feet = las_sphere_in(
        &points,
        true,
        ([east_ft, north_ft, up_ft], [0.0001; 3]),
        |p| {
            [
                east_ft + 0.1 * p[0] / foot_m,
                north_ft + 0.1 * p[1] / foot_m,
                up_ft + 0.1 * p[2] / us_foot_m,
            ]
        },
        vec![crs_record(2112, format!("{wkt}\0").into_bytes())],
    );
    // Geographic (model type 2), in degrees (9102); metres per degree at 45° N on WGS 84 from
    // the series for a degree's length, independent of the loader's radii of curvature.
    let keys: Vec<u16> = vec![1, 1, 0, 2, 1024, 0, 1, 2, 2054, 0, 1, 9102];
    let (lon, lat, up) = (-120.5, 45.0, 200.0);
    let (east_m_per_degree, north_m_per_degree) = (78_846.81, 111_131.75);
    let degrees = las_sphere_in(
        &points,
        false,
        ([lon, lat, up], [1e-10, 1e-10, 0.0001]),
        |p| {
            [
                lon + 0.1 * p[0] / east_m_per_degree,
                lat + 0.1 * p[1] / north_m_per_degree,
                up + 0.1 * p[2],
            ]
        },
        vec![crs_record(34735, keys.iter().flat_map(|k| k.to_le_bytes()).collect())],
    );
    // Each point's disc (a hexagon), by its centre: the discs' turn follows normals estimated
    // from the neighbours, which the files' rounding moves a little.
    let centres = |model: &Model| -> Vec<Vec3> {
        let vertices = &model.primitives[0].mesh.vertices;
        vertices
            .chunks_exact(6)
            .map(|disc| disc.iter().map(|v| Vec3::from(v.position)).sum::<Vec3>() / 6.0)
            .collect()
    };
    let want = centres(&metres);
    for (name, bytes) in [("feet.laz", feet), ("degrees.las", degrees)] {
        let model = load("las-units", name, &bytes).expect("loads");
        assert_is_the_red_topped_sphere(name, &model, points.len());
        let worst = centres(&model)
            .iter()
            .zip(&want)
            .map(|(g, w)| g.distance(*w))
            .fold(0.0, f32::max);
        assert!(worst < 2e-4, "{name}: a point {worst} m from the scan in metres");
    }
}

/// A laser scan as LAS and as LAZ (metres with +Z up, georeferenced, 16-bit colours): drawn as
/// discs in glTF's frame about its centre, coloured by the file, whichever it is and whatever its
/// name; a damaged one is a named error.
#[test]
fn a_las_or_laz_scan_is_drawn_as_discs_the_right_way_up() {
    let points = phantogram_geometry::sphere::fibonacci(2000);
    let las_file = las_sphere(&points, false);
    let laz_file = las_sphere(&points, true);
    assert!(
        laz_file.len() * 2 < las_file.len(),
        "compressed: {} bytes",
        laz_file.len()
    );
    for (name, bytes) in [
        ("scan.las", &las_file),
        ("scan.laz", &laz_file),
        ("laz-named.las", &laz_file),
    ] {
        let model = load("las-cloud", name, bytes).expect("loads");
        assert_is_the_red_topped_sphere(name, &model, points.len());
    }
    assert_imports_from_a_share("las-cloud", &laz_file, points.len());
    // Cut short: the header promises points the file does not hold, compressed or not.
    for (name, bytes) in [("cut.laz", &laz_file), ("cut.las", &las_file)] {
        let err = load("las-cloud-bad", name, &bytes[..bytes.len() * 2 / 3])
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("not a valid LAS file") && err.contains("the file is cut short"),
            "{name}: {err}"
        );
    }
    // A LAZ written once by an earlier version of the encoder (`tests/data/las/README.md`).
    let model = load_model(&test_data("las/sphere-50.laz")).expect("loads");
    assert_is_the_red_topped_sphere("sphere-50.laz", &model, 50);
}

/// The sphere of [`las_sphere`] as an E57 file of two scans written by the `e57` crate's writer:
/// the top half (+z) and the bottom half, each in its own scanner's frame with its pose (a
/// translation) placing it, intensity 0.5, colour as the LAS sphere's.
fn e57_sphere(points: &[Vec3]) -> Vec<u8> {
    use e57::{Quaternion, Record, RecordDataType, RecordName, RecordValue, Transform, Translation};
    let (east, north) = (512_345.678, 5_412_345.678);
    let mut cursor = std::io::Cursor::new(Vec::new());
    {
        let mut writer = e57::E57Writer::new(&mut cursor, "sphere").expect("writer");
        for (k, top) in [true, false].into_iter().enumerate() {
            // Each scanner stands 3 m from the sphere's centre, to its side.
            let scanner = [east + if top { 3.0 } else { -3.0 }, north, 200.0];
            let double = || RecordDataType::Double { min: None, max: None };
            let byte = || RecordDataType::Integer { min: 0, max: 255 };
            let prototype = vec![
                Record {
                    name: RecordName::CartesianX,
                    data_type: double(),
                },
                Record {
                    name: RecordName::CartesianY,
                    data_type: double(),
                },
                Record {
                    name: RecordName::CartesianZ,
                    data_type: double(),
                },
                Record {
                    name: RecordName::ColorRed,
                    data_type: byte(),
                },
                Record {
                    name: RecordName::ColorGreen,
                    data_type: byte(),
                },
                Record {
                    name: RecordName::ColorBlue,
                    data_type: byte(),
                },
            ];
            let mut scan = writer.add_pointcloud(&format!("scan-{k}"), prototype).expect("scan");
            scan.set_transform(Some(Transform {
                rotation: Quaternion {
                    w: 1.0,
                    x: 0.0,
                    y: 0.0,
                    z: 0.0,
                },
                translation: Translation {
                    x: scanner[0],
                    y: scanner[1],
                    z: scanner[2],
                },
            }));
            for p in points.iter().filter(|p| (p.z > 0.0) == top) {
                let world = [
                    east + 0.1 * f64::from(p.x),
                    north + 0.1 * f64::from(p.y),
                    200.0 + 0.1 * f64::from(p.z),
                ];
                let red = if top { 200 } else { 40 };
                let mut values: Vec<RecordValue> = (0..3).map(|i| RecordValue::Double(world[i] - scanner[i])).collect();
                values.extend([red, 90, 60].map(RecordValue::Integer));
                scan.add_point(values).expect("point");
            }
            scan.finalize().expect("scan written");
        }
        writer.finalize().expect("file written");
    }
    cursor.into_inner()
}

/// A terrestrial scanner's E57 of two registered scans (each in its own frame, placed by its
/// pose): drawn as one sphere of discs in glTF's frame about its centre, coloured by the file,
/// whatever its name; a damaged one is a named error.
#[test]
fn an_e57_scan_is_drawn_as_discs_the_right_way_up() {
    let points = phantogram_geometry::sphere::fibonacci(2000);
    let file = e57_sphere(&points);
    let model = load("e57-cloud", "scan.e57", &file).expect("loads");
    assert_is_the_red_topped_sphere("scan.e57", &model, points.len());
    assert_imports_from_a_share("e57-cloud", &file, points.len());
    // Cut short, and whole but with a byte changed (its page's checksum fails): named apart.
    let err = load("e57-cloud-bad", "cut.e57", &file[..file.len() / 2])
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("not a valid E57 file") && err.contains("the file is cut short"),
        "{err}"
    );
    let mut damaged = file.clone();
    damaged[file.len() / 2] ^= 0x55;
    let err = load("e57-cloud-bad", "damaged.e57", &damaged).unwrap_err().to_string();
    assert!(
        err.contains("not a valid E57 file") && !err.contains("cut short"),
        "{err}"
    );
    // An E57 written once by an earlier version of the writer (`tests/data/e57/README.md`).
    let model = load_model(&test_data("e57/sphere-50.e57")).expect("loads");
    assert_is_the_red_topped_sphere("sphere-50.e57", &model, 50);
}

/// Scans of one sphere written by other programs (`tests/data/reference_scans.py`: E57 by
/// libE57Format, LAS 1.4 format 7 by laspy, LAZ by the reference LASzip): every point lands where
/// the script put it (to a tenth of a millimetre, in glTF's frame about the sphere's centre), in
/// the file's colour.
#[test]
fn scans_written_by_other_programs_read_alike() {
    for file in [
        "las/reference-sphere-200.las",
        "las/reference-sphere-200.laz",
        "e57/reference-sphere-200.e57",
    ] {
        assert_is_the_reference_sphere(file);
    }
}

/// The same sphere in Oregon's state-plane feet with US survey feet up (LAZ, PROJ's WKT2 of the
/// compound system) and in degrees (LAS 1.2, GeoTIFF keys; longitude and latitude by PROJ's
/// inverse azimuthal projection): read in metres, each point where the script put it.
#[test]
fn scans_in_feet_or_degrees_by_other_programs_read_in_metres() {
    for file in [
        "las/reference-sphere-200-feet.laz",
        "las/reference-sphere-200-degrees.las",
    ] {
        assert_is_the_reference_sphere(file);
    }
}

/// `file` (in `tests/data`) as the reference script's sphere: 200 Fibonacci points of radius
/// 0.1 m, +z red, each read within 0.1 mm of where the script put it in metres (glTF's frame,
/// about the sphere's centre), in its colour.
fn assert_is_the_reference_sphere(file: &str) {
    let n = 200;
    let expected: Vec<Vec3> = (0..n)
        .map(|i| {
            let i = f64::from(i) + 0.5;
            let phi = (1.0 - 2.0 * i / f64::from(n)).acos();
            let theta = std::f64::consts::PI * (1.0 + 5f64.sqrt()) * i;
            let (x, y, z) = (theta.cos() * phi.sin(), theta.sin() * phi.sin(), phi.cos());
            // +Z up in the file, +Y up in glTF.
            Vec3::new(x as f32, z as f32, -y as f32) * 0.1
        })
        .collect();
    let (lo, hi) = expected
        .iter()
        .fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let centre = (lo + hi) * 0.5;
    let model = load_model(&test_data(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
    let mesh = &model.primitives[0].mesh;
    let discs: Vec<(Vec3, [f32; 4])> = mesh
        .vertices
        .chunks(6)
        .map(|d| (d.iter().map(|v| Vec3::from(v.position)).sum::<Vec3>() / 6.0, d[0].color))
        .collect();
    assert_eq!(discs.len(), n as usize, "{file}");
    for p in &expected {
        let (at, colour) = discs
            .iter()
            .min_by(|a, b| a.0.distance(*p - centre).total_cmp(&b.0.distance(*p - centre)))
            .expect("discs");
        assert!(at.distance(*p - centre) < 1e-4, "{file}: {p} read at {at}");
        let red = if p.y > 0.0 { 0.578 } else { 0.021 };
        assert!((colour[0] - red).abs() < 0.01, "{file}: {colour:?} at {p}");
    }
}
