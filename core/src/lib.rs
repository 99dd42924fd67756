//! # Phantogram core
//!
//! A phone held in the hand becomes a window onto a museum artifact that stays put in the real world
//! (a *phantogram*, after "Handheld phantograms", CHI 2011). This crate holds everything except the
//! platform shells: the physical model of the screen and the viewer's eyes, the off-axis stereo
//! projection, the viewpoint from the motion sensors, the world-fixed light, front-space containment,
//! and the sensor-log plumbing used to replay recordings on the desktop.
//!
//! ## Layers
//!
//! This crate is the top of the library's layers and the one the shells and users depend on. It
//! re-exports the lower crates' modules under their old paths (`phantogram::screen`,
//! `phantogram::fusion`, …):
//!
//! * `phantogram_geometry`: [`screen`], [`eyes`], [`projection`], [`viewpoint`], [`light`],
//!   [`containment`], [`anaglyph`]. Its crate docs hold the frames-and-units contract every crate
//!   uses.
//! * `phantogram_sensing`: [`sensors`], [`lowpass`], [`attitude`], [`fusion`], [`eyetrack`],
//!   [`calibration`], [`session`], [`synthetic`].
//! * `phantogram_lab` (log formats, replay, scoring) is for the desktop and tests and is not
//!   re-exported: the CLI depends on it, the phone libraries do not.
//!
//! Here: assets ([`artifact`], [`model`], [`ibl`]), and with features the renderer, the window
//! surface, face tracking, the calibration screens and [`engine`], the one embedding API.
//!
//! ## Threading
//!
//! Sensor events may be pushed from any thread through [`sensors::SensorInbox`] (shared by `Arc`);
//! everything else is plain data owned by the thread that renders, except face tracking, which
//! runs its networks on a worker thread of its own (`face`).
//!
//! ## Panics and errors
//!
//! Data from outside (files, sensors, FFI) never panics the library: bad files yield typed errors
//! naming the file, bad sensor samples are rejected and counted ([`sensors::SensorStats`]), bad
//! configuration yields typed errors. Panics would indicate a bug.
//!
//! ## Features and dependencies (and why each)
//!
//! * always: the two lower crates, `glam` for small-vector maths (the chosen stack), `thiserror`
//!   for error types.
//! * `models`: `gltf` (gltf-rs, the chosen stack) for the glTF document model; `draco-core`
//!   because museums publish Draco-compressed scans and it decodes them in pure Rust (no C++
//!   toolchain in the phone builds); `bevy_mikktspace`, the reference tangent algorithm normal
//!   maps are baked against; `image` for PNG/JPEG textures and HDR/EXR environments, with `exr`
//!   (the version `image` decodes with) used directly to bound a damaged EXR's sizes before it is
//!   decoded (`exr_guard`); `base64` for
//!   data URIs; `serde_json` for Voyager scenes and extension blocks.
//! * `render` (implies `models`): `wgpu` (the chosen stack), `pollster` to wait on its few
//!   futures, `bytemuck` for uniform and vertex layouts.
//! * `cli` (implies `render`; on by default, off for the phone crates): `phantogram_lab` (logs,
//!   replay, scoring; `flate2` for the gzip-compressed recordings), `clap`, `anyhow` and
//!   `indicatif` (progress bars) for the `phantogram` binary, `winit` (the chosen stack) for its
//!   window.
//! * `face` (on by default; implies `models`): `tract-onnx` runs MediaPipe's face, landmark and
//!   iris networks in pure Rust (no native inference runtime to cross-build for the phones), and
//!   `half` packs the renderer's f16 textures.
//! * `ui` (on by default; implies `render`): `egui` and `egui-wgpu` draw the calibration screens
//!   with the renderer's own device ([`calibration_ui`]); the CLI adds `egui-winit` for mouse input.
//!
//! Modules here: [`artifact`], [`camera`], [`model`], [`ibl`], [`gesture`], [`parallel`]; with `render`,
//! `render`, `surface` and `engine` (the embedding API the phone shells drive); with `face`,
//! `face`; with `ui`, `calibration_ui`.

pub use phantogram_geometry::{anaglyph, containment, eyes, light, projection, screen, viewpoint};
pub use phantogram_sensing::{attitude, calibration, eyetrack, fusion, lowpass, sensors, session, synthetic};

pub mod artifact;
#[cfg(feature = "ui")]
pub mod calibration_ui;
pub mod camera;
#[cfg(feature = "render")]
pub mod engine;
#[cfg(feature = "models")]
mod exr_guard;
#[cfg(feature = "face")]
pub mod face;
pub mod gesture;
pub mod ibl;
pub mod model;
pub mod parallel;
#[cfg(feature = "render")]
pub mod render;
#[cfg(feature = "render")]
pub mod surface;

pub use glam;
pub use session::{FrameView, Session, SessionConfig, SessionError};
/// The wgpu the renderer is built on, for shells that hand it window handles.
#[cfg(feature = "render")]
pub use wgpu;

/// Where `cargo xtask models` puts the face-tracking models and where [`face::FaceModels`] looks
/// for them: `$PHANTOGRAM_MODELS` if set, else `$XDG_CACHE_HOME/phantogram/models`, else
/// `~/.cache/phantogram/models`. `None` only without any of those variables.
pub fn face_models_dir() -> Option<std::path::PathBuf> {
    phantogram_sensing::storage::user_path("PHANTOGRAM_MODELS", "XDG_CACHE_HOME", ".cache", "models")
}
