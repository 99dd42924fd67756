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
//!    every surface; alpha-masked materials are cut out as in the scene pass (their shadows have
//!    the holes they have), blended and transmissive ones cast none. A [`Lamp`] in its place is
//!    seen from one perspective view, or, standing among what it shadows, from the six faces of
//!    a cube ([`point_shadow`]: six passes of 512² texels). Then, where the model has glass and
//!    the light one view, the shadow filter: the transmissive surfaces drawn from the light into
//!    a colour map of the share of the light they pass and the depth of the nearest
//!    (`shadow_filter`), so that glass casts a pale shadow and tinted glass a coloured one.
//! 2. Scene pass per eye into a linear HDR target (`Rgba16Float`) with reverse-Z depth
//!    (`Depth32Float`, cleared to 0, compare `Greater`): the core's projections map near to 1.
//!    Opaque and masked primitives first, then blended ones back to front (depth test, no depth
//!    write), among them those light passes through (glass: `KHR_materials_transmission`), each
//!    drawn twice: a filter that multiplies what is behind by its transmittance (base colour,
//!    Fresnel, the volume's absorption), then its own light added (`DrawLayer`). Glass that
//!    blurs (rough: frosted) or bends (a refracting volume) what is seen through it is drawn
//!    over the eye's backdrop instead (`backdrop`): just before the farthest such glass, the
//!    pass ends, a copy of the eye's target and its halvings are made, and the rest follows in a
//!    second pass, such glass reading what is behind it from the copy (at a level by its
//!    roughness, where its refracted ray lands); blended surfaces between two such glasses are
//!    not in the copy the nearer one reads. Double-sided glass is
//!    drawn in two halves, its back faces (the far side) before its front faces, so that its
//!    near side filters its far side's light; within one half, triangles that overlap on screen
//!    (a shape folded over itself) are drawn in the mesh's order. Mono renders only the
//!    cyclopean eye. Light, materials and textures are shared by both eyes; only the small
//!    per-eye uniform differs. A primitive whose level is
//!    [`IMPOSTOR_LEVEL`] and that has one baked is drawn as its relief-texture impostor
//!    ([`impostor`]; it casts the shadow of its polygon level as exact as it is); a primitive in
//!    [`FrameInput::fades`] is drawn at both its levels, each on its share of the pixels
//!    (pipelines with `FADE` set and the fade per instance, `vs_fade`).
//! 3. Composition pass: tone mapping (Khronos PBR Neutral, exposure) of each eye, then the
//!    anaglyph matrices ([`phantogram_geometry::anaglyph`]) in linear light, into an `Rgba8UnormSrgb` target.
//!
//! ## Models
//! [`Model`]s upload as one vertex and index buffer per primitive, one bind group per material
//! (uniform block, seven textures and their samplers, and the layer extensions' textures as one
//! array with its sampler, `layer_textures`; missing textures bind 1×1 defaults), one
//! scene pipeline per kind of material (culling, blending, alpha mask, and which texture slots it
//! has: the fragment shader is specialised by `override` constants and does not sample the
//! defaults, the same picture for a fifth less time on lavapipe), and
//! textures with full mip chains generated here (colour textures averaged in linear light, then
//! viewed as sRGB so the sampler decodes them).
//!
//! ## Modules
//! Here: the [`Renderer`] (made once per device; its model and targets) and the per-frame input.
//! `frame`: drawing a frame (shadow, scene and composition passes); `environment`: the
//! image-based light it draws with; `lights`: the directional light and the [`Lamp`] with their
//! shadow views ([`point_shadow`]: a lamp's cube); `uniforms`: the blocks the shaders read;
//! `gpu_model`: a model's buffers and materials on the GPU; `pipelines`: the render pipelines;
//! `bindings`: bind group layouts and the eyes' bind groups; `targets`: render targets and read
//! back. [`impostor`], [`surface`], [`prefilter_gpu`]: see each.
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
use phantogram_assets::model::{AlphaMode, Layers, Model, Sampler, Wrap};
pub use phantogram_assets::ward;
use phantogram_assets::ward::WardMap;
use phantogram_geometry::anaglyph::Method;
use phantogram_geometry::projection::OffAxisProjection;

mod backdrop;
mod bindings;
mod block_textures;
mod environment;
mod frame;
mod gpu;
mod gpu_model;
mod gpu_timer;
pub mod impostor;
mod layer_textures;
mod lighting_tables;
mod lights;
mod pipelines;
pub mod point_shadow;
pub mod prefilter_gpu;
mod shadow_filter;
pub mod surface;
mod targets;
mod uniforms;
mod upload;
use bindings::*;
use frame::{FADE_ENTRIES_AT_FIRST, fade_instance_buffer};
use gpu_model::*;
pub use lights::*;
use pipelines::*;
use targets::*;
pub use targets::{read_texture_level, target_texture};
use uniforms::*;

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
    /// What glass between the light and a surface leaves of the light (`shadow_filter`): for the
    /// one view of the light, and for a lamp's cube.
    shadow_filter: shadow_filter::ShadowFilter,
    cube_filter: shadow_filter::ShadowFilter,
    /// Whether the eyes' bind groups hold `cube_filter` (else `shadow_filter`).
    cube_filter_bound: bool,
    /// Draws the levels of the eyes' backdrops (`backdrop`), made with the first that is needed.
    backdrop_halver: Option<backdrop::Halver>,
    /// What the eyes' bind groups hold without a backdrop, and how backdrops are sampled.
    backdrop_placeholder: wgpu::TextureView,
    backdrop_sampler: wgpu::Sampler,
    /// Which backdrop the eyes' bind groups hold (`Backdrop::id`; 0: the placeholder).
    backdrop_bound: u64,
    /// The target size at which the device could not make the backdrops, if it could not.
    backdrop_failed: Option<(u32, u32)>,
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
                filtering_sampler_entry(5),
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
                filtering_sampler_entry(8),
                texture_array_entry(9, false),
                filterable_texture_entry(10),
                filtering_sampler_entry(11),
                // The shadow map again, read as plain floats (`shadow_depths`).
                float_texture_entry(12, false),
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
        // 1×1 until a model with glass is drawn with shadows.
        let shadow_filter = shadow_filter::ShadowFilter::new(device, 1, gpu.array_layers(1, 1, 1));
        let cube_filter = shadow_filter::ShadowFilter::new(device, 1, gpu.array_layers(1, 1, 6));
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
        let backdrop_placeholder = backdrop::placeholder(device);
        let backdrop_sampler = backdrop::sampler(device);
        let eye_bind = eye_bind_groups(
            device,
            &eye_layout,
            &eye_buffers,
            &EyeViews {
                shadow: &shadow_view,
                shadow_sampler: &shadow_sampler,
                shadow_cube: &point_shadow.cube_view,
                shadow_filter: &shadow_filter.view,
                ward_map: &ward_map.1,
                ward_sampler: &ward_sampler,
                backdrop: [&backdrop_placeholder; 2],
                backdrop_sampler: &backdrop_sampler,
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
        for slot in 0..TEXTURE_OVERRIDES.len() as u32 {
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
            material_entries.push(filtering_sampler_entry(2 + 2 * slot));
        }
        // The layer extensions' textures, one array (`layer_textures`).
        material_entries.push(filterable_texture_array_entry(15));
        material_entries.push(filtering_sampler_entry(16));
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
            shadow_filter,
            cube_filter,
            cube_filter_bound: false,
            backdrop_halver: None,
            backdrop_placeholder,
            backdrop_sampler,
            backdrop_bound: 0,
            backdrop_failed: None,
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

    /// Bytes the model's textures take on the GPU, with their mips: the materials' own (RGBA8,
    /// or block-compressed where the image came from a Basis Universal texture and the device
    /// samples a block format) and the layer arrays.
    pub fn texture_bytes(&self) -> u64 {
        self.model.texture_bytes
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
            backdrop: None,
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
            toward_light: input
                .toward_light
                .normalize_or(Vec3::Z)
                .extend(l.light_angular_radius_rad.clamp(0.0, 1.5))
                .to_array(),
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
        let good = "return Shaded(direct + ambient + s.emissive, through);";
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
    fn the_shader_taps_a_stretched_lobe_where_its_reference_does() {
        // `stretched_image_light` in scene.wgsl holds its own copy of the nodes (WGSL has no shared
        // constants with Rust); they must be the reference's.
        let start = SCENE_WGSL
            .find("var nodes = array<f32, 8>(")
            .expect("nodes in scene.wgsl");
        let list = &SCENE_WGSL[start..];
        let list = &list[list.find('(').expect("open") + 1..list.find(')').expect("close")];
        let nodes: Vec<f32> = list.split(',').map(|x| x.trim().parse().expect("a number")).collect();
        let reference = phantogram_assets::ibl::STRETCH_TAP_NODES;
        assert_eq!(nodes.len(), reference.len());
        for (a, b) in nodes.iter().zip(reference) {
            assert!((a - b).abs() < 1e-4, "{nodes:?} vs {reference:?}");
        }
    }

    #[test]
    fn the_shaders_stretched_lobes_and_sheen_tables_are_laid_out_as_the_assets_crate_makes_them() {
        // The pipelines set these overrides; their defaults serve shader validation and must say
        // the same.
        use phantogram_assets::ibl::anisotropic_albedo::{TILE, TILES};
        use phantogram_assets::ibl::sheen_direction::SIDE;
        for (name, value) in [
            ("ANISOTROPIC_TILE", TILE),
            ("ANISOTROPIC_TILES", TILES),
            ("SHEEN_DIRECTION_SIDE", SIDE),
        ] {
            let line = format!("override {name}: f32 = {value}.0;");
            assert!(SCENE_WGSL.contains(&line), "scene.wgsl lacks `{line}`");
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
