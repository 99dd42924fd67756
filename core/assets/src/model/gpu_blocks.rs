//! A Basis Universal texture transcoded once more, to a block-compressed format the GPU samples
//! directly: ASTC 4×4 (the phones' GPUs), BC7 (desktop GPUs, and Mesa's software Vulkan) or ETC2
//! (every OpenGL ES 3.0 GPU). Each is 16 bytes per 4 × 4 texels, a quarter of RGBA8's memory
//! on the GPU. Basis Universal exists for this: a file encoded once is transcoded at load time to
//! whatever the device samples, without encoding anything.
//!
//! The loader keeps the KTX 2.0 file beside the RGBA8 copy it decoded ([`BasisSource`], charged
//! to the budget) when that copy is one of the file's own levels; the renderer asks
//! [`BasisSource::blocks`] for the format its device has and falls back to the RGBA8 copy (with
//! mips it builds itself) where there is none, or where the file cannot give a whole mip chain in
//! whole blocks (`None`).
//!
//! **Panics**: none escape (the transcoder's are caught, as in the loader). **Threading**: no
//! shared state; the renderer transcodes its textures on every core.

use std::sync::Arc;

use super::encoded_image::open_basis;

/// A block-compressed format a GPU samples, each 4 × 4 texels in 16 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlockFormat {
    /// ASTC 4 × 4, LDR. From UASTC a copy of the file's blocks (lossless).
    Astc4x4,
    /// BC7. From UASTC nearly lossless.
    Bc7,
    /// ETC2 RGBA8 (ETC1 colour with EAC alpha). From ETC1S lossless.
    Etc2Rgba8,
}

impl BlockFormat {
    /// Bytes of one 4 × 4 block.
    pub const BLOCK_BYTES: usize = 16;

    fn target(self) -> basisu::TargetFormat {
        match self {
            BlockFormat::Astc4x4 => basisu::TargetFormat::Astc4x4Rgba,
            BlockFormat::Bc7 => basisu::TargetFormat::Bc7Rgba,
            BlockFormat::Etc2Rgba8 => basisu::TargetFormat::Etc2Rgba,
        }
    }
}

/// One mip level in blocks.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BlockLevel {
    /// The level's size in texels (its blocks cover it rounded up to whole blocks).
    pub width: u32,
    pub height: u32,
    /// Rows of blocks, top first, [`BlockFormat::BLOCK_BYTES`] each.
    pub blocks: Vec<u8>,
}

/// The Basis Universal texture (a KTX 2.0 file) that an [`super::Image`]'s texels were
/// transcoded from.
#[derive(Clone, Debug, PartialEq)]
pub struct BasisSource {
    /// The whole KTX 2.0 file.
    pub ktx2: Arc<[u8]>,
    /// The file's level that the image's texels are: the base level, unless the budget scaled the
    /// texture down and the file had a level of that size.
    pub level: u32,
}

impl BasisSource {
    /// The image's texels and every smaller level down to 1 × 1, in `format`; `None` where the
    /// file lacks some of those levels (a texture without mips), where the image's size is not
    /// whole blocks (the GPU requires it of a block-compressed texture's first level), or where
    /// transcoding fails. Then the RGBA8 copy is what the GPU gets.
    pub fn blocks(&self, format: BlockFormat) -> Option<Vec<BlockLevel>> {
        std::panic::catch_unwind(|| self.try_blocks(format)).ok().flatten()
    }

    fn try_blocks(&self, format: BlockFormat) -> Option<Vec<BlockLevel>> {
        let basis = open_basis(&self.ktx2).ok()?;
        if !basis.supports(format.target()) {
            return None;
        }
        let first = basis.image_level_info(self.level).ok()?;
        if first.width % 4 != 0 || first.height % 4 != 0 {
            return None;
        }
        let mut levels = Vec::new();
        let (mut width, mut height) = (first.width, first.height);
        for level in self.level.. {
            if level >= basis.level_count() {
                return None; // the chain stops before 1 × 1
            }
            let info = basis.image_level_info(level).ok()?;
            if (info.width, info.height) != (width, height) {
                return None;
            }
            let blocks = basis
                .transcode(level, format.target(), basisu::DecodeFlags::NONE)
                .ok()?;
            let expected = width.div_ceil(4) as usize * height.div_ceil(4) as usize * BlockFormat::BLOCK_BYTES;
            if blocks.len() != expected {
                return None;
            }
            levels.push(BlockLevel { width, height, blocks });
            if (width, height) == (1, 1) {
                return Some(levels);
            }
            (width, height) = ((width / 2).max(1), (height / 2).max(1));
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ETC1S: &[u8] = include_bytes!("../../tests/data/ktx2/pattern-rgba-etc1s.ktx2");
    const UASTC: &[u8] = include_bytes!("../../tests/data/ktx2/pattern-rgb-uastc.ktx2");

    fn source(ktx2: &[u8], level: u32) -> BasisSource {
        BasisSource {
            ktx2: Arc::from(ktx2),
            level,
        }
    }

    #[test]
    fn a_file_with_its_mips_gives_every_level_in_each_format() {
        for format in [BlockFormat::Astc4x4, BlockFormat::Bc7, BlockFormat::Etc2Rgba8] {
            let levels = source(ETC1S, 0).blocks(format).expect("the 64² fixture has 7 levels");
            let sizes: Vec<(u32, u32)> = levels.iter().map(|l| (l.width, l.height)).collect();
            assert_eq!(
                sizes,
                [(64, 64), (32, 32), (16, 16), (8, 8), (4, 4), (2, 2), (1, 1)],
                "{format:?}"
            );
            // 16 bytes a block, a level smaller than a block in one.
            assert_eq!(levels[0].blocks.len(), 16 * 16 * 16);
            assert_eq!(levels[6].blocks.len(), 16);
        }
        // From a level further down (the texture was scaled down to it).
        let levels = source(ETC1S, 2).blocks(BlockFormat::Bc7).expect("levels 2-6");
        assert_eq!((levels[0].width, levels.len()), (16, 5));
    }

    #[test]
    fn a_file_without_mips_or_a_level_not_in_whole_blocks_gives_none() {
        // The UASTC fixture is one 64 × 48 level.
        assert_eq!(source(UASTC, 0).blocks(BlockFormat::Bc7), None);
        // Level 5 of the ETC1S fixture is 2 × 2.
        assert_eq!(source(ETC1S, 5).blocks(BlockFormat::Bc7), None);
        // Damaged data: none, no panic.
        let mut damaged = ETC1S.to_vec();
        for b in damaged.iter_mut().skip(200).step_by(7) {
            *b ^= 0x5a;
        }
        assert_eq!(source(&damaged, 0).blocks(BlockFormat::Astc4x4), None);
        assert_eq!(source(ETC1S, 9).blocks(BlockFormat::Astc4x4), None);
    }
}
