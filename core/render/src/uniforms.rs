//! The uniform blocks the shaders read, laid out as their WGSL structs (`Eye` and `Material` in
//! `scene.wgsl`, `Compose` in `compose.wgsl`; a test checks the sizes against naga's layout).

use phantogram_assets::{
    appearance::Appearance,
    model::{AlphaMode, Material, TextureRef},
};

/// Per-eye uniform block; matches `Eye` in `scene.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct EyeUniform {
    pub(crate) view_proj: [[f32; 4]; 4],
    pub(crate) eye_pos: [f32; 4],
    pub(crate) toward_light: [f32; 4],
    pub(crate) light: [f32; 4],
    pub(crate) world_from_device: [[f32; 4]; 3],
    pub(crate) light_view_proj: [[f32; 4]; 4],
    /// Texel size (metres) and on/off of the shadow map; the angle a pixel subtends (radians);
    /// 1 when the shadow filter holds this frame's glass (`shadow_filter`).
    pub(crate) shadow: [f32; 4],
    pub(crate) sh: [[f32; 4]; 9],
    /// The artifact's [`Appearance`], as `Appearance` in `scene.wgsl` lays it out.
    pub(crate) appearance: [[f32; 4]; 5],
    /// The [`Lamp`], if one shines: position (w: 1 when on), axis (w: cos outer), intensity (w:
    /// cos inner).
    pub(crate) lamp: [[f32; 4]; 3],
    /// The lamp's cube shadow ([`point_shadow`]): near and far (metres), texels a face, and 1 when
    /// the lamp's shadows are read from it.
    pub(crate) lamp_shadow: [f32; 4],
}

/// `Appearance` in `scene.wgsl`: rgb tint and specular scale; roughness and metalness overrides
/// (negative: keep), clear coat and its roughness; Ward ρd (w: 1 when on), ρs, and αx, αy and
/// the side of its map's tile in metres (0: no map).
pub(crate) fn appearance_uniform(a: &Appearance) -> [[f32; 4]; 5] {
    let a = a.sanitised();
    let ward = a.ward.unwrap_or(phantogram_assets::ward::WardPreset::Matte.material());
    let on = f32::from(u8::from(a.ward.is_some()));
    [
        [a.tint[0], a.tint[1], a.tint[2], a.specular],
        [
            a.roughness.unwrap_or(-1.0),
            a.metalness.unwrap_or(-1.0),
            a.clear_coat,
            a.clear_coat_roughness,
        ],
        [ward.rho_d[0], ward.rho_d[1], ward.rho_d[2], on],
        [ward.rho_s[0], ward.rho_s[1], ward.rho_s[2], 0.0],
        [ward.alpha_x, ward.alpha_y, ward.map.tile_m(), 0.0],
    ]
}

/// Matches `Compose` in `compose.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct ComposeUniform {
    pub(crate) left: [[f32; 4]; 3],
    pub(crate) right: [[f32; 4]; 3],
    pub(crate) params: [f32; 4],
}

/// Twelve values four to a vector, as `array<vec4<f32>, 3>` holds them.
fn by_fours(v: [f32; 12]) -> [[f32; 4]; 3] {
    [
        [v[0], v[1], v[2], v[3]],
        [v[4], v[5], v[6], v[7]],
        [v[8], v[9], v[10], v[11]],
    ]
}

/// Matches `Material` in `scene.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct MaterialUniform {
    pub(crate) base_color: [f32; 4],
    pub(crate) emissive: [f32; 4],
    pub(crate) params: [f32; 4],
    pub(crate) uv_sets: [f32; 4],
    pub(crate) flags: [f32; 4],
    pub(crate) transforms: [[f32; 4]; 38],
    pub(crate) scene: [f32; 4],
    pub(crate) layers: [f32; 4],
    pub(crate) dielectric: [f32; 4],
    pub(crate) volume: [f32; 4],
    pub(crate) sheen: [f32; 4],
    pub(crate) dispersion: [f32; 4],
    pub(crate) diffuse_transmission: [f32; 4],
    pub(crate) layer_index: [[f32; 4]; 3],
    pub(crate) layer_uv_set: [[f32; 4]; 3],
    pub(crate) coat_normal: [f32; 4],
    pub(crate) anisotropy: [f32; 4],
    pub(crate) iridescence: [f32; 4],
}

impl MaterialUniform {
    /// `m`'s block; `layer_index`: the layer of the material's layer textures each
    /// [`phantogram_assets::model::LayerSlot`] reads ([`crate::layer_textures`]), none where it
    /// has no texture.
    pub(crate) fn new(m: &Material, layer_index: [Option<u32>; 12]) -> Self {
        let slots = [
            m.base_color_texture,
            m.metallic_roughness_texture,
            m.normal_texture.map(|(t, _)| t),
            m.occlusion_texture.map(|(t, _)| t),
            m.emissive_texture,
            m.transmission_texture,
            m.thickness_texture,
        ];
        let layer_slots = m.layer_textures.slots();
        let mut transforms = [[0.0; 4]; 38];
        for (i, slot) in slots.iter().chain(&layer_slots).enumerate() {
            let rows = slot.map(|t| t.transform).unwrap_or_default().rows();
            transforms[2 * i] = [rows[0][0], rows[0][1], rows[0][2], 0.0];
            transforms[2 * i + 1] = [rows[1][0], rows[1][1], rows[1][2], 0.0];
        }
        let set = |t: Option<TextureRef>| t.map_or(0.0, |t| t.tex_coord as f32);
        let l = &m.layers;
        // Capped by the shader, after the specular colour texture.
        let f0 = l.dielectric_f0_uncapped();
        // Optical depth across the volume's thickness, at normal incidence.
        let depth = l.absorption_per_unit().map(|a| (a * l.thickness).min(1e4));
        Self {
            base_color: m.base_color,
            emissive: [
                m.emissive[0],
                m.emissive[1],
                m.emissive[2],
                m.normal_texture.map_or(1.0, |(_, s)| s),
            ],
            params: [
                m.metallic,
                m.roughness,
                match m.alpha {
                    AlphaMode::Mask(cutoff) => cutoff,
                    _ => -1.0,
                },
                m.occlusion_texture.map_or(0.0, |(_, s)| s),
            ],
            uv_sets: [set(slots[0]), set(slots[1]), set(slots[2]), set(slots[3])],
            flags: [
                set(slots[4]),
                f32::from(u8::from(m.normal_texture.is_some())),
                f32::from(u8::from(m.alpha == AlphaMode::Blend)),
                f32::from(u8::from(m.unlit)),
            ],
            transforms,
            scene: [
                f32::from(u8::from(m.scenery)),
                set(slots[5]),
                set(slots[6]),
                // The path a ray refracted into the volume takes across it (none without a bend).
                if l.refracts() { l.thickness } else { 0.0 },
            ],
            layers: [
                if m.transmits() { l.transmission } else { 0.0 },
                l.specular,
                l.clear_coat,
                l.clear_coat_roughness,
            ],
            dielectric: [f0[0], f0[1], f0[2], f32::from(u8::from(l.fresnel_rises()))],
            volume: [
                depth[0],
                depth[1],
                depth[2],
                // 1/ior, for the angle of the refracted path (0 for an infinite index).
                1.0 / l.ior,
            ],
            sheen: [l.sheen_color[0], l.sheen_color[1], l.sheen_color[2], l.sheen_roughness],
            dispersion: {
                // 1/ior of red and blue light, and whether they differ from green's.
                let [r, _, b] = l.colour_iors();
                let splits = l.refracts() && l.dispersion > 0.0;
                [1.0 / r, 1.0 / b, f32::from(u8::from(splits)), 0.0]
            },
            diffuse_transmission: {
                let c = l.diffuse_transmission_color;
                [c[0], c[1], c[2], l.diffuse_transmission]
            },
            layer_index: by_fours(layer_index.map(|i| i.map_or(-1.0, |i| i as f32))),
            layer_uv_set: by_fours(layer_slots.map(set)),
            coat_normal: [m.layer_textures.clear_coat_normal_scale, 0.0, 0.0, 0.0],
            anisotropy: [
                l.anisotropy,
                l.anisotropy_rotation_rad.cos(),
                l.anisotropy_rotation_rad.sin(),
                0.0,
            ],
            iridescence: [
                l.iridescence,
                l.iridescence_ior,
                l.iridescence_thickness_nm[0],
                l.iridescence_thickness_nm[1],
            ],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{COMPOSE_WGSL, SCENE_WGSL};
    use phantogram_assets::model::Vertex;

    #[test]
    fn uniform_layouts_match_the_shaders() {
        // Each uniform struct is as large as naga lays out its WGSL namesake.
        let wgsl_size = |source: &str, name: &str| {
            let module = naga::front::wgsl::parse_str(source).expect("valid WGSL");
            module
                .types
                .iter()
                .find(|(_, ty)| ty.name.as_deref() == Some(name))
                .map(|(_, ty)| ty.inner.size(module.to_ctx()) as usize)
                .unwrap_or_else(|| panic!("no struct {name}"))
        };
        assert_eq!(std::mem::size_of::<EyeUniform>(), wgsl_size(SCENE_WGSL, "Eye"));
        assert_eq!(
            std::mem::size_of::<ComposeUniform>(),
            wgsl_size(COMPOSE_WGSL, "Compose")
        );
        assert_eq!(
            std::mem::size_of::<MaterialUniform>(),
            wgsl_size(SCENE_WGSL, "Material")
        );
        // Vertex = 3 + 3 + 4 + 4 + 4 + 2 floats.
        assert_eq!(std::mem::size_of::<Vertex>(), 80);
    }
}
