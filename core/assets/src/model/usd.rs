//! Artifacts in USD: a `.usdz` package (Apple's AR format: what iPhone photogrammetry, Reality
//! Converter and museums' "view in AR" downloads hand over) or a loose layer (`.usd`, `.usda`,
//! `.usdc`, as Blender and Houdini export), read by the `openusd` crate (text and binary formats,
//! composition: sublayers, references, payloads, variants, instances).
//!
//! * **Files**: only the package's own or those beside the loose layer (`usd_files`).
//! * **Meshes**: every `Mesh` prim of the composed stage that is active, visible and not of
//!   purpose `guide` (nor `proxy` where other meshes are), in its world transform (the
//!   `xformOp` stacks of it and its ancestors, `!resetXformStack!` honoured), at the stage's
//!   default time. Polygons are fanned into triangles, holes left out; `leftHanded` meshes and
//!   mirroring transforms keep their faces' fronts. Normals and texture coordinates by their
//!   interpolation (constant, uniform, vertex, varying, face-varying), indexed or not; corners
//!   that share all their values share a vertex. Subdivision surfaces are drawn as their control
//!   meshes (`usd_mesh`). `Points` prims are clouds drawn as discs that close into their
//!   surface (`point_cloud`), with their normals and display colours. Primitive shapes (cubes,
//!   spheres, cylinders, cones, capsules, planes) are made into meshes as the schema defines
//!   them (`usd_shapes`). Curves, NURBS and tetrahedral meshes are not drawn (a warning says
//!   so).
//! * **Units and axes**: the stage's `metersPerUnit` (USD's fallback: centimetres) and `upAxis`
//!   (`Z` turned into glTF's +Y up).
//! * **Materials**: the one bound to a mesh (or to a face subset of it, `GeomSubset` of family
//!   `materialBind`), closest binding first, read as its `UsdPreviewSurface`
//!   (`usd_preview_surface`) and made a glTF material (`usd_material`): its textures decoded
//!   within the budget, a metallic and a roughness texture packed into glTF's one (roughness in
//!   G, metallic in B). Texture coordinates are the primvars the material's primvar readers name
//!   (a first and a second set), else `st` (or `st0`, `UVMap`, `uv`, `map1`, as exporters name
//!   it; else the first of two components), flipped to glTF's top-left origin; a texture's
//!   `UsdTransform2d`s become glTF's texture transform. MikkTSpace tangents are made for normal
//!   maps. A mesh without a material shows its `displayColor`, or else plaster.
//!
//! **Budget**: the package is unpacked within the budget; each mesh is charged before it is
//! built, each texture before it is decoded. **Threading**: the caller's thread (the reader's
//! stage is not shared). **Panics**: none escape (the reader's become the file's error).

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use glam::{DMat4, DQuat, DVec3};
use openusd::{sdf, usd};

use super::loader::{ModelError, check_positions, finish_mesh_model, model_name, over_budget, read_model_file};
use super::tangents::{TangentUv, generate_tangents};
use super::usd_files::{Confined, Files, folded, folder_of, is_package};
use super::usd_material::{Textures, material_of};
use super::usd_mesh::{Look, ReadCloud, ReadMesh, attribute_value, read_mesh, read_points};
use super::usd_preview_surface::{self, Surface, scalar, text, token, vec3};
use super::usd_shapes::{ReadShape, SHAPE_KINDS, read_shape};
use super::{Image, Material, Mesh, Model, Primitive, Vertex, point_cloud};
use crate::budget::{ResourceBudget, Spending};
use crate::progress::Progress;

/// What the format is called in messages.
const FORMAT: &str = "USD";

/// Loads `path` (a `.usdz` package or a loose layer with the files beside it).
pub fn load(path: &Path, budget: ResourceBudget, progress: &Progress) -> Result<Model, ModelError> {
    let cancelled = |_| ModelError::Cancelled {
        path: path.to_path_buf(),
    };
    let parse_error = |message: String| ModelError::Parse {
        path: path.to_path_buf(),
        format: FORMAT,
        message,
    };
    progress.step(0.0).map_err(cancelled)?;
    let mut spending = Spending::new(budget);
    let bytes = read_model_file(path, &spending)?;
    let (files, root) = if is_package(&bytes) {
        Files::unpack(&bytes, budget.memory_bytes).map_err(parse_error)?
    } else {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let folder = folder_of(path);
        let root = folded(&name)
            .filter(|n| !n.is_empty())
            .unwrap_or_else(|| "root.usd".to_owned());
        let files = Files::Folder {
            folder,
            root: (root.clone(), bytes),
            memory_bytes: budget.memory_bytes,
        };
        (files, root)
    };
    let files = Arc::new(files);
    progress.step(0.1).map_err(cancelled)?;
    let read = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| read_scene(&files, &root, progress)))
        .map_err(|_| "the USD reader failed on damaged data".to_owned())
        .and_then(|r| r);
    let scene = match read {
        Ok(Some(scene)) => scene,
        Ok(None) => {
            return Err(ModelError::Cancelled {
                path: path.to_path_buf(),
            });
        }
        Err(message) => return Err(parse_error(message)),
    };
    progress.step(0.6).map_err(cancelled)?;
    build_model(path, scene, &files, &mut spending, progress)
}

/// How a prim the stage shows is drawn.
enum Drawn {
    Mesh,
    /// A cloud of discs.
    Points,
    /// A primitive shape of this kind (`usd_shapes::SHAPE_KINDS`).
    Shape(String),
}

/// What the stage holds, read.
struct Scene {
    meshes: Vec<ReadMesh>,
    /// Primitive shapes, made into meshes as the model is built (`usd_shapes::ReadShape`).
    shapes: Vec<ReadShape>,
    clouds: Vec<ReadCloud>,
    looks: Vec<Look>,
    surfaces: HashMap<String, Surface>,
    /// The layers read (to anchor texture paths at).
    layers: Vec<String>,
    warnings: Vec<String>,
}

/// Reads the stage whose root layer is `root`; `None` when cancelled.
fn read_scene(files: &Arc<Files>, root: &str, progress: &Progress) -> Result<Option<Scene>, String> {
    let stage = usd::Stage::builder()
        .resolver(Confined(Arc::clone(files)))
        .open(root)
        .map_err(text)?;
    let mut warnings = Vec::new();
    let metres_per_unit = stage
        .stage_metadata("metersPerUnit")
        .map_err(text)?
        .as_ref()
        .and_then(scalar)
        .filter(|m| *m > 0.0)
        .unwrap_or(0.01);
    let z_up = stage
        .stage_metadata("upAxis")
        .map_err(text)?
        .as_ref()
        .and_then(token)
        .is_some_and(|a| a.eq_ignore_ascii_case("z"));
    // USD's frame into glTF's: metres, +Y up (a Z-up stage's +Z becomes +Y, its +Y becomes −Z).
    let axes = if z_up {
        DMat4::from_cols_array(&[
            1.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0,
        ])
    } else {
        DMat4::IDENTITY
    };
    let to_model = axes * DMat4::from_scale(DVec3::splat(metres_per_unit));

    let mut paths = Vec::new();
    stage
        .traverse(usd::PrimPredicate::DEFAULT_PROXIES, |p| paths.push(p.clone()))
        .map_err(text)?;
    let mut drawn_paths = Vec::new();
    let mut not_drawn: HashMap<String, usize> = HashMap::new();
    for p in &paths {
        let kind = stage.prim(p.clone()).map_err(text)?.type_name().map_err(text)?;
        match kind.as_ref().map(|t| t.as_str()) {
            Some("Mesh") => drawn_paths.push((p.clone(), Drawn::Mesh)),
            Some("Points") => drawn_paths.push((p.clone(), Drawn::Points)),
            Some(k) if SHAPE_KINDS.contains(&k) => drawn_paths.push((p.clone(), Drawn::Shape(k.to_owned()))),
            Some(k @ ("BasisCurves" | "NurbsCurves" | "NurbsPatch" | "TetMesh")) => {
                *not_drawn.entry(k.to_owned()).or_default() += 1;
            }
            _ => {}
        }
    }
    let mut kinds: Vec<_> = not_drawn.into_iter().collect();
    kinds.sort();
    for (kind, n) in kinds {
        warnings.push(format!(
            "{n} prim(s) of kind {kind}: not drawn (only meshes, points and primitive shapes are)"
        ));
    }
    // Which meshes, shapes and clouds show: visible, not guides; proxies only where nothing else is
    // drawn.
    let mut shown = Vec::new();
    for (p, drawn) in drawn_paths {
        if invisible(&stage, &p)? {
            continue;
        }
        let purpose = inherited_token(&stage, &p, "purpose")?;
        if purpose.as_deref() != Some("guide") {
            shown.push((p, drawn, purpose.as_deref() == Some("proxy")));
        }
    }
    if shown.iter().any(|(_, _, proxy)| !proxy) {
        shown.retain(|(_, _, proxy)| !proxy);
    }

    let mut scene = Scene {
        meshes: Vec::new(),
        shapes: Vec::new(),
        clouds: Vec::new(),
        looks: Vec::new(),
        surfaces: HashMap::new(),
        layers: stage.layer_identifiers(),
        warnings: Vec::new(),
    };
    let count = shown.len().max(1);
    // Each material read once, when a mesh first names it (its textures say which primvars the
    // mesh's texture coordinates are).
    let mut read: HashMap<String, Option<Surface>> = HashMap::new();
    let mut surface_warnings = Vec::new();
    let mut failure = None;
    let mut primvars_of = |material: &str| -> Vec<String> {
        let surface = read.entry(material.to_owned()).or_insert_with(|| {
            let path = sdf::Path::new(material).map_err(text);
            match path.and_then(|path| usd_preview_surface::read(&stage, &path, &mut surface_warnings)) {
                Ok(surface) => surface,
                Err(message) => {
                    failure.get_or_insert(message);
                    None
                }
            }
        });
        surface
            .as_ref()
            .map_or_else(Vec::new, |s| s.primvars().into_iter().map(str::to_owned).collect())
    };
    for (i, (p, drawn, _)) in shown.iter().enumerate() {
        if progress.step(0.1 + 0.5 * i as f32 / count as f32).is_err() {
            return Ok(None);
        }
        let world = to_model * world_transform(&stage, p)?;
        match drawn {
            Drawn::Points => {
                if let Some(cloud) = read_points(&stage, p, world, &mut scene.looks, &mut warnings)? {
                    scene.clouds.push(cloud);
                }
            }
            Drawn::Mesh => {
                if let Some(mesh) = read_mesh(&stage, p, world, &mut scene.looks, &mut primvars_of, &mut warnings)? {
                    scene.meshes.push(mesh);
                }
            }
            Drawn::Shape(kind) => {
                if let Some(shape) = read_shape(&stage, p, kind, world, &mut scene.looks, &mut warnings)? {
                    scene.shapes.push(shape);
                }
            }
        }
    }
    // The materials only clouds and shapes are bound to.
    for look in &scene.looks {
        if let Some(material) = &look.material {
            primvars_of(material);
        }
    }
    if let Some(message) = failure {
        return Err(message);
    }
    warnings.append(&mut surface_warnings);
    scene.surfaces = read.into_iter().filter_map(|(k, s)| Some((k, s?))).collect();
    // What composition could not read (a reference to a file outside, a missing layer), known
    // once the prims have been visited.
    let mut unread: Vec<String> = stage
        .composition_errors()
        .iter()
        .map(|e| format!("{:.200}: left out", e.to_string()))
        .collect();
    unread.dedup();
    unread.truncate(8);
    unread.append(&mut warnings);
    scene.warnings = unread;
    Ok(Some(scene))
}

/// Whether the prim at `p` or an ancestor is `invisible`.
fn invisible(stage: &usd::Stage, p: &sdf::Path) -> Result<bool, String> {
    let mut at = Some(p.clone());
    while let Some(prim) = at {
        if prim.as_str() == "/" {
            break;
        }
        let visibility = attribute_value(stage, &prim, "visibility")?;
        if visibility.as_ref().and_then(token) == Some("invisible") {
            return Ok(true);
        }
        at = prim.parent();
    }
    Ok(false)
}

/// A token attribute of `p` or of its closest ancestor that has it (`purpose` is inherited).
fn inherited_token(stage: &usd::Stage, p: &sdf::Path, name: &str) -> Result<Option<String>, String> {
    let mut at = Some(p.clone());
    while let Some(prim) = at {
        if prim.as_str() == "/" {
            break;
        }
        if let Some(value) = attribute_value(stage, &prim, name)?
            && let Some(t) = token(&value)
            && t != "default"
        {
            return Ok(Some(t.to_owned()));
        }
        at = prim.parent();
    }
    Ok(None)
}

/// `p`'s transform to the stage's frame: the local transforms of it and its ancestors, up to
/// the first that resets the stack (glam's column vectors throughout).
fn world_transform(stage: &usd::Stage, p: &sdf::Path) -> Result<DMat4, String> {
    let mut world = DMat4::IDENTITY;
    let mut at = Some(p.clone());
    while let Some(prim) = at {
        if prim.as_str() == "/" {
            break;
        }
        let (local, resets) = local_transform(stage, &prim)?;
        world = local * world;
        if resets {
            break;
        }
        at = prim.parent();
    }
    Ok(world)
}

/// A prim's own transform from its `xformOpOrder` (UsdGeomXformable): the ops listed, the first
/// outermost (applied last to a point), `!invert!` inverting one, and whether it begins with
/// `!resetXformStack!` (its parents' transforms not applied). No order: identity. An op whose
/// value is missing or of another type is identity, as in USD.
fn local_transform(stage: &usd::Stage, prim: &sdf::Path) -> Result<(DMat4, bool), String> {
    let order: Vec<String> = match attribute_value(stage, prim, "xformOpOrder")? {
        Some(sdf::Value::TokenVec(ops)) => ops.iter().map(|t| t.as_str().to_owned()).collect(),
        Some(sdf::Value::StringVec(ops)) => ops,
        _ => return Ok((DMat4::IDENTITY, false)),
    };
    let mut local = DMat4::IDENTITY;
    let mut resets = false;
    for (i, op) in order.iter().enumerate() {
        if op == "!resetXformStack!" {
            // Only meaningful first; elsewhere USD reports an error: read as nothing.
            resets |= i == 0;
            continue;
        }
        let (inverted, name) = match op.strip_prefix("!invert!") {
            Some(name) => (true, name),
            None => (false, op.as_str()),
        };
        let value = attribute_value(stage, prim, name)?;
        let mut matrix = op_matrix(name, value.as_ref());
        if inverted {
            if matrix.determinant().abs() < 1e-300 {
                return Err(format!(
                    "{:.80}: the inverted op {name:.60} cannot be inverted",
                    prim.as_str()
                ));
            }
            matrix = matrix.inverse();
        }
        local *= matrix;
    }
    Ok((local, resets))
}

/// One xformOp's matrix (column vectors); identity where its value is missing or not a number
/// of the op's shape.
fn op_matrix(name: &str, value: Option<&sdf::Value>) -> DMat4 {
    let Some(value) = value else { return DMat4::IDENTITY };
    let kind = name.strip_prefix("xformOp:").unwrap_or(name);
    let kind = kind.split(':').next().unwrap_or(kind);
    let number = || scalar(value).unwrap_or(0.0);
    let three = |fallback: f64| vec3(value).map_or(DVec3::splat(fallback), DVec3::from);
    let axis = |axis: char, degrees: f64| match axis {
        'X' => DMat4::from_rotation_x(degrees.to_radians()),
        'Y' => DMat4::from_rotation_y(degrees.to_radians()),
        _ => DMat4::from_rotation_z(degrees.to_radians()),
    };
    match kind {
        "translate" => DMat4::from_translation(three(0.0)),
        "translateX" => DMat4::from_translation(DVec3::X * number()),
        "translateY" => DMat4::from_translation(DVec3::Y * number()),
        "translateZ" => DMat4::from_translation(DVec3::Z * number()),
        "scale" => DMat4::from_scale(three(1.0)),
        "scaleX" => DMat4::from_scale(DVec3::new(scalar(value).unwrap_or(1.0), 1.0, 1.0)),
        "scaleY" => DMat4::from_scale(DVec3::new(1.0, scalar(value).unwrap_or(1.0), 1.0)),
        "scaleZ" => DMat4::from_scale(DVec3::new(1.0, 1.0, scalar(value).unwrap_or(1.0))),
        "rotateX" | "rotateY" | "rotateZ" => axis(kind.chars().last().unwrap_or('Z'), number()),
        // `rotateXYZ`: about x first, then y, then z (a point's first rotation is the rightmost).
        k if k.len() == 9 && k.starts_with("rotate") => {
            let angles = three(0.0);
            let degrees = |c: char| match c {
                'X' => angles.x,
                'Y' => angles.y,
                _ => angles.z,
            };
            k[6..].chars().fold(DMat4::IDENTITY, |m, c| axis(c, degrees(c)) * m)
        }
        "orient" => {
            let q = match value {
                sdf::Value::Quatf(q) => DQuat::from_xyzw(q.x.into(), q.y.into(), q.z.into(), q.w.into()),
                sdf::Value::Quatd(q) => DQuat::from_xyzw(q.x, q.y, q.z, q.w),
                sdf::Value::Quath(q) => DQuat::from_xyzw(q.x.to_f64(), q.y.to_f64(), q.z.to_f64(), q.w.to_f64()),
                _ => DQuat::IDENTITY,
            };
            if q.is_finite() && q.length_squared() > 0.0 {
                DMat4::from_quat(q.normalize())
            } else {
                DMat4::IDENTITY
            }
        }
        // USD's matrices are row-major for row vectors: read column-major, their transposes.
        "transform" => match value {
            sdf::Value::Matrix4d(m) => DMat4::from_cols_array(&m.0),
            _ => DMat4::IDENTITY,
        },
        _ => DMat4::IDENTITY,
    }
}

/// The model from the scene read: materials with their textures, one primitive per mesh and
/// look.
fn build_model(
    path: &Path,
    scene: Scene,
    files: &Files,
    spending: &mut Spending,
    progress: &Progress,
) -> Result<Model, ModelError> {
    let cancelled = |_| ModelError::Cancelled {
        path: path.to_path_buf(),
    };
    let mut warnings = scene.warnings;
    let mut images = Vec::new();
    let mut textures = Textures {
        files,
        layers: &scene.layers,
        path,
        decoded: HashMap::new(),
    };
    let mut materials = Vec::new();
    for look in &scene.looks {
        let mut material = match &look.material {
            Some(name) => match scene.surfaces.get(name) {
                Some(surface) => material_of(name, surface, &mut textures, spending, &mut images, &mut warnings)?,
                None => Material::plaster(),
            },
            None if look.vertex_colours => Material::vertex_coloured_scan(),
            None => match look.display_colour {
                Some(c) => {
                    let [r, g, b] = c;
                    Material {
                        name: "display colour".into(),
                        base_color: [r, g, b, 1.0],
                        metallic: 0.0,
                        roughness: 0.6,
                        ..Material::default()
                    }
                }
                None => Material::plaster(),
            },
        };
        material.double_sided |= look.double_sided;
        materials.push(material);
    }
    progress.step(0.8).map_err(cancelled)?;

    let mut primitives = Vec::new();
    // Each shape made only when its turn comes, after the parts before it were charged.
    for mesh in scene
        .meshes
        .into_iter()
        .chain(scene.shapes.into_iter().map(ReadShape::into_mesh))
    {
        let mut by_look: HashMap<usize, Vec<u32>> = HashMap::new();
        for (triangle, look) in &mesh.triangles {
            by_look.entry(*look).or_default().extend_from_slice(triangle);
        }
        let mut looks: Vec<_> = by_look.into_iter().collect();
        looks.sort_by_key(|(look, _)| *look);
        for (look, indices) in looks {
            let what = || format!("mesh {:.80}", mesh.name);
            // The vertices this part uses, in the order it first names them.
            let mut remap = vec![u32::MAX; mesh.positions.len()];
            let mut used = Vec::new();
            let indices: Vec<u32> = indices
                .iter()
                .map(|&i| {
                    let slot = &mut remap[i as usize];
                    if *slot == u32::MAX {
                        *slot = used.len() as u32;
                        used.push(i as usize);
                    }
                    *slot
                })
                .collect();
            spending
                .charge_primitive(what)
                .and_then(|()| {
                    spending.charge_bytes(
                        what,
                        ResourceBudget::mesh_bytes(used.len() as u64, indices.len() as u64),
                    )
                })
                .map_err(|e| over_budget(path, e))?;
            // Display colours only where they are the look (USD shows them where no material
            // is bound); a constant one is the look's material colour, not a vertex tint.
            let colours = mesh.colours.as_ref().filter(|_| scene.looks[look].vertex_colours);
            let vertices = used
                .iter()
                .map(|&i| Vertex {
                    position: mesh.positions[i],
                    normal: mesh.normals.as_ref().map_or([0.0; 3], |n| n[i]),
                    tangent: [1.0, 0.0, 0.0, 1.0],
                    uv: {
                        // A second set where the material reads one, else the first again.
                        let [u, v] = mesh.uvs[0].as_ref().map_or([0.0; 2], |t| t[i]);
                        let [u1, v1] = mesh.uvs[1].as_ref().map_or([u, v], |t| t[i]);
                        [u, v, u1, v1]
                    },
                    color: colours.map_or([1.0; 4], |c| [c[i][0], c[i][1], c[i][2], 1.0]),
                    material: [1.0, 1.0],
                })
                .collect();
            let mut built = Mesh { vertices, indices };
            check_positions(&built, path, what)?;
            if mesh.normals.is_none() || built.vertices.iter().any(|v| v.normal == [0.0; 3]) {
                built.smooth_normals();
            }
            // A normal map is baked against MikkTSpace tangents, from the coordinates it is read
            // with; USD stores none.
            if mesh.uvs[0].is_some() {
                let uv = TangentUv::of(materials.get(look));
                generate_tangents(&mut built, uv.on(mesh.uvs[1].is_some()));
            }
            primitives.push(Primitive {
                mesh: built,
                material: look,
                is_floor: false,
                lods: Vec::new(),
            });
        }
    }
    for cloud in scene.clouds {
        let what = || format!("points {:.80}", cloud.name);
        let discs = spending
            .charge_primitive(what)
            .and_then(|()| point_cloud::charge_discs(spending, cloud.positions.len(), what))
            .map_err(|e| over_budget(path, e))?;
        let colours = cloud
            .colours
            .as_ref()
            .filter(|_| scene.looks[cloud.look].vertex_colours);
        let built = point_cloud::surfels_of(&cloud.positions, discs, |i| Vertex {
            position: cloud.positions[i],
            normal: cloud.normals.as_ref().map_or([0.0; 3], |n| n[i]),
            tangent: [1.0, 0.0, 0.0, 1.0],
            uv: [0.0; 4],
            color: colours.map_or([1.0; 4], |c| [c[i][0], c[i][1], c[i][2], 1.0]),
            material: [1.0, 1.0],
        });
        if built.indices.is_empty() {
            warnings.push(format!("{}: all its points in one place: left out", what()));
            continue;
        }
        check_positions(&built, path, what)?;
        primitives.push(Primitive {
            mesh: built,
            material: cloud.look,
            is_floor: false,
            lods: Vec::new(),
        });
    }
    progress.step(0.9).map_err(cancelled)?;
    // The cache let go, each image has one owner left: moved out, not copied.
    drop(textures);
    let images = images
        .into_iter()
        .map(|image| Arc::try_unwrap(image).unwrap_or_else(|shared| Image::clone(&shared)))
        .collect();
    let model = Model {
        name: model_name(path),
        primitives,
        materials,
        images,
        warnings,
        ..Model::default()
    };
    finish_mesh_model(model, path, spending)
}
