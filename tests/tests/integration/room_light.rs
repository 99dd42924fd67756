//! The live room light reconstructs a room's diffuse light from camera frames: a synthetic phone
//! camera (`phantogram_lab::synthetic_camera`, auto-exposed, clipped, 8-bit sRGB) sweeps each
//! HDR environment in `$PHANTOGRAM_DATA/env` as a visitor turning on the spot would, the frames
//! go into `RoomCapture` with the device's orientation, and the nine SH coefficients of the map
//! give the environment's irradiance (relative RMS over 2000 normals spread evenly over the
//! sphere): within 5 % once the sweep has seen the whole sphere, with an exposure bracket whose
//! exposures the platform reports; at 80 % seen the figures are printed and guarded (the goal
//! of 5 % there is reached by every room with the sweep started at azimuth 0, not at every other
//! start: see the TODO). Auto-exposure alone, exposures
//! estimated, is printed for comparison (up to the unknown overall scale), and so is the error at
//! 80 % seen with the map's level set as the renderer sets it (its mean luminance made the
//! room's: `RoomLightWorker` scales each map to the light it replaces).
//!
//! The same sweep with a rear camera's frames beside the front one's (where a phone runs both at
//! once) sees the room sooner and is within the goal turns sooner.
//!
//! Needs the external data (`PHANTOGRAM_DATA`); without it the tests print a notice and return.
//!
//! And the engine lit by two live rooms (generated here, so without the data too): a camera
//! sweep into each through `Engine::room_light_frame_oriented` lights the frames drawn after it
//! by that room: the generated studio the engine starts with gives the same frame again (to the
//! pixel, almost: the capture reproduces it), a sunset a very different one (golden frames
//! `room-light-studio`, `-sunset`).

use phantogram::anaglyph::Method;
use phantogram::camera::CameraFacing;
use phantogram::engine::{EngineConfig, ShellRequest};
use phantogram::glam::{Mat3, Quat, Vec3};
use phantogram::ibl::{Environment, IrradianceSh};

use crate::golden;
use phantogram_lab::synthetic_camera::{Metering, SyntheticCamera};

/// The short frame of the room light's bracket: the highlights just below clipping, down to
/// 1/10 000 of the average exposure (a phone's shortest exposure at its lowest gain against an
/// indoor auto-exposure, 1/20 000 s at ISO 50 against 1/30 s at ISO 400, is about 1/5000 of it).
const BRACKET: Metering = Metering::Highlights { min_ratio: 1e-4 };
use phantogram_roomlight::{CaptureFrame, CaptureParams, RoomCapture};

/// Relative RMS difference of two irradiances over the normals, after scaling `got` by `scale`.
fn relative_rms(got: &IrradianceSh, want: &IrradianceSh, scale: f32, normals: &[Vec3]) -> f32 {
    let (mut err, mut norm) = (0.0f64, 0.0f64);
    for n in normals {
        let (g, w) = (got.irradiance(*n), want.irradiance(*n));
        for c in 0..3 {
            err += f64::from(g[c] * scale - w[c]).powi(2);
            norm += f64::from(w[c]).powi(2);
        }
    }
    (err / norm).sqrt() as f32
}

/// The scale that best fits `got` to `want` (least squares over the normals).
fn best_scale(got: &IrradianceSh, want: &IrradianceSh, normals: &[Vec3]) -> f32 {
    let (mut gw, mut gg) = (0.0f64, 0.0f64);
    for n in normals {
        let (g, w) = (got.irradiance(*n), want.irradiance(*n));
        for c in 0..3 {
            gw += f64::from(g[c] * w[c]);
            gg += f64::from(g[c] * g[c]);
        }
    }
    (gw / gg.max(1e-30)) as f32
}

/// The device held with its screen's normal (the front camera's axis) along `dir`, the phone's
/// top towards the zenith where it can be.
fn holding(dir: Vec3) -> Quat {
    let z = dir.normalize();
    let x = Vec3::Z.cross(z).try_normalize().unwrap_or(Vec3::X);
    let y = z.cross(x);
    Quat::from_mat3(&Mat3::from_cols(x, y, z))
}

/// The azimuth the sweep starts at, degrees: 0, or `PHANTOGRAM_SWEEP_START_DEG` to measure how
/// much the figures at 80 % seen depend on where the visitor starts turning (they do, a lot:
/// `benchmarks/ibl.md`, "eighth session").
fn sweep_start_deg() -> f32 {
    std::env::var("PHANTOGRAM_SWEEP_START_DEG")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0.0)
}

/// A visitor turning on the spot, the phone at one tilt per turn, then the next, in 15° steps of
/// azimuth: first nearly flat in the hand as a phantogram is held (the front camera sees the
/// ceiling), then raised towards upright (the walls behind the visitor), then lowered past it
/// (the floor, seen last and least).
fn sweep() -> Vec<Quat> {
    let (mut poses, start_deg) = (Vec::new(), sweep_start_deg());
    for elevation_deg in [85.0f32, 60.0, 35.0, 10.0, -15.0, -40.0, -65.0, -85.0] {
        for step in 0..24 {
            let az = (step as f32 * 15.0 + start_deg).to_radians();
            let el = elevation_deg.to_radians();
            poses.push(holding(Vec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin())));
        }
    }
    poses
}

#[test]
fn a_camera_sweep_reconstructs_each_rooms_diffuse_light() {
    let Some(files) = phantogram_integration::shared_environments() else {
        return;
    };
    let camera = SyntheticCamera::phone_front();
    let normals = phantogram_geometry::sphere::fibonacci(2000);
    let (mut worst_full, mut worst_80) = ((0.0f32, String::new()), (0.0f32, String::new()));
    for path in &files {
        let name = path.file_name().unwrap_or_default().to_string_lossy().into_owned();
        let env = Environment::load(path).expect("environment");
        let want = IrradianceSh::from_environment(&env);
        let beyond_reach = beyond_the_brackets_reach(&env, &camera);
        let mut line = Vec::new();
        for bracketed in [true, false] {
            let mut capture = RoomCapture::new(CaptureParams::default());
            let mut at_80 = None;
            // Early in the sweep (bracketed): the irradiance error at these shares seen, for
            // `benchmarks/ibl.md`'s table of the unseen floor's fill.
            let mut early_marks = [0.1f32, 0.2, 0.3, 0.5].into_iter().peekable();
            let mut early = Vec::new();
            for (k, pose) in sweep().into_iter().enumerate() {
                // Bracketed: every other frame the short one, exposures reported (the platform
                // sets them). Not: auto-exposure only, exposures estimated from the overlap.
                let metering = if bracketed && k % 2 == 1 {
                    BRACKET
                } else {
                    Metering::Average
                };
                let (frame, exposure) = camera.capture(&env, pose, metering, k as i64 * 33_000_000);
                capture
                    .add(&CaptureFrame {
                        image: frame.as_frame(),
                        world_from_camera: camera.world_from_camera(pose),
                        exposure: bracketed.then_some(exposure),
                    })
                    .expect("frame");
                if bracketed && early_marks.next_if(|&m| capture.coverage() >= m).is_some() {
                    let got = IrradianceSh::from_environment(&capture.environment());
                    early.push(format!(
                        "{:.0} % seen: {:.1} %",
                        capture.coverage() * 100.0,
                        relative_rms(&got, &want, 1.0, &normals) * 100.0
                    ));
                }
                if at_80.is_none() && capture.coverage() >= 0.8 {
                    let oracle = IrradianceSh::from_environment(&best_one_value_fill(&env, &capture, &want, &normals));
                    let map = capture.environment();
                    // As the renderer gets it: the map's level set to the mean luminance of the
                    // light it replaces (`RoomLightWorker`), here the room's own.
                    let level = env.mean_luminance() / map.mean_luminance();
                    at_80 = Some((k + 1, IrradianceSh::from_environment(&map), oracle, level));
                }
            }
            if bracketed {
                println!("{name} early (bracketed): {}", early.join(", "));
            }
            let (frames_80, sh_80, oracle_80, level_80) = at_80.expect("the sweep sees 80 % of the sphere");
            let full = IrradianceSh::from_environment(&capture.environment());
            let error = |got: &IrradianceSh| {
                let scale = if bracketed {
                    1.0
                } else {
                    best_scale(got, &want, &normals)
                };
                relative_rms(got, &want, scale, &normals)
            };
            let (e80, efull) = (error(&sh_80), error(&full));
            let oracle = relative_rms(&oracle_80, &want, 1.0, &normals);
            let levelled = relative_rms(&sh_80, &want, level_80, &normals);
            line.push(format!(
                "{}: {:.1} % at 80 % seen ({frames_80} frames; best fill of one value: {:.1} %; at the mean level: {:.1} %), {:.1} % at {:.0} % seen",
                if bracketed {
                    "bracketed"
                } else {
                    "auto-exposed (up to scale)"
                },
                e80 * 100.0,
                oracle * 100.0,
                levelled * 100.0,
                efull * 100.0,
                capture.coverage() * 100.0
            ));
            if bracketed {
                if e80 > worst_80.0 {
                    worst_80 = (e80, name.clone());
                }
                if efull > worst_full.0 && !beyond_reach {
                    worst_full = (efull, name.clone());
                }
            }
        }
        let reach = if beyond_reach {
            " [beyond the bracket's reach]".to_string()
        } else {
            String::new()
        };
        println!("{name}{reach}: {}", line.join("; "));
    }
    println!(
        "worst (bracketed): {:.1} % at full coverage ({}; rooms within the bracket's reach), {:.1} % at 80 % ({})",
        worst_full.0 * 100.0,
        worst_full.1,
        worst_80.0 * 100.0,
        worst_80.1
    );
    // The capture itself (linearising, exposure, blending, highlights): within 5 % once the
    // sweep has seen everything, in every room whose light the bracket can hold.
    assert!(
        worst_full.0 <= 0.05,
        "{:.1} % off in {}",
        worst_full.0 * 100.0,
        worst_full.1
    );
    // Issue 20's goal: within 5 % at 80 % seen. The unseen fifth is mostly the floor, filled
    // from the band seen nearest to it on its side of the horizon, that band's mean estimated
    // for every azimuth from the band seen everywhere above it (`fill.rs`, `band_means`): at
    // this start within 3.4 % in every room (the apartment; 5.9 % with the partly seen band's
    // plain mean, 8.9 % with the mean of everything seen below the horizon, 20.6 % with the
    // nearest-seen fill). TODO(issue 20): this holds for the start at 0 only. Started at each
    // of eight azimuths (every 45°, `PHANTOGRAM_SWEEP_START_DEG`), 8 of the 72 room × start
    // cases miss 5 %, the apartment reaching 9.6 % (mean 2.1 % over all; `benchmarks/ibl.md`),
    // and this bound fails there.
    assert!(
        worst_80.0 <= 0.05,
        "{:.1} % off at 80 % seen in {}",
        worst_80.0 * 100.0,
        worst_80.1
    );
}

/// Whether `env` has a sun brighter than `camera`'s short exposure can hold (peak over mean
/// luminance beyond 0.9 / (middle grey × the bracket's floor)): clipped in every frame, as on a
/// phone.
fn beyond_the_brackets_reach(env: &Environment, camera: &SyntheticCamera) -> bool {
    // The plain mean over texels, as this was first judged (not weighted by solid angle).
    let luminance = |c: &[f32; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    let mean = env.texels.iter().map(luminance).sum::<f32>() / env.texels.len() as f32;
    let peak = env.texels.iter().flat_map(|c| c.iter().copied()).fold(0.0f32, f32::max);
    let Metering::Highlights { min_ratio } = BRACKET else {
        unreachable!()
    };
    peak / mean > 0.9 / (camera.middle_grey * min_ratio)
}

/// The `k`th frame of a bracketed sweep (every other frame the short one, exposures reported)
/// that `camera` takes of `env` with the device at `pose`, added to `capture`.
fn add_bracketed(capture: &mut RoomCapture, camera: &SyntheticCamera, env: &Environment, pose: Quat, k: usize) {
    let metering = if k % 2 == 1 { BRACKET } else { Metering::Average };
    let (frame, exposure) = camera.capture(env, pose, metering, k as i64 * 33_000_000);
    capture
        .add(&CaptureFrame {
            image: frame.as_frame(),
            world_from_camera: camera.world_from_camera(pose),
            exposure: Some(exposure),
        })
        .expect("frame");
}

/// What a sweep with `cameras` (each camera's frame taken at every pose) made of a room: after
/// each turn of the sweep (24 poses at one tilt), the share seen and the irradiance error.
fn sweep_with(
    cameras: &[SyntheticCamera],
    env: &Environment,
    want: &IrradianceSh,
    normals: &[Vec3],
) -> Vec<(f32, f32)> {
    let mut capture = RoomCapture::new(CaptureParams::default());
    let mut turns = Vec::new();
    for (k, pose) in sweep().into_iter().enumerate() {
        for camera in cameras {
            add_bracketed(&mut capture, camera, env, pose, k);
        }
        if (k + 1) % 24 == 0 {
            let got = IrradianceSh::from_environment(&capture.environment());
            turns.push((capture.coverage(), relative_rms(&got, want, 1.0, normals)));
        }
    }
    turns
}

/// Issue 20: "the rear camera where the platform allows both at once". The same sweep as above
/// (held nearly flat first, then raised through upright, the floor last), with the rear camera's
/// frames beside the front one's: after every turn at least as much of the room is seen, and the
/// light is within the goal's 5 % (or just over the capture's own floor in that room, where that
/// is higher) turns sooner and stays there. (Not turn by turn nearer the
/// truth: early on, with the ceiling and floor seen and the walls not, two rooms are a few
/// points further off than with the ceiling alone. At 80 % seen the two are not alike either:
/// with both cameras the unseen fifth then is the band round the horizon, where a room's windows
/// and lamps are.) Each shared room, bracketed, exposures reported; the figures are printed for
/// `benchmarks/ibl.md` (`--nocapture`; `PHANTOGRAM_SWEEP_START_DEG` as above).
#[test]
fn the_rear_camera_beside_the_front_one_sees_the_room_sooner() {
    let Some(files) = phantogram_integration::shared_environments() else {
        return;
    };
    let (front, rear) = (SyntheticCamera::phone_front(), SyntheticCamera::phone_rear());
    let normals = phantogram_geometry::sphere::fibonacci(2000);
    let mut failures = Vec::new();
    for path in &files {
        let name = path.file_name().unwrap_or_default().to_string_lossy().into_owned();
        let env = Environment::load(path).expect("environment");
        let want = IrradianceSh::from_environment(&env);
        let alone = sweep_with(&[front], &env, &want, &normals);
        let both = sweep_with(&[front, rear], &env, &want, &normals);
        let show = |turns: &[(f32, f32)]| {
            turns
                .iter()
                .map(|(seen, error)| format!("{:.0} % seen {:.1} %", seen * 100.0, error * 100.0))
                .collect::<Vec<_>>()
                .join(", ")
        };
        println!("{name} after each turn, front only: {}", show(&alone));
        println!("{name} after each turn, front and rear: {}", show(&both));
        for (turn, ((seen_alone, _), (seen_both, _))) in alone.iter().zip(&both).enumerate() {
            if seen_both < seen_alone {
                failures.push(format!(
                    "{name}, turn {}: {seen_both} seen with both, {seen_alone} alone",
                    turn + 1
                ));
            }
        }
        // The first turn from which the light stays within the goal's 5 %, or within a tenth
        // over what the capture reaches in that room once the front camera alone has seen it
        // all, if that is more: at some starts the esplanade's sun, clipped in the frames that
        // catch it near their edge, leaves it 5.0 % off with the whole sphere seen, whichever
        // cameras saw it.
        let floor = alone.last().map_or(0.0, |(_, error)| *error);
        let bound = 0.05f32.max(1.1 * floor);
        let within = |turns: &[(f32, f32)]| {
            turns
                .iter()
                .rposition(|(_, error)| *error > bound)
                .map_or(1, |last_over| last_over + 2)
        };
        let (turn_alone, turn_both) = (within(&alone), within(&both));
        println!(
            "{name}: within {:.1} % from turn {turn_both} with both, {turn_alone} with the front camera alone",
            bound * 100.0
        );
        if turn_both >= turn_alone {
            failures.push(format!(
                "{name}: within {:.1} % from turn {turn_both} with both, {turn_alone} alone",
                bound * 100.0
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("; "));
}

/// `env` with every texel the capture has not seen replaced by the one value (per colour
/// channel, not negative) that brings the irradiance nearest to `want` over `normals`: the best
/// any fill of one value can do, however it were estimated (a reference for the capture's own
/// fill; a phone could not know it). Irradiance is linear in radiance, so that value is a least-
/// squares fit of the unseen part's irradiance per unit radiance to what the seen part leaves.
fn best_one_value_fill(env: &Environment, capture: &RoomCapture, want: &IrradianceSh, normals: &[Vec3]) -> Environment {
    let (map_w, map_h) = (capture.width(), capture.height());
    // Both are equirectangular maps with the same convention (column 0 east, row 0 the zenith).
    let seen = |i: usize| {
        capture.seen(
            (i % env.width) * map_w / env.width,
            (i / env.width) * map_h / env.height,
        )
    };
    let with_unseen = |value: [f32; 3], keep_seen: bool| Environment {
        width: env.width,
        height: env.height,
        texels: (0..env.texels.len())
            .map(|i| match (seen(i), keep_seen) {
                (true, true) => env.texels[i],
                (true, false) => [0.0; 3],
                (false, _) => value,
            })
            .collect(),
    };
    let seen_part = IrradianceSh::from_environment(&with_unseen([0.0; 3], true));
    let per_unit = IrradianceSh::from_environment(&with_unseen([1.0; 3], false));
    let mut best = [0.0f32; 3];
    for (c, value) in best.iter_mut().enumerate() {
        let (mut num, mut den) = (0.0f64, 0.0f64);
        for n in normals {
            let u = f64::from(per_unit.irradiance(*n)[c]);
            num += u * f64::from(want.irradiance(*n)[c] - seen_part.irradiance(*n)[c]);
            den += u * u;
        }
        *value = (num / den.max(1e-30)).max(0.0) as f32;
    }
    with_unseen(best, true)
}

/// A warm evening room made here: a low orange sun in the west, a dim blue sky, a dark floor.
fn sunset_room() -> Environment {
    let (width, height) = (128usize, 64usize);
    let mut env = Environment {
        width,
        height,
        texels: Vec::with_capacity(width * height),
    };
    let sun = Vec3::new(-1.0, 0.1, 0.12).normalize();
    for y in 0..height {
        for x in 0..width {
            let d = env.direction(x, y);
            let glow = 6.0 * ((d.dot(sun) - 1.0) / 0.02).exp();
            let sky = if d.z > 0.0 { 0.05 + 0.1 * d.z } else { 0.02 };
            env.texels
                .push([sky * 0.6 + glow, sky * 0.8 + glow * 0.45, sky * 1.4 + glow * 0.1]);
        }
    }
    env
}

#[test]
fn the_engine_is_lit_by_the_room_its_camera_sweeps() {
    let (w, h) = (180, 400);
    let camera = SyntheticCamera::phone_front();
    let mut frames = Vec::new();
    for (name, room) in [("studio", Environment::studio()), ("sunset", sunset_room())] {
        let config = EngineConfig {
            method: Method::Mono,
            room_light: true,
            ..EngineConfig::default()
        };
        let Some(mut engine) = phantogram_integration::engine_or_skip(config) else {
            return;
        };
        // The room light is on: the shell is asked for the rear camera beside the front one.
        assert_eq!(engine.take_shell_request(), Some(ShellRequest::RearCamera(true)));
        assert_eq!(engine.take_shell_request(), None);
        engine.resume_offscreen(w, h).expect("offscreen");
        engine.draw(Some(0)).expect("draw");
        let before = engine.last_frame().expect("frame").2.to_vec();
        // Every other pose of the sweep: 15° apart is more than a frame needs.
        for (k, pose) in sweep().into_iter().enumerate().filter(|(k, _)| k % 2 == 0) {
            let metering = if k % 4 == 2 { BRACKET } else { Metering::Average };
            let (frame, _) = camera.capture(&room, pose, metering, k as i64 * 100_000_000);
            // As the phones hand frames over: YUV, converted on the worker; every fourth frame's
            // exposure reported apart, as Camera2's capture results come (matched by time).
            let mut frame = phantogram_lab::synthetic_camera::as_yuv420(&frame);
            if k % 8 == 0
                && let Some(exposure) = frame.exposure.take()
            {
                engine
                    .room_light()
                    .expect("on")
                    .note_exposure(CameraFacing::Front, frame.capture_t_ns, exposure);
            }
            assert!(engine.room_light_frame_oriented(frame, CameraFacing::Front, pose));
            let worker = engine.room_light().expect("on");
            assert!(
                worker.wait_until(0, std::time::Duration::from_secs(120)),
                "the worker keeps up"
            );
        }
        let worker = engine.room_light().expect("on");
        let (blended, refused, updates) = worker.counts();
        assert_eq!(refused, 0);
        assert!(blended > 50 && updates > 5, "{blended} frames, {updates} updates");
        assert!(
            worker.coverage() > 0.9,
            "the sweep saw {:.2} of the room",
            worker.coverage()
        );
        engine.draw(Some(0)).expect("draw");
        assert!(
            engine.stats().room_light_updates >= 1,
            "the newest update reached the renderer"
        );
        let lit = engine.last_frame().expect("frame").2.to_vec();
        let changed = phantogram_integration::differing_pixels(&before, &lit);
        let gain = engine.stats().room_light_gain.expect("an update reached the renderer");
        println!("{name}: {blended} frames, {updates} updates, {changed} pixels changed, level gain {gain:.3}");
        if name == "studio" {
            // The room keeps the level of the light it replaces; here that is the room itself.
            assert!(
                (gain - 1.0).abs() < 0.05,
                "the studio seen by the camera scaled by {gain}"
            );
            // The engine starts lit by this very studio: the room it captured lights it the same.
            assert!(
                changed < (w * h / 100) as usize,
                "{changed} pixels changed by the same room"
            );
        } else {
            assert!(
                changed > (w * h / 4) as usize,
                "only {changed} pixels changed by the sunset"
            );
        }
        golden::check(&format!("room-light-{name}"), w, h, &lit, 3, 0.003);
        // A lost device: the new one is lit by the room as the old one was (before, by the
        // studio or the configured file until the worker's next update).
        engine.renderer().gpu().device.destroy();
        engine.draw(Some(0)).expect("draw");
        assert_eq!(engine.stats().devices_recovered, 1);
        let relit = engine.last_frame().expect("frame").2.to_vec();
        assert_eq!(
            phantogram_integration::differing_pixels(&lit, &relit),
            0,
            "{name}: relit"
        );
        // The settings' "Light: the studio's": the frame is lit as before the sweep again, and
        // camera frames are no longer taken.
        engine.set_room_light(false);
        assert!(!engine.room_light_on());
        // ... and the rear camera, whose frames would now be dropped, may stop.
        assert_eq!(engine.take_shell_request(), Some(ShellRequest::RearCamera(false)));
        engine.set_room_light(false);
        assert_eq!(engine.take_shell_request(), None, "no change, nothing asked");
        engine.draw(Some(0)).expect("draw");
        let studio_again = engine.last_frame().expect("frame").2.to_vec();
        assert_eq!(phantogram_integration::differing_pixels(&before, &studio_again), 0);
        let (frame, _) = camera.capture(&room, Quat::IDENTITY, Metering::Average, 1);
        assert!(!engine.room_light_frame_oriented(frame, CameraFacing::Front, Quat::IDENTITY));
        frames.push(lit);
    }
    if frames.len() == 2 {
        let differing = phantogram_integration::differing_pixels(&frames[0], &frames[1]);
        assert!(differing > 5000, "two rooms, two lights ({differing} pixels differ)");
    }
}

/// A synthetic stress case beyond the shared rooms: a dim grey room with one lamp a few texels
/// across and 20 000 times brighter than the walls (most of the light), placed off the poles,
/// high and low. With the bracket and the whole sphere seen, the irradiance is within 5 %.
#[test]
fn a_tiny_bright_lamp_anywhere_is_captured() {
    let camera = SyntheticCamera::phone_front();
    let normals = phantogram_geometry::sphere::fibonacci(2000);
    for (azimuth_deg, elevation_deg) in [(30.0f32, 20.0f32), (200.0, -50.0), (110.0, 70.0)] {
        let (width, height) = (256usize, 128usize);
        let mut room = Environment {
            width,
            height,
            texels: vec![[0.2, 0.19, 0.18]; width * height],
        };
        let (az, el) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
        let lamp = Vec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
        for y in 0..height {
            for x in 0..width {
                if room.direction(x, y).dot(lamp) > 0.99985 {
                    room.texels[y * width + x] = [4000.0, 3800.0, 3300.0];
                }
            }
        }
        let want = IrradianceSh::from_environment(&room);
        let mut capture = RoomCapture::new(CaptureParams::default());
        for (k, pose) in sweep().into_iter().enumerate() {
            add_bracketed(&mut capture, &camera, &room, pose, k);
        }
        let got = IrradianceSh::from_environment(&capture.environment());
        let err = relative_rms(&got, &want, 1.0, &normals);
        println!("lamp at {azimuth_deg}°, {elevation_deg}°: {:.1} % off", err * 100.0);
        assert!(
            err <= 0.05,
            "lamp at {azimuth_deg}°, {elevation_deg}°: {:.1} % off",
            err * 100.0
        );
    }
}
