//! # Phantogram render
//!
//! The renderer: draws the artifact for each eye with its own off-axis projection and composes
//! the pair (anaglyph or mono) in linear light, into an offscreen target read back as an image or
//! onto a window surface ([`surface`], the lifecycle the phones and the desktop viewer share).
//! Depends on `phantogram_geometry` (projections, anaglyph matrices), `phantogram_assets` (what it
//! uploads), nothing of the sensors (the engine turns a session's frame into a [`FrameInput`]);
//! `wgpu` (the chosen
//! stack), `pollster` to wait on its few futures, `bytemuck` for uniform and vertex layouts,
//! `half` to pack f16 textures.
//!
//! ## Passes per frame
//! 1. Shadow pass, once for both eyes: depth from the world-fixed light (orthographic over the
//!    model without its floor, which only receives unless the light is below it), both faces of
//!    every surface; alpha-masked materials are cut out as in the scene pass
//!    (their shadows have the holes they have), blended ones cast none. A [`Lamp`] in its place
//!    is seen from one perspective view, or, standing among what it shadows, from the six faces
//!    of a cube ([`point_shadow`]: six passes of 512² texels).
//! 2. Scene pass per eye into a linear HDR target (`Rgba16Float`) with reverse-Z depth
//!    (`Depth32Float`, cleared to 0, compare `Greater`): the core's projections map near to 1.
//!    Opaque and masked primitives first, then blended ones back to front (depth test, no depth
//!    write). Mono renders only the cyclopean eye. Light, materials and textures are shared by
//!    both eyes; only the small per-eye uniform differs. A primitive whose level is
//!    [`IMPOSTOR_LEVEL`] and that has one baked is drawn as its relief-texture impostor
//!    ([`impostor`]; it casts the shadow of its polygon level as exact as it is); a primitive in
//!    [`FrameInput::fades`] is drawn at both its levels, each on its share of the pixels
//!    (pipelines with `FADE` set and the fade per instance, `vs_fade`).
//! 3. Composition pass: tone mapping (Khronos PBR Neutral, exposure) of each eye, then the
//!    anaglyph matrices ([`phantogram_geometry::anaglyph`]) in linear light, into an `Rgba8UnormSrgb` target.
//!
//! ## Models
//! [`Model`]s upload as one vertex and index buffer per primitive, one bind group per material
//! (uniform block, five textures and their samplers; missing textures bind 1×1 defaults), one
//! scene pipeline per kind of material (culling, blending, alpha mask, and which texture slots it
//! has: the fragment shader is specialised by `override` constants and does not sample the
//! defaults, the same picture for a fifth less time on lavapipe), and
//! textures with full mip chains generated here (colour textures averaged in linear light, then
//! viewed as sRGB so the sampler decodes them).
//!
//! ## Devices
//! [`Gpu::headless`] asks wgpu for any adapter of the backends in `WGPU_BACKEND` (default: all),
//! preferring real hardware and falling back to a software one (Mesa's lavapipe, which is how tests
//! and CI run: Debian's `mesa-vulkan-drivers`). No display is needed: a window handed over later
//! brings its own display handle (as on the phones).
//!
//! **Threading**: a [`Renderer`] belongs to one thread; wgpu's device and queue are internally
//! synchronised. [`prepare_lighting_tables`] may run on any thread (once per process; a renderer
//! created meanwhile waits for it rather than computing the tables twice). **Panics**: none on
//! bad input; GPU failures come back as [`RenderError`].

use glam::{Mat4, Vec3};
use thiserror::Error;
use wgpu::util::DeviceExt;

pub use phantogram_assets::appearance::Appearance;
pub use phantogram_assets::model::LevelFade;
use phantogram_assets::model::{AlphaMode, Material, Model, Sampler, TextureRef, Vertex, Wrap};
pub use phantogram_assets::ward;
use phantogram_assets::ward::WardMap;
use phantogram_geometry::anaglyph::Method;
use phantogram_geometry::projection::OffAxisProjection;

mod gpu;
mod gpu_timer;
pub mod impostor;
mod lighting_tables;
pub mod point_shadow;
pub mod prefilter_gpu;
pub mod surface;
mod upload;

/// The wgpu this crate is built on, for shells that hand it window handles.
pub use wgpu;

pub use gpu::Gpu;
pub use impostor::{IMPOSTOR_LEVEL, ImpostorBox};
use lighting_tables::*;
pub use lighting_tables::{PREFILTERED_BASE_WIDTH, prepare_lighting_tables, prepare_lighting_tables_in_background};
pub use upload::mip_chain;
use upload::*;

/// WGSL sources, validated by naga in the tests.
pub const SCENE_WGSL: &str = include_str!("../../../shaders/scene.wgsl");
pub const COMPOSE_WGSL: &str = include_str!("../../../shaders/compose.wgsl");

const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Shadow map resolution: 1024² texels over what casts shadows, the model without its floor
/// ([`GpuModel::shadow_casters`]): 75 µm per texel for the default artifact, about a pixel of the
/// 1080×2400 screen (60 µm). Over the floor's extent as well it took 2048² texels to reach 390 µm.
const SHADOW_SIZE: u32 = 1024;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
const OUTPUT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
/// Background radiance behind the artifact: a neutral mid-dark grey, the inside of the diorama
/// box. Light enough for black glaze to read against it, dark enough for the red/cyan filters.
const CLEAR_RADIANCE: wgpu::Color = wgpu::Color {
    r: 0.07,
    g: 0.07,
    b: 0.075,
    a: 1.0,
};

#[derive(Debug, Error)]
pub enum RenderError {
    #[error(
        "no GPU adapter found (for software rendering on Linux install Mesa's Vulkan driver: apt-get install mesa-vulkan-drivers libvulkan1)"
    )]
    NoAdapter,
    #[error("could not open the GPU device: {0}")]
    Device(String),
    #[error("frame size {width}×{height} is not supported (1 to {max} pixels per side)")]
    BadSize { width: u32, height: u32, max: u32 },
    /// An offscreen frame is read back through one buffer, whose size the device limits.
    #[error(
        "frame size {width}×{height} needs a {bytes}-byte read-back buffer, over this GPU's limit of {max_bytes} bytes"
    )]
    FrameTooLarge {
        width: u32,
        height: u32,
        bytes: u64,
        max_bytes: u64,
    },
    #[error("the model has nothing to draw")]
    EmptyModel,
    #[error("the GPU rejected {what}: {message}")]
    Gpu { what: &'static str, message: String },
    #[error("reading the frame back from the GPU failed: {0}")]
    Readback(String),
}

/// Per-eye uniform block; matches `Eye` in `scene.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct EyeUniform {
    view_proj: [[f32; 4]; 4],
    eye_pos: [f32; 4],
    toward_light: [f32; 4],
    light: [f32; 4],
    world_from_device: [[f32; 4]; 3],
    light_view_proj: [[f32; 4]; 4],
    /// Texel size (metres) and on/off of the shadow map; the angle a pixel subtends (radians).
    shadow: [f32; 4],
    sh: [[f32; 4]; 9],
    /// The artifact's [`Appearance`], as `Appearance` in `scene.wgsl` lays it out.
    appearance: [[f32; 4]; 5],
    /// The [`Lamp`], if one shines: position (w: 1 when on), axis (w: cos outer), intensity (w:
    /// cos inner).
    lamp: [[f32; 4]; 3],
    /// The lamp's cube shadow ([`point_shadow`]): near and far (metres), texels a face, and 1 when
    /// the lamp's shadows are read from it.
    lamp_shadow: [f32; 4],
}

/// A lamp in place of the directional light: a point light, or a spot light with a cone, in
/// mesh coordinates (the device frame, metres), with its shadows from a perspective shadow map,
/// or from a cube of them when it stands among what it shadows ([`point_shadow`]).
/// The engine places it each frame (held like a torch, or fixed in the room, or where a finger
/// put it); see `phantogram::lamp`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lamp {
    pub position_m: Vec3,
    /// The cone's axis (any length; normalised here). Unused by a point light.
    pub axis: Vec3,
    /// Half-angle of the cone, radians (a spot light), up to just under 90°; `None`: a point
    /// light shining every way.
    pub cone_half_angle_rad: Option<f32>,
    /// Radiant intensity, linear RGB per steradian: the irradiance at 1 m head-on.
    pub intensity_rgb: Vec3,
}

impl Lamp {
    /// The uniform's three rows (see `EyeUniform::lamp`); zero (off) for `None` or a lamp with
    /// non-finite numbers.
    fn uniform(lamp: Option<&Lamp>) -> [[f32; 4]; 3] {
        let Some(l) = lamp.filter(|l| l.is_finite()) else {
            return [[0.0; 4]; 3];
        };
        let axis = l.axis.normalize_or(-Vec3::Z);
        let (cos_outer, cos_inner) = match l.cone_half_angle_rad {
            // The last tenth of the cone fades (a soft edge, as a real spot has).
            Some(a) => {
                let a = a.clamp(0.01, 1.55);
                (a.cos(), (a * 0.9).cos())
            }
            None => (-2.0, -1.0),
        };
        [
            l.position_m.extend(1.0).to_array(),
            axis.extend(cos_outer).to_array(),
            l.intensity_rgb.max(Vec3::ZERO).extend(cos_inner).to_array(),
        ]
    }

    /// Whether every number is finite (a lamp that is not shines nowhere: off).
    fn is_finite(&self) -> bool {
        self.position_m.is_finite()
            && self.axis.is_finite()
            && self.intensity_rgb.is_finite()
            && self.cone_half_angle_rad.is_none_or(f32::is_finite)
    }

    /// Direction towards the lamp from `point`, for choosing what casts shadows.
    fn toward_from(&self, point: Vec3) -> Vec3 {
        (self.position_m - point).normalize_or(Vec3::Z)
    }
}

/// The perspective shadow view of a lamp over `bounds` (mesh coordinates) and the size of a
/// texel at the bounds' centre in metres; `None` when the lamp is within the bounds' sphere (no
/// single view sees all it shadows: the renderer then draws a cube of views, [`point_shadow`]).
pub fn lamp_view_proj(bounds: &phantogram_geometry::containment::Aabb, lamp: &Lamp) -> Option<(Mat4, f32)> {
    let centre = (bounds.min + bounds.max) * 0.5;
    let radius = (bounds.max - bounds.min).length() * 0.5 + 1e-4;
    let to_centre = centre - lamp.position_m;
    let distance = to_centre.length();
    if !distance.is_finite() || distance <= radius * 1.05 {
        return None;
    }
    let forward = to_centre / distance;
    let up = if forward.z.abs() < 0.9 { Vec3::Z } else { Vec3::Y };
    let view = Mat4::look_at_rh(lamp.position_m, centre, up);
    // The cone that holds the bounds' sphere, with a margin of a few texels.
    let half = (radius / distance).asin() * (1.0 + 4.0 / SHADOW_SIZE as f32);
    let near = (distance - radius).max(1e-3);
    let proj = Mat4::perspective_rh(2.0 * half, 1.0, near, distance + radius);
    let texel = 2.0 * distance * half.tan() / SHADOW_SIZE as f32;
    Some((proj * view, texel))
}

/// `Appearance` in `scene.wgsl`: rgb tint and specular scale; roughness and metalness overrides
/// (negative: keep), clear coat and its roughness; Ward ρd (w: 1 when on), ρs, and αx, αy and
/// the side of its map's tile in metres (0: no map).
fn appearance_uniform(a: &Appearance) -> [[f32; 4]; 5] {
    let a = a.sanitised();
    let ward = a.ward.unwrap_or(phantogram_assets::ward::WardPreset::Matte.material());
    let on = f32::from(u8::from(a.ward.is_some()));
    [
        [a.tint[0], a.tint[1], a.tint[2], a.specular],
        [
            a.roughness.unwrap_or(-1.0),
            a.metalness.unwrap_or(-1.0),
            a.clear_coat,
            a.clear_coat_roughness,
        ],
        [ward.rho_d[0], ward.rho_d[1], ward.rho_d[2], on],
        [ward.rho_s[0], ward.rho_s[1], ward.rho_s[2], 0.0],
        [ward.alpha_x, ward.alpha_y, ward.map.tile_m(), 0.0],
    ]
}

/// Matches `Compose` in `compose.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ComposeUniform {
    left: [[f32; 4]; 3],
    right: [[f32; 4]; 3],
    params: [f32; 4],
}

/// Matches `Material` in `scene.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct MaterialUniform {
    base_color: [f32; 4],
    emissive: [f32; 4],
    params: [f32; 4],
    uv_sets: [f32; 4],
    flags: [f32; 4],
    transforms: [[f32; 4]; 10],
    scene: [f32; 4],
}

impl MaterialUniform {
    fn new(m: &Material) -> Self {
        let slots = [
            m.base_color_texture,
            m.metallic_roughness_texture,
            m.normal_texture.map(|(t, _)| t),
            m.occlusion_texture.map(|(t, _)| t),
            m.emissive_texture,
        ];
        let mut transforms = [[0.0; 4]; 10];
        for (i, slot) in slots.iter().enumerate() {
            let rows = slot.map(|t| t.transform).unwrap_or_default().rows();
            transforms[2 * i] = [rows[0][0], rows[0][1], rows[0][2], 0.0];
            transforms[2 * i + 1] = [rows[1][0], rows[1][1], rows[1][2], 0.0];
        }
        let set = |t: Option<TextureRef>| t.map_or(0.0, |t| t.tex_coord as f32);
        Self {
            base_color: m.base_color,
            emissive: [
                m.emissive[0],
                m.emissive[1],
                m.emissive[2],
                m.normal_texture.map_or(1.0, |(_, s)| s),
            ],
            params: [
                m.metallic,
                m.roughness,
                match m.alpha {
                    AlphaMode::Mask(cutoff) => cutoff,
                    _ => -1.0,
                },
                m.occlusion_texture.map_or(0.0, |(_, s)| s),
            ],
            uv_sets: [set(slots[0]), set(slots[1]), set(slots[2]), set(slots[3])],
            flags: [
                set(slots[4]),
                f32::from(u8::from(m.normal_texture.is_some())),
                f32::from(u8::from(m.alpha == AlphaMode::Blend)),
                f32::from(u8::from(m.unlit)),
            ],
            transforms,
            scene: [f32::from(u8::from(m.scenery)), 0.0, 0.0, 0.0],
        }
    }
}

/// Lighting shared by both eyes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lighting {
    /// Radiance of the directional light, linear RGB.
    pub light_rgb: Vec3,
    /// Scale of the environment's light ([`phantogram_assets::ibl`]).
    pub environment_intensity: f32,
    /// Linear exposure multiplier before tone mapping.
    pub exposure: f32,
    /// Shadows from the directional light (one shadow map per frame, shared by both eyes).
    pub shadows: bool,
}

impl Default for Lighting {
    fn default() -> Self {
        Self {
            light_rgb: Vec3::new(3.2, 3.05, 2.85),
            environment_intensity: 1.0,
            exposure: 1.0,
            shadows: true,
        }
    }
}

/// What to draw for one frame, in the device frame.
#[derive(Clone, Copy, Debug)]
pub struct FrameInput<'a> {
    pub left: &'a OffAxisProjection,
    pub right: &'a OffAxisProjection,
    pub mono: &'a OffAxisProjection,
    pub toward_light: Vec3,
    /// Device → world orientation: the environment light is fixed in the room.
    pub device_to_world: glam::Quat,
    /// Translation applied to the mesh this frame (containment's push-back).
    pub offset: Vec3,
    /// The level of detail drawn for each of the model's primitives, by index (0 is the full
    /// mesh, l its `lods[l − 1]`; `phantogram-detail` chooses them). A level past a primitive's
    /// chain draws its coarsest; a primitive without an entry (all of them, for an empty slice)
    /// is drawn at full detail.
    pub levels: &'a [u8],
    /// Primitives cross-fading from another level to theirs in `levels` (at most one entry a
    /// primitive; `phantogram-detail`'s `fade` makes them): both drawn, each on its share of the
    /// pixels. Blended primitives switch at once.
    pub fades: &'a [LevelFade],
}

impl<'a> FrameInput<'a> {
    /// The projections a method draws: both eyes for stereo, the cyclopean eye for mono.
    pub fn eyes_drawn(&self, method: Method) -> Vec<&'a OffAxisProjection> {
        if method.is_stereo() {
            vec![self.left, self.right]
        } else {
            vec![self.mono]
        }
    }
}

struct Targets {
    width: u32,
    height: u32,
    hdr: [wgpu::TextureView; 2],
    depth: wgpu::TextureView,
    compose_bind: [wgpu::BindGroup; 2],
    /// Only when rendering headless: drawing to a window composes into its swapchain image.
    offscreen: Option<Offscreen>,
}

/// The composed frame's texture and the buffer it is read back through.
struct Offscreen {
    output: wgpu::Texture,
    output_view: wgpu::TextureView,
    readback: wgpu::Buffer,
    padded_row: u32,
}

impl Offscreen {
    /// Bytes per row of the read-back buffer: RGBA8, padded to wgpu's copy alignment.
    fn padded_row(width: u32) -> u64 {
        let align = u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        (u64::from(width) * 4).div_ceil(align) * align
    }

    fn new(device: &wgpu::Device, width: u32, height: u32) -> Self {
        let output = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("output"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: OUTPUT_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let output_view = output.create_view(&Default::default());
        // At most 4 × max_texture_dimension_2d, checked before (`targets`).
        let padded_row = Self::padded_row(width) as u32;
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: u64::from(padded_row) * u64::from(height),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        Self {
            output,
            output_view,
            readback,
            padded_row,
        }
    }
}

struct GpuPrimitive {
    vertices: wgpu::Buffer,
    /// Vertices in `vertices` (for [`Renderer::update_vertices`]).
    vertex_count: usize,
    /// The full mesh's indices, then each coarser level's.
    indices: wgpu::Buffer,
    /// Each level's range of `indices`, the full mesh first, and its geometric error, metres.
    levels: Vec<std::ops::Range<u32>>,
    level_errors_m: Vec<f32>,
    /// Which of the model's primitives this is (a piece of, for a mesh larger than a buffer).
    source: usize,
    material: usize,
    centre: Vec3,
    /// This piece's bounds (mesh coordinates), for culling it from the lamp cube's faces;
    /// `None` for a mesh without vertices.
    bounds: Option<phantogram_geometry::containment::Aabb>,
    is_floor: bool,
}

impl GpuPrimitive {
    /// Binds the buffers and draws the level `levels` chooses for it (see
    /// [`FrameInput::levels`]), with whatever pipeline and bind groups are set.
    fn draw(&self, pass: &mut wgpu::RenderPass<'_>, levels: &[u8]) {
        self.draw_at(pass, levels.get(self.source).copied().unwrap_or(0), 0);
    }

    /// Triangles [`Self::draw`] draws at `levels`.
    fn triangles_at(&self, levels: &[u8]) -> u64 {
        let level = usize::from(levels.get(self.source).copied().unwrap_or(0));
        self.levels
            .get(level)
            .or(self.levels.last())
            .map_or(0, |r| u64::from(r.end - r.start) / 3)
    }

    /// Draws level `level` (past the chain: the coarsest) as instance `instance`.
    fn draw_at(&self, pass: &mut wgpu::RenderPass<'_>, level: u8, instance: u32) {
        let Some(range) = self.levels.get(usize::from(level)).or(self.levels.last()) else {
            return;
        };
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(range.clone(), 0, instance..instance + 1);
    }
}

struct GpuMaterial {
    bind: wgpu::BindGroup,
    variant: MaterialVariant,
    // Kept alive for the bind group.
    _uniform: wgpu::Buffer,
}

/// A model on the GPU.
struct GpuModel {
    primitives: Vec<GpuPrimitive>,
    materials: Vec<GpuMaterial>,
    /// Everything, floor included.
    bounds: phantogram_geometry::containment::Aabb,
    /// Everything but the floor (all of it if there is nothing else).
    standing: phantogram_geometry::containment::Aabb,
    /// Baked impostors by the model's primitive index ([`Renderer::bake_impostors`]).
    impostors: Vec<Option<impostor::GpuImpostor>>,
}

impl GpuModel {
    /// What casts shadows this frame, and the bounds the shadow map must cover. The floor is a
    /// plane under everything that faces +z: lit from above it shadows nothing, so the map covers
    /// only what stands on it, at the resolution that detail needs (with the floor, 2.5 screens
    /// out, a texel would be ~10× coarser and the shadow blurred and detached from the feet).
    /// With the light below its plane the floor does cast (it hides the light from all it holds).
    fn shadow_casters(&self, toward_light: Vec3) -> (bool, phantogram_geometry::containment::Aabb) {
        let floor_casts = toward_light.z < 0.0;
        (floor_casts, if floor_casts { self.bounds } else { self.standing })
    }
}

/// The orthographic light view over `bounds` (mesh coordinates) and its texel size in metres.
pub fn light_view_proj(bounds: &phantogram_geometry::containment::Aabb, toward_light: Vec3) -> (Mat4, f32) {
    let l = toward_light.normalize_or(Vec3::Z);
    let centre = (bounds.min + bounds.max) * 0.5;
    let radius = (bounds.max - bounds.min).length() * 0.5 + 1e-4;
    let up = if l.z.abs() < 0.9 { Vec3::Z } else { Vec3::Y };
    let view = Mat4::look_at_rh(centre + l * (2.0 * radius), centre, up);
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for c in bounds.corners() {
        let p = view.transform_point3(c);
        lo = lo.min(p);
        hi = hi.max(p);
    }
    // A texel of margin on every side so PCF taps at the edge stay inside.
    let margin = (hi.x - lo.x).max(hi.y - lo.y) / SHADOW_SIZE as f32 * 2.0;
    let proj = Mat4::orthographic_rh(
        lo.x - margin,
        hi.x + margin,
        lo.y - margin,
        hi.y + margin,
        -hi.z - margin,
        -lo.z + margin,
    );
    let texel = ((hi.x - lo.x).max(hi.y - lo.y) + 2.0 * margin) / SHADOW_SIZE as f32;
    (proj * view, texel)
}

/// What a material's scene pipeline is specialised for: culling and blending, and which texture
/// slots it samples and whether it can discard (WGSL `override` constants in `scene.wgsl`).
/// Slots a material lacks hold 1×1 defaults that change nothing, so not sampling them gives the
/// same picture for less: on lavapipe the fragment work is most of a frame, and every texture
/// sample and the shadow filter are a large part of it (see `benchmarks/render.md`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct MaterialVariant {
    double_sided: bool,
    blend: bool,
    /// Base colour, metallic-roughness, normal, occlusion, emissive: sampled or not.
    textures: [bool; 5],
    /// Alpha mask: the shader may discard (which also costs early depth testing).
    mask: bool,
    /// The pipeline of a cross-fade's draws (`vs_fade`, the per-instance fade, and a
    /// screen-door discard); made for the materials of primitives with levels of detail.
    fade: bool,
}

impl MaterialVariant {
    /// Casts its shadow through the alpha-masked shadow pipeline (blended surfaces cast none).
    fn casts_masked_shadow(&self) -> bool {
        self.mask && !self.blend
    }
}

/// Names of the `override` constants in `scene.wgsl`, in [`MaterialVariant::textures`] order.
const TEXTURE_OVERRIDES: [&str; 5] = [
    "HAS_BASE_TEXTURE",
    "HAS_METALLIC_ROUGHNESS_TEXTURE",
    "HAS_NORMAL_TEXTURE",
    "HAS_OCCLUSION_TEXTURE",
    "HAS_EMISSIVE_TEXTURE",
];

/// Scene pipelines, one per [`MaterialVariant`] in use, created when a model is set (never while
/// drawing: compiling a shader takes a good part of a frame).
struct ScenePipelines {
    module: wgpu::ShaderModule,
    layout: wgpu::PipelineLayout,
    variants: std::collections::HashMap<MaterialVariant, wgpu::RenderPipeline>,
    /// The light's matrix and a material: what the shadow pass of a masked material reads.
    shadow_masked_layout: wgpu::PipelineLayout,
    /// Shadow pass for alpha-masked materials (cut out as in the scene pass), made with the first
    /// model that has one.
    shadow_masked: Option<wgpu::RenderPipeline>,
}

impl ScenePipelines {
    fn get(&self, variant: &MaterialVariant) -> Option<&wgpu::RenderPipeline> {
        self.variants.get(variant)
    }

    /// Creates the pipelines of `model`'s materials that do not exist yet, with the cross-fade
    /// variants of those its primitives with levels of detail use.
    fn prepare(&mut self, device: &wgpu::Device, model: &GpuModel) {
        let fading = model
            .primitives
            .iter()
            .filter(|p| p.levels.len() > 1)
            .map(|p| model.materials[p.material].variant)
            .filter(|v| !v.blend)
            .map(|v| MaterialVariant { fade: true, ..v });
        let variants: Vec<MaterialVariant> = model.materials.iter().map(|m| m.variant).chain(fading).collect();
        for v in variants {
            if !self.variants.contains_key(&v) {
                let pipeline = self.create(device, &v);
                self.variants.insert(v, pipeline);
            }
        }
        let casts_masked = model.materials.iter().any(|m| m.variant.casts_masked_shadow());
        if casts_masked && self.shadow_masked.is_none() {
            self.shadow_masked = Some(self.create_shadow_masked(device));
        }
    }

    fn create_shadow_masked(&self, device: &wgpu::Device) -> wgpu::RenderPipeline {
        let attributes = [
            wgpu::VertexAttribute {
                format: wgpu::VertexFormat::Float32x3,
                offset: std::mem::offset_of!(Vertex, position) as u64,
                shader_location: 0,
            },
            wgpu::VertexAttribute {
                format: wgpu::VertexFormat::Float32x4,
                offset: std::mem::offset_of!(Vertex, uv) as u64,
                shader_location: 3,
            },
            wgpu::VertexAttribute {
                format: wgpu::VertexFormat::Float32x4,
                offset: std::mem::offset_of!(Vertex, color) as u64,
                shader_location: 4,
            },
        ];
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("shadow (alpha-masked)"),
            layout: Some(&self.shadow_masked_layout),
            vertex: wgpu::VertexState {
                module: &self.module,
                entry_point: Some("vs_shadow_masked"),
                compilation_options: Default::default(),
                buffers: &[Some(vertex_buffer(&attributes))],
            },
            primitive: SHADOW_PRIMITIVE,
            depth_stencil: Some(shadow_depth_state()),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &self.module,
                entry_point: Some("fs_shadow_masked"),
                compilation_options: Default::default(),
                targets: &[],
            }),
            multiview_mask: None,
            cache: None,
        })
    }

    fn create(&self, device: &wgpu::Device, v: &MaterialVariant) -> wgpu::RenderPipeline {
        let vertex_attributes = wgpu::vertex_attr_array![
            0 => Float32x3, 1 => Float32x3, 2 => Float32x4, 3 => Float32x4, 4 => Float32x4, 5 => Float32x2
        ];
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        let mut constants: Vec<(&str, f64)> = TEXTURE_OVERRIDES
            .iter()
            .zip(v.textures)
            .map(|(name, has)| (*name, flag(has)))
            .collect();
        constants.push(("ALPHA_MASK", flag(v.mask)));
        constants.push(("FADE", flag(v.fade)));
        let fade_attributes = FADE_ATTRIBUTES;
        let plain = [Some(vertex_buffer(&vertex_attributes))];
        let fading = [
            Some(vertex_buffer(&vertex_attributes)),
            Some(fade_buffer_layout(&fade_attributes)),
        ];
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(if v.fade { "scene (cross-fade)" } else { "scene" }),
            layout: Some(&self.layout),
            vertex: wgpu::VertexState {
                module: &self.module,
                entry_point: Some(if v.fade { "vs_fade" } else { "vs_main" }),
                compilation_options: Default::default(),
                buffers: if v.fade { &fading } else { &plain },
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                front_face: wgpu::FrontFace::Ccw,
                cull_mode: (!v.double_sided).then_some(wgpu::Face::Back),
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                // Blended surfaces are drawn back to front over the opaque ones and must not
                // hide each other.
                depth_write_enabled: Some(!v.blend),
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &self.module,
                entry_point: Some("fs_main"),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &constants,
                    ..Default::default()
                },
                targets: &[Some(wgpu::ColorTargetState {
                    format: HDR_FORMAT,
                    blend: v.blend.then_some(wgpu::BlendState::ALPHA_BLENDING),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        })
    }
}

/// The per-instance cross-fade (`vs_fade`, `vs_impostor`): fraction shown and side.
const FADE_ATTRIBUTES: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![6 => Float32x2];

/// The cross-fades' instance buffer: one `[f32; 2]` per draw ([`Renderer::write_fades`]).
fn fade_buffer_layout(attributes: &[wgpu::VertexAttribute]) -> wgpu::VertexBufferLayout<'_> {
    wgpu::VertexBufferLayout {
        array_stride: 8,
        step_mode: wgpu::VertexStepMode::Instance,
        attributes,
    }
}

/// A model's vertex buffer ([`Vertex`]), of which a pipeline reads `attributes`.
fn vertex_buffer(attributes: &[wgpu::VertexAttribute]) -> wgpu::VertexBufferLayout<'_> {
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes,
    }
}

/// The shadow pass's triangles: both faces cast, since open and double-sided surfaces must
/// shadow too.
const SHADOW_PRIMITIVE: wgpu::PrimitiveState = wgpu::PrimitiveState {
    topology: wgpu::PrimitiveTopology::TriangleList,
    strip_index_format: None,
    front_face: wgpu::FrontFace::Ccw,
    cull_mode: None,
    unclipped_depth: false,
    polygon_mode: wgpu::PolygonMode::Fill,
    conservative: false,
};

fn shadow_depth_state() -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(true),
        depth_compare: Some(wgpu::CompareFunction::LessEqual),
        stencil: Default::default(),
        // Slope-scaled bias against acne on surfaces at a grazing angle to the light.
        bias: wgpu::DepthBiasState {
            constant: 2,
            slope_scale: 2.0,
            clamp: 0.0,
        },
    }
}

/// Draws one model as a phantogram.
pub struct Renderer {
    gpu: Gpu,
    scene: ScenePipelines,
    /// Composition pipelines by target format (offscreen sRGB RGBA; a surface's may differ).
    compose_pipelines: std::collections::HashMap<wgpu::TextureFormat, wgpu::RenderPipeline>,
    compose_module: wgpu::ShaderModule,
    compose_pipeline_layout: wgpu::PipelineLayout,
    eye_buffers: [wgpu::Buffer; 2],
    eye_bind: [wgpu::BindGroup; 2],
    eye_layout: wgpu::BindGroupLayout,
    shadow_sampler: wgpu::Sampler,
    /// Specular image-based light: the prefiltered environment and the split-sum table.
    ibl: IblTextures,
    compose_buffer: wgpu::Buffer,
    compose_layout: wgpu::BindGroupLayout,
    material_layout: wgpu::BindGroupLayout,
    model: GpuModel,
    shadow_pipeline: wgpu::RenderPipeline,
    shadow_bind: wgpu::BindGroup,
    shadow_view: wgpu::TextureView,
    /// The shadow pass's group 0 (the light's matrix), for the lamp cube's faces.
    shadow_layout: wgpu::BindGroupLayout,
    /// The shadows of a lamp among its casters ([`point_shadow`]).
    point_shadow: point_shadow::PointShadowMap,
    /// Triangles the last frame's shadow passes drew (all faces of a lamp's cube together).
    shadow_triangles: u64,
    /// Why the lamp's cube could not be made, if it could not ([`Renderer::lamp_cube_error`]).
    lamp_cube_error: Option<RenderError>,
    /// The texture map of the appearance's Ward material ([`WardMap`]; 1×1 neutral for none),
    /// and its sampler (repeating, mipmapped).
    ward_map: (WardMap, wgpu::TextureView),
    ward_sampler: wgpu::Sampler,
    /// The environment's irradiance, as the shader takes it.
    environment_sh: [[f32; 4]; 9],
    targets: Option<Targets>,
    /// The targets of [`Renderer::render_other_model`] (thumbnails), kept apart so that the
    /// frames' full-size targets are not dropped and made again for each.
    side_targets: Option<Targets>,
    pub lighting: Lighting,
    /// Changes over the model's materials (the material screen's), applied in the next frame;
    /// sanitised on the way to the GPU.
    pub appearance: Appearance,
    /// A lamp in place of the directional light (its shadows too), or `None`.
    pub lamp: Option<Lamp>,
    /// The frames' GPU time, where the device has timestamp queries.
    timer: Option<gpu_timer::GpuTimer>,
    /// Made with the first impostor baked.
    impostor_pipelines: Option<impostor::ImpostorPipelines>,
    /// The cross-fades' instance data for the frame being drawn (entry 0: no fade; fade k:
    /// entries 2k + 1, the new level's, and 2k + 2, the old one's), and its size in entries.
    fade_buffer: wgpu::Buffer,
    fade_entries: u64,
    /// The GPU prefilter: `None` until first asked for, then whether the device has one.
    gpu_prefilter: Option<Option<prefilter_gpu::GpuPrefilter>>,
}

impl Renderer {
    /// A renderer for `model`, lit by the generated neutral studio.
    pub fn new(gpu: Gpu, model: &Model) -> Result<Self, RenderError> {
        Self::with_environment(gpu, model, None)
    }

    /// A renderer for `model`, lit by `environment` (the generated studio when `None`). The same
    /// as [`Self::new`] then [`Self::set_environment`], without prefiltering the studio first.
    pub fn with_environment(
        gpu: Gpu,
        model: &Model,
        environment: Option<&phantogram_assets::ibl::Environment>,
    ) -> Result<Self, RenderError> {
        if model.triangle_count() == 0 {
            return Err(RenderError::EmptyModel);
        }
        let prefiltered;
        let (levels, sh): (&[phantogram_assets::ibl::Environment], _) = match environment {
            Some(env) => {
                prefiltered = phantogram_assets::ibl::prefiltered_levels(env, PREFILTERED_BASE_WIDTH);
                (
                    &prefiltered,
                    phantogram_assets::ibl::IrradianceSh::from_environment(env),
                )
            }
            None => (
                default_prefiltered_environment(),
                phantogram_assets::ibl::IrradianceSh::from_environment(&phantogram_assets::ibl::Environment::studio()),
            ),
        };
        let device = gpu.device.clone();
        checked(&device, "the renderer's pipelines or the model", || {
            Self::build(gpu, model, levels, sh.shader_coefficients())
        })
    }

    fn build(
        gpu: Gpu,
        model: &Model,
        environment: &[phantogram_assets::ibl::Environment],
        environment_sh: [[f32; 4]; 9],
    ) -> Self {
        let device = &gpu.device;
        let scene_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("scene.wgsl"),
            source: wgpu::ShaderSource::Wgsl(SCENE_WGSL.into()),
        });
        let compose_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("compose.wgsl"),
            source: wgpu::ShaderSource::Wgsl(COMPOSE_WGSL.into()),
        });

        let eye_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("eye"),
            entries: &[
                uniform_entry(0, wgpu::ShaderStages::VERTEX_FRAGMENT),
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
                    count: None,
                },
                filterable_texture_entry(3),
                filterable_texture_entry(4),
                wgpu::BindGroupLayoutEntry {
                    binding: 5,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 6,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::Cube,
                        multisampled: false,
                    },
                    count: None,
                },
                filterable_texture_entry(7),
                wgpu::BindGroupLayoutEntry {
                    binding: 8,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let shadow_texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow map"),
            size: wgpu::Extent3d {
                width: SHADOW_SIZE,
                height: SHADOW_SIZE,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let shadow_view = shadow_texture.create_view(&Default::default());
        let shadow_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadow"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        let eye_buffers = ["eye left", "eye right"].map(|label| eye_block_buffer(device, label));
        let ibl = IblTextures::new(&gpu, environment);
        // The shadow pass reads only the light's matrix (the same in both eye blocks) and must
        // not bind the shadow map it writes.
        let shadow_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow"),
            entries: &[uniform_entry(0, wgpu::ShaderStages::VERTEX)],
        });
        // 1×1 a face until a lamp stands among its casters (see `point_shadow`).
        let point_shadow = point_shadow::PointShadowMap::new(device, &shadow_layout, 1);
        let ward_map = (WardMap::Uniform, upload_ward_map(&gpu, WardMap::Uniform));
        let ward_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("Ward map"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let eye_bind = eye_bind_groups(
            device,
            &eye_layout,
            &eye_buffers,
            &EyeViews {
                shadow: &shadow_view,
                shadow_sampler: &shadow_sampler,
                shadow_cube: &point_shadow.cube_view,
                ward_map: &ward_map.1,
                ward_sampler: &ward_sampler,
            },
            &ibl,
        );
        let shadow_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow"),
            layout: &shadow_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: eye_buffers[0].as_entire_binding(),
            }],
        });
        let mut material_entries = vec![uniform_entry(0, wgpu::ShaderStages::FRAGMENT)];
        for slot in 0..5u32 {
            material_entries.push(wgpu::BindGroupLayoutEntry {
                binding: 1 + 2 * slot,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: true },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            });
            material_entries.push(wgpu::BindGroupLayoutEntry {
                binding: 2 + 2 * slot,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                count: None,
            });
        }
        let material_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("material"),
            entries: &material_entries,
        });
        let scene_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("scene"),
            bind_group_layouts: &[Some(&eye_layout), Some(&material_layout)],
            immediate_size: 0,
        });
        let shadow_masked_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow (alpha-masked)"),
            bind_group_layouts: &[Some(&shadow_layout), Some(&material_layout)],
            immediate_size: 0,
        });
        let mut scene = ScenePipelines {
            module: scene_module.clone(),
            layout: scene_layout,
            variants: Default::default(),
            shadow_masked_layout,
            shadow_masked: None,
        };
        let shadow_pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow"),
            bind_group_layouts: &[Some(&shadow_layout)],
            immediate_size: 0,
        });
        let position_only = wgpu::vertex_attr_array![0 => Float32x3];
        let shadow_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("shadow"),
            layout: Some(&shadow_pipeline_layout),
            vertex: wgpu::VertexState {
                module: &scene_module,
                entry_point: Some("vs_shadow"),
                compilation_options: Default::default(),
                buffers: &[Some(vertex_buffer(&position_only))],
            },
            primitive: SHADOW_PRIMITIVE,
            depth_stencil: Some(shadow_depth_state()),
            multisample: Default::default(),
            fragment: None,
            multiview_mask: None,
            cache: None,
        });

        let compose_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("compose"),
            entries: &[
                texture_entry(0),
                texture_entry(1),
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let compose_pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("compose"),
            bind_group_layouts: &[Some(&compose_layout)],
            immediate_size: 0,
        });
        let compose_pipeline =
            create_compose_pipeline(device, &compose_module, &compose_pipeline_layout, OUTPUT_FORMAT);
        let compose_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("compose"),
            size: std::mem::size_of::<ComposeUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let gpu_model = upload_model(&gpu, &material_layout, model);
        scene.prepare(device, &gpu_model);
        Self {
            scene,
            compose_pipelines: [(OUTPUT_FORMAT, compose_pipeline)].into_iter().collect(),
            compose_module,
            compose_pipeline_layout,
            eye_buffers,
            eye_bind,
            eye_layout,
            shadow_sampler,
            ibl,
            compose_buffer,
            compose_layout,
            material_layout,
            model: gpu_model,
            shadow_pipeline,
            shadow_bind,
            shadow_view,
            shadow_layout,
            point_shadow,
            shadow_triangles: 0,
            lamp_cube_error: None,
            ward_map,
            ward_sampler,
            environment_sh,
            targets: None,
            side_targets: None,
            lighting: Lighting::default(),
            appearance: Appearance::default(),
            lamp: None,
            timer: gpu_timer::GpuTimer::new(&gpu.device, &gpu.queue),
            impostor_pipelines: None,
            fade_buffer: fade_instance_buffer(&gpu.device, FADE_ENTRIES_AT_FIRST),
            fade_entries: FADE_ENTRIES_AT_FIRST,
            gpu_prefilter: None,
            gpu,
        }
    }

    /// Whether frames are timed on the GPU (the device has timestamp queries).
    pub fn times_gpu(&self) -> bool {
        self.timer.is_some()
    }

    /// The GPU time of a recent frame, seconds, once per reading (`None` until a new one has
    /// arrived, and always where the device has no timestamp queries): from the first pass's
    /// start to the composition's end, without the overlay. Frames are timed while no earlier
    /// reading is in flight.
    pub fn take_gpu_time_s(&mut self) -> Option<f64> {
        let device = &self.gpu.device;
        self.timer.as_mut()?.take_s(device)
    }

    pub fn gpu(&self) -> &Gpu {
        &self.gpu
    }

    /// Lights the scene with `env` (world frame) instead of the generated studio.
    ///
    /// Prefilters the environment for specular light on the GPU where the device can
    /// ([`Self::prefilters_on_gpu`]), else on the CPU (a few tens of milliseconds in release
    /// builds for the default 256-wide base level); a live room light reduces the environment on
    /// its own thread and hands the result to [`Self::set_environment_base`] or
    /// [`Self::set_prefiltered_environment`].
    pub fn set_environment(&mut self, env: &phantogram_assets::ibl::Environment) -> Result<(), RenderError> {
        let sh = phantogram_assets::ibl::IrradianceSh::from_environment(env);
        let base = phantogram_assets::ibl::prefilter_base(env, PREFILTERED_BASE_WIDTH);
        self.set_environment_base(&base, &sh)
    }

    /// Whether this renderer convolves the specular levels on the GPU ([`prefilter_gpu`]); made
    /// on the first call (a compute pipeline).
    pub fn prefilters_on_gpu(&mut self) -> bool {
        let gpu = &self.gpu;
        self.gpu_prefilter
            .get_or_insert_with(|| prefilter_gpu::GpuPrefilter::new(gpu))
            .is_some()
    }

    /// Lights the scene with an environment given by its level 0 (from
    /// [`phantogram_assets::ibl::prefilter_base`] at [`PREFILTERED_BASE_WIDTH`]) and irradiance:
    /// the rough levels are convolved on the GPU where it can, else here on the CPU.
    pub fn set_environment_base(
        &mut self,
        base: &phantogram_assets::ibl::Environment,
        sh: &phantogram_assets::ibl::IrradianceSh,
    ) -> Result<(), RenderError> {
        if self.prefilters_on_gpu()
            && let Some(Some(prefilter)) = &self.gpu_prefilter
        {
            let texture = prefilter.run(&self.gpu, base)?;
            return self.use_ibl(sh, |gpu| IblTextures::with_texture(gpu, &texture));
        }
        let levels = phantogram_assets::ibl::prefiltered_levels(base, PREFILTERED_BASE_WIDTH);
        self.set_prefiltered_environment(&levels, sh)
    }

    /// Lights the scene with `environment`, or the generated studio when `None` (whose reduction
    /// is made once per process and shared).
    pub fn set_environment_or_studio(
        &mut self,
        environment: Option<&phantogram_assets::ibl::Environment>,
    ) -> Result<(), RenderError> {
        match environment {
            Some(env) => self.set_environment(env),
            None => self.set_prefiltered_environment(
                default_prefiltered_environment(),
                &phantogram_assets::ibl::IrradianceSh::from_environment(&phantogram_assets::ibl::Environment::studio()),
            ),
        }
    }

    /// Lights the scene with an environment already reduced: its specular levels (as
    /// [`phantogram_assets::ibl::prefiltered_levels`] makes them, at [`PREFILTERED_BASE_WIDTH`])
    /// and its irradiance. Only uploads: for the render thread.
    pub fn set_prefiltered_environment(
        &mut self,
        levels: &[phantogram_assets::ibl::Environment],
        sh: &phantogram_assets::ibl::IrradianceSh,
    ) -> Result<(), RenderError> {
        if levels.is_empty()
            || levels
                .iter()
                .any(|l| l.width == 0 || l.height == 0 || l.texels.len() != l.width * l.height)
        {
            return Err(RenderError::Gpu {
                what: "the environment map",
                message: "no levels, or a level whose texels do not fill it".into(),
            });
        }
        self.use_ibl(sh, |gpu| IblTextures::new(gpu, levels))
    }

    /// Lights the scene with the image light `make` builds and the irradiance `sh`, the eyes'
    /// bind groups made again for it.
    fn use_ibl(
        &mut self,
        sh: &phantogram_assets::ibl::IrradianceSh,
        make: impl FnOnce(&Gpu) -> IblTextures,
    ) -> Result<(), RenderError> {
        self.environment_sh = sh.shader_coefficients();
        let device = self.gpu.device.clone();
        checked(&device, "the environment map", || {
            self.ibl = make(&self.gpu);
            self.remake_eye_binds();
        })
    }

    /// The eyes' bind groups made again, after the image light, the lamp's cube or the Ward
    /// map changed.
    fn remake_eye_binds(&mut self) {
        self.eye_bind = eye_bind_groups(
            &self.gpu.device,
            &self.eye_layout,
            &self.eye_buffers,
            &self.eye_views(),
            &self.ibl,
        );
    }

    /// What the eyes' bind groups hold besides their uniforms and the image light.
    fn eye_views(&self) -> EyeViews<'_> {
        EyeViews {
            shadow: &self.shadow_view,
            shadow_sampler: &self.shadow_sampler,
            shadow_cube: &self.point_shadow.cube_view,
            ward_map: &self.ward_map.1,
            ward_sampler: &self.ward_sampler,
        }
    }

    /// Uploads the texture map the appearance's Ward material asks for, if it is not the one
    /// bound (a preset chosen on the material screen: once, not per frame).
    fn use_ward_map(&mut self) -> Result<(), RenderError> {
        let wanted = self.appearance.sanitised().ward.map_or(WardMap::Uniform, |w| w.map);
        if wanted == self.ward_map.0 {
            return Ok(());
        }
        let device = self.gpu.device.clone();
        checked(&device, "the Ward material's texture map", || {
            self.ward_map = (wanted, upload_ward_map(&self.gpu, wanted));
            self.remake_eye_binds();
        })
    }

    /// Replaces the model drawn (keeps pipelines and targets).
    pub fn set_model(&mut self, model: &Model) -> Result<(), RenderError> {
        self.model = self.upload_with_pipelines(model)?;
        Ok(())
    }

    /// Moves the model drawn to `model`'s vertex positions without uploading it anew, when
    /// `model` has the same primitives with the same vertex counts as the one set (bodies that
    /// moved: the Diorama rewrites a few hundred kilobytes a frame instead of rebuilding buffers,
    /// materials and bind groups); otherwise it is set as [`Self::set_model`] does. Indices,
    /// materials and textures are taken to be unchanged.
    pub fn update_vertices(&mut self, model: &Model) -> Result<(), RenderError> {
        let drawn: Vec<&phantogram_assets::model::Primitive> =
            model.primitives.iter().filter(|p| !p.mesh.indices.is_empty()).collect();
        let same_shape = drawn.len() == self.model.primitives.len()
            && drawn
                .iter()
                .zip(&self.model.primitives)
                .all(|(p, g)| p.mesh.vertices.len() == g.vertex_count);
        if !same_shape {
            return self.set_model(model);
        }
        for (p, g) in drawn.iter().zip(&mut self.model.primitives) {
            self.gpu
                .queue
                .write_buffer(&g.vertices, 0, bytemuck::cast_slice(&p.mesh.vertices));
            // Moved bodies: their bounds (the lamp cube's culling) and centres (blending order).
            g.bounds = p.mesh.bounds();
            g.centre = g.bounds.map_or(Vec3::ZERO, |b| (b.min + b.max) * 0.5);
        }
        // Baked from the vertices as they were.
        self.model.impostors.clear();
        let fallback = phantogram_geometry::containment::Aabb::new(Vec3::splat(-0.05), Vec3::splat(0.05));
        self.model.bounds = model.bounds().unwrap_or(fallback);
        self.model.standing = model.bounds_of(|p| !p.is_floor).unwrap_or(self.model.bounds);
        Ok(())
    }

    /// Uploads `model` and builds the scene pipelines its materials need. On failure no
    /// pipeline that failed to build is kept, and the model set stays drawable.
    fn upload_with_pipelines(&mut self, model: &Model) -> Result<GpuModel, RenderError> {
        if model.triangle_count() == 0 {
            return Err(RenderError::EmptyModel);
        }
        let gpu_model = checked(&self.gpu.device, "the model", || {
            upload_model(&self.gpu, &self.material_layout, model)
        })?;
        let device = self.gpu.device.clone();
        let before: std::collections::HashSet<MaterialVariant> = self.scene.variants.keys().copied().collect();
        let had_shadow_masked = self.scene.shadow_masked.is_some();
        if let Err(e) = checked(&device, "the model's pipelines", || {
            self.scene.prepare(&device, &gpu_model)
        }) {
            self.scene.variants.retain(|v, _| before.contains(v));
            if !had_shadow_masked {
                self.scene.shadow_masked = None;
            }
            return Err(e);
        }
        Ok(gpu_model)
    }

    /// Renders `model` — not the one set — once from `input`'s mono eye at `width × height` (a
    /// gallery thumbnail), as authored and without the lamp: uploads it, draws it in targets of
    /// its own and drops it again. The model set, its appearance, the lamp and the frames'
    /// targets stay as they are; the scene pipelines it needed are
    /// kept for later models.
    pub fn render_other_model(
        &mut self,
        model: &Model,
        input: &FrameInput,
        width: u32,
        height: u32,
    ) -> Result<Vec<u8>, RenderError> {
        let gpu_model = self.upload_with_pipelines(model)?;
        let set_model = std::mem::replace(&mut self.model, gpu_model);
        // The other model as authored and in the room's light: the appearance and the lamp set
        // are the shown artifact's.
        let appearance = std::mem::take(&mut self.appearance);
        let lamp = self.lamp.take();
        let side = self.side_targets.take();
        let frame_targets = std::mem::replace(&mut self.targets, side);
        let pixels = self.render_views(&[input.mono], input, Method::Mono, width, height);
        self.side_targets = std::mem::replace(&mut self.targets, frame_targets);
        self.model = set_model;
        self.appearance = appearance;
        self.lamp = lamp;
        pixels
    }

    fn targets(&mut self, width: u32, height: u32) -> Result<&Targets, RenderError> {
        let max = self.gpu.device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(RenderError::BadSize { width, height, max });
        }
        if self
            .targets
            .as_ref()
            .is_none_or(|t| (t.width, t.height) != (width, height))
        {
            self.targets = Some(self.create_targets(width, height));
        }
        Ok(self.targets.as_ref().expect("just created"))
    }

    fn create_targets(&self, width: u32, height: u32) -> Targets {
        let device = &self.gpu.device;
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let texture = |label, format, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let hdr_usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let hdr = [
            texture("hdr left", HDR_FORMAT, hdr_usage).create_view(&Default::default()),
            texture("hdr right", HDR_FORMAT, hdr_usage).create_view(&Default::default()),
        ];
        let depth =
            texture("depth", DEPTH_FORMAT, wgpu::TextureUsages::RENDER_ATTACHMENT).create_view(&Default::default());
        // Bind group 0 composes left with right; bind group 1 reads the left image twice (mono).
        let compose_bind = [(0usize, 1usize), (0, 0)].map(|(a, b)| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("compose"),
                layout: &self.compose_layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(&hdr[a]),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(&hdr[b]),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: self.compose_buffer.as_entire_binding(),
                    },
                ],
            })
        });
        Targets {
            width,
            height,
            hdr,
            depth,
            offscreen: None,
            compose_bind,
        }
    }

    fn eye_uniform(&self, proj: &OffAxisProjection, input: &FrameInput, shadow: (Mat4, f32)) -> EyeUniform {
        // The mesh moves by `offset` (push-back): fold it into the projection.
        let view_proj = proj.view_proj * Mat4::from_translation(input.offset);
        let l = self.lighting;
        // The angle a pixel subtends (at the screen's centre): the near plane's width over its
        // distance, 2 / proj[0][0], shared among the target's pixels. For the Ward map's level.
        let width_px = self.targets.as_ref().map_or(1, |t| t.width).max(1) as f32;
        let radians_per_px = 2.0 / (proj.proj.x_axis.x.abs().max(1e-6) * width_px);
        EyeUniform {
            view_proj: view_proj.to_cols_array_2d(),
            // Shading happens in mesh coordinates, so the eye moves the other way.
            eye_pos: (proj.eye_m - input.offset).extend(1.0).to_array(),
            toward_light: input.toward_light.normalize_or(Vec3::Z).extend(0.0).to_array(),
            light: l.light_rgb.extend(l.environment_intensity).to_array(),
            world_from_device: {
                let m = glam::Mat3::from_quat(input.device_to_world.normalize());
                [
                    m.row(0).extend(0.0).to_array(),
                    m.row(1).extend(0.0).to_array(),
                    m.row(2).extend(0.0).to_array(),
                ]
            },
            light_view_proj: shadow.0.to_cols_array_2d(),
            shadow: [shadow.1, f32::from(u8::from(l.shadows)), radians_per_px, 0.0],
            sh: self.environment_sh,
            appearance: appearance_uniform(&self.appearance),
            lamp: Lamp::uniform(self.lamp.as_ref()),
            lamp_shadow: [0.0; 4],
        }
    }

    /// Renders one frame of `width × height` pixels and reads it back as 8-bit sRGB RGBA, rows top
    /// to bottom.
    pub fn render(
        &mut self,
        input: &FrameInput,
        method: Method,
        width: u32,
        height: u32,
    ) -> Result<Vec<u8>, RenderError> {
        self.render_views(&input.eyes_drawn(method), input, method, width, height)
    }

    /// Renders `projection` alone (no stereo composition), e.g. one eye's image for tests.
    pub fn render_single(
        &mut self,
        projection: &OffAxisProjection,
        input: &FrameInput,
        width: u32,
        height: u32,
    ) -> Result<Vec<u8>, RenderError> {
        self.render_views(&[projection], input, Method::Mono, width, height)
    }

    /// The stereo pair side by side for parallel viewing (and stereo tools): the left eye's
    /// image on the left, the right eye's on the right, each `width × height`; returns
    /// `2·width × height` sRGB RGBA pixels, rows top to bottom.
    pub fn render_side_by_side(&mut self, input: &FrameInput, width: u32, height: u32) -> Result<Vec<u8>, RenderError> {
        let left = self.render_single(input.left, input, width, height)?;
        let right = self.render_single(input.right, input, width, height)?;
        let row = width as usize * 4;
        let mut pair = Vec::with_capacity(left.len() * 2);
        for (l, r) in left.chunks_exact(row).zip(right.chunks_exact(row)) {
            pair.extend_from_slice(l);
            pair.extend_from_slice(r);
        }
        Ok(pair)
    }

    /// As [`Self::render`], with `overlay` painting over the composed frame before it is read back
    /// (the calibration screens): it gets the device, the frame's view, format and size, and
    /// submits its own work.
    pub fn render_with_overlay(
        &mut self,
        input: &FrameInput,
        method: Method,
        width: u32,
        height: u32,
        overlay: impl FnOnce(&Gpu, &wgpu::TextureView, wgpu::TextureFormat, [u32; 2]),
    ) -> Result<Vec<u8>, RenderError> {
        self.render_views_with(&input.eyes_drawn(method), input, method, width, height, Some(overlay))
    }

    fn render_views(
        &mut self,
        eyes: &[&OffAxisProjection],
        input: &FrameInput,
        method: Method,
        width: u32,
        height: u32,
    ) -> Result<Vec<u8>, RenderError> {
        type NoOverlay = fn(&Gpu, &wgpu::TextureView, wgpu::TextureFormat, [u32; 2]);
        self.render_views_with(eyes, input, method, width, height, None::<NoOverlay>)
    }

    fn render_views_with(
        &mut self,
        eyes: &[&OffAxisProjection],
        input: &FrameInput,
        method: Method,
        width: u32,
        height: u32,
        overlay: Option<impl FnOnce(&Gpu, &wgpu::TextureView, wgpu::TextureFormat, [u32; 2])>,
    ) -> Result<Vec<u8>, RenderError> {
        let bytes = Offscreen::padded_row(width) * u64::from(height);
        let max_bytes = self.gpu.device.limits().max_buffer_size;
        if bytes > max_bytes {
            return Err(RenderError::FrameTooLarge {
                width,
                height,
                bytes,
                max_bytes,
            });
        }
        self.targets(width, height)?;
        let device = self.gpu.device.clone();
        let targets = self.targets.as_mut().expect("created above");
        let output_view = targets
            .offscreen
            .get_or_insert_with(|| Offscreen::new(&device, width, height))
            .output_view
            .clone();
        let mut encoder = self.encode_frame(eyes, input, method, &output_view, OUTPUT_FORMAT)?;
        if let Some(overlay) = overlay {
            // The frame first, then the overlay's own submission over it, then the copy.
            let queue = &self.gpu.queue;
            self.submit_timed(|| queue.submit([encoder.finish()]))?;
            overlay(&self.gpu, &output_view, OUTPUT_FORMAT, [width, height]);
            encoder = self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("read-back"),
            });
        }
        let targets = self.targets.as_ref().expect("created above");
        let offscreen = targets.offscreen.as_ref().expect("created above");
        encoder.copy_texture_to_buffer(
            offscreen.output.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &offscreen.readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(offscreen.padded_row),
                    rows_per_image: Some(height),
                },
            },
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
        );
        let queue = &self.gpu.queue;
        self.submit_timed(|| queue.submit([encoder.finish()]))?;
        read_back(&self.gpu.device, offscreen, width, height)
    }

    /// Renders one frame into `target` (e.g. a surface's current texture) of `format` and
    /// `width × height` pixels, and submits it; the caller presents.
    pub fn render_to_view(
        &mut self,
        input: &FrameInput,
        method: Method,
        target: &wgpu::TextureView,
        format: wgpu::TextureFormat,
        width: u32,
        height: u32,
    ) -> Result<(), RenderError> {
        self.targets(width, height)?;
        let encoder = self.encode_frame(&input.eyes_drawn(method), input, method, target, format)?;
        let queue = &self.gpu.queue;
        self.submit_timed(|| queue.submit([encoder.finish()]))
    }

    /// Submits a frame's commands (inside a validation scope) and asks for its GPU time, if the
    /// frame was timed; a failed submission frees the timer for the next frame.
    fn submit_timed(&self, submit: impl FnOnce() -> wgpu::SubmissionIndex) -> Result<(), RenderError> {
        let result = checked(&self.gpu.device, "the frame", submit).map(drop);
        if let Some(timer) = &self.timer {
            match result {
                Ok(()) => timer.submitted(),
                Err(_) => timer.abandon(),
            }
        }
        result
    }

    /// Writes the uniforms and records the shadow, scene and composition passes into `target`.
    fn encode_frame(
        &mut self,
        eyes: &[&OffAxisProjection],
        input: &FrameInput,
        method: Method,
        target: &wgpu::TextureView,
        format: wgpu::TextureFormat,
    ) -> Result<wgpu::CommandEncoder, RenderError> {
        if !self.compose_pipelines.contains_key(&format) {
            let device = self.gpu.device.clone();
            let pipeline = checked(&device, "the composition pipeline for this surface format", || {
                create_compose_pipeline(&device, &self.compose_module, &self.compose_pipeline_layout, format)
            })?;
            self.compose_pipelines.insert(format, pipeline);
        }
        self.use_ward_map()?;
        let lamp = self.lamp.filter(Lamp::is_finite);
        let toward = match &lamp {
            Some(l) => l.toward_from((self.model.bounds.min + self.model.bounds.max) * 0.5),
            None => input.toward_light,
        };
        let (floor_casts, shadow_bounds) = self.model.shadow_casters(toward);
        // A lamp among what it shadows (no single view holds it all) is seen from a cube.
        let (shadow, cube) = match &lamp {
            Some(l) => match lamp_view_proj(&shadow_bounds, l) {
                Some(s) => (s, None),
                None => (
                    (Mat4::IDENTITY, 1.0),
                    Some((l.position_m, point_shadow::cube_range_m(&shadow_bounds, l.position_m))),
                ),
            },
            None => (light_view_proj(&shadow_bounds, input.toward_light), None),
        };
        let mut cube_pass = self.lighting.shadows && cube.is_some() && self.lamp_cube_error.is_none();
        if cube_pass && self.point_shadow.size < point_shadow::POINT_SHADOW_SIZE {
            let device = self.gpu.device.clone();
            let made = checked(&device, "the lamp's shadow cube", || {
                point_shadow::PointShadowMap::new(&device, &self.shadow_layout, point_shadow::POINT_SHADOW_SIZE)
            });
            match made {
                Ok(map) => {
                    self.point_shadow = map;
                    self.remake_eye_binds();
                }
                // A device that cannot make it: such a lamp casts no shadow (as before the
                // cube), the frames go on, and the error is kept for the host to read.
                Err(e) => {
                    self.lamp_cube_error = Some(e);
                    cube_pass = false;
                }
            }
        }
        let mut uniforms: Vec<EyeUniform> = eyes.iter().map(|p| self.eye_uniform(p, input, shadow)).collect();
        let mut faces = None;
        if let Some((lamp_m, (near_m, far_m))) = cube {
            for u in &mut uniforms {
                u.shadow[1] = 0.0;
                u.lamp_shadow = [
                    near_m,
                    far_m,
                    self.point_shadow.size as f32,
                    f32::from(u8::from(cube_pass)),
                ];
            }
            if cube_pass {
                let views = point_shadow::cube_face_view_proj(lamp_m, near_m, far_m);
                self.point_shadow.write_faces(&self.gpu.queue, &views);
                faces = Some(views);
            }
        }
        let (lm, rm) = method.matrices();
        let row = |m: [f32; 3]| [m[0], m[1], m[2], 0.0];
        let compose = ComposeUniform {
            left: lm.map(row),
            right: rm.map(row),
            params: [self.lighting.exposure, 0.0, 0.0, 0.0],
        };
        let fading = self.write_fades(input.fades);
        let queue = &self.gpu.queue;
        for (buffer, u) in self.eye_buffers.iter().zip(&uniforms) {
            queue.write_buffer(buffer, 0, bytemuck::bytes_of(u));
        }
        queue.write_buffer(&self.compose_buffer, 0, bytemuck::bytes_of(&compose));

        // Timed (where the device can) from the first pass's start to the composition's end.
        let timed = self.timer.as_mut().is_some_and(|t| t.start_frame());
        let timer = self.timer.as_ref().filter(|_| timed);
        let shadow_pass = self.lighting.shadows;
        let mut shadow_triangles = 0;
        let targets = self.targets.as_ref().expect("the caller sized the targets");
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        if shadow_pass {
            // Once per frame, for both eyes: one view, or the lamp cube's six, each drawing only
            // what lies in its frustum.
            let views: Vec<(&wgpu::TextureView, &wgpu::BindGroup, Option<Mat4>)> = match &faces {
                Some(faces) => self
                    .point_shadow
                    .face_views
                    .iter()
                    .zip(&self.point_shadow.face_binds)
                    .zip(faces)
                    .map(|((v, b), m)| (v, b, Some(*m)))
                    .collect(),
                None => vec![(&self.shadow_view, &self.shadow_bind, None)],
            };
            // Impostors cast the shadow of the polygon level as exact as they are.
            let shadow_levels = self.shadow_levels(input.levels);
            for (k, (view, bind, cull)) in views.into_iter().enumerate() {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("shadow"),
                    timestamp_writes: timer.filter(|_| k == 0).map(|t| t.writes(true, false)),
                    color_attachments: &[],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view,
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Clear(1.0),
                            store: wgpu::StoreOp::Store,
                        }),
                        stencil_ops: None,
                    }),
                    ..Default::default()
                });
                shadow_triangles +=
                    self.draw_shadow_casters(&mut pass, bind, &shadow_levels, floor_casts, cull.as_ref());
            }
        }
        self.shadow_triangles = shadow_triangles;
        for (i, u) in uniforms.iter().enumerate() {
            let first = i == 0 && !shadow_pass;
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("scene"),
                timestamp_writes: timer.filter(|_| first).map(|t| t.writes(true, false)),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &targets.hdr[i],
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(CLEAR_RADIANCE),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &targets.depth,
                    // Reverse-Z: 0 is infinitely far.
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                ..Default::default()
            });
            pass.set_bind_group(0, &self.eye_bind[i], &[]);
            // Opaque and masked first; then blended, farthest first, as this eye sees them.
            let eye_at = Vec3::from_slice(&u.eye_pos[..3]);
            let mut blended: Vec<&GpuPrimitive> = Vec::new();
            let mut impostors_drawn: Vec<(usize, u32)> = Vec::new();
            for p in &self.model.primitives {
                if self.model.materials[p.material].variant.blend {
                    blended.push(p);
                } else if let Some(k) = fading.get(&p.source) {
                    // Both levels, each on its share of the pixels.
                    let new = input.levels.get(p.source).copied().unwrap_or(0);
                    let old = input.fades[*k].from;
                    let first = 2 * *k as u32 + 1;
                    for (level, instance) in [(new, first), (old, first + 1)] {
                        match self.impostor_of(p.source, level) {
                            Some(imp) if !impostors_drawn.contains(&(p.source, instance)) => {
                                impostors_drawn.push((p.source, instance));
                                self.draw_impostor(&mut pass, imp, instance);
                            }
                            Some(_) => {}
                            None => self.draw_fading(&mut pass, p, level, instance),
                        }
                    }
                } else if let Some(imp) = self.impostor_drawn_for(p, input.levels) {
                    // Once for the primitive, however many pieces it was uploaded in.
                    if !impostors_drawn.contains(&(p.source, 0)) {
                        impostors_drawn.push((p.source, 0));
                        self.draw_impostor(&mut pass, imp, 0);
                    }
                } else {
                    self.draw_primitive(&mut pass, p, input.levels);
                }
            }
            blended.sort_by(|a, b| {
                b.centre
                    .distance_squared(eye_at)
                    .total_cmp(&a.centre.distance_squared(eye_at))
            });
            for p in blended {
                self.draw_primitive(&mut pass, p, input.levels);
            }
        }
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("compose"),
                timestamp_writes: timer.map(|t| t.writes(false, true)),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                ..Default::default()
            });
            pass.set_pipeline(&self.compose_pipelines[&format]);
            let bind = if uniforms.len() == 2 { 0 } else { 1 };
            pass.set_bind_group(0, &targets.compose_bind[bind], &[]);
            pass.draw(0..3, 0..1);
        }
        if let Some(t) = timer {
            t.resolve(&mut encoder);
        }
        Ok(encoder)
    }
}

fn create_compose_pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    format: wgpu::TextureFormat,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("compose"),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("fs_main"),
            compilation_options: Default::default(),
            targets: &[Some(format.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}

impl Renderer {
    /// Draws what casts shadows into a shadow pass whose light matrix `bind` holds: opaque
    /// materials, then masked ones cut out (blended ones cast none); the floor only when
    /// `floor_casts`; with `cull` (that matrix), only pieces whose bounds reach its frustum.
    /// Returns the triangles drawn.
    fn draw_shadow_casters(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        bind: &wgpu::BindGroup,
        levels: &[u8],
        floor_casts: bool,
        cull: Option<&Mat4>,
    ) -> u64 {
        pass.set_pipeline(&self.shadow_pipeline);
        pass.set_bind_group(0, bind, &[]);
        let variant = |p: &GpuPrimitive| self.model.materials[p.material].variant;
        let seen = |p: &GpuPrimitive| match (cull, &p.bounds) {
            (Some(m), Some(b)) => !point_shadow::outside_frustum(m, b),
            _ => true,
        };
        let mut triangles = 0;
        for p in self.model.primitives.iter().filter(|p| {
            let v = variant(p);
            !v.blend && !v.mask && (floor_casts || !p.is_floor) && seen(p)
        }) {
            p.draw(pass, levels);
            triangles += p.triangles_at(levels);
        }
        let mut masked = self
            .model
            .primitives
            .iter()
            .filter(|p| variant(p).casts_masked_shadow() && (floor_casts || !p.is_floor) && seen(p))
            .peekable();
        if masked.peek().is_some() {
            // Made with the model (`ScenePipelines::prepare`); a miss would be our bug, and
            // those surfaces then cast no shadow rather than panic mid-frame.
            match &self.scene.shadow_masked {
                Some(pipeline) => {
                    pass.set_pipeline(pipeline);
                    for p in masked {
                        pass.set_bind_group(1, &self.model.materials[p.material].bind, &[]);
                        p.draw(pass, levels);
                        triangles += p.triangles_at(levels);
                    }
                }
                None => debug_assert!(false, "no shadow pipeline for masked materials"),
            }
        }
        triangles
    }

    /// Triangles the last frame's shadow passes drew: the model's casters once for a light's
    /// map, for a lamp's cube those each face's frustum reaches (a piece across two faces
    /// counts twice); 0 without shadows.
    pub fn shadow_triangles_last_frame(&self) -> u64 {
        self.shadow_triangles
    }

    /// Why the device could not make the cube of shadow views a lamp among its casters needs,
    /// if it could not: such a lamp then casts no shadow and the frames go on.
    pub fn lamp_cube_error(&self) -> Option<&RenderError> {
        self.lamp_cube_error.as_ref()
    }

    /// `levels` with each impostor drawn replaced by the level its shadow is cast with.
    fn shadow_levels<'l>(&self, levels: &'l [u8]) -> std::borrow::Cow<'l, [u8]> {
        if self.model.impostors.is_empty() {
            return std::borrow::Cow::Borrowed(levels);
        }
        levels
            .iter()
            .enumerate()
            .map(|(source, &l)| match self.model.impostors.get(source) {
                Some(Some(imp)) if l == IMPOSTOR_LEVEL => imp.shadow_level,
                _ => l,
            })
            .collect::<Vec<u8>>()
            .into()
    }

    /// The impostor `levels` draws for `p` in place of its triangles, if any.
    fn impostor_drawn_for(&self, p: &GpuPrimitive, levels: &[u8]) -> Option<&impostor::GpuImpostor> {
        self.impostor_of(p.source, levels.get(p.source).copied()?)
    }

    /// Primitive `source`'s impostor, if `level` is [`IMPOSTOR_LEVEL`] and it has one.
    fn impostor_of(&self, source: usize, level: u8) -> Option<&impostor::GpuImpostor> {
        if level != IMPOSTOR_LEVEL {
            return None;
        }
        self.model.impostors.get(source)?.as_ref()
    }

    /// Writes this frame's cross-fades into the instance buffer (growing it when needed) and
    /// returns, by primitive, the index of its fade in `fades`. A fade of a primitive past the
    /// model, or a second one of a primitive, is ignored.
    fn write_fades(&mut self, fades: &[LevelFade]) -> std::collections::HashMap<usize, usize> {
        let mut by_primitive = std::collections::HashMap::new();
        if fades.is_empty() {
            // Entry 0 (no fade) is zero from the buffer's creation and every write.
            return by_primitive;
        }
        let mut data: Vec<[f32; 2]> = vec![[0.0, 0.0]; 2 * fades.len() + 1];
        for (k, f) in fades.iter().enumerate() {
            let source = f.primitive as usize;
            if !self.model.primitives.iter().any(|p| p.source == source) || by_primitive.contains_key(&source) {
                continue;
            }
            let shown = if f.shown.is_finite() {
                f.shown.clamp(0.0, 1.0)
            } else {
                1.0
            };
            data[2 * k + 1] = [shown, 1.0];
            data[2 * k + 2] = [shown, -1.0];
            by_primitive.insert(source, k);
        }
        let needed = data.len() as u64;
        if needed > self.fade_entries {
            self.fade_entries = needed.next_power_of_two();
            self.fade_buffer = fade_instance_buffer(&self.gpu.device, self.fade_entries);
        }
        self.gpu
            .queue
            .write_buffer(&self.fade_buffer, 0, bytemuck::cast_slice(&data));
        by_primitive
    }

    /// Draws `p` at `level` as one side of a cross-fade (instance `instance` of the fades'
    /// buffer).
    fn draw_fading(&self, pass: &mut wgpu::RenderPass<'_>, p: &GpuPrimitive, level: u8, instance: u32) {
        let m = &self.model.materials[p.material];
        let variant = MaterialVariant {
            fade: true,
            ..m.variant
        };
        let Some(pipeline) = self.scene.get(&variant) else {
            // Made with the model for every primitive with levels; without it, the new level
            // alone (a switch without the fade).
            if instance % 2 == 1 {
                self.draw_primitive(pass, p, &[level]);
            }
            return;
        };
        pass.set_pipeline(pipeline);
        pass.set_bind_group(1, &m.bind, &[]);
        pass.set_vertex_buffer(1, self.fade_buffer.slice(..));
        p.draw_at(pass, level, instance);
    }

    fn draw_primitive(&self, pass: &mut wgpu::RenderPass<'_>, p: &GpuPrimitive, levels: &[u8]) {
        let m = &self.model.materials[p.material];
        // Every material's variant was prepared with its model; a miss would be our bug, and
        // skipping the primitive beats a panic in the middle of a frame.
        let Some(pipeline) = self.scene.get(&m.variant) else {
            debug_assert!(false, "no pipeline for {:?}", m.variant);
            return;
        };
        pass.set_pipeline(pipeline);
        pass.set_bind_group(1, &m.bind, &[]);
        p.draw(pass, levels);
    }
}

/// The cross-fades' instance buffer's first size (entries): 31 fades at once; it grows when a
/// frame has more.
const FADE_ENTRIES_AT_FIRST: u64 = 64;

fn fade_instance_buffer(device: &wgpu::Device, entries: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("cross-fades"),
        size: entries * 8,
        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Runs `f` inside a validation error scope, turning what wgpu would otherwise report to its
/// uncaptured-error handler (which panics by default) into a [`RenderError`].
fn checked<T>(device: &wgpu::Device, what: &'static str, f: impl FnOnce() -> T) -> Result<T, RenderError> {
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let out = f();
    match pollster::block_on(scope.pop()) {
        Some(e) => Err(RenderError::Gpu {
            what,
            message: e.to_string(),
        }),
        None => Ok(out),
    }
}

fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A uniform buffer for one `Eye` block: an eye's, or a view's that passes draw from (a lamp
/// cube's face, an impostor's bake), written with `queue.write_buffer`.
fn eye_block_buffer(device: &wgpu::Device, label: &str) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: std::mem::size_of::<EyeUniform>() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// The eyes' bind group's shadow maps and Ward map (see `Eye`'s bindings in `scene.wgsl`).
struct EyeViews<'a> {
    shadow: &'a wgpu::TextureView,
    shadow_sampler: &'a wgpu::Sampler,
    shadow_cube: &'a wgpu::TextureView,
    ward_map: &'a wgpu::TextureView,
    ward_sampler: &'a wgpu::Sampler,
}

/// A Ward map's texels as a mipmapped linear texture (the mips average the scales, so a distant
/// weave shows its mean).
fn upload_ward_map(gpu: &Gpu, map: WardMap) -> wgpu::TextureView {
    let (size, texels) = map.texels();
    upload_texture(gpu, "Ward map", size, size, &texels, false)
}

fn eye_bind_groups(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    buffers: &[wgpu::Buffer; 2],
    views: &EyeViews<'_>,
    ibl: &IblTextures,
) -> [wgpu::BindGroup; 2] {
    [0, 1].map(|i| eye_bind_group(device, layout, &buffers[i], views, ibl))
}

fn eye_bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    buffer: &wgpu::Buffer,
    views: &EyeViews<'_>,
    ibl: &IblTextures,
) -> wgpu::BindGroup {
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("eye"),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(views.shadow),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::Sampler(views.shadow_sampler),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: wgpu::BindingResource::TextureView(&ibl.environment),
            },
            wgpu::BindGroupEntry {
                binding: 4,
                resource: wgpu::BindingResource::TextureView(&ibl.brdf_lut),
            },
            wgpu::BindGroupEntry {
                binding: 5,
                resource: wgpu::BindingResource::Sampler(&ibl.sampler),
            },
            wgpu::BindGroupEntry {
                binding: 6,
                resource: wgpu::BindingResource::TextureView(views.shadow_cube),
            },
            wgpu::BindGroupEntry {
                binding: 7,
                resource: wgpu::BindingResource::TextureView(views.ward_map),
            },
            wgpu::BindGroupEntry {
                binding: 8,
                resource: wgpu::BindingResource::Sampler(views.ward_sampler),
            },
        ],
    })
}

fn filterable_texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    float_texture_entry(binding, true)
}

fn texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    float_texture_entry(binding, false)
}

fn float_texture_entry(binding: u32, filterable: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// Maps `slice` for reading and waits until it is (or the mapping failed).
fn map_for_reading(device: &wgpu::Device, slice: &wgpu::BufferSlice<'_>) -> Result<(), RenderError> {
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| RenderError::Readback(e.to_string()))?;
    rx.recv()
        .map_err(|e| RenderError::Readback(e.to_string()))?
        .map_err(|e| RenderError::Readback(e.to_string()))
}

/// Reads level `mip` of `texture` back, waiting for the GPU: its rows top to bottom, unpadded,
/// in the texture's own texel bytes. Makes a buffer per call: for tests, tools and benchmarks
/// (frames are read through the offscreen target's kept buffer). Needs `COPY_SRC` on the texture and
/// an uncompressed colour format.
pub fn read_texture_level(gpu: &Gpu, texture: &wgpu::Texture, mip: u32) -> Result<Vec<u8>, RenderError> {
    let (w, h) = ((texture.width() >> mip).max(1), (texture.height() >> mip).max(1));
    let texel = texture
        .format()
        .block_copy_size(None)
        .ok_or(RenderError::Readback(format!(
            "{:?} has no single texel size",
            texture.format()
        )))?;
    let row = texel * w;
    let padded = row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let device = &gpu.device;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("texture read-back"),
        size: u64::from(padded) * u64::from(h),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: mip,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(h),
            },
        },
        wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
    );
    checked(device, "the texture read-back", || gpu.queue.submit([encoder.finish()]))?;
    let slice = buffer.slice(..);
    map_for_reading(device, &slice)?;
    let mut bytes = Vec::with_capacity((row * h) as usize);
    {
        let data = slice
            .get_mapped_range()
            .map_err(|e| RenderError::Readback(e.to_string()))?;
        for r in data.chunks(padded as usize).take(h as usize) {
            bytes.extend_from_slice(&r[..row as usize]);
        }
    }
    buffer.unmap();
    Ok(bytes)
}

fn read_back(device: &wgpu::Device, targets: &Offscreen, width: u32, height: u32) -> Result<Vec<u8>, RenderError> {
    let slice = targets.readback.slice(..);
    map_for_reading(device, &slice)?;
    let row_bytes = (width * 4) as usize;
    let mut pixels = Vec::with_capacity(row_bytes * height as usize);
    {
        let data = slice
            .get_mapped_range()
            .map_err(|e| RenderError::Readback(e.to_string()))?;
        for row in data.chunks(targets.padded_row as usize).take(height as usize) {
            pixels.extend_from_slice(&row[..row_bytes]);
        }
    }
    targets.readback.unmap();
    Ok(pixels)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn validate(name: &str, source: &str) {
        let module =
            naga::front::wgsl::parse_str(source).unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}: {e:?}"));
    }

    /// Every `shaders/*.wgsl` file parses and validates (naga), not only the ones compiled in.
    #[test]
    fn every_shader_validates() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shaders");
        let mut n = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "wgsl") {
                validate(&path.display().to_string(), &std::fs::read_to_string(&path).unwrap());
                n += 1;
            }
        }
        assert!(n >= 2, "found {n} shaders in {}", dir.display());
        validate("scene", SCENE_WGSL);
        validate("prefilter", prefilter_gpu::PREFILTER_WGSL);
        validate("compose", COMPOSE_WGSL);
        validate("impostor_dilate", impostor::IMPOSTOR_DILATE_WGSL);
    }

    /// Every shader translates for the phones' other backends, which no test here runs: Metal
    /// (iOS) and OpenGL ES (Android's fallback where Vulkan is missing; 3.0 for drawing, 3.1 for
    /// the compute prefilter, which the renderer uses only where the device has compute). SPIR-V
    /// (Vulkan) is what lavapipe runs in the other tests. Pipeline constants take their defaults.
    #[test]
    fn every_shader_translates_for_metal_and_gles() {
        for (name, source) in [
            ("scene", SCENE_WGSL),
            ("compose", COMPOSE_WGSL),
            ("prefilter", prefilter_gpu::PREFILTER_WGSL),
            ("impostor_dilate", impostor::IMPOSTOR_DILATE_WGSL),
        ] {
            let module = naga::front::wgsl::parse_str(source).unwrap_or_else(|e| panic!("{name}: {e}"));
            let info = naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::default(),
            )
            .validate(&module)
            .unwrap_or_else(|e| panic!("{name}: {e:?}"));
            let (module, info) =
                naga::back::pipeline_constants::process_overrides(&module, &info, None, &Default::default())
                    .unwrap_or_else(|e| panic!("{name}: {e:?}"));
            let msl = naga::back::msl::Options {
                lang_version: (2, 4),
                ..Default::default()
            };
            naga::back::msl::write_string(&module, &info, &msl, &Default::default())
                .unwrap_or_else(|e| panic!("{name}: Metal: {e:?}"));
            for entry in &module.entry_points {
                let version = if entry.stage == naga::ShaderStage::Compute {
                    310
                } else {
                    300
                };
                let options = naga::back::glsl::Options {
                    version: naga::back::glsl::Version::Embedded {
                        version,
                        is_webgl: false,
                    },
                    ..Default::default()
                };
                let pipeline = naga::back::glsl::PipelineOptions {
                    shader_stage: entry.stage,
                    entry_point: entry.name.clone(),
                    multiview: None,
                };
                let mut out = String::new();
                naga::back::glsl::Writer::new(
                    &mut out,
                    &module,
                    &info,
                    &options,
                    &pipeline,
                    naga::proc::BoundsCheckPolicies::default(),
                )
                .and_then(|mut w| w.write())
                .unwrap_or_else(|e| panic!("{name}: {}: GLSL ES {version}: {e:?}", entry.name));
            }
        }
    }

    #[test]
    fn a_broken_shader_fails_validation() {
        let good = "return direct + ambient + s.emissive;";
        assert!(SCENE_WGSL.contains(good), "the sabotage below must apply");
        let bad = SCENE_WGSL.replace(good, "return vec4<f32>(direct, 1.0);");
        let parsed = naga::front::wgsl::parse_str(&bad);
        let failed = match parsed {
            Err(_) => true,
            Ok(m) => naga::valid::Validator::new(naga::valid::ValidationFlags::all(), Default::default())
                .validate(&m)
                .is_err(),
        };
        assert!(failed);
    }

    #[test]
    fn a_lamps_shadow_view_holds_what_it_shadows() {
        let bounds =
            phantogram_geometry::containment::Aabb::new(Vec3::new(-0.02, -0.03, -0.01), Vec3::new(0.02, 0.03, 0.01));
        let lamp = Lamp {
            position_m: Vec3::new(-0.06, 0.0, 0.02),
            axis: Vec3::X,
            cone_half_angle_rad: Some(1.0),
            intensity_rgb: Vec3::ONE,
        };
        let (m, texel) = lamp_view_proj(&bounds, &lamp).expect("outside the bounds");
        assert!(texel > 0.0 && texel < 1e-3, "{texel}");
        for c in bounds.corners() {
            let p = m.project_point3(c);
            assert!(
                p.x.abs() <= 1.0 && p.y.abs() <= 1.0 && (0.0..=1.0).contains(&p.z),
                "{c} → {p}"
            );
        }
        // Inside what it would shadow: no single view, no shadows.
        let inside = Lamp {
            position_m: Vec3::ZERO,
            ..lamp
        };
        assert!(lamp_view_proj(&bounds, &inside).is_none());
        // Off or broken: the uniform says off.
        assert_eq!(Lamp::uniform(None)[0][3], 0.0);
        let broken = Lamp {
            position_m: Vec3::NAN,
            ..lamp
        };
        assert_eq!(Lamp::uniform(Some(&broken))[0][3], 0.0);
        let point = Lamp {
            cone_half_angle_rad: None,
            ..lamp
        };
        assert_eq!(Lamp::uniform(Some(&point))[1][3], -2.0, "a point light has no cone");
    }

    #[test]
    fn uniform_layouts_match_the_shaders() {
        // Each uniform struct is as large as naga lays out its WGSL namesake.
        let wgsl_size = |source: &str, name: &str| {
            let module = naga::front::wgsl::parse_str(source).expect("valid WGSL");
            module
                .types
                .iter()
                .find(|(_, ty)| ty.name.as_deref() == Some(name))
                .map(|(_, ty)| ty.inner.size(module.to_ctx()) as usize)
                .unwrap_or_else(|| panic!("no struct {name}"))
        };
        assert_eq!(std::mem::size_of::<EyeUniform>(), wgsl_size(SCENE_WGSL, "Eye"));
        assert_eq!(
            std::mem::size_of::<ComposeUniform>(),
            wgsl_size(COMPOSE_WGSL, "Compose")
        );
        assert_eq!(
            std::mem::size_of::<MaterialUniform>(),
            wgsl_size(SCENE_WGSL, "Material")
        );
        // Vertex = 3 + 3 + 4 + 4 + 4 + 2 floats.
        assert_eq!(std::mem::size_of::<Vertex>(), 80);
    }

    #[test]
    fn the_shader_taps_a_ward_lobe_where_its_reference_does() {
        // `ward_image_light` in scene.wgsl holds its own copy of the nodes (WGSL has no shared
        // constants with Rust); they must be the reference's.
        let start = SCENE_WGSL
            .find("var nodes = array<f32, 8>(")
            .expect("nodes in scene.wgsl");
        let list = &SCENE_WGSL[start..];
        let list = &list[list.find('(').expect("open") + 1..list.find(')').expect("close")];
        let nodes: Vec<f32> = list.split(',').map(|x| x.trim().parse().expect("a number")).collect();
        let reference = phantogram_assets::ibl::WARD_TAP_NODES;
        assert_eq!(nodes.len(), reference.len());
        for (a, b) in nodes.iter().zip(reference) {
            assert!((a - b).abs() < 1e-4, "{nodes:?} vs {reference:?}");
        }
    }

    #[test]
    fn mips_average_colour_in_linear_light() {
        // A 2×1 image, black and white: the 1×1 mip is 50 % linear grey (188 in sRGB), not 128.
        let levels = mip_chain(2, 1, &[0, 0, 0, 255, 255, 255, 255, 255], true);
        assert_eq!(levels.len(), 2);
        let (w, h, px) = &levels[1];
        assert_eq!((*w, *h), (1, 1));
        assert_eq!(px[0], 188);
        assert_eq!(px[3], 255);
        let data = mip_chain(2, 1, &[0, 0, 0, 0, 255, 255, 255, 255], false);
        assert_eq!(data[1].2[0], 128);
        assert_eq!(mip_chain(5, 3, &[7u8; 60], false).len(), 3);
    }
}
