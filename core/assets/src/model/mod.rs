//! Models: triangle meshes with metallic–roughness materials and textures, in the device frame,
//! and the loaders that produce them (glTF 2.0, STL, PLY, OBJ).
//!
//! ## Loading glTF
//! * `.gltf` (JSON with external or data-URI buffers and images) and `.glb` (binary container).
//! * Geometry through our own accessor reader, which handles every component type, normalised or
//!   not, byte strides and sparse accessors, so `KHR_mesh_quantization` needs no special case.
//!   `KHR_draco_mesh_compression` primitives are decoded with `draco-core` (pure Rust: no C++
//!   toolchain on the phone builds). `EXT_meshopt_compression` / `KHR_meshopt_compression`
//!   buffer views (gltfpack's `-c`) are decoded with meshoptimizer before any accessor reads
//!   them; their fallback buffers are never read (`meshopt_views`).
//! * Node transforms are baked into the vertices (negative determinants flip the winding), and so
//!   are the instances of `EXT_mesh_gpu_instancing` (gltfpack's `-mi`): one mesh per primitive
//!   holding every copy, each charged to the budget before it is made (`instancing`).
//! * Skinned meshes are drawn in the pose the node hierarchy holds, each vertex moved by its joints
//!   (`JOINTS_0`/`WEIGHTS_0`, inverse bind matrices) with the skinned node's own transform ignored,
//!   as glTF defines (`skin`); no animation is played. Morph targets are applied at the weights the
//!   file gives (the node's, else the mesh's), the shape glTF draws without animation.
//! * Triangle strips and fans become the triangle lists they stand for, wound as glTF orders their
//!   corners (`topology`); points become small discs that close into a surface (`point_cloud`,
//!   as a PLY without faces does); lines have no surface to show and are left out with a warning
//!   each (as is a strip, fan or point primitive of Draco, whose decoder hands back faces).
//! * Materials: base colour, metallic–roughness, normal (with scale), occlusion (with strength)
//!   and emissive textures (`KHR_materials_emissive_strength`), `KHR_texture_transform` on every
//!   slot (gltf-rs types it only on `textureInfo`, so for normal and occlusion textures it is read
//!   from the raw extension object; a malformed one becomes a warning), alpha
//!   `OPAQUE`/`MASK`/`BLEND`, double-sided. Images are decoded to RGBA8 (`encoded_image`): PNG,
//!   JPEG, WebP for `EXT_texture_webp` (which web tools write often with no PNG or JPEG beside;
//!   the `image` crate's pure-Rust `image-webp` decoder) and KTX 2.0 with Basis Universal for
//!   `KHR_texture_basisu` (ETC1S or UASTC, gltfpack's `-tc`; the pure-Rust `basisu` transcoder).
//!   Where a texture names both, the core `source` (the lossless fallback) is used. A texture
//!   whose image comes only from an extension we do not read is left out with a warning.
//! * Glass, gems, varnish, cloth, brushed metal and thin films: `KHR_materials_ior`, `_specular`,
//!   `_clearcoat`, `_transmission`, `_volume`, `_dispersion`, `_sheen`, `_diffuse_transmission`,
//!   `_anisotropy` and `_iridescence` (their factors in [`Layers`]; the transmission and thickness
//!   textures in their own slots, every other texture they name in [`LayerTextures`]).
//! * `KHR_materials_pbrSpecularGlossiness` (archived by Khronos, but found in older exports) is
//!   converted to metallic–roughness as Khronos published, texel by texel where it has a texture
//!   (`spec_gloss`).
//! * Tangents come from the file or, where a normal map needs them, from MikkTSpace
//!   (`bevy_mikktspace`, the reference algorithm that normal maps are baked against).
//! * Smithsonian Voyager scans: when a `scene.svx.json` beside the file lists it as a derivative,
//!   [`load_model`] applies the model's rotation from that scene (the scans are stored in the
//!   scanner's frame), see [`voyager_rotation`]. Given the scene itself, or its folder, it loads
//!   the best scan the scene lists that is present ([`voyager_scan`]).
//! * Only glTF 2.0: a file whose `asset.version` is not 2.x is refused by name.
//! * A file that *requires* an extension we do not implement fails with
//!   [`ModelError::UnsupportedExtension`] naming it; [`SUPPORTED_EXTENSIONS`] lists those we do.
//! * A damaged file fails with an error saying where, and does not panic, hang or abort: the
//!   document's indices and enumerations are checked before gltf-rs (which indexes unchecked)
//!   follows them, the node hierarchy must be trees, every accessor's extent is checked before its
//!   output is allocated, and a panic inside the Draco decoder becomes that primitive's error.
//! * Hostile files: a buffer or image URI is followed only to a regular file inside the model's
//!   folder ([`resolve_inside`]); what a file claims (vertices and indices, decoded texels with
//!   their mips, drawn primitives after instancing) is charged to a
//!   [`crate::budget::ResourceBudget`] before it is allocated ([`load_model_within`]; phone-sized
//!   by default), images checked from their headers and decoded under matching limits; every
//!   vertex must be finite and within ±[`MAX_COORDINATE`] after its node transforms. A Draco
//!   stream is decoded before its counts are known (bounded by its own size in the file), then
//!   charged.
//!
//! ## Loading STL, PLY and OBJ
//! Scans published as meshes (3D-printing STL, scanners' PLY, download pages' OBJ) load by their
//! extension. STL and PLY become a model of one primitive: welded, with smooth normals, PLY's
//! vertex colours kept (a PLY without faces is a point cloud, drawn as discs: `point_cloud`);
//! STL read as millimetres with +Z up, PLY as metres with +Y up, both turned
//! into the frame below (`mesh_file`, `stl`, `ply`). OBJ keeps its objects and MTL materials with
//! their colour textures, opened only inside its folder (`obj`). The same budget and no-panic
//! rules as glTF.
//!
//! ## Frames
//! glTF is +Y up, +Z front, metres. [`Model::fit_to_diorama`] turns a standing object's +Y into
//! the device's +Z (out of the glass towards the viewer) and its +Z into −Y (facing the bottom
//! edge, where the viewer holds the phone); a flat one (relief, tablet) keeps its axes, lying in
//! the glass with its front towards the viewer ([`Placement`]). It then scales the model to the
//! diorama and places it straddling the glass.

use glam::{Mat3, Mat4, Quat, Vec3, Vec4};

use phantogram_geometry::containment::Aabb;
use phantogram_geometry::screen::Screen;

/// One vertex: position and normal (device frame, metres), tangent (xyz, w = handedness),
/// texture coordinates (`[u0, v0, u1, v1]`), linear vertex colour with alpha, and per-vertex
/// `[metallic, roughness]` multipliers (1 for loaded models; the procedural artifact paints them).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub tangent: [f32; 4],
    pub uv: [f32; 4],
    pub color: [f32; 4],
    pub material: [f32; 2],
}

/// A triangle mesh, counter-clockwise front faces.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub vertices: Vec<Vertex>,
    pub indices: Vec<u32>,
}

impl Mesh {
    /// Axis-aligned bounds of the vertices; `None` for an empty mesh.
    pub fn bounds(&self) -> Option<Aabb> {
        let first = Vec3::from(self.vertices.first()?.position);
        let (min, max) = self.vertices.iter().fold((first, first), |(lo, hi), v| {
            let p = Vec3::from(v.position);
            (lo.min(p), hi.max(p))
        });
        Some(Aabb::new(min, max))
    }

    /// The first vertex that is not finite or lies beyond ±[`MAX_COORDINATE`] (index and
    /// position): past it the bounds and the fit to the screen overflow, and the frame is blank.
    pub fn out_of_range_vertex(&self) -> Option<(usize, [f32; 3])> {
        self.vertices
            .iter()
            .enumerate()
            .find(|(_, v)| !v.position.iter().all(|c| c.is_finite() && c.abs() <= MAX_COORDINATE))
            .map(|(i, v)| (i, v.position))
    }

    /// Area-weighted vertex normals from the triangles' windings (for files that give none);
    /// a vertex no triangle uses faces +z.
    pub fn smooth_normals(&mut self) {
        let mut acc = vec![Vec3::ZERO; self.vertices.len()];
        for tri in self.indices.chunks(3) {
            let p = |k: usize| Vec3::from(self.vertices[tri[k] as usize].position);
            let n = (p(1) - p(0)).cross(p(2) - p(0));
            for &i in tri {
                acc[i as usize] += n;
            }
        }
        for (v, n) in self.vertices.iter_mut().zip(acc) {
            v.normal = n.normalize_or(Vec3::Z).to_array();
        }
    }

    /// Applies an affine transform to positions, normals and tangents.
    pub fn transform(&mut self, m: Mat4) {
        let linear = Mat3::from_mat4(m);
        let normal_m = linear.inverse().transpose();
        for v in &mut self.vertices {
            v.position = m.transform_point3(Vec3::from(v.position)).to_array();
            v.normal = (normal_m * Vec3::from(v.normal)).normalize_or_zero().to_array();
            let t = Vec4::from(v.tangent);
            let tt = (linear * t.truncate()).normalize_or_zero();
            v.tangent = tt.extend(t.w).to_array();
        }
        if linear.determinant() < 0.0 {
            for tri in self.indices.chunks_mut(3) {
                tri.swap(1, 2);
            }
        }
    }

    /// Appends a small axis-aligned cube (markers, tests).
    pub fn push_cube(&mut self, centre: Vec3, half: f32, color: [f32; 4]) {
        let faces = [
            (Vec3::X, Vec3::Y, Vec3::Z),
            (-Vec3::X, Vec3::Z, Vec3::Y),
            (Vec3::Y, Vec3::Z, Vec3::X),
            (-Vec3::Y, Vec3::X, Vec3::Z),
            (Vec3::Z, Vec3::X, Vec3::Y),
            (-Vec3::Z, Vec3::Y, Vec3::X),
        ];
        for (n, u, v) in faces {
            let base = self.vertices.len() as u32;
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                let p = centre + (n + u * a + v * b) * half;
                self.vertices.push(Vertex {
                    position: p.to_array(),
                    normal: n.to_array(),
                    tangent: u.extend(1.0).to_array(),
                    uv: [(a + 1.0) * 0.5, (1.0 - b) * 0.5, 0.0, 0.0],
                    color,
                    material: [0.0, 0.8],
                });
            }
            // u × v = n for every face above, so this winding is counter-clockwise seen from n.
            self.indices
                .extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
        }
    }

    /// Appends a UV sphere of `radius` at `centre` (annotation pins, tests): `segments` round,
    /// `rings` from pole to pole, white, with its normals and tangents (along φ).
    pub fn push_ball(&mut self, centre: Vec3, radius: f32, segments: u32, rings: u32) {
        let base = self.vertices.len() as u32;
        for i in 0..=rings {
            let theta = std::f32::consts::PI * i as f32 / rings as f32;
            for j in 0..=segments {
                let phi = std::f32::consts::TAU * j as f32 / segments as f32;
                let n = Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
                self.vertices.push(Vertex {
                    position: (centre + n * radius).to_array(),
                    normal: n.to_array(),
                    tangent: [-phi.sin(), phi.cos(), 0.0, 1.0],
                    uv: [j as f32 / segments as f32, i as f32 / rings as f32, 0.0, 0.0],
                    color: [1.0; 4],
                    material: [1.0, 1.0],
                });
            }
        }
        let row = segments + 1;
        for i in 0..rings {
            for j in 0..segments {
                let a = base + i * row + j;
                let b = a + row;
                // Counter-clockwise seen from outside (θ grows towards −z, φ anticlockwise about z).
                self.indices.extend_from_slice(&[a, b, a + 1, a + 1, b, b + 1]);
            }
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaMode {
    Opaque,
    /// Fragments with alpha below the cutoff are discarded.
    Mask(f32),
    Blend,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    Repeat,
    ClampToEdge,
    MirroredRepeat,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sampler {
    pub mag_linear: bool,
    pub min_linear: bool,
    pub mip_linear: bool,
    pub wrap_u: Wrap,
    pub wrap_v: Wrap,
}

impl Default for Sampler {
    /// glTF leaves filtering to the implementation: trilinear, repeat.
    fn default() -> Self {
        Self {
            mag_linear: true,
            min_linear: true,
            mip_linear: true,
            wrap_u: Wrap::Repeat,
            wrap_v: Wrap::Repeat,
        }
    }
}

/// `KHR_texture_transform`: `uv' = T · R · S · uv`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    pub offset: [f32; 2],
    pub rotation_rad: f32,
    pub scale: [f32; 2],
}

impl Default for UvTransform {
    fn default() -> Self {
        Self {
            offset: [0.0, 0.0],
            rotation_rad: 0.0,
            scale: [1.0, 1.0],
        }
    }
}

impl UvTransform {
    /// The two rows of the 2×3 matrix, as the extension defines it (rotation counter-clockwise
    /// in UV space, which has v pointing down).
    pub fn rows(&self) -> [[f32; 3]; 2] {
        let (s, c) = self.rotation_rad.sin_cos();
        let [sx, sy] = self.scale;
        let [ox, oy] = self.offset;
        [[c * sx, s * sy, ox], [-s * sx, c * sy, oy]]
    }

    pub fn apply(&self, uv: [f32; 2]) -> [f32; 2] {
        let r = self.rows();
        [
            r[0][0] * uv[0] + r[0][1] * uv[1] + r[0][2],
            r[1][0] * uv[0] + r[1][1] * uv[1] + r[1][2],
        ]
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    /// Index into [`Model::images`].
    pub image: usize,
    /// Which UV set: 0 or 1.
    pub tex_coord: u32,
    pub transform: UvTransform,
    pub sampler: Sampler,
}

/// glTF metallic–roughness material. Colours are linear.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    pub base_color: [f32; 4],
    pub metallic: f32,
    pub roughness: f32,
    /// Emissive colour times `KHR_materials_emissive_strength`.
    pub emissive: [f32; 3],
    pub alpha: AlphaMode,
    pub double_sided: bool,
    pub base_color_texture: Option<TextureRef>,
    /// Roughness in G, metallic in B.
    pub metallic_roughness_texture: Option<TextureRef>,
    pub normal_texture: Option<(TextureRef, f32)>,
    pub occlusion_texture: Option<(TextureRef, f32)>,
    pub emissive_texture: Option<TextureRef>,
    /// `KHR_materials_transmission`'s texture: its red channel scales [`Layers::transmission`]
    /// (linear), saying which parts of the surface let light through.
    pub transmission_texture: Option<TextureRef>,
    /// `KHR_materials_volume`'s texture: its green channel scales [`Layers::thickness`]
    /// (linear), where the volume is thinner than its thickest.
    pub thickness_texture: Option<TextureRef>,
    /// `KHR_materials_unlit`: shown in its base colour, without lighting (scans whose lighting
    /// is baked into their colour).
    pub unlit: bool,
    /// Part of the scene the artifact stands in (the diorama's floor), not of the artifact: the
    /// material screen's changes leave it as it is.
    pub scenery: bool,
    /// Index of refraction, specular strength, varnish, transmission and absorption (glTF's
    /// material extensions); the core material has none.
    pub layers: Layers,
    /// The textures that scale [`Self::layers`]' varnish (and tilt it: its normal map), specular,
    /// sheen, diffuse transmission, anisotropy and thin film over the surface.
    pub layer_textures: LayerTextures,
}

impl Default for Material {
    /// glTF's default material: white, fully metallic, fully rough.
    fn default() -> Self {
        Self {
            name: "default".into(),
            base_color: [1.0; 4],
            metallic: 1.0,
            roughness: 1.0,
            emissive: [0.0; 3],
            alpha: AlphaMode::Opaque,
            double_sided: false,
            base_color_texture: None,
            metallic_roughness_texture: None,
            normal_texture: None,
            occlusion_texture: None,
            emissive_texture: None,
            transmission_texture: None,
            thickness_texture: None,
            unlit: false,
            scenery: false,
            layers: Layers::default(),
            layer_textures: LayerTextures::default(),
        }
    }
}

impl Material {
    /// A scan without a colour of its own (STL, PLY without colours, OBJ without materials):
    /// a light, warm grey (linear), matte, a cast's colour, not a claim about the object.
    pub fn plaster() -> Self {
        Self {
            name: "plaster".into(),
            base_color: [0.62, 0.6, 0.56, 1.0],
            metallic: 0.0,
            roughness: 0.75,
            ..Self::default()
        }
    }

    /// A scan whose colour is in its vertices (a coloured PLY, an OBJ's `v x y z r g b`) and
    /// that has no material of its own: white, so the colours show as they are, and matte.
    pub fn vertex_coloured_scan() -> Self {
        Self {
            name: "vertex colours".into(),
            metallic: 0.0,
            roughness: 0.8,
            ..Self::default()
        }
    }

    /// For meshes that paint colour and metallic/roughness per vertex (the procedural artifact).
    pub fn vertex_painted() -> Self {
        Self {
            name: "vertex painted".into(),
            double_sided: true,
            ..Self::default()
        }
    }

    /// Whether light passes through the surface ([`Layers::transmits`]): never for an unlit one,
    /// which shows its colour as it is (glTF forbids transmission on it).
    pub fn transmits(&self) -> bool {
        self.layers.transmits() && !self.unlit
    }

    /// Whether what is seen through the surface is blurred (rough glass: frosted) or displaced
    /// (a refracting volume), which needs the picture behind it rather than a filter over it
    /// (the render crate's backdrop). Smooth thin glass needs neither.
    pub fn blurs_or_bends(&self) -> bool {
        self.blurs() || (self.transmits() && self.layers.refracts())
    }

    /// Whether what is seen through the surface is blurred: it lets light through, is rough
    /// somewhere (its factor scales the texture's), and its index differs from the air's (a rough
    /// boundary between media of one index turns no ray).
    pub fn blurs(&self) -> bool {
        self.transmits() && self.roughness > 0.0 && self.layers.ior != 1.0
    }

    /// The textures of the core material and of transmission and thickness, in this order (the
    /// renderer binds each on its own), each with whether it holds colour (sRGB-encoded) data.
    pub fn own_slot_textures(&self) -> [Option<(TextureRef, bool)>; 7] {
        [
            self.base_color_texture.map(|t| (t, true)),
            self.metallic_roughness_texture.map(|t| (t, false)),
            self.normal_texture.map(|(t, _)| (t, false)),
            self.occlusion_texture.map(|(t, _)| (t, false)),
            self.emissive_texture.map(|t| (t, true)),
            self.transmission_texture.map(|t| (t, false)),
            self.thickness_texture.map(|t| (t, false)),
        ]
    }

    /// Every texture the material uses, with whether it holds colour (sRGB-encoded) data.
    pub fn textures(&self) -> impl Iterator<Item = (TextureRef, bool)> + '_ {
        self.own_slot_textures()
            .into_iter()
            .chain(
                LayerSlot::ALL
                    .into_iter()
                    .map(|slot| self.layer_textures.get(slot).map(|t| (t, slot.is_colour()))),
            )
            .flatten()
    }
}

/// An RGBA8 image as stored in the file (colour textures sRGB-encoded, data textures linear).
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub rgba8: Vec<u8>,
    /// The Basis Universal texture these texels were transcoded from, where they are one of its
    /// levels: the renderer transcodes it again to a block-compressed format its GPU samples.
    pub basis: Option<BasisSource>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Primitive {
    pub mesh: Mesh,
    /// Index into [`Model::materials`].
    pub material: usize,
    /// The diorama floor of [`Model::add_floor`], a plane facing +z under everything else. The
    /// renderer fits its shadow map to the rest (what the floor receives shadows from), and draws
    /// the floor into it only when the light is below the floor's plane.
    pub is_floor: bool,
    /// Coarser versions of `mesh`, finest first, over the same vertices (empty: drawn only at
    /// full detail). Made by `phantogram-detail` for big scans; the renderer draws the level the
    /// engine chooses each frame. Everything else (bounds, picking, physics) uses `mesh`.
    pub lods: Vec<Lod>,
}

/// The level of detail that draws a primitive as its relief-texture impostor (where the renderer
/// baked one; the coarsest level where not). Levels below it index the primitive's chain (0 the
/// full mesh, l its `lods[l − 1]`).
pub const IMPOSTOR_LEVEL: u8 = u8::MAX;

/// A primitive changing level of detail, drawn at both for a moment: its new level on the
/// fraction `shown` of the pixels and the level `from` on the rest (a screen-door cross-fade,
/// the same pixels each frame, so that the new level grows in and nothing pops).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LevelFade {
    /// The primitive, by index in its model.
    pub primitive: u32,
    /// The level faded out (a level as in the levels the renderer is given, or
    /// [`IMPOSTOR_LEVEL`]).
    pub from: u8,
    /// Fraction of pixels at the new level, 0 to 1.
    pub shown: f32,
}

/// A coarser level of detail of a [`Primitive`]: triangles over the primitive's own vertices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Lod {
    /// Counter-clockwise triangles, indices into the primitive's `mesh.vertices`.
    pub indices: Vec<u32>,
    /// How far this level's surface may lie from the full mesh's, metres in the model's frame
    /// (the simplifier's measured error; scaled with [`Model::transform`]).
    pub error_m: f32,
}

/// A whole model: primitives, materials and images, all positions in one frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Model {
    pub name: String,
    pub primitives: Vec<Primitive>,
    pub materials: Vec<Material>,
    pub images: Vec<Image>,
    /// Things in the file that were skipped (non-triangle primitives, …), for the user to see.
    pub warnings: Vec<String>,
    /// Points of interest the publisher marked on the artifact (Voyager annotations), in the
    /// model's frame: they move with [`Model::transform`].
    pub annotations: Vec<Annotation>,
}

/// A point of interest on the artifact: where it is, which way its surface faces, what it says.
#[derive(Clone, Debug, PartialEq)]
pub struct Annotation {
    pub id: String,
    pub title: String,
    /// The short text shown when it is tapped.
    pub lead: String,
    /// A point on the surface, in the model's frame.
    pub position: Vec3,
    /// The direction the marker stands out in (the surface's outward side), unit length.
    pub direction: Vec3,
}

/// Which way a glTF model (+Y up, +Z front) is turned into the diorama.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Placement {
    /// Standing, unless the model is thin front to back (a relief, a tablet, a panel): then facing.
    #[default]
    Auto,
    /// +Y along the glass normal: the object stands out of the glass towards the viewer (vases,
    /// statues).
    Standing,
    /// +Z along the glass normal, +Y up the screen: the object lies in the glass, its front
    /// towards the viewer (reliefs, paintings, coins).
    Facing,
    /// Surface mode (tangiBook's): turned as [`Placement::Facing`], at its true size (scaled
    /// down only where it would not fit the screen), its front in the plane of the glass — a
    /// painting, a coin, a manuscript page seen as if lying on the phone, its surface where the
    /// eyes converge, its reflections following them.
    Surface,
}

impl Placement {
    /// The rotation from glTF axes to the device frame, given the model's extent in glTF axes.
    pub fn rotation(self, extent: Vec3) -> Quat {
        let facing = match self {
            Placement::Standing => false,
            Placement::Facing | Placement::Surface => true,
            // Thin front to back: under a third of both its width and height.
            Placement::Auto => extent.z < extent.x.min(extent.y) / 3.0,
        };
        if facing {
            Quat::IDENTITY
        } else {
            Quat::from_rotation_x(std::f32::consts::FRAC_PI_2)
        }
    }
}

/// How a model is placed in the diorama.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DioramaFit {
    pub placement: Placement,
    /// Largest height (along the glass normal), m.
    pub max_height_m: f32,
    /// Largest extent across the glass, as a fraction of the screen's shorter side.
    pub max_width_fraction: f32,
    /// Fraction of the model's height that stands in front of the glass.
    pub protrude_fraction: f32,
    /// Keep the file's size (glTF metres) instead of scaling it into the diorama; it is still
    /// turned and placed straddling the glass.
    pub true_size: bool,
}

impl Default for DioramaFit {
    /// 62 mm tall at most (the default artifact's height), 70 % of the screen's width across,
    /// 40 % in front of the glass.
    fn default() -> Self {
        Self {
            placement: Placement::Auto,
            max_height_m: 0.062,
            max_width_fraction: 0.7,
            protrude_fraction: 0.4,
            true_size: false,
        }
    }
}

impl Model {
    /// A one-material model from a mesh painted per vertex.
    pub fn from_painted_mesh(name: &str, mesh: Mesh) -> Self {
        Self {
            name: name.into(),
            primitives: vec![Primitive {
                mesh,
                material: 0,
                is_floor: false,
                lods: Vec::new(),
            }],
            materials: vec![Material::vertex_painted()],
            images: Vec::new(),
            warnings: Vec::new(),
            annotations: Vec::new(),
        }
    }

    /// How far the app's floor reaches, in screen sizes ([`Model::add_floor`]): far enough to fill
    /// the view at the steepest tilt the viewpoint allows.
    pub const FLOOR_REACH: f32 = 2.5;

    /// Adds the diorama's floor: a matte neutral plane parallel to the glass under the model (at
    /// its lowest point), reaching `reach` screen sizes out so it fills oblique views. It is what
    /// the model stands on and where its shadow falls, the phantogram's main depth cue.
    pub fn add_floor(&mut self, screen: &Screen, reach: f32) {
        let Some(b) = self.bounds() else { return };
        let (hw, hh) = (screen.panel_width_m() * reach, screen.panel_height_m() * reach);
        let z = b.min.z;
        let corner = |x: f32, y: f32, u: f32, v: f32| Vertex {
            position: [x, y, z],
            normal: [0.0, 0.0, 1.0],
            tangent: [1.0, 0.0, 0.0, 1.0],
            uv: [u, v, 0.0, 0.0],
            color: [1.0; 4],
            material: [1.0, 1.0],
        };
        let mesh = Mesh {
            vertices: vec![
                corner(-hw, -hh, 0.0, 1.0),
                corner(hw, -hh, 1.0, 1.0),
                corner(hw, hh, 1.0, 0.0),
                corner(-hw, hh, 0.0, 0.0),
            ],
            indices: vec![0, 1, 2, 0, 2, 3],
        };
        self.materials.push(Material {
            name: "diorama floor".into(),
            base_color: [0.18, 0.18, 0.18, 1.0],
            metallic: 0.0,
            roughness: 0.9,
            scenery: true,
            ..Material::default()
        });
        self.primitives.push(Primitive {
            mesh,
            material: self.materials.len() - 1,
            is_floor: true,
            lods: Vec::new(),
        });
    }

    pub fn bounds(&self) -> Option<Aabb> {
        self.bounds_of(|_| true)
    }

    /// The bounds of the primitives `keep` accepts (`None` if it accepts none with vertices).
    pub fn bounds_of(&self, keep: impl Fn(&Primitive) -> bool) -> Option<Aabb> {
        self.primitives
            .iter()
            .filter(|p| keep(p))
            .filter_map(|p| p.mesh.bounds())
            .reduce(|a, b| Aabb::new(a.min.min(b.min), a.max.max(b.max)))
    }

    pub fn triangle_count(&self) -> usize {
        self.primitives.iter().map(|p| p.mesh.indices.len() / 3).sum()
    }

    /// Moves every primitive, level and annotation by `m` (a similarity: rotation, uniform scale,
    /// translation, perhaps a mirror), and scales the materials' volume lengths with the mesh,
    /// so that a glass's thickness stays that of its walls.
    pub fn transform(&mut self, m: Mat4) {
        let linear = Mat3::from_mat4(m);
        // A length grows by at most the largest singular value; the columns' largest length is
        // that exactly for the similarity transforms models get (rotation, uniform scale).
        let scale = linear
            .x_axis
            .length()
            .max(linear.y_axis.length())
            .max(linear.z_axis.length());
        let mirrors = linear.determinant() < 0.0;
        for p in &mut self.primitives {
            p.mesh.transform(m);
            for lod in &mut p.lods {
                lod.error_m *= scale;
                if mirrors {
                    for tri in lod.indices.chunks_mut(3) {
                        tri.swap(1, 2);
                    }
                }
            }
        }
        for m in &mut self.materials {
            m.layers.scale_lengths(scale);
        }
        let normal_m = linear.inverse().transpose();
        for a in &mut self.annotations {
            a.position = m.transform_point3(a.position);
            a.direction = (normal_m * a.direction).normalize_or(Vec3::Z);
        }
    }

    /// Radius of an annotation's marker, metres on the diorama's scale (what a finger finds on a
    /// phone held at 30 cm, and small beside the artifact).
    pub const PIN_RADIUS_M: f32 = 0.0012;

    /// Where an annotation's marker is drawn: a little out from the surface along its direction,
    /// so that it is not buried in it.
    pub fn pin_centre(a: &Annotation) -> Vec3 {
        a.position + a.direction * Self::PIN_RADIUS_M * 1.5
    }

    /// Adds a marker for each annotation: a small amber ball, unlit so that it reads the same in
    /// any light, drawn with the artifact (so it has the artifact's depth in both eyes and is
    /// hidden where the artifact is in front of it).
    pub fn add_annotation_pins(&mut self) {
        if self.annotations.is_empty() {
            return;
        }
        let mut mesh = Mesh::default();
        for a in &self.annotations {
            mesh.push_ball(Self::pin_centre(a), Self::PIN_RADIUS_M, 12, 8);
        }
        self.materials.push(Material {
            name: "annotation markers".into(),
            base_color: [1.0, 0.62, 0.12, 1.0],
            metallic: 0.0,
            roughness: 1.0,
            unlit: true,
            scenery: true,
            ..Material::default()
        });
        self.primitives.push(Primitive {
            mesh,
            material: self.materials.len() - 1,
            is_floor: false,
            lods: Vec::new(),
        });
    }

    /// Turns a glTF (+Y up, +Z front) model into the device frame as `fit.placement` says, scales
    /// it into the diorama and places it straddling the glass, centred on the screen. Returns the
    /// scale applied.
    pub fn fit_to_diorama(&mut self, screen: &Screen, fit: &DioramaFit) -> f32 {
        let Some(b) = self.bounds() else { return 1.0 };
        self.transform(Mat4::from_quat(fit.placement.rotation(b.max - b.min)));
        let Some(b) = self.bounds() else { return 1.0 };
        let size = b.max - b.min;
        let across = screen.panel_width_m().min(screen.panel_height_m()) * fit.max_width_fraction;
        let scale = [fit.max_height_m / size.z, across / size.x, across / size.y]
            .into_iter()
            .filter(|s| s.is_finite() && *s > 0.0)
            .fold(f32::INFINITY, f32::min);
        let scale = if !scale.is_finite() {
            1.0
        } else if fit.placement == Placement::Surface {
            // True size, unless larger than the screen: then as large as fits.
            let whole = [screen.panel_width_m() / size.x, screen.panel_height_m() / size.y]
                .into_iter()
                .filter(|s| s.is_finite() && *s > 0.0)
                .fold(1.0f32, f32::min);
            whole.min(1.0)
        } else if fit.true_size {
            1.0
        } else {
            scale
        };
        let centre = (b.min + b.max) * 0.5;
        let base_z = if fit.placement == Placement::Surface {
            // The front (the top of the bounds along +z) in the glass.
            -size.z * scale
        } else {
            -size.z * scale * (1.0 - fit.protrude_fraction)
        };
        let m = Mat4::from_translation(Vec3::new(0.0, 0.0, base_z))
            * Mat4::from_scale(Vec3::splat(scale))
            * Mat4::from_translation(Vec3::new(-centre.x, -centre.y, -b.min.z));
        self.transform(m);
        scale
    }
}

pub use gpu_blocks::{BasisSource, BlockFormat, BlockLevel};
pub use layer_arrays::{LayerArray, LayerArrays, MaterialLayers};
pub use layer_textures::{LayerSlot, LayerTextures};
pub use layers::Layers;
pub use loader::{
    MAX_COORDINATE, ModelError, SUPPORTED_EXTENSIONS, load_gltf, load_gltf_with, load_gltf_within, load_model,
    load_model_with, load_model_within, resolve_inside, voyager_annotations, voyager_preview, voyager_rotation,
    voyager_scan,
};
pub use mesh_file::MeshFormat;

mod e57;
mod encoded_image;
mod epsg_units;
mod file_texture;
pub mod gpu_blocks;
mod instancing;
pub mod join;
mod las;
mod las_crs;
pub mod layer_arrays;
pub mod layer_textures;
pub mod layers;
mod laz_chunks;
mod laz_layers;
mod le_fields;
mod loader;
mod mesh_file;
mod meshopt_views;
mod nearest;
mod obj;
mod ply;
mod point_cloud;
mod scan_points;
mod skin;
mod spec_gloss;
mod split;
mod stl;
mod tangents;
mod texture_info;
mod topology;
mod usd;
mod usd_files;
mod usd_material;
mod usd_mesh;
mod usd_preview_surface;
mod usd_shapes;
mod wkt;
mod xyz;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn surface_mode_lays_the_front_in_the_glass_at_true_size() {
        let screen = Screen::default();
        let cuboid = |size: Vec3| {
            let mut mesh = Mesh::default();
            mesh.push_cube(Vec3::ZERO, 0.5, [1.0; 4]);
            mesh.transform(Mat4::from_scale(size));
            mesh
        };
        // A tile 40 × 30 mm, 5 mm thick, facing +z in glTF axes.
        let tile = || Model::from_painted_mesh("tile", cuboid(Vec3::new(0.04, 0.03, 0.005)));
        let surface = DioramaFit {
            placement: Placement::Surface,
            ..DioramaFit::default()
        };
        let mut m = tile();
        let scale = m.fit_to_diorama(&screen, &surface);
        let b = m.bounds().expect("bounds");
        assert_eq!(scale, 1.0, "true size");
        assert!(
            b.max.z.abs() < 1e-6 && (b.min.z + 0.005).abs() < 1e-6,
            "front in the glass: {b:?}"
        );
        assert!((b.max.x - b.min.x - 0.04).abs() < 1e-6 && (b.max.y - b.min.y - 0.03).abs() < 1e-6);
        // The same tile in the default fit is scaled to the diorama and stands partly out.
        let mut d = tile();
        d.fit_to_diorama(&screen, &DioramaFit::default());
        assert!(d.bounds().expect("bounds").max.z > 1e-3);
        // A painting a metre wide is shrunk to fit the screen, never enlarged.
        let mut big = Model::from_painted_mesh("painting", cuboid(Vec3::new(1.0, 0.8, 0.02)));
        let scale = big.fit_to_diorama(&screen, &surface);
        let b = big.bounds().expect("bounds");
        assert!(
            scale < 0.1 && b.max.x - b.min.x <= screen.panel_width_m() + 1e-6,
            "{scale}"
        );
        assert!(b.max.z.abs() < 1e-6);
    }

    #[test]
    fn only_rough_or_refracting_glass_needs_what_is_behind_it() {
        let glass = |roughness: f32, ior: f32, thickness: f32| Material {
            roughness,
            metallic: 0.0,
            layers: Layers {
                transmission: 1.0,
                ior,
                thickness,
                ..Layers::default()
            },
            ..Material::default()
        };
        assert!(!glass(0.0, 1.5, 0.0).blurs_or_bends(), "smooth thin glass filters");
        assert!(glass(0.3, 1.5, 0.0).blurs_or_bends(), "frosted");
        assert!(glass(0.0, 1.5, 0.01).blurs_or_bends(), "a refracting volume");
        assert!(
            !glass(0.0, 1.0, 0.01).blurs_or_bends(),
            "a volume of index 1 bends nothing"
        );
        assert!(
            glass(0.0, f32::INFINITY, 0.01).blurs_or_bends(),
            "an infinite index bends"
        );
        assert!(!glass(0.0, 1.5, 0.01).blurs(), "it bends but does not blur");
        assert!(
            !glass(0.7, 1.0, 0.0).blurs_or_bends(),
            "rough, of index 1: nothing turns"
        );
        let opaque = Material {
            layers: Layers {
                transmission: 0.0,
                ..glass(0.5, 1.5, 0.01).layers
            },
            ..glass(0.5, 1.5, 0.01)
        };
        assert!(!opaque.blurs_or_bends(), "nothing passes: nothing to blur");
        let unlit = Material {
            unlit: true,
            ..glass(0.5, 1.5, 0.01)
        };
        assert!(!unlit.blurs_or_bends(), "an unlit surface lets nothing through");
    }

    #[test]
    fn a_fit_scales_the_volume_of_glass_with_its_mesh() {
        let mut mesh = Mesh::default();
        mesh.push_cube(Vec3::ZERO, 0.5, [1.0; 4]);
        let mut m = Model::from_painted_mesh("paperweight", mesh);
        m.materials[0].layers.thickness = 0.5;
        m.materials[0].layers.attenuation_distance = 2.0;
        let absorbed = m.materials[0].layers.absorption_per_unit();
        let scale = m.fit_to_diorama(&Screen::default(), &DioramaFit::default());
        assert!(scale < 0.1, "a metre cube is shrunk: {scale}");
        let l = m.materials[0].layers;
        assert!(
            (l.thickness - 0.5 * scale).abs() < 1e-7,
            "{} vs {}",
            l.thickness,
            0.5 * scale
        );
        assert!((l.attenuation_distance - 2.0 * scale).abs() < 1e-6);
        // The absorption over the wall is the same.
        let after = l.absorption_per_unit();
        for (a, b) in absorbed.iter().zip(after) {
            assert!((a * 0.5 - b * l.thickness).abs() < 1e-5, "{absorbed:?} vs {after:?}");
        }
        // An infinite distance (nothing absorbed) stays infinite; a bad scale changes nothing.
        let mut clear = Layers::default();
        clear.scale_lengths(0.5);
        assert!(clear.attenuation_distance.is_infinite());
        clear.thickness = 1.0;
        for bad in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            clear.scale_lengths(bad);
        }
        assert_eq!(clear.thickness, 1.0);
    }

    #[test]
    fn uv_transform_matches_the_extension_definition() {
        // Rotation by 90° maps (1, 0) to (0, −1) in UV space (counter-clockwise with v down).
        let t = UvTransform {
            offset: [0.5, 0.25],
            rotation_rad: std::f32::consts::FRAC_PI_2,
            scale: [2.0, 3.0],
        };
        let uv = t.apply([1.0, 0.0]);
        assert!(
            (uv[0] - 0.5).abs() < 1e-6 && (uv[1] - (0.25 - 2.0)).abs() < 1e-6,
            "{uv:?}"
        );
        assert_eq!(UvTransform::default().apply([0.3, 0.7]), [0.3, 0.7]);
    }

    #[test]
    fn cube_faces_wind_outwards() {
        let mut m = Mesh::default();
        m.push_cube(Vec3::ZERO, 1.0, [1.0; 4]);
        for tri in m.indices.chunks(3) {
            let p = |i: u32| Vec3::from(m.vertices[i as usize].position);
            let (a, b, c) = (p(tri[0]), p(tri[1]), p(tri[2]));
            let n = (b - a).cross(c - a);
            let centre = (a + b + c) / 3.0;
            assert!(n.dot(centre) > 0.0, "triangle {tri:?} winds inwards");
        }
    }

    #[test]
    fn mirroring_transform_flips_the_winding() {
        let mut m = Mesh::default();
        m.push_cube(Vec3::ZERO, 1.0, [1.0; 4]);
        m.transform(Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)));
        for tri in m.indices.chunks(3) {
            let p = |i: u32| Vec3::from(m.vertices[i as usize].position);
            let n = (p(tri[1]) - p(tri[0])).cross(p(tri[2]) - p(tri[0]));
            assert!(n.dot((p(tri[0]) + p(tri[1]) + p(tri[2])) / 3.0) > 0.0);
        }
    }

    #[test]
    fn fitting_stands_the_model_up_and_straddles_the_glass() {
        // A 2 m tall, 1 m wide box, +Y up.
        let mut mesh = Mesh::default();
        mesh.push_cube(Vec3::ZERO, 0.5, [1.0; 4]);
        mesh.transform(Mat4::from_scale(Vec3::new(1.0, 2.0, 1.0)));
        let mut model = Model::from_painted_mesh("box", mesh);
        let fit = DioramaFit {
            placement: Placement::Standing,
            ..DioramaFit::default()
        };
        model.fit_to_diorama(&Screen::default(), &fit);
        let b = model.bounds().unwrap();
        assert!(
            (b.max.z - b.min.z - fit.max_height_m).abs() < 1e-6,
            "height along z: {b:?}"
        );
        assert!((b.max.z - fit.max_height_m * fit.protrude_fraction).abs() < 1e-6);
        assert!((b.min.x + b.max.x).abs() < 1e-6 && (b.min.y + b.max.y).abs() < 1e-6);
    }

    #[test]
    fn auto_placement_lays_flat_things_in_the_glass() {
        let panel = Vec3::new(1.0, 0.8, 0.05);
        let vase = Vec3::new(0.4, 1.0, 0.4);
        assert_eq!(Placement::Auto.rotation(panel), Quat::IDENTITY);
        assert_eq!(Placement::Auto.rotation(vase), Placement::Standing.rotation(vase));
        // Standing: glTF up becomes the glass normal, glTF front the screen's bottom edge.
        let q = Placement::Standing.rotation(vase);
        assert!((q * Vec3::Y - Vec3::Z).length() < 1e-6 && (q * Vec3::Z + Vec3::Y).length() < 1e-6);
    }
}
