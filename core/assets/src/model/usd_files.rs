//! The files a USD stage may read, and the asset resolver that confines it to them.
//!
//! A USD layer names other files (sublayers, references, payloads, textures) by asset paths,
//! which the reader hands to a resolver. The `openusd` crate's default resolver would follow any
//! of them anywhere on the file system (an absolute path, `..`, the working directory), so a
//! downloaded file could read whatever the app may read. [`Confined`] resolves only:
//!
//! * in a **package** (`.usdz`, a zip of the root layer and its files): the package's own
//!   entries, unpacked in memory within the budget;
//! * beside a **loose layer** (`.usd`, `.usda`, `.usdc`): files in its folder and below, through
//!   [`resolve_inside`] (no scheme, no absolute path, no `..`, no link leading out), regular
//!   files only, each within the budget.
//!
//! Asset paths are taken relative to the layer that names them (its folder inside the package
//! or beside the root), `.` and `..` folded; one that would climb above the root resolves to
//! nothing, as a missing file does. Nested packages (`a.usdz[b.usdz]`) are not read.
//!
//! **Threading**: [`Files`] is shared (`Arc`) between the resolver, which the reader owns, and
//! the loader, which reads the textures after the stage is read. **Panics**: none.

use std::borrow::Cow;
use std::collections::HashMap;
use std::io::{Cursor, Read};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use openusd::ar;

use super::le_fields;
use super::loader::resolve_inside;

/// Most entries read from one package (an artifact's package holds a layer or two and a few
/// textures; this only bounds the work a hostile archive can ask for).
pub const MAX_PACKAGE_ENTRIES: usize = 4096;

/// How an asset path outside the files is named to the reader (a `[` is in no folded path).
const OUTSIDE: &str = "[outside the artifact's files]";

/// The zip signature a package begins with.
const ZIP_SIGNATURE: &[u8] = b"PK\x03\x04";

/// Where a stage's files come from.
#[derive(Debug)]
pub enum Files {
    /// A package's entries by their names in it.
    Package(HashMap<String, Vec<u8>>),
    /// The folder of a loose layer; the root layer's bytes, already read, under its name.
    Folder {
        folder: PathBuf,
        root: (String, Vec<u8>),
        memory_bytes: u64,
    },
}

/// Whether `bytes` are a USD package: a zip whose first entry is a USD layer, as the USDZ
/// specification requires (a zip of other things is not one).
pub fn is_package(bytes: &[u8]) -> bool {
    // The first local header: its name's length at bytes 26–28, the name from byte 30.
    let Some(name_len) = le_fields::u16_at(bytes, 26) else {
        return false;
    };
    bytes.starts_with(ZIP_SIGNATURE) && bytes.get(30..30 + usize::from(name_len)).is_some_and(is_layer_name)
}

/// Whether `bytes` are a USD layer alone: the binary format's magic or the text format's header.
pub fn is_layer(bytes: &[u8]) -> bool {
    bytes.starts_with(b"PXR-USDC") || bytes.starts_with(b"#usda ")
}

/// Whether a file name is a USD layer's.
fn is_layer_name(name: &[u8]) -> bool {
    let lower = name.to_ascii_lowercase();
    [&b".usd"[..], b".usda", b".usdc"].iter().any(|e| lower.ends_with(e))
}

impl Files {
    /// A package's entries (at most [`MAX_PACKAGE_ENTRIES`], at most `memory_bytes` inflated in
    /// all, counted as they inflate) and the name of its root layer (its first layer).
    pub fn unpack(bytes: &[u8], memory_bytes: u64) -> Result<(Files, String), String> {
        let mut archive = zip::ZipArchive::new(Cursor::new(bytes)).map_err(|e| format!("the package: {e}"))?;
        if archive.len() > MAX_PACKAGE_ENTRIES {
            return Err(format!(
                "the package has {} files; at most {MAX_PACKAGE_ENTRIES} are read",
                archive.len()
            ));
        }
        let mut entries = HashMap::new();
        let mut root = None;
        let mut left = memory_bytes;
        for i in 0..archive.len() {
            let mut entry = archive
                .by_index(i)
                .map_err(|e| format!("the package's file {i}: {e}"))?;
            if entry.is_dir() {
                continue;
            }
            let name = folded(&entry.name().unwrap_or_default()).unwrap_or_default();
            let mut data = Vec::new();
            // One byte more than is left tells a package over the budget from one exactly at it.
            (&mut entry)
                .take(left.saturating_add(1))
                .read_to_end(&mut data)
                .map_err(|e| format!("the package's file {name:.80}: {e}"))?;
            if data.len() as u64 > left {
                return Err(format!(
                    "the package unpacks to more than the {} MB an artifact may take",
                    memory_bytes >> 20
                ));
            }
            left -= data.len() as u64;
            if root.is_none() && is_layer_name(name.as_bytes()) {
                root = Some(name.clone());
            }
            if !name.is_empty() {
                entries.insert(name, data);
            }
        }
        let root = root.ok_or("the package holds no USD layer (.usd, .usda or .usdc)")?;
        Ok((Files::Package(entries), root))
    }

    /// The file `name` (a folded path, [`folded`]), or why it cannot be read: a package's entry
    /// lent, a file beside the layer read.
    pub fn read(&self, name: &str) -> Result<Cow<'_, [u8]>, String> {
        match self {
            Files::Package(entries) => entries
                .get(name)
                .map(|bytes| Cow::Borrowed(bytes.as_slice()))
                .ok_or_else(|| "is not in the package".to_owned()),
            Files::Folder {
                folder,
                root,
                memory_bytes,
            } => {
                if name == root.0 {
                    return Ok(Cow::Borrowed(&root.1));
                }
                let file = resolve_inside(folder, name)?;
                phantogram_files::read_regular_file(&file, *memory_bytes)
                    .map(Cow::Owned)
                    .map_err(|e| e.to_string())
            }
        }
    }

    /// Whether the file `name` exists (a folded path).
    fn has(&self, name: &str) -> bool {
        match self {
            Files::Package(entries) => entries.contains_key(name),
            Files::Folder { folder, root, .. } => {
                name == root.0 || resolve_inside(folder, name).is_ok_and(|file| file.is_file())
            }
        }
    }

    /// The names of the package's files (none for a folder, whose files are not listed).
    pub fn names(&self) -> Vec<&str> {
        match self {
            Files::Package(entries) => entries.keys().map(String::as_str).collect(),
            Files::Folder { .. } => Vec::new(),
        }
    }
}

/// `path` relative to the root with `.` and empty parts dropped and `..` taken back; `None`
/// where it is absolute, climbs above the root, names a package's inside (`a.usdz[b]`) or holds
/// a backslash or NUL.
pub fn folded(path: &str) -> Option<String> {
    if path.starts_with('/') || path.contains(['[', ']', '\\', '\0']) {
        return None;
    }
    let mut parts: Vec<&str> = Vec::new();
    for part in path.split('/') {
        match part {
            "" | "." => {}
            ".." => {
                parts.pop()?;
            }
            part => parts.push(part),
        }
    }
    Some(parts.join("/"))
}

/// `asset` named by the layer (or file) `anchor`: relative to `anchor`'s folder, folded.
pub fn anchored(asset: &str, anchor: Option<&str>) -> Option<String> {
    let folder = anchor.and_then(|a| a.rsplit_once('/')).map_or("", |(folder, _)| folder);
    let asset = asset.strip_prefix("./").unwrap_or(asset);
    if folder.is_empty() {
        folded(asset)
    } else {
        folded(&format!("{folder}/{asset}"))
    }
}

/// The resolver that reads only [`Files`] (module docs).
pub struct Confined(pub Arc<Files>);

impl ar::Resolver for Confined {
    fn create_identifier(&self, asset_path: &str, anchor: Option<&ar::ResolvedPath>) -> String {
        // No asset path: the naming layer itself (an internal reference), as USD reads it.
        if asset_path.is_empty() {
            return String::new();
        }
        let anchor = anchor.map(|a| a.to_string_lossy().into_owned());
        // Outside the files: an identifier that no file has and that [`folded`] refuses (not the
        // empty one, which USD reads as the naming layer itself), naming what was asked for.
        anchored(asset_path, anchor.as_deref())
            .filter(|name| !name.is_empty())
            .unwrap_or_else(|| format!("{OUTSIDE} {asset_path}"))
    }

    fn resolve(&self, asset_path: &str) -> Option<ar::ResolvedPath> {
        let name = folded(asset_path)?;
        (!name.is_empty() && self.0.has(&name)).then(|| ar::ResolvedPath::new(name))
    }

    fn resolve_for_new_asset(&self, _asset_path: &str) -> Option<ar::ResolvedPath> {
        // The loader never writes.
        None
    }

    fn open_asset(&self, resolved_path: &ar::ResolvedPath) -> std::io::Result<Box<dyn ar::Asset>> {
        let name = resolved_path.to_string_lossy();
        self.0
            .read(&name)
            // The reader owns what it reads.
            .map(|bytes| Box::new(Cursor::new(bytes.into_owned())) as Box<dyn ar::Asset>)
            .map_err(|message| std::io::Error::new(std::io::ErrorKind::NotFound, format!("{name:.80} {message}")))
    }

    fn get_modification_timestamp(
        &self,
        _asset_path: &str,
        _resolved_path: &ar::ResolvedPath,
    ) -> Option<std::time::SystemTime> {
        None
    }

    fn identity(&self) -> String {
        "phantogram-confined".to_owned()
    }
}

/// The folder a loose layer's files are read from: its own.
pub fn folder_of(path: &Path) -> PathBuf {
    path.parent().map_or_else(|| PathBuf::from("."), Path::to_path_buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_are_folded_inside_the_root_and_anchored_at_the_layer_naming_them() {
        assert_eq!(folded("a/./b//c.png").as_deref(), Some("a/b/c.png"));
        assert_eq!(folded("a/../b.png").as_deref(), Some("b.png"));
        assert_eq!(folded("../b.png"), None);
        assert_eq!(folded("a/../../b.png"), None);
        assert_eq!(folded("/etc/passwd"), None);
        assert_eq!(folded("pkg.usdz[inner.usdc]"), None);
        assert_eq!(folded("a\\b"), None);
        assert_eq!(anchored("tex.png", Some("0/knob.usda")).as_deref(), Some("0/tex.png"));
        assert_eq!(
            anchored("../1/tex.png", Some("0/knob.usda")).as_deref(),
            Some("1/tex.png")
        );
        assert_eq!(anchored("./tex.png", Some("root.usdc")).as_deref(), Some("tex.png"));
        assert_eq!(anchored("../tex.png", Some("root.usdc")), None);
        assert_eq!(anchored("tex.png", None).as_deref(), Some("tex.png"));
    }

    #[test]
    fn a_package_is_a_zip_whose_first_file_is_a_layer() {
        let zip = |name: &str| {
            let mut out = Cursor::new(Vec::new());
            let mut writer = zip::ZipWriter::new(&mut out);
            let stored = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
            writer.start_file(name, stored).unwrap();
            std::io::Write::write_all(&mut writer, b"#usda 1.0\n").unwrap();
            writer.finish().unwrap();
            out.into_inner()
        };
        assert!(is_package(&zip("scene.usdc")));
        assert!(is_package(&zip("Scene.USDA")));
        assert!(!is_package(&zip("scene.svx.json")));
        assert!(!is_package(b"PK\x03\x04"));
        assert!(is_layer(b"PXR-USDC\x00\x08"));
        assert!(is_layer(b"#usda 1.0\n"));
        assert!(!is_layer(b"#usd"));
        let (files, root) = Files::unpack(&zip("scene.usda"), 1 << 20).unwrap();
        assert_eq!(root, "scene.usda");
        assert_eq!(files.read("scene.usda").unwrap().as_ref(), b"#usda 1.0\n");
        assert!(files.read("other.usda").is_err());
        // Over the budget as it inflates.
        assert!(Files::unpack(&zip("scene.usda"), 4).unwrap_err().contains("more than"));
    }

    #[test]
    fn the_resolver_reads_only_the_files_it_was_given() {
        let mut entries = HashMap::new();
        entries.insert("root.usda".to_owned(), b"#usda 1.0\n".to_vec());
        entries.insert("0/part.usda".to_owned(), b"#usda 1.0\n".to_vec());
        let resolver = Confined(Arc::new(Files::Package(entries)));
        use ar::Resolver;
        let root = ar::ResolvedPath::new("root.usda");
        let id = resolver.create_identifier("0/part.usda", Some(&root));
        assert_eq!(id, "0/part.usda");
        assert!(resolver.resolve(&id).is_some());
        let outside = resolver.create_identifier("/etc/passwd", Some(&root));
        assert_eq!(outside, format!("{OUTSIDE} /etc/passwd"));
        assert!(resolver.resolve(&outside).is_none());
        // Not the empty identifier, which USD reads as the naming layer itself.
        assert!(!resolver.create_identifier("a/..", Some(&root)).is_empty());
        let climbing = resolver.create_identifier("../../etc/passwd", Some(&root));
        assert!(resolver.resolve(&climbing).is_none());
        assert!(resolver.open_asset(&ar::ResolvedPath::new("/etc/passwd")).is_err());
    }
}
