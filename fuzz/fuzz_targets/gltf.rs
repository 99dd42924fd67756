//! The model loader on any bytes, as a `.glb`, a `.gltf`, a `scene.svx.json`, a `.ply`, an
//! `.stl`, an `.obj`, a point cloud as text, `.xyz`, a LAS/LAZ or E57 scan, or USD (`.usdz`,
//! `.usdc`, `.usda`) (by the first bytes), beside a small valid buffer and PNG that URIs and
//! material libraries may name. Within the phone budget: an input may fail, never panic, hang or
//! take more than the budget.
#![no_main]

#[path = "scratch.rs"]
mod scratch;

use libfuzzer_sys::fuzz_target;
use phantogram_assets::budget::ResourceBudget;
use phantogram_assets::model::load_model_within;

/// Counts the Rust heap (its own global allocator): one input may not grow it by more than 1 GiB.
#[path = "heap_limit.rs"]
mod heap_limit;

/// libFuzzer's panic hook aborts on every panic, even one the code catches. The LAZ decoder
/// (`laz`) indexes its chunk table out of bounds on some damaged files; `model::las` catches that
/// and reports the file as damaged, by design, so such a panic is let through here and the run
/// goes on to find what is not handled. Every other panic still aborts, and so does a `laz` panic
/// that escapes the loader (libfuzzer-sys aborts on any panic that leaves the target).
fn tolerate_caught_decoder_panics() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let libfuzzer_hook = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if info.location().is_some_and(|l| l.file().contains("/laz-")) {
                eprintln!("tolerated (the LAS loader catches it): {info}");
            } else {
                libfuzzer_hook(info);
            }
        }));
    });
}

/// An E57 file is 1024-byte pages, each ending in the CRC-32C of its other 1020 bytes (stored
/// big-endian), and the reader refuses a page whose sum does not match: nearly every mutation
/// would stop there. Inputs that begin as E57 are padded to whole pages and their sums set, so
/// that mutations reach the XML and the point data behind them.
fn with_e57_checksums(data: &[u8]) -> Option<Vec<u8>> {
    const PAGE: usize = 1024;
    if !data.starts_with(b"ASTM-E57") {
        return None;
    }
    let mut pages = data.to_vec();
    pages.resize(data.len().div_ceil(PAGE) * PAGE, 0);
    for page in pages.chunks_exact_mut(PAGE) {
        let (payload, sum) = page.split_at_mut(PAGE - 4);
        sum.copy_from_slice(&crc32c(payload).to_be_bytes());
    }
    Some(pages)
}

/// CRC-32C (Castagnoli, reflected polynomial 0x82F63B78), bit by bit: inputs are small.
fn crc32c(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0x82F6_3B78
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

fuzz_target!(|data: &[u8]| {
    tolerate_caught_decoder_panics();
    let paged = with_e57_checksums(data);
    let data = paged.as_deref().unwrap_or(data);
    heap_limit::input_begins();
    let dir = scratch::dir("gltf");
    if !dir.join("tri.bin").exists() {
        let tri: Vec<u8> = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        scratch::write(dir, "tri.bin", &tri);
        // A 2×2 RGBA PNG (75 bytes, written by this project).
        scratch::write(dir, "tex.png", include_bytes!("seeds/tex.png"));
    }
    let name = match data.first() {
        // USD: a package (a zip whose first file is a layer), the binary format, the text one.
        Some(b'P') if data.starts_with(b"PK") => "model.usdz",
        Some(b'P') => "model.usdc",
        Some(b'#') if data.starts_with(b"#usda") => "model.usda",
        Some(b'{') if data.windows(8).any(|w| w == b"\"models\"") => "scene.svx.json",
        Some(b'{') => "model.gltf",
        Some(b'p') => "model.ply",
        Some(b'v' | b'o' | b'#' | b'm') => "model.obj",
        // ASCII STL, and binary STL whose header begins with the same word, as many do.
        Some(b's') => "model.stl",
        Some(b'0'..=b'9' | b'-' | b'+' | b'.') => "model.xyz",
        Some(b'L') => "model.las",
        Some(b'A') => "model.e57",
        _ => "model.glb",
    };
    let path = scratch::write(dir, name, data);
    let _ = load_model_within(&path, ResourceBudget::PHONE);
});
