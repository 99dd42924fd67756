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
//! the CPU: on an NVIDIA H200 the convolution takes 0.2 ms of GPU time and this thread's share of
//! [`GpuPrefilter::run`] 1–2 ms (`benchmarks/ibl.md`, `cargo bench -p phantogram-render --bench
//! prefilter`); a phone's GPU is not measured (no phone here).
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
    /// The textures, buffers and bind groups of the last size of level 0 run: a live room light
    /// updates twice a second at one size, and making them anew each time is allocation the
    /// render thread need not do (and the renderer keeps its bind groups when the texture is the
    /// same).
    kept: Option<Kept>,
}

/// What one size of level 0 needs, kept between runs.
struct Kept {
    /// Level 0's width and height.
    size: (u32, u32),
    /// Level 0 and its halvings, as the levels read them (scaled into `f16`).
    source: wgpu::Texture,
    /// The prefiltered environment: level 0 as given, the others convolved. The same texture
    /// every run of this size: a frame submitted before a run samples the old levels, one after
    /// it the new ones (queue order), so it is overwritten in place.
    target: wgpu::Texture,
    /// Every texel a run uploads (the sources' levels, then level 0 of the target), as `f16`
    /// rows padded for copying: one write a run instead of one per level (each write is a
    /// staging buffer of its own).
    upload: wgpu::Buffer,
    /// Where each level lies in `upload`, in upload order.
    copies: Vec<LevelCopy>,
    /// Every convolved level's `Params` (prefilter.wgsl), one `params_stride` apart.
    params: wgpu::Buffer,
    params_stride: u64,
    /// Levels 1…: each one's bind group.
    levels: Vec<wgpu::BindGroup>,
}

/// One level's rows in [`Kept::upload`].
struct LevelCopy {
    /// Into the target (level 0) rather than the sources.
    into_target: bool,
    mip: u32,
    offset: u64,
    width: u32,
    height: u32,
    /// Bytes per row in the buffer (a multiple of `COPY_BYTES_PER_ROW_ALIGNMENT`).
    padded_row: u32,
}

/// Bytes of `Params` in prefilter.wgsl, padded to 32.
const PARAMS_BYTES: u64 = 32;

/// Bytes of an `Rgba16Float` texel.
const TEXEL_BYTES: u32 = 8;

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
                kept: None,
            }
        })
        .ok()
    }

    /// The prefiltered environment of `base` (a level 0 from
    /// [`phantogram_assets::ibl::prefilter_base`]: a power of two at least `2^PREFILTER_LEVELS`
    /// wide, twice as wide as high): a texture of [`PREFILTER_LEVELS`] mip levels, level 0
    /// `base` itself, the others convolved on the GPU. Submitted, not waited for.
    ///
    /// **Important**: runs of the same size return the same texture, overwritten in place (frames
    /// submitted in between keep seeing the levels they were submitted with); read one run's
    /// levels back before the next run if you need them.
    pub fn run(&mut self, gpu: &Gpu, base: &Environment) -> Result<wgpu::Texture, RenderError> {
        self.record(gpu, &PrefilterSources::new(base.clone()), None)
    }

    /// [`Self::run`] from level 0's halvings already made ([`PrefilterSources::new`]), as the
    /// room-light worker makes them off the render thread.
    pub fn run_sources(&mut self, gpu: &Gpu, sources: &PrefilterSources) -> Result<wgpu::Texture, RenderError> {
        self.record(gpu, sources, None)
    }

    /// [`Self::run`], waited for, with the GPU time of the convolution passes in milliseconds
    /// (from timestamp queries; `None` where the device has none): for the benchmark
    /// (`core/render/benches/prefilter.rs`). The uploads of the sources are not in that time.
    pub fn run_timed(&mut self, gpu: &Gpu, base: &Environment) -> Result<(wgpu::Texture, Option<f64>), RenderError> {
        let device = &gpu.device;
        if !device.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
            let texture = self.record(gpu, &PrefilterSources::new(base.clone()), None)?;
            device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(|e| RenderError::Readback(e.to_string()))?;
            return Ok((texture, None));
        }
        let set = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("prefilter time"),
            ty: wgpu::QueryType::Timestamp,
            count: 2,
        });
        let bytes = 2 * u64::from(wgpu::QUERY_SIZE);
        let resolve = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("prefilter time resolve"),
            size: bytes,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("prefilter time read-back"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let texture = self.record(gpu, &PrefilterSources::new(base.clone()), Some(&set))?;
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.resolve_query_set(&set, 0..2, &resolve, 0);
        encoder.copy_buffer_to_buffer(&resolve, 0, &readback, 0, bytes);
        checked(device, "the GPU prefilter's timestamps", || {
            gpu.queue.submit([encoder.finish()])
        })?;
        let slice = readback.slice(..);
        crate::targets::map_for_reading(device, &slice)?;
        let ticks: [u64; 2] = {
            let view = slice
                .get_mapped_range()
                .map_err(|e| RenderError::Readback(e.to_string()))?;
            bytemuck::pod_read_unaligned(&view[..bytes as usize])
        };
        readback.unmap();
        let period_ns = f64::from(gpu.queue.get_timestamp_period());
        // A reading that runs backwards is no measurement.
        let [start, end] = ticks;
        let ms = end.checked_sub(start).map(|t| t as f64 * period_ns * 1e-6);
        Ok((texture, ms))
    }

    /// Uploads the sources and records and submits the convolution of every level; with `timer`,
    /// its first pass writes timestamp 0 at its start and its last pass timestamp 1 at its end.
    fn record(
        &mut self,
        gpu: &Gpu,
        given: &PrefilterSources,
        timer: Option<&wgpu::QuerySet>,
    ) -> Result<wgpu::Texture, RenderError> {
        let Some(base) = given.halvings.first() else {
            return Err(RenderError::Gpu {
                what: "the GPU prefilter",
                message: "no level 0".into(),
            });
        };
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
        // Sources made by `PrefilterSources::new` halve level 0 each time and are read by index:
        // anything else (the fields are public) is refused rather than copied out of shape.
        let halvings_fit = given.halvings.iter().enumerate().all(|(i, h)| {
            h.width == base.width >> i && h.height == base.height >> i && h.texels.len() == h.width * h.height
        });
        if !halvings_fit || given.read_by.iter().any(|&r| r >= given.halvings.len()) {
            return Err(RenderError::Gpu {
                what: "the GPU prefilter",
                message: "the sources are not level 0's halvings".into(),
            });
        }
        let device = &gpu.device;
        let read_by = given.read_by;
        // The source is f16, which ends at 65504: a brighter sun is divided by a power of two
        // (exact) so that its energy reaches the rough levels as on the CPU, and multiplied back
        // in the shader.
        // One running maximum per channel: three independent chains, not one (a float maximum is
        // not reordered by the compiler).
        let mut channel_peaks = [0.0f32; 3];
        for t in &base.texels {
            for k in 0..3 {
                if t[k].is_finite() {
                    channel_peaks[k] = channel_peaks[k].max(t[k]);
                }
            }
        }
        let peak = channel_peaks[0].max(channel_peaks[1]).max(channel_peaks[2]);
        let scale = if peak > 32_768.0 {
            (peak / 32_768.0).log2().ceil().exp2()
        } else {
            1.0
        };
        let scaled: Option<Vec<Environment>> = (scale != 1.0).then(|| {
            given
                .halvings
                .iter()
                .map(|level| Environment {
                    texels: level.texels.iter().map(|t| t.map(|c| c / scale)).collect(),
                    ..*level
                })
                .collect()
        });
        let sources: &[Environment] = scaled.as_deref().unwrap_or(&given.halvings);
        let kept = match self.kept.take() {
            Some(kept) if kept.size == (w0, h0) && kept.copies.len() == sources.len() + 1 => kept,
            _ => checked(device, "the GPU prefilter", || {
                self.kept_for(gpu, w0, h0, &read_by, sources)
            })?,
        };
        let target = checked(device, "the GPU prefilter", || {
            let mut bytes = Vec::with_capacity(kept.upload.size() as usize);
            for copy in &kept.copies {
                let level = if copy.into_target {
                    base
                } else {
                    &sources[copy.mip as usize]
                };
                lighting_tables::push_rgba16f_rows(&mut bytes, level, copy.padded_row);
            }
            gpu.queue.write_buffer(&kept.upload, 0, &bytes);
            let mut params = vec![0u8; kept.params.size() as usize];
            for (k, &source_level) in read_by.iter().enumerate().skip(1) {
                let roughness = k as f32 / (PREFILTER_LEVELS - 1) as f32;
                let fields = [
                    (roughness * roughness).to_bits(),
                    (source_level as f32).to_bits(),
                    w0 >> k,
                    h0 >> k,
                    scale.to_bits(),
                ];
                let at = (k - 1) * kept.params_stride as usize;
                for (i, field) in fields.iter().enumerate() {
                    params[at + 4 * i..at + 4 * i + 4].copy_from_slice(&field.to_le_bytes());
                }
            }
            gpu.queue.write_buffer(&kept.params, 0, &params);
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("prefilter"),
            });
            for copy in &kept.copies {
                encoder.copy_buffer_to_texture(
                    wgpu::TexelCopyBufferInfo {
                        buffer: &kept.upload,
                        layout: wgpu::TexelCopyBufferLayout {
                            offset: copy.offset,
                            bytes_per_row: Some(copy.padded_row),
                            rows_per_image: Some(copy.height),
                        },
                    },
                    wgpu::TexelCopyTextureInfo {
                        texture: if copy.into_target { &kept.target } else { &kept.source },
                        mip_level: copy.mip,
                        origin: wgpu::Origin3d::ZERO,
                        aspect: wgpu::TextureAspect::All,
                    },
                    wgpu::Extent3d {
                        width: copy.width,
                        height: copy.height,
                        depth_or_array_layers: 1,
                    },
                );
            }
            let last = kept.levels.len();
            for (i, bind) in kept.levels.iter().enumerate() {
                let k = i + 1;
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("prefilter level"),
                    // Only the first and last passes write (wgpu refuses a pass writing none).
                    timestamp_writes: timer.filter(|_| k == 1 || k == last).map(|query_set| {
                        wgpu::ComputePassTimestampWrites {
                            query_set,
                            beginning_of_pass_write_index: (k == 1).then_some(0),
                            end_of_pass_write_index: (k == last).then_some(1),
                        }
                    }),
                });
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, bind, &[]);
                pass.dispatch_workgroups((w0 >> k).div_ceil(8), (h0 >> k).div_ceil(8), 1);
            }
            gpu.queue.submit([encoder.finish()]);
            kept.target.clone()
        })?;
        self.kept = Some(kept);
        Ok(target)
    }

    /// The textures, buffers and bind groups for a level 0 of `w0` × `h0` whose levels read the
    /// halvings `read_by` of `sources`.
    fn kept_for(&self, gpu: &Gpu, w0: u32, h0: u32, read_by: &[usize], sources: &[Environment]) -> Kept {
        let device = &gpu.device;
        let source =
            lighting_tables::prefiltered_texture(device, w0, h0, sources.len() as u32, wgpu::TextureUsages::empty());
        let target = lighting_tables::prefiltered_texture(
            device,
            w0,
            h0,
            PREFILTER_LEVELS as u32,
            wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
        );
        // The sources' levels, then level 0 of the target.
        let mut copies = Vec::new();
        let mut offset = 0u64;
        let shapes = sources
            .iter()
            .enumerate()
            .map(|(m, s)| (false, m, s))
            .chain([(true, 0, &sources[0])]);
        for (into_target, mip, level) in shapes {
            let (width, height) = (level.width as u32, level.height as u32);
            let padded_row =
                (TEXEL_BYTES * width).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
            copies.push(LevelCopy {
                into_target,
                mip: mip as u32,
                offset,
                width,
                height,
                padded_row,
            });
            offset += u64::from(padded_row) * u64::from(height);
        }
        let upload = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("prefilter upload"),
            size: offset,
            usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let params_stride = u64::from(device.limits().min_uniform_buffer_offset_alignment).max(PARAMS_BYTES);
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("prefilter levels"),
            size: params_stride * (read_by.len() as u64 - 1),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let source_view = source.create_view(&Default::default());
        let levels = (1..read_by.len())
            .map(|k| {
                let target_view = target.create_view(&wgpu::TextureViewDescriptor {
                    base_mip_level: k as u32,
                    mip_level_count: Some(1),
                    ..Default::default()
                });
                device.create_bind_group(&wgpu::BindGroupDescriptor {
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
                            resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                                buffer: &params,
                                offset: params_stride * (k as u64 - 1),
                                size: wgpu::BufferSize::new(PARAMS_BYTES),
                            }),
                        },
                    ],
                })
            })
            .collect();
        Kept {
            size: (w0, h0),
            source,
            target,
            upload,
            copies,
            params,
            params_stride,
            levels,
        }
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
