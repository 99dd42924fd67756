//! The prepared parts and levels of a big scan, kept on disk so that opening it again takes a
//! fraction of a second instead of seconds of simplification.
//!
//! What is kept is the recipe, not the meshes: for each primitive [`crate::prepare`] made, the
//! source primitive, the source triangles of a part and its levels' indices with their errors.
//! The meshes are cut again from the loaded model, which is cheap. A file is named by a 64-bit
//! key hashed from everything the recipe depends on — every vertex's bytes, the indices,
//! materials and floors of the model as it is placed, the parameters, this format's version and
//! the simplifier's — so a changed model, placement or parameter simply misses.
//!
//! Files: `<key as 16 hex digits>.pgdetail` in one folder (the library's, in the app's private
//! storage), written whole or not at all (`AtomicFile`), the newest [`KEEP_FILES`] kept. A file
//! is checked before it is used — magic, version, key, length, a checksum of its contents, and
//! every index against the meshes it applies to — and anything wrong means a rebuild, never a
//! wrong picture or a panic.

use std::io::Write;
use std::path::{Path, PathBuf};

use phantogram_assets::model::{Lod, Model};

use crate::DetailParams;

/// How many cache files are kept (the newest); each is about 8 bytes per triangle.
pub const KEEP_FILES: usize = 8;

const MAGIC: &[u8; 8] = b"PGDETAIL";
/// This format's version; also changes when the recipe's meaning does (the simplifier's
/// options, the level ratio).
const VERSION: u32 = 1;
/// The simplifier whose levels are kept (a new meshoptimizer may simplify differently).
const SIMPLIFIER: &str = "meshopt 0.7";

/// One primitive of the prepared model.
#[derive(Clone, Debug, PartialEq)]
pub enum Item {
    /// The source primitive as it was (the floor, a small primitive).
    Kept { source: u32 },
    /// A part of the source primitive: its triangles (ascending) and levels.
    Part {
        source: u32,
        triangles: Vec<u32>,
        lods: Vec<Lod>,
    },
}

/// How a model's primitives were prepared, in order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Recipe {
    pub items: Vec<Item>,
}

/// FNV-1a over 64-bit words: deterministic across runs, platforms and Rust versions (the key
/// names files that outlive the process).
#[derive(Clone, Copy)]
struct Fnv(u64);

impl Fnv {
    fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
    fn word(&mut self, w: u64) {
        self.0 = (self.0 ^ w).wrapping_mul(0x0000_0100_0000_01b3);
    }
    fn bytes(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            self.word(u64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]));
        }
        let rest = chunks.remainder();
        let mut last = [0u8; 8];
        last[..rest.len()].copy_from_slice(rest);
        self.word(u64::from_le_bytes(last) ^ ((rest.len() as u64) << 56));
        self.word(bytes.len() as u64);
    }
}

/// The key of `model` prepared with `params` (see the module docs).
pub fn key(model: &Model, params: &DetailParams) -> u64 {
    let mut h = Fnv::new();
    h.bytes(MAGIC);
    h.word(u64::from(VERSION));
    h.bytes(SIMPLIFIER.as_bytes());
    for v in [
        params.min_model_triangles,
        params.part_triangles,
        params.coarsest_triangles,
    ] {
        h.word(v as u64);
    }
    h.word(model.primitives.len() as u64);
    for p in &model.primitives {
        h.bytes(bytemuck::cast_slice(&p.mesh.vertices));
        h.bytes(bytemuck::cast_slice(&p.mesh.indices));
        h.word(p.material as u64);
        h.word(u64::from(p.is_floor));
    }
    h.0
}

/// The file a key names in `dir`.
pub fn path(dir: &Path, key: u64) -> PathBuf {
    dir.join(format!("{key:016x}.pgdetail"))
}

/// The recipe kept for `key` in `dir`, if there is a sound one. `max_bytes` bounds what is read
/// (the model's size sets it).
pub fn load(dir: &Path, key: u64, max_bytes: u64) -> Option<Recipe> {
    let file = path(dir, key);
    let bytes = phantogram_files::read_regular_file(&file, max_bytes).ok()?;
    let recipe = decode(&bytes, key)?;
    // Used now: the newest to keep when the folder is pruned.
    if let Ok(f) = std::fs::OpenOptions::new().write(true).open(&file) {
        let _ = f.set_modified(std::time::SystemTime::now());
    }
    Some(recipe)
}

/// Keeps `recipe` for `key` in `dir` (made if missing), then removes all but the newest
/// [`KEEP_FILES`] cache files there.
pub fn store(dir: &Path, key: u64, recipe: &Recipe) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let mut file = phantogram_files::AtomicFile::create(&path(dir, key))?;
    file.file().write_all(&encode(recipe, key))?;
    file.commit()?;
    prune(dir);
    Ok(())
}

fn prune(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut files: Vec<(std::time::SystemTime, PathBuf)> = entries
        .filter_map(Result::ok)
        .filter(|e| e.path().extension().is_some_and(|x| x == "pgdetail"))
        .filter_map(|e| Some((e.metadata().ok()?.modified().ok()?, e.path())))
        .collect();
    files.sort_by_key(|f| std::cmp::Reverse(f.0));
    for (_, old) in files.into_iter().skip(KEEP_FILES) {
        let _ = std::fs::remove_file(old);
    }
}

fn encode(recipe: &Recipe, key: u64) -> Vec<u8> {
    let mut body = Vec::new();
    let u32s = |out: &mut Vec<u8>, v: &[u32]| {
        out.extend_from_slice(&(v.len() as u32).to_le_bytes());
        out.extend_from_slice(bytemuck::cast_slice(v));
    };
    body.extend_from_slice(&(recipe.items.len() as u32).to_le_bytes());
    for item in &recipe.items {
        match item {
            Item::Kept { source } => {
                body.push(0);
                body.extend_from_slice(&source.to_le_bytes());
            }
            Item::Part {
                source,
                triangles,
                lods,
            } => {
                body.push(1);
                body.extend_from_slice(&source.to_le_bytes());
                u32s(&mut body, triangles);
                body.extend_from_slice(&(lods.len() as u32).to_le_bytes());
                for lod in lods {
                    body.extend_from_slice(&lod.error_m.to_le_bytes());
                    u32s(&mut body, &lod.indices);
                }
            }
        }
    }
    let mut sum = Fnv::new();
    sum.bytes(&body);
    let mut out = Vec::with_capacity(body.len() + 36);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&key.to_le_bytes());
    out.extend_from_slice(&(body.len() as u64).to_le_bytes());
    out.extend_from_slice(&sum.0.to_le_bytes());
    out.extend_from_slice(&body);
    out
}

/// A cursor over little-endian fields; every read checks what is left.
struct Reader<'a>(&'a [u8]);

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Option<&[u8]> {
        if self.0.len() < n {
            return None;
        }
        let (a, b) = self.0.split_at(n);
        self.0 = b;
        Some(a)
    }
    fn u8(&mut self) -> Option<u8> {
        Some(self.take(1)?[0])
    }
    fn u32(&mut self) -> Option<u32> {
        Some(u32::from_le_bytes(self.take(4)?.try_into().ok()?))
    }
    fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }
    fn f32(&mut self) -> Option<f32> {
        Some(f32::from_le_bytes(self.take(4)?.try_into().ok()?))
    }
    fn u32s(&mut self) -> Option<Vec<u32>> {
        let n = self.u32()? as usize;
        let bytes = self.take(n.checked_mul(4)?)?;
        Some(
            bytes
                .chunks_exact(4)
                .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect(),
        )
    }
}

fn decode(bytes: &[u8], key: u64) -> Option<Recipe> {
    let mut r = Reader(bytes);
    if r.take(8)? != MAGIC || r.u32()? != VERSION || r.u64()? != key {
        return None;
    }
    let len = usize::try_from(r.u64()?).ok()?;
    let sum = r.u64()?;
    if r.0.len() != len {
        return None;
    }
    let mut check = Fnv::new();
    check.bytes(r.0);
    if check.0 != sum {
        return None;
    }
    let n = r.u32()? as usize;
    // Every item takes at least 5 bytes: a count past what the file holds is damage.
    if n > r.0.len() / 5 {
        return None;
    }
    let mut items = Vec::with_capacity(n);
    for _ in 0..n {
        let item = match r.u8()? {
            0 => Item::Kept { source: r.u32()? },
            1 => {
                let source = r.u32()?;
                let triangles = r.u32s()?;
                let levels = r.u32()? as usize;
                if levels > r.0.len() / 8 {
                    return None;
                }
                let mut lods = Vec::with_capacity(levels);
                for _ in 0..levels {
                    let error_m = r.f32()?;
                    let indices = r.u32s()?;
                    lods.push(Lod { indices, error_m });
                }
                Item::Part {
                    source,
                    triangles,
                    lods,
                }
            }
            _ => return None,
        };
        items.push(item);
    }
    r.0.is_empty().then_some(Recipe { items })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn recipe() -> Recipe {
        Recipe {
            items: vec![
                Item::Kept { source: 1 },
                Item::Part {
                    source: 0,
                    triangles: vec![0, 2, 5],
                    lods: vec![Lod {
                        indices: vec![0, 1, 2],
                        error_m: 0.25,
                    }],
                },
            ],
        }
    }

    #[test]
    fn a_recipe_reads_back_as_written_and_damage_is_refused() {
        let bytes = encode(&recipe(), 42);
        assert_eq!(decode(&bytes, 42), Some(recipe()));
        assert_eq!(decode(&bytes, 43), None, "another key");
        for cut in [0, 8, 20, 35, bytes.len() - 1] {
            assert_eq!(decode(&bytes[..cut], 42), None, "cut at {cut}");
        }
        for flip in 0..bytes.len() {
            let mut damaged = bytes.clone();
            damaged[flip] ^= 0x10;
            assert_eq!(decode(&damaged, 42), None, "byte {flip} flipped");
        }
    }

    #[test]
    fn store_and_load_through_a_folder_keep_only_the_newest() {
        let dir = std::env::temp_dir().join(format!("phantogram-detail-cache-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        for k in 0..(KEEP_FILES as u64 + 3) {
            store(&dir, k, &recipe()).unwrap();
        }
        let files = std::fs::read_dir(&dir).unwrap().count();
        assert_eq!(files, KEEP_FILES);
        let newest = KEEP_FILES as u64 + 2;
        assert_eq!(load(&dir, newest, 1 << 20), Some(recipe()));
        assert_eq!(load(&dir, newest, 8), None, "over the size bound");
        assert_eq!(load(&dir, 999, 1 << 20), None, "missing");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
