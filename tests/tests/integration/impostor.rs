//! Relief-texture impostors (issue 22): a part drawn as its impostor puts each surface point
//! within a pixel of the glass of where its polygons put it, in each eye; it hides and is hidden
//! by polygons where they cross; lit, it looks like the polygons; golden frames of both.
//!
//! The test object is a bumpy ball painted in flat cells of five colours (no two neighbours
//! alike), 12 mm across, straddling the glass as the diorama places artifacts, crossed by a
//! polygon cube. Drawn unlit, every pixel's colour names the cell it shows, so a pixel of the
//! impostor's frame whose colour appears nowhere within one pixel of the same place in the
//! polygons' frame is a surface point more than a pixel away from where the polygons draw it.

use crate::golden;

use phantogram::FrameView;
use phantogram::anaglyph::Method;
use phantogram::glam::Vec3;
use phantogram::model::{DioramaFit, Mesh, Model, Vertex};
use phantogram::render::{FrameInput, Gpu, IMPOSTOR_LEVEL, ImpostorBox, Renderer};
use phantogram::screen::Screen;

fn gpu() -> Option<Gpu> {
    phantogram_integration::gpu_or_skip()
}

const CELL_COLOURS: [[f32; 3]; 5] = [
    [0.9, 0.1, 0.1],
    [0.1, 0.8, 0.1],
    [0.1, 0.2, 0.9],
    [0.9, 0.9, 0.9],
    [0.1, 0.1, 0.1],
];
const CUBE_COLOUR: [f32; 4] = [0.9, 0.8, 0.1, 1.0];

/// The bumpy ball (glTF frame, +Y up, radius about 1), one flat colour per cell of 10 × 6
/// (longitude × latitude), vertices not shared between triangles so cells meet at sharp edges.
fn painted_ball() -> Mesh {
    let (lon_steps, lat_steps) = (120usize, 72usize);
    let point = |i: usize, j: usize| {
        let lon = i as f32 / lon_steps as f32 * std::f32::consts::TAU;
        let lat = j as f32 / lat_steps as f32 * std::f32::consts::PI;
        let dir = Vec3::new(lat.sin() * lon.cos(), lat.cos(), lat.sin() * lon.sin());
        // Bumps the six views cannot all see around, but no cavity hidden from all six.
        let r = 1.0 + 0.12 * (3.0 * lon).sin() * (2.0 * lat).sin() * lat.sin();
        dir * r
    };
    let mut mesh = Mesh::default();
    for j in 0..lat_steps {
        for i in 0..lon_steps {
            let cell = (i * 10 / lon_steps) + 2 * (j * 6 / lat_steps);
            let c = CELL_COLOURS[cell % 5];
            let quad = [point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)];
            for tri in [[0, 2, 1], [0, 3, 2]] {
                let [a, b, c3] = tri.map(|k| quad[k]);
                let n = (b - a).cross(c3 - a).normalize_or_zero();
                if n == Vec3::ZERO {
                    continue;
                }
                let base = mesh.vertices.len() as u32;
                for p in [a, b, c3] {
                    mesh.vertices.push(Vertex {
                        position: p.to_array(),
                        // Smooth, outward: the lit frames compare shading too.
                        normal: p.normalize().to_array(),
                        tangent: [0.0; 4],
                        uv: [0.0; 4],
                        color: [c[0], c[1], c[2], 1.0],
                        material: [1.0, 1.0],
                    });
                }
                mesh.indices.extend([base, base + 1, base + 2]);
            }
        }
    }
    mesh
}

/// The ball fitted 12 mm tall into the diorama (straddling the glass), and a cube through its
/// side as a second primitive.
fn scene(unlit: bool) -> Model {
    let mut model = Model::from_painted_mesh("painted ball", painted_ball());
    model.materials[0].unlit = unlit;
    let fit = DioramaFit {
        max_height_m: 0.012,
        ..DioramaFit::default()
    };
    model.fit_to_diorama(&Screen::default(), &fit);
    let b = model.bounds().expect("a ball");
    let centre = (b.min + b.max) * 0.5;
    let r = (b.max - b.min).x * 0.5;
    let mut cube = Mesh::default();
    cube.push_cube(centre + Vec3::new(0.8 * r, 0.3 * r, 0.0), 0.35 * r, CUBE_COLOUR);
    model.primitives.push(phantogram::model::Primitive {
        mesh: cube,
        material: 0,
        is_floor: false,
        lods: Vec::new(),
    });
    model
}

fn oblique_view() -> FrameView {
    phantogram_integration::held_view(30.0, 0.15)
}

/// Fraction of covered pixels (not background in either frame) of `a` with no pixel of the
/// same colour (within `tolerance` per channel) in `b` within one pixel, and the same from `b`
/// to `a`: the larger of the two.
fn unmatched_within_a_pixel(a: &[u8], b: &[u8], width: usize, height: usize, background: [u8; 3]) -> (f64, usize) {
    let tolerance = 12i32;
    let at = |img: &[u8], x: usize, y: usize| {
        let i = (y * width + x) * 4;
        [img[i], img[i + 1], img[i + 2]]
    };
    let close = |p: [u8; 3], q: [u8; 3]| (0..3).all(|k| (i32::from(p[k]) - i32::from(q[k])).abs() <= tolerance);
    let one_way = |from: &[u8], to: &[u8]| {
        let (mut covered, mut missed) = (0usize, 0usize);
        for y in 1..height - 1 {
            for x in 1..width - 1 {
                let p = at(from, x, y);
                if close(p, background) {
                    continue;
                }
                covered += 1;
                let found = (y - 1..=y + 1).any(|v| (x - 1..=x + 1).any(|u| close(at(to, u, v), p)));
                if !found {
                    missed += 1;
                }
            }
        }
        (missed as f64 / covered.max(1) as f64, covered)
    };
    let (ab, covered) = one_way(a, b);
    let (ba, _) = one_way(b, a);
    (ab.max(ba), covered)
}

/// Bakes primitive 0 of the model set at `texels` per side and renders both eyes with polygons
/// only and with the ball as its impostor, at the screen's own pixels.
fn polygons_and_impostor(
    renderer: &mut Renderer,
    model: &Model,
    texels: u32,
) -> ([Vec<u8>; 2], [Vec<u8>; 2], ImpostorBox) {
    let screen = Screen::default();
    let (w, h) = (screen.width_px(), screen.height_px());
    let view = oblique_view();
    let input = phantogram::engine::frame_input(&view, Vec3::ZERO);
    renderer.lighting.shadows = false;
    let bounds = ball_box(model, texels);
    let bytes = renderer.bake_impostors(&[(0, bounds)]).unwrap();
    assert_eq!(bytes, bounds.bytes_on(renderer.gpu().is_opengl()));
    assert!(renderer.has_impostor(0) && !renderer.has_impostor(1));
    let levels = [IMPOSTOR_LEVEL, 0];
    let mixed = FrameInput {
        levels: &levels,
        ..input
    };
    let eyes = [&view.left, &view.right];
    let polygons = eyes.map(|e| renderer.render_single(e, &input, w, h).unwrap());
    let impostor = eyes.map(|e| renderer.render_single(e, &mixed, w, h).unwrap());
    (polygons, impostor, bounds)
}

fn ball_box(model: &Model, texels: u32) -> ImpostorBox {
    ImpostorBox::around(
        model.primitives[0].mesh.vertices.iter().map(|v| Vec3::from(v.position)),
        texels,
    )
    .expect("a box")
}

#[test]
fn an_impostors_surface_lands_within_a_pixel_of_the_polygons_in_each_eye() {
    let Some(gpu) = gpu() else { return };
    let screen = Screen::default();
    let (w, h) = (screen.width_px() as usize, screen.height_px() as usize);
    let model = scene(true);
    let mut renderer = Renderer::new(gpu, &model).unwrap();
    // 384 texels across the 12 mm ball: a texel is 0.03 mm, half the glass's 0.06 mm pixel,
    // and the impostor's error (a texel along a view, half across) under a pixel.
    let (polygons, impostor, bounds) = polygons_and_impostor(&mut renderer, &model, 384);
    // The frame's corner shows the background (the ball is at the glass's centre).
    let bg = [polygons[0][0], polygons[0][1], polygons[0][2]];
    let pixel_m = screen.panel_width_m() / screen.width_px() as f32;
    println!(
        "box {:?}..{:?}, texel error {:.4} mm, glass pixel {:.4} mm",
        bounds.lo,
        bounds.hi,
        bounds.error_m() * 1e3,
        pixel_m * 1e3
    );
    assert!(bounds.texel_m().max_element() < 0.6 * pixel_m);
    for eye in 0..2 {
        let (unmatched, covered) = unmatched_within_a_pixel(&impostor[eye], &polygons[eye], w, h, bg);
        println!(
            "eye {eye}: {covered} covered pixels, {:.4} % not within a pixel",
            unmatched * 100.0
        );
        assert!(covered > 20_000, "eye {eye}: the ball covers only {covered} pixels");
        // Nearly all: where a cell's edge runs exactly along a pixel's centre, either side's
        // colour is right and a sub-texel difference picks the other.
        assert!(
            unmatched < 0.002,
            "eye {eye}: {:.3} % of pixels more than a pixel off",
            unmatched * 100.0
        );
    }
    // The measure sees an impostor too coarse for this glass (the test can fail): at 24 texels
    // (0.55 mm, nine pixels) surface points move by several pixels.
    let (polygons, coarse, bounds) = polygons_and_impostor(&mut renderer, &model, 24);
    assert!(bounds.error_m() > 4.0 * pixel_m);
    let (unmatched, _) = unmatched_within_a_pixel(&coarse[0], &polygons[0], w, h, bg);
    println!("24 texels: {:.2} % not within a pixel", unmatched * 100.0);
    assert!(unmatched > 0.01, "{unmatched}");
}

#[test]
fn a_lit_impostor_looks_like_its_polygons() {
    let Some(gpu) = gpu() else { return };
    let screen = Screen::default();
    let model = scene(false);
    let mut renderer = Renderer::new(gpu, &model).unwrap();
    let (polygons, impostor, _) = polygons_and_impostor(&mut renderer, &model, 256);
    let (w, h) = (screen.width_px(), screen.height_px());
    // Cropped to the ball (the background alone would score near 1).
    let crop = |img: &[u8]| {
        let (x0, y0, cw, ch) = (w / 4, h / 4, w / 2, h / 2);
        let mut out = Vec::with_capacity((cw * ch * 4) as usize);
        for y in y0..y0 + ch {
            let row = ((y * w + x0) * 4) as usize;
            out.extend_from_slice(&img[row..row + (cw * 4) as usize]);
        }
        (out, cw, ch)
    };
    for eye in 0..2 {
        let (a, cw, ch) = crop(&polygons[eye]);
        let (b, _, _) = crop(&impostor[eye]);
        if let Ok(dir) = std::env::var("PHANTOGRAM_SAVE_FRAMES") {
            for (name, px) in [("polygons", &a), ("impostor", &b)] {
                let path = std::path::Path::new(&dir).join(format!("lit-{name}-{eye}.png"));
                image::save_buffer(path, px, cw, ch, image::ExtendedColorType::Rgba8).unwrap();
            }
        }
        let ssim = phantogram_lab::ssim::ssim_rgba8(&a, &b, cw, ch).unwrap();
        println!("eye {eye}: SSIM {ssim:.4} (lit, the ball's half of the frame)");
        assert!(ssim >= 0.98, "eye {eye}: SSIM {ssim}");
    }
    // Golden frames: the Dubois anaglyph of the polygons and of the impostor, small.
    let view = oblique_view();
    let input = phantogram::engine::frame_input(&view, Vec3::ZERO);
    renderer.lighting.shadows = true;
    let levels = [IMPOSTOR_LEVEL, 0];
    let mixed = FrameInput {
        levels: &levels,
        ..input
    };
    let (gw, gh) = (360, 800);
    let full = renderer.render(&input, Method::DuboisRedCyan, gw, gh).unwrap();
    let relief = renderer.render(&mixed, Method::DuboisRedCyan, gw, gh).unwrap();
    golden::check("impostor-polygons-dubois", gw, gh, &full, 3, 0.003);
    golden::check("impostor-relief-dubois", gw, gh, &relief, 3, 0.003);
}

/// A big scan's parts are patches of its shell, open and as thin as the scan's surface: each
/// part's relief hull is that thin too. Every part drawn as its impostor still shows the whole
/// amphora: as many pixels as the polygons (before the hull was grown by a texel and read
/// conservatively, rays stepped through it: 87 % of them at 64 texels, holes where the shell
/// was, and on the turtle most of the shell was gone), and close to their picture (SSIM 0.93 at
/// 128 texels, 360×800; the subdivided relief is at the scale of a pixel there).
#[test]
fn a_big_scans_open_parts_drawn_as_impostors_keep_their_surface() {
    let Some(gpu) = gpu() else { return };
    let mut big = phantogram::artifact::default_model();
    phantogram_lab::big_scan::subdivide_and_displace(&mut big, 2, 0.002, 0.01);
    let report = phantogram::detail::prepare(&mut big, &Default::default(), |_| {});
    assert!(report.parts > 10, "{report:?}");
    let mut renderer = Renderer::new(gpu, &big).unwrap();
    let boxes: Vec<(usize, ImpostorBox)> = (0..big.primitives.len())
        .filter(|&i| !big.primitives[i].lods.is_empty())
        .map(|i| (i, ball_box_of(&big, i, 128)))
        .collect();
    renderer.bake_impostors(&boxes).unwrap();
    let levels: Vec<u8> = (0..big.primitives.len())
        .map(|i| if renderer.has_impostor(i) { IMPOSTOR_LEVEL } else { 0 })
        .collect();
    let view = oblique_view();
    let input = phantogram::engine::frame_input(&view, Vec3::ZERO);
    let relief = FrameInput {
        levels: &levels,
        ..input
    };
    let (w, h) = (360, 800);
    for (k, eye) in [&view.left, &view.right].into_iter().enumerate() {
        let a = renderer.render_single(eye, &input, w, h).unwrap();
        let b = renderer.render_single(eye, &relief, w, h).unwrap();
        // The amphora's pixels: not the background (the frame's corner) in the polygons' frame.
        let bg = [a[0], a[1], a[2]];
        let covered = |img: &[u8]| img.chunks_exact(4).filter(|p| p[..3] != bg).count();
        let (ca, cb) = (covered(&a), covered(&b));
        let ssim = phantogram_lab::ssim::ssim_rgba8(&a, &b, w, h).unwrap();
        println!("eye {k}: {ca} pixels of polygons, {cb} of impostors; SSIM {ssim:.4}");
        if let Ok(dir) = std::env::var("PHANTOGRAM_SAVE_FRAMES") {
            for (name, px) in [("polygons", &a), ("impostors", &b)] {
                let path = std::path::Path::new(&dir).join(format!("big-{name}-{k}.png"));
                image::save_buffer(path, px, w, h, image::ExtendedColorType::Rgba8).unwrap();
            }
        }
        assert!(ca > 10_000, "{ca}");
        assert!(
            (cb as f64) > 0.97 * ca as f64 && (cb as f64) < 1.05 * ca as f64,
            "{cb} of {ca}"
        );
        assert!(ssim > 0.9, "eye {k}: SSIM {ssim}");
    }
}

fn ball_box_of(model: &Model, primitive: usize, texels: u32) -> ImpostorBox {
    ImpostorBox::around(
        model.primitives[primitive]
            .mesh
            .vertices
            .iter()
            .map(|v| Vec3::from(v.position)),
        texels,
    )
    .expect("a box")
}
