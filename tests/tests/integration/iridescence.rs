//! A thin film's colours (`KHR_materials_iridescence`; `scene.wgsl`'s `thin_film_fresnel`): a
//! film a few hundred nanometres thick colours a neutral surface's reflection, differently at
//! different angles, and a film of no thickness or no strength changes nothing; its textures
//! scale its strength and set its thickness.
//!
//! Each case: the tilted block of the sheen tests (`sheen::seen_as`), a dark glossy dielectric
//! under the neutral studio, seen face on and at a grazing angle.

use crate::sheen::seen_as;
use crate::transmission::{largest_difference, one_texel};
use phantogram::model::{Image, LayerSlot, Layers, Material};

/// The dark glossy block under a film of `strength`, thinnest and thickest `thickness_nm`, with
/// `textures` (slot, texel) as images 0, 1, ….
fn filmed(strength: f32, thickness_nm: [f32; 2], textures: &[(LayerSlot, [u8; 4])]) -> Option<([f32; 3], [f32; 3])> {
    let mut material = Material {
        name: "filmed".into(),
        base_color: [0.02, 0.02, 0.02, 1.0],
        metallic: 0.0,
        roughness: 0.3,
        layers: Layers {
            iridescence: strength,
            iridescence_ior: 1.3,
            iridescence_thickness_nm: thickness_nm,
            ..Layers::default()
        },
        ..Material::default()
    };
    let mut images: Vec<Image> = Vec::new();
    for (k, (slot, rgba)) in textures.iter().enumerate() {
        let (image, mut reference) = one_texel(*rgba);
        reference.image = k;
        images.push(image);
        material.layer_textures.set(*slot, Some(reference));
    }
    seen_as(material, images)
}

/// How coloured a pixel is: its largest channel less its smallest.
fn chroma(c: [f32; 3]) -> f32 {
    c.iter().cloned().fold(f32::MIN, f32::max) - c.iter().cloned().fold(f32::MAX, f32::min)
}

#[test]
fn a_thin_film_colours_the_reflection_by_angle() {
    let Some(bare) = filmed(0.0, [100.0, 400.0], &[]) else {
        return;
    };
    let film = filmed(1.0, [100.0, 400.0], &[]).expect("a frame");
    let thicker = filmed(1.0, [100.0, 700.0], &[]).expect("a frame");
    let none_thick = filmed(1.0, [0.0, 0.0], &[]).expect("a frame");
    println!(
        "a dark glossy block (face on, grazing): bare {bare:?}; under a 400 nm film {film:?}; 700 nm {thicker:?}; a film of no thickness {none_thick:?}"
    );
    // The studio is nearly neutral: the bare reflection is nearly grey; the film colours it, and
    // differently face on and at a grazing angle (a shorter path through the film shifts the
    // colours), and differently at another thickness.
    assert!(
        chroma(film.0).max(chroma(film.1)) >= chroma(bare.0).max(chroma(bare.1)) + 8.0,
        "a 400 nm film: {film:?} against bare {bare:?}"
    );
    let hue = |c: [f32; 3]| {
        let sum = c[0] + c[1] + c[2];
        [c[0] / sum, c[1] / sum, c[2] / sum]
    };
    let shift = |a: [f32; 3], b: [f32; 3]| largest_difference(hue(a), hue(b));
    assert!(shift(film.0, film.1) >= 0.03, "the film's colour by angle: {film:?}");
    assert!(
        shift(film.0, thicker.0) >= 0.03,
        "by thickness: {film:?} against {thicker:?}"
    );
    // A film of no thickness is none.
    for (a, b) in [(none_thick.0, bare.0), (none_thick.1, bare.1)] {
        assert!(
            largest_difference(a, b) <= 1.0,
            "no thickness {none_thick:?} against bare {bare:?}"
        );
    }
}

#[test]
fn the_films_textures_scale_its_strength_and_set_its_thickness() {
    let Some(bare) = filmed(0.0, [0.0, 400.0], &[]) else {
        return;
    };
    let film = filmed(1.0, [0.0, 400.0], &[]).expect("a frame");
    // R 0: no film; G 0: the thinnest, of no thickness; G 255: the thickest, as without a texture.
    let no_strength = filmed(1.0, [0.0, 400.0], &[(LayerSlot::Iridescence, [0, 255, 255, 255])]).expect("a frame");
    let thinnest = filmed(
        1.0,
        [0.0, 400.0],
        &[(LayerSlot::IridescenceThickness, [255, 0, 255, 255])],
    )
    .expect("a frame");
    let thickest = filmed(1.0, [0.0, 400.0], &[(LayerSlot::IridescenceThickness, [0, 255, 0, 0])]).expect("a frame");
    println!(
        "bare {bare:?}, film {film:?}; strength texel 0 {no_strength:?}, thickness texel 0 {thinnest:?}, 1 {thickest:?}"
    );
    assert!(
        largest_difference(film.1, bare.1) >= 3.0,
        "the film shows: {film:?} against {bare:?}"
    );
    for (what, seen, expected) in [
        ("strength 0", no_strength, bare),
        ("the thinnest", thinnest, bare),
        ("the thickest", thickest, film),
    ] {
        for (a, b) in [(seen.0, expected.0), (seen.1, expected.1)] {
            assert!(largest_difference(a, b) <= 1.0, "{what}: {seen:?} against {expected:?}");
        }
    }
}
