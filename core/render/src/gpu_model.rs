//! A [`Model`](phantogram_assets::model::Model) on the GPU: each primitive's buffers, each
//! material's bind group, and which scene pipeline (material variant) draws it.

use crate::impostor;
use glam::Vec3;

pub(crate) struct GpuPrimitive {
    pub(crate) vertices: wgpu::Buffer,
    /// Vertices in `vertices` (for [`Renderer::update_vertices`]).
    pub(crate) vertex_count: usize,
    /// The full mesh's indices, then each coarser level's.
    pub(crate) indices: wgpu::Buffer,
    /// Each level's range of `indices`, the full mesh first, and its geometric error, metres.
    pub(crate) levels: Vec<std::ops::Range<u32>>,
    pub(crate) level_errors_m: Vec<f32>,
    /// Which of the model's primitives this is (a piece of, for a mesh larger than a buffer).
    pub(crate) source: usize,
    pub(crate) material: usize,
    pub(crate) centre: Vec3,
    /// This piece's bounds (mesh coordinates), for culling it from the lamp cube's faces;
    /// `None` for a mesh without vertices.
    pub(crate) bounds: Option<phantogram_geometry::containment::Aabb>,
    pub(crate) is_floor: bool,
}

impl GpuPrimitive {
    /// Binds the buffers and draws the level `levels` chooses for it (see
    /// [`FrameInput::levels`]), with whatever pipeline and bind groups are set.
    pub(crate) fn draw(&self, pass: &mut wgpu::RenderPass<'_>, levels: &[u8]) {
        self.draw_at(pass, levels.get(self.source).copied().unwrap_or(0), 0);
    }

    /// Triangles [`Self::draw`] draws at `levels`.
    pub(crate) fn triangles_at(&self, levels: &[u8]) -> u64 {
        let level = usize::from(levels.get(self.source).copied().unwrap_or(0));
        self.levels
            .get(level)
            .or(self.levels.last())
            .map_or(0, |r| u64::from(r.end - r.start) / 3)
    }

    /// Draws level `level` (past the chain: the coarsest) as instance `instance`.
    pub(crate) fn draw_at(&self, pass: &mut wgpu::RenderPass<'_>, level: u8, instance: u32) {
        let Some(range) = self.levels.get(usize::from(level)).or(self.levels.last()) else {
            return;
        };
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(range.clone(), 0, instance..instance + 1);
    }
}

/// What a frame's glass needs of the eyes' backdrops ([`GpuModel::backdrop_needed`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum BackdropNeeded {
    None,
    /// The copy (level 0) alone.
    Sharp,
    /// The copy and its halvings.
    Blurred,
}

pub(crate) struct GpuMaterial {
    pub(crate) bind: wgpu::BindGroup,
    pub(crate) variant: MaterialVariant,
    /// Glass that blurs what is seen through it (`Material::blurs`): its backdrop needs the
    /// halvings.
    pub(crate) blurs: bool,
    // Kept alive for the bind group.
    pub(crate) _uniform: wgpu::Buffer,
}

/// A model on the GPU.
pub(crate) struct GpuModel {
    pub(crate) primitives: Vec<GpuPrimitive>,
    pub(crate) materials: Vec<GpuMaterial>,
    /// Everything, floor included.
    pub(crate) bounds: phantogram_geometry::containment::Aabb,
    /// Everything but the floor (all of it if there is nothing else).
    pub(crate) standing: phantogram_geometry::containment::Aabb,
    /// Baked impostors by the model's primitive index ([`Renderer::bake_impostors`]).
    pub(crate) impostors: Vec<Option<impostor::GpuImpostor>>,
    /// Bytes its textures take ([`Renderer::texture_bytes`]).
    pub(crate) texture_bytes: u64,
}

impl GpuModel {
    /// The primitives light passes through (drawn as [`DrawLayer::Filter`] then
    /// [`DrawLayer::Light`]): what the shadow filter of glass draws.
    pub(crate) fn glass(&self) -> impl Iterator<Item = &GpuPrimitive> {
        self.primitives
            .iter()
            .filter(|p| self.materials[p.material].variant.layer == DrawLayer::Light)
    }

    /// The backdrop the model's glass needs ([`DrawLayer::Backdrop`], `backdrop`): none without
    /// glass that blurs or bends what is seen through it; the copy of what lies behind alone
    /// where such glass only bends; the copy and its halvings where any blurs.
    pub(crate) fn backdrop_needed(&self) -> BackdropNeeded {
        let drawn = || self.primitives.iter().map(|p| &self.materials[p.material]);
        if drawn().any(|m| m.variant.backdrop && m.blurs) {
            BackdropNeeded::Blurred
        } else if drawn().any(|m| m.variant.backdrop) {
            BackdropNeeded::Sharp
        } else {
            BackdropNeeded::None
        }
    }

    /// What casts shadows this frame, and the bounds the shadow map must cover. The floor is a
    /// plane under everything that faces +z: lit from above it shadows nothing, so the map covers
    /// only what stands on it, at the resolution that detail needs (with the floor, 2.5 screens
    /// out, a texel would be ~10× coarser and the shadow blurred and detached from the feet).
    /// With the light below its plane the floor does cast (it hides the light from all it holds).
    pub(crate) fn shadow_casters(&self, toward_light: Vec3) -> (bool, phantogram_geometry::containment::Aabb) {
        let floor_casts = toward_light.z < 0.0;
        (floor_casts, if floor_casts { self.bounds } else { self.standing })
    }
}

/// What a material's scene pipeline is specialised for: culling and blending, and which texture
/// slots it samples and whether it can discard (WGSL `override` constants in `scene.wgsl`).
/// Slots a material lacks hold 1×1 defaults that change nothing, so not sampling them gives the
/// same picture for less: on lavapipe the fragment work is most of a frame, and every texture
/// sample and the shadow filter are a large part of it (see `benchmarks/render.md`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct MaterialVariant {
    pub(crate) double_sided: bool,
    /// Draws the back faces alone (the far side of double-sided glass, drawn before its near
    /// side: [`MaterialVariant::draws`]); overrides `double_sided`.
    pub(crate) cull_front: bool,
    pub(crate) blend: bool,
    /// Base colour, metallic-roughness, normal, occlusion, emissive, transmission, thickness:
    /// sampled or not.
    pub(crate) textures: [bool; 7],
    /// Alpha mask: the shader may discard (which also costs early depth testing).
    pub(crate) mask: bool,
    /// The pipeline of a cross-fade's draws (`vs_fade`, the per-instance fade, and a
    /// screen-door discard); made for the materials of primitives with levels of detail.
    pub(crate) fade: bool,
    /// What the draw writes: the whole surface, or one of the two layers of a surface that
    /// light passes through (`KHR_materials_transmission`).
    pub(crate) layer: DrawLayer,
    /// Whether what is seen through it is blurred (rough glass) or displaced (a refracting
    /// volume): its filter is then [`DrawLayer::Backdrop`] instead of [`DrawLayer::Filter`].
    pub(crate) backdrop: bool,
    /// Whether the material has any of glTF's extension layers; without, the shader uses the
    /// core material's constants (`HAS_LAYERS`), which its compiler folds away.
    pub(crate) layers: bool,
    /// Whether the material has layer textures (`HAS_LAYER_TEXTURES`, `layer_textures`).
    pub(crate) layer_textures: bool,
    /// Whether the model has glass, whose coloured shadow the surface may receive
    /// (`GLASS_SHADOWS`, `shadow_filter`); without, the shader leaves the filter out, at no cost.
    pub(crate) glass_shadows: bool,
}

/// A surface that transmits light changes what is behind it in two ways, which one blend
/// operation cannot do: it filters it (a colour factor: tinted glass) and adds its own light
/// (reflections, emission). So it is drawn twice, [`DrawLayer::Filter`] then
/// [`DrawLayer::Light`]: the pixel becomes behind × filter + light. Every other surface is drawn
/// once, [`DrawLayer::Whole`]. Glass that blurs or bends what is behind it cannot filter the
/// pixel under it: its first draw is [`DrawLayer::Backdrop`], which reads what the eye drew
/// behind it before (the eye's `backdrop`: blurred by its roughness, shifted by refraction), filters that, and blends it over the pixel by the surface's coverage. The
/// `TRANSMIT_LAYER` constant of `scene.wgsl`, in this order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum DrawLayer {
    Whole,
    Filter,
    Light,
    Backdrop,
}

impl DrawLayer {
    pub(crate) fn shader_constant(self) -> f64 {
        match self {
            Self::Whole => 0.0,
            Self::Filter => 1.0,
            Self::Light => 2.0,
            Self::Backdrop => 3.0,
        }
    }

    /// The colour target's blending: alpha blending for a blended whole surface, none for an
    /// opaque one; the destination times the source for the filter, their sum for the light,
    /// the source over the destination by its coverage for the backdrop. The layers leave the
    /// target's alpha as it is.
    pub(crate) fn blend(self, blended: bool) -> Option<wgpu::BlendState> {
        let keep_alpha = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::Zero,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        };
        match self {
            Self::Whole => blended.then_some(wgpu::BlendState::ALPHA_BLENDING),
            Self::Filter => Some(wgpu::BlendState {
                color: wgpu::BlendComponent {
                    src_factor: wgpu::BlendFactor::Zero,
                    dst_factor: wgpu::BlendFactor::Src,
                    operation: wgpu::BlendOperation::Add,
                },
                alpha: keep_alpha,
            }),
            Self::Light => Some(wgpu::BlendState {
                color: wgpu::BlendComponent {
                    src_factor: wgpu::BlendFactor::One,
                    dst_factor: wgpu::BlendFactor::One,
                    operation: wgpu::BlendOperation::Add,
                },
                alpha: keep_alpha,
            }),
            Self::Backdrop => Some(wgpu::BlendState {
                color: wgpu::BlendState::ALPHA_BLENDING.color,
                alpha: keep_alpha,
            }),
        }
    }
}

impl MaterialVariant {
    /// The draws that make a primitive of this material, in order: itself, or for a surface that
    /// transmits light its filter, then itself (its light). The filter of glass that blurs or
    /// bends is its backdrop where the frame has one (`with_backdrop`); without (a device that
    /// could not make it), the plain filter: sharp and straight, but what is behind still shows.
    /// Double-sided glass is drawn in two halves, its back faces (the far side of a closed
    /// shape) and then its front faces, each filter then light: the near side filters the far
    /// side's light, whatever the order of the triangles in the mesh.
    pub(crate) fn draws(self, with_backdrop: bool) -> impl Iterator<Item = MaterialVariant> {
        let filter_layer = if self.backdrop && with_backdrop {
            DrawLayer::Backdrop
        } else {
            DrawLayer::Filter
        };
        let side = |cull_front: bool| MaterialVariant {
            double_sided: false,
            cull_front,
            ..self
        };
        let layers = |light: MaterialVariant| {
            [
                Some(MaterialVariant {
                    layer: filter_layer,
                    ..light
                }),
                Some(light),
            ]
        };
        let draws: [Option<MaterialVariant>; 4] = match (self.layer, self.double_sided) {
            (DrawLayer::Light, true) => {
                let ([far_filter, far], [near_filter, near]) = (layers(side(true)), layers(side(false)));
                [far_filter, far, near_filter, near]
            }
            (DrawLayer::Light, false) => {
                let [filter, light] = layers(self);
                [filter, light, None, None]
            }
            _ => [Some(self), None, None, None],
        };
        draws.into_iter().flatten()
    }

    /// Casts its shadow through the alpha-masked shadow pipeline (blended surfaces cast none).
    pub(crate) fn casts_masked_shadow(&self) -> bool {
        self.mask && !self.blend
    }
}

/// Names of the `override` constants in `scene.wgsl`, in [`MaterialVariant::textures`] order.
pub(crate) const TEXTURE_OVERRIDES: [&str; 7] = [
    "HAS_BASE_TEXTURE",
    "HAS_METALLIC_ROUGHNESS_TEXTURE",
    "HAS_NORMAL_TEXTURE",
    "HAS_OCCLUSION_TEXTURE",
    "HAS_EMISSIVE_TEXTURE",
    "HAS_TRANSMISSION_TEXTURE",
    "HAS_THICKNESS_TEXTURE",
];

#[cfg(test)]
mod tests {
    use super::*;

    fn variant(layer: DrawLayer, double_sided: bool, backdrop: bool) -> MaterialVariant {
        MaterialVariant {
            double_sided,
            cull_front: false,
            blend: layer != DrawLayer::Whole,
            textures: [false; 7],
            mask: false,
            fade: false,
            layer,
            backdrop,
            layers: true,
            layer_textures: false,
            glass_shadows: true,
        }
    }

    #[test]
    fn double_sided_glass_is_drawn_far_side_first() {
        let draws: Vec<_> = variant(DrawLayer::Light, true, false).draws(true).collect();
        let shape: Vec<_> = draws.iter().map(|v| (v.layer, v.cull_front, v.double_sided)).collect();
        assert_eq!(
            shape,
            [
                (DrawLayer::Filter, true, false),
                (DrawLayer::Light, true, false),
                (DrawLayer::Filter, false, false),
                (DrawLayer::Light, false, false),
            ]
        );
        // One-sided glass: its filter, then its light; anything else once, as it is.
        let one_sided: Vec<_> = variant(DrawLayer::Light, false, false)
            .draws(true)
            .map(|v| v.layer)
            .collect();
        assert_eq!(one_sided, [DrawLayer::Filter, DrawLayer::Light]);
        let whole = variant(DrawLayer::Whole, true, false);
        assert_eq!(whole.draws(true).collect::<Vec<_>>(), [whole]);
    }

    #[test]
    fn glass_that_blurs_or_bends_filters_through_the_backdrop_when_there_is_one() {
        let frosted = variant(DrawLayer::Light, false, true);
        let with: Vec<_> = frosted.draws(true).map(|v| v.layer).collect();
        assert_eq!(with, [DrawLayer::Backdrop, DrawLayer::Light]);
        let without: Vec<_> = frosted.draws(false).map(|v| v.layer).collect();
        assert_eq!(without, [DrawLayer::Filter, DrawLayer::Light]);
    }
}
