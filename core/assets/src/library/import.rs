//! Turning bytes the user opened (a file picker's document, an "Open with" intent, a share) into a
//! folder of the library: a `.glb`, a self-contained `.gltf`, a USD package (`.usdz`, kept whole:
//! it is a zip, but one model) or layer, an `.stl`, `.ply` or `.obj` scan,
//! a point cloud as text (`.xyz`, `.pts`) or a laser scan (`.las`, `.laz`, `.e57`),
//! or a zip holding one of those (an OBJ with its materials and textures comes as one) or a
//! Smithsonian Voyager download (`scene.svx.json` beside its scans).
//!
//! Zip archives are unpacked with the same care as any file from outside: names only inside the
//! folder (`..`, absolute paths and links are refused), at most [`MAX_ZIP_ENTRIES`] entries, and
//! no more bytes written than the budget's memory — counted as they are inflated, not as the
//! archive claims, so a zip bomb stops at the budget.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use super::LibraryError;
use crate::model::MeshFormat;

/// Most entries unpacked from one archive (a Voyager download has a dozen).
pub const MAX_ZIP_ENTRIES: usize = 4096;

/// What an opened file's bytes are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Glb,
    GltfJson,
    Zip,
    /// USD, STL, PLY, OBJ, a point cloud as text, or a LAS/LAZ or E57 scan.
    Mesh(MeshFormat),
}

/// Recognises a file by its first bytes (names lie: shares often arrive as `document.bin`).
pub fn sniff(bytes: &[u8]) -> Option<Format> {
    if bytes.starts_with(b"glTF") {
        return Some(Format::Glb);
    }
    // A USD package is a zip whose first file is a USD layer: one model, kept whole.
    if let Some(usd @ MeshFormat::Usdz) = MeshFormat::sniff(bytes) {
        return Some(Format::Mesh(usd));
    }
    if bytes.starts_with(b"PK\x03\x04") || bytes.starts_with(b"PK\x05\x06") {
        return Some(Format::Zip);
    }
    let text = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let first = text.iter().find(|b| !b.is_ascii_whitespace());
    if first == Some(&b'{') {
        return Some(Format::GltfJson);
    }
    MeshFormat::sniff(bytes).map(Format::Mesh)
}

/// Writes `bytes` as one model file `stem` in `folder`, with its format's extension.
pub fn write_single(folder: &Path, stem: &str, format: Format, bytes: &[u8]) -> Result<PathBuf, LibraryError> {
    let extension = match format {
        Format::Glb => "glb",
        Format::Mesh(mesh) => mesh.extension(),
        _ => "gltf",
    };
    let path = folder.join(format!("{stem}.{extension}"));
    std::fs::write(&path, bytes).map_err(|error| LibraryError::io(&path, error))?;
    Ok(path)
}

/// Unpacks a zip archive into `folder` (see the module docs for the limits).
pub fn unzip(folder: &Path, bytes: &[u8], max_bytes: u64, source: &str) -> Result<(), LibraryError> {
    let bad = |message: String| LibraryError::Archive {
        name: source.to_owned(),
        message,
    };
    let mut archive = zip::ZipArchive::new(std::io::Cursor::new(bytes)).map_err(|e| bad(e.to_string()))?;
    if archive.len() > MAX_ZIP_ENTRIES {
        return Err(bad(format!(
            "{} entries; at most {MAX_ZIP_ENTRIES} are unpacked",
            archive.len()
        )));
    }
    let mut left = max_bytes;
    for i in 0..archive.len() {
        let mut entry = archive.by_index(i).map_err(|e| bad(e.to_string()))?;
        if entry.is_dir() || entry.is_symlink() {
            continue;
        }
        let Some(name) = entry.enclosed_name() else {
            return Err(bad(format!(
                "entry {} ({}) names a place outside the archive's folder",
                i,
                phantogram_files::text::excerpt(&entry.name().unwrap_or_default())
            )));
        };
        // macOS's resource forks are not part of the download.
        if name.components().any(|c| c.as_os_str() == "__MACOSX") {
            continue;
        }
        let path = folder.join(&name);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|error| LibraryError::io(parent, error))?;
        }
        let mut out = std::fs::File::create(&path).map_err(|error| LibraryError::io(&path, error))?;
        // One byte more than is left tells an archive over the budget from one exactly at it.
        let mut limited = (&mut entry).take(left.saturating_add(1));
        let written = copy(&mut limited, &mut out).map_err(|e| bad(format!("{}: {e}", name.display())))?;
        if written > left {
            return Err(LibraryError::TooLarge {
                name: source.to_owned(),
                max_bytes,
            });
        }
        left -= written;
    }
    Ok(())
}

/// `std::io::copy`, with the write errors told apart from the archive's read errors by message.
fn copy(from: &mut impl Read, to: &mut std::fs::File) -> std::io::Result<u64> {
    let mut buf = vec![0u8; 64 << 10];
    let mut total = 0u64;
    loop {
        let n = from.read(&mut buf)?;
        if n == 0 {
            break;
        }
        to.write_all(&buf[..n])
            .map_err(|e| std::io::Error::new(e.kind(), format!("writing: {e}")))?;
        total += n as u64;
    }
    to.sync_all()?;
    Ok(total)
}

/// The model an unpacked folder holds: the shallowest Voyager scene's folder, else its only
/// `.glb`/`.gltf`/`.usdz`/`.usd(a|c)`/`.stl`/`.ply`/`.obj`/`.xyz`/`.pts`/`.las`/`.laz`/`.e57` file, else one of the variants of one glTF
/// model laid out as the Khronos samples are ([`khronos_variant`]).
pub fn find_model(folder: &Path, source: &str) -> Result<PathBuf, LibraryError> {
    let mut scenes = Vec::new();
    let mut models = Vec::new();
    let mut stack = vec![(folder.to_path_buf(), 0usize)];
    while let Some((dir, depth)) = stack.pop() {
        let entries = std::fs::read_dir(&dir).map_err(|error| LibraryError::io(&dir, error))?;
        for entry in entries.flatten() {
            let path = entry.path();
            let Ok(kind) = entry.file_type() else { continue };
            let name = entry.file_name().to_string_lossy().to_ascii_lowercase();
            if kind.is_dir() && depth < 8 {
                stack.push((path, depth + 1));
            } else if kind.is_file() && name.ends_with(".svx.json") {
                scenes.push((depth, path));
            } else if kind.is_file() && super::is_model_name(&name) {
                models.push(path);
            }
        }
    }
    scenes.sort();
    if let Some((_, scene)) = scenes.into_iter().next() {
        // The scene's folder: the loader picks its best scan present.
        return Ok(scene.parent().unwrap_or(folder).to_path_buf());
    }
    if let Some(variant) = khronos_variant(&models) {
        return Ok(variant);
    }
    if let Some(root) = usd_root(&models, folder) {
        return Ok(root);
    }
    match models.len() {
        1 => Ok(models.remove(0)),
        0 => Err(LibraryError::NoModel {
            name: source.to_owned(),
        }),
        _ => {
            let mut names: Vec<String> = models
                .iter()
                .filter_map(|p| p.strip_prefix(folder).ok())
                .map(|p| p.display().to_string())
                .collect();
            names.sort();
            Err(LibraryError::SeveralModels {
                name: source.to_owned(),
                models: names,
            })
        }
    }
}

/// Where `models` are all loose USD layers (`.usd`, `.usda`, `.usdc`) and one of them lies higher
/// in `folder` than the others: that one, the stage's root (an exporter puts the layers it
/// references beside or below it). `None` otherwise.
fn usd_root(models: &[PathBuf], folder: &Path) -> Option<PathBuf> {
    let is_layer = |p: &Path| matches!(MeshFormat::of(p), Some(MeshFormat::Usd));
    if models.len() < 2 || !models.iter().all(|p| is_layer(p)) {
        return None;
    }
    let depth = |p: &Path| p.strip_prefix(folder).map_or(usize::MAX, |r| r.components().count());
    let top = models.iter().map(|p| depth(p)).min()?;
    match models.iter().filter(|p| depth(p) == top).collect::<Vec<_>>().as_slice() {
        [root] => Some((*root).clone()),
        _ => None,
    }
}

/// Variant folders of the Khronos glTF samples, most preferred first: one file, then the plain
/// JSON and its buffers, then buffers inlined. Others (`glTF-Draco`, `glTF-Quantized`,
/// `glTF-KTX-BasisU`, …) come after these, by name.
const PREFERRED_VARIANTS: [&str; 3] = ["gltf-binary", "gltf", "gltf-embedded"];

/// Where `models` are all the same glTF model in the Khronos samples' variant folders (each a
/// `.glb`/`.gltf` of one file name, in a folder named `glTF` or `glTF-…`, the folders side by
/// side): the preferred variant. `None` for anything else (two different models stay an error).
fn khronos_variant(models: &[PathBuf]) -> Option<PathBuf> {
    let first = models.first()?;
    let stem = |p: &Path| p.file_stem().map(|s| s.to_string_lossy().to_ascii_lowercase());
    let folder = |p: &Path| {
        p.parent()
            .and_then(Path::file_name)
            .map(|f| f.to_string_lossy().to_ascii_lowercase())
    };
    let grandparent = |p: &Path| p.parent().and_then(Path::parent).map(Path::to_path_buf);
    let is_gltf = |p: &Path| {
        let name = p.to_string_lossy().to_ascii_lowercase();
        name.ends_with(".glb") || name.ends_with(".gltf")
    };
    let variant = |p: &Path| folder(p).filter(|f| f == "gltf" || f.starts_with("gltf-"));
    let same = models.len() > 1
        && models.iter().all(|m| {
            is_gltf(m) && variant(m).is_some() && stem(m) == stem(first) && grandparent(m) == grandparent(first)
        });
    if !same {
        return None;
    }
    models
        .iter()
        .min_by_key(|m| {
            let name = variant(m).unwrap_or_default();
            let rank = PREFERRED_VARIANTS
                .iter()
                .position(|v| *v == name)
                .unwrap_or(PREFERRED_VARIANTS.len());
            (rank, name)
        })
        .cloned()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether `folder` is refused as holding several models.
    fn several_models(folder: &Path) -> bool {
        matches!(find_model(folder, "folder"), Err(LibraryError::SeveralModels { .. }))
    }

    /// Writes `bytes` at `path`, making its folders.
    fn write_file(path: &Path, bytes: &[u8]) {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, bytes).unwrap();
    }

    /// A Khronos sample's folder (Box: glTF, glTF-Binary, glTF-Draco) gives its binary variant;
    /// without it, the plain one; two different models, or a variant beside an unrelated model,
    /// stay an error.
    #[test]
    fn a_khronos_samples_variants_give_one_model() {
        let dir = phantogram_testkit::Scratch::new("khronos-variants");
        let write = |rel: &str| write_file(&dir.join(rel), b"{}");
        write("Box/glTF/Box.gltf");
        write("Box/glTF/Box0.bin");
        write("Box/glTF-Draco/Box.gltf");
        write("Box/glTF-Binary/Box.glb");
        write("Box/screenshot/screenshot.png");
        let found = find_model(&dir.join("Box"), "Box").unwrap();
        assert!(found.ends_with("glTF-Binary/Box.glb"), "{}", found.display());
        std::fs::remove_file(dir.join("Box/glTF-Binary/Box.glb")).unwrap();
        let found = find_model(&dir.join("Box"), "Box").unwrap();
        assert!(found.ends_with("glTF/Box.gltf"), "{}", found.display());
        write("Box/glTF/Other.gltf");
        assert!(several_models(&dir.join("Box")));
        write("Two/a/Box.gltf");
        write("Two/b/Box.gltf");
        assert!(several_models(&dir.join("Two")));
    }

    /// A loose USD stage with its parts below it gives its root; two roots side by side, or a
    /// layer beside another kind of model, stay an error.
    #[test]
    fn a_usd_stages_root_is_its_model() {
        let dir = phantogram_testkit::Scratch::new("usd-root");
        let write = |rel: &str| write_file(&dir.join(rel), b"#usda 1.0\n");
        write("Stage/scene.usdc");
        write("Stage/parts/knob.usda");
        write("Stage/parts/base.usd");
        let found = find_model(&dir.join("Stage"), "Stage").unwrap();
        assert!(found.ends_with("Stage/scene.usdc"), "{}", found.display());
        write("Stage/other.usda");
        assert!(several_models(&dir.join("Stage")));
        write("Mixed/scene.usda");
        write("Mixed/parts/scan.ply");
        assert!(several_models(&dir.join("Mixed")));
    }

    #[test]
    fn formats_are_told_by_their_first_bytes() {
        assert_eq!(sniff(b"glTF\x02\0\0\0"), Some(Format::Glb));
        assert_eq!(sniff(b"PK\x03\x04rest"), Some(Format::Zip));
        // A zip whose first file is a USD layer is a USD package, one model.
        let mut usdz = b"PK\x03\x04".to_vec();
        usdz.resize(26, 0);
        usdz.extend_from_slice(&10u16.to_le_bytes());
        usdz.extend_from_slice(&[0, 0]);
        usdz.extend_from_slice(b"scene.usdc");
        assert_eq!(sniff(&usdz), Some(Format::Mesh(MeshFormat::Usdz)));
        assert_eq!(sniff(b"PXR-USDC\x00\x08"), Some(Format::Mesh(MeshFormat::Usd)));
        assert_eq!(sniff(b"#usda 1.0\n"), Some(Format::Mesh(MeshFormat::Usd)));
        assert_eq!(sniff(b"\xEF\xBB\xBF \n {\"asset\":{}}"), Some(Format::GltfJson));
        assert_eq!(sniff(b"\x89PNG\r\n"), None);
        assert_eq!(sniff(b""), None);
    }
}
