//! Shadows of a lamp that stands among what it shadows: a depth cube map.
//!
//! A lamp outside the casters' bounding sphere is seen from one perspective view
//! ([`crate::lamp_view_proj`]). One among them — a torch held close to a tall artifact, a lamp
//! dragged between the Diorama's blocks — shines every way onto casters, so no single view holds
//! what it shadows: the scene is drawn six times, once per face of a cube about the lamp (90°
//! views), into the six layers of one depth texture, and the lighting shader reads it as a cube
//! along the direction from the lamp (`lamp_cube_visibility` in `scene.wgsl`).
//!
//! ## Faces
//! The faces are drawn so that sampling the cube along a direction reads what its face saw along
//! it: layer k is the k-th face in the order +X, −X, +Y, −Y, +Z, −Z, and each face's view is
//! built from the cube-map lookup rule (the Vulkan and WebGPU table: major axis, then `s`, `t`
//! from the other two) with wgpu's top-left origin for both render targets and textures. The
//! views are mirror images of right-handed cameras (the lookup rule is left-handed), which the
//! shadow pass does not mind: it culls nothing. The depth a face stores for a point is the
//! perspective depth of its distance along the face's axis, which the shader recomputes from the
//! largest component of the direction ([`cube_depth`]).
//!
//! **Memory**: the map starts as 1×1 texels a face and grows to [`POINT_SHADOW_SIZE`]² (6 MiB)
//! the first time a lamp stands among its casters, so a renderer that never needs it pays
//! nothing. **Threading**: as the renderer (one thread).

use glam::{Mat3, Mat4, Vec3};

/// Texels along a face's side: at 10 cm from the lamp a texel is 0.4 mm across (2 × 10 cm / 512
/// at the face's centre), about the 2-D map's over the default artifact.
pub const POINT_SHADOW_SIZE: u32 = 512;

/// The faces' axes: (forward, right, up) in mesh coordinates, in layer order. See the module
/// docs: right and up follow from the cube lookup rule, `ndc_x = s·2 − 1`, `ndc_y = 1 − t·2`.
const FACES: [(Vec3, Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::NEG_Z, Vec3::Y),
    (Vec3::NEG_X, Vec3::Z, Vec3::Y),
    (Vec3::Y, Vec3::X, Vec3::NEG_Z),
    (Vec3::NEG_Y, Vec3::X, Vec3::Z),
    (Vec3::Z, Vec3::X, Vec3::Y),
    (Vec3::NEG_Z, Vec3::NEG_X, Vec3::Y),
];

/// The near and far distances of a lamp's cube over `bounds` (mesh coordinates, metres): far
/// reaches the farthest corner, so everything that casts lies inside; near is a thousandth of
/// it (depth precision of `Depth32Float` is ample at that ratio; a caster nearer than that to
/// the lamp, under a millimetre for a 1 m scene, is clipped).
pub fn cube_range_m(bounds: &phantogram_geometry::containment::Aabb, lamp_m: Vec3) -> (f32, f32) {
    let far = bounds
        .corners()
        .iter()
        .map(|c| (*c - lamp_m).length())
        .fold(0.0f32, f32::max)
        * 1.01
        + 1e-4;
    (far * 1e-3, far)
}

/// The six faces' view-projections about `lamp_m`, in layer order (see the module docs).
pub fn cube_face_view_proj(lamp_m: Vec3, near_m: f32, far_m: f32) -> [Mat4; 6] {
    let proj = Mat4::perspective_rh(std::f32::consts::FRAC_PI_2, 1.0, near_m, far_m);
    FACES.map(|(forward, right, up)| {
        // Rows: x_view = right·r, y_view = up·r, z_view = −forward·r (the camera looks down −z).
        let rotation = Mat3::from_cols(right, up, -forward).transpose();
        proj * Mat4::from_mat3(rotation) * Mat4::from_translation(-lamp_m)
    })
}

/// The depth a face stores for a point `major_m` along its axis (the largest component of the
/// offset from the lamp), as [`cube_face_view_proj`]'s projection gives it; the shader's copy
/// is checked against this in the tests.
pub fn cube_depth(major_m: f32, near_m: f32, far_m: f32) -> f32 {
    far_m * (major_m - near_m) / (major_m * (far_m - near_m))
}

/// Whether the box `b` lies wholly outside the frustum of `view_proj` (clip space as wgpu's:
/// −w ≤ x, y ≤ w, 0 ≤ z ≤ w): all eight corners beyond one of its planes. Conservative: a box
/// beside a corner of the frustum may be kept though nothing of it is inside.
pub fn outside_frustum(view_proj: &Mat4, b: &phantogram_geometry::containment::Aabb) -> bool {
    let clip = b.corners().map(|c| *view_proj * c.extend(1.0));
    let beyond = |test: fn(glam::Vec4) -> bool| clip.iter().all(|c| test(*c));
    beyond(|c| c.x < -c.w)
        || beyond(|c| c.x > c.w)
        || beyond(|c| c.y < -c.w)
        || beyond(|c| c.y > c.w)
        || beyond(|c| c.z < 0.0)
        || beyond(|c| c.z > c.w)
}

/// The GPU side: the cube texture, a view per face to draw into, and per face a uniform block
/// holding that face's view-projection where the shadow pass reads the light's
/// (`Eye::light_view_proj`), so the 2-D map's pipelines draw the faces unchanged.
pub(crate) struct PointShadowMap {
    pub size: u32,
    pub cube_view: wgpu::TextureView,
    pub face_views: Vec<wgpu::TextureView>,
    pub face_buffers: Vec<wgpu::Buffer>,
    pub face_binds: Vec<wgpu::BindGroup>,
}

impl PointShadowMap {
    /// A map of `size`² texels a face; `shadow_layout` is the shadow pass's group 0.
    pub fn new(device: &wgpu::Device, shadow_layout: &wgpu::BindGroupLayout, size: u32) -> Self {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("lamp shadow cube"),
            size: wgpu::Extent3d {
                width: size,
                height: size,
                depth_or_array_layers: 6,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: crate::DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let cube_view = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("lamp shadow cube"),
            dimension: Some(wgpu::TextureViewDimension::Cube),
            array_layer_count: Some(6),
            ..Default::default()
        });
        let face_views = (0..6)
            .map(|layer| {
                texture.create_view(&wgpu::TextureViewDescriptor {
                    label: Some("lamp shadow face"),
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: layer,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        let face_buffers: Vec<wgpu::Buffer> = (0..6)
            .map(|_| crate::eye_block_buffer(device, "lamp shadow face"))
            .collect();
        let face_binds = face_buffers
            .iter()
            .map(|b| {
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("lamp shadow face"),
                    layout: shadow_layout,
                    entries: &[wgpu::BindGroupEntry {
                        binding: 0,
                        resource: b.as_entire_binding(),
                    }],
                })
            })
            .collect();
        Self {
            size,
            cube_view,
            face_views,
            face_buffers,
            face_binds,
        }
    }

    /// Writes the faces' view-projections for the next frame.
    pub fn write_faces(&self, queue: &wgpu::Queue, faces: &[Mat4; 6]) {
        for (buffer, m) in self.face_buffers.iter().zip(faces) {
            let block = crate::EyeUniform {
                light_view_proj: m.to_cols_array_2d(),
                ..bytemuck::Zeroable::zeroed()
            };
            queue.write_buffer(buffer, 0, bytemuck::bytes_of(&block));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cube lookup rule (Vulkan spec, "Cube Map Face Selection"; WebGPU follows it): the
    /// face of the largest component and the (s, t) in it, t = 0 on the image's first row.
    fn lookup(d: Vec3) -> (usize, f32, f32) {
        let a = d.abs();
        let (face, sc, tc, ma) = if a.x >= a.y && a.x >= a.z {
            if d.x > 0.0 {
                (0, -d.z, -d.y, a.x)
            } else {
                (1, d.z, -d.y, a.x)
            }
        } else if a.y >= a.z {
            if d.y > 0.0 {
                (2, d.x, d.z, a.y)
            } else {
                (3, d.x, -d.z, a.y)
            }
        } else if d.z > 0.0 {
            (4, d.x, -d.y, a.z)
        } else {
            (5, -d.x, -d.y, a.z)
        };
        (face, 0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0))
    }

    #[test]
    fn each_face_draws_where_the_cube_lookup_reads() {
        let lamp = Vec3::new(0.01, -0.02, 0.03);
        let (near, far) = (0.001, 1.0);
        let faces = cube_face_view_proj(lamp, near, far);
        // Directions all over the sphere (a Fibonacci spiral), at several distances.
        let n = 500;
        for i in 0..n {
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
            let phi = i as f32 * 2.399_963;
            let r = (1.0 - z * z).sqrt();
            let d = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            for distance in [0.01, 0.2, 0.9] {
                let (face, s, t) = lookup(d);
                let p = faces[face].project_point3(lamp + d * distance);
                // The render target's pixel (x right, y down, both 0..1) is the texel read.
                let (x, y) = (0.5 * (p.x + 1.0), 0.5 * (1.0 - p.y));
                assert!(
                    (x - s).abs() < 1e-4 && (y - t).abs() < 1e-4,
                    "{d}: face {face} ({x}, {y}) vs ({s}, {t})"
                );
                let major = d.abs().max_element() * distance;
                assert!((p.z - cube_depth(major, near, far)).abs() < 1e-5, "{d}: depth {}", p.z);
                assert!((0.0..=1.0).contains(&p.z));
            }
        }
    }

    #[test]
    fn a_box_is_culled_only_from_faces_it_misses() {
        use phantogram_geometry::containment::Aabb;
        let lamp = Vec3::ZERO;
        let faces = cube_face_view_proj(lamp, 0.001, 1.0);
        // A small box straight along +x: in the +X face only.
        let ahead = Aabb::new(Vec3::new(0.3, -0.01, -0.01), Vec3::new(0.32, 0.01, 0.01));
        let kept: Vec<bool> = faces.iter().map(|m| !outside_frustum(m, &ahead)).collect();
        assert_eq!(kept, [true, false, false, false, false, false]);
        // One straddling the +X/+Y edge: in both.
        let edge = Aabb::new(Vec3::new(0.2, 0.18, -0.01), Vec3::new(0.22, 0.24, 0.01));
        let kept: Vec<bool> = faces.iter().map(|m| !outside_frustum(m, &edge)).collect();
        assert_eq!(kept, [true, false, true, false, false, false]);
        // One around the lamp: in every face.
        let around = Aabb::new(Vec3::splat(-0.05), Vec3::splat(0.05));
        assert!(faces.iter().all(|m| !outside_frustum(m, &around)));
        // Beyond the far plane: in none.
        let far = Aabb::new(Vec3::new(1.5, -0.01, -0.01), Vec3::new(1.6, 0.01, 0.01));
        assert!(faces.iter().all(|m| outside_frustum(m, &far)));
        // A box is never culled from a face that sees one of its points (random boxes, checked
        // against the lookup rule at their corners and centre).
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 - 0.5
        };
        for _ in 0..2000 {
            let c = Vec3::new(next(), next(), next());
            let h = Vec3::new(next(), next(), next()).abs() * 0.1;
            let b = Aabb::new(c - h, c + h);
            for p in b.corners().into_iter().chain([c]) {
                let (face, _, _) = lookup(p - lamp);
                if (p - lamp).abs().max_element() > 0.002 {
                    assert!(!outside_frustum(&faces[face], &b), "{b:?}: {p} is in face {face}");
                }
            }
        }
    }

    #[test]
    fn the_range_holds_every_corner() {
        let bounds =
            phantogram_geometry::containment::Aabb::new(Vec3::new(-0.02, -0.03, -0.01), Vec3::new(0.02, 0.03, 0.01));
        let lamp = Vec3::new(0.015, 0.0, 0.0);
        let (near, far) = cube_range_m(&bounds, lamp);
        let faces = cube_face_view_proj(lamp, near, far);
        for c in bounds.corners() {
            let d = c - lamp;
            let (face, _, _) = lookup(d);
            let p = faces[face].project_point3(c);
            assert!((0.0..1.0).contains(&p.z), "{c}: depth {}", p.z);
        }
        assert!(near > 0.0 && near < 1e-4, "{near}");
    }
}
