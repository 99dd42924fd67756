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
//! This crate is the top of the library's layers and the one the shells and users depend on: it
//! holds [`engine`] (the one embedding API), [`artifacts`] (switching artifacts while it runs),
//! [`thumbnails`] (the gallery's pictures) and [`gesture`], and re-exports the lower crates'
//! modules under their old paths (`phantogram::screen`, `phantogram::fusion`, …). Dependencies
//! point down only (see `ARCHITECTURE.md`):
//!
//! * `phantogram_files`: [`files`] (regular files read within a size bound, files written whole
//!   or not at all, untrusted text quoted as short excerpts).
//! * `phantogram_geometry`: [`screen`], [`eyes`], [`projection`], [`viewpoint`], [`light`],
//!   [`containment`], [`anaglyph`]. Its crate docs hold the frames-and-units contract every crate
//!   uses.
//! * `phantogram_sensing`: [`sensors`], [`lowpass`], [`attitude`], [`fusion`], [`eyetrack`],
//!   [`straight_on`], [`calibration`], [`camera`], [`session`], [`synthetic`], [`clock`].
//! * `phantogram_assets` (feature `models`): `model`, `artifact`, `builtin`, `library`, `ibl`,
//!   `parallel`, `progress`, `budget`.
//! * `phantogram_physics` (feature `render`): `physics` (the Diorama's world; [`diorama`] shows
//!   it through the engine).
//! * `phantogram_render` (feature `render`): `render` (the crate itself) and `surface`.
//! * `phantogram_vision` (feature `face`): `face` (the crate itself).
//! * `phantogram_ui` (feature `ui`): `calibration_ui` (the crate itself).
//! * `phantogram_lab` (log formats, replay, scoring) is for the desktop and tests and is not
//!   re-exported: the CLI (`phantogram-cli`) depends on it, the phone libraries do not.
//!
//! ## Threading
//!
//! Sensor events may be pushed from any thread through [`sensors::SensorInbox`] (shared by `Arc`);
//! everything else is plain data owned by the thread that renders, except face tracking, which
//! runs its networks on a worker thread of its own (`face::FaceWorker`).
//!
//! ## Panics and errors
//!
//! Data from outside (files, sensors, FFI) never panics the library: bad files yield typed errors
//! naming the file, bad sensor samples are rejected and counted ([`sensors::SensorStats`]), bad
//! configuration yields typed errors. Panics would indicate a bug.
//!
//! ## Features and dependencies (and why each)
//!
//! * always: the files, geometry and sensing crates, `glam` for small-vector maths (the chosen stack),
//!   `thiserror` for error types.
//! * `models`: `phantogram_assets` (gltf-rs, draco-core, MikkTSpace, image; see its docs).
//! * `render` (implies `models`): `phantogram_render` (wgpu, the chosen stack) and [`engine`];
//!   `image` to encode the pictures it shares as PNG (the version the assets decode with).
//! * `face`: `phantogram_vision` (tract-onnx runs MediaPipe's networks in pure Rust: no native
//!   inference runtime to cross-build for the phones).
//! * `ui` (implies `render`): `phantogram_ui` (egui and egui-wgpu draw the calibration screens with
//!   the renderer's own device, driven by touches through [`engine`], the desktop viewer's mouse
//!   included) and `egui` for the engine's side of it.
//! * The `phantogram` command-line tool and desktop viewer are the `phantogram-cli` crate
//!   (`core/cli`), which depends on this one with its default features; the phone crates turn
//!   the defaults off and choose what they embed.

pub use phantogram_files as files;
pub use phantogram_geometry::{anaglyph, containment, eyes, light, projection, screen, viewpoint};
pub use phantogram_sensing::storage::{face_models_dir, library_dir};
pub use phantogram_sensing::{
    attitude, calibration, camera, clock, eyetrack, fusion, lowpass, sensors, session, straight_on, synthetic,
};

#[cfg(feature = "models")]
pub use phantogram_assets::{appearance, artifact, budget, builtin, ibl, library, model, parallel, progress, ward};
#[cfg(feature = "render")]
pub use phantogram_physics as physics;
#[cfg(feature = "render")]
pub use phantogram_render as render;
#[cfg(feature = "render")]
pub use phantogram_render::surface;
#[cfg(feature = "ui")]
pub use phantogram_ui as calibration_ui;
#[cfg(feature = "face")]
pub use phantogram_vision as face;

#[cfg(feature = "render")]
pub mod appearances;
#[cfg(feature = "render")]
pub mod artifacts;
#[cfg(feature = "render")]
mod background;
#[cfg(feature = "render")]
pub mod diorama;
#[cfg(feature = "render")]
pub mod engine;
pub mod gesture;
#[cfg(feature = "render")]
pub mod impostors;
#[cfg(feature = "render")]
pub mod lamp;
#[cfg(feature = "render")]
pub mod room_light;
#[cfg(feature = "render")]
pub mod thumbnails;

pub use glam;
/// Big scans under a frame budget: parts, levels of detail, the chooser, seen sides.
#[cfg(feature = "render")]
pub use phantogram_detail as detail;
/// The wgpu the renderer is built on, for shells that hand it window handles.
#[cfg(feature = "render")]
pub use phantogram_render::wgpu;
pub use session::{FrameView, Session, SessionConfig, SessionError};
