//! How a visitor has changed an artifact's material on the material screen: a tint over its base
//! colour, roughness and metalness in place of the glTF's, the strength of its dielectric
//! specular, a clear-coat layer, or a Ward lobe ([`crate::ward`]) in place of the
//! metallic-roughness one. [`Appearance::default`] changes nothing: the glTF material as
//! authored.
//!
//! Plain data; [`Appearance::sanitised`] keeps every value in its range whatever a slider, a
//! file or the FFI says, so the renderer never sees NaN or a material that creates energy.

use crate::ward::{WardMap, WardMaterial, WardPreset};

/// Changes over an artifact's glTF materials (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Appearance {
    /// Multiplies the base colour (linear RGB, each 0–1); white keeps it.
    pub tint: [f32; 3],
    /// Replaces the materials' roughness (0–1), or keeps it (`None`).
    pub roughness: Option<f32>,
    /// Replaces the materials' metalness (0–1), or keeps it (`None`).
    pub metalness: Option<f32>,
    /// Scales the dielectric reflectance at normal incidence (glTF's 4 %, or what the material's
    /// index of refraction and specular colour make it), 0–2.
    pub specular: f32,
    /// Strength of a clear lacquer layer over the material (0 none – 1 full; 4 % reflectance).
    /// Where the material has a varnish of its own (`KHR_materials_clearcoat`), the stronger of
    /// the two shows, with its roughness.
    pub clear_coat: f32,
    /// Roughness of that layer (0–1).
    pub clear_coat_roughness: f32,
    /// A Ward lobe in place of the metallic-roughness one: its `rho_d` multiplies the base
    /// colour texture (as glTF's base colour factor does), its `rho_s`, `alpha_x` and `alpha_y`
    /// are the glossy lobe along the surface's tangent.
    pub ward: Option<WardMaterial>,
}

impl Default for Appearance {
    fn default() -> Self {
        Self {
            tint: [1.0; 3],
            roughness: None,
            metalness: None,
            specular: 1.0,
            clear_coat: 0.0,
            clear_coat_roughness: 0.1,
            ward: None,
        }
    }
}

/// The range of [`Appearance::specular`].
pub const SPECULAR_RANGE: std::ops::RangeInclusive<f32> = 0.0..=2.0;

impl Appearance {
    /// The Ward preset's material, nothing else changed.
    pub fn preset(preset: WardPreset) -> Self {
        Self {
            ward: Some(preset.material()),
            ..Self::default()
        }
    }

    /// Whether this changes nothing.
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Every value clamped into its range; NaN becomes the default's value.
    pub fn sanitised(self) -> Self {
        let d = Self::default();
        let clamp = |v: f32, lo: f32, hi: f32, default: f32| if v.is_nan() { default } else { v.clamp(lo, hi) };
        Self {
            tint: std::array::from_fn(|c| clamp(self.tint[c], 0.0, 1.0, 1.0)),
            roughness: self.roughness.map(|r| clamp(r, 0.0, 1.0, 0.5)),
            metalness: self.metalness.map(|m| clamp(m, 0.0, 1.0, 0.0)),
            specular: clamp(
                self.specular,
                *SPECULAR_RANGE.start(),
                *SPECULAR_RANGE.end(),
                d.specular,
            ),
            clear_coat: clamp(self.clear_coat, 0.0, 1.0, d.clear_coat),
            clear_coat_roughness: clamp(self.clear_coat_roughness, 0.0, 1.0, d.clear_coat_roughness),
            ward: self.ward.map(WardMaterial::conserving),
        }
    }
}

impl Appearance {
    /// As JSON (for the per-artifact store): only what differs from the default.
    pub fn to_json(&self) -> serde_json::Value {
        let d = Self::default();
        let mut o = serde_json::Map::new();
        let mut put = |k: &str, v: serde_json::Value| {
            o.insert(k.to_owned(), v);
        };
        if self.tint != d.tint {
            put("tint", serde_json::json!(self.tint));
        }
        if let Some(r) = self.roughness {
            put("roughness", serde_json::json!(r));
        }
        if let Some(m) = self.metalness {
            put("metalness", serde_json::json!(m));
        }
        if self.specular != d.specular {
            put("specular", serde_json::json!(self.specular));
        }
        if self.clear_coat != d.clear_coat || self.clear_coat_roughness != d.clear_coat_roughness {
            put(
                "clear_coat",
                serde_json::json!([self.clear_coat, self.clear_coat_roughness]),
            );
        }
        if let Some(w) = self.ward {
            put(
                "ward",
                serde_json::json!({
                    "rho_d": w.rho_d,
                    "rho_s": w.rho_s,
                    "alpha": [w.alpha_x, w.alpha_y],
                    "map": w.map.key(),
                }),
            );
        }
        serde_json::Value::Object(o)
    }

    /// From [`Self::to_json`]'s form, sanitised; what is missing or malformed keeps the default
    /// (a store written by a later version still loads).
    pub fn from_json(v: &serde_json::Value) -> Self {
        let number = |v: &serde_json::Value| v.as_f64().map(|x| x as f32);
        let rgb = |v: Option<&serde_json::Value>| -> Option<[f32; 3]> {
            let a = v?.as_array()?;
            (a.len() == 3).then(|| std::array::from_fn(|i| number(&a[i]).unwrap_or(f32::NAN)))
        };
        let pair = |v: Option<&serde_json::Value>| -> Option<[f32; 2]> {
            let a = v?.as_array()?;
            (a.len() == 2).then(|| std::array::from_fn(|i| number(&a[i]).unwrap_or(f32::NAN)))
        };
        let d = Self::default();
        let (clear_coat, clear_coat_roughness) =
            pair(v.get("clear_coat")).map_or((d.clear_coat, d.clear_coat_roughness), |[c, r]| (c, r));
        let ward = v.get("ward").and_then(|w| {
            let [alpha_x, alpha_y] = pair(w.get("alpha"))?;
            Some(WardMaterial {
                rho_d: rgb(w.get("rho_d"))?,
                rho_s: rgb(w.get("rho_s"))?,
                alpha_x,
                alpha_y,
                // Stores written before maps (or naming one unknown here): the constants.
                map: w
                    .get("map")
                    .and_then(|m| m.as_str())
                    .and_then(WardMap::from_key)
                    .unwrap_or_default(),
            })
        });
        Self {
            tint: rgb(v.get("tint")).unwrap_or(d.tint),
            roughness: v.get("roughness").and_then(number),
            metalness: v.get("metalness").and_then(number),
            specular: v.get("specular").and_then(number).unwrap_or(d.specular),
            clear_coat,
            clear_coat_roughness,
            ward,
        }
        .sanitised()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sanitising_keeps_good_values_and_bounds_bad_ones() {
        assert!(Appearance::default().is_default());
        assert_eq!(Appearance::default().sanitised(), Appearance::default());
        let glazed = Appearance::preset(WardPreset::Glazed);
        assert_eq!(glazed.sanitised(), glazed);
        assert!(!glazed.is_default());
        let wild = Appearance {
            tint: [2.0, f32::NAN, -1.0],
            roughness: Some(f32::INFINITY),
            metalness: Some(f32::NAN),
            specular: 9.0,
            clear_coat: -3.0,
            clear_coat_roughness: f32::NAN,
            ward: Some(WardMaterial {
                rho_d: [1.0; 3],
                rho_s: [1.0; 3],
                alpha_x: 5.0,
                alpha_y: 0.0,
                map: WardMap::Woven,
            }),
        }
        .sanitised();
        assert_eq!(wild.tint, [1.0, 1.0, 0.0]);
        assert_eq!((wild.roughness, wild.metalness), (Some(1.0), Some(0.0)));
        assert_eq!(
            (wild.specular, wild.clear_coat, wild.clear_coat_roughness),
            (2.0, 0.0, 0.1)
        );
        let ward = wild.ward.expect("kept");
        assert_eq!(
            (ward.rho_d, ward.rho_s, ward.alpha_x, ward.alpha_y),
            ([0.0; 3], [1.0; 3], 1.0, 0.01)
        );
    }

    #[test]
    fn json_round_trips_and_tolerates_junk() {
        let a = Appearance {
            tint: [0.9, 0.8, 0.7],
            roughness: Some(0.3),
            metalness: None,
            specular: 1.5,
            clear_coat: 0.8,
            clear_coat_roughness: 0.05,
            ward: Some(WardPreset::BrushedMetal.material()),
        };
        assert_eq!(Appearance::from_json(&a.to_json()), a);
        assert_eq!(Appearance::default().to_json(), serde_json::json!({}));
        assert_eq!(Appearance::from_json(&serde_json::json!({})), Appearance::default());
        let junk = serde_json::json!({"tint": "red", "roughness": 7, "ward": {"rho_d": [1, 2]}, "x": 1});
        let got = Appearance::from_json(&junk);
        assert_eq!((got.tint, got.roughness, got.ward), ([1.0; 3], Some(1.0), None));
        assert!(Appearance::from_json(&serde_json::json!(null)).is_default());
        // A store from before the maps, or naming a map unknown here: the constants.
        for map in [
            serde_json::json!(null),
            serde_json::json!("plaid"),
            serde_json::json!(3),
        ] {
            let old = serde_json::json!({"ward": {"rho_d": [0.1, 0.1, 0.1], "rho_s": [0.7, 0.7, 0.7], "alpha": [0.05, 0.25], "map": map}});
            let ward = Appearance::from_json(&old).ward.expect("a Ward lobe");
            assert_eq!((ward.map, ward.alpha_y), (WardMap::Uniform, 0.25));
        }
    }
}
