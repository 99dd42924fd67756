//! The calibration screens drawn by the GPU (lavapipe): the eye-reflection targets land on the
//! pixels the geometry puts them at, on a window half the phone's size (so egui's scale is
//! exercised too).

use phantogram::calibration_ui::{CalibrationUi, Overlay, Page, reflection_targets_px};
use phantogram::glam::Vec2;
use phantogram::render::Gpu;
use phantogram::screen::{DisplayRotation, PanelSpec, Screen};

const PHONE_PPP: f32 = 2.75;

#[test]
fn eye_reflection_targets_are_drawn_where_the_geometry_puts_them() {
    let gpu = match Gpu::headless() {
        Ok(g) => g,
        Err(e) if std::env::var_os("CI").is_none() => {
            eprintln!("no GPU adapter ({e}): skipping");
            return;
        }
        Err(e) => panic!("CI needs a GPU adapter (lavapipe): {e}"),
    };
    // Sideways, as the screens ask: a portrait phone (68 mm) is barely wider than an IPD.
    let screen = Screen::new(PanelSpec::TYPICAL_PHONE, DisplayRotation::Deg90).unwrap();
    let (w, h) = (screen.width_px() / 2, screen.height_px() / 2);
    let k = w as f32 / screen.width_px() as f32;
    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let texture = phantogram::render::target_texture(&gpu.device, "calibration test", w, h, format);
    let view = texture.create_view(&Default::default());
    // The frame underneath: black.
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: None,
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: &view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    gpu.queue.submit([encoder.finish()]);

    let ctx = egui::Context::default();
    let mut ui_state = CalibrationUi::default();
    ui_state.page = Page::EyeReflection;
    ui_state.target_separation_mm = 64.0;
    ui_state.target_offset_mm = Vec2::new(3.0, 10.0);
    let ppp = PHONE_PPP * k;
    ctx.set_pixels_per_point(ppp);
    let input = || egui::RawInput {
        screen_rect: Some(egui::Rect::from_min_size(
            egui::Pos2::ZERO,
            egui::vec2(w as f32 / ppp, h as f32 / ppp),
        )),
        ..Default::default()
    };
    // Three frames: the first ones lay out the panel.
    let mut overlay = Overlay::new(&gpu, format);
    for _ in 0..2 {
        let first = ctx.run_ui(input(), |ui| {
            ui_state.show(ui, &screen, PHONE_PPP);
        });
        overlay.paint(&gpu, &ctx, first, &view, [w, h]);
    }
    let output = ctx.run_ui(input(), |ui| {
        ui_state.show(ui, &screen, PHONE_PPP);
    });
    overlay.paint(&gpu, &ctx, output, &view, [w, h]);

    let pixels = phantogram::render::read_texture_level(&gpu, &texture, 0).expect("read back");
    let at = |p: Vec2| {
        assert!(
            p.x >= 0.0 && p.y >= 0.0 && p.x < w as f32 && p.y < h as f32,
            "{p} is off the frame"
        );
        let (x, y) = (p.x.floor() as u32, p.y.floor() as u32);
        let i = ((y * w + x) * 4) as usize;
        pixels[i..i + 3].iter().map(|&c| u32::from(c)).sum::<u32>() / 3
    };
    let targets = reflection_targets_px(&screen, 64.0, Vec2::new(3.0, 10.0)).map(|p| p * k);
    for t in targets {
        // The cross's centre and its arm (beyond the 10-point ring) are lit; between the arms,
        // inside the ring, it is dark: the cross is centred on the predicted pixel.
        let arm = 10.0 * ppp;
        println!(
            "target at {t}: centre {}, arm {}, beside {}",
            at(t),
            at(t + Vec2::new(arm * 1.3, 0.0)),
            at(t + Vec2::splat(arm * 0.4))
        );
        assert!(at(t) > 180, "no target drawn at {t}");
        assert!(at(t + Vec2::new(arm * 1.3, 0.0)) > 180, "horizontal arm missing at {t}");
        assert!(at(t + Vec2::splat(arm * 0.4)) < 40, "target not centred at {t}");
    }
    if let Ok(dir) = std::env::var("PHANTOGRAM_SAVE_UI") {
        image::RgbaImage::from_raw(w, h, pixels)
            .expect("size")
            .save(std::path::Path::new(&dir).join("calibration-eye.png"))
            .expect("saving");
    }
}

/// The phones' path through the engine: a three-finger tap opens the screens over the picture
/// (offscreen here, as the JVM and C bridge tests draw), the touches then drive them, "This is
/// straight on" takes the current pose, the calibration file keeps it, and a new engine (the next
/// start of the app) comes up with it. A damaged file gives the defaults and a warning.
#[test]
fn phones_open_the_screens_with_three_fingers_and_keep_what_they_set() {
    use phantogram::engine::{Engine, EngineConfig};
    use phantogram::gesture::{Gesture, TouchPhase};
    use phantogram::sensors::SensorEvent;

    let dir = phantogram_integration::scratch("engine-calibration");
    let path = dir.join("calibration.txt");
    // The first-run screens were seen (they have a test of their own below).
    std::fs::write(&path, "phantogram-calibration 1\nintroduced 1\n").unwrap();
    // A half-resolution panel of the same physical size: fewer pixels to shade on lavapipe.
    let panel = PanelSpec {
        width_px: 540,
        height_px: 1200,
        xdpi: 210.0,
        ydpi: 210.0,
    };
    let config = || EngineConfig {
        panel,
        method: phantogram::anaglyph::Method::Mono,
        calibration_path: Some(path.clone()),
        ..EngineConfig::default()
    };
    let Some(mut engine) = phantogram_integration::engine_or_skip(config()) else {
        return;
    };
    assert_eq!(
        engine.calibration_warning(),
        None,
        "a file with the first run only is no problem"
    );
    assert!(!engine.welcome_open(), "the first run is done");
    // Held 35° from flat, top edge raised.
    let tilt = 35f32.to_radians();
    let up = phantogram::glam::Vec3::new(0.0, tilt.sin(), tilt.cos());
    for k in 0..20 {
        engine
            .inbox()
            .push(SensorEvent::accelerometer(k * 10_000_000, up * 9.81))
            .unwrap();
    }
    engine.resume_offscreen(panel.width_px, panel.height_px).unwrap();
    let ms = 1_000_000;
    engine.draw(Some(200 * ms)).unwrap();
    let plain = engine.last_frame().unwrap().2.to_vec();

    let mut t = 300 * ms;
    let mut tap_fingers = |engine: &mut Engine, points: &[[f32; 2]]| {
        let mut gesture = None;
        for (i, p) in points.iter().enumerate() {
            assert_eq!(engine.touch(TouchPhase::Down, i as i32, p[0], p[1], t), None);
        }
        t += 80 * ms;
        for (i, p) in points.iter().enumerate() {
            gesture = gesture.or(engine.touch(TouchPhase::Up, i as i32, p[0], p[1], t));
        }
        t += 400 * ms;
        gesture
    };
    let three = [[150.0, 600.0], [270.0, 600.0], [390.0, 600.0]];
    assert_eq!(tap_fingers(&mut engine, &three), Some(Gesture::Calibrate));
    assert!(engine.calibration_open());
    // Two frames lay the menu out; the screens are painted over the picture.
    engine.draw(Some(1_000 * ms)).unwrap();
    engine.draw(Some(1_020 * ms)).unwrap();
    let with_screens = engine.last_frame().unwrap().2.to_vec();
    let changed = plain
        .chunks(4)
        .zip(with_screens.chunks(4))
        .filter(|(a, b)| a != b)
        .count();
    assert!(
        changed > plain.len() / 4 / 20,
        "the screens changed only {changed} pixels"
    );
    if let Ok(dir) = std::env::var("PHANTOGRAM_SAVE_UI") {
        image::RgbaImage::from_raw(panel.width_px, panel.height_px, with_screens.clone())
            .expect("size")
            .save(std::path::Path::new(&dir).join("calibration-engine-menu.png"))
            .expect("saving");
    }

    let flat = engine.control_px("flat").expect("the menu's straight-on button");
    // A touch the system takes back (Cancel) is no click.
    engine.touch(TouchPhase::Down, 0, flat[0], flat[1], 1_100 * ms);
    engine.draw(Some(1_120 * ms)).unwrap();
    engine.touch(TouchPhase::Cancel, 0, flat[0], flat[1], 1_140 * ms);
    engine.draw(Some(1_160 * ms)).unwrap();
    engine.draw(Some(1_180 * ms)).unwrap();
    assert_eq!(
        engine.session().flat_up_device(),
        None,
        "a cancelled touch pressed the button"
    );
    assert_eq!(
        tap_fingers(&mut engine, &[flat]),
        None,
        "touches reach the screens, not gestures"
    );
    engine.draw(Some(1_500 * ms)).unwrap();
    let saved = engine
        .session()
        .flat_up_device()
        .expect("the pose was taken as straight on");
    assert!(saved.distance(up) < 1e-3, "{saved} vs {up}");
    let text = std::fs::read_to_string(&path).expect("the calibration was saved");
    assert!(text.contains("flat_up_device"), "{text}");

    let close = engine.control_px("close").expect("the menu's close button");
    tap_fingers(&mut engine, &[close]);
    engine.draw(Some(2_000 * ms)).unwrap();
    assert!(!engine.calibration_open());
    assert_eq!(
        tap_fingers(&mut engine, &three),
        Some(Gesture::Calibrate),
        "gestures again"
    );

    // The next start comes up with the saved flat angle.
    drop(engine);
    let again = Engine::new(config()).unwrap();
    let restored = again.session().flat_up_device().expect("restored");
    assert!(restored.distance(up) < 1e-3, "{restored}");
    assert_eq!(again.calibration_warning(), None);

    std::fs::write(&path, "not a calibration\n").unwrap();
    let damaged = Engine::new(config()).unwrap();
    assert_eq!(damaged.session().flat_up_device(), None);
    let warning = damaged.calibration_warning().expect("a warning for the damaged file");
    assert!(warning.contains("calibration.txt"), "{warning}");
}

/// A target smaller than the panel (the desktop viewer's window standing in for the phone) shows
/// the phone's layout scaled down, and touches there still hit the controls.
#[test]
fn the_screens_keep_the_phones_layout_on_a_smaller_target() {
    use phantogram::engine::EngineConfig;
    use phantogram::gesture::TouchPhase;

    let panel = PanelSpec {
        width_px: 540,
        height_px: 1200,
        xdpi: 210.0,
        ydpi: 210.0,
    };
    let Some(mut engine) = phantogram_integration::engine_or_skip(EngineConfig {
        panel,
        method: phantogram::anaglyph::Method::Mono,
        ..EngineConfig::default()
    }) else {
        return;
    };
    let ms = 1_000_000;
    assert!(engine.open_calibration());
    engine.resume_offscreen(panel.width_px, panel.height_px).unwrap();
    engine.draw(Some(10 * ms)).unwrap();
    engine.draw(Some(20 * ms)).unwrap();
    let full = engine.control_px("close").expect("the close button");
    // A window of 3/8 of the panel's width, as the viewer's 405 px for a 1080 px phone.
    let (w, h) = (panel.width_px * 3 / 8, panel.height_px * 3 / 8);
    engine.resize(w, h).unwrap();
    engine.draw(Some(30 * ms)).unwrap();
    engine.draw(Some(40 * ms)).unwrap();
    let small = engine.control_px("close").expect("the close button");
    for i in 0..2 {
        assert!(
            (small[i] - full[i] * 3.0 / 8.0).abs() < 2.0,
            "the layout changed with the target: {full:?} → {small:?}"
        );
    }
    engine.touch(TouchPhase::Down, 0, small[0], small[1], 50 * ms);
    engine.draw(Some(60 * ms)).unwrap();
    engine.touch(TouchPhase::Up, 0, small[0], small[1], 70 * ms);
    engine.draw(Some(80 * ms)).unwrap();
    engine.draw(Some(90 * ms)).unwrap();
    assert!(
        !engine.calibration_open(),
        "the tap at {small:?} missed the close button"
    );
}

use crate::golden;

/// The first run, driven by taps as a new user would: the screens open by themselves, the
/// glasses check swaps the eyes when the glasses are on the other way round, Start takes the
/// pose held as straight on, the camera is explained before it is asked for, and the screens do
/// not open again.
#[test]
fn the_first_run_screens_check_the_glasses_and_take_the_pose() {
    use phantogram::engine::{Engine, EngineConfig, Snapshot};
    use phantogram::gesture::TouchPhase;
    use phantogram::sensors::SensorEvent;

    let dir = phantogram_integration::scratch("engine-first-run");
    let path = dir.join("calibration.txt");
    let config = |path: &std::path::Path| EngineConfig {
        method: phantogram::anaglyph::Method::DuboisRedCyan,
        calibration_path: Some(path.to_path_buf()),
        ..EngineConfig::default()
    };
    let Some(mut engine) = phantogram_integration::engine_or_skip(config(&path)) else {
        return;
    };
    assert!(engine.welcome_open(), "a first run opens on the welcome screens");
    // Held 40° from flat.
    let tilt = 40f32.to_radians();
    let up = phantogram::glam::Vec3::new(0.0, tilt.sin(), tilt.cos());
    let push = |engine: &Engine| {
        for k in 0..20 {
            engine
                .inbox()
                .push(SensorEvent::accelerometer(k * 10_000_000, up * 9.81))
                .unwrap();
        }
    };
    push(&engine);
    let (w, h) = (360, 800);
    engine.resume_offscreen(w, h).unwrap();
    let ms = 1_000_000;
    let mut t = 200;
    let frames = |engine: &mut Engine, n: i64, t: &mut i64| {
        for _ in 0..n {
            engine.draw(Some(*t * ms)).unwrap();
            *t += 16;
        }
    };
    frames(&mut engine, 3, &mut t);
    golden::check("welcome-intro", w, h, engine.last_frame().unwrap().2, 3, 0.003);
    let tap = |engine: &mut Engine, name: &str, t: &mut i64| {
        let p = engine
            .control_px(name)
            .unwrap_or_else(|| panic!("no {name} on the first-run screen"));
        engine.touch(TouchPhase::Down, 0, p[0], p[1], *t * ms);
        frames(engine, 1, t);
        engine.touch(TouchPhase::Up, 0, p[0], p[1], *t * ms);
        frames(engine, 3, t);
    };
    tap(&mut engine, "glasses", &mut t);
    golden::check("welcome-glasses", w, h, engine.last_frame().unwrap().2, 3, 0.003);
    // The right eye (left closed) sees the left ring: the red filter is on the right eye.
    tap(&mut engine, "left-ring", &mut t);
    assert!(engine.calibration().glasses_swapped);
    tap(&mut engine, "continue", &mut t);
    tap(&mut engine, "start", &mut t);
    assert!(!engine.welcome_open(), "Start closes the first-run screens");
    let straight_on = engine.session().flat_up_device().expect("Start took the pose");
    assert!(straight_on.distance(up) < 1e-3, "{straight_on} vs {up}");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.contains("introduced 1") && text.contains("glasses_swapped 1"),
        "{text}"
    );

    // Each eye's image went to the other filter: the pair is this engine's halves swapped, as
    // an engine with the glasses the right way round shows the same pose.
    let other = dir.join("other.txt");
    std::fs::write(&other, "phantogram-calibration 1\nintroduced 1\n").unwrap();
    let mut plain = Engine::new(config(&other)).unwrap();
    push(&plain);
    plain.resume_offscreen(w, h).unwrap();
    plain.draw(Some(t * ms)).unwrap();
    plain.calibrate_flat_angle().unwrap();
    engine.draw(Some(t * ms)).unwrap();
    let swapped_now = engine.snapshot(Snapshot::SideBySide).unwrap();
    let normal = plain.snapshot(Snapshot::SideBySide).unwrap();
    assert_eq!((swapped_now.0, swapped_now.1), (2 * w, h));
    let row = (2 * w * 4) as usize;
    let half = (w * 4) as usize;
    let mut same = 0usize;
    for y in 0..h as usize {
        let s = &swapped_now.2[y * row..(y + 1) * row];
        let n = &normal.2[y * row..(y + 1) * row];
        same += usize::from(s[..half] == n[half..] && s[half..] == n[..half]);
    }
    assert!(same > h as usize * 99 / 100, "only {same} of {h} rows swapped");

    // No camera permission yet: the core's camera page says why before the system asks, and
    // waits for the screen in front of it to close.
    engine.open_menu();
    engine.camera_permission_needed();
    frames(&mut engine, 2, &mut t);
    assert!(engine.control_px("allow-camera").is_none(), "the menu stays in front");
    tap(&mut engine, "close", &mut t);
    assert!(
        engine.control_px("allow-camera").is_some(),
        "then the camera page shows"
    );
    golden::check("welcome-camera", w, h, engine.last_frame().unwrap().2, 3, 0.003);
    assert_eq!(engine.take_shell_request(), None, "nothing asked of the system yet");
    tap(&mut engine, "not-now", &mut t);
    assert_eq!(engine.take_shell_request(), None, "\"Not now\" asks nothing");
    assert!(!engine.welcome_open());
    engine.camera_permission_needed();
    frames(&mut engine, 1, &mut t);
    tap(&mut engine, "allow-camera", &mut t);
    assert_eq!(
        engine.take_shell_request(),
        Some(phantogram::engine::ShellRequest::CameraPermission)
    );
    assert!(!engine.welcome_open(), "back to the picture while the system asks");

    // Not shown again.
    drop(engine);
    assert!(!Engine::new(config(&path)).unwrap().welcome_open());
}

/// The eye-reflection page darkens the glass: the screen is a mirror only where it emits no
/// light, so nothing of the picture may show behind the targets.
#[test]
fn the_eye_reflection_page_darkens_the_glass() {
    use phantogram::engine::{Engine, EngineConfig};
    use phantogram::gesture::TouchPhase;

    let Some(mut engine) = phantogram_integration::engine_or_skip(EngineConfig {
        method: phantogram::anaglyph::Method::Mono,
        ..EngineConfig::default()
    }) else {
        return;
    };
    let (w, h) = (270, 600);
    engine.resume_offscreen(w, h).unwrap();
    assert!(engine.open_calibration());
    let ms = 1_000_000;
    let mut t = 10;
    let draw = |engine: &mut Engine, t: &mut i64| {
        engine.draw(Some(*t * ms)).unwrap();
        *t += 16;
    };
    draw(&mut engine, &mut t);
    draw(&mut engine, &mut t);
    let eye = engine.control_px("eye").expect("the eye-distance button");
    engine.touch(TouchPhase::Down, 0, eye[0], eye[1], t * ms);
    draw(&mut engine, &mut t);
    engine.touch(TouchPhase::Up, 0, eye[0], eye[1], t * ms);
    for _ in 0..3 {
        draw(&mut engine, &mut t);
    }
    assert!(engine.control_px("accept").is_some(), "on the eye-reflection page");
    // The upper third (above the page's controls): dark but for the two targets' thin strokes.
    let (_, _, pixels) = engine.last_frame().unwrap();
    let upper = &pixels[..(w * h / 3 * 4) as usize];
    let lit = upper.chunks(4).filter(|p| p[..3].iter().any(|&c| c > 24)).count();
    let fraction = lit as f64 / (upper.len() / 4) as f64;
    assert!(fraction < 0.05, "{:.1} % of the upper screen lit", fraction * 100.0);
}
