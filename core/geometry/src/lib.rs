//! # Phantogram geometry
//!
//! The physical model a phantogram is drawn from, as pure maths (glam, no GPU, no I/O, no
//! threads): the screen ([`screen`]) and the viewer's eyes ([`eyes`]), the off-axis stereo
//! projection ([`projection`]), the paper's gravity viewpoint ([`viewpoint`]), the world-fixed
//! light ([`light`]), front-space containment ([`containment`]), the anaglyph colour matrices
//! ([`anaglyph`]) and directions spread evenly over the sphere ([`sphere`]). The lowest layer of the workspace: every other crate depends on it, it on
//! nothing of ours (see `ARCHITECTURE.md`).
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
//!
//! ## Panics and errors
//!
//! Bad parameters (a zero-sized screen, eyes behind the glass, …) yield typed errors; nothing here
//! panics on finite input. All types are plain data, `Send + Sync`.

pub mod anaglyph;
pub mod containment;
pub mod eyes;
pub mod light;
pub mod projection;
pub mod screen;
pub mod sphere;
pub mod srgb;
pub mod viewpoint;

pub use glam;
