//! Tangents for meshes whose file gives none (MikkTSpace, `bevy_mikktspace`), made from the
//! texture coordinates the normal map is read with, as glTF asks ("client implementations SHOULD
//! calculate tangents using default MikkTSpace algorithms with the specified vertex positions,
//! normals, and texture coordinates associated with the normal texture"): its set
//! (`texCoord` 0 or 1, [`Vertex::uv`]'s first or second pair) and its `KHR_texture_transform`.
//! A normal map read through the second set, or turned by its transform, otherwise shades as if
//! lit from the wrong side.
//!
//! Frames: the tangent is in the mesh's own coordinates, `w` (±1) the handedness that makes the
//! bitangent `cross(normal, tangent.xyz) · w` point along the normal map's +Y (green), the
//! image's up.
//!
//! Pure CPU, any thread; no panics (degenerate coordinates leave a vertex's tangent as it was).

use super::{Material, Mesh, UvTransform};

/// The texture coordinates tangents are made from: a material's normal texture's set and
/// transform, or the first set as it stands where the material has no normal map (anisotropic
/// and Ward lobes still need a tangent; with no normal map to agree with, the first set's is the
/// one tools show).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TangentUv {
    /// 0 or 1; 1 where the mesh has no second set reads the first (see [`Self::on`]).
    pub set: u32,
    pub transform: UvTransform,
}

impl TangentUv {
    /// The coordinates `material`'s normal texture is read with; the first set as it stands
    /// where there is no material or it has no normal map.
    pub fn of(material: Option<&Material>) -> Self {
        material
            .and_then(|m| m.normal_texture.as_ref())
            .map_or_else(Self::default, |(t, _)| Self {
                set: t.tex_coord,
                transform: t.transform,
            })
    }

    /// `self` for a mesh that `has_second_set` or not: a normal map naming a second set the mesh
    /// lacks is read at one point (the loader's missing set is all zeros), so its tangents are
    /// meaningless; the first set's are used instead.
    pub fn on(self, has_second_set: bool) -> Self {
        if self.set == 1 && has_second_set {
            self
        } else {
            Self { set: 0, ..self }
        }
    }
}

/// Gives `mesh` the tangents normal maps are baked against, from the coordinates `uv` names.
/// Where they are degenerate the placeholder tangents stay: normal maps then shade as flat.
pub fn generate_tangents(mesh: &mut Mesh, uv: TangentUv) {
    let _ = bevy_mikktspace::generate_tangents(&mut MikkGeometry { mesh, uv });
}

struct MikkGeometry<'a> {
    mesh: &'a mut Mesh,
    uv: TangentUv,
}

impl bevy_mikktspace::Geometry for MikkGeometry<'_> {
    fn num_faces(&self) -> usize {
        self.mesh.indices.len() / 3
    }
    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }
    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.vertices[self.mesh.indices[face * 3 + vert] as usize].position
    }
    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.vertices[self.mesh.indices[face * 3 + vert] as usize].normal
    }
    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        let uv = self.mesh.vertices[self.mesh.indices[face * 3 + vert] as usize].uv;
        let raw = if self.uv.set == 1 {
            [uv[2], uv[3]]
        } else {
            [uv[0], uv[1]]
        };
        let [u, v] = self.uv.transform.apply(raw);
        // MikkTSpace's bitangent runs towards increasing v; a glTF normal map's +Y (green) is the
        // image's up, towards v = 0 (glTF's v runs down). So v is given flipped, as in the tools
        // that bake normal maps (Blender's v runs up): the tangent is the same, its handedness
        // (w) the one the file's own tangents would carry.
        [u, 1.0 - v]
    }
    fn set_tangent(&mut self, tangent_space: Option<bevy_mikktspace::TangentSpace>, face: usize, vert: usize) {
        if let Some(ts) = tangent_space {
            let i = self.mesh.indices[face * 3 + vert] as usize;
            self.mesh.vertices[i].tangent = ts.tangent_encoded();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Vertex;

    /// A square facing +z with corners (0,0)–(1,1) in x, y; `uv` gives each corner's four
    /// texture coordinates (both sets) from its x, y.
    fn square(uv: impl Fn(f32, f32) -> [f32; 4]) -> Mesh {
        let corner = |x: f32, y: f32| Vertex {
            position: [x, y, 0.0],
            normal: [0.0, 0.0, 1.0],
            tangent: [0.0; 4],
            uv: uv(x, y),
            color: [1.0; 4],
            material: [1.0, 1.0],
        };
        Mesh {
            vertices: vec![corner(0.0, 0.0), corner(1.0, 0.0), corner(1.0, 1.0), corner(0.0, 1.0)],
            indices: vec![0, 1, 2, 0, 2, 3],
        }
    }

    fn assert_tangents(mesh: &Mesh, expected: [f32; 4]) {
        for v in &mesh.vertices {
            let t = v.tangent;
            assert!(
                t.iter().zip(expected).all(|(a, b)| (a - b).abs() < 1e-5),
                "tangent {t:?} at {:?}, expected {expected:?}",
                v.position
            );
        }
    }

    #[test]
    fn generated_tangents_point_the_normal_maps_y_at_the_images_up() {
        // The texture upright on the square: u along +x, the image's top (v = 0) at +y. A normal
        // map's +Y (green) must then lean the normal towards +y: bitangent cross(+z, +x)·w = +y,
        // so w = +1. (Generated with glTF's v as MikkTSpace's, w was −1: every normal map
        // without its own tangents shaded with its green channel upside down.)
        let mut mesh = square(|x, y| [x, 1.0 - y, 0.0, 0.0]);
        generate_tangents(&mut mesh, TangentUv::default());
        assert_tangents(&mesh, [1.0, 0.0, 0.0, 1.0]);
    }

    #[test]
    fn tangents_follow_the_set_the_normal_map_reads() {
        // First set upright (u along +x), second set turned a quarter: u along +y, the image's
        // top (v = 0) at +x. Read through the second set, the map's +X lies along +y and its +Y
        // along +x: tangent +y, bitangent cross(+z, +y)·w = −x·w = +x, so w = −1.
        let mut mesh = square(|x, y| [x, 1.0 - y, y, 1.0 - x]);
        generate_tangents(
            &mut mesh,
            TangentUv {
                set: 1,
                ..TangentUv::default()
            },
        );
        assert_tangents(&mesh, [0.0, 1.0, 0.0, -1.0]);
        // The first set's, as before, where the map reads that one.
        generate_tangents(&mut mesh, TangentUv::default());
        assert_tangents(&mesh, [1.0, 0.0, 0.0, 1.0]);
    }

    #[test]
    fn tangents_follow_the_normal_maps_texture_transform() {
        // A quarter turn (KHR_texture_transform rotation π/2): u' = v, v' = −u. With the upright
        // first set (u = x, v = 1 − y): u' = 1 − y grows towards −y, so the tangent is −y; the
        // image's up (v' falling) is towards +x: bitangent cross(+z, −y)·w = +x·w, so w = +1.
        let mut mesh = square(|x, y| [x, 1.0 - y, 0.0, 0.0]);
        let turned = UvTransform {
            rotation_rad: std::f32::consts::FRAC_PI_2,
            ..UvTransform::default()
        };
        generate_tangents(
            &mut mesh,
            TangentUv {
                set: 0,
                transform: turned,
            },
        );
        assert_tangents(&mesh, [0.0, -1.0, 0.0, 1.0]);
    }

    #[test]
    fn a_second_set_the_mesh_lacks_falls_back_to_the_first() {
        let wanted = TangentUv {
            set: 1,
            ..TangentUv::default()
        };
        assert_eq!(wanted.on(true).set, 1);
        assert_eq!(wanted.on(false).set, 0);
        assert_eq!(TangentUv::default().on(true).set, 0);
    }
}
