//! The model loader on any bytes, as a `.glb`, a `.gltf`, a `scene.svx.json`, a `.ply`, an
//! `.stl`, an `.obj` or a point cloud as text, `.xyz` (by the first bytes), beside a small valid buffer and PNG that URIs and
//! material libraries may name. Within the phone
//! budget: an input may fail, never panic, hang or take more than the budget.
#![no_main]

#[path = "scratch.rs"]
mod scratch;

use libfuzzer_sys::fuzz_target;
use phantogram_assets::budget::ResourceBudget;
use phantogram_assets::model::load_model_within;

/// Counts the Rust heap (its own global allocator): one input may not grow it by more than 1 GiB.
#[path = "heap_limit.rs"]
mod heap_limit;

fuzz_target!(|data: &[u8]| {
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
        Some(b'{') if data.windows(8).any(|w| w == b"\"models\"") => "scene.svx.json",
        Some(b'{') => "model.gltf",
        Some(b'p') => "model.ply",
        Some(b'v' | b'o' | b'#' | b'm') => "model.obj",
        // ASCII STL, and binary STL whose header begins with the same word, as many do.
        Some(b's') => "model.stl",
        Some(b'0'..=b'9' | b'-' | b'+' | b'.') => "model.xyz",
        _ => "model.glb",
    };
    let path = scratch::write(dir, name, data);
    let _ = load_model_within(&path, ResourceBudget::PHONE);
});
