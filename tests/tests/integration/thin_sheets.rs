//! Thin sheets that pass diffuse light (`KHR_materials_diffuse_transmission`; `scene.wgsl`'s
//! `shade_surface`): paper, parchment or a leaf glows with the light behind it, in the colour the
//! light takes through it.

use crate::render::{add_part, pixel_at, push_floor_marker, render_over_floor};
use phantogram::glam::Vec3;
use phantogram::model::{Layers, Material, Mesh, Model};

/// The pixel at the centre of a thin, double-sided sheet 12 mm under the glass, facing the eye,
/// lit from behind (the directional light below it), with `layers`.
fn sheet_lit_from_behind(layers: Layers) -> Option<[f32; 3]> {
    let mut floor = Mesh::default();
    push_floor_marker(&mut floor);
    let mut model = Model::from_painted_mesh("a sheet against the light", floor);
    let mut sheet = Mesh::default();
    crate::transmission::square(&mut sheet, -0.012, true, [1.0; 4]);
    add_part(
        &mut model,
        sheet,
        Material {
            name: "paper".into(),
            base_color: [0.8, 0.8, 0.8, 1.0],
            metallic: 0.0,
            roughness: 1.0,
            double_sided: true,
            layers,
            ..Material::default()
        },
    );
    // No shadows: the floor, lit from below, would hide the light from everything above it.
    let (pixels, proj) = render_over_floor(model, false, Vec3::new(0.3, 0.0, -1.0))?;
    let c = pixel_at(&pixels, &proj, Vec3::new(0.0, 0.0, -0.012));
    Some([f32::from(c[0]), f32::from(c[1]), f32::from(c[2])])
}

#[test]
fn a_thin_sheet_glows_with_the_light_behind_it() {
    let Some(opaque) = sheet_lit_from_behind(Layers::default()) else {
        return;
    };
    let leaf = sheet_lit_from_behind(Layers {
        diffuse_transmission: 0.8,
        diffuse_transmission_color: [0.3, 1.0, 0.2],
        ..Layers::default()
    })
    .expect("a frame");
    println!("a sheet lit from behind: opaque {opaque:?}, passing light like a leaf {leaf:?}");
    assert!(
        leaf[1] > opaque[1] + 30.0,
        "the light behind shows through: {leaf:?} vs {opaque:?}"
    );
    assert!(
        leaf[1] > leaf[0] + 20.0 && leaf[1] > leaf[2] + 20.0,
        "in the leaf's green: {leaf:?}"
    );
}
