//! Block-compressed material textures (assets crate, `model::gpu_blocks`): which of ASTC 4 × 4,
//! BC7 and ETC2 the device samples, and their upload. A Basis Universal texture drawn from one of
//! them takes a quarter of the GPU memory of its RGBA8 copy, and is sampled as the file's encoder
//! meant (its own mips).
//!
//! Render thread only (uploads through the queue); no panics: a format is chosen only from what
//! the device has enabled.

use phantogram_assets::model::{BlockFormat, BlockLevel};
use wgpu::util::DeviceExt as _;

use crate::Gpu;

/// The compression features asked of the adapter where it has them.
pub(crate) const FEATURES: wgpu::Features = wgpu::Features::TEXTURE_COMPRESSION_ASTC
    .union(wgpu::Features::TEXTURE_COMPRESSION_BC)
    .union(wgpu::Features::TEXTURE_COMPRESSION_ETC2);

/// The block format `device` samples, best first: ASTC 4 × 4 (what UASTC is made of, so a copy of
/// the file's blocks; the phones' GPUs), BC7 (desktop GPUs and Mesa's software Vulkan), ETC2
/// (every OpenGL ES 3.0 GPU); none where it samples none of them.
pub(crate) fn format_for(device: &wgpu::Device) -> Option<BlockFormat> {
    let features = device.features();
    [
        (wgpu::Features::TEXTURE_COMPRESSION_ASTC, BlockFormat::Astc4x4),
        (wgpu::Features::TEXTURE_COMPRESSION_BC, BlockFormat::Bc7),
        (wgpu::Features::TEXTURE_COMPRESSION_ETC2, BlockFormat::Etc2Rgba8),
    ]
    .into_iter()
    .find_map(|(feature, format)| features.contains(feature).then_some(format))
}

/// The texture format of `format`, its texels decoded from sRGB where `srgb`.
fn texture_format(format: BlockFormat, srgb: bool) -> wgpu::TextureFormat {
    match (format, srgb) {
        (BlockFormat::Astc4x4, srgb) => wgpu::TextureFormat::Astc {
            block: wgpu::AstcBlock::B4x4,
            channel: if srgb {
                wgpu::AstcChannel::UnormSrgb
            } else {
                wgpu::AstcChannel::Unorm
            },
        },
        (BlockFormat::Bc7, true) => wgpu::TextureFormat::Bc7RgbaUnormSrgb,
        (BlockFormat::Bc7, false) => wgpu::TextureFormat::Bc7RgbaUnorm,
        (BlockFormat::Etc2Rgba8, true) => wgpu::TextureFormat::Etc2Rgba8UnormSrgb,
        (BlockFormat::Etc2Rgba8, false) => wgpu::TextureFormat::Etc2Rgba8Unorm,
    }
}

/// Uploads `levels` (the first one's size whole blocks, each next one half of it down to 1 × 1,
/// as `BasisSource::blocks` gives them) as one texture of `format`; the view and the bytes it
/// takes.
pub(crate) fn upload(
    gpu: &Gpu,
    label: &str,
    format: BlockFormat,
    srgb: bool,
    levels: &[BlockLevel],
) -> (wgpu::TextureView, u64) {
    let (width, height) = levels.first().map_or((4, 4), |l| (l.width, l.height));
    let data: Vec<u8> = levels.iter().flat_map(|l| l.blocks.iter().copied()).collect();
    let texture = gpu.device.create_texture_with_data(
        &gpu.queue,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: levels.len().max(1) as u32,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: texture_format(format, srgb),
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        &data,
    );
    (texture.create_view(&Default::default()), data.len() as u64)
}
