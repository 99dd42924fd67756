//! A glTF `textureInfo` as an extension's JSON writes it (the extensions gltf-rs does not type:
//! `KHR_materials_pbrSpecularGlossiness`, `KHR_materials_transmission`): texture index, texture
//! coordinate set and the `KHR_texture_transform` object, if any. The loader turns it into a
//! [`super::TextureRef`] once it has the document's textures.
//!
//! Pure data; no panics on any input.

use serde_json::Value;

#[derive(Clone, Debug, PartialEq)]
pub(super) struct TextureInfo {
    pub index: usize,
    pub tex_coord: u32,
    pub transform: Option<Value>,
}

impl TextureInfo {
    /// The `textureInfo` under `key` in `object`; `None` where there is none, an error naming
    /// what is malformed.
    pub(super) fn read(object: &Value, key: &str) -> Result<Option<Self>, String> {
        let Some(info) = object.get(key) else {
            return Ok(None);
        };
        let index = info
            .get("index")
            .and_then(Value::as_u64)
            .and_then(|i| usize::try_from(i).ok())
            .ok_or_else(|| format!("{key}.index is missing or not an index"))?;
        let tex_coord = match info.get("texCoord") {
            None => 0,
            Some(t) => t
                .as_u64()
                .and_then(|t| u32::try_from(t).ok())
                .ok_or_else(|| format!("{key}.texCoord is not a set number"))?,
        };
        let transform = info
            .get("extensions")
            .and_then(|e| e.get("KHR_texture_transform"))
            .cloned();
        Ok(Some(Self {
            index,
            tex_coord,
            transform,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn a_texture_info_is_read_with_its_set_and_transform() {
        let object = json!({ "t": { "index": 3, "texCoord": 1, "extensions": { "KHR_texture_transform": { "scale": [2, 2] } } } });
        let info = TextureInfo::read(&object, "t").unwrap().unwrap();
        assert_eq!((info.index, info.tex_coord), (3, 1));
        assert_eq!(info.transform, Some(json!({ "scale": [2, 2] })));
        assert_eq!(TextureInfo::read(&object, "absent").unwrap(), None);
        for bad in [
            json!({ "t": {} }),
            json!({ "t": { "index": -1 } }),
            json!({ "t": { "index": 0, "texCoord": "a" } }),
        ] {
            assert!(TextureInfo::read(&bad, "t").unwrap_err().starts_with("t."), "{bad}");
        }
    }
}
