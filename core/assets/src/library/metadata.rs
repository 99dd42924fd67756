//! What the gallery says about an artifact file: its title, credit and licence, read from the
//! glTF `asset` block (`copyright`, and `extras` with `title`, `author`/`credit`,
//! `license`/`licence` — the keys exporters and museums use) or a Voyager scene's `asset` and
//! `metas[].collection`. Only the JSON is read (a GLB's first chunk), within a small bound: the
//! meshes and images are not touched.

use std::path::Path;

use serde_json::Value;

/// Largest JSON read for the metadata (a glTF's JSON chunk or a Voyager scene).
const MAX_JSON_BYTES: u64 = 16 << 20;

/// Title, credit and licence as a file states them (each may be missing).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Metadata {
    pub title: Option<String>,
    pub credit: Option<String>,
    pub licence: Option<String>,
}

impl Metadata {
    /// Fills what `self` lacks from `other`.
    pub fn or(self, other: Metadata) -> Metadata {
        Metadata {
            title: self.title.or(other.title),
            credit: self.credit.or(other.credit),
            licence: self.licence.or(other.licence),
        }
    }
}

/// A string field, trimmed, at most 200 characters (a title line, not an essay); empty is none.
fn text(v: Option<&Value>) -> Option<String> {
    let s = v?.as_str()?.trim();
    if s.is_empty() {
        return None;
    }
    Some(phantogram_files::text::truncate_chars(s, 200))
}

fn first_text(v: &Value, keys: &[&str]) -> Option<String> {
    keys.iter().find_map(|k| text(v.get(k)))
}

/// The metadata of a glTF document's JSON.
pub fn of_gltf_json(json: &Value) -> Metadata {
    let asset = json.get("asset").unwrap_or(&Value::Null);
    let extras = asset.get("extras").unwrap_or(&Value::Null);
    Metadata {
        title: first_text(extras, &["title", "name"]),
        credit: first_text(extras, &["author", "credit", "attribution"]).or_else(|| text(asset.get("copyright"))),
        licence: first_text(extras, &["license", "licence", "licenseUrl"]),
    }
}

/// The metadata of a Voyager scene's JSON.
pub fn of_voyager_scene(json: &Value) -> Metadata {
    let asset = json.get("asset").unwrap_or(&Value::Null);
    let collections = json
        .get("metas")
        .and_then(|m| m.as_array())
        .into_iter()
        .flatten()
        .filter_map(|m| m.get("collection"));
    let mut meta = Metadata {
        credit: text(asset.get("copyright")),
        ..Metadata::default()
    };
    for c in collections {
        meta = meta.or(Metadata {
            title: first_text(c, &["title", "name"]),
            credit: first_text(c, &["credit", "author"]),
            licence: first_text(c, &["license", "licence", "rights"]),
        });
    }
    meta
}

/// The JSON of a `.gltf` file or of a GLB's JSON chunk.
fn gltf_json(path: &Path) -> Option<Value> {
    let bytes = phantogram_files::read_regular_file(path, MAX_JSON_BYTES).ok();
    let bytes = match bytes {
        Some(b) => b,
        // A GLB larger than the bound: its header and JSON chunk only.
        None => {
            use std::io::Read;
            let mut f = phantogram_files::open_regular_file(path).ok()?;
            let mut head = vec![0; 20];
            f.read_exact(&mut head).ok()?;
            let len = u32::from_le_bytes(head[12..16].try_into().ok()?) as u64;
            if &head[..4] != b"glTF" || len > MAX_JSON_BYTES {
                return None;
            }
            let mut json = Vec::new();
            f.take(len).read_to_end(&mut json).ok()?;
            return serde_json::from_slice(&json).ok();
        }
    };
    if bytes.starts_with(b"glTF") {
        let len = u32::from_le_bytes(bytes.get(12..16)?.try_into().ok()?) as usize;
        let chunk = bytes.get(20..20usize.checked_add(len)?)?;
        serde_json::from_slice(chunk).ok()
    } else {
        serde_json::from_slice(phantogram_files::text::strip_bom(std::str::from_utf8(&bytes).ok()?).as_bytes()).ok()
    }
}

/// The metadata of a model file, with the Voyager scene beside it filling gaps (the scene is
/// what a museum writes; the glTF's `asset` is often the exporter's).
pub fn of_model_file(path: &Path) -> Metadata {
    let from_gltf = gltf_json(path).map(|j| of_gltf_json(&j)).unwrap_or_default();
    let from_scene = path
        .parent()
        .map(|p| of_scene_file(&p.join("scene.svx.json")))
        .unwrap_or_default();
    from_scene.or(from_gltf)
}

/// The metadata of a Voyager scene file; none when it cannot be read.
pub fn of_scene_file(path: &Path) -> Metadata {
    phantogram_files::read_regular_file(path, MAX_JSON_BYTES)
        .ok()
        .and_then(|b| serde_json::from_slice::<Value>(&b).ok())
        .map(|j| of_voyager_scene(&j))
        .unwrap_or_default()
}

/// A readable title from a file or folder name: extension dropped, `_` and `-` as spaces, the
/// first letter upper-case ("sea_turtle-150k.glb" → "Sea turtle 150k").
pub fn title_from_name(name: &str) -> String {
    let lower = name.to_ascii_lowercase();
    // Two-part extensions first (a Voyager scene, a cloud-optimised LAZ), then any a model file
    // has (`is_model_name`), so that a format added there is never shown in a title.
    let stem = [".svx.json", ".copc.laz", ".zip"]
        .iter()
        .find(|e| lower.ends_with(*e))
        .map(|e| &name[..name.len() - e.len()])
        .or_else(|| {
            super::is_model_name(name)
                .then(|| name.rsplit_once('.').map(|(stem, _)| stem))
                .flatten()
        })
        .unwrap_or(name);
    let words: Vec<&str> = stem.split(['_', '-', ' ']).filter(|w| !w.is_empty()).collect();
    let joined = words.join(" ");
    let mut chars = joined.chars();
    match chars.next() {
        Some(c) => c.to_uppercase().chain(chars).collect(),
        None => "Untitled".to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gltf_asset_fields_and_extras_are_read() {
        let j: Value = serde_json::from_str(
            r#"{"asset":{"version":"2.0","copyright":"  (c) A Museum ","extras":{"title":"Bust","license":"CC0"}}}"#,
        )
        .unwrap();
        assert_eq!(
            of_gltf_json(&j),
            Metadata {
                title: Some("Bust".into()),
                credit: Some("(c) A Museum".into()),
                licence: Some("CC0".into())
            }
        );
        let bare: Value = serde_json::from_str(r#"{"asset":{"version":"2.0","extras":7}}"#).unwrap();
        assert_eq!(of_gltf_json(&bare), Metadata::default());
    }

    #[test]
    fn voyager_collections_and_copyright_are_read() {
        let j: Value = serde_json::from_str(
            r#"{"asset":{"copyright":"(c) Smithsonian"},"metas":[{"images":[]},{"collection":{"title":"Hawksbill","license":"CC0"}}]}"#,
        )
        .unwrap();
        let m = of_voyager_scene(&j);
        assert_eq!(m.title.as_deref(), Some("Hawksbill"));
        assert_eq!(m.credit.as_deref(), Some("(c) Smithsonian"));
        assert_eq!(m.licence.as_deref(), Some("CC0"));
    }

    #[test]
    fn long_titles_are_cut_and_names_become_titles() {
        let long = "x".repeat(500);
        let j: Value = serde_json::json!({"asset": {"extras": {"title": long}}});
        assert_eq!(of_gltf_json(&j).title.unwrap().chars().count(), 201);
        assert_eq!(title_from_name("sea_turtle-150k.glb"), "Sea turtle 150k");
        assert_eq!(title_from_name("bust_of_nefertiti.STL"), "Bust of nefertiti");
        assert_eq!(title_from_name("scan.obj"), "Scan");
        assert_eq!(title_from_name("émail.gltf"), "Émail");
        assert_eq!(title_from_name(".glb"), "Untitled");
        // Every format the library opens, scans included.
        assert_eq!(title_from_name("nave_scan.E57"), "Nave scan");
        assert_eq!(title_from_name("autzen.copc.laz"), "Autzen");
        assert_eq!(title_from_name("fresco-2024.las"), "Fresco 2024");
        assert_eq!(title_from_name("cloud.pts"), "Cloud");
        assert_eq!(title_from_name("museum.svx.json"), "Museum");
        // Not a model's extension: kept.
        assert_eq!(title_from_name("notes.txt"), "Notes.txt");
    }
}
