//! Phantogram's live room light (issue 20, after the tabletop decor viewer's live 360° light): the
//! phone's camera sees the room as the user moves it; with the fused orientation each frame is
//! placed in an equirectangular map of the room's radiance in the world frame ([`capture`]), from
//! which the renderer's image-based light is made (nine SH coefficients and the specular levels,
//! `phantogram_assets::ibl`). The map is world-anchored: it turns with the fused heading, as the
//! world light does.
//!
//! * [`tone`]: camera bytes → linear light (YCbCr → RGB, the inverse tone curve).
//! * [`capture`]: the map, its exposure normalisation, blending and coverage.
//! * [`fill`]: what the camera never saw, filled from what it did.
//!
//! Layer: above `phantogram-sensing` (camera frames, poses) and `phantogram-assets` (the
//! environment map type); no GPU, no files. **Threading**: plain data, used from one thread at a
//! time. **Panics**: none on any input.

pub mod capture;
pub mod fill;
pub mod tone;

pub use capture::{AddReport, CaptureError, CaptureFrame, CaptureParams, RoomCapture, world_from_buffer_camera};
pub use fill::{LOCAL_FILL_DEG, UNSEEN_FLOOR_REFLECTANCE};
