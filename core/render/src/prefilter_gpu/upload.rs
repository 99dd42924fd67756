//! An update's texels packed for [`super::GpuPrefilter`]: level 0 and its halvings as `f16` rows
//! padded for buffer-to-texture copies, checked and scaled, made without a device so that a
//! worker thread can make it. The render thread then only writes the bytes, records and submits.
//!
//! **Layout**: the sources' levels in mip order, each row padded to
//! [`wgpu::COPY_BYTES_PER_ROW_ALIGNMENT`]; then level 0 unscaled, for the target's level 0.
//! (Copying the target's level 0 from the sources' mip 0 on the GPU instead, a third fewer
//! bytes, drew an empty level 0 on an NVIDIA H200 under Vulkan while lavapipe copied it: not
//! kept. `benchmarks/ibl.md`.)
//!
//! **Threading**: plain data, `Send`; made on any thread. **Panics**: none.

use phantogram_assets::ibl::{Environment, PREFILTER_LEVELS, PrefilterSources};

use crate::{RenderError, lighting_tables};

/// Bytes of an `Rgba16Float` texel.
const TEXEL_BYTES: u32 = 8;

/// The brightest value the sources hold as they are: beyond it they are divided by a power of two
/// (exact) so that a sun's energy reaches the rough levels as on the CPU, the shader multiplying
/// back. Half of `f16`'s largest (65504), so that the halvings' and the bilinear reads' sums stay
/// finite.
const F16_SAFE_PEAK: f32 = 32_768.0;

/// Level 0 and its halvings as the GPU prefilter uploads them ([`PrefilterUpload::new`]).
pub struct PrefilterUpload {
    /// Level 0 as given (f32): what the CPU path convolves if the renderer has no GPU prefilter
    /// after all.
    pub(super) base: Environment,
    /// `read_by[k]`: the source mip level `k ≥ 1` reads.
    pub(super) read_by: [usize; PREFILTER_LEVELS],
    /// What the sources were divided by (1 unless a sun is beyond `f16`).
    pub(super) scale: f32,
    /// The source mip levels, `base` first.
    pub(super) source_levels: u32,
    pub(super) bytes: Vec<u8>,
    /// Where each level lies in `bytes`, in order: the sources', then the target's level 0.
    pub(super) copies: Vec<LevelCopy>,
}

/// One level's rows in [`PrefilterUpload::bytes`].
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) struct LevelCopy {
    /// Into the target (level 0) rather than the sources.
    pub into_target: bool,
    pub mip: u32,
    pub offset: u64,
    pub width: u32,
    pub height: u32,
    /// Bytes per row in the buffer (a multiple of `COPY_BYTES_PER_ROW_ALIGNMENT`).
    pub padded_row: u32,
}

impl LevelCopy {
    /// The copy of a `width` × `height` level at `offset`.
    fn at(offset: u64, into_target: bool, mip: u32, width: u32, height: u32) -> Self {
        let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        Self {
            into_target,
            mip,
            offset,
            width,
            height,
            padded_row: (TEXEL_BYTES * width).div_ceil(align) * align,
        }
    }

    /// The byte just past this level's rows.
    pub fn end(&self) -> u64 {
        self.offset + u64::from(self.padded_row) * u64::from(self.height)
    }
}

/// The largest finite value of each channel (0 if none is above 0). Twelve running maxima over
/// the flat floats (four texels a step), each a compare and select the compiler turns into
/// vector maxima: `f32::max` (which must pass NaN over) and a branch per texel kept it to one
/// value at a time, 0.14 ms for a 256-wide level 0 against 0.03 ms so.
fn finite_peaks(texels: &[[f32; 3]]) -> [f32; 3] {
    let flat: &[f32] = bytemuck::cast_slice(texels);
    let finite = |v: f32| if v < f32::INFINITY { v } else { 0.0 };
    let mut lanes = [0.0f32; 12];
    let mut steps = flat.chunks_exact(12);
    for step in &mut steps {
        for (lane, &v) in lanes.iter_mut().zip(step) {
            let v = finite(v);
            *lane = if v > *lane { v } else { *lane };
        }
    }
    let mut peaks = [0.0f32; 3];
    // 12 is a multiple of 3: lane i and remainder value i are channel i % 3.
    for (i, &v) in lanes.iter().enumerate().chain(steps.remainder().iter().enumerate()) {
        peaks[i % 3] = peaks[i % 3].max(finite(v));
    }
    peaks
}

impl PrefilterUpload {
    /// Checks and packs `sources` (from [`PrefilterSources::new`]): level 0 must be
    /// 2^k × 2^(k−1) texels with k ≥ [`PREFILTER_LEVELS`], and the others its halvings, read by
    /// index; anything else (the fields are public) is refused rather than copied out of shape.
    pub fn new(sources: PrefilterSources) -> Result<Self, RenderError> {
        let refuse = |message: String| RenderError::Gpu {
            what: "the GPU prefilter",
            message,
        };
        let PrefilterSources { mut halvings, read_by } = sources;
        let Some(base) = halvings.first() else {
            return Err(refuse("no level 0".into()));
        };
        let (w0, h0) = (base.width, base.height);
        if !w0.is_power_of_two() || w0 < 1 << PREFILTER_LEVELS || w0 != 2 * h0 || base.texels.len() != w0 * h0 {
            return Err(refuse(format!(
                "level 0 must be 2^k × 2^(k−1) texels, k ≥ {PREFILTER_LEVELS}; got {w0} × {h0}"
            )));
        }
        let halvings_fit = halvings
            .iter()
            .enumerate()
            .all(|(i, h)| h.width == w0 >> i && h.height == h0 >> i && h.texels.len() == h.width * h.height);
        if !halvings_fit || read_by.iter().any(|&r| r >= halvings.len()) {
            return Err(refuse("the sources are not level 0's halvings".into()));
        }
        let channel_peaks = finite_peaks(&base.texels);
        let peak = channel_peaks[0].max(channel_peaks[1]).max(channel_peaks[2]);
        let scale = if peak > F16_SAFE_PEAK {
            (peak / F16_SAFE_PEAK).log2().ceil().exp2()
        } else {
            1.0
        };
        let mut copies = Vec::with_capacity(halvings.len() + 1);
        let mut offset = 0;
        for (mip, level) in halvings.iter().enumerate() {
            let copy = LevelCopy::at(offset, false, mip as u32, level.width as u32, level.height as u32);
            offset = copy.end();
            copies.push(copy);
        }
        copies.push(LevelCopy::at(offset, true, 0, w0 as u32, h0 as u32));
        let mut bytes = Vec::with_capacity(copies.last().map_or(0, |c| c.end()) as usize);
        let scaled = |level: &Environment| Environment {
            texels: level.texels.iter().map(|t| t.map(|c| c / scale)).collect(),
            ..*level
        };
        for (copy, level) in copies.iter().zip(&halvings) {
            if scale == 1.0 {
                lighting_tables::push_rgba16f_rows(&mut bytes, level, copy.padded_row);
            } else {
                lighting_tables::push_rgba16f_rows(&mut bytes, &scaled(level), copy.padded_row);
            }
        }
        let base = halvings.swap_remove(0);
        lighting_tables::push_rgba16f_rows(&mut bytes, &base, copies[copies.len() - 1].padded_row);
        Ok(Self {
            base,
            read_by,
            scale,
            source_levels: (copies.len() - 1) as u32,
            bytes,
            copies,
        })
    }

    /// Level 0 as given.
    pub fn base(&self) -> &Environment {
        &self.base
    }

    /// Level 0's width and height in texels.
    pub fn size(&self) -> (u32, u32) {
        (self.base.width as u32, self.base.height as u32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sky(width: usize, sun: f32) -> Environment {
        let mut env = Environment {
            width,
            height: width / 2,
            texels: (0..width * width / 2).map(|i| [(i % 7) as f32, 1.0, 2.0]).collect(),
        };
        env.texels[width + 3] = [sun, sun, sun];
        env
    }

    fn f16_at(bytes: &[u8], at: usize) -> f32 {
        half::f16::from_le_bytes([bytes[at], bytes[at + 1]]).to_f32()
    }

    #[test]
    fn the_levels_lie_one_after_another_in_padded_rows_then_level_0_for_the_target() {
        let upload = PrefilterUpload::new(PrefilterSources::new(sky(64, 10.0))).expect("good sources");
        assert_eq!(upload.scale, 1.0);
        // 64 wide: halvings at 64, 32, 16, 8 (none below 8 wide), then level 0 for the target.
        let widths: Vec<u32> = upload.copies.iter().map(|c| c.width).collect();
        assert_eq!(widths, [64, 32, 16, 8, 64]);
        let into_target: Vec<bool> = upload.copies.iter().map(|c| c.into_target).collect();
        assert_eq!(into_target, [false, false, false, false, true]);
        assert_eq!(upload.source_levels, 4);
        for pair in upload.copies.windows(2) {
            assert_eq!(pair[1].offset, pair[0].end());
        }
        for c in &upload.copies {
            assert_eq!(c.padded_row % wgpu::COPY_BYTES_PER_ROW_ALIGNMENT, 0);
            assert!(c.padded_row >= 8 * c.width);
        }
        assert_eq!(upload.bytes.len() as u64, upload.copies[4].end());
        // Row 1, texel 3 of level 0: the sun; texel 5 of row 0: its red is 5; in both copies.
        let row = upload.copies[0].padded_row as usize;
        for at in [0, upload.copies[4].offset as usize] {
            assert_eq!(f16_at(&upload.bytes, at + row + 3 * 8), 10.0);
            assert_eq!(f16_at(&upload.bytes, at + 5 * 8), 5.0);
            assert_eq!(f16_at(&upload.bytes, at + 5 * 8 + 6), 1.0, "alpha");
        }
    }

    #[test]
    fn a_sun_beyond_f16_is_divided_by_a_power_of_two_in_the_sources_alone() {
        let upload = PrefilterUpload::new(PrefilterSources::new(sky(64, 196_608.0))).expect("good sources");
        // 196 608 / 32 768 = 6: divided by the next power of two, 8.
        assert_eq!(upload.scale, 8.0);
        let target = upload.copies.last().expect("a copy");
        assert!(target.into_target && target.mip == 0 && target.width == 64);
        assert_eq!(upload.source_levels, 4);
        let row = upload.copies[0].padded_row as usize;
        assert_eq!(f16_at(&upload.bytes, row + 3 * 8), 24_576.0);
        assert_eq!(f16_at(&upload.bytes, 5 * 8), 5.0 / 8.0);
        // The target's level 0 as shown: clamped into f16, not divided.
        let at = target.offset as usize;
        // 65 000 as f16 (whose steps are 32 apart there).
        assert_eq!(f16_at(&upload.bytes, at + row + 3 * 8), 64_992.0);
        assert_eq!(f16_at(&upload.bytes, at + 5 * 8), 5.0);
        assert_eq!(upload.base().texels[64 + 3][0], 196_608.0);
    }

    #[test]
    fn the_peaks_are_each_channels_largest_finite_value_wherever_it_lies() {
        // Seven texels: four in the vector steps, three in the remainder; each channel's peak
        // placed once in each part, beside NaN and infinities that must not count.
        for at in 0..7 {
            let mut texels = vec![[1.0f32, 2.0, 3.0]; 7];
            texels[at] = [10.0, f32::NAN, f32::INFINITY];
            texels[(at + 3) % 7] = [f32::NEG_INFINITY, 20.0, 30.0];
            assert_eq!(finite_peaks(&texels), [10.0, 20.0, 30.0], "peak texel {at}");
        }
        assert_eq!(finite_peaks(&[[f32::NAN; 3], [-1.0; 3]]), [0.0; 3]);
        assert_eq!(finite_peaks(&[]), [0.0; 3]);
    }

    #[test]
    fn sources_that_are_not_halvings_are_refused() {
        let good = || PrefilterSources::new(sky(64, 1.0));
        let mut wrong_size = good();
        wrong_size.halvings[1] = wrong_size.halvings[2].clone();
        let mut out_of_range = good();
        out_of_range.read_by[1] = out_of_range.halvings.len();
        let mut none = good();
        none.halvings.clear();
        let mut short_texels = good();
        short_texels.halvings[1].texels.pop();
        let mut narrow = good();
        narrow.halvings.truncate(1);
        narrow.halvings[0] = sky(16, 1.0);
        narrow.read_by = [0; PREFILTER_LEVELS];
        for (name, sources) in [
            ("a halving of the wrong size", wrong_size),
            ("a level read from beyond the halvings", out_of_range),
            ("no level 0", none),
            ("a halving short of texels", short_texels),
            ("a level 0 narrower than the levels", narrow),
        ] {
            assert!(PrefilterUpload::new(sources).is_err(), "{name}: accepted");
        }
    }
}
