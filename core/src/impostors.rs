//! Relief-texture impostors for a big scan's parts (issue 22): which parts get one, at what
//! resolution, and baking them a few per frame.
//!
//! Every part with levels of detail gets an impostor ([`phantogram_render::impostor`]); the
//! chooser ([`phantogram_detail::choose`]) then draws it where it is the cheaper way to an
//! error. Their GPU memory comes out of the artifact's memory budget: what the model leaves of
//! it, at most [`IMPOSTOR_MEMORY_BYTES`], shared equally, each face's side a power of two from
//! [`MIN_TEXELS`] to [`MAX_TEXELS`]; with less than that, no impostors. Baking a scan's hundred
//! parts at once would stall a frame on a phone (six views of each part's full mesh), so
//! [`ImpostorBaker::step`] bakes [`BAKED_PER_FRAME`] per frame and hands each to the chooser as
//! it is made.
//!
//! **Threading**: the render thread's, with the renderer. **Panics**: none; a failed bake stops
//! the baking (the parts keep their polygons).

use glam::Vec3;
use phantogram_assets::model::Model;
use phantogram_detail::{Detail, ImpostorSummary};
use phantogram_render::{ImpostorBox, RenderError, Renderer};

/// GPU memory all of a scan's impostors may take together, at most: a tenth of a mid-range
/// phone's artifact budget (`ResourceBudget::PHONE`).
pub const IMPOSTOR_MEMORY_BYTES: u64 = 32 << 20;
/// Fewer texels than this per side and an impostor's error is larger than the coarsest
/// levels' (a 32k-triangle part's coarsest level has 64 triangles): none are made.
pub const MIN_TEXELS: u32 = 16;
/// A part's impostor is drawn where it covers few pixels; more texels than this would only
/// serve parts large on the glass, where the polygons are cheaper anyway.
pub const MAX_TEXELS: u32 = 128;
/// Parts baked per frame: six small views each, a few milliseconds on a phone's GPU.
pub const BAKED_PER_FRAME: usize = 4;

/// Texels per side for `parts` impostors within `memory_bytes`, or `None` when they would be
/// coarser than [`MIN_TEXELS`].
pub fn texels_for(parts: usize, memory_bytes: u64) -> Option<u32> {
    if parts == 0 {
        return None;
    }
    let per_part = memory_bytes.min(IMPOSTOR_MEMORY_BYTES) / parts as u64;
    let side = ((per_part / (6 * phantogram_render::impostor::BYTES_PER_TEXEL)) as f64).sqrt() as u32;
    let texels = if side == 0 {
        0
    } else {
        1u32 << (31 - side.leading_zeros())
    };
    (texels >= MIN_TEXELS).then_some(texels.min(MAX_TEXELS))
}

/// The impostors of one installed model still to bake.
#[derive(Debug, Default)]
pub struct ImpostorBaker {
    queue: Vec<(usize, ImpostorBox)>,
    baked: usize,
    bytes: u64,
}

impl ImpostorBaker {
    /// The parts of `model` (primitives with levels of detail) and their boxes, within
    /// `memory_bytes` of GPU memory.
    pub fn plan(model: &Model, memory_bytes: u64) -> Self {
        let parts: Vec<usize> = (0..model.primitives.len())
            .filter(|&i| !model.primitives[i].lods.is_empty() && !model.primitives[i].is_floor)
            .collect();
        let Some(texels) = texels_for(parts.len(), memory_bytes) else {
            return Self::default();
        };
        let mut queue: Vec<(usize, ImpostorBox)> = parts
            .into_iter()
            .filter_map(|i| {
                let points = model.primitives[i].mesh.vertices.iter().map(|v| Vec3::from(v.position));
                ImpostorBox::around(points, texels).map(|b| (i, b))
            })
            .collect();
        // Popped from the end: the first parts first.
        queue.reverse();
        Self {
            queue,
            baked: 0,
            bytes: 0,
        }
    }

    /// Parts left to bake.
    pub fn pending(&self) -> usize {
        self.queue.len()
    }

    /// Impostors baked so far.
    pub fn baked(&self) -> usize {
        self.baked
    }

    /// GPU memory of the impostors baked so far, bytes.
    pub fn baked_bytes(&self) -> u64 {
        self.bytes
    }

    /// Bakes the next [`BAKED_PER_FRAME`] parts and gives them to `detail`. On a GPU failure
    /// nothing more is baked and the error is returned once.
    pub fn step(&mut self, renderer: &mut Renderer, detail: &mut Detail) -> Result<(), RenderError> {
        let take = self.queue.len().min(BAKED_PER_FRAME);
        let batch: Vec<(usize, ImpostorBox)> = self.queue.split_off(self.queue.len() - take);
        match renderer.bake_impostors(&batch) {
            Ok(bytes) => {
                self.bytes += bytes;
                for (i, b) in batch {
                    if renderer.has_impostor(i) {
                        self.baked += 1;
                        detail.set_impostor(
                            i,
                            Some(ImpostorSummary {
                                error_m: b.error_m(),
                                texels: b.texels,
                            }),
                        );
                    }
                }
                Ok(())
            }
            Err(e) => {
                self.queue.clear();
                Err(e)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn impostors_share_their_memory_in_powers_of_two() {
        // 128 parts in 32 MiB: 52 texels would fit, 32 are made.
        assert_eq!(texels_for(128, u64::MAX), Some(32));
        let taken = ImpostorBox::around([Vec3::ZERO, Vec3::ONE], 32).map(|b| b.bytes());
        assert!(taken.is_some_and(|b| 128 * b <= IMPOSTOR_MEMORY_BYTES), "{taken:?}");
        // A few parts: capped.
        assert_eq!(texels_for(2, u64::MAX), Some(MAX_TEXELS));
        // Little memory left by the model: none, rather than impostors too coarse to use.
        assert_eq!(texels_for(128, 1 << 20), None);
        assert_eq!(texels_for(0, u64::MAX), None);
    }
}
