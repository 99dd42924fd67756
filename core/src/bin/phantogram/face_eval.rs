//! `phantogram eval face IMAGE…`: faces, eye centres and distances in still images.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use phantogram::face::{CameraFrame, FaceModels, Intrinsics, PixelFormat, UprightImage};

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
        println!(
            "# distances assume a {:.0}° horizontal field of view (--hfov-deg) and an 11.7 mm iris",
            args.hfov_deg
        );
    }
    let mut failures = 0usize;
    for path in args.images {
        let image = match image::open(path) {
            Ok(i) => i.to_rgba8(),
            Err(e) => {
                // One unreadable image does not stop the others; the exit status reports it.
                eprintln!("error: {}: {e}", path.display());
                failures += 1;
                continue;
            }
        };
        let (w, h) = image.dimensions();
        let intrinsics = Intrinsics::from_horizontal_fov(w, h, args.hfov_deg.to_radians());
        let frame = CameraFrame {
            width: w,
            height: h,
            row_stride: 4 * w as usize,
            format: PixelFormat::Rgba8,
            data: image.as_raw(),
            rotation_cw_deg: 0,
            intrinsics,
            capture_t_ns: 0,
        };
        let upright = UprightImage::new(frame)?;
        let faces = models.find_faces(&upright)?;
        if args.json {
            let faces: Vec<serde_json::Value> = faces
                .iter()
                .map(|f| {
                    serde_json::json!({
                        "left_eye": [f.left_eye_px.x, f.left_eye_px.y],
                        "right_eye": [f.right_eye_px.x, f.right_eye_px.y],
                        "distance_mm": f.distance_m(&intrinsics, None).map(|d| d * 1000.0),
                        "confidence": f.confidence,
                    })
                })
                .collect();
            println!(
                "{}",
                serde_json::json!({ "image": path.display().to_string(), "faces": faces })
            );
        } else {
            println!("{}: {} face(s)", path.display(), faces.len());
            for (i, f) in faces.iter().enumerate() {
                let distance = f
                    .distance_m(&intrinsics, None)
                    .map_or("-".to_owned(), |d| format!("{:.0} mm", d * 1000.0));
                println!(
                    "  face {}: left eye ({:.1}, {:.1}) px, right eye ({:.1}, {:.1}) px, iris {:.1} px, distance {distance}, confidence {:.2}",
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
