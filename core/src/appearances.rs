//! The material screen's changes, remembered per artifact: an [`Appearance`] per artifact id
//! (the library's id, or `file:NAME` for a model opened from the command line), kept in
//! `<library>/appearances.json` so that a visitor's glaze is still there next time.
//!
//! **Errors**: a missing store is empty; a damaged one is set aside (renamed `.damaged`) with a
//! warning and starts empty, never blocking the app; writing is atomic (the old file stays whole
//! when the disk is full). **Threading**: owned by the engine, used on its thread.

use std::collections::BTreeMap;
use std::path::PathBuf;

use phantogram_assets::appearance::Appearance;

/// The largest store read: a few hundred bytes per artifact, so 1 MiB is thousands of them.
const MAX_STORE_BYTES: u64 = 1 << 20;

#[derive(Debug, Default)]
pub struct AppearanceStore {
    path: Option<PathBuf>,
    by_artifact: BTreeMap<String, Appearance>,
}

impl AppearanceStore {
    /// The store at `path` (`None`: kept in memory only). Returns a warning when a file was
    /// there but could not be used.
    pub fn open(path: Option<PathBuf>) -> (Self, Option<String>) {
        let mut store = Self {
            path,
            by_artifact: BTreeMap::new(),
        };
        let Some(path) = store.path.clone() else {
            return (store, None);
        };
        let bytes = match phantogram_files::read_regular_file(&path, MAX_STORE_BYTES) {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return (store, None),
            Err(e) => {
                return (
                    store,
                    Some(format!("{}: {e}; material changes start afresh", path.display())),
                );
            }
        };
        match serde_json::from_slice::<serde_json::Value>(&bytes) {
            Ok(serde_json::Value::Object(map)) => {
                for (id, v) in map {
                    let a = Appearance::from_json(&v);
                    if !a.is_default() {
                        store.by_artifact.insert(id, a);
                    }
                }
                (store, None)
            }
            _ => {
                let aside = path.with_extension("json.damaged");
                let _ = std::fs::rename(&path, &aside);
                (
                    store,
                    Some(format!(
                        "{} was damaged (set aside as {}); material changes start afresh",
                        path.display(),
                        aside.display()
                    )),
                )
            }
        }
    }

    /// The artifact's appearance (the default when it was never changed).
    pub fn get(&self, artifact: &str) -> Appearance {
        self.by_artifact.get(artifact).copied().unwrap_or_default()
    }

    /// Remembers `appearance` for the artifact (forgets it when default) and writes the store.
    pub fn set(&mut self, artifact: &str, appearance: Appearance) -> std::io::Result<()> {
        let a = appearance.sanitised();
        if a.is_default() {
            self.by_artifact.remove(artifact);
        } else {
            self.by_artifact.insert(artifact.to_owned(), a);
        }
        let Some(path) = &self.path else { return Ok(()) };
        let json = serde_json::Value::Object(
            self.by_artifact
                .iter()
                .map(|(id, a)| (id.clone(), a.to_json()))
                .collect(),
        );
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)?;
        }
        let mut file = phantogram_files::AtomicFile::create(path)?;
        serde_json::to_writer_pretty(file.file(), &json).map_err(std::io::Error::other)?;
        file.commit()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use phantogram_assets::ward::WardPreset;

    #[test]
    fn changes_are_kept_per_artifact_across_opens_and_junk_is_set_aside() {
        let dir = phantogram_testkit::Scratch::new("appearances");
        let path = dir.join("library").join("appearances.json");
        let (mut store, warning) = AppearanceStore::open(Some(path.clone()));
        assert!(warning.is_none());
        let glazed = Appearance::preset(WardPreset::Glazed);
        store.set("builtin:amphora", glazed).expect("write");
        store.set("builtin:medal", Appearance::default()).expect("write");
        let (again, _) = AppearanceStore::open(Some(path.clone()));
        assert_eq!(again.get("builtin:amphora"), glazed);
        assert!(again.get("builtin:medal").is_default());
        assert!(again.get("imported:unknown").is_default());
        // Back to default: forgotten.
        let mut again = again;
        again.set("builtin:amphora", Appearance::default()).expect("write");
        assert!(
            AppearanceStore::open(Some(path.clone()))
                .0
                .get("builtin:amphora")
                .is_default()
        );
        // A damaged file: empty store, a warning, the file set aside.
        std::fs::write(&path, b"{not json").expect("write junk");
        let (fresh, warning) = AppearanceStore::open(Some(path.clone()));
        assert!(warning.expect("warned").contains("damaged"));
        assert!(fresh.get("builtin:amphora").is_default());
        assert!(path.with_extension("json.damaged").exists());
        // In memory only.
        let (mut memory, _) = AppearanceStore::open(None);
        memory.set("x", glazed).expect("no file to write");
        assert_eq!(memory.get("x"), glazed);
    }
}
