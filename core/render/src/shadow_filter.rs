//! What glass does to the light on its way to what stands behind it: a light-space map, beside
//! the shadow map, of the share of the light the surfaces that let light through
//! (`KHR_materials_transmission`) pass, per colour, multiplied over all of them, and in alpha the
//! light-space depth of the nearest, so that what lies between the light and the glass is not
//! tinted by it. A glass vase then casts a pale shadow, tinted glass a coloured one, where the
//! depth-only shadow map would give none (transmissive surfaces do not cast there) or a black one.
//!
//! Drawn when the frame has transmissive primitives and shadows: into one layer for one view of
//! the light (the directional light's, or a lamp's single perspective view), or into six, the
//! faces of the lamp's shadow cube (`point_shadow`, same order and views, its depth the cube's),
//! when a lamp stands among its casters. The renderer keeps one filter of each kind and binds the
//! one the frame needs. The scene shader reads it by `light_filter` (a face's texel from the
//! direction, `lamp_cube_filter`, for the cube; averaged over the penumbra's disc as the opaque
//! shadow is, `soft_light_filter`, under a directional light with a width) when the eye block's
//! `shadow.w` says it holds this frame's glass; the pipelines of a model
//! without glass are made with that read compiled out (`GLASS_SHADOWS`: read behind the branch
//! alone, it cost such frames 4–7 % on lavapipe, `benchmarks/render.md`), and so are the
//! impostors' (a big scan's far parts receive glass's light unfiltered). The share is taken at
//! normal incidence (the Fresnel loss at the light's angle and the refracted path's length are
//! not modelled, nor caustics).
//!
//! Made 1×1 and grown to its shadow map's size the first time a frame needs it (the eyes' bind
//! groups are remade then): 8 MiB for the one view, 12 MiB for the cube. Render thread only,
//! like the renderer; no panics.

use crate::pipelines::{SHADOW_MASKED_ATTRIBUTES, SHADOW_PRIMITIVE, vertex_buffer};

/// Colour: the share of the light passed; alpha: the nearest glass's depth (float for the depth,
/// and a format every device blends).
pub(crate) const FILTER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// Cleared to: all the light passes, and no glass nearer than the far plane.
pub(crate) const NOTHING_FILTERED: wgpu::Color = wgpu::Color {
    r: 1.0,
    g: 1.0,
    b: 1.0,
    a: 1.0,
};

pub(crate) struct ShadowFilter {
    /// Every layer (`texture_2d_array`), as the scene shader reads it.
    pub(crate) view: wgpu::TextureView,
    /// Each layer alone, as the filter pass draws into it.
    pub(crate) layer_views: Vec<wgpu::TextureView>,
    /// Texels along a side.
    pub(crate) size: u32,
    pipeline: Option<wgpu::RenderPipeline>,
}

impl ShadowFilter {
    /// A filter of `layers` layers (1: one view; 6: a cube's faces) of `size`² texels.
    pub(crate) fn new(device: &wgpu::Device, size: u32, layers: u32) -> Self {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow filter"),
            size: wgpu::Extent3d {
                width: size,
                height: size,
                depth_or_array_layers: layers,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: FILTER_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let layer_views = (0..layers)
            .map(|layer| {
                texture.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: layer,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        Self {
            view: texture.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            }),
            layer_views,
            size,
            pipeline: None,
        }
    }

    /// The pipeline that draws a transmissive primitive into the filter, once [`Self::prepare`]
    /// has made it.
    pub(crate) fn pipeline(&self) -> Option<&wgpu::RenderPipeline> {
        self.pipeline.as_ref()
    }

    /// Makes the pipeline that draws a transmissive primitive into the filter
    /// (`fs_shadow_filter`), if it is not made yet. `layout`: the light's matrix and a material,
    /// as the alpha-masked shadow pass has them.
    pub(crate) fn prepare(
        &mut self,
        device: &wgpu::Device,
        module: &wgpu::ShaderModule,
        layout: &wgpu::PipelineLayout,
    ) {
        self.pipeline.get_or_insert_with(|| {
            let attributes = SHADOW_MASKED_ATTRIBUTES;
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("shadow filter"),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some("vs_shadow_masked"),
                    compilation_options: Default::default(),
                    buffers: &[Some(vertex_buffer(&attributes))],
                },
                primitive: SHADOW_PRIMITIVE,
                depth_stencil: None,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some("fs_shadow_filter"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: FILTER_FORMAT,
                        // The shares multiply; the depth keeps the nearest.
                        blend: Some(wgpu::BlendState {
                            color: wgpu::BlendComponent {
                                src_factor: wgpu::BlendFactor::Zero,
                                dst_factor: wgpu::BlendFactor::Src,
                                operation: wgpu::BlendOperation::Add,
                            },
                            alpha: wgpu::BlendComponent {
                                src_factor: wgpu::BlendFactor::One,
                                dst_factor: wgpu::BlendFactor::One,
                                operation: wgpu::BlendOperation::Min,
                            },
                        }),
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        });
    }
}
