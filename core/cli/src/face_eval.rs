//! `phantogram eval face IMAGE…`: faces, eye centres and distances in still images.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::output::outln;
use phantogram::face::{CameraFrame, FaceModels, Intrinsics, UprightImage};

pub struct EvalFaceArgs<'a> {
    pub images: &'a [PathBuf],
    pub json: bool,
    pub hfov_deg: f32,
    pub models: Option<&'a Path>,
}

pub fn eval_face_command(args: EvalFaceArgs) -> Result<()> {
    let dir = match args.models {
        Some(d) => d.to_path_buf(),
        None => FaceModels::default_dir().context("no models folder: pass --models or set PHANTOGRAM_MODELS")?,
    };
    let models = FaceModels::load(&dir)?;
    if !args.json {
        outln!(
            "# distances assume an 11.7 mm iris and, where the image's EXIF gives no 35 mm-equivalent focal length, a {:.0}° horizontal field of view (--hfov-deg)",
            args.hfov_deg
        );
    }
    let mut failures = 0usize;
    for path in args.images {
        let (image, focal_35mm) = match open_with_exif_focal(path) {
            Ok(v) => v,
            Err(e) => {
                // One unreadable image does not stop the others; the exit status reports it.
                eprintln!("error: {}: {e}", path.display());
                failures += 1;
                continue;
            }
        };
        let (w, h) = image.dimensions();
        // The image's own 35 mm-equivalent focal length when its EXIF has one (36 mm across the
        // long side), else the stated field of view across the width.
        let intrinsics = match focal_35mm {
            Some(f35) => {
                let f_px = w.max(h) as f32 * f35 / 36.0;
                Intrinsics {
                    fx_px: f_px,
                    fy_px: f_px,
                    cx_px: w as f32 * 0.5,
                    cy_px: h as f32 * 0.5,
                }
            }
            None => Intrinsics::from_horizontal_fov(w, h, args.hfov_deg.to_radians()),
        };
        let frame = CameraFrame::upright_rgba(w, h, image.as_raw(), intrinsics);
        let upright = UprightImage::new(frame)?;
        let faces = models.find_faces(&upright)?;
        if args.json {
            let faces: Vec<serde_json::Value> = faces
                .iter()
                .map(|f| {
                    // A photo's subject faces the camera: the image's right eye is the viewer's left.
                    let glasses = f.lenses.map(|l| {
                        let seen = l.seen(false);
                        serde_json::json!({
                            "left": seen.left.name(),
                            "right": seen.right.name(),
                            "swapped": seen.swapped(),
                            "strength": seen.strength,
                        })
                    });
                    let ipd = f.ipd_for_distance(None);
                    serde_json::json!({
                        "left_eye": [f.left_eye_px.x, f.left_eye_px.y],
                        "right_eye": [f.right_eye_px.x, f.right_eye_px.y],
                        "distance_mm": f.distance_m(&intrinsics, ipd).map(|d| d * 1000.0),
                        "distance_from": if ipd.is_some() { "eye distance" } else { "iris" },
                        "glasses": glasses,
                        "confidence": f.confidence,
                    })
                })
                .collect();
            outln!(
                "{}",
                serde_json::json!({ "image": path.display().to_string(), "faces": faces })
            );
        } else {
            let camera = focal_35mm.map_or(format!("{:.0}° assumed", args.hfov_deg), |f| {
                format!("EXIF: {f:.0} mm (35 mm equivalent)")
            });
            outln!("{}: {} face(s) [{camera}]", path.display(), faces.len());
            for (i, f) in faces.iter().enumerate() {
                let ipd = f.ipd_for_distance(None);
                let distance = f.distance_m(&intrinsics, ipd).map_or("-".to_owned(), |d| {
                    format!(
                        "{:.0} mm (from the {})",
                        d * 1000.0,
                        if ipd.is_some() { "eye distance" } else { "iris" }
                    )
                });
                let glasses = f.lenses.map_or(String::new(), |l| {
                    let seen = l.seen(false);
                    format!(
                        ", glasses {} over the left eye, {} over the right{}",
                        seen.left.name(),
                        seen.right.name(),
                        if seen.swapped() {
                            " (worn the other way round)"
                        } else {
                            ""
                        }
                    )
                });
                outln!(
                    "  face {}: left eye ({:.1}, {:.1}) px, right eye ({:.1}, {:.1}) px, iris {:.1} px, distance {distance}, confidence {:.2}{glasses}",
                    i + 1,
                    f.left_eye_px.x,
                    f.left_eye_px.y,
                    f.right_eye_px.x,
                    f.right_eye_px.y,
                    f.iris_diameter_px,
                    f.confidence
                );
            }
        }
    }
    if failures > 0 {
        anyhow::bail!("{failures} of {} image(s) could not be read", args.images.len());
    }
    Ok(())
}

/// Decodes the image and, when its EXIF carries one, the 35 mm-equivalent focal length (tag
/// 0xA405 in the Exif IFD).
fn open_with_exif_focal(path: &Path) -> Result<(image::RgbaImage, Option<f32>)> {
    use image::ImageDecoder;
    // Regular files only: a pipe would block, a device never end.
    let file = phantogram::files::open_regular_file(path)?;
    let reader = image::ImageReader::new(std::io::BufReader::new(file)).with_guessed_format()?;
    // Photos: PNG or JPEG. The HDR and EXR decoders are built in for environments only.
    match reader.format() {
        Some(image::ImageFormat::Png | image::ImageFormat::Jpeg) => {}
        other => anyhow::bail!(
            "not a PNG or JPEG photo ({})",
            other.map_or("unrecognised data".to_owned(), |f| format!("{f:?}"))
        ),
    }
    let mut decoder = reader.into_decoder()?;
    // `into_decoder` skips the memory limit `decode` applies: a header claiming 60000 × 60000
    // pixels would otherwise abort on a 14 GB allocation.
    if image::Limits::default().reserve(decoder.total_bytes()).is_err() {
        let (w, h) = decoder.dimensions();
        anyhow::bail!("{w}×{h} pixels is more than this tool decodes (512 MiB)");
    }
    let focal = decoder
        .exif_metadata()
        .ok()
        .flatten()
        .and_then(|exif| focal_length_35mm(&exif));
    let image = image::DynamicImage::from_decoder(decoder)?.to_rgba8();
    Ok((image, focal))
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
        let b: [u8; 2] = tiff.get(o..o + 2)?.try_into().ok()?;
        Some(if little {
            u16::from_le_bytes(b)
        } else {
            u16::from_be_bytes(b)
        })
    };
    let u32_at = |o: usize| -> Option<u32> {
        let b: [u8; 4] = tiff.get(o..o + 4)?.try_into().ok()?;
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
    use super::focal_length_35mm;

    /// A little- and a big-endian EXIF block with FocalLengthIn35mmFilm = 26, built by hand.
    fn block(little: bool, focal: u16) -> Vec<u8> {
        let w16 = |v: u16| if little { v.to_le_bytes() } else { v.to_be_bytes() };
        let w32 = |v: u32| if little { v.to_le_bytes() } else { v.to_be_bytes() };
        let mut b = Vec::new();
        b.extend_from_slice(if little { b"II" } else { b"MM" });
        b.extend_from_slice(&w16(42));
        b.extend_from_slice(&w32(8)); // IFD0 at 8
        b.extend_from_slice(&w16(1)); // one entry: the Exif IFD pointer
        b.extend_from_slice(&w16(0x8769));
        b.extend_from_slice(&w16(4)); // LONG
        b.extend_from_slice(&w32(1));
        b.extend_from_slice(&w32(26)); // Exif IFD at 8 + 2 + 12 + 4 = 26
        b.extend_from_slice(&w32(0)); // no next IFD
        b.extend_from_slice(&w16(1));
        b.extend_from_slice(&w16(0xA405));
        b.extend_from_slice(&w16(3)); // SHORT
        b.extend_from_slice(&w32(1));
        b.extend_from_slice(&w16(focal));
        b.extend_from_slice(&w16(0));
        b.extend_from_slice(&w32(0));
        b
    }

    #[test]
    fn reads_the_35mm_focal_length_in_both_byte_orders_and_survives_garbage() {
        assert_eq!(focal_length_35mm(&block(true, 26)), Some(26.0));
        assert_eq!(focal_length_35mm(&block(false, 28)), Some(28.0));
        let mut prefixed = b"Exif\0\0".to_vec();
        prefixed.extend(block(true, 24));
        assert_eq!(focal_length_35mm(&prefixed), Some(24.0));
        // Truncated anywhere before the value's last byte (offset 38), and pointers past the
        // end: no panic, no value.
        let full = block(true, 26);
        for n in 0..38 {
            assert_eq!(focal_length_35mm(&full[..n]), None, "truncated at {n}");
        }
        let mut bad = full.clone();
        bad[4] = 0xFF;
        assert_eq!(focal_length_35mm(&bad), None);
        assert_eq!(focal_length_35mm(&block(true, 0)), None);
    }
}
