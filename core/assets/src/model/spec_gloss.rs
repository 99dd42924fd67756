//! Materials in the specular–glossiness workflow (`KHR_materials_pbrSpecularGlossiness`, archived
//! by Khronos in favour of `KHR_materials_specular` but found in older exports), turned into the
//! metallic–roughness materials the renderer draws.
//!
//! Without this a file that uses it shows glTF's default material (white, fully metallic): the
//! scan's colour is lost. The conversion is the one Khronos published beside the extension
//! ("convert between workflows"): roughness is `1 − glossiness`; metallic is the root of the
//! quadratic that makes a metallic–roughness surface reflect the given specular colour over
//! the given diffuse one (dielectrics reflect 4 %, [`DIELECTRIC_SPECULAR`]); the base colour is
//! the diffuse colour lifted by what a dielectric's specular took from it, blended towards the
//! specular colour as the surface turns metallic. Brightness is the perceived one
//! (`√(0.299 r² + 0.587 g² + 0.114 b²)`), as there.
//!
//! With a specular–glossiness texture the conversion runs per texel into new images (linear
//! metallic in B and roughness in G; and, where the diffuse texture has the same size, texture
//! coordinates and transform, the base colour, sRGB): [`bake`]. Where the diffuse texture differs,
//! metallic is solved against the diffuse factor alone and the diffuse texture stays the base
//! colour, an approximation that is exact for dielectrics (specular up to 4 %), the usual case of
//! scanned stone, wood and clay.
//!
//! Pure functions; no panics on any input (factors are clamped, images of any size).

use phantogram_geometry::srgb::{code_to_linear, linear_to_code};
use serde_json::Value;

use super::Image;
use super::texture_info::TextureInfo;

/// What a dielectric reflects at normal incidence (the metallic–roughness model's assumption).
pub(super) const DIELECTRIC_SPECULAR: f32 = 0.04;

/// The extension's properties, with its defaults.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct SpecGloss {
    /// Linear RGBA; alpha is coverage.
    pub diffuse: [f32; 4],
    /// Linear RGB.
    pub specular: [f32; 3],
    pub glossiness: f32,
    pub diffuse_texture: Option<TextureInfo>,
    /// Specular colour in RGB (sRGB), glossiness in A (linear).
    pub specular_glossiness_texture: Option<TextureInfo>,
}

/// Reads the extension's object; an error names what is malformed.
pub(super) fn read(value: &Value) -> Result<SpecGloss, String> {
    // A factor: a finite number, clamped to the schema's [0, 1].
    let number = |v: &Value| v.as_f64().filter(|v| v.is_finite()).map(|v| (v as f32).clamp(0.0, 1.0));
    let numbers = |key: &str, n: usize, default: &[f32]| -> Result<Vec<f32>, String> {
        match value.get(key) {
            None => Ok(default.to_vec()),
            Some(Value::Array(a)) if a.len() == n => a
                .iter()
                .map(|v| number(v).ok_or_else(|| format!("{key} holds a non-number")))
                .collect(),
            Some(_) => Err(format!("{key} is not an array of {n} numbers")),
        }
    };
    let texture = |key: &str| TextureInfo::read(value, key);
    let d = numbers("diffuseFactor", 4, &[1.0; 4])?;
    let s = numbers("specularFactor", 3, &[1.0; 3])?;
    let glossiness = match value.get("glossinessFactor") {
        None => 1.0,
        Some(g) => number(g).ok_or("glossinessFactor is not a number")?,
    };
    Ok(SpecGloss {
        diffuse: [d[0], d[1], d[2], d[3]],
        specular: [s[0], s[1], s[2]],
        glossiness,
        diffuse_texture: texture("diffuseTexture")?,
        specular_glossiness_texture: texture("specularGlossinessTexture")?,
    })
}

fn perceived_brightness(c: [f32; 3]) -> f32 {
    (0.299 * c[0] * c[0] + 0.587 * c[1] * c[1] + 0.114 * c[2] * c[2]).sqrt()
}

/// The metallic value that makes a metallic–roughness surface of matching base colour reflect
/// `specular` over `diffuse` (linear colours): 0 for anything reflecting no more than a
/// dielectric, else the quadratic's root, in [0, 1].
pub(super) fn metallic(diffuse: [f32; 3], specular: [f32; 3]) -> f32 {
    let (d, s) = (perceived_brightness(diffuse), perceived_brightness(specular));
    if s < DIELECTRIC_SPECULAR {
        return 0.0;
    }
    let one_minus_strength = 1.0 - specular.iter().copied().fold(0.0, f32::max);
    let a = DIELECTRIC_SPECULAR;
    let b = d * one_minus_strength / (1.0 - a) + s - 2.0 * a;
    let c = a - s;
    let discriminant = (b * b - 4.0 * a * c).max(0.0);
    ((-b + discriminant.sqrt()) / (2.0 * a)).clamp(0.0, 1.0)
}

/// The base colour (linear) of the metallic–roughness surface with `metallic` that looks like
/// `diffuse` and `specular`.
pub(super) fn base_colour(diffuse: [f32; 3], specular: [f32; 3], metallic: f32) -> [f32; 3] {
    let one_minus_strength = 1.0 - specular.iter().copied().fold(0.0, f32::max);
    let a = DIELECTRIC_SPECULAR;
    let t = metallic * metallic;
    std::array::from_fn(|k| {
        let from_diffuse = diffuse[k] * one_minus_strength / (1.0 - a) / (1.0 - metallic).max(1e-4);
        let from_specular = (specular[k] - a * (1.0 - metallic)) / metallic.max(1e-4);
        (from_diffuse + (from_specular - from_diffuse) * t).clamp(0.0, 1.0)
    })
}

/// Per texel of `specular_glossiness` (specular sRGB in RGB, glossiness in A), times the factors:
/// the metallic–roughness image (roughness in G, metallic in B, linear; R and A 255), and, given a
/// `diffuse` image of the same size (sRGB, times `sg.diffuse`), the base colour image (sRGB, the
/// diffuse texel's coverage times the factor's in A). Without one, metallic is solved against
/// the diffuse factor.
pub(super) fn bake(sg: &SpecGloss, specular_glossiness: &Image, diffuse: Option<&Image>) -> (Image, Option<Image>) {
    let (w, h) = (specular_glossiness.width, specular_glossiness.height);
    let texels = specular_glossiness.rgba8.chunks_exact(4);
    let diffuse = diffuse.filter(|d| (d.width, d.height) == (w, h) && d.rgba8.len() == specular_glossiness.rgba8.len());
    let mut metal_rough = Vec::with_capacity(specular_glossiness.rgba8.len());
    let mut base = diffuse.map(|_| Vec::with_capacity(specular_glossiness.rgba8.len()));
    for (i, t) in texels.enumerate() {
        let specular: [f32; 3] = std::array::from_fn(|k| code_to_linear(t[k]) * sg.specular[k]);
        let glossiness = f32::from(t[3]) / 255.0 * sg.glossiness;
        let diffuse_texel = diffuse.map(|d| &d.rgba8[i * 4..i * 4 + 4]);
        let diffuse_rgb: [f32; 3] =
            std::array::from_fn(|k| sg.diffuse[k] * diffuse_texel.map_or(1.0, |d| code_to_linear(d[k])));
        let m = metallic(diffuse_rgb, specular);
        let code = |v: f32| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
        metal_rough.extend_from_slice(&[255, code(1.0 - glossiness), code(m), 255]);
        if let (Some(base), Some(d)) = (base.as_mut(), diffuse_texel) {
            let c = base_colour(diffuse_rgb, specular, m);
            let alpha = code(f32::from(d[3]) / 255.0 * sg.diffuse[3]);
            base.extend_from_slice(&[linear_to_code(c[0]), linear_to_code(c[1]), linear_to_code(c[2]), alpha]);
        }
    }
    let image = |name: &str, rgba8: Vec<u8>| Image {
        name: format!("{} ({name})", specular_glossiness.name),
        width: w,
        height: h,
        rgba8,
        basis: None,
    };
    (
        image("metallic-roughness from specular-glossiness", metal_rough),
        base.map(|b| image("base colour from diffuse and specular", b)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dielectric_stays_its_diffuse_colour_and_a_metal_takes_its_specular_one() {
        // Plastic: 4 % grey specular, red diffuse.
        let plastic = metallic([0.8, 0.1, 0.1], [0.04; 3]);
        assert_eq!(plastic, 0.0);
        let c = base_colour([0.8, 0.1, 0.1], [0.04; 3], 0.0);
        assert!((c[0] - 0.8).abs() < 1e-3 && (c[1] - 0.1).abs() < 1e-3, "{c:?}");
        // Gold: black diffuse, gold specular.
        let gold = [1.0, 0.77, 0.34];
        let m = metallic([0.0; 3], gold);
        assert!(m > 0.99, "{m}");
        let c = base_colour([0.0; 3], gold, m);
        assert!(c.iter().zip(gold).all(|(c, g)| (c - g).abs() < 0.02), "{c:?}");
        // In between: more specular, more metallic.
        let dull = metallic([0.5; 3], [0.2; 3]);
        let bright = metallic([0.5; 3], [0.5; 3]);
        assert!(0.0 < dull && dull < bright && bright < 1.0, "{dull} {bright}");
    }

    #[test]
    fn a_metallic_roughness_surface_comes_back_as_itself() {
        // A metallic–roughness surface's own specular and diffuse colours (glTF's BRDF: specular
        // = mix(0.04, base, metallic), diffuse seen = base × (1 − 0.04) × (1 − metallic), and the
        // specular–glossiness model dims its diffuse colour by 1 − the strongest specular
        // channel) convert back to its metallic and base colour.
        for (base, m) in [
            ([0.9, 0.6, 0.3], 0.5f32),
            ([0.3, 0.3, 0.8], 0.25),
            ([0.95, 0.9, 0.85], 0.8),
        ] {
            let specular: [f32; 3] = std::array::from_fn(|k| 0.04 + (base[k] - 0.04) * m);
            let strength = specular.iter().copied().fold(0.0, f32::max);
            let diffuse: [f32; 3] = std::array::from_fn(|k| base[k] * (1.0 - 0.04) * (1.0 - m) / (1.0 - strength));
            let got = metallic(diffuse, specular);
            // The published conversion is approximate (it solves for brightness, not per
            // channel): within a few hundredths.
            assert!((got - m).abs() < 0.05, "{base:?} {m}: {got}");
            let c = base_colour(diffuse, specular, got);
            assert!(c.iter().zip(base).all(|(c, b)| (c - b).abs() < 0.08), "{base:?}: {c:?}");
        }
    }

    #[test]
    fn the_extension_is_read_with_its_defaults_and_bad_values_named() {
        let sg = read(&serde_json::json!({})).expect("empty");
        assert_eq!((sg.diffuse, sg.specular, sg.glossiness), ([1.0; 4], [1.0; 3], 1.0));
        let sg = read(&serde_json::json!({
            "diffuseFactor": [0.5, 0.25, 1.5, 1],
            "glossinessFactor": 0.3,
            "diffuseTexture": {"index": 2, "texCoord": 1},
            "specularGlossinessTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"scale": [2, 2]}}}
        }))
        .expect("valid");
        assert_eq!(sg.diffuse, [0.5, 0.25, 1.0, 1.0], "clamped to [0, 1]");
        assert_eq!(sg.glossiness, 0.3);
        assert_eq!(
            sg.diffuse_texture.as_ref().map(|t| (t.index, t.tex_coord)),
            Some((2, 1))
        );
        assert!(sg.specular_glossiness_texture.is_some_and(|t| t.transform.is_some()));
        for bad in [
            serde_json::json!({"diffuseFactor": [1, 1]}),
            serde_json::json!({"specularFactor": "shiny"}),
            serde_json::json!({"glossinessFactor": [1]}),
            serde_json::json!({"diffuseTexture": {"index": -1}}),
        ] {
            assert!(read(&bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn a_texture_is_converted_texel_by_texel() {
        // Two texels: a glossy dielectric and a rough gold.
        let sg_image = Image {
            name: "sg".into(),
            width: 2,
            height: 1,
            rgba8: vec![56, 56, 56, 230, 255, 226, 159, 51],
            basis: None,
        };
        let diffuse = Image {
            name: "d".into(),
            width: 2,
            height: 1,
            rgba8: vec![200, 50, 50, 255, 0, 0, 0, 255],
            basis: None,
        };
        let sg = read(&serde_json::json!({})).expect("defaults");
        let (mr, base) = bake(&sg, &sg_image, Some(&diffuse));
        // Roughness 1 − 230/255 and 1 − 51/255; metallic 0 and about 1.
        assert_eq!(mr.rgba8[1], 25);
        assert_eq!(mr.rgba8[2], 0);
        assert_eq!(mr.rgba8[5], 204);
        assert!(mr.rgba8[6] > 250, "{}", mr.rgba8[6]);
        let base = base.expect("same size: the base colour is baked too");
        // The dielectric keeps its diffuse red (lifted by the 4 % its specular took); the gold
        // takes its specular colour.
        assert!(base.rgba8[0] >= 198 && base.rgba8[1] <= 60, "{:?}", &base.rgba8[..4]);
        assert!(
            base.rgba8[4] > 245 && (215..=235).contains(&base.rgba8[5]) && (140..=175).contains(&base.rgba8[6]),
            "{:?}",
            &base.rgba8[4..]
        );
        // A diffuse texture of another size: metallic solved against the diffuse factor only,
        // no base colour image.
        let small = Image {
            name: "d".into(),
            width: 1,
            height: 1,
            rgba8: vec![0, 0, 0, 255],
            basis: None,
        };
        let (mr2, base2) = bake(&sg, &sg_image, Some(&small));
        assert!(base2.is_none());
        assert_eq!(mr2.rgba8[1], 25);
    }
}
