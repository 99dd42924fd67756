//! # Phantogram assets
//!
//! What a phantogram shows, on the CPU: triangle meshes with metallic–roughness materials and
//! textures in the device frame ([`model`], with the glTF 2.0 loader: Draco, quantized meshes,
//! Smithsonian Voyager scenes), the procedural default artifact ([`artifact`]), and the image-based
//! light's environments and precomputed tables ([`ibl`]), within one resource budget checked
//! before anything is allocated ([`budget`]). No GPU: the renderer uploads what this
//! crate makes. Frames and units are `phantogram_geometry`'s.
//!
//! ## Dependencies (and why each)
//! `gltf` (gltf-rs, the chosen stack) for the glTF document model; `draco-core` because museums
//! publish Draco-compressed scans and it decodes them in pure Rust (no C++ toolchain in the phone
//! builds); `bevy_mikktspace`, the reference tangent algorithm normal maps are baked against;
//! `image` for PNG/JPEG textures and HDR/EXR environments, with `exr` (the version `image` decodes
//! with) used directly to bound a damaged EXR's sizes before it is decoded (`exr_guard`); `base64`
//! for data URIs; `serde_json` for Voyager scenes and extension blocks; `bytemuck` for the vertex
//! layout the renderer uploads as it is.
//!
//! ## Threading, panics and errors
//! Loading may use one thread per core for independent pieces ([`parallel`]); everything else is
//! plain data. Files from outside never panic: they yield typed errors naming the file
//! ([`model::ModelError`], [`ibl::EnvironmentError`]).

pub mod appearance;
pub mod artifact;
pub mod budget;
pub mod builtin;
mod exr_guard;
pub mod ibl;
pub mod library;
pub mod model;
pub mod parallel;
pub mod progress;
pub mod ward;
pub mod ward_map;
