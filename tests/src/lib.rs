//! Helpers shared by the integration tests in `tests/tests/`.
//!
//! External recordings live outside the repository; tests find them through the environment
//! variable [`DATA_ENV`] (`.ci/run` sets it to `../shared/data`). Without it, the tests that need
//! them print a notice and pass vacuously *only* when the variable is unset; when it is set but
//! wrong, they fail.

use std::path::PathBuf;

/// Environment variable naming the external data folder.
pub const DATA_ENV: &str = "PHANTOGRAM_DATA";

/// The external data folder, if configured. Panics (failing the test) if the variable is set but
/// does not name a folder, so a misconfigured CI cannot silently skip.
pub fn data_dir() -> Option<PathBuf> {
    let dir = PathBuf::from(std::env::var_os(DATA_ENV)?);
    assert!(dir.is_dir(), "{DATA_ENV}={} is not a folder", dir.display());
    Some(dir)
}

/// `$PHANTOGRAM_DATA/name`, or `None` after printing that the tests needing it are skipped.
pub fn data_subdir(name: &str) -> Option<PathBuf> {
    match data_dir() {
        Some(d) => Some(d.join(name)),
        None => {
            eprintln!("{DATA_ENV} is not set: skipping the tests on {name}");
            None
        }
    }
}

/// The shared HDR environments (`$PHANTOGRAM_DATA/env/*.hdr|exr`), sorted; `None` after printing
/// that the tests needing them are skipped. Fails the test if the folder holds none.
pub fn shared_environments() -> Option<Vec<PathBuf>> {
    let dir = data_subdir("env")?;
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .expect("env folder")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "hdr" || e == "exr"))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no environments in {}", dir.display());
    Some(files)
}

/// Checks a read of a lobe's room light against the read it replaced, in every shared
/// environment ([`shared_environments`]): `errors` gives, for one loaded environment, each case's
/// name and both reads' errors against the truth (`phantogram::ibl::accuracy`); each is printed
/// and the test fails where the new read is not the nearer. Checks nothing, after
/// [`shared_environments`]' notice, where the data is not configured.
pub fn nearer_in_every_shared_room(
    errors: impl Fn(&phantogram::ibl::Environment) -> Vec<(String, phantogram::ibl::accuracy::ReadErrors)>,
) {
    let Some(files) = shared_environments() else {
        return;
    };
    for path in &files {
        let env = phantogram::ibl::Environment::load(path).expect("environment");
        let file = path.file_name().unwrap_or_default().to_string_lossy();
        let cases = errors(&env);
        if cases.is_empty() {
            println!("{file:28} nothing to compare");
        }
        for (case, e) in cases {
            println!("{file:28} {case}: before {:.3}, now {:.3}", e.before, e.now);
            assert!(e.now < e.before, "{file}, {case}: {e:?}");
        }
    }
}

pub use phantogram_testkit::Scratch;

/// An engine on `config`; `None` (the test skips, saying so) where no GPU adapter is found,
/// except under CI (`CI` set), where that fails the test: `.ci/run` installs lavapipe. Any
/// other failure to make it fails the test everywhere.
pub fn engine_or_skip(config: phantogram::engine::EngineConfig) -> Option<phantogram::engine::Engine> {
    match phantogram::engine::Engine::new(config) {
        Ok(e) => Some(e),
        Err(e) if std::env::var_os("CI").is_none() && e.to_string().contains("adapter") => {
            eprintln!("no GPU adapter ({e}): skipping");
            None
        }
        Err(e) => panic!("no engine (CI needs a GPU adapter: lavapipe): {e}"),
    }
}

/// Draws a frame now and returns a copy of its pixels (RGBA8, the offscreen target's size).
pub fn drawn_frame(e: &mut phantogram::engine::Engine) -> Vec<u8> {
    e.draw(None).unwrap();
    e.last_frame().unwrap().2.to_vec()
}

/// A headless GPU (lavapipe on the desktop); `None` (the test skips, saying so) where no adapter
/// is found, except under CI (`CI` set), where that fails the test.
pub fn gpu_or_skip() -> Option<phantogram::render::Gpu> {
    match phantogram::render::Gpu::headless() {
        Ok(g) => Some(g),
        Err(e) if std::env::var_os("CI").is_none() => {
            eprintln!("no GPU adapter ({e}): skipping rendering tests");
            None
        }
        Err(e) => panic!("CI needs a GPU adapter (lavapipe): {e}"),
    }
}

/// MediaPipe's face models from `$PHANTOGRAM_MODELS` (written by `cargo xtask models`), or
/// `None` (the test skips, saying so) when it is unset; set but unloadable fails the test.
pub fn face_models() -> Option<std::sync::Arc<phantogram::face::FaceModels>> {
    let Some(dir) = std::env::var_os("PHANTOGRAM_MODELS") else {
        eprintln!("PHANTOGRAM_MODELS is not set: skipping (run `cargo xtask models`)");
        return None;
    };
    Some(std::sync::Arc::new(
        phantogram::face::FaceModels::load(std::path::Path::new(&dir))
            .expect("PHANTOGRAM_MODELS is set: the models must load"),
    ))
}

/// RGBA pixels of two equal-sized frames that differ by more than 8 levels in some channel:
/// how much of a picture a change changed.
pub fn differing_pixels(a: &[u8], b: &[u8]) -> usize {
    a.chunks(4)
        .zip(b.chunks(4))
        .filter(|(p, q)| p.iter().zip(q.iter()).any(|(x, y)| x.abs_diff(*y) > 8))
        .count()
}

/// A finger's tap at display pixel `px` as a shell sends it, at `*t_ms` on the sensor clock:
/// down, a frame, up 80 ms later, three frames to settle; `*t_ms` moves a second on.
pub fn tap_at(e: &mut phantogram::engine::Engine, px: [f32; 2], t_ms: &mut i64) {
    use phantogram::gesture::TouchPhase;
    let ms = 1_000_000;
    e.touch(TouchPhase::Down, 0, px[0], px[1], *t_ms * ms);
    e.draw(Some((*t_ms + 16) * ms)).expect("draw");
    e.touch(TouchPhase::Up, 0, px[0], px[1], (*t_ms + 80) * ms);
    for k in 0..3 {
        e.draw(Some((*t_ms + 96 + 16 * k) * ms)).expect("draw");
    }
    *t_ms += 1000;
}

/// The default session's view of a phone held still, tilted `tilt_deg` towards the viewer and
/// with gravity's sideways component `sideways` (of its unit vector, before normalising): the
/// oblique view the rendering tests draw.
pub fn held_view(tilt_deg: f32, sideways: f32) -> phantogram::FrameView {
    let mut s = phantogram::Session::new(phantogram::SessionConfig::default()).expect("the default session");
    let tilt = tilt_deg.to_radians();
    let up = phantogram::glam::Vec3::new(sideways, tilt.sin(), tilt.cos()).normalize();
    s.push(phantogram::sensors::SensorEvent::accelerometer(1, up * 9.81))
        .expect("a valid event");
    s.frame().expect("a frame")
}

/// A scratch folder unique to this process and `name`, emptied first, removed when the returned
/// guard drops unless the test is failing (see [`Scratch`]).
pub fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("it-{name}"))
}

/// Decompresses a gzip stream.
pub fn gunzip(gz: &[u8]) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let mut out = Vec::new();
    flate2::read::MultiGzDecoder::new(gz).read_to_end(&mut out)?;
    Ok(out)
}

/// Compresses bytes into a gzip stream.
pub fn gzip(bytes: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    enc.write_all(bytes).expect("writing to memory");
    enc.finish().expect("writing to memory")
}

/// `img` resampled (bilinear, grey 40 outside) into a 640 × 480 frame whose pixel `q` shows `img`
/// at `centre + R(angle) · (q − (320, 240)) / scale`: `centre` in the middle, enlarged by `scale`,
/// turned by `angle_rad` (pixel centres at half-integers). The face tests' synthetic camera
/// frames: a photo moved, scaled and rolled as a hand-held phone would see it.
pub fn warp_into_frame(
    img: &image::RgbaImage,
    centre: phantogram::glam::Vec2,
    scale: f32,
    angle_rad: f32,
) -> image::RgbaImage {
    use phantogram::glam::Vec2;
    let (w, h) = img.dimensions();
    let (s, c) = angle_rad.sin_cos();
    image::RgbaImage::from_fn(640, 480, |x, y| {
        let q = (Vec2::new(x as f32 + 0.5, y as f32 + 0.5) - Vec2::new(320.0, 240.0)) / scale;
        let p = centre + Vec2::new(c * q.x - s * q.y, s * q.x + c * q.y) - Vec2::splat(0.5);
        let (x0, y0) = (p.x.floor(), p.y.floor());
        let (fx, fy) = (p.x - x0, p.y - y0);
        let mut acc = [0.0f32; 3];
        for (dx, dy, wt) in [
            (0, 0, (1.0 - fx) * (1.0 - fy)),
            (1, 0, fx * (1.0 - fy)),
            (0, 1, (1.0 - fx) * fy),
            (1, 1, fx * fy),
        ] {
            let (xi, yi) = (x0 as i64 + dx, y0 as i64 + dy);
            let px = if xi >= 0 && yi >= 0 && xi < w as i64 && yi < h as i64 {
                img.get_pixel(xi as u32, yi as u32).0
            } else {
                [40, 40, 40, 255]
            };
            for k in 0..3 {
                acc[k] += f32::from(px[k]) * wt;
            }
        }
        image::Rgba([acc[0] as u8, acc[1] as u8, acc[2] as u8, 255])
    })
}
