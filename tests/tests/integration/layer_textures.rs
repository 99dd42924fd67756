//! The layer extensions' textures on the GPU (the assets crate's `model::LayerTextures`, the
//! render crate's `layer_textures`, `scene.wgsl`'s `layer_samples`): each scales its factor from
//! the channel its extension names, colour ones decoded from sRGB, so that a texel of value v
//! draws what the factor times v draws without the texture; textures of different sizes share one
//! array; and the varnish follows its own normal map, not the base's.
//!
//! Each case: the tilted block of the sheen tests (`sheen::seen_as`), dark and rough, seen face on
//! and at a grazing angle, where the layers' light is most of what it shows.

use crate::sheen::{seen_as, seen_in};
use crate::transmission::{largest_difference, one_texel};
use phantogram::appearance::Appearance;
use phantogram::model::{Image, LayerSlot, Layers, Material, TextureRef};

/// The dark, rough material of the blocks, with `layers`.
fn dark_rough(layers: Layers) -> Material {
    Material {
        name: "layered".into(),
        base_color: [0.05, 0.05, 0.06, 1.0],
        metallic: 0.0,
        roughness: 0.8,
        layers,
        ..Material::default()
    }
}

/// The dark, rough block with `layers` and `textures` (slot, texture) over `images`.
fn block(layers: Layers, textures: &[(LayerSlot, TextureRef)], images: Vec<Image>) -> Option<([f32; 3], [f32; 3])> {
    let mut material = dark_rough(layers);
    for (slot, texture) in textures {
        material.layer_textures.set(*slot, Some(*texture));
    }
    seen_as(material, images)
}

/// An sRGB code's linear value.
fn linear(code: u8) -> f32 {
    let c = f32::from(code) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// A `size × size` image of one `rgba`, as the model's image `index`.
fn flat_image(size: u32, rgba: [u8; 4], index: usize) -> (Image, TextureRef) {
    let (mut image, mut reference) = one_texel(rgba);
    image.width = size;
    image.height = size;
    image.rgba8 = rgba.repeat((size * size) as usize);
    reference.image = index;
    (image, reference)
}

struct Case {
    what: &'static str,
    /// The factors, untextured.
    layers: Layers,
    /// Each textured slot and its texel.
    texels: Vec<(LayerSlot, [u8; 4])>,
    /// The factors that the texels make of `layers`.
    equivalent: Layers,
}

fn cases() -> Vec<Case> {
    let d = Layers::default();
    let varnish = Layers {
        clear_coat: 1.0,
        clear_coat_roughness: 0.0,
        ..d
    };
    let half = linear(188);
    vec![
        Case {
            what: "clear coat (R)",
            layers: varnish,
            texels: vec![(LayerSlot::ClearCoat, [0, 255, 255, 255])],
            equivalent: Layers {
                clear_coat: 0.0,
                ..varnish
            },
        },
        Case {
            what: "clear coat roughness (G)",
            layers: Layers {
                clear_coat_roughness: 1.0,
                ..varnish
            },
            texels: vec![(LayerSlot::ClearCoatRoughness, [255, 0, 255, 255])],
            equivalent: varnish,
        },
        Case {
            what: "specular (A)",
            layers: d,
            texels: vec![(LayerSlot::Specular, [255, 255, 255, 0])],
            equivalent: Layers { specular: 0.0, ..d },
        },
        Case {
            what: "specular colour (RGB, sRGB)",
            layers: d,
            texels: vec![(LayerSlot::SpecularColor, [188, 255, 0, 0])],
            equivalent: Layers {
                specular_color: [half, 1.0, 0.0],
                ..d
            },
        },
        Case {
            what: "sheen colour (RGB, sRGB)",
            layers: Layers {
                sheen_color: [1.0, 1.0, 1.0],
                sheen_roughness: 0.3,
                ..d
            },
            texels: vec![(LayerSlot::SheenColor, [188, 255, 0, 0])],
            equivalent: Layers {
                sheen_color: [half, 1.0, 0.0],
                sheen_roughness: 0.3,
                ..d
            },
        },
        Case {
            what: "sheen roughness (A)",
            layers: Layers {
                sheen_color: [1.0, 1.0, 1.0],
                sheen_roughness: 1.0,
                ..d
            },
            texels: vec![(LayerSlot::SheenRoughness, [0, 0, 0, 77])],
            equivalent: Layers {
                sheen_color: [1.0, 1.0, 1.0],
                sheen_roughness: 77.0 / 255.0,
                ..d
            },
        },
        Case {
            what: "diffuse transmission (A)",
            layers: Layers {
                diffuse_transmission: 1.0,
                ..d
            },
            texels: vec![(LayerSlot::DiffuseTransmission, [255, 255, 255, 0])],
            equivalent: d,
        },
        Case {
            what: "diffuse transmission colour (RGB, sRGB)",
            layers: Layers {
                diffuse_transmission: 1.0,
                ..d
            },
            texels: vec![(LayerSlot::DiffuseTransmissionColor, [188, 255, 0, 0])],
            equivalent: Layers {
                diffuse_transmission: 1.0,
                diffuse_transmission_color: [half, 1.0, 0.0],
                ..d
            },
        },
        Case {
            what: "clear coat (R) of one size and specular (A) of another",
            layers: varnish,
            texels: vec![
                (LayerSlot::ClearCoat, [0, 255, 255, 255]),
                (LayerSlot::Specular, [255, 255, 255, 0]),
            ],
            equivalent: Layers {
                clear_coat: 0.0,
                specular: 0.0,
                ..varnish
            },
        },
    ]
}

#[test]
fn each_layer_texture_scales_its_factor_from_its_channel() {
    if block(Layers::default(), &[], Vec::new()).is_none() {
        return;
    }
    for case in cases() {
        // Each texel its own image, the second of another size (4 × 4 against 1 × 1).
        let (images, textures): (Vec<Image>, Vec<(LayerSlot, TextureRef)>) = case
            .texels
            .iter()
            .enumerate()
            .map(|(k, (slot, rgba))| {
                let (image, reference) = flat_image(if k == 0 { 1 } else { 4 }, *rgba, k);
                (image, (*slot, reference))
            })
            .unzip();
        let textured = block(case.layers, &textures, images).expect("a frame");
        let untextured = block(case.layers, &[], Vec::new()).expect("a frame");
        let equivalent = block(case.equivalent, &[], Vec::new()).expect("a frame");
        println!(
            "{}: textured {textured:?}, its factors alone {untextured:?}, the factors it makes {equivalent:?}",
            case.what
        );
        // The comparison means something: the texture changes what the factors alone draw.
        let change = largest_difference(untextured.0, equivalent.0).max(largest_difference(untextured.1, equivalent.1));
        assert!(
            change >= 3.0,
            "{}: the texels should make a visible change ({change})",
            case.what
        );
        for (face, (t, e)) in [
            ("face on", (textured.0, equivalent.0)),
            ("grazing", (textured.1, equivalent.1)),
        ] {
            assert!(
                largest_difference(t, e) <= 2.0,
                "{} {face}: textured {t:?} against the factors it makes {e:?}",
                case.what
            );
        }
    }
}

#[test]
fn a_white_layer_texture_changes_nothing() {
    let layers = Layers {
        clear_coat: 1.0,
        sheen_color: [0.6, 0.3, 0.2],
        sheen_roughness: 0.5,
        ..Layers::default()
    };
    let Some(plain) = block(layers, &[], Vec::new()) else {
        return;
    };
    let (image, reference) = one_texel([255; 4]);
    // (Every slot that scales: white is no normal map's "nothing".)
    let textures: Vec<(LayerSlot, TextureRef)> = LayerSlot::ALL
        .iter()
        .filter(|s| **s != LayerSlot::ClearCoatNormal)
        .map(|s| (*s, reference))
        .collect();
    let white = block(layers, &textures, vec![image]).expect("a frame");
    for (t, e) in [(white.0, plain.0), (white.1, plain.1)] {
        assert!(
            largest_difference(t, e) <= 1.0,
            "white textures {t:?} against none {e:?}"
        );
    }
}

/// A one-texel tangent-space normal map tilted 30° towards +x (the texel (0.5, 0, 0.866)
/// encoded), as the model's image `index`.
fn tilted_normal(index: usize) -> (Image, TextureRef) {
    let (image, mut reference) = one_texel([191, 128, 238, 255]);
    reference.image = index;
    (image, reference)
}

/// Black, and reflecting nothing itself: all it shows is its varnish (factor 1, smooth).
fn varnished_black(normal_map: Option<TextureRef>, coat_normal: Option<(TextureRef, f32)>) -> Material {
    let mut m = Material {
        name: "varnished black".into(),
        base_color: [0.0, 0.0, 0.0, 1.0],
        metallic: 0.0,
        roughness: 0.5,
        normal_texture: normal_map.map(|t| (t, 1.0)),
        layers: Layers {
            specular: 0.0,
            clear_coat: 1.0,
            clear_coat_roughness: 0.0,
            ..Layers::default()
        },
        ..Material::default()
    };
    if let Some((t, scale)) = coat_normal {
        m.layer_textures.set(LayerSlot::ClearCoatNormal, Some(t));
        m.layer_textures.clear_coat_normal_scale = scale;
    }
    m
}

#[test]
fn a_varnish_follows_its_own_normal_map_not_the_bases() {
    // glTF: without `clearcoatNormalTexture` the varnish takes the geometric normal, whatever the
    // base's normal map does (a lacquer over carved grain is a smooth mirror).
    let (image, tilt) = tilted_normal(0);
    let Some(smooth) = seen_as(varnished_black(None, None), Vec::new()) else {
        return;
    };
    let over_bumps = seen_as(varnished_black(Some(tilt), None), vec![image.clone()]).expect("a frame");
    let own_tilt = seen_as(varnished_black(None, Some((tilt, 1.0))), vec![image.clone()]).expect("a frame");
    let own_tilt_over_bumps =
        seen_as(varnished_black(Some(tilt), Some((tilt, 1.0))), vec![image.clone()]).expect("a frame");
    let own_flattened = seen_as(varnished_black(None, Some((tilt, 0.0))), vec![image]).expect("a frame");
    println!(
        "a black block's varnish: smooth {smooth:?}; over a tilted normal map {over_bumps:?}; tilted by its own map {own_tilt:?}, \
         the same over the tilted base {own_tilt_over_bumps:?}; its own map at scale 0 {own_flattened:?}"
    );
    let differ = |a: ([f32; 3], [f32; 3]), b: ([f32; 3], [f32; 3])| {
        largest_difference(a.0, b.0).max(largest_difference(a.1, b.1))
    };
    // The tilt shows in the varnish when it is the varnish's own.
    assert!(
        differ(own_tilt, smooth) >= 3.0,
        "own tilt {own_tilt:?} against smooth {smooth:?}"
    );
    // The base's map leaves the varnish as it is; the varnish's own map alone tilts it; at scale 0
    // it tilts nothing.
    assert!(
        differ(over_bumps, smooth) <= 1.0,
        "over bumps {over_bumps:?} against smooth {smooth:?}"
    );
    assert!(
        differ(own_tilt_over_bumps, own_tilt) <= 1.0,
        "own tilt over bumps {own_tilt_over_bumps:?} against own tilt {own_tilt:?}"
    );
    assert!(
        differ(own_flattened, smooth) <= 1.0,
        "scale 0 {own_flattened:?} against smooth {smooth:?}"
    );
}

#[test]
fn the_visitors_varnish_follows_the_surface_as_drawn() {
    // The material screen's clear coat over a scan: its normal map is the object's real relief,
    // which a varnish brushed on follows.
    let (image, tilt) = tilted_normal(0);
    let bare = |normal_map: Option<TextureRef>| Material {
        layers: Layers {
            clear_coat: 0.0,
            ..varnished_black(None, None).layers
        },
        ..varnished_black(normal_map, None)
    };
    let varnish = Appearance {
        clear_coat: 1.0,
        clear_coat_roughness: 0.0,
        ..Appearance::default()
    };
    let Some(smooth) = seen_in(bare(None), Vec::new(), varnish) else {
        return;
    };
    let over_bumps = seen_in(bare(Some(tilt)), vec![image], varnish).expect("a frame");
    println!("the visitor's varnish on a black block: smooth {smooth:?}, over a tilted normal map {over_bumps:?}");
    let differ = largest_difference(over_bumps.0, smooth.0).max(largest_difference(over_bumps.1, smooth.1));
    assert!(differ >= 3.0, "over bumps {over_bumps:?} against smooth {smooth:?}");
}

/// Two blocks side by side on the floor, the left of `left`, the right of `right`, over
/// `images`: each one's top face as the eye sees it.
fn two_blocks(left: Material, right: Material, images: Vec<Image>) -> Option<([f32; 3], [f32; 3])> {
    use crate::render::{OBLIQUE_LIGHT, add_part, pixel_at, push_floor_marker, render_over_floor};
    use phantogram::glam::Vec3;
    let mut floor = phantogram::model::Mesh::default();
    push_floor_marker(&mut floor);
    let mut model = phantogram::model::Model::from_painted_mesh("two blocks", floor);
    model.images = images;
    let tops = [Vec3::new(-0.012, 0.0, -0.02), Vec3::new(0.012, 0.0, -0.02)];
    for (top, material) in tops.iter().zip([left, right]) {
        let mut block = phantogram::model::Mesh::default();
        block.push_cube(*top - Vec3::new(0.0, 0.0, 0.006), 0.006, [1.0; 4]);
        add_part(&mut model, block, material);
    }
    let (pixels, proj) = render_over_floor(model, true, OBLIQUE_LIGHT)?;
    let rgb = |p: Vec3| {
        let c = pixel_at(&pixels, &proj, p);
        [f32::from(c[0]), f32::from(c[1]), f32::from(c[2])]
    };
    Some((rgb(tops[0]), rgb(tops[1])))
}

#[test]
fn materials_sharing_a_layer_image_each_read_their_own_slots() {
    // One image in both materials' slots (so one array for both): the left reads it as its
    // varnish's share (R 0: none), the right as its specular strength (A 0: none).
    let (image, texel) = one_texel([0, 255, 255, 0]);
    let varnish = Layers {
        clear_coat: 1.0,
        ..Layers::default()
    };
    let mut left = dark_rough(varnish);
    left.layer_textures.set(LayerSlot::ClearCoat, Some(texel));
    let mut right = dark_rough(Layers::default());
    right.layer_textures.set(LayerSlot::Specular, Some(texel));
    let Some(textured) = two_blocks(left, right, vec![image]) else {
        return;
    };
    let plain = two_blocks(dark_rough(varnish), dark_rough(Layers::default()), Vec::new()).expect("a frame");
    let expected = two_blocks(
        dark_rough(Layers::default()),
        dark_rough(Layers {
            specular: 0.0,
            ..Layers::default()
        }),
        Vec::new(),
    )
    .expect("a frame");
    println!(
        "two blocks' tops: textured {textured:?}, factors alone {plain:?}, the factors the texels make {expected:?}"
    );
    assert!(largest_difference(plain.0, expected.0) >= 3.0 && largest_difference(plain.1, expected.1) >= 3.0);
    assert!(
        largest_difference(textured.0, expected.0) <= 2.0,
        "left: {textured:?} against {expected:?}"
    );
    assert!(
        largest_difference(textured.1, expected.1) <= 2.0,
        "right: {textured:?} against {expected:?}"
    );
}
