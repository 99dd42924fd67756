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
        // Upright as a photo viewer shows it (the EXIF orientation applied), with the camera's
        // focal length when the EXIF states it.
        let (image, focal_35mm) = match phantogram_lab::photo::open_photo(path) {
            Ok(p) => (p.rgba, p.focal_35mm),
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
