//! The textures of glTF's layer extensions that scale a layer's factors over a surface: where a
//! varnish lies and how glossy it is (`KHR_materials_clearcoat`), how strong and what colour the
//! dielectric's reflection is (`KHR_materials_specular`), the colour and roughness of cloth's
//! sheen (`KHR_materials_sheen`), how much light a thin sheet scatters through and in what
//! colour (`KHR_materials_diffuse_transmission`), along which direction and how strongly a
//! specular lobe is stretched (`KHR_materials_anisotropy`), and where a thin film lies and how
//! thick it is (`KHR_materials_iridescence`). Each is read from the channels its extension
//! names ([`LayerSlot::channels`]); colour ones are sRGB-encoded, the others linear.
//!
//! The varnish's own normal map (`clearcoatNormalTexture`) is among them: without it the varnish
//! lies smooth over the surface's geometric normal, whatever the base's normal map does (glTF's
//! rule: a lacquer over carved grain is a smooth mirror). The transmission and thickness textures
//! are [`super::Material::transmission_texture`] and [`super::Material::thickness_texture`].
//!
//! Pure data; no panics.

use super::TextureRef;

/// One texture of a layer extension, by what it scales.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayerSlot {
    /// `clearcoatTexture`: R scales the varnish's share.
    ClearCoat,
    /// `clearcoatRoughnessTexture`: G scales its roughness.
    ClearCoatRoughness,
    /// `specularTexture`: A scales the dielectric's specular strength.
    Specular,
    /// `specularColorTexture`: RGB (sRGB) scales its reflectance's colour.
    SpecularColor,
    /// `sheenColorTexture`: RGB (sRGB) scales the sheen's colour.
    SheenColor,
    /// `sheenRoughnessTexture`: A scales the sheen's roughness.
    SheenRoughness,
    /// `diffuseTransmissionTexture`: A scales the share of diffuse light passed through.
    DiffuseTransmission,
    /// `diffuseTransmissionColorTexture`: RGB (sRGB) scales that light's colour.
    DiffuseTransmissionColor,
    /// `clearcoatNormalTexture`: RGB, a tangent-space normal map of the varnish (times its scale
    /// in x and y, [`LayerTextures::clear_coat_normal_scale`]).
    ClearCoatNormal,
    /// `anisotropyTexture`: RG the direction of the stretch in tangent space (−1–1, before the
    /// rotation), B scales its strength.
    Anisotropy,
    /// `iridescenceTexture`: R scales the thin film's strength.
    Iridescence,
    /// `iridescenceThicknessTexture`: G blends its thickness from the minimum to the maximum.
    IridescenceThickness,
}

impl LayerSlot {
    /// Every slot, in the order [`LayerTextures::slots`] gives them (the renderer's order too).
    pub const ALL: [LayerSlot; 12] = [
        LayerSlot::ClearCoat,
        LayerSlot::ClearCoatRoughness,
        LayerSlot::Specular,
        LayerSlot::SpecularColor,
        LayerSlot::SheenColor,
        LayerSlot::SheenRoughness,
        LayerSlot::DiffuseTransmission,
        LayerSlot::DiffuseTransmissionColor,
        LayerSlot::ClearCoatNormal,
        LayerSlot::Anisotropy,
        LayerSlot::Iridescence,
        LayerSlot::IridescenceThickness,
    ];

    /// The extension and the texture field it is read from.
    pub fn field(self) -> (&'static str, &'static str) {
        match self {
            LayerSlot::ClearCoat => ("KHR_materials_clearcoat", "clearcoatTexture"),
            LayerSlot::ClearCoatRoughness => ("KHR_materials_clearcoat", "clearcoatRoughnessTexture"),
            LayerSlot::Specular => ("KHR_materials_specular", "specularTexture"),
            LayerSlot::SpecularColor => ("KHR_materials_specular", "specularColorTexture"),
            LayerSlot::SheenColor => ("KHR_materials_sheen", "sheenColorTexture"),
            LayerSlot::SheenRoughness => ("KHR_materials_sheen", "sheenRoughnessTexture"),
            LayerSlot::DiffuseTransmission => ("KHR_materials_diffuse_transmission", "diffuseTransmissionTexture"),
            LayerSlot::DiffuseTransmissionColor => {
                ("KHR_materials_diffuse_transmission", "diffuseTransmissionColorTexture")
            }
            LayerSlot::ClearCoatNormal => ("KHR_materials_clearcoat", "clearcoatNormalTexture"),
            LayerSlot::Anisotropy => ("KHR_materials_anisotropy", "anisotropyTexture"),
            LayerSlot::Iridescence => ("KHR_materials_iridescence", "iridescenceTexture"),
            LayerSlot::IridescenceThickness => ("KHR_materials_iridescence", "iridescenceThicknessTexture"),
        }
    }

    /// The channels it is read from: "R", "G", "A" or "RGB".
    pub fn channels(self) -> &'static str {
        match self {
            LayerSlot::ClearCoat | LayerSlot::Iridescence => "R",
            LayerSlot::ClearCoatRoughness | LayerSlot::IridescenceThickness => "G",
            LayerSlot::Specular | LayerSlot::SheenRoughness | LayerSlot::DiffuseTransmission => "A",
            LayerSlot::SpecularColor
            | LayerSlot::SheenColor
            | LayerSlot::DiffuseTransmissionColor
            | LayerSlot::ClearCoatNormal
            | LayerSlot::Anisotropy => "RGB",
        }
    }

    /// Whether it holds colour (sRGB-encoded, as glTF's colour textures are; a normal map is
    /// linear).
    pub fn is_colour(self) -> bool {
        matches!(
            self,
            LayerSlot::SpecularColor | LayerSlot::SheenColor | LayerSlot::DiffuseTransmissionColor
        )
    }
}

/// A material's layer textures, each where its file gives one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LayerTextures {
    /// By slot, in [`LayerSlot::ALL`]'s order (a slot's index is its discriminant).
    textures: [Option<TextureRef>; 12],
    /// `clearcoatNormalTexture`'s `scale`: the factor on its normals' x and y (1 by default).
    pub clear_coat_normal_scale: f32,
}

impl Default for LayerTextures {
    fn default() -> Self {
        Self {
            textures: [None; 12],
            clear_coat_normal_scale: 1.0,
        }
    }
}

impl LayerTextures {
    /// The texture of `slot`.
    pub fn get(&self, slot: LayerSlot) -> Option<TextureRef> {
        self.textures[slot as usize]
    }

    /// Sets the texture of `slot`.
    pub fn set(&mut self, slot: LayerSlot, texture: Option<TextureRef>) {
        self.textures[slot as usize] = texture;
    }

    /// Each slot's texture, in [`LayerSlot::ALL`]'s order.
    pub fn slots(&self) -> [Option<TextureRef>; 12] {
        self.textures
    }

    /// Whether any slot has a texture.
    pub fn any(&self) -> bool {
        self.textures.iter().any(Option::is_some)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_slot_indexes_its_place_in_all() {
        for (k, slot) in LayerSlot::ALL.into_iter().enumerate() {
            assert_eq!(slot as usize, k, "{slot:?}");
        }
    }

    #[test]
    fn each_slot_is_its_own_field() {
        let mut textures = LayerTextures::default();
        assert!(!textures.any());
        for (k, slot) in LayerSlot::ALL.into_iter().enumerate() {
            let t = TextureRef {
                image: k,
                tex_coord: 0,
                transform: Default::default(),
                sampler: Default::default(),
            };
            textures.set(slot, Some(t));
        }
        assert!(textures.any());
        let images: Vec<usize> = textures.slots().iter().map(|t| t.expect("set").image).collect();
        assert_eq!(images, (0..12).collect::<Vec<_>>());
        let fields: std::collections::HashSet<_> = LayerSlot::ALL.iter().map(|s| s.field()).collect();
        assert_eq!(fields.len(), 12);
        assert_eq!(LayerTextures::default().clear_coat_normal_scale, 1.0);
    }

    #[test]
    fn colour_slots_are_the_rgb_ones() {
        let colour: Vec<LayerSlot> = LayerSlot::ALL.into_iter().filter(|s| s.is_colour()).collect();
        assert_eq!(
            colour,
            [
                LayerSlot::SpecularColor,
                LayerSlot::SheenColor,
                LayerSlot::DiffuseTransmissionColor
            ]
        );
    }
}
