//! `cargo bench -p phantogram --bench face` (or `cargo xtask bench face`): milliseconds per
//! 640×480 camera frame, one thread, measured in the same run: detection mode (the frame that
//! finds the face: BlazeFace + FaceMesh; median of 30), the frame after it that gives the first
//! eyes (2 × Iris; median of 30; the two together are the whole cost of finding a face) and
//! tracking mode (once in `NETWORK_EVERY` frames FaceMesh on one and 2 × Iris on the next, the
//! eyes' patches between; the mean over 60 frames, whole cycles of the schedule, as that is what
//! the tracker takes from the cores; also the worst frame and the median of each kind). The face
//! sways across the frame by up to 7 pixels a frame. All of it three times: the bare face, the same
//! face with red/cyan glasses drawn on (`phantogram_lab::drawn_glasses`), and that face as the YUV
//! 4:2:0 frames the phones hand over (the networks read luma, the glasses' colour comes from the
//! chroma planes).
//!
//! Needs the models (`cargo xtask models`; `PHANTOGRAM_MODELS` or the default cache) and a face
//! photograph: `$PHANTOGRAM_DATA/faces/astronaut.png`, letterboxed into 640×480. Skipped with a
//! notice when either is missing.

use std::sync::Arc;
use std::time::Instant;

use phantogram::face::{
    CameraFrame, CameraPose, FaceModels, FaceTracker, Intrinsics, NETWORK_EVERY, OwnedFrame, TrackedBy, TrackingMode,
    UprightImage,
};
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
    let face = match phantogram_lab::photo::open_photo(&path) {
        Ok(p) => p.rgba,
        Err(e) => {
            eprintln!("error: {}: {e}", path.display());
            std::process::exit(1);
        }
    };
    let face = image::imageops::resize(&face, 480, 480, image::imageops::FilterType::Triangle);
    // The same face with red/cyan glasses drawn on (`phantogram_lab::drawn_glasses`): the tracker
    // then also names the filters, undoes the tint in every crop, finds the lens outlines (their
    // centres and any dark rims) and fills the rims.
    let eyes = {
        let img = UprightImage::new(still(&face)).expect("a valid frame");
        match models
            .find_faces(&img)
            .map(|f| f.first().map(|f| (f.left_eye_px, f.right_eye_px)))
        {
            Ok(Some(eyes)) => eyes,
            Ok(None) => {
                eprintln!("error: no face found in {}", path.display());
                std::process::exit(1);
            }
            Err(e) => {
                eprintln!("error: {e}");
                std::process::exit(1);
            }
        }
    };
    let mut with_glasses = face.clone();
    // One fixed style, so that the figures stay comparable however the test set's styles are
    // picked: the style the bench has timed since glasses were added to it (rimless, a rounded
    // rectangle 0.8 eye distances wide, 85 % strength, a reflection).
    let style = phantogram_lab::drawn_glasses::GlassesStyle {
        shape: phantogram_lab::drawn_glasses::LensShape::RoundedRect(0.3),
        width_ipd: 0.8,
        aspect: 0.8,
        opacity: 0.85,
        rim_ipd: 0.0,
        rim_rgb: [25, 22, 20],
        reflection: 0.25,
        ..phantogram_lab::drawn_glasses::style_for(0)
    };
    phantogram_lab::drawn_glasses::draw(&mut with_glasses, 480, 480, eyes.0, eyes.1, &style);
    for (name, face, yuv) in [
        ("bare face", &face, false),
        ("red/cyan glasses", &with_glasses, false),
        (
            "red/cyan glasses, YUV 4:2:0 as the phones hand it over",
            &with_glasses,
            true,
        ),
    ] {
        measure(&models, name, face, yuv);
    }
}

/// The bench camera's intrinsics: 60° across.
fn intrinsics(w: u32, h: u32) -> Intrinsics {
    Intrinsics::from_horizontal_fov(w, h, 60f32.to_radians())
}

/// A still RGBA image as a camera frame.
fn still(img: &image::RgbaImage) -> CameraFrame<'_> {
    let (w, h) = img.dimensions();
    CameraFrame::upright_rgba(w, h, img.as_raw(), intrinsics(w, h))
}

/// Detection and tracking modes for `face` (480 × 480) swaying across a 640 × 480 frame, printed;
/// `yuv`: the frames as luma and chroma planes (`phantogram_lab::synthetic_camera::as_yuv420`).
fn measure(models: &Arc<FaceModels>, name: &str, face: &image::RgbaImage, yuv: bool) {
    // The face swaying across the frame, up to 7 pixels a frame (on a still frame the eyes'
    // patches would settle in one step; a moving one costs what a real tracked frame does).
    let frames: Vec<OwnedFrame> = (0..18)
        .map(|k| {
            let x = 80.0 + 20.0 * (std::f64::consts::TAU * f64::from(k) / 18.0).sin();
            let mut img = image::RgbaImage::from_pixel(640, 480, image::Rgba([40, 40, 40, 255]));
            image::imageops::overlay(&mut img, face, x.round() as i64, 0);
            let owned = OwnedFrame::upright_rgba(640, 480, img.into_raw(), intrinsics(640, 480), 0);
            if yuv {
                phantogram_lab::synthetic_camera::as_yuv420(&owned)
            } else {
                owned
            }
        })
        .collect();
    let frame = |k: usize| frames[k % frames.len()].as_frame();
    let mut tracker = FaceTracker::new(models.clone(), CameraPose::front(Vec3::new(0.0, 0.07, 0.0)));
    let run = |tracker: &mut FaceTracker, k: usize| {
        let t = Instant::now();
        let obs = tracker.process(frame(k)).expect("a valid frame");
        (t.elapsed().as_secs_f64() * 1e3, obs.eyes_m.is_some())
    };
    // Detection mode: the tracker forgotten before every frame that finds the face, then the
    // frame after (the face moved on), which gives the first eyes; the first frames warm caches
    // and allocators.
    let (mut detection, mut first_eyes) = (Vec::new(), Vec::new());
    for k in 0..33 {
        tracker.reset();
        let (found_ms, eyes) = run(&mut tracker, k);
        assert_eq!(tracker.last_step(), TrackedBy::Detector);
        assert!(!eyes, "the frame that finds the face reports no eyes");
        let (eyes_ms, eyes) = run(&mut tracker, k + 1);
        assert_eq!(
            tracker.last_step(),
            TrackedBy::Irises,
            "frame {k}: the eyes' patches were refused"
        );
        assert!(eyes, "the face must be found for the figure to mean anything");
        if k >= 3 {
            detection.push(found_ms);
            first_eyes.push(eyes_ms);
        }
    }
    // Tracking mode: 3 warm-up frames, then 60 (whole cycles for NETWORK_EVERY 1 to 6, 10 or
    // 12), after one detection and its first eyes.
    tracker.reset();
    run(&mut tracker, 0);
    run(&mut tracker, 1);
    let (mut all, mut by_step) = (Vec::new(), std::collections::BTreeMap::<String, Vec<f64>>::new());
    for k in 2..5 + 60 {
        let (ms, eyes) = run(&mut tracker, k);
        assert!(
            eyes && tracker.last_mode() == TrackingMode::Tracking,
            "frame {k}: the track was lost"
        );
        if k >= 5 {
            all.push(ms);
            by_step
                .entry(format!("{:?}", tracker.last_step()))
                .or_default()
                .push(ms);
        }
    }
    let mean = all.iter().sum::<f64>() / all.len() as f64;
    let worst = all.iter().copied().fold(0.0, f64::max);
    let (detection, first_eyes) = (median_ms(detection), median_ms(first_eyes));
    println!("{name}:");
    println!(
        "640×480 frame, one thread: detection mode {detection:.1} ms (median; the frame after it, with the first eyes: {first_eyes:.1} ms), tracking mode {mean:.2} ms (mean over {} frames; worst {worst:.1} ms)",
        all.len()
    );
    let kinds: Vec<String> = by_step
        .into_iter()
        .map(|(step, v)| format!("{step} {} × {:.2} ms", v.len(), median_ms(v)))
        .collect();
    println!(
        "tracking mode by frame (median): {} (the networks once in {NETWORK_EVERY} tracked frames, over two of them)",
        kinds.join(", ")
    );
    println!("tracking / detection = {:.2}", mean / detection);
}
