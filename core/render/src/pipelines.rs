//! The render pipelines: one scene pipeline per material variant (specialised by WGSL `override`
//! constants), their shadow-pass twins, the vertex layouts they share, and the composition pipeline.

use crate::{
    DEPTH_FORMAT, HDR_FORMAT,
    gpu_model::{GpuModel, MaterialVariant, TEXTURE_OVERRIDES},
};
use phantogram_assets::ibl::anisotropic_albedo;
use phantogram_assets::model::Vertex;

/// Scene pipelines, one per [`MaterialVariant`] in use, created when a model is set (never while
/// drawing: compiling a shader takes a good part of a frame).
pub(crate) struct ScenePipelines {
    pub(crate) module: wgpu::ShaderModule,
    pub(crate) layout: wgpu::PipelineLayout,
    pub(crate) variants: std::collections::HashMap<MaterialVariant, wgpu::RenderPipeline>,
    /// The light's matrix and a material: what the shadow pass of a masked material reads.
    pub(crate) shadow_masked_layout: wgpu::PipelineLayout,
    /// Shadow pass for alpha-masked materials (cut out as in the scene pass), made with the first
    /// model that has one.
    pub(crate) shadow_masked: Option<wgpu::RenderPipeline>,
}

impl ScenePipelines {
    pub(crate) fn get(&self, variant: &MaterialVariant) -> Option<&wgpu::RenderPipeline> {
        self.variants.get(variant)
    }

    /// Creates the pipelines of `model`'s materials that do not exist yet, with the cross-fade
    /// variants of those its primitives with levels of detail use.
    pub(crate) fn prepare(&mut self, device: &wgpu::Device, model: &GpuModel) {
        let fading = model
            .primitives
            .iter()
            .filter(|p| p.levels.len() > 1)
            .map(|p| model.materials[p.material].variant)
            .filter(|v| !v.blend)
            .map(|v| MaterialVariant { fade: true, ..v });
        let variants: Vec<MaterialVariant> = model
            .materials
            .iter()
            .flat_map(|m| m.variant.draws(true).chain(m.variant.draws(false)))
            .chain(fading)
            .collect();
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

    pub(crate) fn create_shadow_masked(&self, device: &wgpu::Device) -> wgpu::RenderPipeline {
        let attributes = SHADOW_MASKED_ATTRIBUTES;
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

    pub(crate) fn create(&self, device: &wgpu::Device, v: &MaterialVariant) -> wgpu::RenderPipeline {
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
        constants.push(("TRANSMIT_LAYER", v.layer.shader_constant()));
        constants.push(("HAS_LAYERS", flag(v.layers)));
        constants.push(("HAS_LAYER_TEXTURES", flag(v.layer_textures)));
        constants.push(("GLASS_SHADOWS", flag(v.glass_shadows)));
        // The stretched lobes' table's layout, as the assets crate makes it.
        constants.push(("ANISOTROPIC_TILE", anisotropic_albedo::TILE as f64));
        constants.push(("ANISOTROPIC_TILES", anisotropic_albedo::TILES as f64));
        // The sheen's mean directions' table's side, likewise.
        constants.push((
            "SHEEN_DIRECTION_SIDE",
            phantogram_assets::ibl::sheen_direction::SIDE as f64,
        ));
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
                cull_mode: if v.cull_front {
                    Some(wgpu::Face::Front)
                } else {
                    (!v.double_sided).then_some(wgpu::Face::Back)
                },
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
                    blend: v.layer.blend(v.blend),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        })
    }
}

/// What `vs_shadow_masked` reads of a [`Vertex`]: position, texture coordinates and colour (the
/// alpha-masked shadow pass and the shadow filter of glass).
pub(crate) const SHADOW_MASKED_ATTRIBUTES: [wgpu::VertexAttribute; 3] = [
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

/// The per-instance cross-fade (`vs_fade`, `vs_impostor`): fraction shown and side.
pub(crate) const FADE_ATTRIBUTES: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![6 => Float32x2];

/// The cross-fades' instance buffer: one `[f32; 2]` per draw ([`Renderer::write_fades`]).
pub(crate) fn fade_buffer_layout(attributes: &[wgpu::VertexAttribute]) -> wgpu::VertexBufferLayout<'_> {
    wgpu::VertexBufferLayout {
        array_stride: 8,
        step_mode: wgpu::VertexStepMode::Instance,
        attributes,
    }
}

/// A model's vertex buffer ([`Vertex`]), of which a pipeline reads `attributes`.
pub(crate) fn vertex_buffer(attributes: &[wgpu::VertexAttribute]) -> wgpu::VertexBufferLayout<'_> {
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes,
    }
}

/// The shadow pass's triangles: both faces cast, since open and double-sided surfaces must
/// shadow too.
pub(crate) const SHADOW_PRIMITIVE: wgpu::PrimitiveState = wgpu::PrimitiveState {
    topology: wgpu::PrimitiveTopology::TriangleList,
    strip_index_format: None,
    front_face: wgpu::FrontFace::Ccw,
    cull_mode: None,
    unclipped_depth: false,
    polygon_mode: wgpu::PolygonMode::Fill,
    conservative: false,
};

pub(crate) fn shadow_depth_state() -> wgpu::DepthStencilState {
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

pub(crate) fn create_compose_pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    format: wgpu::TextureFormat,
) -> wgpu::RenderPipeline {
    // A target that does not encode sRGB on write has the shader do it.
    let encode = if format.is_srgb() { 0.0 } else { 1.0 };
    create_fullscreen_pipeline(
        device,
        "compose",
        module,
        layout,
        "fs_main",
        format,
        &[("ENCODE_SRGB", encode)],
    )
}

/// Records a pass that clears `target` to black and draws one triangle over it with `pipeline`
/// (made by [`create_fullscreen_pipeline`]) and `bind` as its group 0.
pub(crate) fn draw_fullscreen(
    encoder: &mut wgpu::CommandEncoder,
    label: &str,
    target: &wgpu::TextureView,
    pipeline: &wgpu::RenderPipeline,
    bind: &wgpu::BindGroup,
    timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
) {
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        timestamp_writes,
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
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, bind, &[]);
    pass.draw(0..3, 0..1);
}

/// A pipeline that draws one triangle over its whole target (`module`'s `vs_main`, three
/// vertices, no buffers) with `module`'s `fragment_entry` into `format`, without depth or
/// blending; the fragment stage's pipeline constants `constants`.
pub(crate) fn create_fullscreen_pipeline(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    fragment_entry: &str,
    format: wgpu::TextureFormat,
    constants: &[(&str, f64)],
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
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
            entry_point: Some(fragment_entry),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants,
                ..Default::default()
            },
            targets: &[Some(format.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}
