//! Relief-texture impostors for a big scan's parts (issue 22): which parts get one, at what
//! resolution, and baking those worth drawing, a few per frame.
//!
//! Every part with levels of detail is planned an impostor ([`phantogram_render::impostor`]):
//! their GPU memory comes out of the artifact's memory budget — what the model leaves of it, at
//! most [`IMPOSTOR_MEMORY_BYTES`], shared equally, each face's side a power of two from
//! [`MIN_TEXELS`] to [`MAX_TEXELS`]; with less than that, none. The chooser
//! ([`phantogram_detail::choose`]) knows each planned impostor's error and cost, and an impostor
//! is baked only once the chooser would draw it
//! ([`phantogram_detail::Detail::impostors_worth_baking`]): at the glass, from arm's length, a
//! scan's parts are large on the screen, their polygons are cheaper, and nothing is baked (no
//! memory, no time); a part small on the screen for its triangles gets its impostor within a few
//! frames. Baking takes six views of a part's full mesh, so [`ImpostorBaker::step`] bakes at most
//! [`BAKED_PER_FRAME`] a frame.
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
/// coarser than [`MIN_TEXELS`]: the maps on OpenGL (ES) (`opengl`: a spare layer) or another
/// backend ([`phantogram_render::impostor::maps_bytes`]).
pub fn texels_for(parts: usize, memory_bytes: u64, opengl: bool) -> Option<u32> {
    if parts == 0 {
        return None;
    }
    let per_part = memory_bytes.min(IMPOSTOR_MEMORY_BYTES) / parts as u64;
    // The maps' bytes grow with the side squared: those of one texel a side, per texel.
    let per_texel = phantogram_render::impostor::maps_bytes(1, opengl);
    let side = ((per_part / per_texel) as f64).sqrt() as u32;
    let texels = if side == 0 {
        0
    } else {
        1u32 << (31 - side.leading_zeros())
    };
    (texels >= MIN_TEXELS).then_some(texels.min(MAX_TEXELS))
}

/// The impostors planned for one installed model, and those baked.
#[derive(Debug, Default)]
pub struct ImpostorBaker {
    /// By part (the model's primitive): its box while planned and not yet baked.
    planned: Vec<Option<ImpostorBox>>,
    baked: usize,
    bytes: u64,
}

impl ImpostorBaker {
    /// The parts of `model` (primitives with levels of detail) and their boxes, within
    /// `memory_bytes` of GPU memory on OpenGL (ES) (`opengl`) or another backend, each announced
    /// to `detail` as planned (not baked), so that the chooser can say which are worth baking.
    pub fn plan_for(model: &Model, memory_bytes: u64, opengl: bool, detail: &mut Detail) -> Self {
        let baker = Self::plan(model, memory_bytes, opengl);
        baker.announce(detail);
        baker
    }

    /// The parts of `model` (primitives with levels of detail) and their boxes, within
    /// `memory_bytes` of GPU memory (on OpenGL (ES) where `opengl`).
    fn plan(model: &Model, memory_bytes: u64, opengl: bool) -> Self {
        let parts: Vec<usize> = (0..model.primitives.len())
            .filter(|&i| !model.primitives[i].lods.is_empty() && !model.primitives[i].is_floor)
            .collect();
        let Some(texels) = texels_for(parts.len(), memory_bytes, opengl) else {
            return Self::default();
        };
        let mut planned = vec![None; model.primitives.len()];
        for i in parts {
            let points = model.primitives[i].mesh.vertices.iter().map(|v| Vec3::from(v.position));
            planned[i] = ImpostorBox::around(points, texels);
        }
        Self {
            planned,
            baked: 0,
            bytes: 0,
        }
    }

    /// Tells `detail` of every planned impostor (not baked yet), so that the chooser can say
    /// which are worth baking.
    fn announce(&self, detail: &mut Detail) {
        for (i, b) in self.planned.iter().enumerate() {
            if let Some(b) = b {
                detail.set_impostor(i, Some(summary(b, false)));
            }
        }
    }

    /// Planned impostors not baked yet.
    pub fn pending(&self) -> usize {
        self.planned.iter().flatten().count()
    }

    /// Impostors baked so far.
    pub fn baked(&self) -> usize {
        self.baked
    }

    /// GPU memory of the impostors baked so far, bytes.
    pub fn baked_bytes(&self) -> u64 {
        self.bytes
    }

    /// Bakes up to [`BAKED_PER_FRAME`] of the impostors the chooser's last choice would have
    /// drawn ([`Detail::impostors_worth_baking`]: a frame's lag) and marks them baked in
    /// `detail`. Returns how many were baked. On a GPU failure nothing more is planned and the
    /// error is returned once.
    pub fn step(&mut self, renderer: &mut Renderer, detail: &mut Detail) -> Result<usize, RenderError> {
        let wanted: Vec<usize> = detail
            .impostors_worth_baking()
            .iter()
            .copied()
            .filter(|&i| self.planned.get(i).is_some_and(Option::is_some))
            .take(BAKED_PER_FRAME)
            .collect();
        self.bake(renderer, detail, &wanted)
    }

    /// Bakes every planned impostor at once (the benchmark's measure of what they cost).
    pub fn bake_all(&mut self, renderer: &mut Renderer, detail: &mut Detail) -> Result<usize, RenderError> {
        let all: Vec<usize> = (0..self.planned.len()).filter(|&i| self.planned[i].is_some()).collect();
        self.bake(renderer, detail, &all)
    }

    fn bake(&mut self, renderer: &mut Renderer, detail: &mut Detail, parts: &[usize]) -> Result<usize, RenderError> {
        let batch: Vec<(usize, ImpostorBox)> = parts
            .iter()
            .filter_map(|&i| self.planned.get_mut(i).and_then(Option::take).map(|b| (i, b)))
            .collect();
        if batch.is_empty() {
            return Ok(0);
        }
        match renderer.bake_impostors(&batch) {
            Ok(bytes) => {
                self.bytes += bytes;
                let mut made = 0;
                for (i, b) in batch {
                    if renderer.has_impostor(i) {
                        made += 1;
                        detail.set_impostor(i, Some(summary(&b, true)));
                    } else {
                        // Skipped by the renderer (a blended material): not an option.
                        detail.set_impostor(i, None);
                    }
                }
                self.baked += made;
                Ok(made)
            }
            Err(e) => {
                for p in &mut self.planned {
                    *p = None;
                }
                for (i, _) in batch {
                    detail.set_impostor(i, None);
                }
                Err(e)
            }
        }
    }
}

fn summary(b: &ImpostorBox, baked: bool) -> ImpostorSummary {
    ImpostorSummary {
        error_m: b.error_m(),
        texels: b.texels,
        baked,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn impostors_share_their_memory_in_powers_of_two() {
        // 128 parts in 32 MiB: 52 texels would fit, 32 are made.
        assert_eq!(texels_for(128, u64::MAX, false), Some(32));
        let taken = ImpostorBox::around([Vec3::ZERO, Vec3::ONE], 32).map(|b| b.bytes());
        assert!(taken.is_some_and(|b| 128 * b <= IMPOSTOR_MEMORY_BYTES), "{taken:?}");
        // A few parts: capped.
        assert_eq!(texels_for(2, u64::MAX, false), Some(MAX_TEXELS));
        // Little memory left by the model: none, rather than impostors too coarse to use.
        assert_eq!(texels_for(128, 1 << 20, false), None);
        assert_eq!(texels_for(0, u64::MAX, false), None);
        // 67 parts: 64 texels fit six maps each, not OpenGL's seven.
        assert_eq!(texels_for(67, u64::MAX, false), Some(64));
        assert_eq!(texels_for(67, u64::MAX, true), Some(32));
        for opengl in [false, true] {
            let texels = texels_for(67, u64::MAX, opengl).expect("texels");
            let taken = ImpostorBox::around([Vec3::ZERO, Vec3::ONE], texels).map(|b| b.bytes_on(opengl));
            assert!(taken.is_some_and(|b| 67 * b <= IMPOSTOR_MEMORY_BYTES), "{taken:?}");
        }
    }
}
