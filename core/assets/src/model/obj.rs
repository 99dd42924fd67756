//! Wavefront OBJ with its MTL materials and their colour textures: the "OBJ zip" many museum
//! download pages and photogrammetry tools offer beside (or instead of) glTF.
//!
//! Parsed by `tobj` (a well-kept port of tinyobjloader; polygons triangulated, one index per
//! corner). Read as metres with +Y up (OBJ's usual convention, and glTF's). From the MTL: the
//! diffuse colour `Kd` (taken as linear, as glTF converters do; white where a `map_Kd` texture
//! gives the colour), `map_Kd`, and the dissolve `d` (blended below 1). Bump and specular maps
//! are not read; the surface is a matte dielectric (scans bake their look into the colour).
//! Vertex colours (`v x y z r g b`, as scanners and MeshLab write them) are sRGB, like a PLY's.
//! Texture coordinates are flipped to glTF's top-left origin.
//!
//! **Files**: the MTL libraries and textures are opened only inside the OBJ's folder
//! ([`super::resolve_inside`]), regular files only, within the budget; one that is missing or
//! damaged leaves its material or texture out with a warning, as a viewer does. **Budget**:
//! textures are charged from their headers before decoding, meshes before they are built.
//! **Panics**: none escape (a parser panic becomes the file's error).

use std::cell::RefCell;
use std::path::Path;

use super::loader::{
    ModelError, check_positions, finish_mesh_model, model_name, over_budget, read_model_file, resolve_inside,
};
use super::mesh_file::{MeshFormat, scan_colour};
use super::{AlphaMode, Image, Material, Mesh, Model, Primitive, TextureRef, Vertex};
use crate::budget::{ResourceBudget, Spending};
use crate::progress::Progress;

/// Loads `path` (an `.obj`) with the materials and textures beside it.
pub fn load(path: &Path, budget: ResourceBudget, progress: &Progress) -> Result<Model, ModelError> {
    let cancelled = |_| ModelError::Cancelled {
        path: path.to_path_buf(),
    };
    progress.step(0.0).map_err(cancelled)?;
    let folder = path.parent().unwrap_or(Path::new("."));
    let mut spending = Spending::new(budget);
    let bytes = read_model_file(path, &spending)?;
    let warnings = RefCell::new(Vec::new());
    // An MTL library: inside the folder, a regular file, within the budget; else a warning.
    let library = |name: &Path| -> tobj::MTLLoadResult {
        let name = name.to_string_lossy();
        let read = resolve_inside(folder, &name).and_then(|file| {
            phantogram_files::read_regular_file(&file, budget.memory_bytes).map_err(|e| e.to_string())
        });
        match read {
            Ok(mtl) => tobj::load_mtl_buf(&mut mtl.as_slice()),
            Err(message) => {
                warnings.borrow_mut().push(format!(
                    "material library {name:.80} not read ({message}): shown in a plain material"
                ));
                Err(tobj::LoadError::OpenFileFailed)
            }
        }
    };
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let parsed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        tobj::load_obj_buf(&mut bytes.as_slice(), &options, library)
    }))
    .map_err(|_| "the OBJ reader failed on damaged data".to_owned())
    .and_then(|r| r.map_err(|e| e.to_string()));
    drop(bytes);
    let (meshes, materials) = parsed.map_err(|message| ModelError::Parse {
        path: path.to_path_buf(),
        format: MeshFormat::Obj.name(),
        message,
    })?;
    let mut warnings = warnings.into_inner();
    let materials = materials.unwrap_or_default();
    progress.step(0.2).map_err(cancelled)?;

    let mut images = Vec::new();
    let mut model_materials: Vec<Material> = materials
        .iter()
        .map(|m| material(m, folder, path, &mut spending, &mut images, &mut warnings))
        .collect::<Result<_, _>>()?;
    let plain = model_materials.len();
    model_materials.push(Material::plaster());
    // Without a material, a scan with vertex colours shows them as they are (white, matte),
    // as a coloured PLY does; without either, plaster.
    let coloured = model_materials.len();
    model_materials.push(Material::vertex_coloured_scan());
    progress.step(0.6).map_err(cancelled)?;

    let mut primitives = Vec::new();
    for m in &meshes {
        let mesh = &m.mesh;
        let count = mesh.positions.len() / 3;
        spending
            .charge_primitive(|| format!("object {:.60}", m.name))
            .and_then(|()| {
                spending.charge_bytes(
                    || format!("object {:.60}", m.name),
                    ResourceBudget::mesh_bytes(count as u64, mesh.indices.len() as u64),
                )
            })
            .map_err(|e| over_budget(path, e))?;
        if let Some(&bad) = mesh.indices.iter().find(|&&i| i as usize >= count) {
            return Err(ModelError::Data {
                path: path.to_path_buf(),
                what: format!("object {:.60}", m.name),
                message: format!("a face names vertex {bad}, of {count}"),
            });
        }
        let has_normals = mesh.normals.len() == mesh.positions.len();
        let vertices = (0..count)
            .map(|i| Vertex {
                position: get(&mesh.positions, i, 3).map_or([0.0; 3], |p| [p[0], p[1], p[2]]),
                normal: if has_normals {
                    get(&mesh.normals, i, 3).map_or([0.0; 3], |n| [n[0], n[1], n[2]])
                } else {
                    [0.0; 3]
                },
                tangent: [1.0, 0.0, 0.0, 1.0],
                // OBJ's v runs up from the image's bottom; glTF's down from its top.
                uv: get(&mesh.texcoords, i, 2).map_or([0.0; 4], |t| [t[0], 1.0 - t[1], 0.0, 0.0]),
                // `v x y z r g b`: a scan's colours, sRGB-encoded like a PLY's (MeshLab and
                // photogrammetry tools write the same 8-bit values, as 0–1).
                color: get(&mesh.vertex_color, i, 3).map_or([1.0; 4], |c| scan_colour([c[0], c[1], c[2], 1.0])),
                material: [1.0, 1.0],
            })
            .collect();
        let mut built = Mesh {
            vertices,
            indices: mesh.indices.clone(),
        };
        check_positions(&built, path, || format!("object {:.60}", m.name))?;
        if !has_normals || built.vertices.iter().any(|v| v.normal == [0.0; 3]) {
            built.smooth_normals();
        } else {
            for v in &mut built.vertices {
                v.normal = glam::Vec3::from(v.normal).normalize_or(glam::Vec3::Z).to_array();
            }
        }
        primitives.push(Primitive {
            mesh: built,
            material: mesh
                .material_id
                .filter(|&i| i < plain)
                .unwrap_or(if mesh.vertex_color.is_empty() { plain } else { coloured }),
            is_floor: false,
            lods: Vec::new(),
        });
    }
    progress.step(0.9).map_err(cancelled)?;
    let model = Model {
        name: model_name(path),
        primitives,
        materials: model_materials,
        images,
        warnings,
        ..Model::default()
    };
    finish_mesh_model(model, path, &spending)
}

/// Row `i` of `n` values in `data`, if there.
fn get(data: &[f32], i: usize, n: usize) -> Option<&[f32]> {
    data.get(n * i..n * i + n)
}

/// One MTL material, its `map_Kd` decoded into `images` (or left out with a warning).
fn material(
    m: &tobj::Material,
    folder: &Path,
    path: &Path,
    spending: &mut Spending,
    images: &mut Vec<Image>,
    warnings: &mut Vec<String>,
) -> Result<Material, ModelError> {
    let texture = match &m.diffuse_texture {
        Some(name) => texture(name, folder, path, spending, images, warnings)?,
        None => None,
    };
    let kd = m.diffuse.unwrap_or([0.8; 3]);
    let alpha = m.dissolve.unwrap_or(1.0).clamp(0.0, 1.0);
    let colour = if texture.is_some() {
        [1.0; 3]
    } else {
        kd.map(|c| c.clamp(0.0, 1.0))
    };
    Ok(Material {
        name: m.name.clone(),
        base_color: [colour[0], colour[1], colour[2], alpha],
        metallic: 0.0,
        roughness: 0.8,
        alpha: if alpha < 1.0 {
            AlphaMode::Blend
        } else {
            AlphaMode::Opaque
        },
        base_color_texture: texture.map(|image| TextureRef {
            image,
            tex_coord: 0,
            transform: Default::default(),
            sampler: Default::default(),
        }),
        ..Material::default()
    })
}

/// A texture named in an MTL, decoded; `None` (and a warning) when it cannot be read. The name
/// may carry options before the file (`-s 1 1 1 skin.jpg`): the whole text is tried, then its
/// last word.
fn texture(
    name: &str,
    folder: &Path,
    path: &Path,
    spending: &mut Spending,
    images: &mut Vec<Image>,
    warnings: &mut Vec<String>,
) -> Result<Option<usize>, ModelError> {
    // A texture several materials share is decoded once.
    if let Some(known) = images.iter().position(|i| i.name == name) {
        return Ok(Some(known));
    }
    let memory = spending.budget().memory_bytes;
    let read = |candidate: &str| {
        resolve_inside(folder, candidate)
            .and_then(|file| phantogram_files::read_regular_file(&file, memory).map_err(|e| e.to_string()))
    };
    let last_word = name.split_ascii_whitespace().last().unwrap_or(name);
    let raw = match read(name).or_else(|first| read(last_word).map_err(|_| first)) {
        Ok(raw) => raw,
        Err(message) => {
            warnings.push(format!("texture {name:.80} not read ({message}): left out"));
            return Ok(None);
        }
    };
    Ok(
        super::file_texture::decode(name, &raw, path, spending, warnings)?.map(|image| {
            images.push(image);
            images.len() - 1
        }),
    )
}
