//! Scans published as meshes rather than glTF: STL (`stl`) and PLY (`ply`), and point clouds as
//! text (`.xyz`, `.pts`: `xyz`, metres with +Z up) or laser scans in LAS/LAZ (`las`) or E57
//! (`e57`, the same frame), loaded into a [`Model`] of one primitive; OBJ with its materials is
//! `obj`'s, reached through the same [`MeshFormat`].
//!
//! **Conventions** (neither format states them): STL is read as millimetres with +Z up, as 3D
//! printing writes it (Scan the World's museum scans, museums' "download for printing"), and
//! turned into glTF's metres with +Y up; PLY is read as metres with +Y up, as the Stanford scans
//! and most scanner software write it. Either way the artifact is fitted to the diorama unless
//! the user asks for true size, so a wrong guess changes only true size.
//!
//! **Surface**: an STL soup is welded (corners at the same position become one vertex) and given
//! smooth, area-weighted normals, so a scan is not drawn as facets; a PLY keeps its vertices and
//! its normals where it has all three components, else gets the same smooth normals. PLY colours
//! (sRGB, as scanners write them) become the vertex colours, over a white material; without colour
//! the material is a matte, light stone-like grey (plaster: a cast's colour, not a claim about the
//! object). A PLY with vertices and no faces is a point cloud, drawn as small discs
//! (`point_cloud`). **Budget**: the parsers never allocate more than the file's size implies; the mesh
//! built from it is charged before it is made. **Panics**: none.

use std::collections::HashMap;
use std::path::Path;

use glam::{Mat4, Vec3};

use super::loader::{ModelError, check_positions, model_name, over_budget, read_model_file};
use super::{Material, Mesh, Model, Primitive, Vertex, e57, las, ply, point_cloud, stl, usd_files, xyz};
use crate::budget::{ResourceBudget, Spending};
use crate::progress::Progress;

/// What a parser hands back: positions, optional per-vertex normals and colours (0–1, sRGB),
/// triangles as index triples.
#[derive(Debug, Default, PartialEq)]
pub struct Soup {
    pub positions: Vec<[f32; 3]>,
    pub normals: Option<Vec<[f32; 3]>>,
    pub colors: Option<Vec<[f32; 4]>>,
    pub indices: Vec<u32>,
}

impl Soup {
    /// Unshared triangles: three positions each.
    pub fn triangles(positions: Vec<[f32; 3]>) -> Soup {
        let indices = (0..positions.len() as u32).collect();
        Soup {
            positions,
            indices,
            ..Soup::default()
        }
    }
}

/// The mesh formats read besides glTF, by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    Stl,
    Ply,
    /// Wavefront OBJ, with its MTL materials (the `obj` module).
    Obj,
    /// A point cloud as text, a point a line: `.xyz` or Leica's `.pts` (the `xyz` module).
    Xyz,
    /// A point cloud in ASPRS LAS or its compressed form LAZ (the `las` module).
    Las,
    /// Laser scans in ASTM E57 (the `e57` module).
    E57,
    /// A USD package (`.usdz`: the root layer and its files in one zip; the `usd` module).
    Usdz,
    /// A USD layer alone (`.usd`, `.usda`, `.usdc`), with the files beside it.
    Usd,
}

impl MeshFormat {
    /// The format a file name's extension says, if one of these.
    pub fn of(path: &Path) -> Option<MeshFormat> {
        let extension = path.extension()?.to_str()?.to_ascii_lowercase();
        match extension.as_str() {
            "stl" => Some(MeshFormat::Stl),
            "ply" => Some(MeshFormat::Ply),
            "obj" => Some(MeshFormat::Obj),
            "xyz" | "pts" => Some(MeshFormat::Xyz),
            "las" | "laz" => Some(MeshFormat::Las),
            "e57" => Some(MeshFormat::E57),
            "usdz" => Some(MeshFormat::Usdz),
            "usd" | "usda" | "usdc" => Some(MeshFormat::Usd),
            _ => None,
        }
    }

    /// The format of a file's bytes, if one of these (a share may arrive without its name): PLY
    /// by its first line, STL by its first word or by a binary file's exact size, OBJ by its
    /// first statement that is not a comment (a vertex, a group, a material library…).
    pub fn sniff(bytes: &[u8]) -> Option<MeshFormat> {
        if usd_files::is_package(bytes) {
            return Some(MeshFormat::Usdz);
        }
        if usd_files::is_layer(bytes) {
            return Some(MeshFormat::Usd);
        }
        if bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n") {
            return Some(MeshFormat::Ply);
        }
        if las::recognises(bytes) {
            return Some(MeshFormat::Las);
        }
        if e57::recognises(bytes) {
            return Some(MeshFormat::E57);
        }
        if stl::recognises(bytes) {
            return Some(MeshFormat::Stl);
        }
        let head = &bytes[..bytes.len().min(4096)];
        let statement = head
            .split(|&b| b == b'\n')
            .map(<[u8]>::trim_ascii)
            .find(|line| !line.is_empty() && !line.starts_with(b"#"))?;
        let keyword = statement.split(u8::is_ascii_whitespace).next()?;
        const OBJ: [&[u8]; 9] = [b"v", b"vt", b"vn", b"f", b"o", b"g", b"s", b"mtllib", b"usemtl"];
        if OBJ.contains(&keyword) && statement.len() > keyword.len() {
            return Some(MeshFormat::Obj);
        }
        xyz::recognises(bytes).then_some(MeshFormat::Xyz)
    }

    /// What the format is called in messages to the user.
    pub fn name(self) -> &'static str {
        match self {
            MeshFormat::Stl => "STL",
            MeshFormat::Ply => "PLY",
            MeshFormat::Obj => "OBJ",
            MeshFormat::Xyz => "point cloud",
            MeshFormat::Las => "LAS",
            MeshFormat::E57 => "E57",
            MeshFormat::Usdz | MeshFormat::Usd => "USD",
        }
    }

    pub fn extension(self) -> &'static str {
        match self {
            MeshFormat::Stl => "stl",
            MeshFormat::Ply => "ply",
            MeshFormat::Obj => "obj",
            MeshFormat::Xyz => "xyz",
            // LAZ too: the header, not the name, says whether the points are compressed.
            MeshFormat::Las => "las",
            MeshFormat::E57 => "e57",
            MeshFormat::Usdz => "usdz",
            // The reader tells the text format from the binary one by its first bytes.
            MeshFormat::Usd => "usd",
        }
    }
}

/// Loads an STL or PLY file (`format`) into a model of one primitive, or an OBJ with its
/// materials, within `budget`.
pub fn load(path: &Path, format: MeshFormat, budget: ResourceBudget, progress: &Progress) -> Result<Model, ModelError> {
    match format {
        MeshFormat::Obj => return super::obj::load(path, budget, progress),
        MeshFormat::Usdz | MeshFormat::Usd => return super::usd::load(path, budget, progress),
        _ => {}
    }
    let cancelled = |_| ModelError::Cancelled {
        path: path.to_path_buf(),
    };
    progress.step(0.0).map_err(cancelled)?;
    let mut spending = Spending::new(budget);
    let bytes = read_model_file(path, &spending)?;
    progress.step(0.1).map_err(cancelled)?;
    // Decoding a large scan takes seconds: its share of the progress is reported as it goes.
    let keep_going = |share: f64| progress.step(0.1 + 0.4 * share as f32).is_ok();
    let mut soup = match parse(format, bytes, keep_going) {
        Ok(Some(soup)) => soup,
        Ok(None) => {
            return Err(ModelError::Cancelled {
                path: path.to_path_buf(),
            });
        }
        Err(message) => {
            return Err(ModelError::Parse {
                path: path.to_path_buf(),
                format: format.name(),
                message,
            });
        }
    };
    progress.step(0.5).map_err(cancelled)?;
    if format == MeshFormat::Stl {
        soup = weld(soup);
    }
    let cloud = soup.indices.is_empty() && !soup.positions.is_empty();
    let mut mesh = if cloud {
        let discs = spending
            .charge_primitive(|| "the point cloud".to_owned())
            .and_then(|()| {
                point_cloud::charge_discs(&mut spending, soup.positions.len(), || "the point cloud".to_owned())
            })
            .map_err(|e| over_budget(path, e))?;
        // Thinned before the points become vertices (80 bytes each, against the file's 12 or
        // so): only the kept ones are made.
        point_cloud::surfels_of(&soup.positions, discs, |i| vertex(&soup, i))
    } else {
        spending
            .charge_primitive(|| "the mesh".to_owned())
            .and_then(|()| {
                spending.charge_bytes(
                    || "the mesh".to_owned(),
                    ResourceBudget::mesh_bytes(soup.positions.len() as u64, soup.indices.len() as u64),
                )
            })
            .map_err(|e| over_budget(path, e))?;
        build(soup)
    };
    // Nothing to draw: every triangle degenerate, or a cloud whose points all coincide.
    let flat = mesh.bounds().is_none_or(|b| b.max == b.min);
    if mesh.indices.is_empty() || flat {
        return Err(ModelError::Empty {
            path: path.to_path_buf(),
        });
    }
    match format {
        // Millimetres, +Z up → metres, +Y up (a quarter turn about x).
        MeshFormat::Stl => {
            mesh.transform(Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2) * Mat4::from_scale(Vec3::splat(0.001)))
        }
        // Metres, +Z up, as scanners write them.
        MeshFormat::Xyz | MeshFormat::Las | MeshFormat::E57 => {
            mesh.transform(Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2))
        }
        _ => {}
    }
    // Checked in the model's frame, as glTF's vertices are after their node transforms.
    check_positions(&mesh, path, || "the mesh".to_owned())?;
    progress.step(0.9).map_err(cancelled)?;
    let coloured = mesh.vertices.iter().any(|v| v.color != [1.0; 4]);
    let mut material = if coloured {
        Material::vertex_coloured_scan()
    } else {
        Material::plaster()
    };
    // A disc turned the wrong way by its estimated normal still draws.
    material.double_sided = cloud;
    Ok(Model {
        name: model_name(path),
        primitives: vec![Primitive {
            mesh,
            material: 0,
            is_floor: false,
            lods: Vec::new(),
        }],
        materials: vec![material],
        ..Model::default()
    })
}

/// The soup in a file's `bytes` (STL, PLY, a cloud as text, LAS/LAZ or E57); `Ok(None)` when a
/// scan's decoding was stopped by `keep_going`. The bytes are let go when this returns, before
/// the mesh is built.
fn parse(format: MeshFormat, bytes: Vec<u8>, keep_going: impl FnMut(f64) -> bool) -> Result<Option<Soup>, String> {
    match format {
        MeshFormat::Las => las::parse(bytes, keep_going),
        MeshFormat::E57 => e57::parse(bytes, keep_going),
        MeshFormat::Stl => stl::parse(&bytes).map(Some),
        MeshFormat::Xyz => xyz::parse(&bytes).map(Some),
        _ => ply::parse(&bytes).map(Some),
    }
}

/// Corners at exactly the same position become one vertex (an STL soup's triangles share none).
fn weld(soup: Soup) -> Soup {
    let mut index_of: HashMap<[u32; 3], u32> = HashMap::with_capacity(soup.positions.len() / 4);
    let mut positions = Vec::with_capacity(soup.positions.len() / 4);
    let indices = soup
        .indices
        .iter()
        .map(|&i| {
            let p = soup.positions[i as usize];
            *index_of.entry(p.map(f32::to_bits)).or_insert_with(|| {
                positions.push(p);
                (positions.len() - 1) as u32
            })
        })
        .collect();
    Soup {
        positions,
        indices,
        ..Soup::default()
    }
}

/// The vertices and triangles of a soup; normals from the file when it has them, else smooth.
fn build(soup: Soup) -> Mesh {
    let mut mesh = Mesh {
        vertices: (0..soup.positions.len()).map(|i| vertex(&soup, i)).collect(),
        indices: soup.indices,
    };
    // Degenerate triangles (repeated corners, common in scans) draw nothing and bend smooth
    // normals towards nothing: left out.
    let keep: Vec<u32> = mesh
        .indices
        .chunks_exact(3)
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
        .flatten()
        .copied()
        .collect();
    mesh.indices = keep;
    if soup.normals.is_none() || mesh.vertices.iter().any(|v| v.normal == [0.0; 3]) {
        mesh.smooth_normals();
    }
    mesh
}

/// A scan's vertex colour, sRGB-encoded as scanners write it (0–1, alpha linear), made linear.
pub(super) fn scan_colour(c: [f32; 4]) -> [f32; 4] {
    let linear = phantogram_geometry::srgb::to_linear;
    [linear(c[0]), linear(c[1]), linear(c[2]), c[3]]
}

/// A soup's `i`-th vertex: its normal where given (else zero), its sRGB colour linearised (else
/// white).
fn vertex(soup: &Soup, i: usize) -> Vertex {
    Vertex {
        position: soup.positions[i],
        normal: soup
            .normals
            .as_ref()
            .and_then(|n| n.get(i))
            .map_or([0.0; 3], |n| Vec3::from(*n).normalize_or_zero().to_array()),
        tangent: [1.0, 0.0, 0.0, 1.0],
        uv: [0.0; 4],
        color: soup
            .colors
            .as_ref()
            .and_then(|c| c.get(i))
            .map_or([1.0; 4], |&c| scan_colour(c)),
        material: [1.0, 1.0],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn welding_shares_equal_corners_and_keeps_the_triangles() {
        let square = Soup::triangles(vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ]);
        let welded = weld(square);
        assert_eq!(welded.positions.len(), 4);
        assert_eq!(welded.indices, [0, 1, 2, 0, 2, 3]);
    }

    #[test]
    fn formats_are_known_by_name_and_by_content() {
        assert_eq!(MeshFormat::of(Path::new("bust.STL")), Some(MeshFormat::Stl));
        assert_eq!(MeshFormat::of(Path::new("scan.ply")), Some(MeshFormat::Ply));
        assert_eq!(MeshFormat::of(Path::new("scan.glb")), None);
        assert_eq!(MeshFormat::sniff(b"ply\nformat ascii 1.0\n"), Some(MeshFormat::Ply));
        assert_eq!(MeshFormat::sniff(b"  solid bust\n"), Some(MeshFormat::Stl));
        let mut binary = vec![0u8; 84 + 50];
        binary[80] = 1;
        assert_eq!(MeshFormat::sniff(&binary), Some(MeshFormat::Stl));
        binary.push(0);
        assert_eq!(
            MeshFormat::sniff(&binary),
            None,
            "a size that does not match is not STL"
        );
        assert_eq!(MeshFormat::sniff(b"glTF"), None);
        assert_eq!(MeshFormat::of(Path::new("statue.obj")), Some(MeshFormat::Obj));
        assert_eq!(
            MeshFormat::sniff(b"# Exported by a scanner\nmtllib statue.mtl\nv 0 0 0\n"),
            Some(MeshFormat::Obj)
        );
        assert_eq!(MeshFormat::sniff(b"v 0 0 0\nv 1 0 0\n"), Some(MeshFormat::Obj));
        assert_eq!(
            MeshFormat::sniff(b"Dear visitor,\nthank you"),
            None,
            "a letter is not OBJ"
        );
        assert_eq!(MeshFormat::sniff(b"version 2\n"), None);
    }
}
