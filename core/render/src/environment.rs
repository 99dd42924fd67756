//! The renderer's image-based light: setting the environment (a map, its prefiltered levels, or
//! the generated studio), prefiltering on the GPU where it can, and the Ward map.

use crate::{
    RenderError, Renderer,
    bindings::{EyeViews, eye_bind_groups, upload_ward_map},
    checked,
    gpu::Gpu,
    lighting_tables::{IblTextures, PREFILTERED_BASE_WIDTH, default_prefiltered_environment},
    prefilter_gpu,
};
use phantogram_assets::ward::WardMap;

impl Renderer {
    /// Lights the scene with `env` (world frame) instead of the generated studio.
    ///
    /// Prefilters the environment for specular light on the GPU where the device can
    /// ([`Self::prefilters_on_gpu`]), else on the CPU (a few tens of milliseconds in release
    /// builds for the default 256-wide base level); a live room light reduces the environment on
    /// its own thread and hands the result to [`Self::set_environment_base`] or
    /// [`Self::set_prefiltered_environment`].
    pub fn set_environment(&mut self, env: &phantogram_assets::ibl::Environment) -> Result<(), RenderError> {
        let sh = phantogram_assets::ibl::IrradianceSh::from_environment(env);
        let base = phantogram_assets::ibl::prefilter_base(env, PREFILTERED_BASE_WIDTH);
        self.set_environment_base(&base, &sh)
    }

    /// Whether this renderer convolves the specular levels on the GPU ([`prefilter_gpu`]); made
    /// on the first call (a compute pipeline).
    pub fn prefilters_on_gpu(&mut self) -> bool {
        let gpu = &self.gpu;
        self.gpu_prefilter
            .get_or_insert_with(|| prefilter_gpu::GpuPrefilter::new(gpu))
            .is_some()
    }

    /// Lights the scene with an environment given by its level 0 (from
    /// [`phantogram_assets::ibl::prefilter_base`] at [`PREFILTERED_BASE_WIDTH`]) and irradiance:
    /// the rough levels are convolved on the GPU where it can, else here on the CPU.
    pub fn set_environment_base(
        &mut self,
        base: &phantogram_assets::ibl::Environment,
        sh: &phantogram_assets::ibl::IrradianceSh,
    ) -> Result<(), RenderError> {
        if self.prefilters_on_gpu() {
            let sources = phantogram_assets::ibl::PrefilterSources::new(base.clone());
            return self.set_environment_upload(&prefilter_gpu::PrefilterUpload::new(sources)?, sh);
        }
        // The CPU path makes its own halvings: none made here for it.
        let levels = phantogram_assets::ibl::prefiltered_levels(base, PREFILTERED_BASE_WIDTH);
        self.set_prefiltered_environment(&levels, sh)
    }

    /// [`Self::set_environment_base`] with level 0's halvings already made and packed
    /// ([`prefilter_gpu::PrefilterUpload::new`]): a live room light makes them on its worker, so
    /// that the render thread only writes the bytes, records and submits. Where this renderer has
    /// no GPU prefilter after all, the CPU convolves the upload's level 0.
    pub fn set_environment_upload(
        &mut self,
        upload: &prefilter_gpu::PrefilterUpload,
        sh: &phantogram_assets::ibl::IrradianceSh,
    ) -> Result<(), RenderError> {
        if self.prefilters_on_gpu()
            && let Some(Some(prefilter)) = &mut self.gpu_prefilter
        {
            let texture = prefilter.run_upload(&self.gpu, upload)?;
            if self.ibl.environment_texture == texture {
                // The same texture, convolved again in place (an update of the same size): the
                // eyes' bind groups already hold it; only the irradiance changes.
                self.environment_sh = sh.shader_coefficients();
                return Ok(());
            }
            return self.use_ibl(sh, |gpu| IblTextures::with_texture(gpu, &texture));
        }
        let levels = phantogram_assets::ibl::prefiltered_levels(upload.base(), PREFILTERED_BASE_WIDTH);
        self.set_prefiltered_environment(&levels, sh)
    }

    /// Lights the scene with `environment`, or the generated studio when `None` (whose reduction
    /// is made once per process and shared).
    pub fn set_environment_or_studio(
        &mut self,
        environment: Option<&phantogram_assets::ibl::Environment>,
    ) -> Result<(), RenderError> {
        match environment {
            Some(env) => self.set_environment(env),
            None => self.set_prefiltered_environment(
                default_prefiltered_environment(),
                &phantogram_assets::ibl::IrradianceSh::from_environment(&phantogram_assets::ibl::Environment::studio()),
            ),
        }
    }

    /// Lights the scene with an environment already reduced: its specular levels (as
    /// [`phantogram_assets::ibl::prefiltered_levels`] makes them, at [`PREFILTERED_BASE_WIDTH`])
    /// and its irradiance. Only uploads: for the render thread.
    pub fn set_prefiltered_environment(
        &mut self,
        levels: &[phantogram_assets::ibl::Environment],
        sh: &phantogram_assets::ibl::IrradianceSh,
    ) -> Result<(), RenderError> {
        if levels.is_empty()
            || levels
                .iter()
                .any(|l| l.width == 0 || l.height == 0 || l.texels.len() != l.width * l.height)
        {
            return Err(RenderError::Gpu {
                what: "the environment map",
                message: "no levels, or a level whose texels do not fill it".into(),
            });
        }
        self.use_ibl(sh, |gpu| IblTextures::new(gpu, levels))
    }

    /// Lights the scene with the image light `make` builds and the irradiance `sh`, the eyes'
    /// bind groups made again for it.
    pub(crate) fn use_ibl(
        &mut self,
        sh: &phantogram_assets::ibl::IrradianceSh,
        make: impl FnOnce(&Gpu) -> IblTextures,
    ) -> Result<(), RenderError> {
        self.environment_sh = sh.shader_coefficients();
        let device = self.gpu.device.clone();
        checked(&device, "the environment map", || {
            self.ibl = make(&self.gpu);
            self.remake_eye_binds();
        })
    }

    /// The eyes' bind groups made again, after the image light, the lamp's cube or the Ward
    /// map changed.
    pub(crate) fn remake_eye_binds(&mut self) {
        self.eye_bind = eye_bind_groups(
            &self.gpu.device,
            &self.eye_layout,
            &self.eye_buffers,
            &self.eye_views(),
            &self.ibl,
        );
        self.backdrop_bound = self.backdrop().map_or(0, |b| b.id);
    }

    /// The frame targets' backdrop, if they have one.
    pub(crate) fn backdrop(&self) -> Option<&crate::backdrop::Backdrop> {
        self.targets.as_ref().and_then(|t| t.backdrop.as_ref())
    }

    /// What the eyes' bind groups hold besides their uniforms and the image light.
    pub(crate) fn eye_views(&self) -> EyeViews<'_> {
        EyeViews {
            shadow: &self.shadow_view,
            shadow_sampler: &self.shadow_sampler,
            shadow_cube: &self.point_shadow.cube_view,
            shadow_filter: if self.cube_filter_bound {
                &self.cube_filter.view
            } else {
                &self.shadow_filter.view
            },
            ward_map: &self.ward_map.1,
            ward_sampler: &self.ward_sampler,
            backdrop: [0, 1].map(|eye| {
                self.backdrop()
                    .and_then(|b| b.view(eye))
                    .unwrap_or(&self.backdrop_placeholder)
            }),
            backdrop_sampler: &self.backdrop_sampler,
        }
    }

    /// Uploads the texture map the appearance's Ward material asks for, if it is not the one
    /// bound (a preset chosen on the material screen: once, not per frame).
    pub(crate) fn use_ward_map(&mut self) -> Result<(), RenderError> {
        let wanted = self.appearance.sanitised().ward.map_or(WardMap::Uniform, |w| w.map);
        if wanted == self.ward_map.0 {
            return Ok(());
        }
        let device = self.gpu.device.clone();
        checked(&device, "the Ward material's texture map", || {
            self.ward_map = (wanted, upload_ward_map(&self.gpu, wanted));
            self.remake_eye_binds();
        })
    }
}
