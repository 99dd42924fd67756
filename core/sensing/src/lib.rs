//! # Phantogram sensing
//!
//! From the platform's sensor events to what one frame needs, without a GPU or a network: the
//! validated, thread-safe event inbox ([`sensors`]), the paper's low-pass attitude ([`lowpass`],
//! [`attitude`]), the fused gyroscope/accelerometer/magnetometer orientation ([`fusion`]), the
//! eye-tracking filter that blends face observations with the gravity viewpoint ([`eyetrack`]),
//! the user's calibration ([`calibration`]), front-camera frames and their intrinsics ([`camera`]) and the per-device [`session`] that ties them to the
//! geometry of `phantogram_geometry`. [`synthetic`] simulates the sensors from a known motion, for
//! tests and benchmarks.
//!
//! Frames and units are those of `phantogram_geometry`'s crate docs (device frame = Android's
//! sensor frame, world = ENU, time stamps in integer nanoseconds).
//!
//! ## Threading
//!
//! Sensor events may be pushed from any thread through [`sensors::SensorInbox`] (shared by `Arc`);
//! everything else is plain data owned by the thread that renders. Nothing here blocks for long:
//! the inbox holds a mutex only to append or drain a queue.
//!
//! ## Panics and errors
//!
//! Data from outside never panics: bad sensor samples are rejected and counted
//! ([`sensors::SensorStats`], [`fusion::FusionStats`]), a bad calibration file falls back to the
//! defaults with a message, bad configuration yields typed errors. A panic would be a bug.

pub mod attitude;
pub mod calibration;
pub mod camera;
pub mod clock;
pub mod eyetrack;
pub mod fusion;
pub mod glasses;
pub mod lowpass;
pub mod sensors;
pub mod session;
pub mod storage;
pub mod straight_on;
pub mod synthetic;
pub mod turn_by_touch;

pub use session::{FrameView, Session, SessionConfig, SessionError};
