//! An image as a glTF file holds it, and its decoding to RGBA8: PNG or JPEG (core glTF), WebP
//! (`EXT_texture_webp`) or a KTX 2.0 texture with Basis Universal supercompression
//! (`KHR_texture_basisu`: ETC1S or UASTC, what gltfpack's `-tc` and glTF-Transform's `etc1s` /
//! `uastc` write).
//!
//! Two steps, so that the loader can charge every image to the budget before any is decoded:
//! [`Encoded::probe`] finds the codec and reads the size from the header alone, and
//! [`Encoded::decode`] decodes under limits that hold the decoder to that size (a damaged stream
//! that claims more fails instead of allocating).
//!
//! **Basis Universal** textures are transcoded by the `basisu` crate, a pure-Rust port of the
//! reference transcoder (its output byte-identical to the C++ one, so no C++ in the phone builds),
//! to RGBA8 like every other image: the renderer makes the mip chain itself. Where a texture is
//! larger than the device draws, the file's own mip level nearest above the fitted size is
//! transcoded instead of the base level. A KTX 2.0 file that is not Basis Universal (plain
//! `VK_FORMAT` data), a cube map or array, a video or an HDR texture is refused by name.
//! The file is also kept beside that copy (`super::gpu_blocks`), so that the renderer can
//! transcode it again to ASTC, BC7 or ETC2, whichever the device samples, and keep the texture
//! compressed on the GPU (a quarter of RGBA8's memory). That needs the file's own mips down to
//! 1 × 1 and a size in whole 4 × 4 blocks; other files are drawn from the RGBA8 copy.
//!
//! **Panics**: none escape; a decoder that panics on damaged data becomes that image's error
//! (the transcoder does on some: a million mutated copies of the test textures found a slice
//! index out of range in its key/value reader, caught here, and no abort or hang once the level
//! lengths are checked first, [`check_level_claims`]).
//! **Threading**: no shared state; the loader decodes its images on every core, one per call.

use crate::budget::ResourceBudget;

/// The 12 bytes every KTX 2.0 file starts with (KTX 2.0 specification, section 3.1).
const KTX2_IDENTIFIER: [u8; 12] = [0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A];

/// The codec of an image, found from its bytes (not from the file's `mimeType`, which the data
/// must agree with anyway).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Codec {
    /// PNG, JPEG or WebP, decoded by the `image` crate.
    Raster(image::ImageFormat),
    /// KTX 2.0 with Basis Universal (ETC1S or UASTC) payload.
    Basis,
}

/// An image's codec and its size in texels, read from its header.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Encoded {
    pub codec: Codec,
    pub width: u32,
    pub height: u32,
}

impl Encoded {
    /// The codec and size of `raw`, from its header (for a Basis texture, its level index and
    /// codebooks, bounded by the file's own size). The error says what the data is instead.
    pub fn probe(raw: &[u8]) -> Result<Encoded, String> {
        if raw.starts_with(&KTX2_IDENTIFIER) {
            let basis = open_basis(raw)?;
            let (width, height) = basis.base_dimensions();
            if width == 0 || height == 0 {
                return Err(format!("a KTX 2.0 texture of {width}×{height} texels"));
            }
            return Ok(Encoded {
                codec: Codec::Basis,
                width,
                height,
            });
        }
        let format = match image::guess_format(raw) {
            Ok(format @ (image::ImageFormat::Png | image::ImageFormat::Jpeg | image::ImageFormat::WebP)) => format,
            Ok(other) => {
                return Err(format!(
                    "{other:?} data; glTF images must be PNG, JPEG, WebP or KTX 2.0 (Basis Universal)"
                ));
            }
            Err(_) => return Err("neither PNG, JPEG, WebP nor KTX 2.0 data".to_owned()),
        };
        let (width, height) = image::ImageReader::with_format(std::io::Cursor::new(raw), format)
            .into_dimensions()
            .map_err(|e| e.to_string())?;
        Ok(Encoded {
            codec: Codec::Raster(format),
            width,
            height,
        })
    }

    /// Decodes `raw` (the bytes [`Encoded::probe`] read) to RGBA8 at `fitted` texels (the size
    /// the budget allows, at most the probed one), using at most `max_bytes` of memory.
    pub fn decode(&self, raw: &[u8], fitted: (u32, u32), max_bytes: u64) -> Result<image::RgbaImage, String> {
        self.decode_with_level(raw, fitted, max_bytes).map(|(image, _)| image)
    }

    /// [`Encoded::decode`], and for a Basis Universal texture whose texels are one of the file's
    /// levels as it holds it (not scaled further), that level's index (`super::gpu_blocks`).
    pub fn decode_with_level(
        &self,
        raw: &[u8],
        fitted: (u32, u32),
        max_bytes: u64,
    ) -> Result<(image::RgbaImage, Option<u32>), String> {
        // A decoder panic on a damaged image is this file's error, not the app's end.
        let (decoded, level) = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| match self.codec {
            Codec::Raster(format) => self.decode_raster(raw, format, max_bytes).map(|i| (i, None)),
            Codec::Basis => self.decode_basis(raw, fitted).map(|(i, level)| (i, Some(level))),
        }))
        .map_err(|_| "the decoder failed on damaged data".to_owned())??;
        // Larger than the device's textures: scaled down (a triangle filter averages the texels
        // each new one covers).
        Ok(if (decoded.width(), decoded.height()) == fitted {
            (decoded, level)
        } else {
            let scaled = image::imageops::resize(&decoded, fitted.0, fitted.1, image::imageops::FilterType::Triangle);
            (scaled, None)
        })
    }

    /// What the user is told when the image is drawn at `fitted`, smaller than it is (`what`
    /// names it); `None` at its own size.
    pub fn scaled_down_note(&self, what: &str, fitted: (u32, u32)) -> Option<String> {
        (fitted != (self.width, self.height)).then(|| {
            format!(
                "{what} ({}×{}) scaled down to {}×{}, the largest texture this device draws",
                self.width, self.height, fitted.0, fitted.1
            )
        })
    }

    fn decode_raster(
        &self,
        raw: &[u8],
        format: image::ImageFormat,
        max_bytes: u64,
    ) -> Result<image::RgbaImage, String> {
        let mut reader = image::ImageReader::with_format(std::io::Cursor::new(raw), format);
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(self.width);
        limits.max_image_height = Some(self.height);
        limits.max_alloc = Some(
            ResourceBudget::texture_bytes(self.width, self.height)
                .saturating_mul(2)
                .min(max_bytes),
        );
        reader.limits(limits);
        reader
            .decode()
            .map(|decoded| decoded.into_rgba8())
            .map_err(|e| e.to_string())
    }

    /// The smallest of the file's levels that covers `fitted` (the base level unless the budget
    /// scaled the texture down and the file carries mips), transcoded to RGBA8, and its index.
    fn decode_basis(&self, raw: &[u8], fitted: (u32, u32)) -> Result<(image::RgbaImage, u32), String> {
        let basis = open_basis(raw)?;
        let mut level = 0;
        let (mut width, mut height) = (self.width, self.height);
        for next in 1..basis.level_count() {
            let Ok(info) = basis.image_level_info(next) else { break };
            if info.width < fitted.0 || info.height < fitted.1 {
                break;
            }
            (level, width, height) = (next, info.width, info.height);
        }
        let rgba = basis
            .transcode(level, basisu::TargetFormat::Rgba32, basisu::DecodeFlags::NONE)
            .map_err(|e| format!("Basis Universal level {level}: {e:?}"))?;
        image::RgbaImage::from_raw(width, height, rgba)
            .map(|image| (image, level))
            .ok_or_else(|| format!("Basis Universal level {level} is not the {width}×{height} texels its header says"))
    }
}

/// Opens a KTX 2.0 file as a Basis Universal texture a material can use: 2D, one image, a codec
/// that transcodes to 8-bit RGBA.
pub(super) fn open_basis(raw: &[u8]) -> Result<basisu::Transcoder<'_>, String> {
    check_level_claims(raw)?;
    let basis = std::panic::catch_unwind(|| basisu::Transcoder::new(raw))
        .map_err(|_| "the KTX 2.0 reader failed on damaged data".to_owned())?
        .map_err(|e| match e {
            basisu::Error::InvalidData => {
                "a KTX 2.0 texture that is not Basis Universal (ETC1S or UASTC), or is damaged".to_owned()
            }
            other => format!("KTX 2.0 texture: {other:?}"),
        })?;
    if basis.is_video() {
        return Err("a Basis Universal video, not a texture".to_owned());
    }
    if basis.layer_count() > 1 || basis.face_count() > 1 {
        return Err(format!(
            "a KTX 2.0 texture of {} layers and {} faces; a glTF material's texture is one 2D image",
            basis.layer_count(),
            basis.face_count()
        ));
    }
    if !basis.supports(basisu::TargetFormat::Rgba32) {
        return Err(format!(
            "a {:?} texture (high dynamic range); a glTF material's textures are 8-bit",
            basis.source_format()
        ));
    }
    Ok(basis)
}

/// Refuses a KTX 2.0 file whose level index claims more uncompressed bytes for a level than an
/// RGBA8 image of that level's size: the transcoder allocates a Zstandard level at the length
/// its index claims before inflating it (a damaged file claimed 1.4 PB and aborted the process),
/// and no 8-bit Basis payload is larger than its RGBA8 image (UASTC is a quarter of it). The
/// budget has charged the RGBA8 base level already, so this holds every level to what is charged.
fn check_level_claims(raw: &[u8]) -> Result<(), String> {
    // KTX 2.0 specification, section 3: the header's fields are little-endian words at fixed
    // offsets, the level index follows at byte 80, 24 bytes a level.
    let word = |at: usize| -> Option<u64> {
        let bytes = raw.get(at..at + 4)?;
        Some(u64::from(u32::from_le_bytes(bytes.try_into().ok()?)))
    };
    let long = |at: usize| -> Option<u64> { Some(u64::from_le_bytes(raw.get(at..at + 8)?.try_into().ok()?)) };
    let truncated = || "a KTX 2.0 texture cut short in its header".to_owned();
    let (width, height, levels) = (
        word(20).ok_or_else(truncated)?,
        word(24).ok_or_else(truncated)?,
        word(40).ok_or_else(truncated)?.max(1),
    );
    for level in 0..levels.min(64) {
        let Some(claimed) = usize::try_from(80 + 24 * level + 16).ok().and_then(long) else {
            return Err(truncated());
        };
        // A level's texels, rounded up to whole 4 × 4 blocks, as 4 bytes each.
        let side = |texels: u64| (texels >> level).max(1).div_ceil(4) * 4;
        let rgba8 = side(width).saturating_mul(side(height)).saturating_mul(4);
        if claimed > rgba8 {
            return Err(format!(
                "KTX 2.0 level {level} claims {claimed} bytes uncompressed, more than its {}×{} texels take as RGBA8",
                (width >> level).max(1),
                (height >> level).max(1)
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn data_of_no_image_format_is_named() {
        let error = Encoded::probe(b"not an image at all").unwrap_err();
        assert!(error.contains("neither PNG"), "{error}");
    }

    #[test]
    fn a_ktx2_file_that_is_not_basis_universal_is_refused_by_name() {
        // A KTX 2.0 header of a plain VK_FORMAT_R8G8B8A8_UNORM (37) 4×4 texture, no levels.
        let mut raw = KTX2_IDENTIFIER.to_vec();
        for word in [37u32, 1, 4, 4, 0, 0, 1, 1, 0] {
            raw.extend_from_slice(&word.to_le_bytes());
        }
        // The rest of the index, one empty level and an empty data format descriptor.
        raw.resize(200, 0);
        let error = Encoded::probe(&raw).unwrap_err();
        assert!(error.contains("not Basis Universal"), "{error}");
    }

    /// The reference encoder's 64×64 ETC1S file with its 7 mip levels (`tests/data/ktx2`).
    const ETC1S: &[u8] = include_bytes!("../../tests/data/ktx2/pattern-rgba-etc1s.ktx2");

    fn level(raw: &[u8], level: u32) -> Vec<u8> {
        basisu::Transcoder::new(raw)
            .and_then(|t| t.transcode(level, basisu::TargetFormat::Rgba32, basisu::DecodeFlags::NONE))
            .expect("the fixture transcodes")
    }

    #[test]
    fn a_texture_fitted_to_a_mip_level_of_the_file_is_that_level() {
        let encoded = Encoded::probe(ETC1S).expect("probe");
        assert_eq!(
            encoded,
            Encoded {
                codec: Codec::Basis,
                width: 64,
                height: 64
            }
        );
        for (fitted, expected_level) in [((64, 64), 0), ((32, 32), 1), ((16, 16), 2)] {
            let decoded = encoded.decode(ETC1S, fitted, u64::MAX).expect("decode");
            assert_eq!(decoded.dimensions(), fitted);
            assert_eq!(decoded.into_raw(), level(ETC1S, expected_level), "{fitted:?}");
        }
    }

    #[test]
    fn a_texture_fitted_between_levels_is_scaled_from_the_level_above() {
        let encoded = Encoded::probe(ETC1S).expect("probe");
        let decoded = encoded.decode(ETC1S, (24, 24), u64::MAX).expect("decode");
        let above = image::RgbaImage::from_raw(32, 32, level(ETC1S, 1)).expect("level 1");
        let expected = image::imageops::resize(&above, 24, 24, image::imageops::FilterType::Triangle);
        assert_eq!(decoded, expected);
    }

    #[test]
    fn a_level_claiming_more_than_its_texels_is_refused_before_it_is_inflated() {
        // The UASTC fixture (64 × 48, one Zstandard level) with its level's uncompressed length
        // raised from 64 × 48 bytes to one byte over the level's RGBA8 size, then to 2^50.
        let uastc: &[u8] = include_bytes!("../../tests/data/ktx2/pattern-rgb-uastc.ktx2");
        assert!(Encoded::probe(uastc).is_ok());
        for claimed in [64 * 48 * 4 + 1, 1u64 << 50] {
            let mut raw = uastc.to_vec();
            raw[96..104].copy_from_slice(&claimed.to_le_bytes());
            let error = Encoded::probe(&raw).unwrap_err();
            assert!(error.contains("claims"), "{claimed}: {error}");
        }
    }

    #[test]
    fn a_truncated_ktx2_identifier_is_not_taken_for_one() {
        let error = Encoded::probe(&KTX2_IDENTIFIER[..8]).unwrap_err();
        assert!(error.contains("neither PNG"), "{error}");
    }
}
