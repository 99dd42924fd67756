//! Artifacts in USD (`.usdz` packages and loose layers) load as models in glTF's frame, with
//! their UsdPreviewSurface materials and textures, reading nothing outside their own files.
//! Before, neither was read. The reference files were written by Pixar's own library
//! (`tests/data/usd/reference_usd.py`), not by the crate that reads them.

use std::path::{Path, PathBuf};

use glam::Vec3;
use phantogram_assets::budget::ResourceBudget;
use phantogram_assets::library::Library;
use phantogram_assets::model::{AlphaMode, Model, ModelError, load_model};
use phantogram_assets::progress::Progress;
use phantogram_testkit::Scratch;

fn data(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/usd").join(file)
}

/// Within 10 µm.
fn near(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1e-5
}

/// The reference stage (`reference_usd.py`): a box 40 × 20 × 10 cm, scaled from a 10 cm cube on
/// its own prim, turned 90° about +z and moved 100 cm along +x by its parent, with a pyramid 5 cm
/// high referenced from another layer on its top; centimetres with +Z up in the file.
fn assert_is_the_reference_box(what: &str, model: &Model) {
    assert!(model.warnings.is_empty(), "{what}: {:?}", model.warnings);
    // In metres, +Y up: x 0.90–1.10 (the box's 20 cm, turned), up −0.05–0.10 (its 10 cm and the
    // pyramid's 5 cm), depth ±0.20 (its 40 cm; the file's +y is glTF's −z).
    let bounds = model.bounds().expect("bounds");
    assert!(near(bounds.min, Vec3::new(0.90, -0.05, -0.20)), "{what}: {bounds:?}");
    assert!(near(bounds.max, Vec3::new(1.10, 0.10, 0.20)), "{what}: {bounds:?}");
    assert_eq!(
        model.triangle_count(),
        12 + 6,
        "{what}: the box's six quads, four sides and a base"
    );
    // Every face's front outward from its solid's centre (the winding kept through the turn and
    // the axes' change).
    for primitive in &model.primitives {
        let mesh = &primitive.mesh;
        let bounds = mesh.bounds().expect("bounds");
        let centre = (bounds.min + bounds.max) / 2.0;
        for tri in mesh.indices.chunks(3) {
            let p = |k: usize| Vec3::from(mesh.vertices[tri[k] as usize].position);
            let normal = (p(1) - p(0)).cross(p(2) - p(0));
            let middle = (p(0) + p(1) + p(2)) / 3.0;
            assert!(
                normal.dot(middle - centre) > 0.0,
                "{what}: a face turned inward at {middle}"
            );
        }
    }
    // The painted box: its texture (red, green / blue, white) and constants.
    let painted = model
        .materials
        .iter()
        .position(|m| m.name == "Painted")
        .expect("the box's material");
    let material = &model.materials[painted];
    assert_eq!((material.roughness, material.metallic), (0.3, 0.0), "{what}");
    assert_eq!(material.alpha, AlphaMode::Opaque);
    let texture = material.base_color_texture.as_ref().expect("its texture");
    let image = &model.images[texture.image];
    assert_eq!((image.width, image.height), (2, 2));
    assert_eq!(
        &image.rgba8[..8],
        &[255, 0, 0, 255, 0, 255, 0, 255],
        "{what}: the top row red, green"
    );
    // The top face's corner at file point (−5, −5, 5) × (4, 2, 1), turned and moved: (110, −20, 5)
    // cm, glTF (1.10, 0.05, 0.20); its st (0, 0) is the image's bottom left, glTF's uv (0, 1).
    let box_mesh = &model
        .primitives
        .iter()
        .find(|p| p.material == painted)
        .expect("the box")
        .mesh;
    let corner = box_mesh
        .vertices
        .iter()
        .filter(|v| near(Vec3::from(v.position), Vec3::new(1.10, 0.05, 0.20)))
        .find(|v| v.normal[1] > 0.99)
        .expect("the top face's corner");
    assert_eq!(&corner.uv[..2], &[0.0, 1.0], "{what}");
    // Its tangent (for normal maps: MikkTSpace, which USD does not store) along increasing s: the
    // file's +x, turned to +y by the parent, glTF's −z.
    assert!(
        near(Vec3::from_slice(&corner.tangent[..3]), Vec3::NEG_Z),
        "{what}: tangent {:?}",
        corner.tangent
    );
    // The referenced pyramid: its own material, from its own layer.
    let metal = model
        .materials
        .iter()
        .find(|m| m.name == "Metal")
        .expect("the pyramid's material");
    assert_eq!(&metal.base_color[..3], &[0.2, 0.4, 0.6], "{what}");
    assert_eq!((metal.metallic, metal.roughness), (1.0, 0.25), "{what}");
}

#[test]
fn usd_files_by_pixars_library_read_as_written() {
    for file in ["reference-box.usdz", "loose/reference-box.usdc"] {
        let model = load_model(&data(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_is_the_reference_box(file, &model);
    }
}

/// Writes `files` (name, text) into a scratch folder and loads its first file.
fn load_stage(test: &str, files: &[(&str, &str)]) -> Result<Model, ModelError> {
    let dir = Scratch::new(&format!("usd-files-{test}"));
    for (name, text) in files {
        let path = dir.join(name);
        std::fs::create_dir_all(path.parent().expect("a folder")).expect("folder");
        std::fs::write(&path, text).expect("write");
    }
    load_model(&dir.join(files[0].0))
}

/// A unit square (two triangles' worth, as one quad) in the plane z = 0, front +z, metres, Z up.
const SQUARE: &str = r#"
        int[] faceVertexCounts = [4]
        int[] faceVertexIndices = [0, 1, 2, 3]
        point3f[] points = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]"#;

#[test]
fn a_stage_reads_nothing_outside_its_own_files() {
    // The layer sits in `inner/`; beside the folder lie a layer and a texture it names by `..`
    // and by an absolute path. Neither is read; the square itself is drawn, and the user is told.
    let dir_layer = format!(
        r#"#usda 1.0
(
    metersPerUnit = 1
    upAxis = "Z"
)
def Mesh "Square" (
    prepend references = @../secret.usda@
)
{{{SQUARE}
    rel material:binding = </Look>
}}
def "Stolen" (
    prepend references = @/etc/hostname@
)
{{
}}
def Material "Look"
{{
    token outputs:surface.connect = </Look/Surface.outputs:surface>
    def Shader "Surface"
    {{
        uniform token info:id = "UsdPreviewSurface"
        color3f inputs:diffuseColor.connect = </Look/Tex.outputs:rgb>
        token outputs:surface
    }}
    def Shader "Tex"
    {{
        uniform token info:id = "UsdUVTexture"
        asset inputs:file = @../secret.png@
        color3f outputs:rgb
    }}
}}
"#
    );
    let secret = format!("#usda 1.0\ndef Mesh \"Secret\"\n{{{SQUARE}\n}}\n");
    let model = load_stage(
        "outside",
        &[
            ("inner/scene.usda", &dir_layer),
            ("secret.usda", &secret),
            ("secret.png", "not read"),
        ],
    )
    .expect("the square loads");
    assert_eq!(model.triangle_count(), 2, "only the square's own quad");
    assert!(model.images.is_empty(), "no texture read from outside");
    let said = model.warnings.join("\n");
    assert!(said.contains("secret.png"), "the texture left out is named: {said}");
    assert!(said.contains("secret.usda"), "the reference left out is named: {said}");
}

#[test]
fn mirrored_and_left_handed_meshes_keep_their_fronts() {
    // One square four ways, each facing +z (glTF's +y; Z up in the file): plain (wound
    // counter-clockwise seen from +z); mirrored across x by its transform (a mirror across a
    // vertical plane leaves a floor tile facing up, though it winds the square's corners the other
    // way round); left-handed, wound clockwise (its front by the left-hand rule); and both.
    let mesh = |name: &str, indices: &str, extra: &str| {
        format!(
            "def Mesh \"{name}\"\n{{\n    int[] faceVertexCounts = [4]\n    int[] faceVertexIndices = [{indices}]\n    point3f[] points = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]\n{extra}}}\n"
        )
    };
    let mirror = "    float3 xformOp:scale = (-1, 1, 1)\n    uniform token[] xformOpOrder = [\"xformOp:scale\"]\n";
    let left = "    uniform token orientation = \"leftHanded\"\n";
    let stage = format!(
        "#usda 1.0\n(\n    metersPerUnit = 1\n    upAxis = \"Z\"\n)\n{}{}{}{}",
        mesh("Plain", "0, 1, 2, 3", ""),
        mesh("Mirrored", "0, 1, 2, 3", mirror),
        mesh("Left", "0, 3, 2, 1", left),
        mesh("Both", "0, 3, 2, 1", &format!("{mirror}{left}")),
    );
    let model = load_stage("handedness", &[("scene.usda", &stage)]).expect("loads");
    assert_eq!(model.triangle_count(), 8);
    for primitive in &model.primitives {
        let mesh = &primitive.mesh;
        for tri in mesh.indices.chunks(3) {
            let p = |k: usize| Vec3::from(mesh.vertices[tri[k] as usize].position);
            let normal = (p(1) - p(0)).cross(p(2) - p(0));
            assert!(normal.y > 0.0, "a square at {} faces {normal}", p(0));
        }
    }
}

#[test]
fn face_subsets_display_colours_and_the_default_unit() {
    // Centimetres by USD's fallback (no metersPerUnit), Y up by its fallback. Two quads: the first
    // bound to a red material through a face subset, the second to the mesh's blue one; a second
    // mesh with only a display colour (green); one coloured by its vertices; one with neither
    // (plaster).
    let stage = r#"#usda 1.0
def Mesh "Two" (
    prepend apiSchemas = ["MaterialBindingAPI"]
)
{
    int[] faceVertexCounts = [4, 4]
    int[] faceVertexIndices = [0, 1, 2, 3, 1, 4, 5, 2]
    point3f[] points = [(0, 0, 0), (100, 0, 0), (100, 100, 0), (0, 100, 0), (200, 0, 0), (200, 100, 0)]
    rel material:binding = </Blue>
    def GeomSubset "First" (
        prepend apiSchemas = ["MaterialBindingAPI"]
    )
    {
        uniform token elementType = "face"
        uniform token familyName = "materialBind"
        int[] indices = [0]
        rel material:binding = </Red>
    }
}
def Mesh "Green"
{
    int[] faceVertexCounts = [3]
    int[] faceVertexIndices = [0, 1, 2]
    point3f[] points = [(0, 0, 10), (100, 0, 10), (0, 100, 10)]
    color3f[] primvars:displayColor = [(0, 1, 0)] (
        interpolation = "constant"
    )
}
def Mesh "Painted"
{
    int[] faceVertexCounts = [3]
    int[] faceVertexIndices = [0, 1, 2]
    point3f[] points = [(0, 0, 30), (100, 0, 30), (0, 100, 30)]
    color3f[] primvars:displayColor = [(1, 0, 0), (0, 1, 0), (0, 0, 1)] (
        interpolation = "vertex"
    )
}
def Mesh "Bare"
{
    int[] faceVertexCounts = [3]
    int[] faceVertexIndices = [0, 1, 2]
    point3f[] points = [(0, 0, 20), (100, 0, 20), (0, 100, 20)]
}
def Material "Red"
{
    token outputs:surface.connect = </Red/S.outputs:surface>
    def Shader "S"
    {
        uniform token info:id = "UsdPreviewSurface"
        color3f inputs:diffuseColor = (1, 0, 0)
        token outputs:surface
    }
}
def Material "Blue"
{
    token outputs:surface.connect = </Blue/S.outputs:surface>
    def Shader "S"
    {
        uniform token info:id = "UsdPreviewSurface"
        color3f inputs:diffuseColor = (0, 0, 1)
        float inputs:opacity = 0.5
        token outputs:surface
    }
}
"#;
    let model = load_stage("subsets", &[("scene.usda", stage)]).expect("loads");
    let bounds = model.bounds().expect("bounds");
    assert!(near(bounds.max, Vec3::new(2.0, 1.0, 0.3)), "centimetres: {bounds:?}");
    let colour_of = |name: &str| {
        let material = model
            .materials
            .iter()
            .position(|m| m.name == name)
            .unwrap_or_else(|| panic!("{name}"));
        let triangles: usize = model
            .primitives
            .iter()
            .filter(|p| p.material == material)
            .map(|p| p.mesh.indices.len() / 3)
            .sum();
        (model.materials[material].base_color, triangles)
    };
    assert_eq!(colour_of("Red"), ([1.0, 0.0, 0.0, 1.0], 2), "the subset's face");
    assert_eq!(
        colour_of("Blue"),
        ([0.0, 0.0, 1.0, 0.5], 2),
        "the other face, half see-through"
    );
    let blue = model.materials.iter().find(|m| m.name == "Blue").expect("blue");
    assert_eq!(blue.alpha, AlphaMode::Blend);
    assert_eq!(colour_of("display colour"), ([0.0, 1.0, 0.0, 1.0], 1));
    // A display colour is the material's colour alone, not a vertex tint as well; one that
    // varies over a mesh is its vertices' colours, over white.
    let painted = model
        .materials
        .iter()
        .position(|m| m.name == "vertex colours")
        .expect("painted");
    for primitive in &model.primitives {
        let mut colours: Vec<[f32; 4]> = primitive.mesh.vertices.iter().map(|v| v.color).collect();
        colours.dedup();
        if primitive.material == painted {
            assert_eq!(
                colours,
                [[1.0, 0.0, 0.0, 1.0], [0.0, 1.0, 0.0, 1.0], [0.0, 0.0, 1.0, 1.0]]
            );
        } else {
            assert_eq!(colours, [[1.0; 4]], "tinted vertices");
        }
    }
    assert_eq!(colour_of("plaster").1, 1);
}

#[test]
fn damaged_usd_files_are_named_errors() {
    let package = std::fs::read(data("reference-box.usdz")).expect("the reference package");
    let dir = Scratch::new("usd-files-damaged");
    // Cut short, and with its layer's bytes overwritten.
    let mut scrambled = package.clone();
    for b in scrambled.iter_mut().skip(200).take(400) {
        *b = 0x5a;
    }
    for (name, bytes) in [
        ("cut.usdz", package[..package.len() / 2].to_vec()),
        ("scrambled.usdz", scrambled),
        ("empty.usda", b"#usda 1.0\n".to_vec()),
        ("garbage.usdc", b"PXR-USDC\0\0\0\0 not a crate file".to_vec()),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, &bytes).expect("write");
        match load_model(&path) {
            Err(ModelError::Parse { format: "USD", .. } | ModelError::Empty { .. }) => {}
            other => panic!("{name}: {other:?}"),
        }
    }
}

#[test]
fn a_usdz_opened_from_bytes_is_kept_whole_and_loaded_whatever_its_name() {
    let package = std::fs::read(data("reference-box.usdz")).expect("the reference package");
    let dir = Scratch::new("usd-files-share");
    let lib = Library::new(Some(dir.to_path_buf()), None);
    // A zip, but one model: not unpacked into its layers (which would be two "models").
    let imported = lib
        .import("document.bin", &package, ResourceBudget::PHONE, &Progress::new())
        .expect("imported");
    assert_is_the_reference_box("imported", &imported.model);
}

/// Every kind of xformOp and op order (`reference_transforms.py`): each triangle's corners where
/// Pixar's own library puts them (its `UsdGeom.XformCache`), within 1 µm.
#[test]
fn transforms_compose_as_pixars_library_composes_them() {
    let model = load_model(&data("transforms.usda")).expect("loads");
    let loaded: Vec<Vec3> = model
        .primitives
        .iter()
        .flat_map(|p| p.mesh.vertices.iter().map(|v| Vec3::from(v.position)))
        .collect();
    let expected = std::fs::read_to_string(data("transforms-expected.txt")).expect("the expected corners");
    let mut meshes = 0;
    for line in expected.lines() {
        let mut words = line.split_whitespace();
        let name = words.next().expect("a prim");
        let numbers: Vec<f32> = words.map(|w| w.parse().expect("a number")).collect();
        for corner in numbers.chunks(3) {
            let corner = Vec3::new(corner[0], corner[1], corner[2]);
            let nearest = loaded.iter().map(|p| p.distance(corner)).fold(f32::MAX, f32::min);
            assert!(
                nearest < 1e-6,
                "{name}: no corner within 1 µm of {corner} (nearest {nearest} m)"
            );
        }
        meshes += 1;
    }
    assert_eq!(meshes, 12);
    assert_eq!(model.triangle_count(), 12);
}

#[test]
fn opacity_from_the_colour_textures_alpha_is_cut_or_blended() {
    // A leaf: its colour texture's alpha is its opacity, cut at 0.5. A second material reads its
    // opacity from another texture's red channel: written into the colour texture's alpha (it
    // was drawn opaque before). A third places its opacity texture otherwise than its colour's,
    // which glTF's one colour texture cannot hold: drawn opaque, and said so.
    let dir = Scratch::new("usd-files-opacity");
    let png = |rgba: Vec<u8>| {
        let mut png = Vec::new();
        image::RgbaImage::from_raw(2, 1, rgba)
            .expect("2 × 1")
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .expect("png");
        png
    };
    std::fs::write(dir.join("leaf.png"), png(vec![0, 200, 0, 255, 0, 200, 0, 0])).expect("write");
    // Red 0 then 255, both texels opaque: only a read of its red channel makes the leaf's left
    // half clear.
    std::fs::write(dir.join("mask.png"), png(vec![0, 9, 9, 255, 255, 9, 9, 255])).expect("write");
    let material = |name: &str, opacity_file: &str, output: &str, placed: &str| {
        format!(
            r#"def Material "{name}"
{{
    token outputs:surface.connect = </{name}/S.outputs:surface>
    def Shader "S"
    {{
        uniform token info:id = "UsdPreviewSurface"
        color3f inputs:diffuseColor.connect = </{name}/Colour.outputs:rgb>
        float inputs:opacity.connect = </{name}/Opacity.outputs:{output}>
        float inputs:opacityThreshold = 0.5
        token outputs:surface
    }}
    def Shader "Colour"
    {{
        uniform token info:id = "UsdUVTexture"
        asset inputs:file = @leaf.png@
        color3f outputs:rgb
    }}
    def Shader "Place"
    {{
        uniform token info:id = "UsdTransform2d"
        float2 inputs:scale = (2, 2)
        float2 outputs:result
    }}
    def Shader "Opacity"
    {{
        uniform token info:id = "UsdUVTexture"
        asset inputs:file = @{opacity_file}@
        {placed}
        float outputs:{output}
    }}
}}
"#
        )
    };
    let mesh = |name: &str, z: u32| {
        format!(
            "def Mesh \"{name}Mesh\"\n{{\n    int[] faceVertexCounts = [3]\n    int[] faceVertexIndices = [0, 1, 2]\n    point3f[] points = [(0, 0, {z}), (1, 0, {z}), (0, 1, {z})]\n    rel material:binding = </{name}>\n}}\n"
        )
    };
    let tiled = format!("float2 inputs:st.connect = </{}/Place.outputs:result>", "Tiled");
    // A fourth, "Veil", has a constant colour: its opacity texture becomes a white texture with
    // that alpha.
    let veil = material("Veil", "mask.png", "r", "").replace(
        "color3f inputs:diffuseColor.connect = </Veil/Colour.outputs:rgb>",
        "color3f inputs:diffuseColor = (0.5, 0.25, 0.125)",
    );
    let stage = format!(
        "#usda 1.0\n(\n    metersPerUnit = 1\n)\n{}{}{}{}{}{}{}{}",
        mesh("Leaf", 0),
        mesh("Other", 1),
        mesh("Tiled", 2),
        mesh("Veil", 3),
        material("Leaf", "leaf.png", "a", ""),
        material("Other", "mask.png", "r", ""),
        material("Tiled", "mask.png", "r", &tiled),
        veil
    );
    std::fs::write(dir.join("scene.usda"), stage).expect("write");
    let model = load_model(&dir.join("scene.usda")).expect("loads");
    let find = |name: &str| model.materials.iter().find(|m| m.name == name).expect(name);
    let texels = |name: &str| {
        let texture = find(name).base_color_texture.as_ref().expect("its texture");
        model.images[texture.image].rgba8.clone()
    };
    assert_eq!(find("Leaf").alpha, AlphaMode::Mask(0.5));
    assert_eq!(&texels("Leaf")[4..8], &[0, 200, 0, 0], "the alpha kept");
    assert_eq!(find("Other").alpha, AlphaMode::Mask(0.5));
    assert_eq!(
        texels("Other"),
        vec![0, 200, 0, 0, 0, 200, 0, 255],
        "the leaf's colour, the mask's red as alpha"
    );
    let veil = find("Veil");
    assert_eq!(
        (veil.alpha, veil.base_color),
        (AlphaMode::Mask(0.5), [0.5, 0.25, 0.125, 1.0])
    );
    assert_eq!(texels("Veil"), vec![255, 255, 255, 0, 255, 255, 255, 255]);
    assert_eq!(find("Tiled").alpha, AlphaMode::Opaque);
    assert!(
        model
            .warnings
            .iter()
            .any(|w| w.contains("Tiled") && w.contains("opaque")),
        "{:?}",
        model.warnings
    );
    assert_eq!(model.warnings.len(), 1, "{:?}", model.warnings);
}

#[test]
fn the_specular_workflow_is_read_as_a_dielectric_and_said_so() {
    let stage = r#"#usda 1.0
def Mesh "Tile"
{
    int[] faceVertexCounts = [3]
    int[] faceVertexIndices = [0, 1, 2]
    point3f[] points = [(0, 0, 0), (100, 0, 0), (0, 100, 0)]
    rel material:binding = </Glaze>
}
def Material "Glaze"
{
    token outputs:surface.connect = </Glaze/S.outputs:surface>
    def Shader "S"
    {
        uniform token info:id = "UsdPreviewSurface"
        int inputs:useSpecularWorkflow = 1
        color3f inputs:specularColor = (1, 1, 1)
        float inputs:metallic = 1
        float inputs:roughness = 0.2
        token outputs:surface
    }
}
"#;
    let model = load_stage("specular", &[("scene.usda", stage)]).expect("loads");
    let glaze = model.materials.iter().find(|m| m.name == "Glaze").expect("glaze");
    assert_eq!((glaze.metallic, glaze.roughness), (0.0, 0.2));
    assert!(
        model.warnings.iter().any(|w| w.contains("specular workflow")),
        "{:?}",
        model.warnings
    );
}

#[test]
fn texture_coordinates_follow_the_transform_and_the_primvar_named() {
    // Pixar's library wrote the stage (`reference_texture_coordinates.py`): a unit quad whose
    // colour is placed by a `UsdTransform2d`, read through a primvar named by the material's
    // interface input, and whose occlusion reads a second primvar. Before, both were ignored: the
    // colour drawn unplaced, the occlusion from the first set.
    let model = load_model(&data("coords/texture-coordinates.usda")).expect("loads");
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let material = model
        .materials
        .iter()
        .find(|m| m.name == "Transformed")
        .expect("the material");
    let colour = material.base_color_texture.as_ref().expect("its colour texture");
    assert_eq!(colour.tex_coord, 0);
    // The same placement as glTF states it: Khronos's TextureTransformTest, material "All", whose
    // USD conversion by the USD working group holds the transform written here.
    let t = colour.transform;
    let close = |a: f32, b: f32| (a - b).abs() < 1e-5;
    assert!(
        close(t.offset[0], -0.2) && close(t.offset[1], -0.1),
        "offset {:?}",
        t.offset
    );
    assert!(close(t.rotation_rad, 0.3), "rotation {}", t.rotation_rad);
    assert!(close(t.scale[0], 1.5) && close(t.scale[1], 1.5), "scale {:?}", t.scale);
    let (occlusion, _) = material.occlusion_texture.as_ref().expect("its occlusion");
    assert_eq!(occlusion.tex_coord, 1, "the occlusion reads st1");
    assert_eq!(occlusion.transform, Default::default());

    // Corner by corner, where the specification puts the sample: st' = R(17.188734°)·1.5·st + t,
    // with t running up from the image's bottom, against where the model's transform puts it (its
    // v down from the top). The quad's st is its position's x and y; its st1 is that mirrored.
    let mesh = &model.primitives[0].mesh;
    assert_eq!(mesh.vertices.len(), 4);
    let (sin, cos) = 17.188734f32.to_radians().sin_cos();
    let rows = t.rows();
    for vertex in &mesh.vertices {
        let [x, y, _] = vertex.position;
        let (s, tt) = (1.5 * x, 1.5 * y);
        let expected = [cos * s - sin * tt + 0.24328034, sin * s + cos * tt - 0.33300462];
        let [u, v, u1, v1] = vertex.uv;
        let placed = [
            rows[0][0] * u + rows[0][1] * v + rows[0][2],
            rows[1][0] * u + rows[1][1] * v + rows[1][2],
        ];
        assert!(
            close(placed[0], expected[0]) && close(placed[1], 1.0 - expected[1]),
            "corner ({x}, {y}): sampled at {placed:?}, the specification's {expected:?} (t up)"
        );
        assert!(
            close(u1, 1.0 - x) && close(v1, 1.0 - y),
            "corner ({x}, {y}): second set ({u1}, {v1})"
        );
    }
}

#[test]
fn texture_coordinates_that_cannot_be_followed_are_named() {
    // A texture placed by a node that is not evaluated, and one by a turn then a stretch along s
    // (a shear glTF's transform cannot hold): each drawn with what can be, and said so. A third
    // placed by a shift then a turn, which glTF's transform holds: composed in that order.
    let texture = |name: &str, st_source: &str| {
        format!(
            r#"    def Shader "{name}"
    {{
        uniform token info:id = "UsdUVTexture"
        asset inputs:file = @grid.png@
        float2 inputs:st.connect = </M/{st_source}.outputs:result>
        color3f outputs:rgb
    }}
"#
        )
    };
    let stage = format!(
        r#"#usda 1.0
(
    metersPerUnit = 1
)
def Mesh "Tile"
{{{SQUARE}
    texCoord2f[] primvars:st = [(0, 0), (1, 0), (1, 1), (0, 1)] (interpolation = "vertex")
    rel material:binding = </M>
}}
def Material "M"
{{
    token outputs:surface.connect = </M/S.outputs:surface>
    def Shader "S"
    {{
        uniform token info:id = "UsdPreviewSurface"
        color3f inputs:diffuseColor.connect = </M/Colour.outputs:rgb>
        color3f inputs:emissiveColor.connect = </M/Glow.outputs:rgb>
        float inputs:occlusion.connect = </M/Shade.outputs:r>
        token outputs:surface
    }}
    def Shader "Reader"
    {{
        uniform token info:id = "UsdPrimvarReader_float2"
        string inputs:varname = "st"
        float2 outputs:result
    }}
    def Shader "Noise"
    {{
        uniform token info:id = "ND_noise2d_vector2"
        float2 outputs:result
    }}
    def Shader "Turn"
    {{
        uniform token info:id = "UsdTransform2d"
        float2 inputs:in.connect = </M/Reader.outputs:result>
        float inputs:rotation = 45
        float2 outputs:result
    }}
    def Shader "Stretch"
    {{
        uniform token info:id = "UsdTransform2d"
        float2 inputs:in.connect = </M/Turn.outputs:result>
        float2 inputs:scale = (2, 1)
        float2 outputs:result
    }}
    def Shader "Shift"
    {{
        uniform token info:id = "UsdTransform2d"
        float2 inputs:in.connect = </M/Reader.outputs:result>
        float2 inputs:translation = (0.5, 0)
        float2 outputs:result
    }}
    def Shader "Quarter"
    {{
        uniform token info:id = "UsdTransform2d"
        float2 inputs:in.connect = </M/Shift.outputs:result>
        float inputs:rotation = 90
        float2 outputs:result
    }}
{}{}{}}}
"#,
        texture("Colour", "Noise"),
        texture("Glow", "Stretch"),
        texture("Shade", "Quarter").replace("color3f outputs:rgb", "float outputs:r")
    );
    let mut png = Vec::new();
    image::RgbaImage::from_raw(1, 1, vec![200, 100, 50, 255])
        .expect("1 × 1")
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .expect("png");
    let dir = Scratch::new("usd-files-coordinates-named");
    std::fs::write(dir.join("grid.png"), &png).expect("write");
    std::fs::write(dir.join("scene.usda"), stage).expect("write");
    let model = load_model(&dir.join("scene.usda")).expect("loads");
    let said = |what: &str| model.warnings.iter().any(|w| w.contains(what));
    assert!(said("ND_noise2d_vector2"), "{:?}", model.warnings);
    assert!(said("sheared"), "{:?}", model.warnings);
    let material = &model.materials[0];
    assert_eq!(
        material.base_color_texture.as_ref().expect("colour").transform,
        Default::default(),
        "the node not evaluated: the mesh's own coordinates"
    );
    let glow = material.emissive_texture.as_ref().expect("glow").transform;
    assert!(glow.rows().iter().flatten().all(|v| v.is_finite()), "{glow:?}");
    // st' = R(90°)·(st + (0.5, 0)) = R(90°)·st + (0, 0.5): glTF's offset (0 − 1, 1 − 0.5 − 0).
    // Composed the other way round (the shift after the turn) it would be (−0.5, 1).
    let (shade, _) = material.occlusion_texture.as_ref().expect("shade");
    let t = shade.transform;
    assert!(
        (t.offset[0] + 1.0).abs() < 1e-5 && (t.offset[1] - 0.5).abs() < 1e-5,
        "{t:?}"
    );
    assert!((t.rotation_rad - std::f32::consts::FRAC_PI_2).abs() < 1e-5, "{t:?}");
}

#[test]
fn a_points_prim_is_drawn_as_a_closed_cloud() {
    // Pixar's library wrote it (`reference_points.py`): 2000 points on a sphere of 10 cm radius,
    // 50 cm above the origin, centimetres with +Z up, red above its equator and blue below, and a
    // guide cloud far away. Before, points were not drawn (the stage had nothing to show).
    let model = load_model(&data("points.usdc")).expect("loads");
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    assert_eq!(model.primitives.len(), 1, "the guide left out");
    let primitive = &model.primitives[0];
    let mesh = &primitive.mesh;
    assert_eq!(mesh.indices.len() / 3, 2000 * 4, "a disc (four triangles) a point");
    let material = &model.materials[primitive.material];
    assert!(material.double_sided, "a disc turned the wrong way still draws");
    // In metres, +Y up: the sphere's centre at (0, 0.5, 0), its discs within a centimetre of its
    // 10 cm radius (they lie tangent to it, as wide as the gaps between points).
    let centre = Vec3::new(0.0, 0.5, 0.0);
    let bounds = mesh.bounds().expect("bounds");
    assert!(
        (bounds.min - (centre - Vec3::splat(0.1))).abs().max_element() < 0.01
            && (bounds.max - (centre + Vec3::splat(0.1))).abs().max_element() < 0.01,
        "{bounds:?}"
    );
    for v in &mesh.vertices {
        let p = Vec3::from(v.position) - centre;
        assert!(
            (p.length() - 0.1).abs() < 0.01,
            "a disc corner {} m from the centre",
            p.length()
        );
        // The file's +z is up: red above the equator, blue below (linear, as USD stores them).
        let expected = if p.y > 0.005 {
            Some([1.0, 0.0, 0.0, 1.0])
        } else if p.y < -0.005 {
            Some([0.0, 0.0, 1.0, 1.0])
        } else {
            None
        };
        if let Some(colour) = expected {
            assert_eq!(v.color, colour, "at {p}");
        }
        // Normals estimated from the neighbours, turned away from the cloud's centre.
        assert!(Vec3::from(v.normal).dot(p) > 0.0, "a disc facing inward at {p}");
    }
}

#[test]
fn a_cloud_shows_the_material_bound_to_it() {
    // Only a cloud is bound to the material: it is read all the same (it had been read only
    // when a mesh named it, so the cloud came out plaster).
    let stage = r#"#usda 1.0
(
    metersPerUnit = 1
)
def Points "Cloud"
{
    point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0), (0.5, 0.5, 0.1)]
    rel material:binding = </Glaze>
}
def Material "Glaze"
{
    token outputs:surface.connect = </Glaze/S.outputs:surface>
    def Shader "S"
    {
        uniform token info:id = "UsdPreviewSurface"
        color3f inputs:diffuseColor = (0.1, 0.6, 0.2)
        float inputs:roughness = 0.2
        token outputs:surface
    }
}
"#;
    let model = load_stage("cloud-material", &[("cloud.usda", stage)]).expect("loads");
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let material = &model.materials[model.primitives[0].material];
    assert_eq!(material.name, "Glaze");
    assert_eq!(
        (&material.base_color[..3], material.roughness),
        (&[0.1, 0.6, 0.2][..], 0.2)
    );
    assert!(material.double_sided);
}

#[test]
fn tangents_come_from_the_primvar_the_normal_map_reads() {
    // The square's st stands upright on it (s along +x); its st1 is turned a quarter (s along +y,
    // t along +x). The colour reads st, so st1 is the material's second set. A normal map read
    // through st1 needs tangents along st1's s (+y, the map's up then along +x: handedness −1);
    // a stage whose normal map reads st, or that has none, the first set's (+x, +1). Made from
    // the first set always, the st1 map shaded as if lit from the side.
    let stage = |normal_varname: &str| {
        let normal = if normal_varname.is_empty() {
            ""
        } else {
            "\n        normal3f inputs:normal.connect = </M/Bumps.outputs:rgb>"
        };
        format!(
            r#"#usda 1.0
(
    metersPerUnit = 1
)
def Mesh "Tile"
{{{SQUARE}
    normal3f[] normals = [(0, 0, 1), (0, 0, 1), (0, 0, 1), (0, 0, 1)] (interpolation = "vertex")
    texCoord2f[] primvars:st = [(0, 0), (1, 0), (1, 1), (0, 1)] (interpolation = "vertex")
    texCoord2f[] primvars:st1 = [(0, 0), (0, 1), (1, 1), (1, 0)] (interpolation = "vertex")
    rel material:binding = </M>
}}
def Material "M"
{{
    token outputs:surface.connect = </M/S.outputs:surface>
    def Shader "S"
    {{
        uniform token info:id = "UsdPreviewSurface"
        color3f inputs:diffuseColor.connect = </M/Colour.outputs:rgb>{normal}
        token outputs:surface
    }}
    def Shader "ColourReader"
    {{
        uniform token info:id = "UsdPrimvarReader_float2"
        string inputs:varname = "st"
        float2 outputs:result
    }}
    def Shader "Colour"
    {{
        uniform token info:id = "UsdUVTexture"
        asset inputs:file = @flat.png@
        float2 inputs:st.connect = </M/ColourReader.outputs:result>
        color3f outputs:rgb
    }}
    def Shader "Reader"
    {{
        uniform token info:id = "UsdPrimvarReader_float2"
        string inputs:varname = "{normal_varname}"
        float2 outputs:result
    }}
    def Shader "Bumps"
    {{
        uniform token info:id = "UsdUVTexture"
        asset inputs:file = @flat.png@
        float2 inputs:st.connect = </M/Reader.outputs:result>
        float4 inputs:scale = (2, 2, 2, 1)
        float4 inputs:bias = (-1, -1, -1, 0)
        color3f outputs:rgb
    }}
}}
"#
        )
    };
    let mut png = Vec::new();
    image::RgbaImage::from_raw(1, 1, vec![128, 128, 255, 255])
        .expect("1 × 1")
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .expect("png");
    for (varname, expected_along_x, handedness) in [("st1", false, -1.0), ("st", true, 1.0), ("", true, 1.0)] {
        let dir = Scratch::new(&format!("usd-files-tangents-{varname}"));
        std::fs::write(dir.join("flat.png"), &png).expect("write");
        std::fs::write(dir.join("scene.usda"), stage(varname)).expect("write");
        let model = load_model(&dir.join("scene.usda")).expect("loads");
        let material = &model.materials[model.primitives[0].material];
        let wanted_set = u32::from(varname == "st1");
        assert_eq!(
            material.normal_texture.as_ref().map(|(t, _)| t.tex_coord),
            (!varname.is_empty()).then_some(wanted_set),
            "{varname}: {:?}",
            model.warnings
        );
        // The square's own x and y as loaded (the stage's axes may be turned to the model's).
        let mesh = &model.primitives[0].mesh;
        let at = |i: usize| Vec3::from(mesh.vertices[i].position);
        let (x, y) = ((at(1) - at(0)).normalize(), (at(3) - at(0)).normalize());
        let along = if expected_along_x { x } else { y };
        for v in &mesh.vertices {
            let t = v.tangent;
            assert!(
                Vec3::new(t[0], t[1], t[2]).distance(along) < 1e-4 && t[3] == handedness,
                "normal map reading {varname:?}: tangent {t:?}, expected {along} with handedness {handedness}"
            );
        }
    }
}

#[test]
fn primitive_shapes_are_drawn_as_the_schema_defines_them() {
    // A stage of primitive shapes as exporters write props: a cube of the schema's size (2),
    // a sphere moved and coloured, a capsule along X bound to a material, a double-sided plane;
    // and a curve, still not drawn. Z up, centimetres: the loader turns them into metres, +Y up.
    // Before, every shape was left out with a warning and the stage had nothing to show.
    let stage = r#"#usda 1.0
(
    upAxis = "Z"
)
def Cube "Crate"
{
}
def Sphere "Ball"
{
    double radius = 0.5
    double3 xformOp:translate = (10, 0, 0)
    uniform token[] xformOpOrder = ["xformOp:translate"]
    color3f[] primvars:displayColor = [(0.8, 0.1, 0.1)]
}
def Capsule "Rod"
{
    double radius = 0.25
    double height = 4
    uniform token axis = "X"
    double3 xformOp:translate = (0, 10, 0)
    uniform token[] xformOpOrder = ["xformOp:translate"]
    rel material:binding = </Brass>
}
def Plane "Card"
{
    double width = 6
    double length = 2
    double3 xformOp:translate = (0, 0, 10)
    uniform token[] xformOpOrder = ["xformOp:translate"]
}
def BasisCurves "Wire"
{
    int[] curveVertexCounts = [2]
    point3f[] points = [(0, 0, 0), (1, 1, 1)]
}
def Material "Brass"
{
    token outputs:surface.connect = </Brass/S.outputs:surface>
    def Shader "S"
    {
        uniform token info:id = "UsdPreviewSurface"
        color3f inputs:diffuseColor = (0.7, 0.5, 0.2)
        float inputs:metallic = 1
        float inputs:roughness = 0.3
        token outputs:surface
    }
}
"#;
    let model = load_stage("shapes", &[("shapes.usda", stage)]).expect("loads");
    assert_eq!(
        model.warnings,
        vec!["1 prim(s) of kind BasisCurves: not drawn (only meshes, points and primitive shapes are)".to_owned()]
    );
    // Each shape's bounds in the model's frame (metres, Y up: the stage's (x, y, z) is the
    // model's (x, z, −y)).
    let bounds_of = |colour: Option<[f32; 3]>, name: Option<&str>| {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        let mut found = 0;
        for primitive in &model.primitives {
            let material = &model.materials[primitive.material];
            let this = match (colour, name) {
                (Some(c), _) => material.base_color[..3] == c,
                (_, Some(n)) => material.name == n,
                _ => false,
            };
            if !this {
                continue;
            }
            found += 1;
            for v in &primitive.mesh.vertices {
                lo = lo.min(Vec3::from(v.position));
                hi = hi.max(Vec3::from(v.position));
            }
        }
        (found, lo, hi)
    };
    let close = |a: Vec3, b: Vec3| a.distance(b) < 1e-3;
    // The sphere: radius 0.5 cm about (10, 0, 0) cm, in its display colour.
    let (found, lo, hi) = bounds_of(Some([0.8, 0.1, 0.1]), None);
    assert_eq!(found, 1);
    assert!(
        close(lo, Vec3::new(0.095, -0.005, -0.005)) && close(hi, Vec3::new(0.105, 0.005, 0.005)),
        "{lo} {hi}"
    );
    // The capsule: along the stage's X, 4 cm of spine and 0.25 cm caps, about (0, 10, 0) cm.
    let (found, lo, hi) = bounds_of(None, Some("Brass"));
    assert_eq!(found, 1);
    assert!(
        close(lo, Vec3::new(-0.0225, -0.0025, -0.1025)) && close(hi, Vec3::new(0.0225, 0.0025, -0.0975)),
        "{lo} {hi}"
    );
    let brass = model.materials.iter().find(|m| m.name == "Brass").expect("the brass");
    assert_eq!((brass.metallic, brass.roughness), (1.0, 0.3));
    // The cube (2 cm) and the plane (6 × 2 cm, facing the stage's +Z, both sides) take the
    // stage's plaster: the model's whole bounds reach from the cube's corner to the plane.
    let plane = model
        .primitives
        .iter()
        .find(|p| p.mesh.vertices.len() == 4)
        .expect("the plane's four corners");
    let normal = Vec3::from(plane.mesh.vertices[0].normal);
    assert!(normal.distance(Vec3::Y) < 1e-5, "the plane faces up: {normal}");
    assert!(model.materials[plane.material].double_sided, "a plane shows both sides");
    let ys: Vec<f32> = plane.mesh.vertices.iter().map(|v| v.position[1]).collect();
    assert!(ys.iter().all(|y| (y - 0.1).abs() < 1e-5), "{ys:?}");
    let xs = plane.mesh.vertices.iter().map(|v| v.position[0].abs());
    assert!(xs.fold(0.0f32, f32::max) - 0.03 < 1e-5);
    let crate_ = model
        .primitives
        .iter()
        .find(|p| p.mesh.vertices.len() == 24)
        .expect("the cube's 24 corners");
    let (lo, hi) = crate_.mesh.vertices.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), v| (lo.min(Vec3::from(v.position)), hi.max(Vec3::from(v.position))),
    );
    assert!(
        close(lo, Vec3::splat(-0.01)) && close(hi, Vec3::splat(0.01)),
        "{lo} {hi}"
    );
}

#[test]
fn a_stage_of_more_shapes_than_the_budget_reads_is_refused() {
    // A shape is a line of text and becomes two thousand vertices: each is charged as a part
    // before it is made (`usd_shapes::ReadShape::into_mesh`), so a stage declaring more than the
    // budget reads is refused (here 8 draws × 16 parts read per draw; the budget's own, 65 536,
    // as for meshes).
    let stage: String = std::iter::once("#usda 1.0\n".to_owned())
        .chain((0..200).map(|i| format!("def Sphere \"S{i}\" {{ double radius = 0.01 }}\n")))
        .collect();
    let dir = Scratch::new("usd-files-many-shapes");
    std::fs::write(dir.join("many.usda"), &stage).expect("write");
    let small = ResourceBudget {
        max_primitives: 8,
        ..ResourceBudget::PHONE
    };
    match phantogram_assets::model::load_model_within(&dir.join("many.usda"), small) {
        Err(ModelError::OverBudget { error, .. }) => {
            assert_eq!(error.unit, "primitives read", "{error:?}");
        }
        other => panic!("{:?}", other.map(|m| m.primitives.len())),
    }
    // Within the budget they are drawn.
    let few: String = stage.lines().take(41).map(|l| format!("{l}\n")).collect();
    std::fs::write(dir.join("few.usda"), few).expect("write");
    let model = phantogram_assets::model::load_model_within(&dir.join("few.usda"), small).expect("40 spheres load");
    let vertices: usize = model.primitives.iter().map(|p| p.mesh.vertices.len()).sum();
    assert_eq!(vertices, 40 * 33 * 64, "forty spheres of 33 rings of 64");
}

#[test]
fn primitive_shapes_written_by_pixars_library_fill_its_extents() {
    // `reference_shapes.py`: one prim of each shape kind, written by Pixar's library, and the
    // world-space extent that library computes for each (`shapes-expected.txt`). The shapes stand
    // apart, so each vertex belongs to the one box it lies in; each box is filled to its faces.
    let model = load_model(&data("shapes.usda")).expect("loads");
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let expected = std::fs::read_to_string(data("shapes-expected.txt")).expect("the extents");
    let boxes: Vec<(String, Vec3, Vec3)> = expected
        .lines()
        .map(|line| {
            let mut words = line.split_whitespace();
            let path = words.next().expect("a path").to_owned();
            let v: Vec<f32> = words.map(|w| w.parse().expect("a number")).collect();
            (path, Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]))
        })
        .collect();
    assert_eq!(boxes.len(), 8);
    let mut filled: Vec<(Vec3, Vec3)> = vec![(Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)); 8];
    for v in model.primitives.iter().flat_map(|p| &p.mesh.vertices) {
        let p = Vec3::from(v.position);
        let k = boxes
            .iter()
            .position(|(_, lo, hi)| p.cmpge(*lo - 1e-4).all() && p.cmple(*hi + 1e-4).all())
            .unwrap_or_else(|| panic!("vertex {p} in no shape's extent"));
        filled[k] = (filled[k].0.min(p), filled[k].1.max(p));
    }
    for ((path, lo, hi), (min, max)) in boxes.iter().zip(filled) {
        // The round parts' outline is a polygon: within 0.2 % of the extent's size.
        let tolerance = 2e-3 * (*hi - *lo).max_element();
        assert!(
            min.distance(*lo) < tolerance && max.distance(*hi) < tolerance,
            "{path}: {min} – {max}, Pixar's {lo} – {hi}"
        );
    }
    let brass = model
        .materials
        .iter()
        .find(|m| m.name == "Brass")
        .expect("the bound material");
    assert_eq!((brass.metallic, brass.roughness), (1.0, 0.3));
}
