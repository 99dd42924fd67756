//! Brushed metal (`KHR_materials_anisotropy`; `scene.wgsl`'s `ggx_anisotropic` and
//! `stretched_image_light`): the light's highlight on a metal plate is drawn out along the
//! direction the extension names (the mesh's tangent turned by its rotation, or its texture's
//! direction), and not at all without it.

use crate::render::{W, add_part, render_over_floor};
use crate::transmission::one_texel;
use phantogram::glam::{Mat4, Vec3};
use phantogram::model::{Image, LayerSlot, Layers, Material, Mesh, Model, TextureRef};

/// A 60 mm square metal plate facing the eye, lit from straight above it (towards the eye).
fn plate(anisotropy: f32, rotation_rad: f32, texture: Option<(Image, TextureRef)>) -> Option<Vec<u8>> {
    let mut floor = Mesh::default();
    floor.push_cube(Vec3::new(0.0, 0.07, -0.03), 0.001, [0.2, 0.2, 0.2, 1.0]);
    let mut model = Model::from_painted_mesh("brushed plate", floor);
    let mut slab = Mesh::default();
    slab.push_cube(Vec3::ZERO, 0.5, [1.0; 4]);
    slab.transform(
        Mat4::from_translation(Vec3::new(0.0, 0.0, -0.015)) * Mat4::from_scale(Vec3::new(0.06, 0.06, 0.002)),
    );
    let mut material = Material {
        name: "brushed".into(),
        base_color: [0.9, 0.9, 0.9, 1.0],
        metallic: 1.0,
        roughness: 0.1,
        layers: Layers {
            anisotropy,
            anisotropy_rotation_rad: rotation_rad,
            ..Layers::default()
        },
        ..Material::default()
    };
    if let Some((image, reference)) = texture {
        model.images = vec![image];
        material.layer_textures.set(LayerSlot::Anisotropy, Some(reference));
    }
    add_part(&mut model, slab, material);
    render_over_floor(model, true, Vec3::Z).map(|(pixels, _)| pixels)
}

/// The spread (RMS, px) along x and along y of the light the plate adds above its median within
/// 60 px of the frame's centre.
fn highlight_spread(pixels: &[u8]) -> (f64, f64) {
    let w = W as usize;
    let h = pixels.len() / 4 / w;
    let (cx, cy) = (w / 2, h / 2);
    let luminance = |x: usize, y: usize| {
        let i = (y * w + x) * 4;
        0.2126 * f64::from(pixels[i]) + 0.7152 * f64::from(pixels[i + 1]) + 0.0722 * f64::from(pixels[i + 2])
    };
    let window: Vec<(usize, usize)> = (cy - 60..cy + 60)
        .flat_map(|y| (cx - 60..cx + 60).map(move |x| (x, y)))
        .collect();
    let mut values: Vec<f64> = window.iter().map(|&(x, y)| luminance(x, y)).collect();
    values.sort_by(f64::total_cmp);
    let median = values[values.len() / 2];
    let (mut total, mut sx, mut sy) = (0.0, 0.0, 0.0);
    for &(x, y) in &window {
        let e = (luminance(x, y) - median).max(0.0);
        total += e;
        sx += e * (x as f64 - cx as f64).powi(2);
        sy += e * (y as f64 - cy as f64).powi(2);
    }
    ((sx / total.max(1e-9)).sqrt(), (sy / total.max(1e-9)).sqrt())
}

#[test]
fn a_brushed_plate_draws_the_highlight_out_along_its_direction() {
    // Roughness 0.1; strength 0.3 makes the alpha along the direction 0.10 against 0.01 across.
    let Some(round) = plate(0.0, 0.0, None) else {
        return;
    };
    let along_tangent = plate(0.3, 0.0, None).expect("a frame");
    let turned = plate(0.3, std::f32::consts::FRAC_PI_2, None).expect("a frame");
    let (round, along_tangent, turned) = (
        highlight_spread(&round),
        highlight_spread(&along_tangent),
        highlight_spread(&turned),
    );
    println!(
        "the highlight's spread (x, y px): isotropic {round:?}, brushed along the tangent {along_tangent:?}, turned a quarter {turned:?}"
    );
    assert!((round.0 / round.1 - 1.0).abs() < 0.1, "isotropic: round {round:?}");
    // The mesh's tangent is x on the plate's face.
    assert!(
        along_tangent.0 > 2.0 * along_tangent.1,
        "along the tangent: {along_tangent:?}"
    );
    assert!(turned.1 > 2.0 * turned.0, "turned by a quarter: {turned:?}");
}

#[test]
fn the_anisotropy_texture_gives_direction_and_strength() {
    // RG: the direction (0, 1), along the bitangent; B: the strength's factor.
    let texel = |strength: u8| Some(one_texel([128, 255, strength, 255]));
    let Some(by_texture) = plate(0.3, 0.0, texel(255)) else {
        return;
    };
    let by_rotation = plate(0.3, std::f32::consts::FRAC_PI_2, None).expect("a frame");
    let weakened = plate(0.3, 0.0, texel(0)).expect("a frame");
    let isotropic = plate(0.0, 0.0, None).expect("a frame");
    let largest = |a: &[u8], b: &[u8]| a.iter().zip(b).map(|(a, b)| a.abs_diff(*b)).max().unwrap_or(0);
    println!(
        "the highlight's spread (x, y px): by the texture's direction {:?}, by the rotation {:?}",
        highlight_spread(&by_texture),
        highlight_spread(&by_rotation)
    );
    // The texel's direction is 0.2° off the bitangent (128 of 255 is not quite the middle).
    let off = largest(&by_texture, &by_rotation);
    assert!(
        off <= 1,
        "the texture's direction draws what the rotation does (off by {off})"
    );
    let off = largest(&weakened, &isotropic);
    assert!(
        off <= 1,
        "a texel of strength 0 draws the isotropic plate (off by {off})"
    );
}

#[test]
fn stretched_ggx_image_light_on_the_shared_rooms() {
    // The taps' read of a stretched GGX lobe's room light (`ibl::anisotropic`) checked where it
    // was not measured when chosen: every shared room, a light brush and a full stretch, against
    // a Monte-Carlo integral of the lobe over the room. It must beat the bent normal it replaced
    // (Khronos's glTF Sample Viewer's) on each.
    use phantogram::ibl::accuracy::stretched_ggx_read_errors;
    phantogram_integration::nearer_in_every_shared_room(|env| {
        [(0.2f32, 0.5f32), (0.4, 1.0)]
            .into_iter()
            .map(|(roughness, strength)| {
                (
                    format!("roughness {roughness} strength {strength} (bent normal → taps)"),
                    stretched_ggx_read_errors(env, roughness, strength, 60),
                )
            })
            .collect()
    });
}
