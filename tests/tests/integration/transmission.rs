//! glTF's material extensions on the GPU (the assets crate's `model::layers`, `scene.wgsl`'s
//! `shade_surface` and the render crate's `DrawLayer`): glass shows what is behind it, filtered by
//! its base colour or absorbed by its volume, an index of refraction of 1 reflects nothing, a
//! material's own varnish and specular strength change its reflection, and glass casts the
//! shadow it should: pale when clear, coloured when tinted (the render crate's `shadow_filter`).
//!
//! Each scene: a block on the floor, seen straight on from 30 cm, and a second block of the
//! material under test floating over it; the pixel at the centre looks through the upper block's
//! top face onto the lower block's.

use crate::render::{OBLIQUE_LIGHT, add_part, pixel_at, push_floor_marker, render_over_floor, render_over_floor_lit};
use phantogram::glam::Vec3;
use phantogram::model::{Image, Layers, Material, Mesh, Model, TextureRef, Vertex};
use phantogram::projection::OffAxisProjection;

/// The centre of the lower block's top face, which the upper block hides from the eye.
const BEHIND: Vec3 = Vec3::new(0.0, 0.0, -0.022);

/// A block of `colour` standing on the floor under `over`'s block (none: nothing over it), with
/// `images` for `over`'s textures.
fn render_under_with(
    colour: [f32; 4],
    over: Option<Material>,
    images: Vec<Image>,
) -> Option<(Vec<u8>, OffAxisProjection)> {
    let mut mesh = Mesh::default();
    mesh.push_cube(Vec3::new(0.0, 0.0, -0.026), 0.004, colour);
    push_floor_marker(&mut mesh);
    let mut model = Model::from_painted_mesh("under glass", mesh);
    model.images = images;
    if let Some(material) = over {
        let mut block = Mesh::default();
        block.push_cube(Vec3::new(0.0, 0.0, -0.012), 0.004, [1.0; 4]);
        add_part(&mut model, block, material);
    }
    render_over_floor(model, true, OBLIQUE_LIGHT)
}

/// The pixel at [`BEHIND`] with `over` floating above the block of `colour`.
pub(crate) fn seen(colour: [f32; 4], over: Option<Material>) -> Option<[f32; 3]> {
    seen_with(colour, over, Vec::new())
}

/// [`seen`], with `images` for `over`'s textures.
fn seen_with(colour: [f32; 4], over: Option<Material>, images: Vec<Image>) -> Option<[f32; 3]> {
    let (pixels, proj) = render_under_with(colour, over, images)?;
    let p = pixel_at(&pixels, &proj, BEHIND);
    Some([p[0] as f32, p[1] as f32, p[2] as f32])
}

/// A one-texel image of `rgba` (linear data, as the layers' textures are), and a reference to it
/// as the model's first image.
pub(crate) fn one_texel(rgba: [u8; 4]) -> (Image, TextureRef) {
    let image = Image {
        name: format!("texel {rgba:?}"),
        width: 1,
        height: 1,
        rgba8: rgba.to_vec(),
        basis: None,
    };
    let reference = TextureRef {
        image: 0,
        tex_coord: 0,
        transform: Default::default(),
        sampler: Default::default(),
    };
    (image, reference)
}

/// [`glass`] without transmission: a white dielectric block.
fn opaque_white() -> Material {
    Material {
        layers: Layers::default(),
        ..glass([1.0; 3], Layers::default())
    }
}

/// Smooth glass: a dielectric that lets through what it does not reflect.
pub(crate) fn glass(base: [f32; 3], layers: Layers) -> Material {
    Material {
        name: "glass".into(),
        base_color: [base[0], base[1], base[2], 1.0],
        metallic: 0.0,
        roughness: 0.05,
        layers: Layers {
            transmission: 1.0,
            ..layers
        },
        ..Material::default()
    }
}

pub(crate) fn largest_difference(a: [f32; 3], b: [f32; 3]) -> f32 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f32::max)
}

pub(crate) const RED: [f32; 4] = [0.6, 0.05, 0.05, 1.0];
const GREY: [f32; 4] = [0.7, 0.7, 0.7, 1.0];

#[test]
fn clear_glass_shows_what_is_behind_it() {
    let Some(bare) = seen(RED, None) else {
        return;
    };
    let through = seen(RED, Some(glass([1.0; 3], Layers::default()))).expect("a frame");
    let opaque = seen(RED, Some(opaque_white())).expect("a frame");
    println!("the red block: bare {bare:?}, through clear glass {through:?}, under an opaque white block {opaque:?}");
    assert!(bare[0] > 2.0 * bare[1], "the block is red: {bare:?}");
    // Through the glass: the red block, less the ~4 % the glass reflects, plus the room that
    // reflection shows.
    assert!(
        largest_difference(through, bare) <= 16.0,
        "through clear glass {through:?} vs bare {bare:?}"
    );
    assert!(through[0] > 2.0 * through[1], "red through the glass: {through:?}");
    // The same block without transmission hides it.
    assert!(
        opaque[1] > 0.8 * opaque[0],
        "an opaque white block is not red: {opaque:?}"
    );
}

#[test]
fn glass_filters_by_its_base_colour_and_a_volume_by_its_attenuation() {
    let amber = [1.0, 0.4, 0.1];
    let Some(bare) = seen(GREY, None) else {
        return;
    };
    let tinted = seen(GREY, Some(glass(amber, Layers::default()))).expect("a frame");
    // A clear volume whose thickness is its attenuation distance: at normal incidence its light
    // leaves tinted by exactly the attenuation colour (Beer–Lambert), as the thin tinted wall's.
    let volume = Layers {
        thickness: 0.01,
        attenuation_distance: 0.01,
        attenuation_color: amber,
        ..Layers::default()
    };
    let absorbed = seen(GREY, Some(glass([1.0; 3], volume))).expect("a frame");
    println!("the grey block: bare {bare:?}, through amber glass {tinted:?}, through an amber volume {absorbed:?}");
    assert!(
        tinted[0] > tinted[1] + 20.0 && tinted[1] > tinted[2] + 20.0,
        "amber: {tinted:?}"
    );
    assert!(
        (tinted[0] - bare[0]).abs() <= 16.0,
        "red passes: {tinted:?} vs {bare:?}"
    );
    assert!(
        largest_difference(tinted, absorbed) <= 3.0,
        "thin amber {tinted:?} vs amber volume {absorbed:?}"
    );
}

#[test]
fn an_index_of_refraction_of_one_reflects_nothing() {
    let Some(bare) = seen(RED, None) else {
        return;
    };
    let air = Layers {
        ior: 1.0,
        ..Layers::default()
    };
    let diamond = Layers {
        ior: 2.42,
        ..Layers::default()
    };
    let through_air = seen(RED, Some(glass([1.0; 3], air))).expect("a frame");
    let through_diamond = seen(RED, Some(glass([1.0; 3], diamond))).expect("a frame");
    println!("the red block: bare {bare:?}, through ior 1 {through_air:?}, through ior 2.42 {through_diamond:?}");
    assert!(
        largest_difference(through_air, bare) <= 1.0,
        "an index of 1: {through_air:?} vs bare {bare:?}"
    );
    // Diamond reflects 17 % at normal incidence: the red block dims and the room shows.
    assert!(
        largest_difference(through_diamond, bare) >= 4.0,
        "an index of 2.42: {through_diamond:?} vs bare {bare:?}"
    );
}

#[test]
fn a_materials_own_varnish_and_specular_strength_change_its_reflection() {
    // Dark, rough plastic: its reflection of the room is most of what it shows.
    let plastic = |layers: Layers| Material {
        name: "plastic".into(),
        base_color: [0.02, 0.02, 0.02, 1.0],
        metallic: 0.0,
        roughness: 0.6,
        layers,
        ..Material::default()
    };
    let luminance = |c: [f32; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    let Some(plain) = seen(GREY, Some(plastic(Layers::default()))) else {
        return;
    };
    let varnished = seen(
        GREY,
        Some(plastic(Layers {
            clear_coat: 1.0,
            clear_coat_roughness: 0.0,
            ..Layers::default()
        })),
    )
    .expect("a frame");
    let unreflecting = seen(
        GREY,
        Some(plastic(Layers {
            specular: 0.0,
            ..Layers::default()
        })),
    )
    .expect("a frame");
    println!("dark plastic {plain:?}, varnished {varnished:?}, with no specular {unreflecting:?}");
    assert!(
        luminance(varnished) >= luminance(plain) + 2.0,
        "varnish: {varnished:?} vs {plain:?}"
    );
    assert!(
        luminance(unreflecting) + 2.0 <= luminance(plain),
        "no specular: {unreflecting:?} vs {plain:?}"
    );
}

#[test]
fn a_transmission_texture_says_where_the_glass_is() {
    // One texel, as a transmission texture: its red channel scales the factor (linear).
    let textured = |red: u8| {
        let (image, reference) = one_texel([red, 0, 0, 255]);
        let material = Material {
            transmission_texture: Some(reference),
            ..glass([1.0; 3], Layers::default())
        };
        seen_with(RED, Some(material), vec![image])
    };
    let Some(stopped) = textured(0) else {
        return;
    };
    let passed = textured(255).expect("a frame");
    let clear = seen(RED, Some(glass([1.0; 3], Layers::default()))).expect("a frame");
    let opaque = seen(RED, Some(opaque_white())).expect("a frame");
    println!(
        "red block under glass: texture 0 {stopped:?} (opaque {opaque:?}), texture 1 {passed:?} (clear {clear:?})"
    );
    assert!(
        largest_difference(stopped, opaque) <= 2.0,
        "where the texture says 0 the glass is opaque: {stopped:?} vs {opaque:?}"
    );
    assert!(
        largest_difference(passed, clear) <= 1.0,
        "where it says 1, clear: {passed:?} vs {clear:?}"
    );
}

#[test]
fn a_thickness_texture_thins_the_volume() {
    let amber = [1.0, 0.4, 0.1];
    let volume = Layers {
        thickness: 0.01,
        attenuation_distance: 0.01,
        attenuation_color: amber,
        ..Layers::default()
    };
    // One texel, as a thickness texture: its green channel scales the thickness (linear).
    let thinned = |green: u8| {
        let (image, reference) = one_texel([0, green, 0, 255]);
        let material = Material {
            thickness_texture: Some(reference),
            ..glass([1.0; 3], volume)
        };
        seen_with(GREY, Some(material), vec![image])
    };
    let Some(none) = thinned(0) else {
        return;
    };
    let whole = thinned(255).expect("a frame");
    let clear = seen(GREY, Some(glass([1.0; 3], Layers::default()))).expect("a frame");
    let absorbed = seen(GREY, Some(glass([1.0; 3], volume))).expect("a frame");
    println!(
        "grey block under a volume: texture 0 {none:?} (clear {clear:?}), texture 1 {whole:?} (full thickness {absorbed:?})"
    );
    assert!(
        largest_difference(none, clear) <= 1.0,
        "no thickness absorbs nothing: {none:?} vs {clear:?}"
    );
    assert!(
        largest_difference(whole, absorbed) <= 1.0,
        "the full thickness: {whole:?} vs {absorbed:?}"
    );
}

/// The floor's pixels (RGB) in the shadow of a block of `material` 15 mm above it and at the
/// mirror point across the block, lit: the oblique light puts the shadow's centre 7.5 mm
/// towards −x.
fn shadow_and_lit(material: Material) -> Option<([f32; 3], [f32; 3])> {
    let mut marker = Mesh::default();
    push_floor_marker(&mut marker);
    let mut model = Model::from_painted_mesh("glass shadow", marker);
    let mut block = Mesh::default();
    block.push_cube(Vec3::new(0.0, 0.0, -0.015), 0.004, [1.0; 4]);
    add_part(&mut model, block, material);
    let (pixels, proj) = render_over_floor(model, true, OBLIQUE_LIGHT)?;
    let rgb = |p: Vec3| {
        let c = pixel_at(&pixels, &proj, p);
        [c[0] as f32, c[1] as f32, c[2] as f32]
    };
    Some((rgb(Vec3::new(-0.0075, 0.0, -0.03)), rgb(Vec3::new(0.0075, 0.0, -0.03))))
}

#[test]
fn glass_casts_a_pale_shadow_and_tinted_glass_a_coloured_one() {
    let Some((opaque_shadow, opaque_lit)) = shadow_and_lit(opaque_white()) else {
        return;
    };
    let (clear_shadow, clear_lit) = shadow_and_lit(glass([1.0; 3], Layers::default())).expect("a frame");
    let (red_shadow, red_lit) = shadow_and_lit(glass([1.0, 0.1, 0.1], Layers::default())).expect("a frame");
    println!(
        "floor in the shadow / lit: opaque {opaque_shadow:?} / {opaque_lit:?}, clear glass {clear_shadow:?} / {clear_lit:?}, red glass {red_shadow:?} / {red_lit:?}"
    );
    let luminance = |c: [f32; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    assert!(
        luminance(opaque_shadow) < 0.6 * luminance(opaque_lit),
        "an opaque block's shadow: {opaque_shadow:?} vs {opaque_lit:?}"
    );
    // Clear glass passes most of the light: its shadow is pale, but there.
    assert!(
        luminance(clear_shadow) > 0.8 * luminance(clear_lit) && luminance(clear_shadow) < luminance(clear_lit) - 1.0,
        "clear glass's shadow: {clear_shadow:?} vs {clear_lit:?}"
    );
    // Red glass passes red: the shadow keeps the lit floor's red and loses its green and blue.
    assert!(
        red_shadow[0] > 0.85 * red_lit[0] && red_shadow[1] < 0.8 * red_lit[1] && red_shadow[2] < 0.8 * red_lit[2],
        "red glass's shadow: {red_shadow:?} vs {red_lit:?}"
    );
}

/// A lamp among what it shadows (seen from its cube, `render::a_lamp_among_its_casters_shadows_every_way`'s
/// scene): red glass to its −x casts a red shadow and an opaque block to its +y a dark one, each
/// read on the floor beyond the block against the point mirrored across the lamp in x, where
/// nothing stands between. Before the cube had a glass filter, the lamp's light passed the glass
/// as if it were not there.
#[test]
fn glass_among_a_lamps_casters_casts_a_coloured_shadow() {
    let mut marker = Mesh::default();
    push_floor_marker(&mut marker);
    let mut model = Model::from_painted_mesh("glass among a lamp's casters", marker);
    let mut red = Mesh::default();
    red.push_cube(Vec3::new(-0.012, 0.006, -0.024), 0.003, [1.0; 4]);
    add_part(&mut model, red, glass([1.0, 0.1, 0.1], Layers::default()));
    let mut block = Mesh::default();
    block.push_cube(Vec3::new(0.006, 0.012, -0.024), 0.003, [1.0; 4]);
    add_part(&mut model, block, opaque_white());
    let lamp = phantogram::render::Lamp {
        position_m: Vec3::new(0.0, 0.0, -0.022),
        axis: Vec3::NEG_Z,
        cone_half_angle_rad: None,
        intensity_rgb: Vec3::splat(0.004),
    };
    let Some((pixels, proj, _)) = render_over_floor_lit(model, true, OBLIQUE_LIGHT, Some(lamp)) else {
        return;
    };
    let rgb = |(x, y): (f32, f32)| {
        let c = pixel_at(&pixels, &proj, Vec3::new(x, y, -0.031));
        [c[0] as f32, c[1] as f32, c[2] as f32]
    };
    let (red_shadow, red_lit) = (rgb((-0.029, 0.018)), rgb((0.029, 0.018)));
    let (dark, dark_lit) = (rgb((0.018, 0.029)), rgb((-0.018, 0.029)));
    println!(
        "floor beyond the red glass {red_shadow:?} (mirrored {red_lit:?}), beyond the block {dark:?} (mirrored {dark_lit:?})"
    );
    assert!(
        red_shadow[0] > 0.85 * red_lit[0] && red_shadow[1] < 0.8 * red_lit[1] && red_shadow[2] < 0.8 * red_lit[2],
        "red glass's shadow: {red_shadow:?} vs {red_lit:?}"
    );
    // Behind the block only the room's light is left (about 51 of the lit floor's 82 here):
    // what the red glass leaves in green and blue.
    assert!(
        (0..3).all(|c| dark[c] < dark_lit[c] - 20.0 && (dark[c] - red_shadow[1]).abs() < 3.0),
        "the opaque block's shadow: {dark:?} vs {dark_lit:?}"
    );
}

/// A square 10 mm across at height `z`, facing up (+z) or down, in `colour`.
pub(crate) fn square(mesh: &mut Mesh, z: f32, up: bool, colour: [f32; 4]) {
    let base = mesh.vertices.len() as u32;
    let normal = if up { [0.0, 0.0, 1.0] } else { [0.0, 0.0, -1.0] };
    for (x, y) in [(-0.005, -0.005), (0.005, -0.005), (0.005, 0.005), (-0.005, 0.005)] {
        mesh.vertices.push(Vertex {
            position: [x, y, z],
            normal,
            tangent: [1.0, 0.0, 0.0, 1.0],
            uv: [0.0; 4],
            color: colour,
            material: [1.0, 1.0],
        });
    }
    // Counter-clockwise as seen from the side it faces.
    let order = if up { [0, 1, 2, 0, 2, 3] } else { [0, 2, 1, 0, 3, 2] };
    mesh.indices.extend(order.map(|i| base + i));
}

#[test]
fn the_near_side_of_double_sided_glass_filters_the_far_sides_light() {
    // One primitive, half-transmissive and double-sided: the top of a thin box tinted red, its
    // bottom tinted blue, the top's triangles first in the mesh. Looking down, the red top's own
    // light and, through it, the blue bottom's light filtered red: mostly red. Drawn in the
    // mesh's order, the blue bottom would filter the red top's light instead: mostly blue.
    let mut glass_box = Mesh::default();
    square(&mut glass_box, -0.010, true, [1.0, 0.1, 0.1, 1.0]);
    square(&mut glass_box, -0.020, false, [0.1, 0.1, 1.0, 1.0]);
    let mut floor = Mesh::default();
    push_floor_marker(&mut floor);
    let mut model = Model::from_painted_mesh("under a glass box", floor);
    add_part(
        &mut model,
        glass_box,
        Material {
            name: "half-clear".into(),
            base_color: [1.0; 4],
            metallic: 0.0,
            roughness: 0.0,
            double_sided: true,
            layers: Layers {
                transmission: 0.5,
                ..Layers::default()
            },
            ..Material::default()
        },
    );
    let Some((pixels, proj)) = render_over_floor(model, false, OBLIQUE_LIGHT) else {
        return;
    };
    let p = pixel_at(&pixels, &proj, Vec3::new(0.0, 0.0, -0.010));
    println!("looking down through the red top onto the blue bottom: {p:?}");
    assert!(
        f32::from(p[0]) > 1.5 * f32::from(p[2]),
        "the near (red) side's light over the far (blue) side's: {p:?}"
    );
}
