//! Rendering on the GPU (Mesa's lavapipe in CI): geometric truth against the core's projection,
//! golden images of the default artifact, and the anaglyph composition against its CPU reference.
//!
//! Without a GPU adapter these tests print a notice and return, except under CI (`CI` set), where
//! a missing adapter fails them: `.ci/run` installs `mesa-vulkan-drivers`.
//!
//! Golden images live in `tests/golden/`. On a mismatch the test writes `NAME-actual.png` and
//! `NAME-difference.png` beside the golden image (git-ignored). `PHANTOGRAM_BLESS=1` rewrites the
//! golden images from the current output; look at them before committing.

use crate::golden;

use phantogram::anaglyph::Method;
use phantogram::artifact::default_model;
use phantogram::glam::{Mat4, Vec3};
use phantogram::model::{Mesh, Model};
use phantogram::projection::{DepthRange, OffAxisProjection};
use phantogram::render::{FrameInput, Gpu, Renderer};
use phantogram::screen::Screen;
use phantogram::{FrameView, Session, SessionConfig};

fn gpu() -> Option<Gpu> {
    phantogram_integration::gpu_or_skip()
}

/// The output size used by the tests: the default phone's aspect, small for lavapipe.
pub(crate) const W: u32 = 180;
pub(crate) const H: u32 = 400;

/// The view of a phone held 35° from horizontal, uncalibrated (the viewer looks obliquely, the
/// classic phantogram view).
fn oblique_view() -> FrameView {
    let mut s = Session::new(SessionConfig::default()).unwrap();
    let tilt = 35f32.to_radians();
    let up = Vec3::new(0.0, tilt.sin(), tilt.cos());
    s.push(phantogram::sensors::SensorEvent::accelerometer(1, up * 9.81))
        .unwrap();
    s.frame().unwrap()
}

fn luminance(px: &[u8]) -> f32 {
    0.2126 * px[0] as f32 + 0.7152 * px[1] as f32 + 0.0722 * px[2] as f32
}

/// Centroid (pixel coordinates, centre of pixel = +0.5) of the pixels whose luminance differs
/// from the background's (the top-left pixel's) by more than `threshold`.
fn marker_centroid(pixels: &[u8], threshold: f32) -> Option<(f32, f32)> {
    let background = luminance(&pixels[..4]);
    let (mut sx, mut sy, mut n) = (0.0f64, 0.0f64, 0u32);
    for (i, px) in pixels.chunks(4).enumerate() {
        if (luminance(px) - background).abs() > threshold {
            sx += (i as u32 % W) as f64 + 0.5;
            sy += (i as u32 / W) as f64 + 0.5;
            n += 1;
        }
    }
    (n > 0).then(|| ((sx / n as f64) as f32, (sy / n as f64) as f32))
}

fn marker_model(at: Vec3) -> Model {
    let mut m = Mesh::default();
    m.push_cube(at, 0.0006, [1.0, 1.0, 1.0, 1.0]);
    Model::from_painted_mesh("marker", m)
}

#[test]
fn markers_land_on_the_predicted_pixel_in_each_eye() {
    let Some(gpu) = gpu() else { return };
    let screen = Screen::default();
    let view = oblique_view();
    let scale = W as f32 / screen.width_px() as f32;
    let points = [
        Vec3::new(0.012, -0.02, 0.025), // in front of the glass
        Vec3::new(-0.015, 0.03, -0.03), // behind it
        Vec3::new(0.008, 0.01, 0.0),    // on it
    ];
    let mut renderer = Renderer::new(gpu, &marker_model(points[0])).unwrap();
    for p in points {
        renderer.set_model(&marker_model(p)).unwrap();
        let input = FrameInput {
            toward_light: Vec3::new(0.2, -0.3, 1.0),
            ..phantogram::engine::frame_input(&view, Vec3::ZERO)
        };
        let mut centroids = Vec::new();
        for (name, proj) in [("left", &view.left), ("right", &view.right)] {
            let pixels = renderer.render_single(proj, &input, W, H).unwrap();
            let got = marker_centroid(&pixels, 30.0).unwrap_or_else(|| panic!("marker {p} not visible ({name})"));
            let want = proj.project(p).unwrap().pixel * scale;
            let err = ((got.0 - want.x).powi(2) + (got.1 - want.y).powi(2)).sqrt();
            println!(
                "marker {p} {name} eye: rendered {got:?}, predicted ({:.2}, {:.2}), error {err:.3} px",
                want.x, want.y
            );
            assert!(err < 1.0, "marker {p}, {name} eye: {err} px from the prediction");
            centroids.push(got);
        }
        let disparity = centroids[1].0 - centroids[0].0;
        println!("marker {p}: horizontal disparity {disparity:+.2} px");
        if p.z == 0.0 {
            assert!(
                disparity.abs() < 0.25,
                "a point on the glass has disparity {disparity} px"
            );
        } else if p.z > 0.0 {
            // In front of the glass: crossed disparity (the right eye sees it further left).
            assert!(disparity < -1.0, "{disparity}");
        } else {
            assert!(disparity > 1.0, "{disparity}");
        }
    }
}

/// Compares with `tests/golden/NAME.png` (see the `golden` module).
fn check_golden(name: &str, pixels: &[u8], tolerance: u8, max_fraction: f64) {
    golden::check(name, W, H, pixels, tolerance, max_fraction);
}

#[test]
fn default_artifact_matches_its_golden_images() {
    let Some(gpu) = gpu() else { return };
    let view = oblique_view();
    let mut renderer = Renderer::new(gpu, &default_model()).unwrap();
    let input = phantogram::engine::frame_input(&view, Vec3::ZERO);
    for (name, method) in [
        ("amphora-mono", Method::Mono),
        ("amphora-dubois", Method::DuboisRedCyan),
    ] {
        let pixels = renderer.render(&input, method, W, H).unwrap();
        // Rasterisation may differ by a unit here and there across Mesa versions; a broken
        // projection, light or composition changes thousands of pixels.
        check_golden(name, &pixels, 3, 0.002);
    }
    // As the README's command shows it: on the diorama floor, with its shadow.
    let mut staged = default_model();
    staged.add_floor(&Screen::default(), Model::FLOOR_REACH);
    renderer.set_model(&staged).unwrap();
    let pixels = renderer.render(&input, Method::DuboisRedCyan, W, H).unwrap();
    check_golden("amphora-floor-dubois", &pixels, 3, 0.002);
}

/// A gallery thumbnail of another model is drawn beside the one set, which stays as it was:
/// the frame after it is the frame before it, to the bit.
#[test]
fn another_model_drawn_beside_leaves_the_frame_as_it_was() {
    let Some(gpu) = gpu() else { return };
    let view = oblique_view();
    let input = phantogram::engine::frame_input(&view, Vec3::ZERO);
    let mut renderer = Renderer::new(gpu, &default_model()).unwrap();
    let before = renderer.render(&input, Method::DuboisRedCyan, W, H).unwrap();
    let mut mesh = Mesh::default();
    mesh.push_cube(Vec3::ZERO, 0.02, [0.2, 0.8, 0.3, 1.0]);
    let posed = phantogram::thumbnails::pose(Model::from_painted_mesh("cube", mesh)).unwrap();
    let thumb = phantogram::thumbnails::render(&mut renderer, &posed).expect("a thumbnail");
    let side = phantogram::thumbnails::THUMBNAIL_PX as usize;
    assert_eq!(thumb.len(), side * side * 4);
    // The green cube fills the middle of its picture.
    let centre = &thumb[(side / 2 * side + side / 2) * 4..][..4];
    assert!(
        centre[1] > centre[0] + 20 && centre[1] > centre[2] + 20,
        "green: {centre:?}"
    );
    let after = renderer.render(&input, Method::DuboisRedCyan, W, H).unwrap();
    assert!(before == after, "the frame changed after drawing another model");
}

#[test]
fn shared_models_match_their_golden_images() {
    let Some(models) = phantogram_integration::data_subdir("models") else {
        return;
    };
    let Some(gpu) = gpu() else { return };
    let view = oblique_view();
    let input = phantogram::engine::frame_input(&view, Vec3::ZERO);
    let screen = Screen::default();
    let cases = [
        ("duck-mono", "khronos/Duck/glTF-Binary/Duck.glb", Method::Mono),
        (
            "sea-turtle-draco-dubois",
            "heritage/smithsonian_nmnh_sea_turtle/sea_turtle-150k-1024-low.glb",
            Method::DuboisRedCyan,
        ),
        (
            "damaged-helmet-mono",
            "khronos/DamagedHelmet/glTF-Binary/DamagedHelmet.glb",
            Method::Mono,
        ),
    ];
    let mut renderer: Option<Renderer> = None;
    let mut gpu = Some(gpu);
    for (name, file, method) in cases {
        let mut model = phantogram::model::load_model(&models.join(file)).unwrap();
        model.fit_to_diorama(&screen, &Default::default());
        let r = match (&mut renderer, gpu.take()) {
            (Some(r), _) => {
                r.set_model(&model).unwrap();
                r
            }
            (None, Some(g)) => renderer.insert(Renderer::new(g, &model).unwrap()),
            (None, None) => unreachable!("a renderer or a GPU is always at hand"),
        };
        let pixels = r.render(&input, method, W, H).unwrap();
        check_golden(name, &pixels, 3, 0.002);
    }
}

#[test]
fn gpu_composition_matches_the_cpu_reference() {
    // Two flat-coloured walls, one per eye: a large quad behind the glass lit head-on, seen by
    // both eyes; the composed pixel at the centre must equal Method::compose of the two eyes'
    // pixels (in linear light), for every method.
    let Some(gpu) = gpu() else { return };
    let mut mesh = Mesh::default();
    mesh.push_cube(Vec3::new(0.0, 0.0, -0.5), 0.3, [0.6, 0.3, 0.1, 1.0]);
    let mesh = Model::from_painted_mesh("wall", mesh);
    let screen = Screen::default();
    let left = OffAxisProjection::new(&screen, Vec3::new(-0.03, 0.0, 0.3), DepthRange::default()).unwrap();
    let right = OffAxisProjection::new(&screen, Vec3::new(0.03, 0.0, 0.3), DepthRange::default()).unwrap();
    let mut renderer = Renderer::new(gpu, &mesh).unwrap();
    let input = FrameInput {
        left: &left,
        right: &right,
        mono: &left,
        toward_light: Vec3::Z,
        device_to_world: phantogram::glam::Quat::IDENTITY,
        offset: Vec3::ZERO,
        levels: &[],
        fades: &[],
    };
    let centre = ((H / 2) * W + W / 2) as usize * 4;
    let to_linear = |c: u8| {
        let c = c as f32 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let eye = |r: &mut Renderer, p: &OffAxisProjection| {
        let px = r.render_single(p, &input, W, H).unwrap();
        [0, 1, 2].map(|c| to_linear(px[centre + c]))
    };
    let (l, r) = (eye(&mut renderer, &left), eye(&mut renderer, &right));
    for method in Method::ALL {
        let px = renderer.render(&input, method, W, H).unwrap();
        let got = [0, 1, 2].map(|c| to_linear(px[centre + c]));
        let want = if method.is_stereo() {
            method.compose(l, r)
        } else {
            method.compose(l, l)
        };
        for c in 0..3 {
            assert!(
                (got[c] - want[c]).abs() < 0.01,
                "{method}: channel {c}: {} vs {}",
                got[c],
                want[c]
            );
        }
    }
}

/// A window whose surface offers no sRGB format (an OpenGL ES surface without
/// `EGL_KHR_gl_colorspace`) shows the frame the offscreen sRGB target does: the composition
/// encodes sRGB itself there. Written to an `Rgba8Unorm` texture, the default artifact's anaglyph
/// frame is within a code of the usual one; without the encoding its mid-tones are far darker
/// (checked: 74 codes).
#[test]
fn a_target_without_srgb_encoding_shows_the_same_frame() {
    use phantogram::wgpu;
    let Some(gpu) = gpu() else { return };
    let view = oblique_view();
    let input = phantogram::engine::frame_input(&view, Vec3::ZERO);
    let mut renderer = Renderer::new(gpu, &default_model()).unwrap();
    let method = Method::DuboisRedCyan;
    let srgb = renderer.render(&input, method, W, H).unwrap();
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let target = phantogram::render::target_texture(&renderer.gpu().device, "unorm window", W, H, format);
    let view_of_target = target.create_view(&Default::default());
    renderer
        .render_to_view(&input, method, &view_of_target, format, W, H)
        .unwrap();
    let unorm = phantogram::render::read_texture_level(renderer.gpu(), &target, 0).unwrap();
    assert_eq!(unorm.len(), srgb.len());
    let worst = srgb
        .iter()
        .zip(&unorm)
        .map(|(a, b)| (i16::from(*a) - i16::from(*b)).abs())
        .max()
        .unwrap_or(0);
    let mid_tones = srgb.chunks(4).filter(|p| (64..192).contains(&p[0])).count();
    println!(
        "largest difference {worst} codes over {} pixels ({mid_tones} with red in mid-tones)",
        W * H
    );
    assert!(mid_tones > 100, "the frame shows mid-tones: {mid_tones}");
    assert!(worst <= 1, "largest difference {worst} codes");
}

/// A floor at z = −30 mm seen straight on, with a cube above it or resting on it, lit obliquely.
fn shadow_scene(cube_centre: Vec3, half: f32, shadows: bool) -> Option<(Vec<u8>, OffAxisProjection)> {
    let mut mesh = Mesh::default();
    mesh.push_cube(cube_centre, half, [0.8, 0.8, 0.8, 1.0]);
    push_floor_marker(&mut mesh);
    render_over_floor(Model::from_painted_mesh("shadow test", mesh), shadows, OBLIQUE_LIGHT)
}

pub(crate) const OBLIQUE_LIGHT: Vec3 = Vec3::new(0.5, 0.0, 1.0);

/// A tiny cube whose bottom is at z = −31 mm, so that `add_floor` puts the floor there.
pub(crate) fn push_floor_marker(mesh: &mut Mesh) {
    mesh.push_cube(Vec3::new(0.03, 0.06, -0.0305), 0.0005, [0.5, 0.5, 0.5, 1.0]);
}

/// `model` on its floor seen straight on from 30 cm, lit from `toward_light`, in mono.
pub(crate) fn render_over_floor(
    model: Model,
    shadows: bool,
    toward_light: Vec3,
) -> Option<(Vec<u8>, OffAxisProjection)> {
    render_over_floor_lit(model, shadows, toward_light, None).map(|(px, proj, _)| (px, proj))
}

/// [`render_over_floor`] (with shadows, lit from [`OBLIQUE_LIGHT`]) in the visitor's
/// `appearance`.
pub(crate) fn render_over_floor_as(
    model: Model,
    appearance: phantogram::appearance::Appearance,
) -> Option<(Vec<u8>, OffAxisProjection)> {
    render_over_floor_with(model, true, OBLIQUE_LIGHT, None, appearance).map(|(px, proj, _)| (px, proj))
}

/// [`render_over_floor`], with `lamp` in place of the directional light if given; also the
/// triangles the shadow passes drew.
pub(crate) fn render_over_floor_lit(
    model: Model,
    shadows: bool,
    toward_light: Vec3,
    lamp: Option<phantogram::render::Lamp>,
) -> Option<(Vec<u8>, OffAxisProjection, u64)> {
    render_over_floor_with(model, shadows, toward_light, lamp, Default::default())
}

/// [`render_over_floor_lit`] in the visitor's `appearance`.
fn render_over_floor_with(
    mut model: Model,
    shadows: bool,
    toward_light: Vec3,
    lamp: Option<phantogram::render::Lamp>,
    appearance: phantogram::appearance::Appearance,
) -> Option<(Vec<u8>, OffAxisProjection, u64)> {
    let gpu = gpu()?;
    let screen = Screen::default();
    model.add_floor(&screen, 2.0);
    let eye = Vec3::new(0.0, 0.0, 0.3);
    let mono = OffAxisProjection::new(&screen, eye, DepthRange::default()).unwrap();
    let mut renderer = Renderer::new(gpu, &model).unwrap();
    renderer.lighting.shadows = shadows;
    renderer.lamp = lamp;
    renderer.appearance = appearance;
    let input = still_input(&mono, &mono, &mono, toward_light);
    let pixels = renderer.render(&input, Method::Mono, W, H).unwrap();
    Some((pixels, mono, renderer.shadow_triangles_last_frame()))
}

/// A frame's input for the eyes `left`, `right` and `mono`, lit from `toward_light`: the device
/// upright in the world, the mesh where it is, every part at its full level, nothing fading.
pub(crate) fn still_input<'a>(
    left: &'a OffAxisProjection,
    right: &'a OffAxisProjection,
    mono: &'a OffAxisProjection,
    toward_light: Vec3,
) -> FrameInput<'a> {
    FrameInput {
        left,
        right,
        mono,
        toward_light,
        device_to_world: phantogram::glam::Quat::IDENTITY,
        offset: Vec3::ZERO,
        levels: &[],
        fades: &[],
    }
}

/// `mesh` added to `model` as a part of its own, in `material`.
pub(crate) fn add_part(model: &mut Model, mesh: Mesh, material: phantogram::model::Material) {
    model.materials.push(material);
    model.primitives.push(phantogram::model::Primitive {
        mesh,
        material: model.materials.len() - 1,
        is_floor: false,
        lods: Vec::new(),
    });
}

/// Each of `models` on its floor as [`render_over_floor`] draws it (with shadows, lit from
/// `toward_light`), one after the other by one renderer (`Renderer::set_model` between).
pub(crate) fn render_in_turn_over_floor(models: Vec<Model>, toward_light: Vec3) -> Option<Vec<Vec<u8>>> {
    let gpu = gpu()?;
    let screen = Screen::default();
    let models: Vec<Model> = models
        .into_iter()
        .map(|mut m| {
            m.add_floor(&screen, 2.0);
            m
        })
        .collect();
    let mono = OffAxisProjection::new(&screen, Vec3::new(0.0, 0.0, 0.3), DepthRange::default()).unwrap();
    let mut renderer = Renderer::new(gpu, models.first()?).unwrap();
    renderer.lighting.shadows = true;
    let input = still_input(&mono, &mono, &mono, toward_light);
    let mut frames = Vec::new();
    for model in &models {
        renderer.set_model(model).unwrap();
        frames.push(renderer.render(&input, Method::Mono, W, H).unwrap());
    }
    Some(frames)
}

/// `model` on its floor as [`render_over_floor`] draws it (with shadows), by one renderer in
/// each of `methods` in turn, `size` pixels (default: the tests' size); stereo with the eyes
/// 64 mm apart.
pub(crate) fn render_methods_over_floor(
    mut model: Model,
    methods: &[Method],
    size: Option<(u32, u32)>,
) -> Option<Vec<Vec<u8>>> {
    let (w, h) = size.unwrap_or((W, H));
    let gpu = gpu()?;
    let screen = Screen::default();
    model.add_floor(&screen, 2.0);
    let at = |x: f32| OffAxisProjection::new(&screen, Vec3::new(x, 0.0, 0.3), DepthRange::default()).unwrap();
    let (left, right, mono) = (at(-0.032), at(0.032), at(0.0));
    let mut renderer = Renderer::new(gpu, &model).unwrap();
    renderer.lighting.shadows = true;
    let input = still_input(&left, &right, &mono, OBLIQUE_LIGHT);
    Some(
        methods
            .iter()
            .map(|m| renderer.render(&input, *m, w, h).unwrap())
            .collect(),
    )
}

fn luminance_at(pixels: &[u8], proj: &OffAxisProjection, p: Vec3) -> f32 {
    luminance(&pixel_at(pixels, proj, p))
}

/// The pixel (RGBA) of a [`render_over_floor`] frame where `p` (device frame) projects.
pub(crate) fn pixel_at(pixels: &[u8], proj: &OffAxisProjection, p: Vec3) -> [u8; 4] {
    let px = proj.project(p).unwrap().pixel * (W as f32 / Screen::default().width_px() as f32);
    let i = (px.y as u32 * W + px.x as u32) as usize * 4;
    [pixels[i], pixels[i + 1], pixels[i + 2], pixels[i + 3]]
}

#[test]
fn shadows_fall_where_the_light_says() {
    // Cube centre 15 mm above the floor; light along (0.5, 0, 1): the shadow's centre lands
    // 7.5 mm towards −x on the floor.
    let centre = Vec3::new(0.0, 0.0, -0.015);
    let Some((pixels, proj)) = shadow_scene(centre, 0.004, true) else {
        return;
    };
    let floor_z = -0.03;
    let shadow = Vec3::new(-0.0075, 0.0, floor_z);
    let mirror = Vec3::new(0.0075, 0.0, floor_z);
    let (dark, lit) = (
        luminance_at(&pixels, &proj, shadow),
        luminance_at(&pixels, &proj, mirror),
    );
    println!("floor luminance: in the predicted shadow {dark}, at its mirror image {lit}");
    assert!(dark < 0.6 * lit, "shadow {dark} vs lit {lit}");
}

/// A point lamp standing among what it shadows (inside the casters' bounds, so no single view
/// holds them): 9 mm above the floor, with a block to its −x (off to +y) and one to its +y (off
/// to +x) whose tops rise 1 mm above it, each shadow starts on the floor 16 mm out on its side
/// (the ray over the block's lower inner edge) and runs outwards, fanning away from the axis. There
/// the floor has only the room's light (as with the lamp dark); at the points mirrored across
/// the lamp in x and in y, with nothing between, and between the lamp and the blocks, it is lit
/// as without shadows. The shadows are read from two faces of the cube (−X and +Y), off their
/// centres on both axes, so a face drawn mirrored any way or in another's place moves a shadow
/// off its point. Each block and the marker is its own primitive: each face of the cube draws
/// only those its frustum reaches, so the six passes draw far fewer triangles than six times
/// the casters. Lamps outside the casters' sphere keep the one perspective view
/// (`a_lamps_shadow_view_holds_...`).
#[test]
fn a_lamp_among_its_casters_shadows_every_way() {
    let scene = |shadows: bool, intensity: f32| {
        let mut marker = Mesh::default();
        push_floor_marker(&mut marker);
        let mut model = Model::from_painted_mesh("lamp among blocks", marker);
        for centre in [Vec3::new(-0.012, 0.006, -0.024), Vec3::new(0.006, 0.012, -0.024)] {
            let mut mesh = Mesh::default();
            mesh.push_cube(centre, 0.003, [0.8, 0.8, 0.8, 1.0]);
            model.primitives.push(phantogram::model::Primitive {
                mesh,
                material: 0,
                is_floor: false,
                lods: Vec::new(),
            });
        }
        let lamp = phantogram::render::Lamp {
            position_m: Vec3::new(0.0, 0.0, -0.022),
            axis: Vec3::NEG_Z,
            cone_half_angle_rad: None,
            intensity_rgb: Vec3::splat(intensity),
        };
        render_over_floor_lit(model, shadows, OBLIQUE_LIGHT, Some(lamp))
    };
    let Some((pixels, proj, shadow_triangles)) = scene(true, 0.004) else {
        return;
    };
    let (without, _, none) = scene(false, 0.004).expect("a GPU");
    let (dark_lamp, _, _) = scene(true, 0.0).expect("a GPU");
    // Three casters of 12 triangles each: the marker in the +Y face's frustum, each block in
    // two (each touches the diagonal between its face and the next: the −x block reaches
    // |y| = |x| at (−9, 9) mm from the lamp): five draws, 60 triangles; unculled, 216.
    println!("shadow passes drew {shadow_triangles} triangles (casters 36, six faces unculled 216)");
    assert_eq!(none, 0, "no shadow pass without shadows");
    assert!(
        (36..=72).contains(&shadow_triangles),
        "{shadow_triangles} triangles in the cube's passes"
    );
    let floor_z = -0.031;
    let at = |px: &[u8], (x, y): (f32, f32)| luminance_at(px, &proj, Vec3::new(x, y, floor_z));
    // Luminance is in 8-bit levels: two and a half are a rounding of each channel.
    let near = |a: f32, b: f32| (a - b).abs() < 2.5;
    for (name, (x, y)) in [
        ("beyond the −x block", (-0.029, 0.018)),
        ("beyond the +y block", (0.018, 0.029)),
    ] {
        let dark = at(&pixels, (x, y));
        let room_only = at(&dark_lamp, (x, y));
        println!("{name}: {dark} in the shadow, {room_only} in the room's light alone");
        assert!(
            near(dark, room_only),
            "{name}: the shadow {dark} vs the room's light alone {room_only}"
        );
        for mirror in [(-x, y), (x, -y), (-x, -y)] {
            let lit = at(&pixels, mirror);
            assert!(
                lit > room_only + 20.0,
                "{name}: the lamp lights {mirror:?} ({lit} vs {room_only})"
            );
            assert!(
                near(lit, at(&without, mirror)),
                "{name}: {mirror:?} is lit as without shadows"
            );
        }
        assert!(
            near(at(&without, (x, y)), at(&without, (-x, -y))),
            "{name}: without shadows alike"
        );
    }
    for p in [(-0.018, 0.0), (0.0, 0.018), (0.01, -0.01), (-0.02, -0.02)] {
        let (with, plain) = (at(&pixels, p), at(&without, p));
        assert!(near(with, plain), "{p:?}: {with} with shadows, {plain} without");
    }
}

#[test]
fn alpha_masked_surfaces_shadow_only_where_they_are_kept() {
    use phantogram::model::{AlphaMode, Image, Material, Primitive, TextureRef};
    // Two cubes 15 mm above the floor, both alpha-masked at 0.5: one kept, one cut out by its
    // base-colour texture's alpha of 0. Only the kept one may shadow the floor.
    let mut marker = Mesh::default();
    push_floor_marker(&mut marker);
    let mut model = Model::from_painted_mesh("masked shadows", marker);
    model.images.push(Image {
        name: "transparent".into(),
        width: 1,
        height: 1,
        rgba8: vec![255, 255, 255, 0],
        basis: None,
    });
    let transparent = TextureRef {
        image: 0,
        tex_coord: 0,
        transform: Default::default(),
        sampler: Default::default(),
    };
    let (kept_y, cut_y) = (0.012, -0.012);
    for (y, texture) in [(kept_y, None), (cut_y, Some(transparent))] {
        let mut mesh = Mesh::default();
        mesh.push_cube(Vec3::new(0.0, y, -0.015), 0.004, [1.0; 4]);
        model.materials.push(Material {
            name: "masked".into(),
            base_color: [0.8, 0.8, 0.8, 1.0],
            metallic: 0.0,
            alpha: AlphaMode::Mask(0.5),
            base_color_texture: texture,
            ..Material::default()
        });
        model.primitives.push(Primitive {
            mesh,
            material: model.materials.len() - 1,
            is_floor: false,
            lods: Vec::new(),
        });
    }
    let Some((pixels, proj)) = render_over_floor(model, true, OBLIQUE_LIGHT) else {
        return;
    };
    // As in `shadows_fall_where_the_light_says`: each cube's shadow centre is 7.5 mm towards −x.
    let floor = |x: f32, y: f32| luminance_at(&pixels, &proj, Vec3::new(x, y, -0.03));
    let (kept_shadow, kept_lit) = (floor(-0.0075, kept_y), floor(0.0075, kept_y));
    let (cut_shadow, cut_lit) = (floor(-0.0075, cut_y), floor(0.0075, cut_y));
    println!(
        "floor luminance in / beside the shadow: kept cube {kept_shadow} / {kept_lit}, cut-out cube {cut_shadow} / {cut_lit}"
    );
    assert!(
        kept_shadow < 0.6 * kept_lit,
        "kept: shadow {kept_shadow} vs lit {kept_lit}"
    );
    assert!(
        (cut_shadow - cut_lit).abs() < 0.05 * cut_lit,
        "cut out: {cut_shadow} where its shadow would be vs {cut_lit}"
    );
}

#[test]
fn lit_floor_has_no_acne_and_resting_objects_no_gap() {
    let Some((with, proj)) = shadow_scene(Vec3::new(0.0, 0.0, -0.026), 0.004, true) else {
        return;
    };
    let Some((without, _)) = shadow_scene(Vec3::new(0.0, 0.0, -0.026), 0.004, false) else {
        return;
    };
    // Acne: a lit stretch of floor away from the cube is as bright with shadows as without,
    // everywhere in a 12 × 12 mm patch.
    let mut worst = 0.0f32;
    for i in 0..12 {
        for j in 0..12 {
            let p = Vec3::new(0.008 + i as f32 * 0.001, 0.01 + j as f32 * 0.001, -0.03);
            worst = worst.max((luminance_at(&with, &proj, p) - luminance_at(&without, &proj, p)).abs());
        }
    }
    assert!(
        worst <= 2.0,
        "self-shadowing on a lit floor: luminance differs by up to {worst}"
    );
    // Peter-panning: the cube rests on the floor (bottom at −30 mm); its shadow starts at its
    // edge, so the floor half a millimetre beyond the shadowed side is dark.
    let beside = Vec3::new(-0.0045, 0.0, -0.03);
    let far = Vec3::new(-0.0045, 0.012, -0.03);
    let (near_l, far_l) = (luminance_at(&with, &proj, beside), luminance_at(&with, &proj, far));
    println!("floor beside the resting cube {near_l}, away from it {far_l}");
    assert!(
        near_l < 0.6 * far_l,
        "shadow detached from a resting object: {near_l} vs {far_l}"
    );
}

/// The shadow map covers what stands on the floor, not the floor (its texels would be ~10× coarser
/// over the floor's extent). But a light below the floor's plane (the phone tilted past it) is
/// hidden by the floor from everything on it: a face turned towards such a light stays in shadow.
#[test]
fn a_light_below_the_floor_is_blocked_by_it() {
    // A cube turned 45° about y: one face looks up and towards +x, visible from the eye above and
    // facing a light 17° below the floor's plane from +x (n·l ≈ 0.47). The ray from that face's
    // centre towards the light meets the floor 72 mm further on, well inside it.
    let below = Vec3::new(1.0, 0.0, -0.3);
    let centre = Vec3::new(-0.015, 0.0, -0.015);
    let render = |shadows: bool| {
        let mut mesh = Mesh::default();
        mesh.push_cube(Vec3::ZERO, 0.008, [0.8, 0.8, 0.8, 1.0]);
        mesh.transform(Mat4::from_translation(centre) * Mat4::from_rotation_y(-std::f32::consts::FRAC_PI_4));
        push_floor_marker(&mut mesh);
        render_over_floor(Model::from_painted_mesh("light below", mesh), shadows, below)
    };
    let Some((with, proj)) = render(true) else { return };
    let Some((without, _)) = render(false) else { return };
    let face_centre = centre + Vec3::new(1.0, 0.0, 1.0).normalize() * 0.008;
    let face: Vec<Vec3> = (-2..=2).map(|k| face_centre + Vec3::Y * (0.002 * k as f32)).collect();
    let mean = |pixels: &[u8]| face.iter().map(|&p| luminance_at(pixels, &proj, p)).sum::<f32>() / face.len() as f32;
    let (shadowed, lit) = (mean(&with), mean(&without));
    println!("face towards a light below the floor: {shadowed} with shadows, {lit} without");
    assert!(
        shadowed < 0.6 * lit,
        "the floor let the light through: {shadowed} vs {lit}"
    );
}

/// The environment is fixed in the room: with a sky-only environment (no directional light), the
/// glass-facing side of a cube is bright while the device lies face up, and dark once the device
/// is turned face down, although nothing moved in the device frame.
#[test]
fn environment_light_turns_with_the_device() {
    let Some(gpu) = gpu() else { return };
    let screen = Screen::default();
    let mut mesh = Mesh::default();
    mesh.push_cube(Vec3::new(0.0, 0.0, -0.02), 0.01, [0.8, 0.8, 0.8, 1.0]);
    let model = Model::from_painted_mesh("cube", mesh);
    let mut renderer = Renderer::new(gpu, &model).unwrap();
    let mut sky = phantogram::ibl::Environment::studio();
    for (i, t) in sky.texels.iter_mut().enumerate() {
        let above = i / sky.width < sky.height / 2;
        *t = if above { [1.0; 3] } else { [0.0; 3] };
    }
    renderer.set_environment(&sky).unwrap();
    renderer.lighting.light_rgb = Vec3::ZERO;
    renderer.lighting.shadows = false;
    let eye = Vec3::new(0.0, 0.0, 0.3);
    let mono = OffAxisProjection::new(&screen, eye, DepthRange::default()).unwrap();
    let frame = |renderer: &mut Renderer, q: phantogram::glam::Quat| {
        let input = FrameInput {
            left: &mono,
            right: &mono,
            mono: &mono,
            toward_light: Vec3::Z,
            device_to_world: q,
            offset: Vec3::ZERO,
            levels: &[],
            fades: &[],
        };
        renderer.render(&input, Method::Mono, W, H).unwrap()
    };
    let brightness = |renderer: &mut Renderer, q| luminance_at(&frame(renderer, q), &mono, Vec3::new(0.0, 0.0, -0.01));
    let face_up = brightness(&mut renderer, phantogram::glam::Quat::IDENTITY);
    let face_down = brightness(
        &mut renderer,
        phantogram::glam::Quat::from_rotation_x(std::f32::consts::PI),
    );
    println!("cube top under a sky: device face up {face_up}, face down {face_down}");
    assert!(face_up > 2.0 * face_down, "{face_up} vs {face_down}");

    // Made with the sky from the start (the studio never prefiltered), the renderer draws the
    // same frame to the byte.
    let Some(second_gpu) = self::gpu() else { return };
    let mut from_start = Renderer::with_environment(second_gpu, &model, Some(&sky)).unwrap();
    from_start.lighting = renderer.lighting;
    let tilted = phantogram::glam::Quat::from_rotation_x(0.4);
    assert!(
        frame(&mut from_start, tilted) == frame(&mut renderer, tilted),
        "with_environment differs from set_environment"
    );
}

/// Specular image-based light comes from the prefiltered environment in the reflection direction
/// (split sum), not from the irradiance: under a small bright disc at the zenith and nothing
/// else, a mirror-smooth metal top seen from straight above reflects the disc (≈ F0 × its
/// radiance), while a fully rough one spreads it over the hemisphere and stays dark. Irradiance
/// alone would make both dark (the disc covers 1.5 % of the sky).
#[test]
fn mirror_metal_reflects_the_environment_and_rough_metal_blurs_it() {
    let Some(gpu) = gpu() else { return };
    let screen = Screen::default();
    let mut disc = phantogram::ibl::Environment::studio();
    disc.width = 256;
    disc.height = 128;
    disc.texels = (0..disc.height)
        .flat_map(|y| (0..256).map(move |x| (x, y)))
        .map(|(x, y)| {
            let d = phantogram::ibl::Environment {
                width: 256,
                height: 128,
                texels: Vec::new(),
            }
            .direction(x, y);
            if d.z > 10f32.to_radians().cos() {
                [1.0; 3]
            } else {
                [0.0; 3]
            }
        })
        .collect();
    let eye = Vec3::new(0.0, 0.0, 0.3);
    let mono = OffAxisProjection::new(&screen, eye, DepthRange::default()).unwrap();
    let cube = |roughness: f32| {
        let mut mesh = Mesh::default();
        mesh.push_cube(Vec3::new(0.0, 0.0, -0.02), 0.01, [0.9, 0.9, 0.9, 1.0]);
        for v in &mut mesh.vertices {
            v.material = [1.0, 1.0];
        }
        let mut model = Model::from_painted_mesh("metal cube", mesh);
        model.materials[0].metallic = 1.0;
        model.materials[0].roughness = roughness;
        model
    };
    let mut renderer = Renderer::new(gpu, &cube(0.05)).unwrap();
    renderer.set_environment(&disc).unwrap();
    renderer.lighting.light_rgb = Vec3::ZERO;
    renderer.lighting.shadows = false;
    let mut top = |model: &Model| {
        renderer.set_model(model).unwrap();
        let input = FrameInput {
            left: &mono,
            right: &mono,
            mono: &mono,
            toward_light: Vec3::Z,
            device_to_world: phantogram::glam::Quat::IDENTITY,
            offset: Vec3::ZERO,
            levels: &[],
            fades: &[],
        };
        let px = renderer.render(&input, Method::Mono, W, H).unwrap();
        luminance_at(&px, &mono, Vec3::new(0.0, 0.0, -0.01))
    };
    let (mirror, rough) = (top(&cube(0.05)), top(&cube(1.0)));
    println!("metal top under a zenith disc: mirror {mirror}, rough {rough}");
    assert!(mirror > 150.0, "the mirror should show the disc: {mirror}");
    assert!(mirror > 3.0 * rough, "{mirror} vs {rough}");
}

/// Each material's pipeline samples only the texture slots it has (render.rs,
/// `MaterialVariant`). Skipping a slot must look exactly like sampling its neutral default: the
/// amphora with only a (tilted) normal map, drawn by its specialised pipeline, equals the same
/// amphora with every other slot filled by a neutral 1×1 image, drawn by the general one. Were a
/// present texture skipped, or a missing one replaced by the wrong value, the frames would differ.
#[test]
fn pipelines_that_skip_missing_textures_draw_the_same_picture() {
    use phantogram::model::{Image, TextureRef};
    let Some(gpu) = gpu() else { return };
    let image = |name: &str, rgba: [u8; 4]| Image {
        name: name.into(),
        width: 2,
        height: 2,
        rgba8: rgba.repeat(4),
        basis: None,
    };
    let slot = |image: usize| TextureRef {
        image,
        tex_coord: 0,
        transform: Default::default(),
        sampler: Default::default(),
    };
    let mut normal_only = default_model();
    // Normals tilted 30° towards +u: visibly different shading if the map were skipped.
    normal_only.images.push(image("tilted normal", [192, 128, 238, 255]));
    normal_only.materials[0].normal_texture = Some((slot(0), 1.0));
    let mut every_slot = normal_only.clone();
    every_slot.images.push(image("white", [255; 4]));
    let m = &mut every_slot.materials[0];
    m.base_color_texture = Some(slot(1));
    m.metallic_roughness_texture = Some(slot(1));
    m.occlusion_texture = Some((slot(1), 1.0));
    m.emissive_texture = Some(slot(1));
    let view = oblique_view();
    let input = phantogram::engine::frame_input(&view, Vec3::ZERO);
    let mut renderer = Renderer::new(gpu, &normal_only).unwrap();
    let specialised = renderer.render(&input, Method::DuboisRedCyan, W, H).unwrap();
    renderer.set_model(&every_slot).unwrap();
    let general = renderer.render(&input, Method::DuboisRedCyan, W, H).unwrap();
    renderer.set_model(&default_model()).unwrap();
    let untextured = renderer.render(&input, Method::DuboisRedCyan, W, H).unwrap();
    let max_diff = |a: &[u8], b: &[u8]| a.iter().zip(b).map(|(x, y)| x.abs_diff(*y)).max().unwrap_or(0);
    assert!(
        max_diff(&specialised, &untextured) > 8,
        "the normal map should change the picture"
    );
    let d = max_diff(&specialised, &general);
    assert!(d <= 1, "specialised and general pipelines differ by {d} levels");
}

/// Whether `gpu` runs the compute shaders of [`run_compute`] (64 invocations, storage buffers):
/// an OpenGL ES 3.0 device, or any under `PHANTOGRAM_GPU_LIMITS=gles3`, does not.
fn computes(gpu: &Gpu) -> bool {
    let limits = gpu.device.limits();
    gpu.adapter
        .get_downlevel_capabilities()
        .flags
        .contains(phantogram::wgpu::DownlevelFlags::COMPUTE_SHADERS)
        && limits.max_storage_buffers_per_shader_stage >= 2
        && limits.max_compute_workgroup_size_x >= 64
        && limits.max_compute_invocations_per_workgroup >= 64
}

/// Runs `shader`'s compute entry point `main` (workgroups of 64) over `queries` and returns its
/// `results`, `per_query` f32s a query. Its group 0 holds `leading` at bindings 0, 1, …, then
/// the queries (`array<vec4<f32>>`, read-only storage) and the results (read-write storage).
fn run_compute(
    gpu: &Gpu,
    shader: &str,
    leading: &[phantogram::wgpu::BindingResource<'_>],
    queries: &[[f32; 4]],
    per_query: usize,
) -> Vec<f32> {
    use phantogram::wgpu;
    use phantogram::wgpu::util::DeviceExt;
    let device = &gpu.device;
    let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("queries"),
        contents: bytemuck::cast_slice(queries),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let size = (queries.len() * per_query * 4) as u64;
    let results = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("results"),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("compute test"),
        source: wgpu::ShaderSource::Wgsl(shader.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("compute test"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let mut entries: Vec<wgpu::BindGroupEntry> = leading
        .iter()
        .enumerate()
        .map(|(k, r)| wgpu::BindGroupEntry {
            binding: k as u32,
            resource: r.clone(),
        })
        .collect();
    let n = leading.len() as u32;
    entries.push(wgpu::BindGroupEntry {
        binding: n,
        resource: input.as_entire_binding(),
    });
    entries.push(wgpu::BindGroupEntry {
        binding: n + 1,
        resource: results.as_entire_binding(),
    });
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups((queries.len() as u32).div_ceil(64), 1, 1);
    }
    encoder.copy_buffer_to_buffer(&results, 0, &readback, 0, size);
    gpu.queue.submit([encoder.finish()]);
    readback.slice(..).map_async(wgpu::MapMode::Read, |r| r.unwrap());
    device.poll(wgpu::PollType::wait_indefinitely()).unwrap();
    let bytes = readback.slice(..).get_mapped_range().expect("mapped").to_vec();
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// The shadow filter in `scene.wgsl` (`shadow_pcf`, four gathers) gives the same visibility as
/// the nine bilinear comparisons it stands for: the function, cut out of the real shader, runs in
/// a compute pass beside a plain nine-tap reference, on a random depth map at 4096 random lookups
/// whose receiver depths make most of them partly lit. A wrong weight or a gather placed on the
/// wrong block moves the result by tenths.
#[test]
fn shadow_filter_equals_nine_bilinear_comparisons() {
    use phantogram::wgpu;
    use phantogram::wgpu::util::DeviceExt;
    let Some(gpu) = gpu() else { return };
    // The test writes its depth map from the CPU and reads results from a storage buffer, which
    // OpenGL ES devices may lack (the renderer itself does neither).
    let copies = wgpu::DownlevelFlags::DEPTH_TEXTURE_AND_BUFFER_COPIES;
    if !gpu.adapter.get_downlevel_capabilities().flags.contains(copies) || !computes(&gpu) {
        println!("skipped: the device cannot copy into depth textures or run compute shaders");
        return;
    }
    let source = phantogram::render::SCENE_WGSL;
    let (begin, end) = ("// BEGIN shadow_pcf", "// END shadow_pcf");
    let pcf = &source[source.find(begin).expect(begin)..source.find(end).expect(end)];
    let shader = format!(
        "@group(0) @binding(0) var shadow_map: texture_depth_2d;
@group(0) @binding(1) var shadow_sampler: sampler_comparison;
@group(0) @binding(2) var<storage, read> queries: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> results: array<vec2<f32>>;
{pcf}
fn nine_taps(uv: vec2<f32>, depth: f32) -> f32 {{
    let size = vec2<f32>(textureDimensions(shadow_map));
    var lit = 0.0;
    for (var dy = -1; dy <= 1; dy = dy + 1) {{
        for (var dx = -1; dx <= 1; dx = dx + 1) {{
            lit = lit + textureSampleCompareLevel(shadow_map, shadow_sampler, uv + vec2<f32>(f32(dx), f32(dy)) / size, depth);
        }}
    }}
    return lit / 9.0;
}}
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {{
    if (id.x >= arrayLength(&queries)) {{
        return;
    }}
    let q = queries[id.x];
    results[id.x] = vec2<f32>(shadow_pcf(q.xy, q.z), nine_taps(q.xy, q.z));
}}"
    );
    let device = &gpu.device;
    // Deterministic pseudo-random numbers in [0, 1).
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    const SIZE: u32 = 64;
    let depths: Vec<u16> = (0..SIZE * SIZE).map(|_| (next() * 65535.0) as u16).collect();
    let map = device.create_texture_with_data(
        &gpu.queue,
        &wgpu::TextureDescriptor {
            label: Some("random depths"),
            size: wgpu::Extent3d {
                width: SIZE,
                height: SIZE,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Depth16Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytemuck::cast_slice(&depths),
    );
    // The renderer's comparison sampler.
    let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        compare: Some(wgpu::CompareFunction::LessEqual),
        ..Default::default()
    });
    const N: usize = 4096;
    let queries: Vec<[f32; 4]> = (0..N)
        .map(|_| [0.05 + 0.9 * next(), 0.05 + 0.9 * next(), 0.25 + 0.5 * next(), 0.0])
        .collect();
    let view = map.create_view(&Default::default());
    let values = run_compute(
        &gpu,
        &shader,
        &[
            wgpu::BindingResource::TextureView(&view),
            wgpu::BindingResource::Sampler(&sampler),
        ],
        &queries,
        2,
    );
    let (mut worst, mut partial) = (0.0f32, 0);
    for pair in values.chunks_exact(2) {
        worst = worst.max((pair[0] - pair[1]).abs());
        if pair[1] > 0.05 && pair[1] < 0.95 {
            partial += 1;
        }
    }
    println!("shadow_pcf vs nine taps: largest difference {worst:.5} over {N} lookups, {partial} partly lit");
    assert!(
        partial > N / 2,
        "only {partial} lookups partly lit: the test would prove little"
    );
    // Bilinear weights are quantised (8 fractional bits on lavapipe, as on most GPUs).
    assert!(worst < 0.01, "largest difference {worst}");
}

/// The lamp cube's depth in `scene.wgsl` (`cube_depth`, cut out of the real shader) is the one
/// the faces store (`point_shadow::cube_depth`, which the render crate's tests check against
/// the faces' projection): both run on the same distances and ranges, from a tenth of a
/// millimetre to the far plane.
#[test]
fn the_shaders_cube_depth_is_the_faces() {
    use phantogram::render::point_shadow::cube_depth;
    let Some(gpu) = gpu() else { return };
    if !computes(&gpu) {
        println!("skipped: the device runs no compute shaders");
        return;
    }
    let source = phantogram::render::SCENE_WGSL;
    let (begin, end) = ("// BEGIN cube_depth", "// END cube_depth");
    let function = &source[source.find(begin).expect(begin)..source.find(end).expect(end)];
    let shader = format!(
        "@group(0) @binding(0) var<storage, read> queries: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> results: array<f32>;
{function}
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {{
    if (id.x < arrayLength(&queries)) {{
        let q = queries[id.x];
        results[id.x] = cube_depth(q.x, q.y, q.z);
    }}
}}"
    );
    let mut queries: Vec<[f32; 4]> = Vec::new();
    for far in [0.05f32, 0.3, 2.0] {
        let near = far * 1e-3;
        for k in 0..=40 {
            let major = near + (far - near) * (k as f32 / 40.0).powi(3);
            queries.push([major, near, far, 0.0]);
        }
    }
    let values = run_compute(&gpu, &shader, &[], &queries, 1);
    for (q, &got) in queries.iter().zip(&values) {
        let want = cube_depth(q[0], q[1], q[2]);
        assert!(
            (got - want).abs() < 1e-5,
            "major {} near {} far {}: {got} vs {want}",
            q[0],
            q[1],
            q[2]
        );
    }
}

/// `KHR_materials_unlit`: an unlit surface shows its base colour whatever the light does; the
/// same surface lit changes with the light's direction.
#[test]
fn unlit_materials_ignore_the_light() {
    let Some(gpu) = gpu() else { return };
    let view = oblique_view();
    let mut mesh = Mesh::default();
    mesh.push_cube(Vec3::new(0.0, 0.0, 0.005), 0.012, [1.0; 4]);
    let mut model = Model::from_painted_mesh("cube", mesh);
    model.materials[0].base_color = [0.5, 0.25, 0.1, 1.0];
    model.materials[0].metallic = 0.0;
    let centre = |pixels: &[u8]| {
        let i = ((H / 2) * W + W / 2) as usize * 4;
        [pixels[i], pixels[i + 1], pixels[i + 2]]
    };
    let mut renderer = Renderer::new(gpu, &model).unwrap();
    let colours = |renderer: &mut Renderer| {
        [Vec3::new(0.2, 0.3, 1.0), Vec3::new(-1.0, -0.6, 0.3)].map(|light| {
            let mut input = phantogram::engine::frame_input(&view, Vec3::ZERO);
            input.toward_light = light.normalize();
            centre(&renderer.render(&input, Method::Mono, W, H).unwrap())
        })
    };
    let [lit_a, lit_b] = colours(&mut renderer);
    let differs = |a: [u8; 3], b: [u8; 3]| a.iter().zip(b).map(|(x, y)| x.abs_diff(y)).max().unwrap_or(0);
    assert!(
        differs(lit_a, lit_b) > 10,
        "the lit cube did not change with the light: {lit_a:?} {lit_b:?}"
    );
    model.materials[0].unlit = true;
    renderer.set_model(&model).unwrap();
    let [unlit_a, unlit_b] = colours(&mut renderer);
    assert!(
        differs(unlit_a, unlit_b) <= 1,
        "the unlit cube changed with the light: {unlit_a:?} {unlit_b:?}"
    );
    // Its colour is the base colour's hue: red over green over blue.
    assert!(unlit_a[0] > unlit_a[1] && unlit_a[1] > unlit_a[2], "{unlit_a:?}");
}

/// Centroid of the annotation markers' amber pixels (unlit: the same in any light).
fn amber_centroid(pixels: &[u8]) -> Option<(f32, f32, usize)> {
    let (mut sx, mut sy, mut n) = (0.0, 0.0, 0usize);
    for (i, px) in pixels.chunks(4).enumerate() {
        let (r, g, b) = (px[0] as i32, px[1] as i32, px[2] as i32);
        if r > 150 && r - b > 90 && g > b + 30 {
            sx += (i as u32 % W) as f32 + 0.5;
            sy += (i as u32 / W) as f32 + 0.5;
            n += 1;
        }
    }
    (n > 0).then(|| (sx / n as f32, sy / n as f32, n))
}

/// Annotation markers are drawn with the artifact: at their true depth in each eye (on the pixel
/// the eye's projection predicts, within a pixel), and hidden where the artifact is in front.
#[test]
fn annotation_markers_land_on_their_pixel_in_each_eye_and_hide_behind_the_artifact() {
    use phantogram::model::Annotation;
    let Some(gpu) = gpu() else { return };
    let screen = Screen::default();
    let view = oblique_view();
    let scale = W as f32 / screen.width_px() as f32;
    let model_with = |position: Vec3, direction: Vec3| {
        let mut mesh = Mesh::default();
        mesh.push_cube(Vec3::new(0.0, 0.0, 0.005), 0.012, [0.5, 0.5, 0.5, 1.0]);
        let mut model = Model::from_painted_mesh("cube", mesh);
        model.annotations.push(Annotation {
            id: "a".into(),
            title: "A".into(),
            lead: String::new(),
            position,
            direction,
        });
        model.add_annotation_pins();
        model
    };
    let visible = [
        (Vec3::new(0.004, 0.003, 0.017), Vec3::Z),  // on the top, in front of the glass
        (Vec3::new(-0.003, 0.012, 0.0), Vec3::Y),   // on the face towards the eyes, at the glass
        (Vec3::new(0.006, 0.012, -0.004), Vec3::Y), // on the same face, behind the glass
    ];
    // The eyes are above the glass towards its top edge (+y, +z).
    assert!(view.left.eye_m.y > 0.05 && view.left.eye_m.z > 0.05);
    let mut renderer = Renderer::new(gpu, &model_with(visible[0].0, visible[0].1)).unwrap();
    let input = phantogram::engine::frame_input(&view, Vec3::ZERO);
    for (position, direction) in visible {
        renderer.set_model(&model_with(position, direction)).unwrap();
        let centre = position + direction * Model::PIN_RADIUS_M * 1.5;
        for (name, proj) in [("left", &view.left), ("right", &view.right)] {
            let pixels = renderer.render_single(proj, &input, W, H).unwrap();
            let (x, y, n) =
                amber_centroid(&pixels).unwrap_or_else(|| panic!("marker at {position} not visible ({name} eye)"));
            let want = proj.project(centre).unwrap().pixel * scale;
            let err = ((x - want.x).powi(2) + (y - want.y).powi(2)).sqrt();
            println!("marker at {position}, {name} eye: {n} px at ({x:.2}, {y:.2}), predicted {want}, error {err:.3}");
            assert!(err < 1.0, "marker at {position}, {name} eye: {err} px from its pixel");
        }
    }
    // Under the cube (its far side from the viewer): hidden in both eyes. (A marker on a side
    // face is seen by one eye only, as a real mark would be.)
    renderer
        .set_model(&model_with(Vec3::new(0.0, 0.004, -0.007), -Vec3::Z))
        .unwrap();
    for proj in [&view.left, &view.right] {
        let pixels = renderer.render_single(proj, &input, W, H).unwrap();
        assert_eq!(
            amber_centroid(&pixels).map(|c| c.2),
            None,
            "a marker behind the artifact shows"
        );
    }
}

/// Where the adapter has timestamp queries (lavapipe has), each frame's GPU time is read back
/// once, without waiting, and is no longer than the frame took on the clock.
#[test]
fn frames_are_timed_on_the_gpu_once_per_reading() {
    let Some(gpu) = gpu() else { return };
    let mut renderer = Renderer::new(gpu, &default_model()).unwrap();
    if !renderer.times_gpu() {
        eprintln!("the adapter has no timestamp queries: frames are timed by the clock");
        return;
    }
    let view = oblique_view();
    let input = phantogram::engine::frame_input(&view, Vec3::ZERO);
    let mut readings = 0;
    for _ in 0..4 {
        let start = std::time::Instant::now();
        renderer.render(&input, Method::DuboisRedCyan, W, H).unwrap();
        let wall_s = start.elapsed().as_secs_f64();
        // `render` waits for its frame to be read back, so the frame's own reading is ready.
        let gpu_s = renderer.take_gpu_time_s().expect("a reading for the frame just drawn");
        assert!(gpu_s > 0.0 && gpu_s <= wall_s * 1.05, "GPU {gpu_s} s, wall {wall_s} s");
        assert_eq!(renderer.take_gpu_time_s(), None, "each reading is handed out once");
        readings += 1;
    }
    assert_eq!(readings, 4);
}
