//! The core's screens through a screen reader's eyes (TalkBack, VoiceOver), driven through the
//! engine as the shells drive it: every control on the menu and the settings has a name and
//! lies where its tap target is, and activating one does what tapping it does.

use phantogram::calibration_ui::accessibility::{AccessNode, AccessRole};
use phantogram::engine::{Engine, EngineConfig};
use phantogram_testkit::Scratch;

fn draw_frames(e: &mut Engine, t_ms: &mut i64, n: usize) {
    for _ in 0..n {
        *t_ms += 16;
        e.draw(Some(*t_ms * 1_000_000)).unwrap();
    }
}

/// The node whose rectangle holds the tap point of control `name`.
fn node_at(e: &Engine, name: &str) -> AccessNode {
    let [x, y] = e.control_px(name).unwrap_or_else(|| panic!("no control {name}"));
    e.accessibility_nodes()
        .iter()
        .filter(|n| n.role != AccessRole::Text && n.role != AccessRole::Image)
        .find(|n| n.bounds_px[0] <= x && x <= n.bounds_px[2] && n.bounds_px[1] <= y && y <= n.bounds_px[3])
        .cloned()
        .unwrap_or_else(|| panic!("no node at {name}'s tap point {x},{y}: {:#?}", e.accessibility_nodes()))
}

/// Every control a screen reader can land on says what it is.
fn every_control_is_named(e: &Engine, page: &str) {
    let nodes = e.accessibility_nodes();
    assert!(!nodes.is_empty(), "{page}: nothing to read");
    for n in nodes {
        eprintln!("{page}: {:?} {:?} {:?} {:?}", n.role, n.label, n.value, n.checked);
        assert!(!n.label.trim().is_empty(), "{page}: a control without a name: {n:?}");
        let [x0, y0, x1, y1] = n.bounds_px;
        assert!(x0 < x1 && y0 < y1, "{page}: {n:?}");
    }
}

/// An engine in `dir` whose viewer has been through the first run (so the bare picture shows).
fn introduced_engine(dir: &Scratch) -> Option<Engine> {
    let calibration = dir.join("calibration.txt");
    std::fs::write(&calibration, "phantogram-calibration 1\nintroduced 1\n").unwrap();
    phantogram_integration::engine_or_skip(EngineConfig {
        library_dir: Some(dir.join("library")),
        calibration_path: Some(calibration),
        ..EngineConfig::default()
    })
}

#[test]
fn a_screen_reader_finds_names_and_activates_the_screens_controls() {
    let dir = Scratch::new("engine-accessibility");
    let Some(mut e) = introduced_engine(&dir) else { return };
    let (w, h) = (360, 800);
    e.resume_offscreen(w, h).unwrap();
    let mut t = 100;
    draw_frames(&mut e, &mut t, 1);

    // The bare picture: one node, the whole surface, naming the artifact; activating it opens
    // the menu (a screen reader's double tap, where a plain tap would).
    let nodes = e.accessibility_nodes().to_vec();
    assert_eq!(nodes.len(), 1, "{nodes:?}");
    let picture = &nodes[0];
    assert_eq!(picture.role, AccessRole::Image);
    assert!(
        picture.label.contains("Amphora") || picture.label.contains("amphora"),
        "{picture:?}"
    );
    assert_eq!(picture.bounds_px, [0.0, 0.0, w as f32, h as f32]);
    let generation = e.accessibility_generation();
    assert!(!e.accessibility_click(picture.id + 1000), "an unknown id does nothing");
    assert!(e.accessibility_click(picture.id));
    assert!(e.menu_open());
    draw_frames(&mut e, &mut t, 2);
    assert!(
        e.accessibility_generation() > generation,
        "the shells are told to read again"
    );
    every_control_is_named(&e, "menu");
    assert!(
        e.accessibility_nodes().iter().all(|n| n.role != AccessRole::Image),
        "the picture is under the menu, not beside it"
    );

    // The settings button, where its tap lands, activated.
    let settings = node_at(&e, "settings");
    assert_eq!(settings.role, AccessRole::Button);
    assert!(settings.clickable);
    assert!(e.accessibility_click(settings.id));
    draw_frames(&mut e, &mut t, 2);
    assert!(e.control_px("floor").is_some(), "the settings page is open");
    every_control_is_named(&e, "settings");

    // The floor switch reads its state and turns by activation.
    let floor = node_at(&e, "floor");
    // A toggle (egui's selectable button): read as checked or not, whatever it is drawn as.
    assert_eq!(floor.checked, Some(true), "{floor:?}");
    assert!(
        matches!(floor.role, AccessRole::Button | AccessRole::CheckBox),
        "{floor:?}"
    );
    assert!(e.accessibility_click(floor.id));
    draw_frames(&mut e, &mut t, 2);
    assert_eq!(node_at(&e, "floor").checked, Some(false), "switched off");

    // The glasses are a choice of several: the chosen one says so.
    let amber = node_at(&e, "amber-blue");
    assert_eq!(amber.checked, Some(false), "{amber:?}");
    assert!(e.accessibility_click(amber.id));
    draw_frames(&mut e, &mut t, 2);
    assert_eq!(e.method(), phantogram::anaglyph::Method::DuboisAmberBlue);
    assert_eq!(node_at(&e, "amber-blue").checked, Some(true));

    // The material page (sliders named by the text above them) and the calibration's first
    // page, through the menu by activation alone.
    for (button, page) in [("material", "material"), ("calibrate", "calibration")] {
        let done = e.control_px("done");
        if let Some([x, y]) = done {
            let close = e
                .accessibility_nodes()
                .iter()
                .find(|n| n.bounds_px[0] <= x && x <= n.bounds_px[2] && n.bounds_px[1] <= y && y <= n.bounds_px[3])
                .map(|n| n.id);
            assert!(close.is_some_and(|id| e.accessibility_click(id)), "{page}: done");
            draw_frames(&mut e, &mut t, 2);
        }
        if !e.menu_open() {
            let picture = e.accessibility_nodes().first().map(|n| n.id).unwrap();
            assert!(e.accessibility_click(picture), "{page}: the picture opens the menu");
            draw_frames(&mut e, &mut t, 2);
        }
        let open = node_at(&e, button);
        assert!(e.accessibility_click(open.id));
        draw_frames(&mut e, &mut t, 2);
        assert!(!e.menu_open(), "{page} replaced the menu");
        every_control_is_named(&e, page);
        if page == "material" {
            let sliders: Vec<AccessNode> = e
                .accessibility_nodes()
                .iter()
                .filter(|n| n.role == AccessRole::Slider)
                .cloned()
                .collect();
            assert!(sliders.len() >= 3, "the material's sliders");
            // A swipe up on "Metal" (0 %) makes the artifact metallic.
            let metal = sliders.iter().find(|n| n.label == "Metal").expect("the metal slider");
            assert_eq!(metal.value.as_deref(), Some("0"));
            assert!(e.accessibility_adjust(metal.id, 5));
            draw_frames(&mut e, &mut t, 2);
            let after = e
                .accessibility_nodes()
                .iter()
                .find(|n| n.id == metal.id)
                .cloned()
                .unwrap();
            assert_eq!(after.value.as_deref(), Some("5"), "five steps of 1 %: {after:?}");
            assert!(!e.accessibility_adjust(open.id, 1), "a button is not adjusted");
        }
    }
}

/// The first run's page, before anything was set: its buttons are read and work.
#[test]
fn the_first_run_page_is_read_and_started_by_a_screen_reader() {
    let dir = Scratch::new("engine-accessibility-first-run");
    let Some(mut e) = phantogram_integration::engine_or_skip(EngineConfig {
        library_dir: Some(dir.join("library")),
        calibration_path: Some(dir.join("calibration.txt")),
        ..EngineConfig::default()
    }) else {
        return;
    };
    e.resume_offscreen(360, 800).unwrap();
    let mut t = 100;
    draw_frames(&mut e, &mut t, 2);
    every_control_is_named(&e, "welcome");
    let start = node_at(&e, "start");
    assert_eq!(start.role, AccessRole::Button);
    assert!(e.accessibility_click(start.id));
    draw_frames(&mut e, &mut t, 2);
    assert!(e.control_px("start").is_none(), "started");
    assert_eq!(
        e.accessibility_nodes().len(),
        1,
        "the bare picture: {:?}",
        e.accessibility_nodes()
    );
}

/// On a sliver of a surface (split screen, a surface mid-resize) every page still lays out and
/// draws: laid out at a least size and cut off, not squeezed into negative widths (egui
/// asserted on the material page of a 1-pixel surface: found by the random JNI calls).
#[test]
fn every_page_draws_on_a_sliver_of_a_surface() {
    let dir = Scratch::new("engine-sliver");
    let Some(mut e) = introduced_engine(&dir) else { return };
    let mut t = 100;
    for (w, h) in [(360, 800), (1, 1), (3, 400), (400, 2), (40, 40)] {
        e.resume_offscreen(w, h).unwrap();
        for page in ["Material", "Settings", "Calibration", "How to use it"] {
            assert!(e.open_menu());
            draw_frames(&mut e, &mut t, 2);
            let id = e
                .accessibility_nodes()
                .iter()
                .find(|n| n.label.starts_with(page))
                .map(|n| n.id)
                .unwrap_or_else(|| panic!("{w}×{h}: no {page} in the menu"));
            assert!(e.accessibility_click(id));
            // The click's frame, then a card's first (egui sizes a new area unseen), then one
            // to read.
            draw_frames(&mut e, &mut t, 3);
            assert!(!e.accessibility_nodes().is_empty(), "{w}×{h}: {page} is read");
            // Back to the bare picture for the next page.
            let done = e
                .accessibility_nodes()
                .iter()
                .find(|n| matches!(n.label.as_str(), "Done" | "Close" | "OK"))
                .map(|n| n.id);
            if let Some(id) = done {
                e.accessibility_click(id);
                draw_frames(&mut e, &mut t, 3);
            }
        }
    }
}

/// A banner over the bare picture (a failed import): the picture is read first, then the
/// banner, and the nodes' generation stands still while nothing changes — the shells re-read
/// only on a change.
#[test]
fn under_a_banner_the_picture_and_the_banner_are_read_and_stand_still() {
    let dir = Scratch::new("engine-banner-reader");
    let Some(mut e) = introduced_engine(&dir) else { return };
    e.resume_offscreen(360, 800).unwrap();
    let mut t = 100;
    draw_frames(&mut e, &mut t, 1);
    e.import_artifact("broken scan.glb", b"glTF\x02\x00\x00\x00 not a model".to_vec());
    e.wait_for_artifact(std::time::Duration::from_secs(60));
    assert!(matches!(
        e.loading_status(),
        phantogram::engine::LoadStatus::Failed { .. }
    ));
    draw_frames(&mut e, &mut t, 3);
    let nodes = e.accessibility_nodes().to_vec();
    assert_eq!(nodes.first().map(|n| n.role), Some(AccessRole::Image), "{nodes:?}");
    assert!(nodes.iter().any(|n| n.label == "OK" && n.clickable), "{nodes:?}");
    let generation = e.accessibility_generation();
    draw_frames(&mut e, &mut t, 3);
    assert_eq!(
        e.accessibility_generation(),
        generation,
        "nothing changed, yet the shells were told to re-read"
    );
}
