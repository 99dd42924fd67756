//! A lamp the visitor places over the diorama: a raking light across the clay tablet matches its
//! golden frame (its inscription's cuts in light and shadow), a finger's drag moves the lamp in
//! the next frame drawn (a tap still opens the menu), and taking the lamp away gives the room's
//! light back to the pixel.

use crate::golden;

use phantogram::anaglyph::Method;
use phantogram::engine::EngineConfig;
use phantogram::gesture::TouchPhase;
use phantogram::lamp::LampSetting;

const SIZE: (u32, u32) = (180, 400);

fn engine() -> Option<phantogram::engine::Engine> {
    let config = EngineConfig {
        method: Method::Mono,
        artifact: Some("builtin:tablet".parse().expect("id")),
        ..EngineConfig::default()
    };
    let mut e = phantogram_integration::engine_or_skip(config)?;
    e.resume_offscreen(SIZE.0, SIZE.1).expect("offscreen");
    Some(e)
}

#[test]
fn a_raking_light_across_the_tablet_matches_its_golden_frame() {
    let Some(mut e) = engine() else { return };
    e.draw(Some(0)).expect("draw");
    let room_light = e.last_frame().expect("frame").2.to_vec();
    e.set_lamp(Some(LampSetting::raking()));
    e.draw(Some(0)).expect("draw");
    let raking = e.last_frame().expect("frame").2.to_vec();
    golden::check("lamp-raking-tablet", SIZE.0, SIZE.1, &raking, 3, 0.003);
    let differing = phantogram_integration::differing_pixels(&room_light, &raking);
    assert!(
        differing > (SIZE.0 * SIZE.1 / 4) as usize,
        "the lamp changed the light ({differing} pixels)"
    );
    e.set_lamp(None);
    e.draw(Some(0)).expect("draw");
    assert_eq!(
        e.last_frame().expect("frame").2,
        &room_light[..],
        "the room's light again"
    );
}

#[test]
fn a_drag_moves_the_lamp_in_the_next_frame() {
    let Some(mut e) = engine() else { return };
    e.set_lamp(Some(LampSetting::raking()));
    e.draw(Some(0)).expect("draw");
    let screen = e.session().config().screen;
    let start = e.renderer().lamp.expect("a lamp").position_m;
    assert!(
        (start.x + 0.5 * screen.width_m()).abs() < 1e-5,
        "starts at the left edge: {start}"
    );
    // A finger down at a quarter of the width, then dragged to three quarters down the screen.
    let (w, h) = (SIZE.0 as f32, SIZE.1 as f32);
    e.touch(TouchPhase::Down, 0, 0.25 * w, 0.5 * h, 10_000_000);
    e.touch(TouchPhase::Move, 0, 0.75 * w, 0.75 * h, 20_000_000);
    e.draw(Some(30_000_000)).expect("draw");
    let moved = e.renderer().lamp.expect("a lamp").position_m;
    let want = (0.25 * screen.width_m(), -0.25 * screen.height_m());
    assert!(
        (moved.x - want.0).abs() < 1e-4 && (moved.y - want.1).abs() < 1e-4,
        "the lamp is under the finger: {moved} vs {want:?}"
    );
    assert_eq!(moved.z, start.z, "at its height");
    // A drag is no gesture: nothing else happened.
    assert_eq!(e.touch(TouchPhase::Up, 0, 0.75 * w, 0.75 * h, 40_000_000), None);
    // A tap still opens the menu, and does not move the lamp.
    let mut t = 1000i64;
    phantogram_integration::tap_at(&mut e, [0.5 * w, 0.2 * h], &mut t);
    // A single tap is known once no second one followed (a frame later than the double tap's gap).
    e.draw(Some(t * 1_000_000)).expect("draw");
    assert!(e.menu_open(), "a single tap opens the menu with a lamp on");
    let still = e.renderer().lamp.expect("a lamp").position_m;
    assert!(
        still.distance(moved) < 1e-6,
        "the tap left the lamp where it was: {still}"
    );
}

#[test]
fn the_menu_puts_a_lamp_on_and_takes_it_away() {
    let Some(mut e) = engine() else { return };
    let mut t = 0i64;
    for on in [true, false] {
        assert!(e.open_menu());
        for _ in 0..2 {
            t += 16;
            e.draw(Some(t * 1_000_000)).expect("draw");
        }
        let lamp = e.control_px("lamp").expect("the menu's lamp button");
        phantogram_integration::tap_at(&mut e, lamp, &mut t);
        assert!(!e.menu_open(), "the menu closed, for the finger to move the lamp");
        assert_eq!(e.lamp().is_some(), on);
        assert_eq!(e.renderer().lamp.is_some(), on, "in the frame drawn since");
    }
}
