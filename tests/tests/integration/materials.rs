//! The material screen's changes as the engine shows them: each Ward preset on the default
//! artifact matches its golden frame (the floor keeps its own material), a change shows in the
//! very next frame, an artifact's change is remembered across engines through the library's
//! `appearances.json`, and the screen itself is reached from the menu and driven by taps.

use crate::golden;

use phantogram::anaglyph::Method;
use phantogram::appearance::Appearance;
use phantogram::engine::{Engine, EngineConfig};
use phantogram::glam::{Quat, Vec3};
use phantogram::sensors::SensorEvent;
use phantogram::ward::WardPreset;
use phantogram_integration::differing_pixels;

const SIZE: (u32, u32) = (180, 400);
/// When the frames are drawn: after a second held still at the tilt.
const FRAME_T_NS: i64 = 1_000_000_000;

/// Holds the phone tilted 50° towards the viewer (as a phantogram is held) for a second, so that
/// the frames show the artifact's side, where the materials differ most.
fn hold_tilted(engine: &Engine) {
    let inbox = engine.inbox();
    let up = Quat::from_rotation_x(50f32.to_radians()).inverse() * Vec3::Z * 9.81;
    for k in 0..=200i64 {
        let t = k * 5_000_000;
        inbox.push(SensorEvent::accelerometer(t, up)).expect("accelerometer");
        inbox.push(SensorEvent::gyroscope(t, Vec3::ZERO)).expect("gyroscope");
    }
}

fn frame(engine: &mut Engine) -> Vec<u8> {
    engine.draw(Some(FRAME_T_NS)).expect("draw");
    engine.last_frame().expect("a frame").2.to_vec()
}

/// A mono engine on a `w × h` offscreen surface with the material screen opened from the menu
/// by taps, and the sensor clock (ms) after them; `None` without a GPU.
fn material_screen(w: u32, h: u32) -> Option<(Engine, i64)> {
    let config = EngineConfig {
        method: Method::Mono,
        ..EngineConfig::default()
    };
    let mut e = phantogram_integration::engine_or_skip(config)?;
    e.resume_offscreen(w, h).expect("offscreen");
    let mut t = 0i64;
    assert!(e.open_menu());
    for _ in 0..2 {
        t += 16;
        e.draw(Some(t * 1_000_000)).expect("draw");
    }
    let material = e.control_px("material").expect("the menu's material button");
    phantogram_integration::tap_at(&mut e, material, &mut t);
    Some((e, t))
}

#[test]
fn each_preset_matches_its_golden_frame_and_shows_in_the_next_frame() {
    let config = EngineConfig {
        method: Method::Mono,
        ..EngineConfig::default()
    };
    let Some(mut engine) = phantogram_integration::engine_or_skip(config) else {
        return;
    };
    engine.resume_offscreen(SIZE.0, SIZE.1).expect("offscreen");
    hold_tilted(&engine);
    let authored = frame(&mut engine);
    // The floor's corner (top left: nothing of the artifact there) never changes.
    let corner = |f: &[u8]| f[..4].to_vec();
    for preset in WardPreset::ALL {
        engine
            .set_appearance(Appearance::preset(preset))
            .expect("in memory: nothing to save");
        let shown = frame(&mut engine);
        assert!(
            differing_pixels(&authored, &shown) > 500,
            "{preset:?} changed the artifact in the next frame"
        );
        assert_eq!(corner(&shown), corner(&authored), "{preset:?} left the floor alone");
        golden::check(
            &format!("material-{}", preset.name().replace(' ', "-")),
            SIZE.0,
            SIZE.1,
            &shown,
            3,
            0.003,
        );
    }
    // Back to the glTF's own material: the first frame again.
    engine.set_appearance(Appearance::default()).expect("reset");
    assert_eq!(differing_pixels(&authored, &frame(&mut engine)), 0);
}

#[test]
fn a_change_is_remembered_for_its_artifact() {
    let library = phantogram_testkit::Scratch::new("materials-library");
    let config = || EngineConfig {
        library_dir: Some(library.to_path_buf()),
        ..EngineConfig::default()
    };
    let Some(mut engine) = phantogram_integration::engine_or_skip(config()) else {
        return;
    };
    let coat = Appearance {
        clear_coat: 1.0,
        tint: [0.8, 0.9, 1.0],
        ..Appearance::default()
    };
    engine.set_appearance(coat).expect("saved");
    assert_eq!(engine.appearance(), coat);
    drop(engine);
    let mut engine = Engine::new(config()).expect("a second engine");
    assert_eq!(engine.appearance(), coat, "remembered for the default artifact");
    // Another artifact comes with its own (here: none), and the first keeps its change.
    engine.select_artifact("builtin:medal".parse().expect("id"));
    assert!(engine.wait_for_artifact(std::time::Duration::from_secs(60)));
    assert!(engine.appearance().is_default());
    engine.select_artifact("builtin:amphora".parse().expect("id"));
    assert!(engine.wait_for_artifact(std::time::Duration::from_secs(60)));
    assert_eq!(engine.appearance(), coat);
}

#[test]
fn the_material_screen_is_reached_from_the_menu_and_driven_by_taps() {
    let (w, h) = (360, 800);
    let Some((mut e, mut t)) = material_screen(w, h) else {
        return;
    };
    let screen = e.last_frame().expect("frame").2.to_vec();
    if let Ok(dir) = std::env::var("PHANTOGRAM_SAVE_UI") {
        image::save_buffer(
            std::path::Path::new(&dir).join("material-screen.png"),
            &screen,
            w,
            h,
            image::ExtendedColorType::Rgba8,
        )
        .expect("save");
    }
    golden::check("menu-material", w, h, &screen, 3, 0.003);
    let polished = e.control_px("preset-polished").expect("the polished preset");
    phantogram_integration::tap_at(&mut e, polished, &mut t);
    assert_eq!(e.appearance(), Appearance::preset(WardPreset::Polished));
    let done = e.control_px("preset-matte").and(e.control_px("done"));
    assert!(done.is_some(), "the screen stays open for more changes");
}

#[test]
fn a_change_that_cannot_be_saved_is_shown_and_reported() {
    let library = phantogram_testkit::Scratch::new("materials-unwritable");
    // A folder where the store's file would go: it cannot be written.
    std::fs::create_dir_all(library.join("appearances.json")).expect("folder");
    let config = EngineConfig {
        library_dir: Some(library.to_path_buf()),
        ..EngineConfig::default()
    };
    let Some(mut engine) = phantogram_integration::engine_or_skip(config) else {
        return;
    };
    let lacquer = Appearance::preset(WardPreset::Lacquer);
    let err = engine.set_appearance(lacquer).expect_err("not saved");
    assert_eq!(err.kind(), phantogram::engine::ErrorKind::Load, "{err}");
    assert!(err.to_string().contains("could not be saved"), "{err}");
    assert_eq!(engine.appearance(), lacquer, "shown all the same");
}

#[test]
fn ward_image_light_on_the_shared_rooms() {
    // The anisotropic read of the image light (ibl/anisotropic.rs) checked where its taps were
    // not chosen: every shared room, brushed metal's and silk's lobes, against a Monte-Carlo
    // integral of the lobe over the room. It must beat the round read it replaced on each.
    use phantogram::ibl::accuracy::read_errors;
    use phantogram::ward::WardLobe;
    phantogram_integration::nearer_in_every_shared_room(|env| {
        [("brushed", WardPreset::BrushedMetal), ("silk", WardPreset::Silk)]
            .into_iter()
            .map(|(name, preset)| {
                let m = preset.material();
                (
                    format!("{name} (round read → taps)"),
                    read_errors(env, WardLobe::new(m.alpha_x, m.alpha_y), 80),
                )
            })
            .collect()
    });
}

/// A Ward preset's texture map as the renderer lays it: silk's plain weave over a flat panel in
/// the glass, seen straight on at phone resolution. The threads are a millimetre wide along the
/// surface's tangent frame whatever the screen: along a row, luminance one thread over is
/// anti-correlated (warp and weft alternate) and two threads over correlated; the map keeps the
/// preset's brightness on average (its scales average one: the mean of the preset's lobe and
/// the lobe turned a quarter, as warp and weft are) but not its uniformity. Brushed metal's
/// grooves run along the tangent: rows differ more from each other than columns do.
#[test]
fn a_ward_map_lays_its_threads_a_millimetre_apart_and_keeps_the_albedo() {
    use phantogram::model::{Mesh, Model};
    use phantogram::projection::{DepthRange, OffAxisProjection};
    use phantogram::render::{FrameInput, Renderer};
    use phantogram::screen::Screen;
    use phantogram::ward::WardMap;
    let Some(gpu) = phantogram_integration::gpu_or_skip() else {
        return;
    };
    let screen = Screen::default();
    let (w, h) = (540u32, 1200u32);
    let px_per_mm = w as f32 / (screen.width_m() * 1000.0);
    // A panel 50 mm square whose top face lies in the glass (z = 0), tangent +x, bitangent +y.
    let mut mesh = Mesh::default();
    mesh.push_cube(Vec3::new(0.0, 0.0, -0.025), 0.025, [1.0; 4]);
    let model = Model::from_painted_mesh("panel", mesh);
    let mut renderer = Renderer::new(gpu, &model).expect("renderer");
    let eye = OffAxisProjection::new(&screen, Vec3::new(0.0, 0.0, 0.3), DepthRange::default()).expect("projection");
    let input = FrameInput {
        left: &eye,
        right: &eye,
        mono: &eye,
        toward_light: Vec3::new(0.3, 0.4, 1.0),
        device_to_world: Quat::IDENTITY,
        offset: Vec3::ZERO,
        levels: &[],
        fades: &[],
    };
    let mut draw = |preset: WardPreset, map: Option<WardMap>, turned: bool| {
        let mut look = Appearance::preset(preset);
        if let Some(ward) = look.ward.as_mut() {
            if let Some(map) = map {
                ward.map = map;
            }
            if turned {
                (ward.alpha_x, ward.alpha_y) = (ward.alpha_y, ward.alpha_x);
            }
        }
        renderer.appearance = look;
        let px = renderer.render(&input, Method::Mono, w, h).expect("render");
        // Luminance of the central 240 × 240 pixels (about 30 mm), rows top to bottom.
        let (x0, y0, n) = (w / 2 - 120, h / 2 - 120, 240u32);
        (0..n)
            .map(|y| {
                (0..n)
                    .map(|x| {
                        let k = (((y0 + y) * w + x0 + x) * 4) as usize;
                        0.2126 * f64::from(px[k]) + 0.7152 * f64::from(px[k + 1]) + 0.0722 * f64::from(px[k + 2])
                    })
                    .collect::<Vec<f64>>()
            })
            .collect::<Vec<Vec<f64>>>()
    };
    let mean = |img: &[Vec<f64>]| img.iter().flatten().sum::<f64>() / img.iter().map(Vec::len).sum::<usize>() as f64;
    let spread = |img: &[Vec<f64>]| {
        let m = mean(img);
        (img.iter().flatten().map(|v| (v - m).powi(2)).sum::<f64>() / img.iter().map(Vec::len).sum::<usize>() as f64)
            .sqrt()
    };
    // Correlation of each row with itself shifted by `lag` pixels, over all rows.
    let row_correlation = |img: &[Vec<f64>], lag: usize| {
        let (mut num, mut den) = (0.0, 0.0);
        for row in img {
            let m = row.iter().sum::<f64>() / row.len() as f64;
            for i in 0..row.len() - lag {
                num += (row[i] - m) * (row[i + lag] - m);
            }
            den += row.iter().map(|v| (v - m).powi(2)).sum::<f64>();
        }
        num / den.max(1e-12)
    };
    let woven = draw(WardPreset::Silk, None, false);
    let plain = draw(WardPreset::Silk, Some(WardMap::Uniform), false);
    let turned = draw(WardPreset::Silk, Some(WardMap::Uniform), true);
    let (m_woven, m_plain) = (mean(&woven), 0.5 * (mean(&plain) + mean(&turned)));
    let (s_woven, s_plain) = (spread(&woven), spread(&plain));
    let thread = px_per_mm.round() as usize;
    let (one, two) = (row_correlation(&woven, thread), row_correlation(&woven, 2 * thread));
    println!(
        "silk: mean {m_woven:.1} with its weave, {m_plain:.1} without (both ways); spread {s_woven:.2} vs {s_plain:.2}; \
         row correlation at one thread ({thread} px) {one:.2}, at two {two:.2}"
    );
    assert!((m_woven - m_plain).abs() < 0.03 * m_plain, "the weave keeps the albedo");
    // (The plain panel's spread is its shading's gradient.)
    assert!(s_woven > 2.0 * s_plain.max(0.5), "the weave shows");
    assert!(one < -0.2 && two > 0.3, "warp and weft alternate every millimetre");

    let brushed = draw(WardPreset::BrushedMetal, None, false);
    let plain = draw(WardPreset::BrushedMetal, Some(WardMap::Uniform), false);
    // Grooves along x: a row is one groove (nearly), so the spread of row means is large and
    // that of column means small (both of the difference from the plain panel, which has its
    // shading's gradient).
    let diff: Vec<Vec<f64>> = brushed
        .iter()
        .zip(&plain)
        .map(|(a, b)| a.iter().zip(b).map(|(x, y)| x - y).collect())
        .collect();
    let row_means: Vec<f64> = diff.iter().map(|r| r.iter().sum::<f64>() / r.len() as f64).collect();
    let column_means: Vec<f64> = (0..diff[0].len())
        .map(|x| diff.iter().map(|r| r[x]).sum::<f64>() / diff.len() as f64)
        .collect();
    let deviation = |v: &[f64]| {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
    };
    let (across, along) = (deviation(&row_means), deviation(&column_means));
    let (m_brushed, m_plain) = (mean(&brushed), mean(&plain));
    println!("brushed: mean {m_brushed:.1} vs {m_plain:.1}; row means spread {across:.2}, column means {along:.2}");
    assert!(
        (m_brushed - m_plain).abs() < 0.05 * m_plain,
        "the grooves keep the albedo"
    );
    assert!(across > 3.0 * along, "the grooves run along the tangent");
}

/// A finger scrolls the material screen: its Done button starts below the screen's edge on a
/// phone-sized surface, a drag up over the panel brings it into view (egui scrolls by dragging
/// only once it knows the pointer is a touch screen's), and a tap on it closes the screen.
#[test]
fn a_finger_drag_scrolls_the_material_screen() {
    use phantogram::gesture::TouchPhase;
    let (w, h) = (360u32, 800u32);
    let Some((mut e, mut t)) = material_screen(w, h) else {
        return;
    };
    let done_before = e.control_px("done").expect("the Done button");
    assert!(done_before[1] > h as f32, "Done starts below the edge: {done_before:?}");
    // Up from the panel's heading (no control there), 300 px in 20 moves, a frame each.
    let ms = 1_000_000;
    let (x, y0) = (w as f32 * 0.5, h as f32 * 0.64);
    e.touch(TouchPhase::Down, 7, x, y0, t * ms);
    for k in 1..=20 {
        let y = y0 - 15.0 * k as f32;
        e.touch(TouchPhase::Move, 7, x, y, (t + 16 * k) * ms);
        e.draw(Some((t + 16 * k) * ms)).expect("draw");
    }
    e.touch(TouchPhase::Up, 7, x, y0 - 300.0, (t + 336) * ms);
    for k in 0..60 {
        e.draw(Some((t + 352 + 16 * k) * ms)).expect("draw");
    }
    t += 2000;
    let done_after = e.control_px("done").expect("the Done button");
    println!("Done at {done_before:?}, after the drag at {done_after:?}");
    assert!(
        done_after[1] < done_before[1] - 250.0,
        "the drag scrolled the panel: {done_before:?} → {done_after:?}"
    );
    // Nothing under the finger changed: still the glTF's own material.
    assert_eq!(e.appearance(), Appearance::default());
    assert!(done_after[1] < h as f32 - 10.0, "Done is on the screen: {done_after:?}");
    phantogram_integration::tap_at(&mut e, done_after, &mut t);
    assert!(e.control_px("done").is_none(), "Done closed the screen");
}
