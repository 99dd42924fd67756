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

pub(crate) struct GpuMaterial {
    pub(crate) bind: wgpu::BindGroup,
    pub(crate) variant: MaterialVariant,
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
}

impl GpuModel {
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
    pub(crate) blend: bool,
    /// Base colour, metallic-roughness, normal, occlusion, emissive: sampled or not.
    pub(crate) textures: [bool; 5],
    /// Alpha mask: the shader may discard (which also costs early depth testing).
    pub(crate) mask: bool,
    /// The pipeline of a cross-fade's draws (`vs_fade`, the per-instance fade, and a
    /// screen-door discard); made for the materials of primitives with levels of detail.
    pub(crate) fade: bool,
}

impl MaterialVariant {
    /// Casts its shadow through the alpha-masked shadow pipeline (blended surfaces cast none).
    pub(crate) fn casts_masked_shadow(&self) -> bool {
        self.mask && !self.blend
    }
}

/// Names of the `override` constants in `scene.wgsl`, in [`MaterialVariant::textures`] order.
pub(crate) const TEXTURE_OVERRIDES: [&str; 5] = [
    "HAS_BASE_TEXTURE",
    "HAS_METALLIC_ROUGHNESS_TEXTURE",
    "HAS_NORMAL_TEXTURE",
    "HAS_OCCLUSION_TEXTURE",
    "HAS_EMISSIVE_TEXTURE",
];
