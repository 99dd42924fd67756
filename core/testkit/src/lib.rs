//! Scratch folders, a small valid GLB, the process's resident memory and a counting allocator
//! ([`heap`]) for tests: the crates' unit tests, the CLI tests and the workspace's
//! integration tests share this one piece, as a dev-dependency only: no library writes temporary
//! files.
//!
//! Each folder is unique to the process and a name, emptied when made, and removed when
//! dropped, unless the thread is panicking: a failing test keeps its files for inspection and
//! says where, a passing one leaves nothing in the temporary folder.

use std::path::{Path, PathBuf};

pub mod heap;

pub struct Scratch(PathBuf);

impl Scratch {
    /// `phantogram-NAME-PID` in the temporary folder, empty. Panics if it cannot be made (tests
    /// only).
    pub fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("phantogram-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create scratch folder");
        Self(dir)
    }
}

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if std::thread::panicking() {
            eprintln!("kept {} for inspection", self.0.display());
        } else {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// A small valid GLB for tests: a tetrahedron `size_m` across (unindexed, positions only), with
/// `asset_extra` spliced into its `asset` object (e.g. `"copyright":"A museum"`; empty for none).
/// Different sizes give different files.
pub fn tetrahedron_glb(size_m: f32, asset_extra: &str) -> Vec<u8> {
    let s = size_m;
    let [a, b, c, d] = [[0.0, 0.0, 0.0], [s, 0.0, 0.0], [0.0, s, 0.0], [0.0, 0.0, s]];
    // Counter-clockwise from outside.
    let triangles = [[a, c, b], [a, b, d], [a, d, c], [b, c, d]];
    let mut bin = Vec::new();
    for p in triangles.iter().flatten().flatten() {
        bin.extend_from_slice(&f32::to_le_bytes(*p));
    }
    let sep = if asset_extra.is_empty() { "" } else { "," };
    let json = format!(
        concat!(
            r#"{{"asset":{{"version":"2.0"{sep}{extra}}},"scene":0,"scenes":[{{"nodes":[0]}}],"#,
            r#""nodes":[{{"mesh":0}}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],"#,
            r#""accessors":[{{"bufferView":0,"componentType":5126,"count":12,"type":"VEC3","#,
            r#""min":[0,0,0],"max":[{s},{s},{s}]}}],"#,
            r#""bufferViews":[{{"buffer":0,"byteLength":{len}}}],"buffers":[{{"byteLength":{len}}}]}}"#
        ),
        sep = sep,
        extra = asset_extra,
        s = s,
        len = bin.len()
    );
    glb(&json, &bin)
}

/// A GLB container of `json` and the binary chunk `bin` (each padded to 4 bytes as the format
/// asks: the JSON with spaces, the binary with zeros).
pub fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut json = json.as_bytes().to_vec();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let mut bin = bin.to_vec();
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut glb = Vec::with_capacity(total);
    glb.extend_from_slice(b"glTF");
    glb.extend_from_slice(&2u32.to_le_bytes());
    glb.extend_from_slice(&(total as u32).to_le_bytes());
    glb.extend_from_slice(&(json.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"JSON");
    glb.extend_from_slice(&json);
    glb.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"BIN\0");
    glb.extend_from_slice(&bin);
    glb
}

/// Resident memory of this process, bytes, from `/proc/self/statm` (Linux; 4 KiB pages, as on
/// the desktops and CI machines the memory tests run on); `None` where there is no such file.
pub fn resident_bytes() -> Option<u64> {
    let statm = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: u64 = statm.split_whitespace().nth(1)?.parse().ok()?;
    Some(pages * 4096)
}
