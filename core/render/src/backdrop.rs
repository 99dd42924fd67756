//! What glass that blurs or bends the view through it shows: per eye, a copy of what the eye has
//! drawn so far (linear HDR, the eye's target format) with its chain of halvings down to one
//! texel, made just before the eye's farthest such glass is drawn.
//!
//! Smooth thin glass filters the pixel under it (`DrawLayer::Filter`), which is exact for any
//! number of layers. Frosted glass shows a blur of what is behind it and a refracting volume
//! shows what is behind it displaced: neither is the pixel under it, so such glass
//! (`Material::blurs_or_bends`) reads the backdrop instead (`DrawLayer::Backdrop`, `seen_through`
//! in `scene.wgsl`: a level by its roughness, a place by its refracted ray). The copy holds the
//! opaque scene and the blended surfaces drawn before it (those farther than the farthest such
//! glass, by the blended surfaces' back-to-front order): what is blended between two such glasses
//! is not seen through the nearer one. The glTF sample viewer, whose transmission pass this
//! follows, copies the opaque scene alone.
//!
//! Made with the frame's targets, only while the model has such glass, for an eye only once a
//! frame draws it (a 1080×2400 eye costs 21 MB, 28 MB with its halvings), and with the halvings
//! only while some of that glass is rough (glass that only bends reads the copy itself); the
//! eyes' bind groups are remade when the backdrop they hold is not the current one. Each level is
//! one draw of `backdrop.wgsl` reading the level above: two passes of the eye's scene instead of
//! one, plus one small one per level. Render thread only, like the renderer; no panics.
//!
//! The halvings weigh 4 × 4 texels by [1 3 3 1] / 8 and the scene shader reads them with a cubic
//! B-spline (`backdrop_at`), as wide a blur at each roughness as the sample viewer's chain of
//! 2 × 2 means read bilinearly, which snaps what is blurred to its texels (a pattern of crosses
//! over anything that repeats near their size; a spot that jumps as what it blurs moves):
//! `seen_through::frosted_glass_blurs_a_thing_alike_wherever_it_stands`.

use std::sync::atomic::{AtomicU64, Ordering};

use crate::HDR_FORMAT;
use crate::bindings::{filterable_texture_entry, filtering_sampler_entry};
use crate::pipelines::{create_fullscreen_pipeline, draw_fullscreen};

pub(crate) const BACKDROP_WGSL: &str = include_str!("../../../shaders/backdrop.wgsl");

/// Draws one level of a backdrop from the one above (or from the eye's target).
pub(crate) struct Halver {
    /// Level 0: the eye's target as it is.
    copy: wgpu::RenderPipeline,
    /// Every further level: the one above, halved.
    halve: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
}

impl Halver {
    pub(crate) fn new(device: &wgpu::Device) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("backdrop.wgsl"),
            source: wgpu::ShaderSource::Wgsl(BACKDROP_WGSL.into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("backdrop level"),
            entries: &[filterable_texture_entry(0), filtering_sampler_entry(1)],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("backdrop level"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let copy = create_fullscreen_pipeline(
            device,
            "backdrop copy",
            &module,
            &pipeline_layout,
            "fs_copy",
            HDR_FORMAT,
            &[],
        );
        let halve = create_fullscreen_pipeline(
            device,
            "backdrop halving",
            &module,
            &pipeline_layout,
            "fs_halve",
            HDR_FORMAT,
            &[],
        );
        Self {
            copy,
            halve,
            layout,
            sampler: sampler(device),
        }
    }
}

/// The sampler the scene shader reads a backdrop with, and levels are drawn with: bilinear within
/// and between levels, clamped at the screen's edges (a ray bent off the screen reads its edge).
pub(crate) fn sampler(device: &wgpu::Device) -> wgpu::Sampler {
    device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("backdrop"),
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        ..Default::default()
    })
}

/// What the eyes' bind groups hold while no backdrop is made: one black texel.
pub(crate) fn placeholder(device: &wgpu::Device) -> wgpu::TextureView {
    device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some("no backdrop"),
            size: wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: HDR_FORMAT,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        })
        .create_view(&Default::default())
}

/// Levels of a chain of halvings of `width × height` down to one texel.
pub(crate) fn level_count(width: u32, height: u32) -> u32 {
    32 - width.max(height).max(1).leading_zeros()
}

/// Each backdrop made gets its own number, so that the eyes' bind groups can tell whether they
/// hold the current one (0: the placeholder).
static NEXT_ID: AtomicU64 = AtomicU64::new(1);

/// One eye's backdrop.
struct EyeBackdrop {
    /// Its levels together, as the scene shader samples them.
    view: wgpu::TextureView,
    /// Its levels, one view each, drawn into in order.
    levels: Vec<wgpu::TextureView>,
    /// What level k is drawn from: the eye's target for level 0, then level k − 1.
    sources: Vec<wgpu::BindGroup>,
}

/// The eyes' backdrops for targets of one size, each made when a frame first draws that eye (a
/// mono frame only the first).
pub(crate) struct Backdrop {
    /// Changes whenever an eye's backdrop is made.
    pub(crate) id: u64,
    /// Levels made: 1 (the copy alone, for glass that only bends) or the whole chain.
    pub(crate) level_count: u32,
    size: (u32, u32),
    eyes: [Option<EyeBackdrop>; 2],
}

impl Backdrop {
    /// Backdrops of `width × height` (none made yet): the copy alone, or with `halvings` the
    /// whole chain.
    pub(crate) fn new((width, height): (u32, u32), halvings: bool) -> Self {
        Self {
            id: NEXT_ID.fetch_add(1, Ordering::Relaxed),
            level_count: if halvings { level_count(width, height) } else { 1 },
            size: (width, height),
            eyes: [None, None],
        }
    }

    /// Eye `eye`'s levels together, once made.
    pub(crate) fn view(&self, eye: usize) -> Option<&wgpu::TextureView> {
        self.eyes.get(eye)?.as_ref().map(|e| &e.view)
    }

    /// Makes eye `eye`'s backdrop from its target `target`, if not made yet (a new [`Self::id`]).
    pub(crate) fn make_eye(&mut self, device: &wgpu::Device, halver: &Halver, target: &wgpu::TextureView, eye: usize) {
        if eye >= 2 || self.eyes[eye].is_some() {
            return;
        }
        let (width, height) = self.size;
        let count = self.level_count;
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(if eye == 0 { "backdrop left" } else { "backdrop right" }),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: count,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: HDR_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let levels: Vec<wgpu::TextureView> = (0..count)
            .map(|k| {
                texture.create_view(&wgpu::TextureViewDescriptor {
                    label: Some("backdrop level"),
                    base_mip_level: k,
                    mip_level_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        let sources = (0..count as usize)
            .map(|k| {
                let source = if k == 0 { target } else { &levels[k - 1] };
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("backdrop level"),
                    layout: &halver.layout,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: wgpu::BindingResource::TextureView(source),
                        },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: wgpu::BindingResource::Sampler(&halver.sampler),
                        },
                    ],
                })
            })
            .collect();
        self.eyes[eye] = Some(EyeBackdrop {
            view: texture.create_view(&Default::default()),
            levels,
            sources,
        });
        self.id = NEXT_ID.fetch_add(1, Ordering::Relaxed);
    }

    /// Records eye `eye`'s copy of its target and the halvings, after its opaque draws.
    /// Nothing where that eye's backdrop is not made.
    pub(crate) fn record(&self, encoder: &mut wgpu::CommandEncoder, halver: &Halver, eye: usize) {
        let Some(Some(made)) = self.eyes.get(eye) else {
            return;
        };
        for (k, (level, source)) in made.levels.iter().zip(&made.sources).enumerate() {
            let pipeline = if k == 0 { &halver.copy } else { &halver.halve };
            draw_fullscreen(encoder, "backdrop level", level, pipeline, source, None);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_chain_ends_at_one_texel() {
        assert_eq!(level_count(1, 1), 1);
        assert_eq!(level_count(2, 1), 2);
        assert_eq!(level_count(1080, 2400), 12);
        assert_eq!(level_count(2048, 2048), 12);
        assert_eq!(level_count(2049, 3), 12);
        assert_eq!(level_count(3, 4096), 13);
        assert_eq!(level_count(0, 0), 1);
    }
}
