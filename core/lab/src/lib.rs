//! # Phantogram lab
//!
//! The desktop's side of the sensors: recorded logs and the formats they come in ([`sensorlog`],
//! with importers for the public datasets in [`sensorlog::import`]), deterministic replay of a log
//! through a `Session` ([`replay`]), and orientation scoring against motion-capture truth
//! ([`orientation_eval`]); a synthetic camera looking into an HDR environment for the live room
//! light ([`synthetic_camera`]); photos read upright for the face evaluation ([`photo`]); a big test scan made from a smaller one ([`big_scan`]) and the
//! structural similarity of two frames ([`ssim`]). Used by the `phantogram` CLI, the benchmarks
//! and the tests; the phone libraries do not link it.
//!
//! ## Panics and errors
//!
//! Files from outside never panic: a bad log yields [`sensorlog::LogError`] naming file and line,
//! a bad track [`orientation_eval::TrackError`]. Single-threaded; replay may sleep between frames
//! only when asked to (`Pace::RealTime`).

pub mod big_scan;
pub mod drawn_glasses;
pub mod orientation_eval;
pub mod photo;
pub mod replay;
pub mod sensorlog;
pub mod ssim;
pub mod synthetic_camera;
