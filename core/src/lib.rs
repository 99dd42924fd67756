//! # Phantogram core
//!
//! A phone held in the hand becomes a window onto a museum artifact that stays put in the real world
//! (a *phantogram*, after "Handheld phantograms", CHI 2011). This crate holds everything except the
//! platform shells: the physical model of the screen and the viewer's eyes, the off-axis stereo
//! projection, the viewpoint from the motion sensors, the world-fixed light, front-space containment,
//! and the sensor-log plumbing used to replay recordings on the desktop.
//!
//! ## Frames and units (defined here, once, and used everywhere)
//!
//! * **Units**: lengths in metres (`_m`; `_mm` where millimetres are printed), angles in radians
//!   (`_rad`; `_deg` only for human-facing input and output), time stamps in integer nanoseconds
//!   (`t_ns`, any epoch, the sensor clock), durations in seconds (`_s`). Accelerometer readings are in
//!   m/s² *including* gravity, gyroscope readings in rad/s, magnetometer readings in µT.
//! * **Device frame** = Android's sensor frame, fixed to the phone in its natural (portrait)
//!   orientation: origin at the centre of the screen's glass, **x** to the right, **y** up along the
//!   screen, **z** out of the glass towards the viewer. The glass is the plane `z = 0`; the screen
//!   rectangle is centred on the origin. Display rotation (portrait/landscape) changes only which
//!   device axis the *display's* right and up point along (see [`screen`]), never this frame.
//!   A phone lying face up on a table reads `+9.81` m/s² on the accelerometer's z axis: the
//!   accelerometer measures the reaction to gravity, which points **up**.
//! * **World frame**: x east, y north, z up (ENU), the frame of Android's rotation vector and of the
//!   BROAD benchmark's ground truth.
//! * **Orientations** are unit quaternions rotating device-frame vectors into the world frame
//!   (`device_to_world`).
//! * **The scene lives in the device frame**: the artifact sits in a diorama box behind and in front
//!   of the glass. As the phone turns, the viewer's eyes and the world light move *in the device
//!   frame*; the artifact does not.
//! * **Pixels**: display pixel coordinates have their origin at the top-left corner of the display
//!   as the viewer sees it, x to the right, y down; pixel `(i, j)` covers `[i, i+1) × [j, j+1)`, so
//!   its centre is `(i + 0.5, j + 0.5)`.
//! * **Depth**: reverse-Z in wgpu's clip space: the near plane maps to depth 1, the far plane to 0
//!   (or infinity to 0), for even precision over the diorama; compare with `Greater`.
//!
//! ## Threading
//!
//! Sensor events may be pushed from any thread through [`sensors::SensorInbox`] (shared by `Arc`);
//! everything else is plain data owned by the thread that renders. Nothing here blocks for long:
//! the inbox holds a mutex only to append or drain a queue.
//!
//! ## Panics and errors
//!
//! Data from outside (files, sensors, FFI) never panics the library: bad files yield
//! [`sensorlog::LogError`] naming file and line, bad sensor samples are rejected and counted
//! ([`sensors::SensorStats`]), bad configuration yields typed errors. Panics would indicate a bug.
//!
//! ## Features and dependencies (and why each)
//!
//! * always: `glam` for small-vector maths (the chosen stack), `thiserror` for error types,
//!   `flate2` for the gzip-compressed recordings and logs.
//! * `models`: `gltf` (gltf-rs, the chosen stack) for the glTF document model; `draco-core`
//!   because museums publish Draco-compressed scans and it decodes them in pure Rust (no C++
//!   toolchain in the phone builds); `bevy_mikktspace`, the reference tangent algorithm normal
//!   maps are baked against; `image` for PNG/JPEG textures and HDR/EXR environments, with `exr`
//!   (the version `image` decodes with) used directly to bound a damaged EXR's sizes before it is
//!   decoded (`exr_guard`); `base64` for
//!   data URIs; `serde_json` for Voyager scenes and extension blocks.
//! * `render` (implies `models`): `wgpu` (the chosen stack), `pollster` to wait on its few
//!   futures, `bytemuck` for uniform and vertex layouts.
//! * `cli` (implies `render`; on by default, off for the phone crates): `clap`, `anyhow` and
//!   `indicatif` (progress bars) for the `phantogram` binary, `winit` (the chosen stack) for its
//!   window.
//! * `face` (on by default; implies `models`): `tract-onnx` runs MediaPipe's face, landmark and
//!   iris networks in pure Rust (no native inference runtime to cross-build for the phones), and
//!   `half` packs the renderer's f16 textures.
//! * `ui` (on by default; implies `render`): `egui` and `egui-wgpu` draw the calibration screens
//!   with the renderer's own device ([`calibration_ui`]); the CLI adds `egui-winit` for mouse input.
//!
//! Modules: [`screen`], [`eyes`], [`viewpoint`], [`projection`], [`containment`], [`light`],
//! [`lowpass`], [`attitude`], [`fusion`], [`sensors`], [`sensorlog`], [`replay`], [`session`],
//! [`synthetic`], [`orientation_eval`], [`calibration`], [`anaglyph`], [`artifact`], [`model`],
//! [`ibl`], [`eyetrack`], [`gesture`], [`parallel`], and with `render`, `render`, `surface` and `engine` (the
//! embedding API the phone shells drive); with `face`, `face`; with `ui`,
//! `calibration_ui`.

pub mod anaglyph;
pub mod artifact;
pub mod attitude;
pub mod calibration;
#[cfg(feature = "ui")]
pub mod calibration_ui;
pub mod containment;
#[cfg(feature = "render")]
pub mod engine;
#[cfg(feature = "models")]
mod exr_guard;
pub mod eyes;
pub mod eyetrack;
#[cfg(feature = "face")]
pub mod face;
pub mod fusion;
pub mod gesture;
pub mod ibl;
pub mod light;
pub mod lowpass;
pub mod model;
pub mod orientation_eval;
pub mod parallel;
pub mod projection;
#[cfg(feature = "render")]
pub mod render;
pub mod replay;
#[doc(hidden)]
pub mod scratch;
pub mod screen;
pub mod sensorlog;
pub mod sensors;
pub mod session;
#[cfg(feature = "render")]
pub mod surface;
pub mod synthetic;
pub mod viewpoint;

pub use glam;
pub use session::{FrameView, Session, SessionConfig, SessionError};
/// The wgpu the renderer is built on, for shells that hand it window handles.
#[cfg(feature = "render")]
pub use wgpu;

/// Where `cargo xtask models` puts the face-tracking models and where [`face::FaceModels`] looks
/// for them: `$PHANTOGRAM_MODELS` if set, else `$XDG_CACHE_HOME/phantogram/models`, else
/// `~/.cache/phantogram/models`. `None` only without any of those variables.
pub fn face_models_dir() -> Option<std::path::PathBuf> {
    user_path("PHANTOGRAM_MODELS", "XDG_CACHE_HOME", ".cache", "models")
}

/// `$override_var` if set, else `$xdg_var/phantogram/name`, else `~/home_dir/phantogram/name`.
pub(crate) fn user_path(override_var: &str, xdg_var: &str, home_dir: &str, name: &str) -> Option<std::path::PathBuf> {
    use std::path::PathBuf;
    if let Some(p) = std::env::var_os(override_var) {
        return Some(PathBuf::from(p));
    }
    let base = std::env::var_os(xdg_var)
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(home_dir)))?;
    Some(base.join("phantogram").join(name))
}
