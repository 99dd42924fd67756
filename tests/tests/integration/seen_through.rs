//! Glass that blurs or bends what is seen through it (the render crate's `backdrop`,
//! `seen_through` in `scene.wgsl`): frosted glass shows a blur of what is behind it, as much as its
//! roughness and index say, and what it shows agrees with the plain filter's picture where it
//! is smooth; a refracting volume shows what is behind it displaced the way Snell's law bends
//! the ray, and not at normal incidence; a dispersing one splits white into colours.

use crate::golden;
use crate::render::{
    OBLIQUE_LIGHT, add_part, pixel_at, push_floor_marker, render_in_turn_over_floor, render_methods_over_floor,
    render_over_floor,
};
use crate::transmission::{RED, glass, largest_difference, seen, square};
use phantogram::anaglyph::Method;
use phantogram::glam::{Mat4, Vec3};
use phantogram::model::{Layers, Material, Mesh, Model};

const GREEN: [f32; 4] = [0.05, 0.6, 0.05, 1.0];

/// Red over green: how much the pixel still shows the red block.
fn redness(c: [f32; 3]) -> f32 {
    c[0] / c[1].max(1.0)
}

/// Glass of `roughness` and index `ior` over the red block.
fn rough_glass(roughness: f32, ior: f32) -> Material {
    Material {
        roughness,
        ..glass(
            [1.0; 3],
            Layers {
                ior,
                ..Layers::default()
            },
        )
    }
}

#[test]
fn frosted_glass_blurs_what_is_behind_it_by_its_roughness() {
    // Roughness 0 is drawn with the plain filter; any other through the backdrop.
    let Some(smooth) = seen(RED, Some(rough_glass(0.0, 1.5))) else {
        return;
    };
    let barely = seen(RED, Some(rough_glass(1e-4, 1.5))).expect("a frame");
    let half = seen(RED, Some(rough_glass(0.4, 1.5))).expect("a frame");
    let frosted = seen(RED, Some(rough_glass(1.0, 1.5))).expect("a frame");
    let same_index_smooth = seen(RED, Some(rough_glass(0.0, 1.0))).expect("a frame");
    let same_index_rough = seen(RED, Some(rough_glass(1.0, 1.0))).expect("a frame");
    println!(
        "the red block through glass of roughness 0 {smooth:?}, 1e-4 {barely:?}, 0.4 {half:?}, 1 {frosted:?}; of index 1, smooth {same_index_smooth:?}, rough {same_index_rough:?}"
    );
    // The backdrop is the opaque scene as the eye saw it: at the sharpest level the two ways of
    // drawing glass agree.
    assert!(
        largest_difference(barely, smooth) <= 2.0,
        "backdrop {barely:?} vs filter {smooth:?}"
    );
    assert!(redness(smooth) > 2.0, "smooth glass shows the red block: {smooth:?}");
    // Fully rough: the whole scene's mean, mostly the grey floor.
    assert!(redness(frosted) < 1.3, "frosted glass shows a blur: {frosted:?}");
    assert!(
        redness(half) < 0.95 * redness(smooth) && redness(half) > 1.05 * redness(frosted),
        "half as rough, half as blurred: {half:?} between {smooth:?} and {frosted:?}"
    );
    // A rough boundary between media of one index turns no ray: sharp, as the smooth one.
    assert!(
        largest_difference(same_index_rough, same_index_smooth) <= 2.0,
        "index 1: rough {same_index_rough:?} vs smooth {same_index_smooth:?}"
    );
}

/// Where a ray from the eye straight down onto the screen's centre lands through a 12 mm gem
/// (diamond's index) tilted 30° about x: refracted towards the face's inward normal, it leaves
/// the gem 18° off the vertical, 3.7 mm towards +y, and meets the plane 24 mm under the glass
/// 3.8 mm out (a slab's exit ray, parallel to the entering one, lands 3.8 mm out too).
const BENT_TO: Vec3 = Vec3::new(0.0, 0.0038, -0.024);

/// A 12 mm block of `layers` over the floor, tilted by `tilt_deg` about x, with a 4 mm block of
/// `under` standing where [`BENT_TO`] is.
fn gem_scene(layers: Layers, roughness: f32, tilt_deg: f32, under: [f32; 4]) -> Model {
    let mut mesh = Mesh::default();
    mesh.push_cube(BENT_TO - Vec3::new(0.0, 0.0, 0.002), 0.002, under);
    push_floor_marker(&mut mesh);
    let mut model = Model::from_painted_mesh("under a gem", mesh);
    let mut gem = Mesh::default();
    gem.push_cube(Vec3::ZERO, 0.006, [1.0; 4]);
    gem.transform(Mat4::from_translation(Vec3::new(0.0, 0.0, -0.012)) * Mat4::from_rotation_x(tilt_deg.to_radians()));
    add_part(
        &mut model,
        gem,
        Material {
            roughness,
            ..glass([1.0; 3], layers)
        },
    );
    model
}

/// The pixel at the screen's centre through [`gem_scene`]'s smooth block.
fn through_a_gem(layers: Layers, tilt_deg: f32) -> Option<[f32; 3]> {
    let (pixels, proj) = render_over_floor(gem_scene(layers, 0.0, tilt_deg, RED), true, OBLIQUE_LIGHT)?;
    let p = pixel_at(&pixels, &proj, Vec3::new(0.0, 0.0, BENT_TO.z));
    Some([p[0] as f32, p[1] as f32, p[2] as f32])
}

#[test]
fn a_refracting_volume_shows_what_is_behind_it_where_the_ray_bends() {
    let diamond = diamond();
    let Some(bent) = through_a_gem(diamond, 30.0) else {
        return;
    };
    let thin = through_a_gem(
        Layers {
            ior: 2.42,
            ..Layers::default()
        },
        30.0,
    )
    .expect("a frame");
    let straight_on = through_a_gem(diamond, 0.0).expect("a frame");
    println!(
        "the screen's centre through a tilted gem {bent:?}, a tilted thin wall {thin:?}, the gem face on {straight_on:?}"
    );
    // The red block is 3.8 mm off the straight line of sight, under the floor's grey.
    assert!(redness(thin) < 1.3, "a thin wall does not bend the ray: {thin:?}");
    assert!(
        redness(straight_on) < 1.3,
        "at normal incidence the ray goes straight on: {straight_on:?}"
    );
    assert!(
        redness(bent) > 2.0,
        "the gem bends the ray onto the red block: {bent:?}"
    );
}

/// Diamond 12 mm thick: the gem blocks' volume.
fn diamond() -> Layers {
    Layers {
        ior: 2.42,
        thickness: 0.012,
        ..Layers::default()
    }
}

/// The largest difference of one channel between two frames, and how many channels differ by
/// more than 8.
fn compare_frames(a: &[u8], b: &[u8]) -> (u8, usize) {
    let differences = || a.iter().zip(b).map(|(x, y)| x.abs_diff(*y));
    (
        differences().max().unwrap_or(0),
        differences().filter(|d| *d > 8).count(),
    )
}

#[test]
fn one_renderer_draws_each_kind_of_glass_as_a_fresh_one_does() {
    // Frosted (a backdrop with its halvings), only bending (the copy alone), no glass (none),
    // and frosted again: the backdrop is made, remade and dropped as each model needs. The block
    // under the gem changes colour from one to the next, so that a backdrop left over from the
    // model before shows.
    let diamond = diamond();
    let scenes = || {
        vec![
            gem_scene(diamond, 0.6, 30.0, RED),
            gem_scene(diamond, 0.0, 30.0, GREEN),
            gem_scene(
                Layers {
                    transmission: 0.0,
                    ..diamond
                },
                0.0,
                30.0,
                RED,
            ),
            gem_scene(diamond, 0.6, 30.0, GREEN),
        ]
    };
    let Some(in_turn) = render_in_turn_over_floor(scenes(), OBLIQUE_LIGHT) else {
        return;
    };
    for (k, (model, drawn)) in scenes().into_iter().zip(&in_turn).enumerate() {
        let fresh = render_in_turn_over_floor(vec![model], OBLIQUE_LIGHT).expect("a frame");
        let (worst, _) = compare_frames(&fresh[0], drawn);
        assert!(worst <= 1, "scene {k}: a channel differs by {worst}");
    }
    // And the frames differ where they should: the frosted gem is not the sharp one.
    let (_, differs) = compare_frames(&in_turn[0], &in_turn[1]);
    assert!(differs > 1000, "frosted and sharp differ at {differs} channels");
}

#[test]
fn a_stereo_frame_after_mono_ones_sees_through_frosted_glass_with_both_eyes() {
    // A mono frame makes the first eye's backdrop alone; the stereo frame after it needs the
    // second's too.
    let diamond = diamond();
    let scene = || gem_scene(diamond, 0.6, 30.0, RED);
    let Some(frames) = render_methods_over_floor(scene(), &[Method::Mono, Method::DuboisRedCyan], None) else {
        return;
    };
    let fresh = render_methods_over_floor(scene(), &[Method::DuboisRedCyan], None).expect("a frame");
    let (worst, _) = compare_frames(&fresh[0], &frames[1]);
    assert!(
        worst <= 1,
        "the stereo frame after a mono one: a channel differs by {worst}"
    );
    let (_, differs) = compare_frames(&frames[0], &frames[1]);
    assert!(differs > 1000, "mono and stereo differ at {differs} channels");
}

/// The pixel looking down through a frosted block onto the red block, with `between` (if any) a
/// square of glass halfway between them.
fn through_frost_onto_red(between: Option<Material>) -> Option<[f32; 3]> {
    let mut mesh = Mesh::default();
    mesh.push_cube(Vec3::new(0.0, 0.0, -0.026), 0.004, RED);
    push_floor_marker(&mut mesh);
    let mut model = Model::from_painted_mesh("under glass", mesh);
    if let Some(material) = between {
        let mut pane = Mesh::default();
        square(&mut pane, -0.019, true, [1.0; 4]);
        add_part(&mut model, pane, material);
    }
    let mut frosted = Mesh::default();
    frosted.push_cube(Vec3::new(0.0, 0.0, -0.012), 0.004, [1.0; 4]);
    add_part(&mut model, frosted, rough_glass(0.1, 1.5));
    let (pixels, proj) = render_over_floor(model, true, OBLIQUE_LIGHT)?;
    let p = pixel_at(&pixels, &proj, Vec3::new(0.0, 0.0, -0.022));
    Some([p[0] as f32, p[1] as f32, p[2] as f32])
}

#[test]
fn frosted_glass_shows_the_glass_behind_it() {
    let Some(alone) = through_frost_onto_red(None) else {
        return;
    };
    let green = Material {
        roughness: 0.0,
        ..glass([0.1, 1.0, 0.1], Layers::default())
    };
    let behind_green = through_frost_onto_red(Some(green)).expect("a frame");
    println!("the red block through frosted glass {alone:?}, and through green glass under it too {behind_green:?}");
    assert!(redness(alone) > 2.0, "through the frost alone, red: {alone:?}");
    // Green glass passes a tenth of the red: the frost must show it, not the bare block.
    assert!(
        behind_green[0] < 0.5 * alone[0],
        "the green glass under the frost filters the red: {behind_green:?} vs {alone:?}"
    );
}

#[test]
fn four_kinds_of_glass_match_their_golden_frame() {
    // Over red and white bars on the floor, left to right: clear thin glass (the filter), an
    // amber volume (absorbs; of index 1.5 it bends too), frosted glass, and a tilted diamond.
    let mut mesh = Mesh::default();
    for i in -9..=9 {
        let colour = if i % 2 == 0 { RED } else { [0.9, 0.9, 0.9, 1.0] };
        for y in [-0.004, 0.0, 0.004] {
            mesh.push_cube(Vec3::new(i as f32 * 0.002, y, -0.028), 0.001, colour);
        }
    }
    push_floor_marker(&mut mesh);
    let mut model = Model::from_painted_mesh("four glasses", mesh);
    let clear = rough_glass(0.0, 1.5);
    let amber = Material {
        roughness: 0.0,
        ..glass(
            [1.0; 3],
            Layers {
                thickness: 0.007,
                attenuation_distance: 0.007,
                attenuation_color: [0.95, 0.55, 0.15],
                ..Layers::default()
            },
        )
    };
    let frosted = rough_glass(0.35, 1.5);
    let diamond = Material {
        roughness: 0.0,
        ..glass(
            [1.0; 3],
            Layers {
                ior: 2.42,
                thickness: 0.007,
                ..Layers::default()
            },
        )
    };
    for (k, material) in [clear, amber, frosted, diamond].into_iter().enumerate() {
        let mut block = Mesh::default();
        block.push_cube(Vec3::ZERO, 0.0035, [1.0; 4]);
        let tilt = if k == 3 { 30f32.to_radians() } else { 0.0 };
        block.transform(
            Mat4::from_translation(Vec3::new(-0.0135 + 0.009 * k as f32, 0.0, -0.014)) * Mat4::from_rotation_x(tilt),
        );
        add_part(&mut model, block, material);
    }
    let size = (360, 800);
    let Some(frames) = render_methods_over_floor(model, &[Method::Mono], Some(size)) else {
        return;
    };
    golden::check("glass-four-kinds-mono", size.0, size.1, &frames[0], 3, 0.003);
}

/// Pixels of a frame whose red and blue differ by more than 40: colour where the scene has none.
fn coloured_pixels(frame: &[u8]) -> usize {
    frame.chunks(4).filter(|p| p[0].abs_diff(p[2]) > 40).count()
}

#[test]
fn a_dispersing_gem_splits_white_into_colours() {
    // White under a tilted gem on grey: no colour anywhere, unless the gem bends red and blue
    // apart. The dispersion is far beyond any real stone's (an Abbe number of 1, so that the split
    // spans pixels at this size; diamond's is 55).
    let white = [0.9, 0.9, 0.9, 1.0];
    let plain = diamond();
    let fiery = Layers {
        dispersion: 20.0,
        ..diamond()
    };
    let Some(without) = render_methods_over_floor(gem_scene(plain, 0.0, 30.0, white), &[Method::Mono], None) else {
        return;
    };
    let with = render_methods_over_floor(gem_scene(fiery, 0.0, 30.0, white), &[Method::Mono], None).expect("a frame");
    let (before, after) = (coloured_pixels(&without[0]), coloured_pixels(&with[0]));
    println!("coloured pixels: without dispersion {before}, with {after}");
    assert!(before < 5, "a clear gem over white and grey shows no colour: {before}");
    assert!(
        after > 20,
        "a dispersing gem fringes the white block with colour: {after}"
    );
}

/// What a white 3 mm cube standing on the floor at `x` (m) adds to the luminance of a
/// [`render_in_turn_over_floor`] frame, against `empty`, within 40 px of where it is drawn:
/// the centre (x, px) of what it adds, the most it adds to a pixel, and the spread (RMS, px)
/// along x.
fn blurred_spot(frame: &[u8], empty: &[u8], at_px: (f32, f32)) -> (f64, f32, f64) {
    let luminance =
        |f: &[u8], i: usize| 0.2126 * f[i * 4] as f32 + 0.7152 * f[i * 4 + 1] as f32 + 0.0722 * f[i * 4 + 2] as f32;
    let (w, h) = (crate::render::W as usize, crate::render::H as usize);
    let added: Vec<(f64, f64)> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|(x, y)| (*x as f32 - at_px.0).abs() < 40.0 && (*y as f32 - at_px.1).abs() < 40.0)
        .map(|(x, y)| {
            let i = y * w + x;
            (x as f64, (luminance(frame, i) - luminance(empty, i)).max(0.0) as f64)
        })
        .collect();
    let total: f64 = added.iter().map(|(_, d)| d).sum();
    let centre = added.iter().map(|(x, d)| x * d).sum::<f64>() / total;
    let spread = (added.iter().map(|(x, d)| (x - centre).powi(2) * d).sum::<f64>() / total).sqrt();
    let peak = added.iter().map(|(_, d)| *d as f32).fold(0.0, f32::max);
    (centre, peak, spread)
}

#[test]
fn frosted_glass_blurs_a_thing_alike_wherever_it_stands() {
    // A small white cube moved along x in 1 mm steps (2.5 px) under a pane of roughness 0.5: the
    // blur's texels are about 20 px there. A blur made of a chain of 2 × 2 means read bilinearly
    // snaps what it shows to those texels (measured: the spot's centre up to 4.4 px off where the
    // cube is, its peak varying 1.9 : 1, its width 1.5 : 1); the [1 3 3 1] halvings read with a
    // cubic B-spline follow it (0.6 px, 1.13 : 1, 1.10 : 1).
    let screen = phantogram::screen::Screen::default();
    let mono = phantogram::projection::OffAxisProjection::new(&screen, Vec3::new(0.0, 0.0, 0.3), Default::default())
        .expect("a projection");
    let to_frame = crate::render::W as f32 / screen.width_px() as f32;
    let cube_z = -0.03 + 0.0015;
    let scene = |x: f32, y: f32| {
        let mut mesh = Mesh::default();
        mesh.push_cube(Vec3::new(x, y, cube_z), 0.0015, [1.0; 4]);
        let mut model = Model::from_painted_mesh("a cube under frosted glass", mesh);
        let mut pane = Mesh::default();
        pane.push_cube(Vec3::ZERO, 0.5, [1.0; 4]);
        pane.transform(
            Mat4::from_translation(Vec3::new(0.0, 0.0, -0.012)) * Mat4::from_scale(Vec3::new(0.05, 0.05, 0.002)),
        );
        add_part(&mut model, pane, rough_glass(0.5, 1.5));
        model
    };
    let xs: Vec<f32> = (0..9).map(|k| k as f32 * 0.001).collect();
    // The cube out of sight (the floor stays where it is): what the pane shows without it.
    let mut models = vec![scene(0.0, 0.2)];
    models.extend(xs.iter().map(|x| scene(*x, 0.0)));
    let Some(frames) = render_in_turn_over_floor(models, OBLIQUE_LIGHT) else {
        return;
    };
    let drawn_at = |x: f32| {
        let p = mono.project(Vec3::new(x, 0.0, cube_z)).expect("in view").pixel * to_frame;
        (p.x, p.y)
    };
    let spots: Vec<(f64, f32, f64)> = xs
        .iter()
        .zip(&frames[1..])
        .map(|(x, frame)| blurred_spot(frame, &frames[0], drawn_at(*x)))
        .collect();
    println!("the cube's blurred spot under frosted glass at each step (centre px, peak, spread px): {spots:?}");
    let (first_centre, first_x) = (spots[0].0, drawn_at(0.0).0 as f64);
    for ((x, spot), step) in xs.iter().zip(&spots).zip(0..) {
        let moved = spot.0 - first_centre;
        let expected = drawn_at(*x).0 as f64 - first_x;
        assert!(
            (moved - expected).abs() <= 1.5,
            "step {step}: the spot moved {moved:.2} px where the cube moved {expected:.2} px"
        );
    }
    let ratio = |f: &dyn Fn(&(f64, f32, f64)) -> f64| {
        let values: Vec<f64> = spots.iter().map(f).collect();
        values.iter().cloned().fold(f64::MIN, f64::max) / values.iter().cloned().fold(f64::MAX, f64::min)
    };
    let (peaks, spreads) = (ratio(&|s| s.1 as f64), ratio(&|s| s.2));
    assert!(
        spots.iter().all(|s| s.1 > 20.0),
        "the cube shows through the pane: {spots:?}"
    );
    assert!(peaks <= 1.25, "the spot's peak varies {peaks:.2} : 1 as the cube moves");
    assert!(
        spreads <= 1.2,
        "the spot's width varies {spreads:.2} : 1 as the cube moves"
    );
}
