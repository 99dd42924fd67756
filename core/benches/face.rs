//! `cargo bench -p phantogram --bench face` (or `cargo xtask bench face`): milliseconds per
//! 640×480 camera frame in detection mode (BlazeFace + FaceMesh + 2 × Iris) and tracking mode
//! (FaceMesh + 2 × Iris on one frame in `MESH_EVERY`, 2 × Iris alone between), one thread, median
//! of 30 frames each (and of each kind of tracked frame), measured in the same run.
//!
//! Needs the models (`cargo xtask models`; `PHANTOGRAM_MODELS` or the default cache) and a face
//! photograph: `$PHANTOGRAM_DATA/faces/astronaut.png`, letterboxed into 640×480. Skipped with a
//! notice when either is missing.

use std::sync::Arc;
use std::time::Instant;

use phantogram::face::{CameraFrame, CameraPose, FaceModels, FaceTracker, Intrinsics, PixelFormat, TrackingMode};
use phantogram::glam::Vec3;

fn median_ms(mut samples: Vec<f64>) -> f64 {
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

fn main() {
    let Some(dir) = FaceModels::default_dir().filter(|d| d.is_dir()) else {
        eprintln!("no face models: run `cargo xtask models` first; skipped");
        return;
    };
    let Some(data) = std::env::var_os("PHANTOGRAM_DATA") else {
        eprintln!("PHANTOGRAM_DATA is not set (needs faces/astronaut.png); skipped");
        return;
    };
    let t = Instant::now();
    let models = match FaceModels::load(&dir) {
        Ok(m) => Arc::new(m),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    };
    println!("model load: {:.0} ms", t.elapsed().as_secs_f64() * 1e3);
    let path = std::path::Path::new(&data).join("faces/astronaut.png");
    let face = match image::open(&path) {
        Ok(i) => i.to_rgba8(),
        Err(e) => {
            eprintln!("error: {}: {e}", path.display());
            std::process::exit(1);
        }
    };
    let face = image::imageops::resize(&face, 480, 480, image::imageops::FilterType::Triangle);
    let mut frame_img = image::RgbaImage::from_pixel(640, 480, image::Rgba([40, 40, 40, 255]));
    image::imageops::overlay(&mut frame_img, &face, 80, 0);
    let frame = CameraFrame {
        width: 640,
        height: 480,
        row_stride: 640 * 4,
        format: PixelFormat::Rgba8,
        data: frame_img.as_raw(),
        rotation_cw_deg: 0,
        intrinsics: Intrinsics::from_horizontal_fov(640, 480, 60f32.to_radians()),
        capture_t_ns: 0,
        chroma: None,
    };
    let mut tracker = FaceTracker::new(models, CameraPose::front(Vec3::new(0.0, 0.07, 0.0)));
    // Medians per frame kind: (all, FaceMesh run, irises alone).
    let mut measure = |detect: bool| {
        let (mut all, mut mesh, mut irises) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..33 {
            if detect {
                tracker.reset();
            }
            let t = Instant::now();
            let obs = tracker.process(frame).expect("a valid frame");
            let ms = t.elapsed().as_secs_f64() * 1e3;
            assert!(
                obs.eyes_m.is_some(),
                "the face must be found for the figure to mean anything"
            );
            let want = if detect {
                TrackingMode::Detecting
            } else {
                TrackingMode::Tracking
            };
            assert_eq!(tracker.last_mode(), want);
            // The first frames warm caches and allocators.
            if i >= 3 {
                all.push(ms);
                if tracker.followed_irises_only() {
                    irises.push(ms);
                } else {
                    mesh.push(ms);
                }
            }
        }
        let median = |v: Vec<f64>| if v.is_empty() { f64::NAN } else { median_ms(v) };
        (median(all), median(mesh), median(irises))
    };
    let (detection, _, _) = measure(true);
    let (tracking, with_mesh, irises_only) = measure(false);
    println!("640×480 frame, one thread: detection mode {detection:.1} ms, tracking mode {tracking:.1} ms");
    println!(
        "tracking mode by frame: with FaceMesh {with_mesh:.1} ms, irises alone {irises_only:.1} ms (FaceMesh on one tracked frame in {})",
        phantogram::face::MESH_EVERY
    );
    println!("tracking / detection = {:.2}", tracking / detection);
}
