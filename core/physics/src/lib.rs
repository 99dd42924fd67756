//! # Phantogram physics: the Diorama
//!
//! The handheld-phantograms paper grew out of its "Diorama" game: a box of loose objects held in
//! the hand, whose objects slide toward the side of the phone that is lower in the room while
//! the picture is re-projected for the viewer's eyes. This crate is that box, GPU-free:
//!
//! * [`diorama::Diorama`]: the world — a tray behind the glass (a floor and four walls along
//!   the screen's edges), loose bodies, a fixed time step (120 Hz by default) decoupled from the
//!   frame rate, poses interpolated between steps for drawing, a grab for the finger;
//! * [`frustum`]: front-space containment as in the paper — the pyramids from each eye to the
//!   screen's edges, updated every step as kinematic half-spaces, so that a body in front of
//!   the glass is never cut by the screen's border in either eye's image;
//! * [`apparent_gravity`]: the gravity the bodies feel, in the device frame — the room's real
//!   "down" from the fused orientation, plus a bounded nudge from the hand's own acceleration;
//! * [`bodies`]: what can lie in the tray (marbles, dice, coins, small vessels, convex hulls of
//!   artifacts) and the default scene.
//!
//! **Frames and units**: the device frame of `phantogram_geometry` (the glass is the plane
//! `z = 0`, `+z` towards the viewer, metres), seconds and nanoseconds of the sensor clock.
//!
//! **Why rapier3d** (0.36, single-threaded): a maintained pure-Rust engine with continuous
//! collision detection, kinematic bodies and half-space colliders, deterministic on one binary
//! (same inputs, same poses, bit for bit), and fast enough here — 50 bodies step in about a
//! tenth of a millisecond (`cargo xtask bench diorama`). Its maths is glam 0.33; ours is glam
//! 0.30, so positions cross the boundary as arrays (`convert`). avian3d needs Bevy and a newer
//! Rust; rolling our own contact solver would be the larger risk.
//!
//! **Threading**: a [`diorama::Diorama`] is plain data owned by one thread (the render thread
//! in the engine). **Panics**: none on any input; non-finite inputs are ignored.

pub mod apparent_gravity;
pub mod bodies;
mod convert;
pub mod diorama;
pub mod frustum;
