//! # Phantogram files
//!
//! How the core touches files it did not write, and writes its own: the lowest layer beside
//! `phantogram_geometry`, used by sensing (calibration), assets (models, environments) and lab
//! (sensor logs).
//!
//! * [`read`]: regular files only (a pipe would block, `/dev/zero` never ends), with a size
//!   bound checked before the memory is taken.
//! * [`atomic`]: [`atomic::AtomicFile`], a file written whole or not at all, and only over a
//!   regular file (never over a device node).
//! * [`text`]: a byte-order mark accepted; untrusted text quoted back only as a short, escaped
//!   excerpt.
//!
//! ## Threading, panics and errors
//! Plain functions and one owned handle; `std::io::Error`s with the reason in their message
//! (the callers add the path). Nothing here panics.

pub mod atomic;
pub mod read;
pub mod text;

pub use atomic::AtomicFile;
pub use read::{open_regular_file, read_regular_file};

#[cfg(test)]
mod tests;
