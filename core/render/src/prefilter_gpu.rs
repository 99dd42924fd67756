//! The prefiltered environment on the GPU: the rough levels of the specular image light
//! convolved by a compute shader (`shaders/prefilter.wgsl`) instead of on the CPU, where the
//! device has compute shaders and `Rgba16Float` storage textures (phones' Vulkan and Metal, and
//! lavapipe; not WebGL-class devices, which keep the CPU path).
//!
//! The CPU makes level 0 ([`phantogram_assets::ibl::prefilter_base`], a resampling) and its
//! box-filtered halvings (cheap); the GPU convolves levels 1… from them with the same samples and
//! weights as [`phantogram_assets::ibl::prefiltered_levels`], so the two paths agree to the
//! precision of `f16` (tested in `tests/tests/integration/prefilter_gpu.rs`). This moves the tens of
//! milliseconds of GGX convolution (66–140 ms on this machine's CPU for a room-light update) off
//! the CPU; the figure on a phone's GPU is not measured here (no GPU machine was lent).
//!
//! **Threading**: runs on the thread that owns the [`Gpu`] (the render thread); [`GpuPrefilter::run`]
//! records and submits without waiting; frames submitted after it see the result (queue order).
//! No panics: validation failures come back as [`RenderError::Gpu`].

use phantogram_assets::ibl::{Environment, PREFILTER_LEVELS, PrefilterSources};

use crate::{Gpu, RenderError, checked, lighting_tables};

/// The prefilter's WGSL.
pub const PREFILTER_WGSL: &str = include_str!("../../../shaders/prefilter.wgsl");

/// The compute pipeline and what it binds; made once per renderer.
pub struct GpuPrefilter {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
}

impl GpuPrefilter {
    /// The prefilter, or `None` where the device lacks compute shaders or `Rgba16Float` storage
    /// writes (the caller keeps the CPU path) or the pipeline cannot be made.
    pub fn new(gpu: &Gpu) -> Option<Self> {
        let flags = gpu.adapter.get_downlevel_capabilities().flags;
        let format = gpu
            .adapter
            .get_texture_format_features(wgpu::TextureFormat::Rgba16Float);
        if !flags.contains(wgpu::DownlevelFlags::COMPUTE_SHADERS)
            || !format.allowed_usages.contains(wgpu::TextureUsages::STORAGE_BINDING)
            || gpu.device.limits().max_storage_textures_per_shader_stage == 0
        {
            return None;
        }
        let device = &gpu.device;
        checked(device, "the GPU prefilter", || {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("prefilter"),
                source: wgpu::ShaderSource::Wgsl(PREFILTER_WGSL.into()),
            });
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("prefilter"),
                entries: &[
                    wgpu::BindGroupLayoutEntry {
                        binding: 0,
                        visibility: wgpu::ShaderStages::COMPUTE,
                        ty: wgpu::BindingType::Texture {
                            sample_type: wgpu::TextureSampleType::Float { filterable: true },
                            view_dimension: wgpu::TextureViewDimension::D2,
                            multisampled: false,
                        },
                        count: None,
                    },
                    wgpu::BindGroupLayoutEntry {
                        binding: 1,
                        visibility: wgpu::ShaderStages::COMPUTE,
                        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                        count: None,
                    },
                    wgpu::BindGroupLayoutEntry {
                        binding: 2,
                        visibility: wgpu::ShaderStages::COMPUTE,
                        ty: wgpu::BindingType::StorageTexture {
                            access: wgpu::StorageTextureAccess::WriteOnly,
                            format: wgpu::TextureFormat::Rgba16Float,
                            view_dimension: wgpu::TextureViewDimension::D2,
                        },
                        count: None,
                    },
                    crate::uniform_entry(3, wgpu::ShaderStages::COMPUTE),
                ],
            });
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("prefilter"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
            let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("prefilter"),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some("main"),
                compilation_options: Default::default(),
                cache: None,
            });
            // As Environment::sample reads: wrapping in azimuth, clamped at the poles, bilinear,
            // one whole level at a time.
            let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("prefilter source"),
                address_mode_u: wgpu::AddressMode::Repeat,
                address_mode_v: wgpu::AddressMode::ClampToEdge,
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                mipmap_filter: wgpu::MipmapFilterMode::Nearest,
                ..Default::default()
            });
            Self {
                pipeline,
                layout,
                sampler,
            }
        })
        .ok()
    }

    /// The prefiltered environment of `base` (a level 0 from
    /// [`phantogram_assets::ibl::prefilter_base`]: a power of two at least `2^PREFILTER_LEVELS`
    /// wide, twice as wide as high): a texture of [`PREFILTER_LEVELS`] mip levels, level 0
    /// `base` itself, the others convolved on the GPU. Submitted, not waited for.
    pub fn run(&self, gpu: &Gpu, base: &Environment) -> Result<wgpu::Texture, RenderError> {
        let (w0, h0) = (base.width as u32, base.height as u32);
        if !w0.is_power_of_two()
            || w0 < 1 << PREFILTER_LEVELS
            || w0 != 2 * h0
            || base.texels.len() != base.width * base.height
        {
            return Err(RenderError::Gpu {
                what: "the GPU prefilter",
                message: format!("level 0 must be 2^k × 2^(k−1) texels, k ≥ {PREFILTER_LEVELS}; got {w0} × {h0}"),
            });
        }
        let device = &gpu.device;
        // The halvings each level reads, as prefiltered_levels reads them.
        let PrefilterSources {
            halvings: mut sources,
            read_by,
        } = PrefilterSources::new(base.clone());
        // The source is f16, which ends at 65504: a brighter sun is divided by a power of two
        // (exact) so that its energy reaches the rough levels as on the CPU, and multiplied back
        // in the shader.
        let peak = base
            .texels
            .iter()
            .flatten()
            .fold(0.0f32, |m, &c| if c.is_finite() { m.max(c) } else { m });
        let scale = if peak > 32_768.0 {
            (peak / 32_768.0).log2().ceil().exp2()
        } else {
            1.0
        };
        for level in &mut sources {
            for t in &mut level.texels {
                *t = t.map(|c| c / scale);
            }
        }
        checked(device, "the GPU prefilter", || {
            let source = lighting_tables::prefiltered_texture(
                device,
                w0,
                h0,
                sources.len() as u32,
                wgpu::TextureUsages::empty(),
            );
            for (m, level) in sources.iter().enumerate() {
                lighting_tables::write_level(&gpu.queue, &source, m as u32, level);
            }
            let target = lighting_tables::prefiltered_texture(
                device,
                w0,
                h0,
                PREFILTER_LEVELS as u32,
                wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
            );
            let source_view = source.create_view(&Default::default());
            // Level 0 as given (clamped to f16 as the CPU path's upload clamps it).
            lighting_tables::write_level(&gpu.queue, &target, 0, base);
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("prefilter"),
            });
            for (k, &mip) in read_by.iter().enumerate().skip(1) {
                let roughness = k as f32 / (PREFILTER_LEVELS - 1) as f32;
                let (w, h) = (w0 >> k, h0 >> k);
                // Params in prefilter.wgsl, padded to 32 bytes.
                let params: Vec<u8> = [
                    (roughness * roughness).to_bits(),
                    (mip as f32).to_bits(),
                    w,
                    h,
                    scale.to_bits(),
                    0,
                    0,
                    0,
                ]
                .iter()
                .flat_map(|x| x.to_le_bytes())
                .collect();
                let buffer = wgpu::util::DeviceExt::create_buffer_init(
                    device,
                    &wgpu::util::BufferInitDescriptor {
                        label: Some("prefilter level"),
                        contents: &params,
                        usage: wgpu::BufferUsages::UNIFORM,
                    },
                );
                let target_view = target.create_view(&wgpu::TextureViewDescriptor {
                    base_mip_level: k as u32,
                    mip_level_count: Some(1),
                    ..Default::default()
                });
                let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("prefilter level"),
                    layout: &self.layout,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: wgpu::BindingResource::TextureView(&source_view),
                        },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: wgpu::BindingResource::Sampler(&self.sampler),
                        },
                        wgpu::BindGroupEntry {
                            binding: 2,
                            resource: wgpu::BindingResource::TextureView(&target_view),
                        },
                        wgpu::BindGroupEntry {
                            binding: 3,
                            resource: buffer.as_entire_binding(),
                        },
                    ],
                });
                {
                    let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                        label: Some("prefilter level"),
                        timestamp_writes: None,
                    });
                    pass.set_pipeline(&self.pipeline);
                    pass.set_bind_group(0, &bind, &[]);
                    pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
                }
            }
            gpu.queue.submit([encoder.finish()]);
            target
        })
    }

    /// Reads every level of a prefiltered texture back (waits for the GPU): for tests and the
    /// benchmark.
    pub fn read_back(gpu: &Gpu, texture: &wgpu::Texture) -> Result<Vec<Environment>, RenderError> {
        let mut levels = Vec::new();
        for mip in 0..texture.mip_level_count() {
            let (w, h) = ((texture.width() >> mip).max(1), (texture.height() >> mip).max(1));
            // `Rgba16Float`: eight bytes a texel, alpha unused.
            let bytes = crate::read_texture_level(gpu, texture, mip)?;
            let texels = bytes
                .chunks_exact(8)
                .map(|t| std::array::from_fn(|i| half::f16::from_le_bytes([t[2 * i], t[2 * i + 1]]).to_f32()))
                .collect();
            levels.push(Environment {
                width: w as usize,
                height: h as usize,
                texels,
            });
        }
        Ok(levels)
    }
}
