//! The desktop integration tests, as one test binary: each module is what was once a binary of
//! its own. One binary links the engine's dependencies (wgpu, tract, egui, …) once instead of two
//! dozen times, and its tests share the cores instead of waiting for each other binary by binary.
//! `cargo test -p phantogram-integration --test integration render::` runs one module.
//! Filters match anywhere in a test's name: `.ci/run`'s `--skip face::` (the CPU-only face tests)
//! also skips any module whose name ends in `face` — hence `surface_mode`, not `surface`, whose
//! golden frame those runs once left unchecked.
//!
//! A test that measures the process itself (resident memory) cannot share it: it has its own
//! binary (`tests/tests/memory.rs`).

mod accessibility;
mod anisotropy;
mod artifacts;
mod assets;
mod block_textures;
mod calibration_ui;
mod containment_sweep;
mod detail;
mod device_loss;
mod diorama;
mod eyetrack;
mod face;
mod fade;
mod furnace;
mod fusion_real;
mod fusion_vigorous;
mod glasses;
mod golden;
mod impostor;
mod iridescence;
mod lamp;
mod layer_textures;
mod materials;
mod models;
mod penumbra;
mod prefilter_gpu;
mod projection_ground_truth;
mod render;
mod room_light;
mod seen_through;
mod shared_data;
mod sheen;
mod sun;
mod surface_mode;
mod thin_sheets;
mod transmission;
mod viewpoint_and_light;
