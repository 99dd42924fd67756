//! The face tracker with anaglyph glasses on: lenses drawn over the shared face photographs
//! (`phantogram_lab::drawn_glasses`: ellipses and rounded rectangles 0.6–0.8 of the eye distance
//! wide, the three kinds of glasses either way round, full and partly transparent lenses,
//! cardboard and plastic rims, reflections), with the clean photo's result as the reference, on
//! the photos as they are, at selfie scale (each face cropped and enlarged to a 120-pixel eye
//! distance in a 640 × 480 frame, as a phone's front camera sees a viewer at arm's length), at
//! selfie scale turned by 20° (either way), and on the photos with the lenses off the eyes as real
//! glasses sit (the tracker takes the lens centres as a second fix of each eye, so lenses drawn
//! exactly on the eyes alone would flatter it). Also ordinary glasses (clear, sunglasses, tinted
//! both one colour) drawn the same way, which must not be taken for anaglyph glasses. Needs
//! `$PHANTOGRAM_DATA/faces` and `$PHANTOGRAM_MODELS`; skipped with a notice without them.

use std::sync::Arc;

use phantogram::face::glasses;
use phantogram::face::{CameraFrame, FaceFound, FaceModels, Intrinsics, PixelFormat, UprightImage};
use phantogram::glam::Vec2;
use phantogram_geometry::srgb::{code_to_linear, linear_to_code};
use phantogram_integration::{data_subdir, warp_into_frame};
use phantogram_lab::drawn_glasses::{draw, style_for};
use phantogram_lab::photo::open_photo;

fn models() -> Option<Arc<FaceModels>> {
    phantogram_integration::face_models()
}

fn frame(img: &image::RgbaImage) -> CameraFrame<'_> {
    let (w, h) = img.dimensions();
    CameraFrame::upright_rgba(
        w,
        h,
        img.as_raw(),
        Intrinsics::from_horizontal_fov(w, h, 60f32.to_radians()),
    )
}

fn faces(models: &FaceModels, img: &image::RgbaImage) -> Vec<FaceFound> {
    models
        .find_faces(&UprightImage::new(frame(img)).expect("a valid frame"))
        .expect("inference")
}

/// The photos, as they are.
const PHOTOS: [&str; 6] = [
    "astronaut.png",
    "Tom_Cruise_avp_2014_4.jpg",
    "2008_001009.jpg",
    "2008_001322.jpg",
    "2008_002470.jpg",
    "2008_007676.jpg",
];

struct Outcome {
    case: String,
    ipd_px: f32,
    /// The face's eye distance in the photograph as it was taken (before any enlarging).
    photo_ipd_px: f32,
    /// The lenses were drawn with a reflection across them.
    reflection: bool,
    /// `None`: the face was lost with the glasses on.
    eye_error: Option<f32>,
    distance_error: Option<f32>,
    iris_distance_error: Option<f32>,
    glasses_right: bool,
}

/// Draws four styles over each face of `img` (clean faces `clean`; `img` is the photo enlarged
/// `enlarged` times) and compares. `off_centre`: the lenses sit off the eyes as real glasses do
/// (spaced 8 % of the eye distance wider or narrower than the eyes, 4 % higher or lower, 3 % to
/// one side, turned by 2.5°).
fn try_styles(
    models: &FaceModels,
    case: &str,
    img: &image::RgbaImage,
    clean: &[FaceFound],
    enlarged: f32,
    seed: &mut u32,
    off_centre: bool,
) -> Vec<Outcome> {
    let k = frame(img).intrinsics;
    let mut out = Vec::new();
    for f in clean {
        let ipd_px = f.left_eye_px.distance(f.right_eye_px);
        // The viewer's calibrated eye distance: the clean result's own (from its iris), so that
        // the distance compares like with like.
        let ipd_m = f.eyes_camera_m(&k, None).map(|[a, b]| a.distance(b));
        let clean_distance = f.distance_m(&k, None);
        for _ in 0..4 {
            let mut style = style_for(*seed);
            if off_centre {
                // Each kind of glasses (`seed % 4`) both ways, spaced wide and narrow, high and
                // low, shifted to either side and turned either way: for a 63 mm eye distance
                // 2.5 mm a side, 2.5 mm up or down, 1.9 mm sideways and 2.5°, each about one to
                // one and a half of what `glasses::LENS_OFFSET_IPD`'s reasoning takes as usual.
                style.spacing_ipd = [0.92, 1.08][(*seed / 4 % 2) as usize];
                style.drop_ipd = [-0.04, 0.04][(*seed / 8 % 2) as usize];
                style.shift_ipd = [-0.03, 0.03][(*seed / 16 % 2) as usize];
                style.tilt_rad = [-2.5f32, 2.5][(*seed / 32 % 2) as usize].to_radians();
            }
            *seed += 1;
            let mut with = img.clone();
            let (w, h) = with.dimensions();
            draw(&mut with, w, h, f.left_eye_px, f.right_eye_px, &style);
            let found = faces(models, &with);
            let mid = eyes_midpoint(f);
            let hit = found.iter().find(|g| eyes_midpoint(g).distance(mid) < 0.5 * ipd_px);
            let rel = |a: Option<f32>, b: Option<f32>| Some(a? / b? - 1.0);
            out.push(match hit {
                None => Outcome {
                    case: format!("{case} {style:?}"),
                    ipd_px,
                    photo_ipd_px: ipd_px / enlarged,
                    reflection: style.reflection > 0.0,
                    eye_error: None,
                    distance_error: None,
                    iris_distance_error: None,
                    glasses_right: false,
                },
                Some(g) => Outcome {
                    case: format!(
                        "{case} {:?}/{:?} opacity {}",
                        style.filters.0, style.filters.1, style.opacity
                    ),
                    ipd_px,
                    photo_ipd_px: ipd_px / enlarged,
                    reflection: style.reflection > 0.0,
                    eye_error: Some(eye_error(g, f)),
                    distance_error: rel(g.distance_m(&k, g.ipd_for_distance(ipd_m)), clean_distance),
                    iris_distance_error: rel(g.distance_m(&k, None), clean_distance),
                    glasses_right: g.lenses.is_some_and(|l| (l.image_left, l.image_right) == style.filters),
                },
            });
        }
    }
    out
}

fn percentile(mut v: Vec<f32>, p: f32) -> f32 {
    v.sort_by(f32::total_cmp);
    v.get(((v.len() as f32 - 1.0) * p).round() as usize)
        .copied()
        .unwrap_or(f32::NAN)
}

/// The face found in the middle of a 640 × 480 frame a face was enlarged into
/// (`warp_into_frame`), if any: none or one.
fn centred_face(models: &FaceModels, frame_img: &image::RgbaImage) -> Vec<FaceFound> {
    faces(models, frame_img)
        .into_iter()
        .filter(|g| eyes_midpoint(g).distance(Vec2::new(320.0, 240.0)) < 40.0)
        .take(1)
        .collect()
}

/// The middle between a face's eyes, pixels.
fn eyes_midpoint(f: &FaceFound) -> Vec2 {
    (f.left_eye_px + f.right_eye_px) * 0.5
}

/// How far `found`'s eyes are from `reference`'s, the farther of the two, as a share of
/// `reference`'s eye distance.
fn eye_error(found: &FaceFound, reference: &FaceFound) -> f32 {
    found
        .left_eye_px
        .distance(reference.left_eye_px)
        .max(found.right_eye_px.distance(reference.right_eye_px))
        / reference.left_eye_px.distance(reference.right_eye_px)
}

#[test]
fn drawn_glasses_are_seen_and_keep_the_eyes_and_the_distance() {
    let (Some(dir), Some(models)) = (data_subdir("faces"), models()) else {
        return;
    };
    let mut seed = 0u32;
    // Its own styles' sequence, so the other sets keep theirs.
    let mut off_seed = 1000u32;
    let mut bare_strongest = 0.0f32;
    let (mut photos, mut selfies, mut turned, mut off_centre) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut jitter = Vec::new();
    for name in PHOTOS {
        let path = dir.join(name);
        let img = open_photo(&path)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
            .rgba;
        let clean = faces(&models, &img);
        let image = UprightImage::new(frame(&img)).expect("frame");
        for f in &clean {
            if let Some(shifts) = glasses::eye_shifts(&image, f) {
                bare_strongest = bare_strongest.max(shifts[0].length().min(shifts[1].length()));
            }
            assert!(
                f.lenses.is_none(),
                "{name}: glasses seen on a bare face: {:?}",
                f.lenses
            );
        }
        photos.extend(try_styles(&models, name, &img, &clean, 1.0, &mut seed, false));
        off_centre.extend(try_styles(&models, name, &img, &clean, 1.0, &mut off_seed, true));
        for f in &clean {
            let ipd_px = f.left_eye_px.distance(f.right_eye_px);
            let mid = eyes_midpoint(f);
            // Upright, and turned by 20° one way or the other (alternating between faces).
            let turn = if seed % 8 < 4 { 20.0 } else { -20.0 };
            for angle_deg in [0.0f32, turn] {
                let selfie = warp_into_frame(&img, mid, 120.0 / ipd_px, angle_deg.to_radians());
                // The reference: the face in the middle of the enlarged, clean frame.
                let clean_selfie = centred_face(&models, &selfie);
                for g in &clean_selfie {
                    assert!(g.lenses.is_none(), "{name} at selfie scale: glasses on a bare face");
                    if angle_deg == 0.0 {
                        // The tracker's own noise, for scale: the same bare face moved by
                        // (0.5, 0.3) pixels.
                        let shift = Vec2::new(0.5, 0.3);
                        let moved = warp_into_frame(&img, mid - shift * ipd_px / 120.0, 120.0 / ipd_px, 0.0);
                        let ipd = g.left_eye_px.distance(g.right_eye_px);
                        if let Some(m) = centred_face(&models, &moved).pop() {
                            jitter.push(
                                (m.left_eye_px - shift)
                                    .distance(g.left_eye_px)
                                    .max((m.right_eye_px - shift).distance(g.right_eye_px))
                                    / ipd,
                            );
                        }
                    }
                }
                let case = format!("{name} ×{:.1} {angle_deg:+.0}°", 120.0 / ipd_px);
                let outcomes = try_styles(&models, &case, &selfie, &clean_selfie, 120.0 / ipd_px, &mut seed, false);
                if angle_deg == 0.0 {
                    selfies.extend(outcomes);
                } else {
                    turned.extend(outcomes);
                }
            }
        }
    }
    println!(
        "bare faces: strongest colour shift {bare_strongest:.3} (glasses from {})",
        glasses::MIN_STRENGTH
    );
    println!(
        "bare faces at selfie scale moved by half a pixel: eyes move by median {:.3}, 90 % {:.3}, max {:.3} of the eye distance",
        percentile(jitter.clone(), 0.5),
        percentile(jitter.clone(), 0.9),
        percentile(jitter.clone(), 1.0)
    );
    // No glasses on a bare face: asserted above for every face, as the goal asks.
    assert!(bare_strongest < glasses::MIN_STRENGTH);
    for (set, outcomes) in [
        ("photos", &photos),
        ("selfie scale", &selfies),
        ("selfie scale, turned ±20°", &turned),
        ("photos, lenses off the eyes", &off_centre),
    ] {
        let found: Vec<&Outcome> = outcomes.iter().filter(|o| o.eye_error.is_some()).collect();
        let eyes: Vec<f32> = found.iter().filter_map(|o| o.eye_error).collect();
        let dist: Vec<f32> = found.iter().filter_map(|o| o.distance_error.map(f32::abs)).collect();
        let iris: Vec<f32> = found
            .iter()
            .filter_map(|o| o.iris_distance_error.map(f32::abs))
            .collect();
        let right = found.iter().filter(|o| o.glasses_right).count();
        println!(
            "{set}: {} of {} found; glasses right {right}; eye error / eye distance median {:.3}, 90 % {:.3}, max {:.3}; \
             distance error median {:.3}, 90 % {:.3}, max {:.3} (from the iris instead: median {:.3}, max {:.3})",
            found.len(),
            outcomes.len(),
            percentile(eyes.clone(), 0.5),
            percentile(eyes.clone(), 0.9),
            percentile(eyes.clone(), 1.0),
            percentile(dist.clone(), 0.5),
            percentile(dist.clone(), 0.9),
            percentile(dist.clone(), 1.0),
            percentile(iris.clone(), 0.5),
            percentile(iris.clone(), 1.0),
        );
        // By the detail the photograph holds (a phone's front camera at arm's length puts its
        // viewer's eyes about 100 px apart; the shared photos' small faces, 13–35 px), and by
        // whether a reflection lies across the lenses.
        type Part = (&'static str, fn(&Outcome) -> bool);
        let parts: [Part; 4] = [
            ("eyes ≥ 40 px apart in the photo", |o| o.photo_ipd_px >= 40.0),
            ("eyes < 40 px apart", |o| o.photo_ipd_px < 40.0),
            ("lenses without a reflection", |o| !o.reflection),
            ("lenses with a reflection", |o| o.reflection),
        ];
        for (part, within) in parts {
            let errors: Vec<f32> = found.iter().filter(|o| within(o)).filter_map(|o| o.eye_error).collect();
            if !errors.is_empty() {
                println!(
                    "  {part}: {} faces, eye error median {:.3}, 90 % {:.3}, max {:.3}",
                    errors.len(),
                    percentile(errors.clone(), 0.5),
                    percentile(errors.clone(), 0.9),
                    percentile(errors.clone(), 1.0)
                );
            }
        }
        for o in outcomes
            .iter()
            .filter(|o| o.eye_error.is_none_or(|e| e > 0.05) || !o.glasses_right)
        {
            println!(
                "  {} (eye distance {:.0} px): eyes {:?}, distance {:?}, glasses {}",
                o.case,
                o.ipd_px,
                o.eye_error,
                o.distance_error,
                if o.glasses_right { "right" } else { "WRONG" }
            );
        }
        // The goals (issue 21): every face found again, the glasses named, eyes within 3 % of
        // the eye distance, distance within 5 % — met by the median; the tail is printed above
        // and guarded (a regression beyond today's figures fails). Lenses off the eyes (a
        // harder set than the goal's: each lens 2–9 % of the eye distance off its eye) pull the
        // lens-fused eyes off by design, so its bounds are today's figures with a margin.
        let off = set == "photos, lenses off the eyes";
        let lost = outcomes.len() - found.len();
        let at_photo_scale = set.starts_with("photos");
        let lost_allowed = if at_photo_scale { outcomes.len() / 20 } else { 0 };
        assert!(lost <= lost_allowed, "{set}: {lost} faces lost with glasses on");
        // At photo scale some eyes are 13 pixels apart, the skin under a lens a pixel or two.
        let named_share = if at_photo_scale { 0.95 } else { 0.97 };
        assert!(
            right as f32 >= named_share * found.len() as f32,
            "{set}: glasses named on {right} of {}",
            found.len()
        );
        let [eye_median, eye_90, distance_median, distance_90] = if off {
            [0.04, 0.10, 0.04, 0.08]
        } else {
            [0.03, 0.07, 0.02, 0.065]
        };
        assert!(percentile(eyes.clone(), 0.5) <= eye_median, "{set}: median eye error");
        assert!(
            percentile(eyes.clone(), 0.9) <= eye_90,
            "{set}: 90th-percentile eye error"
        );
        assert!(
            percentile(dist.clone(), 0.5) <= distance_median,
            "{set}: median distance error"
        );
        assert!(
            percentile(dist.clone(), 0.9) <= distance_90,
            "{set}: 90th-percentile distance error"
        );
    }
}

/// Through the engine as a phone drives it: a YUV frame (luma plus interleaved chroma, as the
/// bridges hand it over) of a face with red/cyan glasses, red over the viewer's left eye; the
/// engine reports the glasses the right way round.
#[test]
fn the_engine_reports_the_glasses_of_a_colour_camera_frame() {
    use phantogram::engine::{EngineConfig, SharedEngine};
    let (Some(dir), Some(_)) = (data_subdir("faces"), models()) else {
        return;
    };
    let models_dir = std::path::PathBuf::from(std::env::var_os("PHANTOGRAM_MODELS").expect("checked"));
    let Some(engine) = phantogram_integration::engine_or_skip(EngineConfig {
        face_models_dir: Some(models_dir),
        ..EngineConfig::default()
    }) else {
        return;
    };
    let shared = SharedEngine::new(engine);
    let img = open_photo(&dir.join("astronaut.png")).expect("photo").rgba;
    let clean = faces(&models().expect("models"), &img);
    let f = clean.first().expect("the astronaut's face");
    let mut with = img.clone();
    let (w, h) = with.dimensions();
    let style = style_for(0);
    assert_eq!(style.filters, (glasses::Filter::Cyan, glasses::Filter::Red));
    draw(&mut with, w, h, f.left_eye_px, f.right_eye_px, &style);
    let rgba = phantogram::face::OwnedFrame::upright_rgba(
        w,
        h,
        with.into_raw(),
        Intrinsics::from_horizontal_fov(w, h, 60f32.to_radians()),
        5_000_000,
    );
    let yuv = phantogram_lab::synthetic_camera::as_yuv420(&rgba);
    assert_eq!(yuv.format, PixelFormat::Luma8);
    // Twice, as a camera streams: the frame that finds the face, then the one with its eyes.
    let worker = shared.lock().face_worker().expect("face tracking is on");
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
    for t_ns in [5_000_000, 6_000_000] {
        let mut yuv = yuv.clone();
        yuv.capture_t_ns = t_ns;
        assert!(
            shared
                .camera_frame(phantogram::camera::CameraFacing::Front, yuv)
                .expect("a valid frame"),
            "face tracking is on"
        );
        while worker.newest().is_none_or(|o| o.capture_t_ns != t_ns) {
            assert!(std::time::Instant::now() < deadline, "the frame was never processed");
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
    }
    let mut engine = shared.lock();
    engine.resume_offscreen(54, 120).expect("offscreen");
    engine.draw(Some(10_000_000)).expect("drawing");
    let seen = engine.glasses_seen().expect("glasses seen through the YUV frame");
    assert_eq!(
        (seen.left, seen.right, seen.swapped()),
        (glasses::Filter::Red, glasses::Filter::Cyan, false)
    );
}

/// The astronaut photo at the face bench's size (480 × 480, for a 640 × 480 frame).
fn astronaut_at_bench_size(faces_dir: &std::path::Path) -> image::RgbaImage {
    let photo = open_photo(&faces_dir.join("astronaut.png")).expect("photo").rgba;
    image::imageops::resize(&photo, 480, 480, image::imageops::FilterType::Triangle)
}

/// A face with glasses, found by the tracker's whole-frame detector, gets its eyes on the very
/// next frame as a bare face does: the astronaut at the face bench's size (eyes 40 px apart in a
/// 640 × 480 frame) with the glasses test's first style, whose tinted eyes the detector scores
/// under `MIN_FACE_CONFIDENCE` (FaceMesh, on the crop with the tint undone, is sure of it). The
/// eyes are the still photo's (`find_faces`) within 3 % of the eye distance.
#[test]
fn a_tracked_face_with_glasses_has_eyes_on_the_frame_after_its_detection() {
    use phantogram::face::{CameraPose, FaceTracker, TrackedBy};
    let (Some(dir), Some(models)) = (data_subdir("faces"), models()) else {
        return;
    };
    let face = astronaut_at_bench_size(&dir);
    let mut img = image::RgbaImage::from_pixel(640, 480, image::Rgba([40, 40, 40, 255]));
    image::imageops::overlay(&mut img, &face, 80, 0);
    let clean = faces(&models, &img);
    let f = clean.first().expect("the astronaut's face");
    let (w, h) = img.dimensions();
    draw(&mut img, w, h, f.left_eye_px, f.right_eye_px, &style_for(0));
    let still = faces(&models, &img);
    let g = still.first().expect("the face with glasses, as a still photo");
    assert!(g.lenses.is_some(), "glasses seen on the still photo");
    let mut tracker = FaceTracker::new(models.clone(), CameraPose::front(phantogram::glam::Vec3::ZERO));
    let first = tracker.process(frame(&img)).expect("a valid frame");
    assert_eq!(tracker.last_step(), TrackedBy::Detector);
    assert!(first.eyes_m.is_none(), "the frame that finds the face has no eyes yet");
    let second = tracker.process(frame(&img)).expect("a valid frame");
    assert_eq!(tracker.last_step(), TrackedBy::Irises);
    let [a, b] = second.eyes_m.expect("eyes on the frame after the detection");
    assert!(second.glasses.is_some(), "glasses reported");
    // Back to pixels: the eyes project where the still photo has them.
    let k = frame(&img).intrinsics;
    let (pose, ipd) = (tracker.pose, g.left_eye_px.distance(g.right_eye_px));
    let project = |p: phantogram::glam::Vec3| {
        let c = pose.device_from_camera.inverse() * (p - pose.position_m);
        Vec2::new(k.fx_px * c.x / c.z + k.cx_px, k.fy_px * c.y / c.z + k.cy_px)
    };
    let (pa, pb) = (project(a), project(b));
    let (l, r) = if pa.x <= pb.x { (pa, pb) } else { (pb, pa) };
    let error = l.distance(g.left_eye_px).max(r.distance(g.right_eye_px)) / ipd;
    assert!(error < 0.03, "tracked eyes {l} {r} against the still photo's: {error}");
}

/// Phones hand over YUV frames, whose crops the networks read in grey (luma); the glasses are
/// named from the chroma planes. With glasses on, the eyes found through YUV are as close to the
/// bare face's as those found through RGBA (the glasses test's first eight styles over the
/// astronaut, tracked for two frames as a camera streams).
#[test]
fn a_face_with_glasses_in_a_yuv_frame_keeps_its_eyes_as_in_rgba() {
    use phantogram::face::{CameraPose, FaceTracker, OwnedFrame};
    let (Some(dir), Some(models)) = (data_subdir("faces"), models()) else {
        return;
    };
    let photo = open_photo(&dir.join("astronaut.png")).expect("photo").rgba;
    let (w, h) = photo.dimensions();
    let owned = |img: &image::RgbaImage| {
        OwnedFrame::upright_rgba(
            w,
            h,
            img.as_raw().clone(),
            Intrinsics::from_horizontal_fov(w, h, 60f32.to_radians()),
            0,
        )
    };
    // The tracker's eyes (image left, image right), in pixels, and whether it saw glasses.
    let eyes = |frame: &OwnedFrame| {
        let mut tracker = FaceTracker::new(models.clone(), CameraPose::front(phantogram::glam::Vec3::ZERO));
        tracker.process(frame.as_frame()).expect("a valid frame");
        let o = tracker.process(frame.as_frame()).expect("a valid frame");
        let (k, pose) = (frame.intrinsics, tracker.pose);
        let project = |p: phantogram::glam::Vec3| {
            let c = pose.device_from_camera.inverse() * (p - pose.position_m);
            Vec2::new(k.fx_px * c.x / c.z + k.cx_px, k.fy_px * c.y / c.z + k.cy_px)
        };
        let [a, b] = o.eyes_m.expect("eyes").map(project);
        (if a.x <= b.x { [a, b] } else { [b, a] }, o.glasses.is_some())
    };
    let bare = owned(&photo);
    let (clean, _) = eyes(&bare);
    let ipd = clean[0].distance(clean[1]);
    let off = |e: [Vec2; 2]| e[0].distance(clean[0]).max(e[1].distance(clean[1])) / ipd;
    let (bare_yuv, _) = eyes(&phantogram_lab::synthetic_camera::as_yuv420(&bare));
    println!(
        "bare face: YUV eyes off the RGBA ones by {:.2} %",
        100.0 * off(bare_yuv)
    );
    let (mut through_rgba, mut through_yuv) = (Vec::new(), Vec::new());
    for seed in 0..8 {
        let mut img = photo.clone();
        draw(&mut img, w, h, clean[0], clean[1], &style_for(seed));
        let rgba = owned(&img);
        let ((a, ga), (b, gb)) = (eyes(&rgba), eyes(&phantogram_lab::synthetic_camera::as_yuv420(&rgba)));
        assert!(ga && gb, "style {seed}: glasses seen through RGBA {ga}, YUV {gb}");
        println!(
            "style {seed}: eyes off the bare face's by {:.2} % through RGBA, {:.2} % through YUV",
            100.0 * off(a),
            100.0 * off(b)
        );
        through_rgba.push(off(a));
        through_yuv.push(off(b));
    }
    let worst = |v: &[f32]| v.iter().copied().fold(0.0f32, f32::max);
    let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len() as f32;
    assert!(
        worst(&through_yuv) <= worst(&through_rgba) + 0.01 && mean(&through_yuv) <= mean(&through_rgba) + 0.005,
        "through YUV: mean {:.2} %, worst {:.2} %; through RGBA: mean {:.2} %, worst {:.2} %",
        100.0 * mean(&through_yuv),
        100.0 * worst(&through_yuv),
        100.0 * mean(&through_rgba),
        100.0 * worst(&through_rgba)
    );
}

/// A swaying face with glasses is found on every detection and has its eyes on the frame after
/// it, through RGBA and through YUV: the face bench's frames (the astronaut at 480 × 480 in a
/// 640 × 480 frame, 18 positions up to 7 px apart), with the glasses test's first eight styles
/// drawn on. The tracker is reset before each position, so each is a fresh detection.
#[test]
fn a_swaying_face_with_glasses_is_found_again_at_every_position() {
    use phantogram::face::{CameraPose, FaceTracker, OwnedFrame, TrackedBy};
    let (Some(dir), Some(models)) = (data_subdir("faces"), models()) else {
        return;
    };
    let face = astronaut_at_bench_size(&dir);
    let clean = faces(&models, &face);
    let f = clean.first().expect("the astronaut's face");
    let mut failures = Vec::new();
    for seed in 0..8 {
        let mut with_glasses = face.clone();
        draw(
            &mut with_glasses,
            480,
            480,
            f.left_eye_px,
            f.right_eye_px,
            &style_for(seed),
        );
        let frames: Vec<OwnedFrame> = (0..18)
            .map(|k| {
                let x = 80.0 + 20.0 * (std::f64::consts::TAU * f64::from(k) / 18.0).sin();
                let mut img = image::RgbaImage::from_pixel(640, 480, image::Rgba([40, 40, 40, 255]));
                image::imageops::overlay(&mut img, &with_glasses, x.round() as i64, 0);
                OwnedFrame::upright_rgba(
                    640,
                    480,
                    img.into_raw(),
                    Intrinsics::from_horizontal_fov(640, 480, 60f32.to_radians()),
                    0,
                )
            })
            .collect();
        for yuv in [false, true] {
            let frames: Vec<OwnedFrame> = if yuv {
                frames.iter().map(phantogram_lab::synthetic_camera::as_yuv420).collect()
            } else {
                frames.clone()
            };
            let mut tracker = FaceTracker::new(models.clone(), CameraPose::front(phantogram::glam::Vec3::ZERO));
            for k in 0..frames.len() {
                tracker.reset();
                tracker.process(frames[k].as_frame()).expect("a valid frame");
                let found = tracker.last_step() == TrackedBy::Detector;
                let next = tracker
                    .process(frames[(k + 1) % frames.len()].as_frame())
                    .expect("a valid frame");
                let ok = found && next.eyes_m.is_some() && next.glasses.is_some();
                if !ok {
                    failures.push(format!(
                        "style {seed} {} position {k}: detected {found}, eyes {}, glasses {}",
                        if yuv { "YUV" } else { "RGBA" },
                        next.eyes_m.is_some(),
                        next.glasses.is_some()
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Ordinary glasses — clear prescription lenses, grey, brown or green sunglasses, glasses tinted
/// rose or yellow, both lenses one colour — are not anaglyph glasses: drawn over every face of the
/// shared photos, at photo and at selfie scale (a museum's visitors wear their own glasses), no
/// face is said to wear anaglyph glasses, and behind clear lenses the eyes stay where the clean
/// photo has them. (Dark sunglasses may hide the eyes: those faces are counted, not required.)
#[test]
fn ordinary_glasses_are_not_taken_for_anaglyph_glasses() {
    let (Some(dir), Some(models)) = (data_subdir("faces"), models()) else {
        return;
    };
    // Name, both lenses' linear transmission, rim (share of the eye distance), reflection.
    let kinds: [(&str, [f32; 3], f32, f32); 7] = [
        ("clear, dark rims, a reflection", [0.92; 3], 0.025, 0.25),
        ("clear, rimless, a reflection", [0.92; 3], 0.0, 0.25),
        ("grey sunglasses", [0.12; 3], 0.025, 0.0),
        ("brown sunglasses", [0.3, 0.18, 0.07], 0.025, 0.25),
        ("green (G-15) sunglasses", [0.12, 0.2, 0.1], 0.025, 0.0),
        ("rose-tinted", [0.85, 0.5, 0.55], 0.0, 0.0),
        ("yellow (blue-blocking)", [0.85, 0.75, 0.12], 0.025, 0.0),
    ];
    let (mut cases, mut named, mut lost) = (0usize, Vec::new(), vec![0usize; kinds.len()]);
    let mut clear_errors = Vec::new();
    // Per kind, the distance (from the iris, as without anaglyph glasses) against the clean's.
    let mut distance_errors = vec![Vec::new(); kinds.len()];
    let mut seed = 2000u32;
    for name in PHOTOS {
        let img = open_photo(&dir.join(name)).expect("photo").rgba;
        for f in faces(&models, &img) {
            let ipd_px = f.left_eye_px.distance(f.right_eye_px);
            let mid = eyes_midpoint(&f);
            // At photo scale, and the face enlarged to a 120-pixel eye distance in a 640 × 480 frame.
            let selfie = warp_into_frame(&img, mid, 120.0 / ipd_px, 0.0);
            let scales: [(&image::RgbaImage, f32); 2] = [(&img, 1.0), (&selfie, 120.0 / ipd_px)];
            for (picture, scale) in scales {
                let centre = |p: Vec2| {
                    if scale == 1.0 {
                        p
                    } else {
                        (p - mid) * scale + Vec2::new(320.0, 240.0)
                    }
                };
                let (left, right) = (centre(f.left_eye_px), centre(f.right_eye_px));
                let near =
                    |g: &&FaceFound| eyes_midpoint(g).distance((left + right) * 0.5) < 0.5 * left.distance(right);
                // The reference: the clean picture's own result for this face (at photo scale,
                // the face itself).
                let clean = if scale == 1.0 {
                    Some(f.clone())
                } else {
                    faces(&models, picture).into_iter().find(|g| near(&g))
                };
                let Some(clean) = clean else {
                    continue;
                };
                let intrinsics = frame(picture).intrinsics;
                for (k, (kind, tint, rim, reflection)) in kinds.iter().enumerate() {
                    let style = phantogram_lab::drawn_glasses::GlassesStyle {
                        tints: Some([*tint; 2]),
                        rim_ipd: *rim,
                        rim_rgb: [25, 22, 20],
                        reflection: *reflection,
                        ..style_for(seed)
                    };
                    seed += 1;
                    let mut with = picture.clone();
                    let (w, h) = with.dimensions();
                    draw(&mut with, w, h, clean.left_eye_px, clean.right_eye_px, &style);
                    cases += 1;
                    let found = faces(&models, &with);
                    let Some(g) = found.iter().find(near) else {
                        lost[k] += 1;
                        continue;
                    };
                    if g.lenses.is_some() || found.iter().any(|g| g.lenses.is_some()) {
                        named.push(format!("{name} ×{scale:.1} {kind}: {:?}", g.lenses));
                    }
                    if let (Some(d), Some(d0)) = (g.distance_m(&intrinsics, None), clean.distance_m(&intrinsics, None))
                    {
                        distance_errors[k].push((d / d0 - 1.0).abs());
                    }
                    if *tint == [0.92; 3] {
                        clear_errors.push((scale == 1.0, eye_error(g, &clean)));
                    }
                }
            }
        }
    }
    for (k, (kind, ..)) in kinds.iter().enumerate() {
        println!(
            "{kind}: {} of {} faces lost; distance from the iris off by median {:.3}, 90 % {:.3}",
            lost[k],
            cases / kinds.len(),
            percentile(distance_errors[k].clone(), 0.5),
            percentile(distance_errors[k].clone(), 0.9)
        );
    }
    let mut all_clear = Vec::new();
    for (at_photo_scale, set) in [(true, "photos"), (false, "selfie scale")] {
        let errors: Vec<f32> = clear_errors
            .iter()
            .filter(|e| e.0 == at_photo_scale)
            .map(|e| e.1)
            .collect();
        println!(
            "behind clear lenses, {set}: eye error / eye distance median {:.3}, 90 % {:.3}, max {:.3} ({} faces)",
            percentile(errors.clone(), 0.5),
            percentile(errors.clone(), 0.9),
            percentile(errors.clone(), 1.0),
            errors.len()
        );
        all_clear.extend(errors);
    }
    assert!(cases > 100, "only {cases} cases");
    assert!(
        named.is_empty(),
        "anaglyph glasses named on ordinary ones:\n{}",
        named.join("\n")
    );
    // Clear lenses leave the face found, and its eyes near: a guard at today's median with a
    // margin (a reflection across a clear lens moves the iris network's answer; the glasses-
    // aware path undoes nothing here, there is no tint to find; `benchmarks/face.md`).
    assert!(lost[0] + lost[1] <= cases / kinds.len() / 10, "{lost:?}");
    assert!(
        percentile(all_clear, 0.5) <= 0.05,
        "behind clear lenses: median eye error"
    );
    // Without a calibrated eye distance the distance comes from the iris, which lenses make
    // look smaller or larger (up to a quarter off at 90 %, the yellow and the dark-rimmed ones;
    // `benchmarks/face.md`): guarded at today's medians with a margin.
    for (k, (kind, ..)) in kinds.iter().enumerate() {
        assert!(
            percentile(distance_errors[k].clone(), 0.5) <= 0.10,
            "{kind}: median distance error"
        );
    }
}

/// The light the photograph was taken in, changed: each pixel's linear colour times `gains`
/// (per channel), back to 8-bit sRGB (clipped, as a camera clips).
fn relit(img: &image::RgbaImage, gains: [f32; 3]) -> image::RgbaImage {
    let mut out = img.clone();
    for p in out.pixels_mut() {
        for (code, gain) in p.0.iter_mut().zip(gains) {
            *code = linear_to_code(code_to_linear(*code) * gain);
        }
    }
    out
}

/// The glasses are named, and bare faces are not taken for glasses, under other light than the
/// photographs': two stops darker (a dim gallery, or darker skin at the same exposure: the lens
/// then tints a darker, noisier skin), a tungsten lamp's warm cast and a cool daylight one. The
/// lens's colour is measured against the cheek's, which cancels the light's colour; this checks
/// that it does, on the photos as they are and at selfie scale (not the turned or off-centre
/// sets: the light changes nothing about geometry). A camera's white balance would take most of a
/// cast out; here none is, the harder case.
///
/// Overexposure is not covered: with the cheek clipped, its colour (the reference) is wrong in
/// the clipped channels. Measured with the photos 1.3 stops brighter (`benchmarks/face.md`,
/// eleventh session): no bare face named, but 8 of 160 glasses not named.
#[test]
fn glasses_are_named_under_other_light() {
    let (Some(dir), Some(models)) = (data_subdir("faces"), models()) else {
        return;
    };
    let lights: [(&str, [f32; 3]); 3] = [
        ("two stops darker", [0.25; 3]),
        ("tungsten", [1.0, 0.6, 0.25]),
        ("cool daylight", [0.7, 0.85, 1.0]),
    ];
    for (light, gains) in lights {
        let mut seed = 0u32;
        let (mut photos, mut selfies) = (Vec::new(), Vec::new());
        for name in PHOTOS {
            let path = dir.join(name);
            let img = open_photo(&path)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
                .rgba;
            let img = relit(&img, gains);
            let clean = faces(&models, &img);
            for f in &clean {
                assert!(f.lenses.is_none(), "{name}, {light}: glasses seen on a bare face");
            }
            photos.extend(try_styles(&models, name, &img, &clean, 1.0, &mut seed, false));
            for f in &clean {
                let ipd_px = f.left_eye_px.distance(f.right_eye_px);
                let selfie = warp_into_frame(&img, eyes_midpoint(f), 120.0 / ipd_px, 0.0);
                let clean_selfie = centred_face(&models, &selfie);
                for g in &clean_selfie {
                    assert!(
                        g.lenses.is_none(),
                        "{name} at selfie scale, {light}: glasses on a bare face"
                    );
                }
                let case = format!("{name} ×{:.1}", 120.0 / ipd_px);
                selfies.extend(try_styles(
                    &models,
                    &case,
                    &selfie,
                    &clean_selfie,
                    120.0 / ipd_px,
                    &mut seed,
                    false,
                ));
            }
        }
        for (set, outcomes) in [("photos", &photos), ("selfie scale", &selfies)] {
            let found: Vec<&Outcome> = outcomes.iter().filter(|o| o.eye_error.is_some()).collect();
            let eyes: Vec<f32> = found.iter().filter_map(|o| o.eye_error).collect();
            let dist: Vec<f32> = found.iter().filter_map(|o| o.distance_error.map(f32::abs)).collect();
            let right = found.iter().filter(|o| o.glasses_right).count();
            println!(
                "{light}, {set}: {} of {} found; glasses right {right}; eye error median {:.3}, 90 % {:.3}; \
                 distance error median {:.3}, 90 % {:.3}",
                found.len(),
                outcomes.len(),
                percentile(eyes.clone(), 0.5),
                percentile(eyes.clone(), 0.9),
                percentile(dist.clone(), 0.5),
                percentile(dist.clone(), 0.9)
            );
            for o in outcomes.iter().filter(|o| !o.glasses_right) {
                println!(
                    "  {} (eye distance {:.0} px): glasses not named right",
                    o.case, o.ipd_px
                );
            }
            // As the glasses test asks of the photographs' own light: faces found again (a few
            // may be lost at photo scale), the glasses named, the eyes and distance kept.
            let lost = outcomes.len() - found.len();
            let lost_allowed = if set == "photos" { outcomes.len() / 20 } else { 0 };
            assert!(
                lost <= lost_allowed,
                "{light}, {set}: {lost} faces lost with glasses on"
            );
            assert!(
                right as f32 >= 0.95 * found.len() as f32,
                "{light}, {set}: glasses named on {right} of {}",
                found.len()
            );
            assert!(percentile(eyes, 0.5) <= 0.03, "{light}, {set}: median eye error");
            assert!(percentile(dist, 0.5) <= 0.02, "{light}, {set}: median distance error");
        }
    }
}
