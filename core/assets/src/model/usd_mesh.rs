//! A USD `Mesh` prim read as triangles in the model's frame (the `usd` module's meshes).
//!
//! Polygons are fanned into triangles, holes left out; `leftHanded` meshes and mirroring
//! transforms keep their faces' fronts. Normals, texture coordinates and display colours by their
//! interpolation (constant, uniform, vertex, varying, face-varying), indexed or not; corners that
//! share all their values share a vertex. Texture coordinates: the primvars the mesh's material
//! reads (`usd_preview_surface::Surface::primvars`: first and second set), else the first found
//! of [`UV_NAMES`], else the first two-component primvar. A face subset (`GeomSubset` of family
//! `materialBind`) draws its faces with its own material; a mesh's material is its own binding or
//! its closest ancestor's. A `Points` prim is read as a cloud ([`read_points`]). A mesh that is malformed (face sizes that do not add up, a corner naming a point
//! it does not have) is left out with a warning, not the whole stage.
//!
//! **Panics**: none (indices are checked before use).

use std::collections::{HashMap, HashSet};

use glam::{DMat3, DMat4, DVec3};
use openusd::{sdf, usd};

use super::usd_preview_surface::{scalar, text, token, vec3};

/// One triangle mesh read from the stage, in metres with +Y up.
pub(super) struct ReadMesh {
    pub name: String,
    pub positions: Vec<[f32; 3]>,
    pub normals: Option<Vec<[f32; 3]>>,
    /// The first and second sets of texture coordinates (v down: USD's t as 1 − t).
    pub uvs: [Option<Vec<[f32; 2]>>; 2],
    pub colours: Option<Vec<[f32; 3]>>,
    /// Triangles, and the look each is drawn with (an index into the looks [`read_mesh`] was
    /// given).
    pub triangles: Vec<([u32; 3], usize)>,
}

/// One `Points` prim read from the stage, in metres with +Y up: a cloud, drawn as discs
/// (`point_cloud`). Its `widths` are not read: a disc's size comes from the gaps to its
/// neighbours, which closes a scanned surface whatever size the writer gave its points.
pub(super) struct ReadCloud {
    pub name: String,
    pub positions: Vec<[f32; 3]>,
    /// One a point, where the prim has them (a zero one: none, estimated from the neighbours).
    pub normals: Option<Vec<[f32; 3]>>,
    /// Linear, one a point, where its display colour varies over it.
    pub colours: Option<Vec<[f32; 3]>>,
    /// An index into the looks [`read_points`] was given.
    pub look: usize,
}

/// Reads the `Points` prim at `p` (transformed by `world` into the model's frame); `None` (with
/// a warning) where it has no point.
pub(super) fn read_points(
    stage: &usd::Stage,
    p: &sdf::Path,
    world: DMat4,
    looks: &mut Vec<Look>,
    warnings: &mut Vec<String>,
) -> Result<Option<ReadCloud>, String> {
    let name = p.as_str().to_owned();
    let points = attribute_value(stage, p, "points")?
        .as_ref()
        .and_then(vec3s)
        .unwrap_or_default();
    if points.is_empty() {
        warnings.push(format!("points {name:.80}: no points: left out"));
        return Ok(None);
    }
    let normals = match primvar(stage, p, "primvars:normals", Interpolation::Vertex, vec3s)? {
        Some(n) => Some(n),
        None => primvar(stage, p, "normals", Interpolation::Vertex, vec3s)?,
    };
    let display = primvar(stage, p, "primvars:displayColor", Interpolation::Constant, vec3s)?;
    let material = bound_material(stage, p)?;
    let varies = display
        .as_ref()
        .is_some_and(|d| d.interpolation != Interpolation::Constant);
    let look = look_index(
        looks,
        Look {
            display_colour: match (&material, &display) {
                (None, Some(d)) if !varies => d.values.first().map(|c| c.map(|v| v.clamp(0.0, 1.0) as f32)),
                _ => None,
            },
            vertex_colours: material.is_none() && varies,
            material,
            // A disc turned the wrong way by its estimated normal still draws.
            double_sided: true,
        },
    );
    let normal_matrix = DMat3::from_mat4(world).inverse().transpose();
    let cloud = ReadCloud {
        name,
        positions: points
            .iter()
            .map(|&q| world.transform_point3(DVec3::from(q)).as_vec3().to_array())
            .collect(),
        normals: normals.map(|n| {
            (0..points.len())
                .map(|i| {
                    // A cloud is one face whose corners are its points: each point its own value
                    // (vertex, varying, face-varying), or the one (constant, uniform).
                    n.at(0, i, i)
                        .and_then(|k| n.values.get(k as usize))
                        .map_or([0.0; 3], |v| {
                            (normal_matrix * DVec3::from(*v))
                                .normalize_or_zero()
                                .as_vec3()
                                .to_array()
                        })
                })
                .collect()
        }),
        colours: display.filter(|_| varies).map(|d| {
            (0..points.len())
                .map(|i| {
                    d.at(0, i, i)
                        .and_then(|k| d.values.get(k as usize))
                        .map_or([1.0; 3], |c| c.map(|v| v as f32))
                })
                .collect()
        }),
        look,
    };
    Ok(Some(cloud))
}

/// How a part of a mesh is drawn: its material's path (none: its display colour), and whether
/// both sides show.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Look {
    pub material: Option<String>,
    pub double_sided: bool,
    /// The mesh's constant display colour (linear), where it has no material.
    pub display_colour: Option<[f32; 3]>,
    /// Whether its display colour varies over it (then its vertices' colours).
    pub vertex_colours: bool,
}

/// The value of `p`'s attribute `name` at the stage's default time (else its earliest sample).
pub(super) fn attribute_value(stage: &usd::Stage, p: &sdf::Path, name: &str) -> Result<Option<sdf::Value>, String> {
    let attribute = stage.attribute(p.append_property(name).map_err(text)?).map_err(text)?;
    match attribute.get::<sdf::Value>().map_err(text)? {
        Some(v) => Ok(Some(v)),
        None => attribute.get_at::<sdf::Value>(usd::TimeCode::EARLIEST).map_err(text),
    }
}

/// A primvar: its values, their interpolation, and its indices where it has them.
struct Primvar<T> {
    values: Vec<T>,
    interpolation: Interpolation,
    indices: Option<Vec<i32>>,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Interpolation {
    Constant,
    Uniform,
    Vertex,
    FaceVarying,
}

impl<T> Primvar<T> {
    /// The value index at a corner (face `face`, corner `corner` of all corners, point `point`);
    /// `None` where the primvar does not reach it (too few values or indices).
    fn at(&self, face: usize, corner: usize, point: usize) -> Option<u32> {
        let slot = match self.interpolation {
            Interpolation::Constant => 0,
            Interpolation::Uniform => face,
            Interpolation::Vertex => point,
            Interpolation::FaceVarying => corner,
        };
        let index = match &self.indices {
            Some(indices) => usize::try_from(*indices.get(slot)?).ok()?,
            None => slot,
        };
        (index < self.values.len()).then_some(index as u32)
    }
}

/// Reads `p`'s attribute `name` (and its `interpolation`, its `:indices`) as a primvar with
/// `values` converting its value; `fallback` its interpolation where none is authored.
fn primvar<T>(
    stage: &usd::Stage,
    p: &sdf::Path,
    name: &str,
    fallback: Interpolation,
    values: impl Fn(&sdf::Value) -> Option<Vec<T>>,
) -> Result<Option<Primvar<T>>, String> {
    let Some(value) = attribute_value(stage, p, name)? else {
        return Ok(None);
    };
    let Some(values) = values(&value) else {
        return Ok(None);
    };
    let attribute = stage.attribute(p.append_property(name).map_err(text)?).map_err(text)?;
    let interpolation = match attribute
        .get_metadata::<sdf::Value>("interpolation")
        .map_err(text)?
        .as_ref()
        .and_then(token)
    {
        Some("constant") => Interpolation::Constant,
        Some("uniform") => Interpolation::Uniform,
        Some("vertex" | "varying") => Interpolation::Vertex,
        Some("faceVarying") => Interpolation::FaceVarying,
        _ => fallback,
    };
    let indices = match attribute_value(stage, p, &format!("{name}:indices"))? {
        Some(sdf::Value::IntVec(i)) => Some(i),
        _ => None,
    };
    Ok(Some(Primvar {
        values,
        interpolation,
        indices,
    }))
}

fn vec3s(value: &sdf::Value) -> Option<Vec<[f64; 3]>> {
    Some(match value {
        sdf::Value::Vec3fVec(v) => v.iter().map(|p| [p.x, p.y, p.z].map(f64::from)).collect(),
        sdf::Value::Vec3dVec(v) => v.iter().map(|p| [p.x, p.y, p.z]).collect(),
        sdf::Value::Vec3hVec(v) => v
            .iter()
            .map(|p| [p.x, p.y, p.z].map(|c| f64::from(c.to_f32())))
            .collect(),
        single => vec![vec3(single)?],
    })
}

fn vec2s(value: &sdf::Value) -> Option<Vec<[f32; 2]>> {
    Some(match value {
        sdf::Value::Vec2fVec(v) => v.iter().map(|p| [p.x, p.y]).collect(),
        sdf::Value::Vec2dVec(v) => v.iter().map(|p| [p.x as f32, p.y as f32]).collect(),
        sdf::Value::Vec2hVec(v) => v.iter().map(|p| [p.x.to_f32(), p.y.to_f32()]).collect(),
        _ => return None,
    })
}

fn ints(value: Option<sdf::Value>) -> Vec<i32> {
    match value {
        Some(sdf::Value::IntVec(v)) => v,
        _ => Vec::new(),
    }
}

/// The primvar holding texture coordinates: the one named `st` or as exporters name it, else
/// the first of two-component values.
const UV_NAMES: [&str; 5] = [
    "primvars:st",
    "primvars:st0",
    "primvars:UVMap",
    "primvars:uv",
    "primvars:map1",
];

/// Reads the mesh at `p` (transformed by `world` into the model's frame); `None` (with a
/// warning) where it has no face to draw. `primvars_of` gives the primvars a material's
/// textures read (by the material's path; first and second set).
pub(super) fn read_mesh(
    stage: &usd::Stage,
    p: &sdf::Path,
    world: DMat4,
    looks: &mut Vec<Look>,
    primvars_of: &mut dyn FnMut(&str) -> Vec<String>,
    warnings: &mut Vec<String>,
) -> Result<Option<ReadMesh>, String> {
    let name = p.as_str().to_owned();
    let bad = |what: &str| format!("mesh {name:.80}: {what}: left out");
    let Some(points) = attribute_value(stage, p, "points")?.as_ref().and_then(vec3s) else {
        warnings.push(bad("no points"));
        return Ok(None);
    };
    let counts = ints(attribute_value(stage, p, "faceVertexCounts")?);
    let indices = ints(attribute_value(stage, p, "faceVertexIndices")?);
    let holes: HashSet<i32> = ints(attribute_value(stage, p, "holeIndices")?).into_iter().collect();
    if counts.iter().map(|&c| i64::from(c.max(0))).sum::<i64>() != indices.len() as i64 {
        warnings.push(bad("its face sizes do not add up to its corners"));
        return Ok(None);
    }
    if let Some(&i) = indices.iter().find(|&&i| i < 0 || i as usize >= points.len()) {
        warnings.push(bad(&format!("a face names point {i}, of {}", points.len())));
        return Ok(None);
    }
    let left_handed = attribute_value(stage, p, "orientation")?.as_ref().and_then(token) == Some("leftHanded");
    let double_sided = attribute_value(stage, p, "doubleSided")?
        .as_ref()
        .and_then(scalar)
        .is_some_and(|d| d != 0.0);
    // Normals: the primvar wins over the attribute (whose interpolation defaults to vertex).
    let normals = match primvar(stage, p, "primvars:normals", Interpolation::Vertex, vec3s)? {
        Some(n) => Some(n),
        None => primvar(stage, p, "normals", Interpolation::Vertex, vec3s)?,
    };
    let display = primvar(stage, p, "primvars:displayColor", Interpolation::Constant, vec3s)?;

    // The look of each face: the mesh's binding, or a face subset's.
    let mesh_material = bound_material(stage, p)?;
    let base_look = |material: Option<String>| Look {
        display_colour: match (&material, &display) {
            (None, Some(d)) if d.interpolation == Interpolation::Constant => {
                d.values.first().map(|c| c.map(|v| v.clamp(0.0, 1.0) as f32))
            }
            _ => None,
        },
        vertex_colours: material.is_none()
            && display
                .as_ref()
                .is_some_and(|d| d.interpolation != Interpolation::Constant),
        material,
        double_sided,
    };
    let mut face_look = vec![look_index(looks, base_look(mesh_material.clone())); counts.len()];
    let mut materials: Vec<String> = mesh_material.into_iter().collect();
    for child in stage.prim(p.clone()).map_err(text)?.children().map_err(text)? {
        let child = child.path().clone();
        if stage
            .prim(child.clone())
            .map_err(text)?
            .type_name()
            .map_err(text)?
            .as_ref()
            .map(|t| t.as_str())
            != Some("GeomSubset")
        {
            continue;
        }
        let family = attribute_value(stage, &child, "familyName")?;
        let element = attribute_value(stage, &child, "elementType")?;
        if family.as_ref().and_then(token) != Some("materialBind")
            || element.as_ref().and_then(token).is_some_and(|e| e != "face")
        {
            continue;
        }
        let Some(material) = direct_binding(stage, &child)? else {
            continue;
        };
        let look = look_index(looks, base_look(Some(material.clone())));
        materials.push(material);
        for face in ints(attribute_value(stage, &child, "indices")?) {
            if let Some(slot) = usize::try_from(face).ok().and_then(|f| face_look.get_mut(f)) {
                *slot = look;
            }
        }
    }

    // Texture coordinates: where the first material whose textures name primvars says, and where
    // the sets of the others' differ, with a warning (a model's sets are per mesh).
    let mut wanted: Option<Vec<String>> = None;
    for material in &materials {
        let names = primvars_of(material);
        if names.is_empty() {
            continue;
        }
        match &wanted {
            None => wanted = Some(names),
            Some(first) if names.iter().zip(first).any(|(a, b)| a != b) => warnings.push(format!(
                "mesh {name:.80}: its materials read different texture coordinates ({:.40} and {:.40}): {:.80} reads the first material's",
                first.join(", "),
                names.join(", "),
                material
            )),
            Some(_) => {}
        }
    }
    let wanted = wanted.unwrap_or_default();
    let named = |n: &String| primvar(stage, p, &format!("primvars:{n}"), Interpolation::FaceVarying, vec2s);
    let mut first_set = match wanted.first() {
        Some(n) => named(n)?,
        None => None,
    };
    if first_set.is_none() {
        first_set = texture_coordinates(stage, p)?;
        if let (Some(n), Some(_)) = (wanted.first(), &first_set) {
            warnings.push(format!(
                "mesh {name:.80}: its material reads texture coordinates {n:.40}, which it lacks: its first set read instead"
            ));
        }
    }
    let second_set = match wanted.get(1) {
        Some(n) => {
            let set = named(n)?;
            if set.is_none() {
                warnings.push(format!(
                    "mesh {name:.80}: its material reads texture coordinates {n:.40}, which it lacks: its first set read instead"
                ));
            }
            set
        }
        None => None,
    };
    let uvs = [first_set, second_set];

    // Corners to vertices: one per distinct (point, normal, uv, colour) value.
    let normal_matrix = DMat3::from_mat4(world).inverse().transpose();
    let flip = left_handed != (DMat3::from_mat4(world).determinant() < 0.0);
    let mut welded: HashMap<[u32; 5], u32> = HashMap::new();
    let mut mesh = ReadMesh {
        name: name.clone(),
        positions: Vec::new(),
        normals: normals.as_ref().map(|_| Vec::new()),
        uvs: [0, 1].map(|k| uvs[k].as_ref().map(|_| Vec::new())),
        colours: display.as_ref().map(|_| Vec::new()),
        triangles: Vec::new(),
    };
    let mut corner = 0usize;
    let mut face_corners = Vec::new();
    for (face, &n) in counts.iter().enumerate() {
        let n = n.max(0) as usize;
        let first = corner;
        corner += n;
        if n < 3 || holes.contains(&(face as i32)) {
            continue;
        }
        face_corners.clear();
        for (c, &point) in indices.iter().enumerate().skip(first).take(n) {
            let point = point as usize;
            let key = [
                point as u32,
                normals.as_ref().and_then(|v| v.at(face, c, point)).unwrap_or(u32::MAX),
                uvs[0].as_ref().and_then(|v| v.at(face, c, point)).unwrap_or(u32::MAX),
                display.as_ref().and_then(|v| v.at(face, c, point)).unwrap_or(u32::MAX),
                uvs[1].as_ref().and_then(|v| v.at(face, c, point)).unwrap_or(u32::MAX),
            ];
            let next = mesh.positions.len() as u32;
            let vertex = *welded.entry(key).or_insert_with(|| {
                let position = world.transform_point3(DVec3::from(points[point]));
                mesh.positions.push(position.as_vec3().to_array());
                if let (Some(out), Some(n)) = (&mut mesh.normals, &normals) {
                    let normal = n.values.get(key[1] as usize).map_or(DVec3::ZERO, |v| DVec3::from(*v));
                    out.push((normal_matrix * normal).normalize_or_zero().as_vec3().to_array());
                }
                for (k, slot) in [(0, 2), (1, 4)] {
                    if let (Some(out), Some(t)) = (&mut mesh.uvs[k], &uvs[k]) {
                        // USD's t runs up from the image's bottom; glTF's v down from its top.
                        let [s, t] = t.values.get(key[slot] as usize).copied().unwrap_or([0.0, 0.0]);
                        out.push([s, 1.0 - t]);
                    }
                }
                if let (Some(out), Some(d)) = (&mut mesh.colours, &display) {
                    out.push(d.values.get(key[3] as usize).map_or([1.0; 3], |c| c.map(|v| v as f32)));
                }
                next
            });
            face_corners.push(vertex);
        }
        for k in 1..n - 1 {
            let (a, b, c) = (face_corners[0], face_corners[k], face_corners[k + 1]);
            let triangle = if flip { [a, c, b] } else { [a, b, c] };
            mesh.triangles.push((triangle, face_look[face]));
        }
    }
    if mesh.triangles.is_empty() {
        warnings.push(bad("no face with three corners"));
        return Ok(None);
    }
    Ok(Some(mesh))
}

/// The mesh's texture coordinates where its material names none: the first primvar of
/// [`UV_NAMES`] it has, else its first primvar of two-component values.
fn texture_coordinates(stage: &usd::Stage, p: &sdf::Path) -> Result<Option<Primvar<[f32; 2]>>, String> {
    for uv_name in UV_NAMES {
        if let Some(set) = primvar(stage, p, uv_name, Interpolation::FaceVarying, vec2s)? {
            return Ok(Some(set));
        }
    }
    let attributes = stage.prim(p.clone()).map_err(text)?.property_names().map_err(text)?;
    for property in attributes {
        let property = property.as_str();
        if property.starts_with("primvars:")
            && !property.ends_with(":indices")
            && let Some(set) = primvar(stage, p, property, Interpolation::FaceVarying, vec2s)?
        {
            return Ok(Some(set));
        }
    }
    Ok(None)
}

/// The look of a prim drawn in one piece without colours of its own per vertex (a primitive
/// shape, `usd_shapes`): its bound material, else its constant display colour; its index among
/// `looks`, added where new.
pub(super) fn look_of(
    stage: &usd::Stage,
    p: &sdf::Path,
    looks: &mut Vec<Look>,
    double_sided: bool,
) -> Result<usize, String> {
    let material = bound_material(stage, p)?;
    let display = primvar(stage, p, "primvars:displayColor", Interpolation::Constant, vec3s)?;
    let display_colour = match (&material, &display) {
        (None, Some(d)) => d.values.first().map(|c| c.map(|v| v.clamp(0.0, 1.0) as f32)),
        _ => None,
    };
    Ok(look_index(
        looks,
        Look {
            material,
            double_sided,
            display_colour,
            vertex_colours: false,
        },
    ))
}

/// The index of `look` among `looks`, added where new.
fn look_index(looks: &mut Vec<Look>, look: Look) -> usize {
    looks.iter().position(|l| *l == look).unwrap_or_else(|| {
        looks.push(look);
        looks.len() - 1
    })
}

/// The material bound to `p` directly or through its closest ancestor with a binding.
fn bound_material(stage: &usd::Stage, p: &sdf::Path) -> Result<Option<String>, String> {
    let mut at = Some(p.clone());
    while let Some(prim) = at {
        if prim.as_str() == "/" {
            break;
        }
        if let Some(material) = direct_binding(stage, &prim)? {
            return Ok(Some(material));
        }
        at = prim.parent();
    }
    Ok(None)
}

/// `p`'s own all-purpose binding (`material:binding`, else the full-render one).
fn direct_binding(stage: &usd::Stage, p: &sdf::Path) -> Result<Option<String>, String> {
    for name in ["material:binding", "material:binding:full"] {
        let relationship = stage
            .relationship(p.append_property(name).map_err(text)?)
            .map_err(text)?;
        if let Some(target) = relationship.targets().map_err(text)?.into_iter().next() {
            return Ok(Some(target.as_str().to_owned()));
        }
    }
    Ok(None)
}
