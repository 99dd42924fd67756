//! A lost GPU device (a driver reset, a GPU hang, Android reclaiming it) is replaced by the
//! engine at its next draw, with everything on it made again: wgpu's `Device::destroy` loses the
//! device as a driver would, on lavapipe and GL alike. Before the engine replaced it, the first
//! draw after the loss failed and the second panicked (an unscoped wgpu error), and nothing was
//! drawn again.

use phantogram::engine::{Engine, EngineConfig};
use phantogram::lamp::LampSetting;
use phantogram::library::ArtifactId;
use phantogram::render::Appearance;
use phantogram::ward::WardPreset;
use phantogram_integration::{drawn_frame, engine_or_skip};

const W: u32 = 180;
const H: u32 = 400;

/// Loses the engine's device. The engine learns of it when it next draws: wgpu tells its
/// device-lost callback when it next looks at the device, which the engine's draw does first
/// (without that look, the first draw failed and egui's painter panicked in the second).
fn lose_device(e: &Engine) {
    e.renderer().gpu().device.destroy();
}

/// The artifact under a raking lamp in a polished finish: the frame after the loss is the frame
/// before, pixel for pixel (the same scene made again on a new device), and so is the next.
#[test]
fn a_lost_device_is_replaced_and_the_same_frame_drawn() {
    let Some(mut e) = engine_or_skip(EngineConfig::default()) else {
        return;
    };
    e.resume_offscreen(W, H).unwrap();
    e.set_lamp(Some(LampSetting::raking()));
    e.show_appearance(Appearance::preset(WardPreset::Polished));
    let before = drawn_frame(&mut e);
    lose_device(&e);
    let after = drawn_frame(&mut e);
    assert_eq!(e.stats().devices_recovered, 1);
    assert!(!e.renderer().gpu().is_lost());
    let differing = before.chunks(4).zip(after.chunks(4)).filter(|(a, b)| a != b).count();
    assert_eq!(differing, 0, "{differing} pixels differ after the new device");
    assert_eq!(drawn_frame(&mut e), before);
    assert_eq!(e.stats().devices_recovered, 1, "one loss, one new device");
}

/// The Diorama (its own model, moved every frame) and the menu over it (egui's painter and its
/// textures) come back on the new device too: the frames go on, and show the menu as before.
#[test]
fn the_diorama_and_the_menu_come_back_on_a_new_device() {
    let config = EngineConfig {
        artifact: Some(ArtifactId::built_in("diorama")),
        ..EngineConfig::default()
    };
    let Some(mut e) = engine_or_skip(config) else { return };
    e.resume_offscreen(W, H).unwrap();
    assert!(e.open_menu());
    e.wait_for_thumbnails(std::time::Duration::from_secs(30));
    let before = drawn_frame(&mut e);
    lose_device(&e);
    let after = drawn_frame(&mut e);
    assert_eq!(e.stats().devices_recovered, 1);
    // The menu covers the frame: it is drawn as before, the gallery's pictures included (with
    // its egui context replaced but the pictures not loaded into the new one, 95.7 % of the
    // pixels were; with the context kept, none of the menu showed).
    let same = before.chunks(4).zip(after.chunks(4)).filter(|(a, b)| a == b).count();
    let share = same as f64 / f64::from(W * H);
    println!("{:.1} % of pixels as before the loss", 100.0 * share);
    assert!(share > 0.99, "{share}");
    let lit = after.chunks(4).filter(|p| p[..3].iter().any(|&c| c > 40)).count();
    assert!(lit > (W * H / 20) as usize, "{lit} lit pixels");
}
