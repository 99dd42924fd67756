//! The sheen of cloth (`KHR_materials_sheen`; the assets crate's `ibl::sheen`, `scene.wgsl`'s
//! `charlie`): velvet's fibres catch the light where the surface turns away from the eye, and
//! hardly where it faces it.

use crate::render::{add_part, pixel_at, push_floor_marker, render_over_floor_as};
use phantogram::appearance::Appearance;
use phantogram::glam::{Mat4, Vec3};
use phantogram::model::{Image, Layers, Material, Mesh, Model};

const CENTRE: Vec3 = Vec3::new(0.0, 0.0, -0.015);
const HALF: f32 = 0.006;
const TILT_DEG: f32 = 75.0;

/// The block's two faces the eye sees: one almost face on (n·v 0.97) and one at a grazing angle
/// (n·v 0.26), at their centres.
fn faces() -> (Vec3, Vec3) {
    let turn = Mat4::from_rotation_x(TILT_DEG.to_radians());
    let face_on = CENTRE + turn.transform_vector3(Vec3::new(0.0, HALF, 0.0));
    let grazing = CENTRE + turn.transform_vector3(Vec3::new(0.0, 0.0, HALF));
    (face_on, grazing)
}

/// The block's two faces, a dark cloth with `sheen` (colour, roughness), as the eye sees them.
fn seen(sheen: Option<([f32; 3], f32)>) -> Option<([f32; 3], [f32; 3])> {
    let (sheen_color, sheen_roughness) = sheen.unwrap_or(([0.0; 3], 0.0));
    seen_as(
        Material {
            name: "cloth".into(),
            base_color: [0.08, 0.08, 0.1, 1.0],
            metallic: 0.0,
            roughness: 0.9,
            layers: Layers {
                sheen_color,
                sheen_roughness,
                ..Layers::default()
            },
            ..Material::default()
        },
        Vec::new(),
    )
}

/// The block's two faces in `material` (with `images` for its textures), as the eye sees them:
/// face on, then at a grazing angle.
pub(crate) fn seen_as(material: Material, images: Vec<Image>) -> Option<([f32; 3], [f32; 3])> {
    seen_in(material, images, Appearance::default())
}

/// [`seen_as`], in the visitor's `appearance`.
pub(crate) fn seen_in(material: Material, images: Vec<Image>, appearance: Appearance) -> Option<([f32; 3], [f32; 3])> {
    let mut floor = Mesh::default();
    push_floor_marker(&mut floor);
    let mut model = Model::from_painted_mesh("tilted block", floor);
    model.images = images;
    let mut block = Mesh::default();
    block.push_cube(Vec3::ZERO, HALF, [1.0; 4]);
    block.transform(Mat4::from_translation(CENTRE) * Mat4::from_rotation_x(TILT_DEG.to_radians()));
    add_part(&mut model, block, material);
    let (pixels, proj) = render_over_floor_as(model, appearance)?;
    let (face_on, grazing) = faces();
    let rgb = |p: Vec3| {
        let c = pixel_at(&pixels, &proj, p);
        [f32::from(c[0]), f32::from(c[1]), f32::from(c[2])]
    };
    Some((rgb(face_on), rgb(grazing)))
}

#[test]
fn velvet_shines_where_it_turns_away_from_the_eye() {
    let Some((bare_on, bare_grazing)) = seen(None) else {
        return;
    };
    let (velvet_on, velvet_grazing) = seen(Some(([1.0, 0.2, 0.2], 0.3))).expect("a frame");
    println!(
        "dark cloth face on {bare_on:?}, at a grazing angle {bare_grazing:?}; with a red sheen face on {velvet_on:?}, grazing {velvet_grazing:?}"
    );
    let gain = |with: [f32; 3], without: [f32; 3]| with[0] - without[0];
    let (on, grazing) = (gain(velvet_on, bare_on), gain(velvet_grazing, bare_grazing));
    assert!(grazing > 15.0, "the sheen at a grazing angle: +{grazing} red");
    assert!(
        grazing > 3.0 * on.max(1.0),
        "grazing +{grazing} red against face on +{on}"
    );
    // Red fibres shine red.
    assert!(
        velvet_grazing[0] > 1.5 * velvet_grazing[1],
        "the sheen's colour: {velvet_grazing:?}"
    );
}

#[test]
fn the_sheens_room_light_on_the_shared_rooms() {
    // The sheen's image light read about the normal (assets crate `ibl::accuracy`) checked where
    // the read was not chosen: every shared room, a fine and a coarse sheen, against an integral
    // of the lobe over the room. It must beat the mirror-direction read it replaced (Filament's
    // and Khronos's glTF Sample Viewer's) in each.
    use phantogram::ibl::accuracy::sheen_read_errors;
    phantogram_integration::nearer_in_every_shared_room(|env| {
        [0.3f32, 0.7]
            .into_iter()
            .map(|roughness| {
                (
                    format!("sheen roughness {roughness} (mirror → normal)"),
                    sheen_read_errors(env, roughness, 40),
                )
            })
            .collect()
    });
}
