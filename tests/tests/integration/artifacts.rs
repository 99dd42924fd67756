//! The artifact library driven through the engine as a shell drives it: a file opened from
//! bytes is imported, listed, shown and rendered; a damaged file is an on-screen error while the
//! previous artifact stays (switching a hundred times: `tests/tests/memory.rs`).

use std::time::Duration;

use phantogram::artifacts::LoadStatus;
use phantogram::engine::{Engine, EngineConfig};
use phantogram::library::{ArtifactId, Origin};
use phantogram_integration::{differing_pixels, drawn_frame, tap_at};
use phantogram_testkit::{Scratch, tetrahedron_glb};

const W: u32 = 180;
const H: u32 = 400;
const WAIT: Duration = Duration::from_secs(60);

/// An engine on `config` (see [`phantogram_integration::engine_or_skip`]).
fn start(config: EngineConfig) -> Option<Engine> {
    phantogram_integration::engine_or_skip(config)
}

fn engine(library: &Scratch) -> Option<Engine> {
    start(EngineConfig {
        library_dir: Some(library.to_path_buf()),
        ..EngineConfig::default()
    })
}

#[test]
fn an_opened_file_is_imported_listed_shown_and_a_damaged_one_keeps_the_previous() {
    let dir = Scratch::new("engine-artifacts");
    let Some(mut e) = engine(&dir) else { return };
    e.resume_offscreen(W, H).unwrap();
    let amphora = drawn_frame(&mut e);
    assert_eq!(
        e.model_info().artifact.as_ref().map(|a| a.id.to_string()).as_deref(),
        Some("builtin:amphora")
    );

    // Opened as a shell hands it over: a name and the content, here read on the loader's
    // thread as Android's content:// descriptors are.
    let glb = tetrahedron_glb(0.2, r#""copyright":"(c) Test museum","extras":{"title":"Tetrahedron"}"#);
    e.import_artifact_from(
        "tetra.glb",
        phantogram::artifacts::FileSource::Reader(Box::new(std::io::Cursor::new(glb))),
    );
    assert!(matches!(
        e.loading_status(),
        LoadStatus::Loading { .. } | LoadStatus::Idle
    ));
    assert!(e.wait_for_artifact(WAIT), "{:?}", e.loading_status());
    assert_eq!(e.loading_status(), LoadStatus::Idle);
    let info = e.model_info().clone();
    let entry = info.artifact.clone().expect("a library entry");
    assert_eq!(
        (entry.title.as_str(), entry.id.origin),
        ("Tetrahedron", Origin::Imported)
    );
    assert_eq!(info.triangles, 4);
    assert!(e.artifacts().iter().any(|a| a.id == entry.id), "listed");
    let tetra = drawn_frame(&mut e);
    assert!(differing_pixels(&amphora, &tetra) > 1000, "the new artifact is drawn");

    // A damaged file: an error to show, naming the file; the tetrahedron stays.
    let mut broken = tetrahedron_glb(0.3, "");
    broken.truncate(60);
    e.import_artifact("broken scan.glb", broken);
    assert!(!e.wait_for_artifact(WAIT));
    match e.loading_status() {
        LoadStatus::Failed { title, message } => {
            assert_eq!(title, "broken scan.glb");
            assert!(
                message.contains("broken-scan.glb") || message.contains("broken scan"),
                "{message}"
            );
        }
        other => panic!("expected a failure, got {other:?}"),
    }
    assert_eq!(e.model_info(), &info);
    assert_eq!(
        differing_pixels(&tetra, &drawn_frame(&mut e)),
        0,
        "the previous artifact stays on screen"
    );
    // Amphora, medal, tablet, the Diorama and the tetrahedron.
    assert_eq!(e.artifacts().len(), 5, "nothing damaged is listed");
    e.dismiss_message();
    assert_eq!(e.loading_status(), LoadStatus::Idle);

    // An id that is not in the library is a failure too, not a panic.
    e.select_artifact("imported:gone".parse().unwrap());
    assert!(!e.wait_for_artifact(WAIT));
    assert!(matches!(e.loading_status(), LoadStatus::Failed { .. }));

    // A cancelled load leaves everything as it was.
    e.select_artifact(ArtifactId::built_in("tablet"));
    e.cancel_loading();
    assert!(!e.wait_for_artifact(Duration::from_millis(200)));
    assert_eq!(e.loading_status(), LoadStatus::Idle);
    assert_eq!(e.model_info(), &info);

    // Removed from the library; a new engine on the same storage no longer lists it.
    e.remove_artifact(&entry.id).unwrap();
    assert!(!e.artifacts().iter().any(|a| a.id == entry.id));
}

#[test]
fn a_voyager_folder_is_shown_in_its_thumb_first_then_in_its_best_scan() {
    let dir = Scratch::new("engine-preview");
    let turtle = dir.join("bundled/turtle");
    std::fs::create_dir_all(&turtle).unwrap();
    let scene = br#"{"models":[{"derivatives":[
        {"usage":"Web3D","quality":"High","assets":[{"uri":"t-high.glb"}]},
        {"usage":"Web3D","quality":"Thumb","assets":[{"uri":"t-thumb.glb"}]}]}]}"#;
    std::fs::write(turtle.join("scene.svx.json"), scene).unwrap();
    std::fs::write(turtle.join("t-high.glb"), tetrahedron_glb(0.2, "")).unwrap();
    std::fs::write(turtle.join("t-thumb.glb"), tetrahedron_glb(0.2, "")).unwrap();
    let Some(mut e) = start(EngineConfig {
        bundled_dir: Some(dir.join("bundled")),
        ..EngineConfig::default()
    }) else {
        return;
    };
    e.resume_offscreen(W, H).unwrap();
    let amphora = drawn_frame(&mut e);
    let id: ArtifactId = "bundled:turtle".parse().unwrap();
    e.select_artifact(id.clone());
    // Frames as a shell draws them: the first that shows the turtle shows its thumb, with the
    // load still under way; later ones its best scan, and the load is over.
    let mut names = Vec::new();
    let deadline = std::time::Instant::now() + WAIT;
    while std::time::Instant::now() < deadline {
        let pixels = drawn_frame(&mut e);
        let info = e.model_info();
        if info.artifact.as_ref().map(|a| &a.id) == Some(&id) {
            if names.last() != Some(&info.name) {
                assert!(differing_pixels(&amphora, &pixels) > 1000, "the turtle is drawn");
                let loading = matches!(e.loading_status(), LoadStatus::Loading { .. });
                names.push(info.name.clone());
                assert_eq!(info.preview, loading, "{:?} while {:?}", info.name, e.loading_status());
            }
            if !info.preview {
                break;
            }
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    assert_eq!(names, ["t-thumb", "t-high"]);
    assert_eq!(e.loading_status(), LoadStatus::Idle);
    // The tools wait for the best scan only.
    e.select_artifact(ArtifactId::built_in("medal"));
    assert!(e.wait_for_artifact(WAIT));
    e.select_artifact(id);
    assert!(e.wait_for_artifact(WAIT));
    assert_eq!(
        (e.model_info().name.as_str(), e.model_info().preview),
        ("t-high", false)
    );
}

use crate::golden;

/// The menu a single tap opens and the status banner, driven by simulated taps: choose an
/// artifact, see a failure, dismiss it. Each screen is compared with its golden image.
#[test]
fn the_menu_and_the_banner_are_driven_by_taps() {
    use phantogram::anaglyph::Method;
    let dir = Scratch::new("engine-menu");
    let config = EngineConfig {
        library_dir: Some(dir.to_path_buf()),
        method: Method::Mono,
        ..EngineConfig::default()
    };
    let Some(mut e) = start(config) else { return };
    let (w, h) = (360, 800);
    e.resume_offscreen(w, h).unwrap();
    e.import_artifact(
        "votive_figure.glb",
        tetrahedron_glb(0.1, r#""copyright":"(c) Test museum","extras":{"license":"CC0"}"#),
    );
    assert!(e.wait_for_artifact(WAIT));
    e.select_artifact(ArtifactId::built_in("amphora"));
    assert!(e.wait_for_artifact(WAIT));
    let ms = 1_000_000;
    let mut t = 100;
    // One tap in the middle: the menu, once the double tap's time has passed.
    let centre = [w as f32 / 2.0, h as f32 / 2.0];
    {
        use phantogram::gesture::TouchPhase;
        e.touch(TouchPhase::Down, 0, centre[0], centre[1], t * ms);
        assert_eq!(e.touch(TouchPhase::Up, 0, centre[0], centre[1], (t + 80) * ms), None);
    }
    e.draw(Some((t + 200) * ms)).unwrap();
    assert!(!e.menu_open(), "not before a second tap could have come");
    e.draw(Some((t + 800) * ms)).unwrap();
    assert!(e.menu_open());
    // Each artifact's picture, drawn by the renderer and kept in the library's folder.
    assert!(e.wait_for_thumbnails(WAIT), "the gallery's pictures are made");
    let cached = std::fs::read_dir(dir.join("thumbnails")).map_or(0, |d| d.count());
    assert_eq!(cached, 5, "one picture per artifact (the Diorama's too), cached");
    e.draw(Some((t + 816) * ms)).unwrap();
    e.draw(Some((t + 832) * ms)).unwrap();
    t += 1000;
    let menu = e.last_frame().unwrap().2.to_vec();
    golden::check("menu-gallery", w, h, &menu, 3, 0.003);

    // Choose the medal: the menu closes and the medal is loaded.
    let medal = e.control_px("item:builtin:medal").expect("the medal's entry");
    tap_at(&mut e, medal, &mut t);
    assert!(!e.menu_open());
    assert!(e.wait_for_artifact(WAIT) || e.model_info().name == "medal");
    assert_eq!(e.model_info().name, "medal");

    // A damaged file: the banner says so over the medal; its OK button dismisses it.
    let mut broken = tetrahedron_glb(0.3, "");
    broken.truncate(60);
    e.import_artifact("broken.glb", broken);
    assert!(!e.wait_for_artifact(WAIT));
    e.draw(Some(t * ms)).unwrap();
    e.draw(Some((t + 16) * ms)).unwrap();
    t += 100;
    let banner = e.last_frame().unwrap().2.to_vec();
    golden::check("banner-failure", w, h, &banner, 3, 0.003);
    let ok = e.control_px("banner").expect("the banner is showing");
    // A tap elsewhere is the picture's (no menu while a gesture window is open), the banner's
    // own is the banner's.
    tap_at(&mut e, ok, &mut t);
    assert_eq!(e.loading_status(), LoadStatus::Idle, "dismissed");
    e.draw(Some((t + 1000) * ms)).unwrap();
    assert!(
        !e.menu_open(),
        "the banner's tap was not also a single tap on the picture"
    );

    // Share as a stereo pair: the menu closes and the shell is asked for its share sheet; the
    // picture it then takes is the pair without the menu.
    e.open_menu();
    e.draw(Some(t * ms)).unwrap();
    e.draw(Some((t + 16) * ms)).unwrap();
    t += 100;
    let share = e.control_px("share-pair").expect("the share button");
    tap_at(&mut e, share, &mut t);
    assert!(!e.menu_open());
    assert_eq!(
        e.take_shell_request(),
        Some(phantogram::engine::ShellRequest::Share(
            phantogram::engine::Snapshot::SideBySide
        ))
    );
    let (pw, ph, pair) = e.snapshot(phantogram::engine::Snapshot::SideBySide).unwrap();
    assert_eq!((pw, ph), (2 * w, h));
    let (_, _, picture) = e.snapshot(phantogram::engine::Snapshot::Composed).unwrap();
    assert_eq!(
        differing_pixels(&picture, e.last_frame().unwrap().2),
        0,
        "the view, no menu"
    );
    assert!(pair.len() == (4 * pw * ph) as usize);
    if let Ok(dir) = std::env::var("PHANTOGRAM_SAVE_UI") {
        for (name, px) in [("menu-gallery", &menu), ("banner-failure", &banner)] {
            image::save_buffer(
                std::path::Path::new(&dir).join(format!("{name}.png")),
                px,
                w,
                h,
                image::ExtendedColorType::Rgba8,
            )
            .unwrap();
        }
    }
}

/// The Smithsonian turtle with five Voyager annotations (shared data): markers drawn, and a tap
/// on one reads it; the card closes with its button.
#[test]
fn a_tap_on_an_annotation_marker_reads_it() {
    use phantogram::gesture::TouchPhase;
    let Some(data) = std::env::var_os("PHANTOGRAM_DATA") else {
        eprintln!("PHANTOGRAM_DATA not set: skipping");
        return;
    };
    let scene =
        std::path::Path::new(&data).join("models/heritage/smithsonian_nmnh_sea_turtle/scene-annotated.svx.json");
    let config = EngineConfig {
        model_path: Some(scene),
        method: phantogram::anaglyph::Method::Mono,
        ..EngineConfig::default()
    };
    let Some(mut e) = start(config) else { return };
    let titles: Vec<String> = e.model_info().annotations.iter().map(|a| a.title.clone()).collect();
    assert_eq!(titles, ["Head", "Carapace", "Front flipper", "Front flipper", "Rear"]);
    let (w, h) = (360, 800);
    e.resume_offscreen(w, h).unwrap();
    let ms = 1_000_000;
    e.draw(Some(10 * ms)).unwrap();
    let carapace = e.annotation_px(1).expect("the carapace's marker");
    assert!(carapace[0] > 0.0 && carapace[0] < w as f32 && carapace[1] > 0.0 && carapace[1] < h as f32);
    e.touch(TouchPhase::Down, 0, carapace[0], carapace[1], 100 * ms);
    e.touch(TouchPhase::Up, 0, carapace[0] + 2.0, carapace[1], 160 * ms);
    e.draw(Some(900 * ms)).unwrap();
    assert_eq!(e.open_annotation_index(), Some(1), "the tap on the carapace read it");
    assert!(!e.menu_open());
    e.draw(Some(916 * ms)).unwrap();
    e.draw(Some(932 * ms)).unwrap();
    let card = e.last_frame().unwrap().2.to_vec();
    golden::check("annotation-card", w, h, &card, 3, 0.003);
    if let Ok(dir) = std::env::var("PHANTOGRAM_SAVE_UI") {
        image::save_buffer(
            std::path::Path::new(&dir).join("annotation-card.png"),
            &card,
            w,
            h,
            image::ExtendedColorType::Rgba8,
        )
        .unwrap();
    }
}

/// The settings screen through the engine: opened from the menu, the glasses and the floor
/// chosen by taps, applied at once (the artifact shown again without its floor), saved, and in
/// force at the next start.
#[test]
fn settings_are_chosen_by_taps_applied_and_kept() {
    use phantogram::anaglyph::Method;
    let dir = Scratch::new("engine-settings");
    let calibration = dir.join("calibration.txt");
    std::fs::write(&calibration, "phantogram-calibration 1\nintroduced 1\n").unwrap();
    let config = || EngineConfig {
        library_dir: Some(dir.join("library")),
        calibration_path: Some(calibration.clone()),
        ..EngineConfig::default()
    };
    let Some(mut e) = start(config()) else { return };
    let (w, h) = (360, 800);
    e.resume_offscreen(w, h).unwrap();
    let mut t = 100;
    e.draw(Some(t * 1_000_000)).unwrap();
    let with_floor = drawn_frame(&mut e);
    assert!(e.open_menu());
    for _ in 0..2 {
        t += 16;
        e.draw(Some(t * 1_000_000)).unwrap();
    }
    // "How to use it": the gestures' card over the picture.
    let help = e.control_px("help").expect("the menu's help button");
    tap_at(&mut e, help, &mut t);
    assert!(!e.menu_open(), "the help card replaced the menu");
    let help_card = e.last_frame().unwrap().2.to_vec();
    assert!(differing_pixels(&with_floor, &help_card) > 5000, "no help card drawn");
    if let Ok(dir) = std::env::var("PHANTOGRAM_SAVE_UI") {
        image::save_buffer(
            std::path::Path::new(&dir).join("help-card.png"),
            &help_card,
            w,
            h,
            image::ExtendedColorType::Rgba8,
        )
        .unwrap();
    }
    assert!(e.open_menu());
    for _ in 0..2 {
        t += 16;
        e.draw(Some(t * 1_000_000)).unwrap();
    }
    let settings = e.control_px("settings").expect("the menu's settings button");
    tap_at(&mut e, settings, &mut t);
    let screen = e.last_frame().unwrap().2.to_vec();
    golden::check("menu-settings", w, h, &screen, 3, 0.003);
    let amber = e.control_px("amber-blue").expect("the amber/blue glasses");
    tap_at(&mut e, amber, &mut t);
    assert_eq!(e.method(), Method::DuboisAmberBlue);
    let floor = e.control_px("floor").expect("the floor switch");
    tap_at(&mut e, floor, &mut t);
    let surface = e.control_px("surface").expect("the surface-mode switch");
    tap_at(&mut e, surface, &mut t);
    assert!(!e.room_light_on(), "the studio's light by default");
    let room_light = e.control_px("room-light").expect("the light switch");
    tap_at(&mut e, room_light, &mut t);
    assert!(e.room_light_on(), "the room's light switched on");
    let done = e.control_px("done").expect("done");
    tap_at(&mut e, done, &mut t);
    // The amphora shown again without its floor (reloaded in the background: perhaps already
    // during the taps' frames).
    e.wait_for_artifact(WAIT);
    assert_eq!(e.loading_status(), LoadStatus::Idle);
    let without_floor = drawn_frame(&mut e);
    assert!(
        differing_pixels(&with_floor, &without_floor) > (w * h / 4) as usize,
        "the floor is still drawn"
    );
    let saved = std::fs::read_to_string(&calibration).unwrap();
    assert!(
        saved.contains("anaglyph dubois-amber-blue")
            && saved.contains("floor 0")
            && saved.contains("surface 1")
            && saved.contains("room_light 1"),
        "{saved}"
    );
    drop(e);
    let again = Engine::new(config()).unwrap();
    assert_eq!(again.method(), Method::DuboisAmberBlue, "kept for the next start");
    assert!(again.room_light_on(), "the room's light kept for the next start");
}

/// The system's text size reaches the screens: the menu's controls grow with it, within
/// [`phantogram::engine::TEXT_SCALE_RANGE`]; nonsense is refused.
#[test]
fn the_menu_follows_the_system_text_size() {
    let dir = Scratch::new("engine-text-scale");
    let Some(mut e) = engine(&dir) else { return };
    let (w, h) = (360, 800);
    e.resume_offscreen(w, h).unwrap();
    e.open_menu();
    let spacing = |e: &mut Engine| {
        e.draw(None).unwrap();
        e.draw(None).unwrap();
        let (open, help) = (e.control_px("open").unwrap(), e.control_px("help").unwrap());
        help[1] - open[1]
    };
    let normal = spacing(&mut e);
    e.set_text_scale(1.5).unwrap();
    let large = spacing(&mut e);
    assert!((large / normal - 1.5).abs() < 0.05, "{normal} → {large}");
    if let Ok(out) = std::env::var("PHANTOGRAM_SAVE_UI") {
        let (fw, fh, px) = e.last_frame().unwrap();
        image::save_buffer(
            std::path::Path::new(&out).join("menu-text-1.5.png"),
            px,
            fw,
            fh,
            image::ExtendedColorType::Rgba8,
        )
        .unwrap();
    }
    e.set_text_scale(9.0).unwrap();
    let most = spacing(&mut e);
    assert!((most / normal - 2.0).abs() < 0.05, "clamped to 2×: {normal} → {most}");
    assert!(e.set_text_scale(f32::NAN).is_err() && e.set_text_scale(0.0).is_err());
}

/// "Reduce motion", chosen in the settings: tilting the phone no longer moves the picture, a
/// finger's drag turns the artifact, and the choice is kept for the next start.
#[test]
fn with_reduce_motion_a_finger_turns_the_artifact_and_tilting_does_nothing() {
    use phantogram::sensors::SensorEvent;
    let dir = Scratch::new("engine-reduce-motion");
    let calibration = dir.join("calibration.txt");
    std::fs::write(&calibration, "phantogram-calibration 1\nintroduced 1\n").unwrap();
    let config = || EngineConfig {
        calibration_path: Some(calibration.clone()),
        ..EngineConfig::default()
    };
    let Some(mut e) = start(config()) else { return };
    let (w, h) = (360, 800);
    e.resume_offscreen(w, h).unwrap();
    let tilted = |deg: f32| {
        let a = deg.to_radians();
        phantogram::glam::Vec3::new(0.0, a.sin(), a.cos()) * 9.81
    };
    let mut t = 100;
    let ms = 1_000_000;
    let push = |e: &Engine, deg: f32, t: i64| {
        for k in 0..30 {
            e.inbox()
                .push(SensorEvent::accelerometer((t + k) * ms, tilted(deg)))
                .unwrap();
        }
    };
    push(&e, 30.0, t);
    t += 100;
    assert!(e.open_menu());
    e.draw(Some(t * ms)).unwrap();
    e.draw(Some((t + 16) * ms)).unwrap();
    t += 100;
    let settings = e.control_px("settings").expect("settings");
    tap_at(&mut e, settings, &mut t);
    let turn = e.control_px("turn-by-touch").expect("the reduce-motion switch");
    tap_at(&mut e, turn, &mut t);
    let done = e.control_px("done").expect("done");
    tap_at(&mut e, done, &mut t);
    assert!(e.session().turning_by_touch());
    e.draw(Some(t * ms)).unwrap();
    let still = drawn_frame(&mut e);
    // The phone tilts by 40°: the picture stays.
    push(&e, 70.0, t);
    t += 100;
    e.draw(Some(t * ms)).unwrap();
    let after_tilt = drawn_frame(&mut e);
    assert_eq!(differing_pixels(&still, &after_tilt), 0, "tilting moved the picture");
    // A finger drags 20 mm to the right: the artifact turns.
    use phantogram::gesture::TouchPhase;
    let px_per_mm = 420.0 / 25.4 * (w as f32 / 1080.0);
    let (x0, y0) = (w as f32 * 0.3, h as f32 * 0.5);
    e.touch(TouchPhase::Down, 0, x0, y0, t * ms);
    for k in 1..=10 {
        e.touch(
            TouchPhase::Move,
            0,
            x0 + k as f32 * 2.0 * px_per_mm,
            y0,
            (t + k * 16) * ms,
        );
    }
    e.touch(TouchPhase::Up, 0, x0 + 20.0 * px_per_mm, y0, (t + 200) * ms);
    t += 1000;
    e.draw(Some(t * ms)).unwrap();
    let turned = drawn_frame(&mut e);
    assert!(differing_pixels(&still, &turned) > 1000, "the drag did not turn it");
    // 20 mm at 90° per 60 mm: a third of a right angle to the right, none down.
    let (right, down) = e.session().touch_turn_rad().unwrap();
    assert!((right - 20.0 / 60.0 * std::f32::consts::FRAC_PI_2).abs() < 0.02 && down.abs() < 1e-3);
    let saved = std::fs::read_to_string(&calibration).unwrap();
    assert!(saved.contains("turn_by_touch 1"), "{saved}");
    drop(e);
    let again = Engine::new(config()).unwrap();
    assert!(again.session().turning_by_touch(), "kept for the next start");
}
