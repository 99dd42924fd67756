//! A photograph from outside, read upright: the face evaluation's input.
//!
//! Phones store a portrait photo as the sensor saw it (landscape) and say in the EXIF
//! `Orientation` tag how to turn it for display; every photo viewer does. The face networks
//! look for upright faces, so a photo read without that turn shows its faces lying on their
//! side, where the detector finds none. [`open_photo`] applies the tag (all eight values,
//! the mirrored ones included) before anything else sees the pixels, so eye positions are
//! reported in the picture as a person sees it.
//!
//! It also reads the 35 mm-equivalent focal length (EXIF tag 0xA405) when the photo has one:
//! the distance to a face depends on it. Turning the picture does not change it (it refers
//! to the long side).
//!
//! Panics: none on any input; a damaged EXIF block gives no turn and no focal length, as if
//! absent. Only PNG, JPEG and WebP are read (the HDR and EXR decoders are built in for
//! environments). A header claiming more than `image`'s default limit (512 MiB decoded) is
//! refused before anything is allocated for it.

use std::path::Path;

use image::metadata::Orientation;
use image::{ImageDecoder, ImageFormat, RgbaImage};

/// A photo's pixels turned upright, and its camera's focal length when the file states it.
#[derive(Debug)]
pub struct Photo {
    pub rgba: RgbaImage,
    /// FocalLengthIn35mmFilm from the EXIF: the focal length a 36 × 24 mm frame would need for
    /// the same field of view across the long side.
    pub focal_35mm: Option<f32>,
    /// The turn the file asked for and that was applied ([`Orientation::NoTransforms`] when
    /// none).
    pub orientation: Orientation,
}

/// Why a photo could not be read.
#[derive(Debug, thiserror::Error)]
pub enum PhotoError {
    #[error("{0}")]
    Io(#[from] std::io::Error),
    #[error("not a PNG, JPEG or WebP photo ({0})")]
    NotAPhoto(String),
    #[error("{width}×{height} pixels is more than this tool decodes (512 MiB)")]
    TooLarge { width: u32, height: u32 },
    #[error("{0}")]
    Decode(#[from] image::ImageError),
}

/// Reads a PNG, JPEG or WebP photo upright (its EXIF orientation applied) as RGBA8.
pub fn open_photo(path: &Path) -> Result<Photo, PhotoError> {
    // Regular files only: a pipe would block, a device never end.
    let file = phantogram_files::open_regular_file(path)?;
    let reader = image::ImageReader::new(std::io::BufReader::new(file)).with_guessed_format()?;
    match reader.format() {
        Some(ImageFormat::Png | ImageFormat::Jpeg | ImageFormat::WebP) => {}
        other => {
            return Err(PhotoError::NotAPhoto(
                other.map_or("unrecognised data".to_owned(), |f| format!("{f:?}")),
            ));
        }
    }
    let mut decoder = reader.into_decoder()?;
    // `into_decoder` skips the memory limit `decode` applies: a header claiming 60000 × 60000
    // pixels would otherwise abort on a 14 GB allocation.
    if image::Limits::default().reserve(decoder.total_bytes()).is_err() {
        let (width, height) = decoder.dimensions();
        return Err(PhotoError::TooLarge { width, height });
    }
    let exif = decoder.exif_metadata().ok().flatten();
    let focal_35mm = exif.as_deref().and_then(focal_length_35mm);
    let orientation = exif.as_deref().map_or(Orientation::NoTransforms, orientation_of);
    let mut image = image::DynamicImage::from_decoder(decoder)?;
    image.apply_orientation(orientation);
    Ok(Photo {
        rgba: image.to_rgba8(),
        focal_35mm,
        orientation,
    })
}

/// The EXIF block's Orientation (tag 0x0112 in IFD0); none, or a value outside 1–8, is no
/// turn. `image`'s own reader wants the block without the "Exif\0\0" prefix some files keep.
fn orientation_of(exif: &[u8]) -> Orientation {
    let tiff = exif.strip_prefix(b"Exif\0\0").unwrap_or(exif);
    Orientation::from_exif_chunk(tiff).unwrap_or(Orientation::NoTransforms)
}

/// FocalLengthIn35mmFilm from a TIFF-structured EXIF block (optionally after "Exif\0\0").
/// Every offset is checked: a malformed block gives `None`.
fn focal_length_35mm(exif: &[u8]) -> Option<f32> {
    let tiff = exif.strip_prefix(b"Exif\0\0").unwrap_or(exif);
    let little = match tiff.get(0..2)? {
        b"II" => true,
        b"MM" => false,
        _ => return None,
    };
    let u16_at = |o: usize| -> Option<u16> {
        let b: [u8; 2] = tiff.get(o..o.checked_add(2)?)?.try_into().ok()?;
        Some(if little {
            u16::from_le_bytes(b)
        } else {
            u16::from_be_bytes(b)
        })
    };
    let u32_at = |o: usize| -> Option<u32> {
        let b: [u8; 4] = tiff.get(o..o.checked_add(4)?)?.try_into().ok()?;
        Some(if little {
            u32::from_le_bytes(b)
        } else {
            u32::from_be_bytes(b)
        })
    };
    // The value of `tag` in the IFD at `ifd`, as the entry's offset.
    let find = |ifd: usize, tag: u16| -> Option<usize> {
        let n = usize::from(u16_at(ifd)?);
        (0..n.min(512))
            .map(|i| ifd + 2 + 12 * i)
            .find(|&e| u16_at(e) == Some(tag))
    };
    let ifd0 = u32_at(4)? as usize;
    let exif_ifd = u32_at(find(ifd0, 0x8769)? + 8)? as usize;
    let entry = find(exif_ifd, 0xA405)?;
    // SHORT (type 3), count 1: the value sits in the entry itself.
    if u16_at(entry + 2)? != 3 {
        return None;
    }
    let f = u16_at(entry + 8)?;
    (f > 0).then_some(f32::from(f))
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::ImageEncoder as _;

    /// A TIFF-structured EXIF block, little- or big-endian: IFD0 with Orientation (when given)
    /// and a pointer to an Exif IFD holding FocalLengthIn35mmFilm (when given). Built by hand
    /// from the TIFF 6.0 layout, not by the code under test.
    fn block(little: bool, orientation: Option<u16>, focal: Option<u16>) -> Vec<u8> {
        let w16 = |v: u16| if little { v.to_le_bytes() } else { v.to_be_bytes() };
        let w32 = |v: u32| if little { v.to_le_bytes() } else { v.to_be_bytes() };
        let n0 = u16::from(orientation.is_some()) + u16::from(focal.is_some());
        let exif_ifd = 8 + 2 + 12 * u32::from(n0) + 4;
        let mut b = Vec::new();
        b.extend_from_slice(if little { b"II" } else { b"MM" });
        b.extend_from_slice(&w16(42));
        b.extend_from_slice(&w32(8)); // IFD0 at 8
        b.extend_from_slice(&w16(n0));
        if let Some(o) = orientation {
            b.extend_from_slice(&w16(0x0112));
            b.extend_from_slice(&w16(3)); // SHORT
            b.extend_from_slice(&w32(1));
            b.extend_from_slice(&w16(o));
            b.extend_from_slice(&w16(0));
        }
        if focal.is_some() {
            b.extend_from_slice(&w16(0x8769)); // the Exif IFD pointer
            b.extend_from_slice(&w16(4)); // LONG
            b.extend_from_slice(&w32(1));
            b.extend_from_slice(&w32(exif_ifd));
        }
        b.extend_from_slice(&w32(0)); // no next IFD
        if let Some(f) = focal {
            b.extend_from_slice(&w16(1));
            b.extend_from_slice(&w16(0xA405));
            b.extend_from_slice(&w16(3)); // SHORT
            b.extend_from_slice(&w32(1));
            b.extend_from_slice(&w16(f));
            b.extend_from_slice(&w16(0));
            b.extend_from_slice(&w32(0));
        }
        b
    }

    /// An upright test picture, 5 × 3, every pixel a different colour.
    const W: u32 = 5;
    const H: u32 = 3;
    fn upright() -> RgbaImage {
        RgbaImage::from_fn(W, H, |x, y| image::Rgba([40 * x as u8, 80 * y as u8, 7, 255]))
    }

    /// Where upright pixel (x, y) lies in the file stored with EXIF orientation `o`, from the
    /// tag's definition (which stored row and column are the picture's top and left).
    fn stored_at(o: u16, x: u32, y: u32) -> (u32, u32) {
        match o {
            1 => (x, y),
            2 => (W - 1 - x, y),
            3 => (W - 1 - x, H - 1 - y),
            4 => (x, H - 1 - y),
            5 => (y, x),
            6 => (y, W - 1 - x),
            7 => (H - 1 - y, W - 1 - x),
            8 => (H - 1 - y, x),
            _ => unreachable!(),
        }
    }

    /// The upright picture as a camera with orientation `o` would have stored it.
    fn stored(o: u16) -> RgbaImage {
        let (sw, sh) = if o >= 5 { (H, W) } else { (W, H) };
        let up = upright();
        let mut s = RgbaImage::new(sw, sh);
        for y in 0..H {
            for x in 0..W {
                let (sx, sy) = stored_at(o, x, y);
                s.put_pixel(sx, sy, *up.get_pixel(x, y));
            }
        }
        s
    }

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("phantogram-photo-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    fn write_png(path: &Path, img: &RgbaImage, exif: Option<Vec<u8>>) {
        let file = std::fs::File::create(path).unwrap();
        let mut enc = image::codecs::png::PngEncoder::new(file);
        if let Some(e) = exif {
            enc.set_exif_metadata(e).unwrap();
        }
        enc.write_image(img.as_raw(), img.width(), img.height(), image::ExtendedColorType::Rgba8)
            .unwrap();
    }

    #[test]
    fn every_exif_orientation_is_turned_upright() {
        for o in 1..=8u16 {
            for little in [true, false] {
                let path = scratch(&format!("o{o}-{little}.png"));
                write_png(&path, &stored(o), Some(block(little, Some(o), None)));
                let photo = open_photo(&path).unwrap();
                assert_eq!(photo.orientation.to_exif(), o as u8);
                assert_eq!(photo.rgba.dimensions(), (W, H), "orientation {o}");
                assert!(photo.rgba == upright(), "orientation {o}, little-endian {little}");
                assert_eq!(photo.focal_35mm, None);
            }
        }
        // No EXIF, and an orientation outside 1–8: the pixels as stored.
        for (name, exif) in [("none.png", None), ("nine.png", Some(block(true, Some(9), None)))] {
            let path = scratch(name);
            write_png(&path, &upright(), exif);
            let photo = open_photo(&path).unwrap();
            assert_eq!(photo.orientation, Orientation::NoTransforms);
            assert!(photo.rgba == upright());
        }
    }

    /// WebP (some phones' and messengers' format) carries EXIF too.
    #[test]
    fn a_webp_photo_is_turned_upright_too() {
        let path = scratch("o8.webp");
        let file = std::fs::File::create(&path).unwrap();
        let mut enc = image::codecs::webp::WebPEncoder::new_lossless(file);
        enc.set_exif_metadata(block(true, Some(8), None)).unwrap();
        let img = stored(8);
        enc.write_image(img.as_raw(), img.width(), img.height(), image::ExtendedColorType::Rgba8)
            .unwrap();
        let photo = open_photo(&path).unwrap();
        assert_eq!(photo.orientation, Orientation::Rotate270);
        assert!(photo.rgba == upright());
    }

    #[test]
    fn a_portrait_jpeg_from_a_phone_is_read_upright_with_its_focal_length() {
        // Large flat blocks so that JPEG's loss cannot swap them: a red top half and a blue
        // bottom half, stored turned as a phone held upright stores it (orientation 6).
        let (w, h) = (32u32, 48u32);
        let up = RgbaImage::from_fn(w, h, |_, y| {
            if y < h / 2 {
                image::Rgba([220, 20, 20, 255])
            } else {
                image::Rgba([20, 20, 220, 255])
            }
        });
        let turned = image::imageops::rotate270(&up); // stored: displayed after a 90° CW turn
        let path = scratch("portrait.jpg");
        let file = std::fs::File::create(&path).unwrap();
        let mut enc = image::codecs::jpeg::JpegEncoder::new_with_quality(file, 95);
        enc.set_exif_metadata(block(false, Some(6), Some(26))).unwrap();
        let rgb = image::DynamicImage::ImageRgba8(turned).to_rgb8();
        enc.write_image(rgb.as_raw(), rgb.width(), rgb.height(), image::ExtendedColorType::Rgb8)
            .unwrap();
        let photo = open_photo(&path).unwrap();
        assert_eq!(photo.rgba.dimensions(), (w, h));
        assert_eq!(photo.orientation, Orientation::Rotate90);
        assert_eq!(photo.focal_35mm, Some(26.0));
        let top = photo.rgba.get_pixel(w / 2, 4);
        let bottom = photo.rgba.get_pixel(w / 2, h - 4);
        assert!(top[0] > 180 && top[2] < 60, "{top:?}");
        assert!(bottom[2] > 180 && bottom[0] < 60, "{bottom:?}");
    }

    #[test]
    fn reads_the_35mm_focal_length_in_both_byte_orders_and_survives_garbage() {
        assert_eq!(focal_length_35mm(&block(true, None, Some(26))), Some(26.0));
        assert_eq!(focal_length_35mm(&block(false, Some(6), Some(28))), Some(28.0));
        let mut prefixed = b"Exif\0\0".to_vec();
        prefixed.extend(block(true, None, Some(24)));
        assert_eq!(focal_length_35mm(&prefixed), Some(24.0));
        // Truncated anywhere before the value's last byte (offset 38), and pointers past the
        // end: no panic, no value; the same block read for its orientation: no turn.
        let full = block(true, None, Some(26));
        for n in 0..38 {
            assert_eq!(focal_length_35mm(&full[..n]), None, "truncated at {n}");
            assert_eq!(orientation_of(&full[..n]), Orientation::NoTransforms);
        }
        let mut bad = full.clone();
        bad[4] = 0xFF;
        assert_eq!(focal_length_35mm(&bad), None);
        assert_eq!(focal_length_35mm(&block(true, None, Some(0))), None);
        // The orientation behind the "Exif\0\0" prefix some writers keep.
        let mut prefixed = b"Exif\0\0".to_vec();
        prefixed.extend(block(false, Some(8), None));
        assert_eq!(orientation_of(&prefixed), Orientation::Rotate270);
    }

    #[test]
    fn what_is_not_a_photo_is_refused_by_name() {
        let path = scratch("env.hdr");
        std::fs::write(&path, b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 1\n\0\0\0\0").unwrap();
        let e = open_photo(&path).unwrap_err();
        assert!(matches!(e, PhotoError::NotAPhoto(_)), "{e}");
        assert!(e.to_string().contains("not a PNG, JPEG or WebP"), "{e}");
        let e = open_photo(&std::env::temp_dir()).unwrap_err();
        assert!(matches!(e, PhotoError::Io(_)), "{e}");
    }
}
