//! `cargo bench -p phantogram --bench render` (or `cargo xtask bench render`): rendering figures
//! that the tests do not assert, because this machine is shared and noisy.
//!
//! * cold load-to-first-frame of the Draco-compressed Smithsonian sea turtle (needs
//!   `PHANTOGRAM_DATA`; skipped with a notice otherwise): file read, Draco decoding, image
//!   decoding, mip generation, upload, pipeline creation and one 1080×2400 stereo frame read back,
//!   with the renderer's lighting tables computed on another thread meanwhile, as the app does;
//! * stereo (Dubois) / mono frame time at 1080×2400 for the default artifact (alone, and on the
//!   diorama floor as the app draws it) and the turtle, as the median of 11 frames each, mono
//!   and stereo alternating;
//! * choosing the turtle in the gallery of a running engine (a bundled Voyager folder, as a
//!   museum ships it): from the tap to the first frame that shows it (in its thumb scan, the
//!   engine's preview) and to the first in its best scan, the engine drawing 1080×2400 stereo
//!   frames with the progress banner meanwhile as the app does, and how many frames showed
//!   progress before the turtle; also the best scan's load waited for without drawing (load,
//!   fit, upload and one frame);
//! * the amphora as smooth glass on its floor (drawn twice per eye, and a shadow filter), and as
//!   amber glass of index 1 (the same, back faces culled) and 1.5 (it bends what is seen
//!   through it: drawn over each eye's backdrop, the copy alone), and frosted (blurred: the
//!   backdrop's halvings too);
//! * the raking lamp over the amphora on its floor (`LampSetting::raking`, at the screen's left
//!   edge 2 cm above the glass: inside the amphora's bounding sphere, so its shadows come from a
//!   cube of six views, `phantogram_render::point_shadow`), with shadows and without, and the
//!   triangles the shadow passes drew; and over the glass amphora, whose glass the cube's six
//!   views also draw into its shadow filter;
//! * the amphora on its floor under a directional light of angular radius 0 (the sharp filter),
//!   the sun's 0.0047 rad, the studio room's lamp's 0.05 and the widest room's sun's 0.1 (the
//!   soft shadow's blocker search and disc of taps, `scene.wgsl`'s `soft_shadow`), and the glass
//!   amphora under the same lights (its coloured shadow softened likewise, `soft_light_filter`);
//! * peak resident memory of the process (VmHWM).
//!
//! With `PHANTOGRAM_BENCH_FRAMES=DIR` each model's mono frame is also written to `DIR` as a PNG.
//!
//! Frame times include reading the frame back to the CPU, as `phantogram render` does.

use std::time::Instant;

use phantogram::anaglyph::Method;
use phantogram::glam::Vec3;
use phantogram::model::{DioramaFit, Model};
use phantogram::render::{FrameInput, Gpu, Renderer};
use phantogram::{Session, SessionConfig};

const W: u32 = 1080;
const H: u32 = 2400;

fn median_ms(mut samples: Vec<f64>) -> f64 {
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// Median mono and stereo frame times, ms, and where the device has timestamp queries the median
/// GPU times of the same frames (first pass to composition). The two are measured alternately,
/// frame by frame, so that the load of this shared machine weighs on both alike.
fn frame_times(renderer: &mut Renderer, input: &FrameInput, frames: usize) -> ((f64, f64), Option<(f64, f64)>) {
    // Each frame is read back, which waits for its timestamps too: its reading is there at once.
    let mut time = |method: Method| {
        let start = Instant::now();
        std::hint::black_box(renderer.render(input, method, W, H).expect("frame"));
        let wall = start.elapsed().as_secs_f64() * 1e3;
        (wall, renderer.take_gpu_time_s().map(|s| s * 1e3))
    };
    time(Method::Mono);
    time(Method::DuboisRedCyan);
    let (mut mono, mut stereo) = (Vec::new(), Vec::new());
    let (mut mono_gpu, mut stereo_gpu) = (Vec::new(), Vec::new());
    for _ in 0..frames {
        let (wall, gpu) = time(Method::Mono);
        mono.push(wall);
        mono_gpu.extend(gpu);
        let (wall, gpu) = time(Method::DuboisRedCyan);
        stereo.push(wall);
        stereo_gpu.extend(gpu);
    }
    let gpu = (!mono_gpu.is_empty() && !stereo_gpu.is_empty()).then(|| (median_ms(mono_gpu), median_ms(stereo_gpu)));
    ((median_ms(mono), median_ms(stereo)), gpu)
}

fn main() {
    let quick = std::env::args().any(|a| a == "--test" || a == "--list");
    let frames = if quick { 1 } else { 11 };
    let frames_dir = std::env::var_os("PHANTOGRAM_BENCH_FRAMES").map(std::path::PathBuf::from);
    let gpu = match Gpu::headless() {
        Ok(g) => g,
        Err(e) => {
            println!("no GPU adapter: {e}");
            return;
        }
    };
    println!("adapter: {}", gpu.describe());
    let mut session = Session::new(SessionConfig::default()).expect("default config");
    let tilt = 35f32.to_radians();
    let up = Vec3::new(0.0, tilt.sin(), tilt.cos());
    session
        .push(phantogram::sensors::SensorEvent::accelerometer(1, up * 9.81))
        .expect("valid event");
    let view = session.frame().expect("frame");
    let input = phantogram::engine::frame_input(&view, Vec3::ZERO);

    let turtle_path = std::env::var_os("PHANTOGRAM_DATA").map(|d| {
        std::path::PathBuf::from(d).join("models/heritage/smithsonian_nmnh_sea_turtle/sea_turtle-150k-1024-low.glb")
    });
    // The artifact alone, and as `phantogram render` and the viewer draw it: standing on the
    // diorama's floor, which fills the rest of each eye's view with shaded, shadowed surface.
    let mut on_floor = phantogram::artifact::default_model();
    on_floor.add_floor(&SessionConfig::default().screen, Model::FLOOR_REACH);
    let mut models: Vec<(String, Model)> = vec![
        ("amphora".into(), phantogram::artifact::default_model()),
        ("amphora on the floor".into(), on_floor),
        ("glass amphora on the floor".into(), glass_amphora_on_floor(None)),
        (
            "amber glass amphora on the floor, index 1".into(),
            glass_amphora_on_floor(Some(1.0)),
        ),
        (
            "amber glass amphora on the floor, index 1.5".into(),
            glass_amphora_on_floor(Some(1.5)),
        ),
        (
            "frosted amber glass amphora on the floor, index 1.5".into(),
            frosted(glass_amphora_on_floor(Some(1.5))),
        ),
    ];
    let mut renderer = None;
    let mut gpu = Some(gpu);
    match turtle_path.filter(|p| p.exists()) {
        Some(path) => {
            let start = Instant::now();
            // As `phantogram render` and the engine start: the lighting tables on another thread
            // while the model loads.
            phantogram::render::prepare_lighting_tables_in_background(true);
            let mut turtle = phantogram::model::load_model(&path).expect("the turtle loads");
            turtle.fit_to_diorama(&SessionConfig::default().screen, &DioramaFit::default());
            let loaded = start.elapsed();
            let mut r = Renderer::new(gpu.take().expect("unused"), &turtle).expect("renderer");
            r.render(&input, Method::DuboisRedCyan, W, H).expect("first frame");
            let first = start.elapsed();
            println!(
                "sea turtle (Draco, 150k triangles): cold load-to-first-frame {:.0} ms (load + decode {:.0} ms)",
                first.as_secs_f64() * 1e3,
                loaded.as_secs_f64() * 1e3
            );
            renderer = Some(r);
            models.push(("sea turtle".into(), turtle));
        }
        None => println!("PHANTOGRAM_DATA not set: skipping the sea turtle"),
    }
    let mut renderer = match (renderer, gpu) {
        (Some(r), _) => r,
        (None, Some(g)) => Renderer::new(g, &models[0].1).expect("renderer"),
        (None, None) => unreachable!(),
    };
    for (name, model) in &models {
        renderer.set_model(model).expect("model");
        let ((mono, stereo), gpu) = frame_times(&mut renderer, &input, frames);
        let on_gpu = gpu.map_or(String::new(), |(m, s)| {
            format!("; on the GPU mono {m:.2} ms, stereo {s:.2} ms")
        });
        println!(
            "{name}, {W}x{H}: mono {mono:.1} ms, stereo {stereo:.1} ms, stereo/mono {:.2}x{on_gpu}",
            stereo / mono
        );
        if let Some(dir) = &frames_dir {
            save_frame(&mut renderer, &input, dir, name);
        }
    }
    lamp_among_the_artifact(&mut renderer, "amphora", &models[1].1, &input, frames);
    lamp_among_the_artifact(&mut renderer, "glass amphora", &models[2].1, &input, frames);
    sun_over_the_artifact(&mut renderer, "amphora", &models[1].1, &input, frames);
    sun_over_the_artifact(&mut renderer, "glass amphora", &models[2].1, &input, frames);
    if let Some(data) = std::env::var_os("PHANTOGRAM_DATA") {
        select_from_gallery(&std::path::PathBuf::from(data).join("models/heritage"));
    }
    if let Some(mib) = peak_rss_mib() {
        println!("peak resident memory: {mib:.0} MiB");
    }
}

/// Writes `name`'s mono frame as a PNG into `dir`, to look at what was timed (on another machine's
/// GPU, say).
fn save_frame(renderer: &mut Renderer, input: &FrameInput, dir: &std::path::Path, name: &str) {
    let rgba = renderer.render(input, Method::Mono, W, H).expect("frame");
    let image = image::RgbaImage::from_raw(W, H, rgba).expect("a whole frame");
    let file: String = name
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    let path = dir.join(format!("{file}.png"));
    image.save(&path).expect("the frame is written");
    println!("  frame written to {}", path.display());
}

/// The amphora as glass on its floor: every one of its materials transmits, smooth, so each eye
/// draws it twice (filter and light) and the light's view draws the shadow filter. With a
/// volume's index, its walls are 4 mm of amber glass (back faces culled); of index 1 it bends
/// nothing and is drawn with the filter, of any other over each eye's backdrop (a copy of the
/// opaque scene and its halvings): the two differ by the backdrop's cost alone.
fn glass_amphora_on_floor(volume_ior: Option<f32>) -> Model {
    let mut glass = phantogram::artifact::default_model();
    for material in &mut glass.materials {
        material.layers.transmission = 1.0;
        material.roughness = 0.0;
        if let Some(ior) = volume_ior {
            material.layers.ior = ior;
            material.layers.thickness = 0.004;
            material.layers.attenuation_distance = 0.01;
            material.layers.attenuation_color = [0.95, 0.6, 0.2];
        }
        // The painted amphora's material is metallic, and metal lets no light through.
        material.metallic = 0.0;
    }
    glass.add_floor(&SessionConfig::default().screen, Model::FLOOR_REACH);
    glass
}

/// `glass` made rough (0.5), so that what is seen through it is blurred: the backdrop with its
/// halvings.
fn frosted(mut glass: Model) -> Model {
    for material in glass.materials.iter_mut().filter(|m| m.transmits()) {
        material.roughness = 0.5;
    }
    glass
}

/// `name` on its floor under a directional light with a width, as a room's sun lights it
/// (`Lighting::light_angular_radius_rad`): the soft shadow's search and filter against the sharp
/// filter of a point-like light, in one run (see the module docs).
fn sun_over_the_artifact(renderer: &mut Renderer, name: &str, on_floor: &Model, input: &FrameInput, frames: usize) {
    renderer.set_model(on_floor).expect("model");
    let mut times = Vec::new();
    // A point; the sun (0.27° in radius); the studio room's lamp (pmndrs_studio, 2.9°); the
    // widest a room's sun may be (`ibl::sun`, 0.1 rad).
    for beta_rad in [0.0f32, 0.0047, 0.05, 0.1] {
        renderer.lighting.light_angular_radius_rad = beta_rad;
        let ((mono, stereo), _) = frame_times(renderer, input, frames);
        times.push(format!("{beta_rad} rad: mono {mono:.1} ms, stereo {stereo:.1} ms"));
    }
    renderer.lighting.light_angular_radius_rad = 0.0;
    println!(
        "{name} on the floor, {W}x{H}, under a light of angular radius {}",
        times.join("; ")
    );
}

/// The raking lamp over `name` on its floor, with its cube shadows and without (see the module
/// docs).
fn lamp_among_the_artifact(renderer: &mut Renderer, name: &str, on_floor: &Model, input: &FrameInput, frames: usize) {
    let screen = SessionConfig::default().screen;
    let setting = phantogram::lamp::LampSetting::raking();
    let mut placed = phantogram::lamp::PlacedLamp::new(setting, -0.5 * screen.width_m(), 0.0);
    let target = on_floor
        .bounds_of(|p| !p.is_floor)
        .map_or(Vec3::ZERO, |b| (b.min + b.max) * 0.5);
    renderer.set_model(on_floor).expect("model");
    renderer.lamp = Some(placed.lamp(None, target));
    let ((mono, stereo), _) = frame_times(renderer, input, frames);
    let triangles = renderer.shadow_triangles_last_frame();
    renderer.lighting.shadows = false;
    let ((mono_plain, stereo_plain), _) = frame_times(renderer, input, frames);
    renderer.lighting.shadows = true;
    renderer.lamp = None;
    println!(
        "{name} on the floor, raking lamp among it, {W}x{H}: with its cube shadows mono {mono:.1} ms, stereo \
         {stereo:.1} ms ({triangles} triangles in the shadow passes); without shadows mono {mono_plain:.1} ms, stereo \
         {stereo_plain:.1} ms"
    );
}

/// The turtle chosen in the gallery of a running engine (see the module docs).
fn select_from_gallery(bundled: &std::path::Path) {
    use phantogram::engine::{Engine, EngineConfig, LoadStatus};
    let id: phantogram::library::ArtifactId = "bundled:smithsonian_nmnh_sea_turtle".parse().expect("an id");
    let config = || EngineConfig {
        bundled_dir: Some(bundled.to_path_buf()),
        ..EngineConfig::default()
    };
    let mut engine = Engine::new(config()).expect("engine");
    engine.resume_offscreen(W, H).expect("target");
    engine.draw(None).expect("a frame of the amphora");
    let start = Instant::now();
    engine.select_artifact(id.clone());
    let mut progress_frames = 0;
    let mut first: Option<(std::time::Duration, String, usize)> = None;
    loop {
        let loading = matches!(engine.loading_status(), LoadStatus::Loading { .. });
        engine.draw(None).expect("frame");
        let info = engine.model_info();
        if info.artifact.as_ref().map(|a| &a.id) == Some(&id) {
            first.get_or_insert((start.elapsed(), info.name.clone(), info.triangles));
            if !info.preview {
                break;
            }
        } else {
            progress_frames += 1;
        }
        assert!(
            loading || matches!(engine.loading_status(), LoadStatus::Loading { .. }),
            "the load ended without the turtle: {:?}",
            engine.loading_status()
        );
    }
    let refined = start.elapsed();
    let (shown, first_name, first_triangles) = first.expect("the turtle was drawn");
    println!(
        "sea turtle chosen in the gallery: first frame showing it {:.0} ms after the tap ({first_name}, {first_triangles} triangles), {progress_frames} frames of progress before; in its best scan ({}, {} triangles) {:.0} ms after the tap ({W}x{H} stereo)",
        shown.as_secs_f64() * 1e3,
        engine.model_info().name,
        engine.model_info().triangles,
        refined.as_secs_f64() * 1e3
    );
    // The same with nothing drawn meanwhile (as a phone's 16 ms frames nearly are).
    let mut fresh = Engine::new(config()).expect("engine");
    fresh.resume_offscreen(W, H).expect("target");
    fresh.draw(None).expect("a frame of the amphora");
    let start = Instant::now();
    fresh.select_artifact(id);
    assert!(
        fresh.wait_for_artifact(std::time::Duration::from_secs(60)),
        "{:?}",
        fresh.loading_status()
    );
    fresh.draw(None).expect("frame");
    println!(
        "  the best scan without frames meanwhile: load, fit, upload and first frame {:.0} ms",
        start.elapsed().as_secs_f64() * 1e3
    );
}
