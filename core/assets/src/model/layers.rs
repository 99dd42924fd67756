//! What glTF's material extensions add to a metallic–roughness surface, by the factors they give:
//! the dielectric's index of refraction (`KHR_materials_ior`) and specular strength and colour
//! (`KHR_materials_specular`), a varnish over it (`KHR_materials_clearcoat`), light passing
//! through it as through glass (`KHR_materials_transmission`) and absorbed inside it
//! (`KHR_materials_volume`) and split into colours by it (`KHR_materials_dispersion`: a gem's
//! fire), the sheen of cloth's fibres over it (`KHR_materials_sheen`: velvet, silk, felt), and
//! light scattered through a thin sheet to its other side (`KHR_materials_diffuse_transmission`:
//! paper, parchment, leaves, a lampshade), a specular lobe stretched along one direction of
//! the surface (`KHR_materials_anisotropy`: brushed metal), and the colours of a thin film on it
//! (`KHR_materials_iridescence`: weathered Roman glass, tarnish, a soap bubble).
//!
//! Invariants of a [`Layers`] made by [`Layers::from_extensions`]: every value finite and in the
//! range its extension allows (a value outside it is clamped, with a warning). The defaults are
//! glTF's core material: none of the layers, an index of 1.5.
//!
//! Of their textures, `transmissionTexture` and `thicknessTexture` are read (by the loader, into
//! [`super::Material::transmission_texture`] and [`super::Material::thickness_texture`]): the
//! first says which parts of a surface are glass (without it a lantern's frame would be as clear
//! as its panes), the second where a volume is thinner than its factor (without it a glass
//! figure's thin fingers would be as dark as its body). Those of the varnish, specular, sheen and
//! diffuse transmission, and the varnish's normal map, are read into
//! [`super::Material::layer_textures`] (`layer_textures`).
//!
//! Pure data; no panics.

use serde_json::Value;

/// The extensions [`Layers::from_extensions`] reads, for the loader's list of supported ones.
pub const EXTENSIONS: [&str; 10] = [
    "KHR_materials_ior",
    "KHR_materials_specular",
    "KHR_materials_clearcoat",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_materials_sheen",
    "KHR_materials_dispersion",
    "KHR_materials_diffuse_transmission",
    "KHR_materials_anisotropy",
    "KHR_materials_iridescence",
];

/// The layers over, in and through a material's base (see the module docs). Lengths are in the
/// model's units as its meshes stand (glTF's metres: the loader scales a volume with the node
/// that places it, [`super::Model::transform`] with the model), colours linear.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layers {
    /// Index of refraction of the dielectric: its reflectance at normal incidence is
    /// ((ior − 1)/(ior + 1))², 4 % at glTF's 1.5; 1 reflects nothing. Infinite: the file's 0,
    /// `KHR_materials_ior`'s specular–glossiness mode, where the reflectance is the specular
    /// colour at every angle ([`Self::fresnel_rises`] is false).
    pub ior: f32,
    /// Strength of the dielectric's specular reflection, 0–1 (it scales the reflectance at every
    /// angle, grazing included).
    pub specular: f32,
    /// Colour of the dielectric's reflectance at normal incidence, a factor on the one `ior`
    /// gives (the product is kept at most 1); may exceed 1.
    pub specular_color: [f32; 3],
    /// Share of the surface under a clear varnish (a dielectric of index 1.5), 0–1, and the
    /// varnish's roughness.
    pub clear_coat: f32,
    pub clear_coat_roughness: f32,
    /// Share of the light entering the dielectric that passes through instead of being scattered
    /// back (glass: 1), 0–1. The base colour tints it.
    pub transmission: f32,
    /// Thickness of the volume under the surface (0: a thin wall, as glTF has it without
    /// `KHR_materials_volume`).
    pub thickness: f32,
    /// The colour white light becomes after [`Self::attenuation_distance`] inside the volume.
    pub attenuation_color: [f32; 3],
    /// Distance over which the volume absorbs light to [`Self::attenuation_color`]; infinite:
    /// nothing is absorbed.
    pub attenuation_distance: f32,
    /// Colour of the sheen of fibres standing from the surface (cloth), linear, 0–1 (black: no
    /// sheen), and their roughness, 0–1 (the spread of the sheen: low, a rim light at grazing
    /// angles like velvet's; high, a soft glow).
    pub sheen_color: [f32; 3],
    pub sheen_roughness: f32,
    /// How much the index of refraction changes across the visible colours: 20 / the Abbe
    /// number (0: none; crown glass about 0.3, diamond 0.36, flint glass up to 0.6).
    pub dispersion: f32,
    /// Share of the diffusely scattered light that leaves through the other side of a thin sheet
    /// (0–1), and the colour it takes on the way (linear, 0–1).
    pub diffuse_transmission: f32,
    pub diffuse_transmission_color: [f32; 3],
    /// How much the specular lobe's roughness grows along one direction of the surface (0–1; its
    /// alpha becomes mix(α, 1, strength²) there, the other direction keeps α), and that
    /// direction's angle from the mesh's tangent towards its bitangent (radians).
    pub anisotropy: f32,
    pub anisotropy_rotation_rad: f32,
    /// How much a thin film over the surface colours its reflection (0–1: the Fresnel term mixed
    /// towards the film's), the film's index of refraction, and its thickness range (nm): the
    /// maximum where no thickness texture says otherwise, which blends from the minimum.
    pub iridescence: f32,
    pub iridescence_ior: f32,
    pub iridescence_thickness_nm: [f32; 2],
}

impl Default for Layers {
    fn default() -> Self {
        Self {
            ior: 1.5,
            specular: 1.0,
            specular_color: [1.0; 3],
            clear_coat: 0.0,
            clear_coat_roughness: 0.0,
            transmission: 0.0,
            thickness: 0.0,
            attenuation_color: [1.0; 3],
            attenuation_distance: f32::INFINITY,
            sheen_color: [0.0; 3],
            sheen_roughness: 0.0,
            dispersion: 0.0,
            diffuse_transmission: 0.0,
            diffuse_transmission_color: [1.0; 3],
            anisotropy: 0.0,
            anisotropy_rotation_rad: 0.0,
            iridescence: 0.0,
            iridescence_ior: 1.3,
            iridescence_thickness_nm: [100.0, 400.0],
        }
    }
}

impl Layers {
    /// The dielectric's reflectance at normal incidence, per channel: ((ior − 1)/(ior + 1))² times
    /// the specular colour, at most 1 (`KHR_materials_specular`'s definition). Not scaled by
    /// [`Self::specular`], which scales the whole lobe.
    pub fn dielectric_f0(&self) -> [f32; 3] {
        self.dielectric_f0_uncapped().map(|c| c.min(1.0))
    }

    /// [`Self::dielectric_f0`] before its cap at 1: the extension caps it after the specular colour
    /// texture has scaled it, which the renderer does per fragment.
    pub fn dielectric_f0_uncapped(&self) -> [f32; 3] {
        let r = if self.ior.is_finite() {
            (self.ior - 1.0) / (self.ior + 1.0)
        } else {
            1.0
        };
        self.specular_color.map(|c| r * r * c)
    }

    /// Whether the dielectric's reflectance rises towards 1 at grazing angles (Fresnel), as every
    /// finite index has it; with an infinite one it is [`Self::dielectric_f0`] at every angle.
    pub fn fresnel_rises(&self) -> bool {
        self.ior.is_finite()
    }

    /// Optical depth per unit of path length in the volume, per channel: −ln(attenuation colour)
    /// / attenuation distance (Beer–Lambert; 0 where nothing is absorbed, and for a thin wall).
    pub fn absorption_per_unit(&self) -> [f32; 3] {
        if self.thickness <= 0.0 || !self.attenuation_distance.is_finite() {
            return [0.0; 3];
        }
        // A colour of 0 would absorb everything at once: kept finite, far past visible.
        self.attenuation_color
            .map(|c| -(c.max(1e-6)).ln() / self.attenuation_distance)
    }

    /// The indices of refraction of red, green and blue light: [`Self::ior`] spread by
    /// [`Self::dispersion`] about green, by (ior − 1) × dispersion / 40 each way (from the Abbe
    /// number's definition, V = (n_d − 1)/(n_F − n_C), and the extension's 20/V).
    /// An infinite index (the file's 0) has no spread: it is that for every colour.
    pub fn colour_iors(&self) -> [f32; 3] {
        if !self.ior.is_finite() {
            return [self.ior; 3];
        }
        let half = (self.ior - 1.0) * self.dispersion / 40.0;
        [self.ior - half, self.ior, self.ior + half]
    }

    /// Whether the surface has a sheen (a sheen colour other than black).
    pub fn has_sheen(&self) -> bool {
        self.sheen_color.iter().any(|c| *c > 0.0)
    }

    /// Whether light passes through the surface: drawn over what is behind it, filtering it.
    pub fn transmits(&self) -> bool {
        self.transmission > 0.0
    }

    /// Whether a ray crossing the surface changes direction: a volume of an index other than 1
    /// (thin walls, as glTF has them, leave the ray where it was).
    pub fn refracts(&self) -> bool {
        self.thickness > 0.0 && self.ior != 1.0
    }

    /// The layers of the model scaled by `scale` (every length grows by it): the volume's
    /// thickness and attenuation distance, whose ratio, the absorption, stays as it was. A scale
    /// that is not a positive finite number changes nothing.
    pub fn scale_lengths(&mut self, scale: f32) {
        if scale.is_finite() && scale > 0.0 {
            self.thickness *= scale;
            self.attenuation_distance *= scale;
        }
    }

    /// The layers a material's extensions give; `extension` returns an extension's object by
    /// name. `what` names the material in warnings; values out of range are clamped, malformed
    /// ones ignored, each with a warning. Their textures are the loader's to read.
    pub fn from_extensions<'a>(
        extension: impl Fn(&str) -> Option<&'a Value>,
        what: &str,
        warnings: &mut Vec<String>,
    ) -> Self {
        let mut layers = Self::default();
        let mut reader = Reader { what, warnings };
        if let Some(e) = extension("KHR_materials_ior") {
            let ior = reader.number(e, "KHR_materials_ior", "ior", 1.5);
            // The schema allows 0 besides ≥ 1: an infinite index, the mode for materials
            // converted from specular–glossiness (the specular colour is the reflectance).
            layers.ior = if ior == 0.0 {
                f32::INFINITY
            } else {
                reader.clamped("KHR_materials_ior", "ior", ior, 1.0, f32::MAX)
            };
        }
        if let Some(e) = extension("KHR_materials_specular") {
            let name = "KHR_materials_specular";
            let s = reader.number(e, name, "specularFactor", 1.0);
            layers.specular = reader.clamped(name, "specularFactor", s, 0.0, 1.0);
            if let Some(c) = reader.color(e, name, "specularColorFactor") {
                layers.specular_color = c.map(|c| reader.clamped(name, "specularColorFactor", c, 0.0, f32::MAX));
            }
        }
        if let Some(e) = extension("KHR_materials_clearcoat") {
            let name = "KHR_materials_clearcoat";
            let c = reader.number(e, name, "clearcoatFactor", 0.0);
            layers.clear_coat = reader.clamped(name, "clearcoatFactor", c, 0.0, 1.0);
            let r = reader.number(e, name, "clearcoatRoughnessFactor", 0.0);
            layers.clear_coat_roughness = reader.clamped(name, "clearcoatRoughnessFactor", r, 0.0, 1.0);
        }
        if let Some(e) = extension("KHR_materials_transmission") {
            let name = "KHR_materials_transmission";
            let t = reader.number(e, name, "transmissionFactor", 0.0);
            layers.transmission = reader.clamped(name, "transmissionFactor", t, 0.0, 1.0);
        }
        if let Some(e) = extension("KHR_materials_volume") {
            let name = "KHR_materials_volume";
            let t = reader.number(e, name, "thicknessFactor", 0.0);
            layers.thickness = reader.clamped(name, "thicknessFactor", t, 0.0, f32::MAX);
            let d = reader.number(e, name, "attenuationDistance", f32::INFINITY);
            layers.attenuation_distance = if d > 0.0 {
                d
            } else {
                reader.warn(name, "attenuationDistance", "must be positive: no absorption");
                f32::INFINITY
            };
            if let Some(c) = reader.color(e, name, "attenuationColor") {
                layers.attenuation_color = c.map(|c| reader.clamped(name, "attenuationColor", c, 0.0, 1.0));
            }
        }
        if let Some(e) = extension("KHR_materials_sheen") {
            let name = "KHR_materials_sheen";
            if let Some(c) = reader.color(e, name, "sheenColorFactor") {
                layers.sheen_color = c.map(|c| reader.clamped(name, "sheenColorFactor", c, 0.0, 1.0));
            }
            let r = reader.number(e, name, "sheenRoughnessFactor", 0.0);
            layers.sheen_roughness = reader.clamped(name, "sheenRoughnessFactor", r, 0.0, 1.0);
        }
        if let Some(e) = extension("KHR_materials_diffuse_transmission") {
            let name = "KHR_materials_diffuse_transmission";
            let t = reader.number(e, name, "diffuseTransmissionFactor", 0.0);
            layers.diffuse_transmission = reader.clamped(name, "diffuseTransmissionFactor", t, 0.0, 1.0);
            if let Some(c) = reader.color(e, name, "diffuseTransmissionColorFactor") {
                layers.diffuse_transmission_color =
                    c.map(|c| reader.clamped(name, "diffuseTransmissionColorFactor", c, 0.0, 1.0));
            }
        }
        if let Some(e) = extension("KHR_materials_dispersion") {
            let name = "KHR_materials_dispersion";
            let d = reader.number(e, name, "dispersion", 0.0);
            layers.dispersion = reader.clamped(name, "dispersion", d, 0.0, f32::MAX);
        }
        if let Some(e) = extension("KHR_materials_anisotropy") {
            let name = "KHR_materials_anisotropy";
            let a = reader.number(e, name, "anisotropyStrength", 0.0);
            layers.anisotropy = reader.clamped(name, "anisotropyStrength", a, 0.0, 1.0);
            layers.anisotropy_rotation_rad = reader.number(e, name, "anisotropyRotation", 0.0);
        }
        if let Some(e) = extension("KHR_materials_iridescence") {
            let name = "KHR_materials_iridescence";
            let f = reader.number(e, name, "iridescenceFactor", 0.0);
            layers.iridescence = reader.clamped(name, "iridescenceFactor", f, 0.0, 1.0);
            let n = reader.number(e, name, "iridescenceIOR", 1.3);
            layers.iridescence_ior = reader.clamped(name, "iridescenceIOR", n, 1.0, f32::MAX);
            let lo = reader.number(e, name, "iridescenceThicknessMinimum", 100.0);
            let hi = reader.number(e, name, "iridescenceThicknessMaximum", 400.0);
            layers.iridescence_thickness_nm = [
                reader.clamped(name, "iridescenceThicknessMinimum", lo, 0.0, f32::MAX),
                reader.clamped(name, "iridescenceThicknessMaximum", hi, 0.0, f32::MAX),
            ];
        }
        layers
    }
}

/// Reads an extension object's fields into warnings where they are not what its schema says.
struct Reader<'w> {
    what: &'w str,
    warnings: &'w mut Vec<String>,
}

impl Reader<'_> {
    fn warn(&mut self, extension: &str, field: &str, message: &str) {
        self.warnings
            .push(format!("{}: {extension} {field} {message}", self.what));
    }

    /// A number field, `default` where it is absent or not a finite number (with a warning).
    fn number(&mut self, object: &Value, extension: &str, field: &str, default: f32) -> f32 {
        match object.get(field) {
            None => default,
            Some(v) => match v.as_f64().map(|x| x as f32).filter(|x| x.is_finite()) {
                Some(x) => x,
                None => {
                    self.warn(extension, field, "is not a number: its default used");
                    default
                }
            },
        }
    }

    fn clamped(&mut self, extension: &str, field: &str, x: f32, lo: f32, hi: f32) -> f32 {
        if x < lo || x > hi {
            self.warn(
                extension,
                field,
                &format!("{x} is out of its range: kept within {lo}–{hi}"),
            );
        }
        x.clamp(lo, hi)
    }

    /// An RGB array field; `None` where it is absent or malformed (with a warning).
    fn color(&mut self, object: &Value, extension: &str, field: &str) -> Option<[f32; 3]> {
        let v = object.get(field)?;
        let c = v.as_array().filter(|a| a.len() == 3).and_then(|a| {
            let c: Vec<f32> = a
                .iter()
                .filter_map(|x| x.as_f64().map(|x| x as f32).filter(|x| x.is_finite()))
                .collect();
            <[f32; 3]>::try_from(c).ok()
        });
        if c.is_none() {
            self.warn(extension, field, "is not three numbers: its default used");
        }
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn read(extensions: Value) -> (Layers, Vec<String>) {
        let mut warnings = Vec::new();
        let layers = Layers::from_extensions(|name| extensions.get(name), "material glass", &mut warnings);
        (layers, warnings)
    }

    #[test]
    fn without_extensions_the_layers_are_the_core_material() {
        let (layers, warnings) = read(json!({}));
        assert_eq!(layers, Layers::default());
        assert!(warnings.is_empty());
        // ((1.5 − 1)/(1.5 + 1))² = 0.04, the core material's dielectric reflectance.
        for f0 in layers.dielectric_f0() {
            assert!((f0 - 0.04).abs() < 1e-7, "{f0}");
        }
        assert_eq!(layers.absorption_per_unit(), [0.0; 3]);
        assert!(!layers.transmits());
    }

    #[test]
    fn each_extension_sets_its_factors() {
        let (layers, warnings) = read(json!({
            "KHR_materials_ior": { "ior": 2.42 },
            "KHR_materials_specular": { "specularFactor": 0.5, "specularColorFactor": [1.0, 0.5, 0.25] },
            "KHR_materials_clearcoat": { "clearcoatFactor": 0.8, "clearcoatRoughnessFactor": 0.2 },
            "KHR_materials_transmission": { "transmissionFactor": 1.0 },
            "KHR_materials_volume": { "thicknessFactor": 0.01, "attenuationDistance": 0.02, "attenuationColor": [0.9, 0.5, 0.1] }
        }));
        assert!(warnings.is_empty(), "{warnings:?}");
        assert_eq!(layers.ior, 2.42);
        assert_eq!(layers.specular, 0.5);
        assert_eq!((layers.clear_coat, layers.clear_coat_roughness), (0.8, 0.2));
        assert_eq!(layers.transmission, 1.0);
        // Diamond's ((2.42 − 1)/(2.42 + 1))² ≈ 0.1724, times the colour.
        let f0 = layers.dielectric_f0();
        let diamond = (1.42f32 / 3.42).powi(2);
        for (got, c) in f0.iter().zip([1.0, 0.5, 0.25]) {
            assert!((got - diamond * c).abs() < 1e-6, "{f0:?}");
        }
        // After the attenuation distance, white light has become the attenuation colour.
        let sigma = layers.absorption_per_unit();
        for (s, c) in sigma.iter().zip([0.9f32, 0.5, 0.1]) {
            assert!(((-s * 0.02).exp() - c).abs() < 1e-6, "{sigma:?}");
        }
    }

    #[test]
    fn values_out_of_range_are_clamped_and_named() {
        let (layers, warnings) = read(json!({
            "KHR_materials_ior": { "ior": 0.5 },
            "KHR_materials_transmission": { "transmissionFactor": 3.0 },
            "KHR_materials_clearcoat": { "clearcoatFactor": "lots" },
            "KHR_materials_specular": { "specularColorFactor": [1.0, 2.0] },
            "KHR_materials_volume": { "thicknessFactor": 1.0, "attenuationDistance": -1.0 }
        }));
        assert_eq!(layers.ior, 1.0);
        assert_eq!(layers.dielectric_f0(), [0.0; 3]);
        assert_eq!(layers.transmission, 1.0);
        assert_eq!(layers.clear_coat, 0.0);
        assert_eq!(layers.specular_color, [1.0; 3]);
        assert_eq!(layers.attenuation_distance, f32::INFINITY);
        assert_eq!(layers.absorption_per_unit(), [0.0; 3]);
        for field in [
            "ior",
            "transmissionFactor",
            "clearcoatFactor",
            "specularColorFactor",
            "attenuationDistance",
        ] {
            assert!(
                warnings
                    .iter()
                    .any(|w| w.contains(field) && w.starts_with("material glass")),
                "{field}: {warnings:?}"
            );
        }
        assert_eq!(warnings.len(), 5, "{warnings:?}");
    }

    #[test]
    fn dispersion_spreads_the_index_by_the_abbe_number() {
        let (diamond, warnings) = read(json!({
            "KHR_materials_ior": { "ior": 2.417 },
            "KHR_materials_dispersion": { "dispersion": 0.3636 }
        }));
        assert!(warnings.is_empty(), "{warnings:?}");
        // Diamond: Abbe number 55, so n_F − n_C = (n_d − 1)/55 = 0.0258 between blue and red.
        let [r, g, b] = diamond.colour_iors();
        assert_eq!(g, 2.417);
        assert!(((b - r) - 1.417 / 55.0).abs() < 1e-4, "{r} {g} {b}");
        assert!(r < g && g < b);
        // None by default, and a negative factor is clamped to none.
        assert_eq!(Layers::default().colour_iors(), [1.5; 3]);
        let infinite = Layers {
            ior: f32::INFINITY,
            dispersion: 1.0,
            ..Layers::default()
        };
        assert_eq!(infinite.colour_iors(), [f32::INFINITY; 3]);
        let (bad, warnings) = read(json!({ "KHR_materials_dispersion": { "dispersion": -1.0 } }));
        assert_eq!(bad.dispersion, 0.0);
        assert_eq!(warnings.len(), 1, "{warnings:?}");
    }

    #[test]
    fn a_thin_sheet_lets_diffuse_light_through() {
        let (parchment, warnings) = read(json!({
            "KHR_materials_diffuse_transmission": {
                "diffuseTransmissionFactor": 0.4,
                "diffuseTransmissionColorFactor": [1.0, 0.8, 0.5]
            }
        }));
        assert!(warnings.is_empty(), "{warnings:?}");
        assert_eq!(parchment.diffuse_transmission, 0.4);
        assert_eq!(parchment.diffuse_transmission_color, [1.0, 0.8, 0.5]);
        let (bad, warnings) = read(json!({
            "KHR_materials_diffuse_transmission": {
                "diffuseTransmissionFactor": 1.5,
                "diffuseTransmissionTexture": { "index": 0 }
            }
        }));
        assert_eq!(bad.diffuse_transmission, 1.0);
        // The factor clamped; the texture is the loader's to read.
        assert_eq!(warnings.len(), 1, "{warnings:?}");
    }

    #[test]
    fn a_sheen_is_read_and_clamped() {
        let (velvet, warnings) = read(json!({
            "KHR_materials_sheen": { "sheenColorFactor": [0.6, 0.1, 0.2], "sheenRoughnessFactor": 0.3 }
        }));
        assert!(warnings.is_empty(), "{warnings:?}");
        assert_eq!(velvet.sheen_color, [0.6, 0.1, 0.2]);
        assert_eq!(velvet.sheen_roughness, 0.3);
        assert!(velvet.has_sheen());
        // The extension's defaults: black, which is no sheen.
        let (none, _) = read(json!({ "KHR_materials_sheen": {} }));
        assert!(!none.has_sheen());
        let (bad, warnings) = read(json!({
            "KHR_materials_sheen": {
                "sheenColorFactor": [1.5, -0.5, 0.5],
                "sheenRoughnessFactor": 2.0,
                "sheenColorTexture": { "index": 0 }
            }
        }));
        assert_eq!(bad.sheen_color, [1.0, 0.0, 0.5]);
        assert_eq!(bad.sheen_roughness, 1.0);
        // Three values clamped; the texture is the loader's to read.
        assert_eq!(warnings.len(), 3, "{warnings:?}");
        assert!(
            !warnings.iter().any(|w| w.contains("sheenColorTexture")),
            "{warnings:?}"
        );
    }

    #[test]
    fn an_ior_of_zero_makes_the_specular_colour_the_reflectance() {
        let (layers, warnings) = read(json!({
            "KHR_materials_ior": { "ior": 0 },
            "KHR_materials_specular": { "specularColorFactor": [0.5, 0.25, 2.0] },
            "KHR_materials_transmission": { "transmissionFactor": 0.5, "transmissionTexture": { "index": 0 } },
            "KHR_materials_volume": { "thicknessFactor": 0.5, "thicknessTexture": { "index": 0 } },
            "KHR_materials_clearcoat": { "clearcoatFactor": 0.5, "clearcoatNormalTexture": { "index": 0 } }
        }));
        assert_eq!(layers.dielectric_f0(), [0.5, 0.25, 1.0]);
        assert!(!layers.fresnel_rises());
        assert!(Layers::default().fresnel_rises());
        // Every texture is the loader's to read.
        assert!(warnings.is_empty(), "{warnings:?}");
    }

    #[test]
    fn anisotropy_is_read_and_clamped() {
        let (brushed, warnings) = read(json!({
            "KHR_materials_anisotropy": { "anisotropyStrength": 0.6, "anisotropyRotation": 1.57 }
        }));
        assert!(warnings.is_empty(), "{warnings:?}");
        assert_eq!((brushed.anisotropy, brushed.anisotropy_rotation_rad), (0.6, 1.57));
        let (bad, warnings) = read(json!({
            "KHR_materials_anisotropy": { "anisotropyStrength": 2.0, "anisotropyRotation": "up" }
        }));
        assert_eq!((bad.anisotropy, bad.anisotropy_rotation_rad), (1.0, 0.0));
        assert_eq!(warnings.len(), 2, "{warnings:?}");
        assert_eq!(Layers::default().anisotropy, 0.0);
    }

    #[test]
    fn iridescence_is_read_with_the_extensions_defaults() {
        let (film, warnings) = read(json!({
            "KHR_materials_iridescence": { "iridescenceFactor": 1.0, "iridescenceIOR": 1.8, "iridescenceThicknessMaximum": 800 }
        }));
        assert!(warnings.is_empty(), "{warnings:?}");
        assert_eq!(
            (film.iridescence, film.iridescence_ior, film.iridescence_thickness_nm),
            (1.0, 1.8, [100.0, 800.0])
        );
        let (bad, warnings) = read(json!({
            "KHR_materials_iridescence": { "iridescenceFactor": 3, "iridescenceIOR": 0.5, "iridescenceThicknessMinimum": -5 }
        }));
        assert_eq!(
            (bad.iridescence, bad.iridescence_ior, bad.iridescence_thickness_nm),
            (1.0, 1.0, [0.0, 400.0])
        );
        assert_eq!(warnings.len(), 3, "{warnings:?}");
        assert_eq!(Layers::default().iridescence, 0.0);
    }
}
