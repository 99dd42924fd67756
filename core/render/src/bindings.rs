//! Bind group layouts and the per-eye bind groups: uniform blocks, the shadow maps, image-based
//! light and the Ward map as the scene shader binds them.

use crate::{gpu::Gpu, lighting_tables::IblTextures, uniforms::EyeUniform, upload::upload_texture};
use phantogram_assets::ward::WardMap;

pub(crate) fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
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
pub(crate) fn eye_block_buffer(device: &wgpu::Device, label: &str) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: std::mem::size_of::<EyeUniform>() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// The eyes' bind group's shadow maps and Ward map (see `Eye`'s bindings in `scene.wgsl`).
pub(crate) struct EyeViews<'a> {
    pub(crate) shadow: &'a wgpu::TextureView,
    pub(crate) shadow_sampler: &'a wgpu::Sampler,
    pub(crate) shadow_cube: &'a wgpu::TextureView,
    /// What glass leaves of the light (`shadow_filter`): the one view's or the lamp cube's.
    pub(crate) shadow_filter: &'a wgpu::TextureView,
    pub(crate) ward_map: &'a wgpu::TextureView,
    pub(crate) ward_sampler: &'a wgpu::Sampler,
    /// Each eye's copy of what lies behind its glass (`backdrop`; a placeholder without one) and its
    /// sampler.
    pub(crate) backdrop: [&'a wgpu::TextureView; 2],
    pub(crate) backdrop_sampler: &'a wgpu::Sampler,
}

/// A Ward map's texels as a mipmapped linear texture (the mips average the scales, so a distant
/// weave shows its mean).
pub(crate) fn upload_ward_map(gpu: &Gpu, map: WardMap) -> wgpu::TextureView {
    let (size, texels) = map.texels();
    upload_texture(gpu, "Ward map", size, size, &texels, false)
}

pub(crate) fn eye_bind_groups(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    buffers: &[wgpu::Buffer; 2],
    views: &EyeViews<'_>,
    ibl: &IblTextures,
) -> [wgpu::BindGroup; 2] {
    [0, 1].map(|i| eye_bind_group(device, layout, &buffers[i], views, i, ibl))
}

/// The bind group of a view drawn from `buffer`'s block with eye `eye`'s backdrop.
pub(crate) fn eye_bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    buffer: &wgpu::Buffer,
    views: &EyeViews<'_>,
    eye: usize,
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
            wgpu::BindGroupEntry {
                binding: 9,
                resource: wgpu::BindingResource::TextureView(views.shadow_filter),
            },
            wgpu::BindGroupEntry {
                binding: 10,
                resource: wgpu::BindingResource::TextureView(views.backdrop[eye]),
            },
            wgpu::BindGroupEntry {
                binding: 11,
                resource: wgpu::BindingResource::Sampler(views.backdrop_sampler),
            },
            wgpu::BindGroupEntry {
                binding: 12,
                resource: wgpu::BindingResource::TextureView(views.shadow),
            },
        ],
    })
}

/// A filtering sampler at `binding`, for the fragment stage.
pub(crate) fn filtering_sampler_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        count: None,
    }
}

pub(crate) fn filterable_texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    float_texture_entry(binding, true)
}

pub(crate) fn texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    float_texture_entry(binding, false)
}

/// A filterable 2D array texture at `binding`, read by the fragment stage.
pub(crate) fn filterable_texture_array_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    texture_array_entry(binding, true)
}

/// A float 2D array texture at `binding` (filterable or only loaded), read by the fragment stage.
pub(crate) fn texture_array_entry(binding: u32, filterable: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable },
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        },
        ..float_texture_entry(binding, filterable)
    }
}

pub(crate) fn float_texture_entry(binding: u32, filterable: bool) -> wgpu::BindGroupLayoutEntry {
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
