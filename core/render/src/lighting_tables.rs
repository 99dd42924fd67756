//! The image-based light's tables: the split-sum BRDF table and the generated studio's
//! prefiltered levels (computed once per process, optionally ahead of time), and their textures.

use super::*;

/// Width of the prefiltered environment's sharpest level (mirror-like reflections).
pub const PREFILTERED_BASE_WIDTH: usize = 256;
/// Size of the split-sum BRDF table (n·v × roughness), and the lighting tables' texture width.
pub(super) const BRDF_LUT_SIZE: usize = 64;
/// The lighting tables' texture height: the round lobes' tables above, the stretched lobes'
/// ([`phantogram_assets::ibl::anisotropic_albedo`]) below them and the sheen's mean directions
/// ([`phantogram_assets::ibl::sheen_direction`]) at the bottom, all as wide as the texture.
pub(super) const LIGHTING_TABLES_HEIGHT: usize = BRDF_LUT_SIZE + anisotropic_albedo::SIDE + sheen_direction::SIDE;
const _: () = assert!(
    anisotropic_albedo::SIDE == BRDF_LUT_SIZE && sheen_direction::TABLE_WIDTH == BRDF_LUT_SIZE,
    "the tables share the texture's width"
);

use phantogram_assets::ibl::{anisotropic_albedo, sheen_direction};

/// Computes, once per process, the tables a [`Renderer`] needs before its first frame: the
/// split-sum BRDF table and, if `studio`, the generated studio's prefiltered levels (the lighting
/// when no environment is given). About 100 ms of CPU work on this machine's two cores, and 60 ms
/// more since the split-sum table takes four times the samples per entry and the Ward lobe's
/// albedo joined it, about 50 ms more for the stretched lobes' table and 10 ms for the sheen's
/// mean directions (2026-12-07); an app calls it on a background thread at start-up, overlapping
/// it with loading the model and opening the device (the sea turtle's cold load-to-first-frame:
/// see `benchmarks/render.md`). Calling it is never required: the renderer computes what is
/// missing, or waits for a computation under way.
pub fn prepare_lighting_tables(studio: bool) {
    brdf_lut_texels();
    if studio {
        default_prefiltered_environment();
    }
}

/// [`prepare_lighting_tables`] on a new, detached thread. If the thread cannot be created the
/// renderer computes the tables itself when it needs them: nothing fails, it only starts later.
pub fn prepare_lighting_tables_in_background(studio: bool) {
    let _ = std::thread::Builder::new()
        .name("lighting tables".into())
        .spawn(move || prepare_lighting_tables(studio));
}

/// The generated studio's prefiltered levels, computed once per process: every renderer without
/// an environment of its own starts with them.
pub(super) fn default_prefiltered_environment() -> &'static [phantogram_assets::ibl::Environment] {
    static LEVELS: std::sync::OnceLock<Vec<phantogram_assets::ibl::Environment>> = std::sync::OnceLock::new();
    LEVELS.get_or_init(|| {
        phantogram_assets::ibl::prefiltered_levels(
            &phantogram_assets::ibl::Environment::studio(),
            PREFILTERED_BASE_WIDTH,
        )
    })
}

/// The lighting tables as `Rgba16Float` texels, `BRDF_LUT_SIZE` wide and
/// `LIGHTING_TABLES_HEIGHT` high, computed once per process (they depend on nothing). Above, the
/// round lobes' tables read at the same (n·v, roughness): the split sum (scale and bias on F0),
/// the sheen's directional albedo ([`phantogram_assets::ibl::sheen`]) and the round Ward lobe's
/// ([`phantogram_assets::ibl::ward_albedo`]). Below, the stretched lobes' tiles
/// ([`anisotropic_albedo`]): the stretched GGX lobe's split sum and the Ward lobe's albedo (the
/// fourth channel unused, 1). At the bottom, where the sheen's image light is read from
/// ([`sheen_direction`]).
pub(super) fn brdf_lut_texels() -> &'static [u8] {
    static TEXELS: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
    TEXELS.get_or_init(|| {
        let sheen = phantogram_assets::ibl::sheen_albedo_table(BRDF_LUT_SIZE);
        let ward = phantogram_assets::ibl::ward_albedo_table(BRDF_LUT_SIZE);
        let round = phantogram_assets::ibl::brdf_lut(BRDF_LUT_SIZE)
            .into_iter()
            .zip(sheen)
            .zip(ward)
            .map(|(([a, b], e), w)| [a, b, e, w]);
        let stretched = anisotropic_albedo::anisotropic_albedo_table()
            .into_iter()
            .map(|[a, b, w]| [a, b, w, 1.0]);
        round
            .chain(stretched)
            .chain(sheen_direction::sheen_direction_table())
            .flat_map(|texel| texel.map(half::f16::from_f32))
            .flat_map(|h| h.to_le_bytes())
            .collect()
    })
}

/// The GPU side of the specular image-based light.
pub(super) struct IblTextures {
    /// The prefiltered environment (a mip chain), and its view.
    pub(super) environment_texture: wgpu::Texture,
    pub(super) environment: wgpu::TextureView,
    pub(super) brdf_lut: wgpu::TextureView,
    pub(super) sampler: wgpu::Sampler,
}

impl IblTextures {
    /// Uploads `levels` (from [`phantogram_assets::ibl::prefiltered_levels`], a mip chain) and the BRDF table.
    pub(super) fn new(gpu: &Gpu, levels: &[phantogram_assets::ibl::Environment]) -> Self {
        let texture = prefiltered_texture(
            &gpu.device,
            levels[0].width as u32,
            levels[0].height as u32,
            levels.len() as u32,
            wgpu::TextureUsages::empty(),
        );
        for (k, level) in levels.iter().enumerate() {
            write_level(&gpu.queue, &texture, k as u32, level);
        }
        Self::with_texture(gpu, &texture)
    }

    /// The prefiltered environment `texture` (made by [`prefiltered_texture`] and filled) and the
    /// BRDF table.
    pub(super) fn with_texture(gpu: &Gpu, texture: &wgpu::Texture) -> Self {
        let (device, queue) = (&gpu.device, &gpu.queue);
        let lut = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("lighting tables"),
            size: wgpu::Extent3d {
                width: BRDF_LUT_SIZE as u32,
                height: LIGHTING_TABLES_HEIGHT as u32,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba16Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &lut,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            brdf_lut_texels(),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(8 * BRDF_LUT_SIZE as u32),
                rows_per_image: Some(LIGHTING_TABLES_HEIGHT as u32),
            },
            wgpu::Extent3d {
                width: BRDF_LUT_SIZE as u32,
                height: LIGHTING_TABLES_HEIGHT as u32,
                depth_or_array_layers: 1,
            },
        );
        // Azimuth wraps; the shader keeps the table's coordinates inside its texel centres.
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("environment"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        Self {
            environment_texture: texture.clone(),
            environment: texture.create_view(&Default::default()),
            brdf_lut: lut.create_view(&Default::default()),
            sampler,
        }
    }
}

/// An `Rgba16Float` texture for a prefiltered environment of `levels` mip levels, sampled by the
/// scene shader and written by uploads, plus `extra` uses (the GPU prefilter's storage writes).
pub(super) fn prefiltered_texture(
    device: &wgpu::Device,
    width: u32,
    height: u32,
    levels: u32,
    extra: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("prefiltered environment"),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: levels,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba16Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST | extra,
        view_formats: &[],
    })
}

/// Appends `level`'s texels as `Rgba16Float` rows of `row_bytes` bytes each (at least eight a
/// texel; zero-padded beyond), alpha 1.
///
/// A row at a time through `half`'s slice conversion, which uses the CPU's conversion
/// instructions eight values at a time where it has them (F16C, detected at run time; aarch64's
/// FP16): one `f16::from_f32` per value, each with its own feature check, took 1.1 ms of the
/// render thread's 2.5 ms for a GPU prefilter update at the 256-wide base here (2026-12-04).
pub(super) fn push_rgba16f_rows(bytes: &mut Vec<u8>, level: &phantogram_assets::ibl::Environment, row_bytes: u32) {
    use half::slice::HalfFloatSliceExt;
    let width = level.width.max(1);
    let row_bytes = row_bytes as usize;
    let (mut wide, mut narrow) = (vec![0.0f32; 4 * width], vec![half::f16::ZERO; 4 * width]);
    bytes.reserve(row_bytes * level.height);
    for row in level.texels.chunks_exact(width) {
        // f16 saturates at 65504: clamp so a very bright sun stays finite.
        for (w, t) in wide.chunks_exact_mut(4).zip(row) {
            w[0] = t[0].min(65_000.0);
            w[1] = t[1].min(65_000.0);
            w[2] = t[2].min(65_000.0);
            w[3] = 1.0;
        }
        narrow.convert_from_f32_slice(&wide);
        let start = bytes.len();
        let bits: &[u16] = narrow.reinterpret_cast();
        if cfg!(target_endian = "little") {
            bytes.extend_from_slice(bytemuck::cast_slice(bits));
        } else {
            bytes.extend(bits.iter().flat_map(|b| b.to_le_bytes()));
        }
        bytes.resize(start + row_bytes, 0);
    }
}

/// Writes `level` into mip `mip` of an `Rgba16Float` texture.
pub(super) fn write_level(
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    mip: u32,
    level: &phantogram_assets::ibl::Environment,
) {
    let mut bytes = Vec::with_capacity(8 * level.texels.len());
    push_rgba16f_rows(&mut bytes, level, 8 * level.width as u32);
    queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: mip,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        &bytes,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(8 * level.width as u32),
            rows_per_image: Some(level.height as u32),
        },
        wgpu::Extent3d {
            width: level.width as u32,
            height: level.height as u32,
            depth_or_array_layers: 1,
        },
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The row writer gives, value for value, `f16::from_f32` of each channel clamped at 65000
    /// and alpha 1, little-endian, each row zero-padded to its length (round to nearest even,
    /// subnormals, a sun past f16's range, infinity and NaN included).
    #[test]
    fn rows_of_f16_are_each_value_converted_clamped_and_padded() {
        let values = [
            0.0f32,
            1.0,
            0.1,
            1.0 / 3.0,
            2.0e-7,
            6.1e-5,
            1.0e5,
            65_000.0,
            65_519.0,
            f32::INFINITY,
            f32::NAN,
            -0.5,
            12.345,
        ];
        let texels: Vec<[f32; 3]> = (0..15)
            .map(|i| [0, 1, 2].map(|k| values[(3 * i + k) % values.len()]))
            .collect();
        let level = phantogram_assets::ibl::Environment {
            width: 5,
            height: 3,
            texels,
        };
        let row_bytes = 8 * 5 + 24;
        let mut bytes = vec![7u8];
        push_rgba16f_rows(&mut bytes, &level, row_bytes);
        let mut want = vec![7u8];
        for row in level.texels.chunks_exact(5) {
            let start = want.len();
            for t in row {
                for c in [t[0], t[1], t[2], 1.0] {
                    want.extend_from_slice(&half::f16::from_f32(c.min(65_000.0)).to_le_bytes());
                }
            }
            want.resize(start + row_bytes as usize, 0);
        }
        assert_eq!(bytes, want);
    }
}
