//! The prefiltered environment on the GPU: the rough levels of the specular image light
//! convolved by a compute shader (`shaders/prefilter.wgsl`) instead of on the CPU, where the
//! device has compute shaders and `Rgba16Float` storage textures (phones' Vulkan and Metal, and
//! lavapipe; not WebGL-class devices, which keep the CPU path).
//!
//! The CPU makes level 0 ([`phantogram_assets::ibl::prefilter_base`], a resampling), its
//! box-filtered halvings and their `f16` rows ([`PrefilterUpload`], on any thread: the room
//! light's worker); the GPU convolves levels 1… from them with the same samples, bilinear reads
//! and weights as [`phantogram_assets::ibl::prefiltered_levels`], so the two paths agree to the
//! precision of `f16` (tested in `tests/tests/integration/prefilter_gpu.rs`; on an NVIDIA H200
//! too). This moves the tens of milliseconds of GGX convolution (66–140 ms on this machine's CPU
//! for a room-light update) off the CPU: on an NVIDIA H200 the convolution takes 0.28 ms of GPU
//! time and this thread's share of [`GpuPrefilter::run_upload`] 0.11–0.19 ms
//! (`benchmarks/ibl.md`, `cargo bench -p phantogram-render --bench prefilter`); a phone's GPU is
//! not measured (no phone here).
//!
//! **Threading**: runs on the thread that owns the [`Gpu`] (the render thread);
//! [`GpuPrefilter::run_upload`] writes, records and submits without waiting; frames submitted
//! after it see the result (queue order). No panics: validation failures come back as
//! [`RenderError::Gpu`].

mod upload;

use phantogram_assets::ibl::{Environment, PREFILTER_LEVELS, PrefilterSources};
pub use upload::PrefilterUpload;

use crate::{Gpu, RenderError, checked, lighting_tables};

/// The prefilter's WGSL.
pub const PREFILTER_WGSL: &str = include_str!("../../../../shaders/prefilter.wgsl");

/// The compute pipeline and what it binds; made once per renderer.
pub struct GpuPrefilter {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
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
    /// The update's bytes ([`PrefilterUpload`]): one write a run instead of one per level (each
    /// write is a staging buffer of its own).
    upload: wgpu::Buffer,
    /// Every convolved level's `Params` (prefilter.wgsl), one `params_stride` apart.
    params: wgpu::Buffer,
    params_stride: u64,
    /// Levels 1…: each one's bind group.
    levels: Vec<wgpu::BindGroup>,
}

/// Bytes of `Params` in prefilter.wgsl, padded to 32.
const PARAMS_BYTES: u64 = 32;

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
            Self {
                pipeline,
                layout,
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
        self.record(gpu, &PrefilterUpload::new(PrefilterSources::new(base.clone()))?, None)
    }

    /// [`Self::run`] from an update already packed ([`PrefilterUpload::new`]), as the room-light
    /// worker packs it off the render thread: this thread then only writes its bytes, records
    /// and submits.
    pub fn run_upload(&mut self, gpu: &Gpu, upload: &PrefilterUpload) -> Result<wgpu::Texture, RenderError> {
        self.record(gpu, upload, None)
    }

    /// [`Self::run`], waited for, with the GPU time of the convolution passes in milliseconds
    /// (from timestamp queries; `None` where the device has none): for the benchmark
    /// (`core/render/benches/prefilter.rs`). The uploads of the sources are not in that time.
    pub fn run_timed(&mut self, gpu: &Gpu, base: &Environment) -> Result<(wgpu::Texture, Option<f64>), RenderError> {
        let device = &gpu.device;
        let upload = PrefilterUpload::new(PrefilterSources::new(base.clone()))?;
        if !device.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
            let texture = self.record(gpu, &upload, None)?;
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
        let texture = self.record(gpu, &upload, Some(&set))?;
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
        upload: &PrefilterUpload,
        timer: Option<&wgpu::QuerySet>,
    ) -> Result<wgpu::Texture, RenderError> {
        let device = &gpu.device;
        let (w0, h0) = upload.size();
        // An upload's layout follows from its size and number of halvings alone
        // (`PrefilterUpload::new`), so those two decide whether the kept buffer fits it.
        let kept = match self.kept.take() {
            Some(kept)
                if kept.size == (w0, h0)
                    && kept.source.mip_level_count() == upload.source_levels
                    && kept.upload.size() == upload.bytes.len() as u64 =>
            {
                kept
            }
            _ => checked(device, "the GPU prefilter", || self.kept_for(gpu, upload))?,
        };
        let target = checked(device, "the GPU prefilter", || {
            gpu.queue.write_buffer(&kept.upload, 0, &upload.bytes);
            let mut params = vec![0u8; kept.params.size() as usize];
            for (k, &source_level) in upload.read_by.iter().enumerate().skip(1) {
                let roughness = k as f32 / (PREFILTER_LEVELS - 1) as f32;
                let fields = [
                    (roughness * roughness).to_bits(),
                    (source_level as f32).to_bits(),
                    w0 >> k,
                    h0 >> k,
                    upload.scale.to_bits(),
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
            for copy in &upload.copies {
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

    /// The textures, buffers and bind groups for uploads of `upload`'s size and layout.
    fn kept_for(&self, gpu: &Gpu, upload: &PrefilterUpload) -> Kept {
        let device = &gpu.device;
        let ((w0, h0), source_levels) = (upload.size(), upload.source_levels);
        let source = lighting_tables::prefiltered_texture(device, w0, h0, source_levels, wgpu::TextureUsages::empty());
        let target = lighting_tables::prefiltered_texture(
            device,
            w0,
            h0,
            PREFILTER_LEVELS as u32,
            wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
        );
        let upload_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("prefilter upload"),
            size: upload.bytes.len() as u64,
            usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let params_stride = u64::from(device.limits().min_uniform_buffer_offset_alignment).max(PARAMS_BYTES);
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("prefilter levels"),
            size: params_stride * (PREFILTER_LEVELS as u64 - 1),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let source_view = source.create_view(&Default::default());
        let levels = (1..PREFILTER_LEVELS)
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
            upload: upload_buffer,
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
