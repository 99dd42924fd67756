//! Render targets (per-eye HDR colour and depth, the composed output) and reading frames and
//! texture levels back from the GPU.

use crate::{OUTPUT_FORMAT, RenderError, checked, gpu::Gpu};

pub(crate) struct Targets {
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) hdr: [wgpu::TextureView; 2],
    pub(crate) depth: wgpu::TextureView,
    pub(crate) compose_bind: [wgpu::BindGroup; 2],
    /// Only when rendering headless: drawing to a window composes into its swapchain image.
    pub(crate) offscreen: Option<Offscreen>,
    /// Only while the model has glass that blurs or bends what is behind it.
    pub(crate) backdrop: Option<crate::backdrop::Backdrop>,
}

/// The composed frame's texture and the buffer it is read back through.
pub(crate) struct Offscreen {
    pub(crate) output: wgpu::Texture,
    pub(crate) output_view: wgpu::TextureView,
    pub(crate) readback: wgpu::Buffer,
    pub(crate) padded_row: u32,
}

/// A `width × height` texture of `format` to draw a frame into and read back (the offscreen
/// output; in tests, a window's surface texture).
pub fn target_texture(
    device: &wgpu::Device,
    label: &str,
    width: u32,
    height: u32,
    format: wgpu::TextureFormat,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

impl Offscreen {
    /// Bytes per row of the read-back buffer: RGBA8, padded to wgpu's copy alignment.
    pub(crate) fn padded_row(width: u32) -> u64 {
        let align = u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        (u64::from(width) * 4).div_ceil(align) * align
    }

    pub(crate) fn new(device: &wgpu::Device, width: u32, height: u32) -> Self {
        let output = target_texture(device, "output", width, height, OUTPUT_FORMAT);
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

/// Maps `slice` for reading and waits until it is (or the mapping failed).
pub(crate) fn map_for_reading(device: &wgpu::Device, slice: &wgpu::BufferSlice<'_>) -> Result<(), RenderError> {
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

pub(crate) fn read_back(
    device: &wgpu::Device,
    targets: &Offscreen,
    width: u32,
    height: u32,
) -> Result<Vec<u8>, RenderError> {
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
