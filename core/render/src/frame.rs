//! Drawing a frame: the shadow pass, each eye's scene pass (impostors and level fades included),
//! composition, and the ways to ask for a frame (offscreen, side by side, into a view).

use crate::{
    CLEAR_RADIANCE, FrameInput, OUTPUT_FORMAT, RenderError, Renderer, SHADOW_SIZE, checked,
    gpu::Gpu,
    gpu_model::{GpuPrimitive, MaterialVariant},
    impostor::{self, IMPOSTOR_LEVEL},
    lights::{Lamp, lamp_view_proj, light_view_proj},
    pipelines::create_compose_pipeline,
    point_shadow, shadow_filter,
    targets::{Offscreen, read_back},
    uniforms::{ComposeUniform, EyeUniform},
};
use glam::{Mat4, Vec3};
use phantogram_assets::model::LevelFade;
use phantogram_geometry::{anaglyph::Method, projection::OffAxisProjection};

impl Renderer {
    /// Renders one frame of `width × height` pixels and reads it back as 8-bit sRGB RGBA, rows top
    /// to bottom.
    pub fn render(
        &mut self,
        input: &FrameInput,
        method: Method,
        width: u32,
        height: u32,
    ) -> Result<Vec<u8>, RenderError> {
        self.render_views(&input.eyes_drawn(method), input, method, width, height)
    }

    /// Renders `projection` alone (no stereo composition), e.g. one eye's image for tests.
    pub fn render_single(
        &mut self,
        projection: &OffAxisProjection,
        input: &FrameInput,
        width: u32,
        height: u32,
    ) -> Result<Vec<u8>, RenderError> {
        self.render_views(&[projection], input, Method::Mono, width, height)
    }

    /// The stereo pair side by side for parallel viewing (and stereo tools): the left eye's
    /// image on the left, the right eye's on the right, each `width × height`; returns
    /// `2·width × height` sRGB RGBA pixels, rows top to bottom.
    pub fn render_side_by_side(&mut self, input: &FrameInput, width: u32, height: u32) -> Result<Vec<u8>, RenderError> {
        let left = self.render_single(input.left, input, width, height)?;
        let right = self.render_single(input.right, input, width, height)?;
        let row = width as usize * 4;
        let mut pair = Vec::with_capacity(left.len() * 2);
        for (l, r) in left.chunks_exact(row).zip(right.chunks_exact(row)) {
            pair.extend_from_slice(l);
            pair.extend_from_slice(r);
        }
        Ok(pair)
    }

    /// As [`Self::render`], with `overlay` painting over the composed frame before it is read back
    /// (the calibration screens): it gets the device, the frame's view, format and size, and
    /// submits its own work.
    pub fn render_with_overlay(
        &mut self,
        input: &FrameInput,
        method: Method,
        width: u32,
        height: u32,
        overlay: impl FnOnce(&Gpu, &wgpu::TextureView, wgpu::TextureFormat, [u32; 2]),
    ) -> Result<Vec<u8>, RenderError> {
        self.render_views_with(&input.eyes_drawn(method), input, method, width, height, Some(overlay))
    }

    pub(crate) fn render_views(
        &mut self,
        eyes: &[&OffAxisProjection],
        input: &FrameInput,
        method: Method,
        width: u32,
        height: u32,
    ) -> Result<Vec<u8>, RenderError> {
        type NoOverlay = fn(&Gpu, &wgpu::TextureView, wgpu::TextureFormat, [u32; 2]);
        self.render_views_with(eyes, input, method, width, height, None::<NoOverlay>)
    }

    pub(crate) fn render_views_with(
        &mut self,
        eyes: &[&OffAxisProjection],
        input: &FrameInput,
        method: Method,
        width: u32,
        height: u32,
        overlay: Option<impl FnOnce(&Gpu, &wgpu::TextureView, wgpu::TextureFormat, [u32; 2])>,
    ) -> Result<Vec<u8>, RenderError> {
        let bytes = Offscreen::padded_row(width) * u64::from(height);
        let max_bytes = self.gpu.device.limits().max_buffer_size;
        if bytes > max_bytes {
            return Err(RenderError::FrameTooLarge {
                width,
                height,
                bytes,
                max_bytes,
            });
        }
        self.targets(width, height)?;
        let device = self.gpu.device.clone();
        let targets = self.targets.as_mut().expect("created above");
        let output_view = targets
            .offscreen
            .get_or_insert_with(|| Offscreen::new(&device, width, height))
            .output_view
            .clone();
        let mut encoder = self.encode_frame(eyes, input, method, &output_view, OUTPUT_FORMAT)?;
        if let Some(overlay) = overlay {
            // The frame first, then the overlay's own submission over it, then the copy.
            let queue = &self.gpu.queue;
            self.submit_timed(|| queue.submit([encoder.finish()]))?;
            overlay(&self.gpu, &output_view, OUTPUT_FORMAT, [width, height]);
            encoder = self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("read-back"),
            });
        }
        let targets = self.targets.as_ref().expect("created above");
        let offscreen = targets.offscreen.as_ref().expect("created above");
        encoder.copy_texture_to_buffer(
            offscreen.output.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &offscreen.readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(offscreen.padded_row),
                    rows_per_image: Some(height),
                },
            },
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
        );
        let queue = &self.gpu.queue;
        self.submit_timed(|| queue.submit([encoder.finish()]))?;
        read_back(&self.gpu.device, offscreen, width, height)
    }

    /// Renders one frame into `target` (e.g. a surface's current texture) of `format` and
    /// `width × height` pixels, and submits it; the caller presents.
    pub fn render_to_view(
        &mut self,
        input: &FrameInput,
        method: Method,
        target: &wgpu::TextureView,
        format: wgpu::TextureFormat,
        width: u32,
        height: u32,
    ) -> Result<(), RenderError> {
        self.targets(width, height)?;
        let encoder = self.encode_frame(&input.eyes_drawn(method), input, method, target, format)?;
        let queue = &self.gpu.queue;
        self.submit_timed(|| queue.submit([encoder.finish()]))
    }

    /// Submits a frame's commands (inside a validation scope) and asks for its GPU time, if the
    /// frame was timed; a failed submission frees the timer for the next frame.
    pub(crate) fn submit_timed(&self, submit: impl FnOnce() -> wgpu::SubmissionIndex) -> Result<(), RenderError> {
        let result = checked(&self.gpu.device, "the frame", submit).map(drop);
        if let Some(timer) = &self.timer {
            match result {
                Ok(()) => timer.submitted(),
                Err(_) => timer.abandon(),
            }
        }
        result
    }

    /// Writes the uniforms and records the shadow, scene and composition passes into `target`.
    pub(crate) fn encode_frame(
        &mut self,
        eyes: &[&OffAxisProjection],
        input: &FrameInput,
        method: Method,
        target: &wgpu::TextureView,
        format: wgpu::TextureFormat,
    ) -> Result<wgpu::CommandEncoder, RenderError> {
        if !self.compose_pipelines.contains_key(&format) {
            let device = self.gpu.device.clone();
            let pipeline = checked(&device, "the composition pipeline for this surface format", || {
                create_compose_pipeline(&device, &self.compose_module, &self.compose_pipeline_layout, format)
            })?;
            self.compose_pipelines.insert(format, pipeline);
        }
        self.use_ward_map()?;
        let lamp = self.lamp.filter(Lamp::is_finite);
        let toward = match &lamp {
            Some(l) => l.toward_from((self.model.bounds.min + self.model.bounds.max) * 0.5),
            None => input.toward_light,
        };
        let (floor_casts, shadow_bounds) = self.model.shadow_casters(toward);
        // A lamp among what it shadows (no single view holds it all) is seen from a cube.
        let (shadow, cube) = match &lamp {
            Some(l) => match lamp_view_proj(&shadow_bounds, l) {
                Some(s) => (s, None),
                None => (
                    (Mat4::IDENTITY, 1.0),
                    Some((l.position_m, point_shadow::cube_range_m(&shadow_bounds, l.position_m))),
                ),
            },
            None => (
                light_view_proj(
                    &shadow_bounds,
                    input.toward_light,
                    self.lighting.light_angular_radius_rad,
                ),
                None,
            ),
        };
        let mut cube_pass = self.lighting.shadows && cube.is_some() && self.lamp_cube_error.is_none();
        if cube_pass && self.point_shadow.size < point_shadow::POINT_SHADOW_SIZE {
            let device = self.gpu.device.clone();
            let made = checked(&device, "the lamp's shadow cube", || {
                point_shadow::PointShadowMap::new(&device, &self.shadow_layout, point_shadow::POINT_SHADOW_SIZE)
            });
            match made {
                Ok(map) => {
                    self.point_shadow = map;
                    self.remake_eye_binds();
                }
                // A device that cannot make it: such a lamp casts no shadow (as before the
                // cube), the frames go on, and the error is kept for the host to read.
                Err(e) => {
                    self.lamp_cube_error = Some(e);
                    cube_pass = false;
                }
            }
        }
        let mut uniforms: Vec<EyeUniform> = eyes.iter().map(|p| self.eye_uniform(p, input, shadow)).collect();
        let mut faces = None;
        if let Some((lamp_m, (near_m, far_m))) = cube {
            for u in &mut uniforms {
                u.shadow[1] = 0.0;
                u.lamp_shadow = [
                    near_m,
                    far_m,
                    self.point_shadow.size as f32,
                    f32::from(u8::from(cube_pass)),
                ];
            }
            if cube_pass {
                let views = point_shadow::cube_face_view_proj(lamp_m, near_m, far_m);
                self.point_shadow.write_faces(&self.gpu.queue, &views);
                faces = Some(views);
            }
        }
        // Glass filters the light of the one view, or of the lamp cube's six: drawn after the
        // shadows, with the same views.
        let on_cube = cube.is_some();
        let mut filter_pass = self.lighting.shadows && (!on_cube || cube_pass) && self.model.glass().next().is_some();
        let (size, layers) = if on_cube {
            (point_shadow::POINT_SHADOW_SIZE, 6)
        } else {
            (SHADOW_SIZE, 1)
        };
        let layers = self.gpu.array_layers(size, size, layers);
        let mut made_new = false;
        if filter_pass && self.filter(on_cube).size < size {
            let device = self.gpu.device.clone();
            // A device that cannot make it: glass casts no shadow (as before the filter) and the
            // frames go on.
            match checked(&device, "the shadow filter of glass", || {
                shadow_filter::ShadowFilter::new(&device, size, layers)
            }) {
                Ok(made) => {
                    *self.filter_for(on_cube) = made;
                    made_new = true;
                }
                Err(_) => filter_pass = false,
            }
        }
        if filter_pass {
            let device = self.gpu.device.clone();
            // Handles (reference-counted), so that the filter can be borrowed beside them.
            let (module, layout) = (self.scene.module.clone(), self.scene.shadow_masked_layout.clone());
            let filter = self.filter_for(on_cube);
            filter_pass = checked(&device, "the shadow filter's pipeline", || {
                filter.prepare(&device, &module, &layout)
            })
            .is_ok();
        }
        if filter_pass && (made_new || self.cube_filter_bound != on_cube) {
            self.cube_filter_bound = on_cube;
            self.remake_eye_binds();
        }
        if filter_pass {
            for u in &mut uniforms {
                u.shadow[3] = 1.0;
            }
        }
        let with_backdrop = self.prepare_backdrop(eyes.len());
        let (lm, rm) = method.matrices();
        let row = |m: [f32; 3]| [m[0], m[1], m[2], 0.0];
        let compose = ComposeUniform {
            left: lm.map(row),
            right: rm.map(row),
            params: [self.lighting.exposure, 0.0, 0.0, 0.0],
        };
        let fading = self.write_fades(input.fades);
        let queue = &self.gpu.queue;
        for (buffer, u) in self.eye_buffers.iter().zip(&uniforms) {
            queue.write_buffer(buffer, 0, bytemuck::bytes_of(u));
        }
        queue.write_buffer(&self.compose_buffer, 0, bytemuck::bytes_of(&compose));

        // Timed (where the device can) from the first pass's start to the composition's end.
        let timed = self.timer.as_mut().is_some_and(|t| t.start_frame());
        let timer = self.timer.as_ref().filter(|_| timed);
        let shadow_pass = self.lighting.shadows;
        let mut shadow_triangles = 0;
        let targets = self.targets.as_ref().expect("the caller sized the targets");
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        if shadow_pass {
            // Once per frame, for both eyes: one view, or the lamp cube's six, each drawing only
            // what lies in its frustum.
            let views: Vec<(&wgpu::TextureView, &wgpu::BindGroup, Option<Mat4>)> = match &faces {
                Some(faces) => self
                    .point_shadow
                    .face_views
                    .iter()
                    .zip(&self.point_shadow.face_binds)
                    .zip(faces)
                    .map(|((v, b), m)| (v, b, Some(*m)))
                    .collect(),
                None => vec![(&self.shadow_view, &self.shadow_bind, None)],
            };
            // Impostors cast the shadow of the polygon level as exact as they are.
            let shadow_levels = self.shadow_levels(input.levels);
            for (k, (view, bind, cull)) in views.into_iter().enumerate() {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("shadow"),
                    timestamp_writes: timer.filter(|_| k == 0).map(|t| t.writes(true, false)),
                    color_attachments: &[],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view,
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Clear(1.0),
                            store: wgpu::StoreOp::Store,
                        }),
                        stencil_ops: None,
                    }),
                    ..Default::default()
                });
                shadow_triangles +=
                    self.draw_shadow_casters(&mut pass, bind, &shadow_levels, floor_casts, cull.as_ref());
            }
            let filter = self.filter(on_cube);
            // Each view with its matrix, to draw only the glass its frustum reaches.
            let binds: Vec<(&wgpu::BindGroup, Option<Mat4>)> = match &faces {
                Some(faces) if on_cube => self.point_shadow.face_binds.iter().zip(faces.map(Some)).collect(),
                _ => vec![(&self.shadow_bind, None)],
            };
            for (view, (bind, cull)) in filter.layer_views.iter().zip(binds) {
                let Some(pipeline) = filter.pipeline().filter(|_| filter_pass) else {
                    break;
                };
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("shadow filter"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(shadow_filter::NOTHING_FILTERED),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    ..Default::default()
                });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, bind, &[]);
                let seen = |p: &GpuPrimitive| match (&cull, &p.bounds) {
                    (Some(m), Some(b)) => !point_shadow::outside_frustum(m, b),
                    _ => true,
                };
                for p in self.model.glass().filter(|p| seen(p)) {
                    pass.set_bind_group(1, &self.model.materials[p.material].bind, &[]);
                    p.draw(&mut pass, &shadow_levels);
                }
            }
        }
        self.shadow_triangles = shadow_triangles;
        let backdrop = targets.backdrop.as_ref().filter(|_| with_backdrop);
        for (i, u) in uniforms.iter().enumerate() {
            let first = i == 0 && !shadow_pass;
            // Reverse-Z depth, cleared to 0 (infinitely far); kept for the second half of the pass
            // where a backdrop is made between.
            let mut pass = begin_scene_pass(
                &mut encoder,
                &targets.hdr[i],
                &targets.depth,
                ScenePassPart::First {
                    timestamps: timer.filter(|_| first).map(|t| t.writes(true, false)),
                    keep_depth: backdrop.is_some(),
                },
            );
            pass.set_bind_group(0, &self.eye_bind[i], &[]);
            // Opaque and masked first; then blended, farthest first, as this eye sees them.
            let eye_at = Vec3::from_slice(&u.eye_pos[..3]);
            let mut blended: Vec<&GpuPrimitive> = Vec::new();
            let mut impostors_drawn: Vec<(usize, u32)> = Vec::new();
            for p in &self.model.primitives {
                if self.model.materials[p.material].variant.blend {
                    blended.push(p);
                } else if let Some(k) = fading.get(&p.source) {
                    // Both levels, each on its share of the pixels.
                    let new = input.levels.get(p.source).copied().unwrap_or(0);
                    let old = input.fades[*k].from;
                    let first = 2 * *k as u32 + 1;
                    for (level, instance) in [(new, first), (old, first + 1)] {
                        match self.impostor_of(p.source, level) {
                            Some(imp) if !impostors_drawn.contains(&(p.source, instance)) => {
                                impostors_drawn.push((p.source, instance));
                                self.draw_impostor(&mut pass, imp, instance);
                            }
                            Some(_) => {}
                            None => self.draw_fading(&mut pass, p, level, instance),
                        }
                    }
                } else if let Some(imp) = self.impostor_drawn_for(p, input.levels) {
                    // Once for the primitive, however many pieces it was uploaded in.
                    if !impostors_drawn.contains(&(p.source, 0)) {
                        impostors_drawn.push((p.source, 0));
                        self.draw_impostor(&mut pass, imp, 0);
                    }
                } else {
                    self.draw_primitive(&mut pass, p, input.levels, false);
                }
            }
            blended.sort_by(|a, b| {
                b.centre
                    .distance_squared(eye_at)
                    .total_cmp(&a.centre.distance_squared(eye_at))
            });
            // Glass that blurs or bends reads what is behind it from the eye's backdrop, made
            // just before the farthest such glass is drawn: of everything drawn until then (the
            // opaque scene and the blended surfaces farther away), in a pass of its own between
            // two of the scene's.
            let over_backdrop = backdrop.zip(self.backdrop_halver.as_ref());
            let mut backdrop_to_make = over_backdrop;
            for p in blended {
                if let Some((made, halver)) =
                    backdrop_to_make.take_if(|_| self.model.materials[p.material].variant.backdrop)
                {
                    drop(pass);
                    made.record(&mut encoder, halver, i);
                    pass = begin_scene_pass(
                        &mut encoder,
                        &targets.hdr[i],
                        &targets.depth,
                        ScenePassPart::OverBackdrop,
                    );
                    pass.set_bind_group(0, &self.eye_bind[i], &[]);
                }
                self.draw_primitive(&mut pass, p, input.levels, over_backdrop.is_some());
            }
        }
        // Bind group 0 composes the two eyes, 1 the first alone (mono).
        let bind = if uniforms.len() == 2 { 0 } else { 1 };
        crate::pipelines::draw_fullscreen(
            &mut encoder,
            "compose",
            target,
            &self.compose_pipelines[&format],
            &targets.compose_bind[bind],
            timer.map(|t| t.writes(false, true)),
        );
        if let Some(t) = timer {
            t.resolve(&mut encoder);
        }
        Ok(encoder)
    }
}

impl Renderer {
    /// The glass filter for a lamp's cube (`cube`) or for one view of the light.
    fn filter(&self, cube: bool) -> &shadow_filter::ShadowFilter {
        if cube { &self.cube_filter } else { &self.shadow_filter }
    }

    /// [`Self::filter`], to remake or prepare.
    fn filter_for(&mut self, cube: bool) -> &mut shadow_filter::ShadowFilter {
        if cube {
            &mut self.cube_filter
        } else {
            &mut self.shadow_filter
        }
    }

    /// Makes the eyes' backdrops for the current targets if the model has glass that blurs or
    /// bends (`backdrop`), drops them if it has none, and points the eyes' bind groups at what is
    /// there. Whether this frame draws with a backdrop: not where the device could not make one
    /// (such glass is then drawn with the plain filter; not tried again at that size).
    pub(crate) fn prepare_backdrop(&mut self, eyes: usize) -> bool {
        let needed = self.model.backdrop_needed();
        let halvings = needed == crate::gpu_model::BackdropNeeded::Blurred;
        let Some(targets) = self.targets.as_mut() else {
            return false;
        };
        let size = (targets.width, targets.height);
        let full = crate::backdrop::level_count(size.0, size.1);
        // None needed: the memory goes when the eyes' bind groups let go of it (below). One made
        // without the halvings now needed, or with those no longer needed, is made again.
        if needed == crate::gpu_model::BackdropNeeded::None
            || targets
                .backdrop
                .as_ref()
                .is_some_and(|b| (b.level_count == full) != halvings)
        {
            targets.backdrop = None;
        }
        let missing = |b: &Option<crate::backdrop::Backdrop>| {
            b.as_ref().is_none_or(|b| (0..eyes).any(|eye| b.view(eye).is_none()))
        };
        if needed != crate::gpu_model::BackdropNeeded::None
            && missing(&targets.backdrop)
            && self.backdrop_failed != Some(size)
        {
            let device = self.gpu.device.clone();
            if self.backdrop_halver.is_none() {
                self.backdrop_halver = checked(&device, "the backdrop's pipeline", || {
                    crate::backdrop::Halver::new(&device)
                })
                .ok();
            }
            if let Some(halver) = &self.backdrop_halver {
                let hdr = &targets.hdr;
                let backdrop = targets
                    .backdrop
                    .get_or_insert_with(|| crate::backdrop::Backdrop::new(size, halvings));
                let made = checked(&device, "the eyes' backdrops", || {
                    for (eye, target) in hdr.iter().enumerate().take(eyes) {
                        backdrop.make_eye(&device, halver, target, eye);
                    }
                });
                if made.is_err() {
                    targets.backdrop = None;
                    self.backdrop_failed = Some(size);
                }
            }
        }
        if self.backdrop().map_or(0, |b| b.id) != self.backdrop_bound {
            self.remake_eye_binds();
        }
        self.backdrop()
            .is_some_and(|b| (0..eyes).all(|eye| b.view(eye).is_some()))
    }

    /// Draws what casts shadows into a shadow pass whose light matrix `bind` holds: opaque
    /// materials, then masked ones cut out (blended ones cast none); the floor only when
    /// `floor_casts`; with `cull` (that matrix), only pieces whose bounds reach its frustum.
    /// Returns the triangles drawn.
    pub(crate) fn draw_shadow_casters(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        bind: &wgpu::BindGroup,
        levels: &[u8],
        floor_casts: bool,
        cull: Option<&Mat4>,
    ) -> u64 {
        pass.set_pipeline(&self.shadow_pipeline);
        pass.set_bind_group(0, bind, &[]);
        let variant = |p: &GpuPrimitive| self.model.materials[p.material].variant;
        let seen = |p: &GpuPrimitive| match (cull, &p.bounds) {
            (Some(m), Some(b)) => !point_shadow::outside_frustum(m, b),
            _ => true,
        };
        let mut triangles = 0;
        for p in self.model.primitives.iter().filter(|p| {
            let v = variant(p);
            !v.blend && !v.mask && (floor_casts || !p.is_floor) && seen(p)
        }) {
            p.draw(pass, levels);
            triangles += p.triangles_at(levels);
        }
        let mut masked = self
            .model
            .primitives
            .iter()
            .filter(|p| variant(p).casts_masked_shadow() && (floor_casts || !p.is_floor) && seen(p))
            .peekable();
        if masked.peek().is_some() {
            // Made with the model (`ScenePipelines::prepare`); a miss would be our bug, and
            // those surfaces then cast no shadow rather than panic mid-frame.
            match &self.scene.shadow_masked {
                Some(pipeline) => {
                    pass.set_pipeline(pipeline);
                    for p in masked {
                        pass.set_bind_group(1, &self.model.materials[p.material].bind, &[]);
                        p.draw(pass, levels);
                        triangles += p.triangles_at(levels);
                    }
                }
                None => debug_assert!(false, "no shadow pipeline for masked materials"),
            }
        }
        triangles
    }

    /// Triangles the last frame's shadow passes drew: the model's casters once for a light's
    /// map, for a lamp's cube those each face's frustum reaches (a piece across two faces
    /// counts twice); 0 without shadows.
    pub fn shadow_triangles_last_frame(&self) -> u64 {
        self.shadow_triangles
    }

    /// Why the device could not make the cube of shadow views a lamp among its casters needs,
    /// if it could not: such a lamp then casts no shadow and the frames go on.
    pub fn lamp_cube_error(&self) -> Option<&RenderError> {
        self.lamp_cube_error.as_ref()
    }

    /// `levels` with each impostor drawn replaced by the level its shadow is cast with.
    pub(crate) fn shadow_levels<'l>(&self, levels: &'l [u8]) -> std::borrow::Cow<'l, [u8]> {
        if self.model.impostors.is_empty() {
            return std::borrow::Cow::Borrowed(levels);
        }
        levels
            .iter()
            .enumerate()
            .map(|(source, &l)| match self.model.impostors.get(source) {
                Some(Some(imp)) if l == IMPOSTOR_LEVEL => imp.shadow_level,
                _ => l,
            })
            .collect::<Vec<u8>>()
            .into()
    }

    /// The impostor `levels` draws for `p` in place of its triangles, if any.
    pub(crate) fn impostor_drawn_for(&self, p: &GpuPrimitive, levels: &[u8]) -> Option<&impostor::GpuImpostor> {
        self.impostor_of(p.source, levels.get(p.source).copied()?)
    }

    /// Primitive `source`'s impostor, if `level` is [`IMPOSTOR_LEVEL`] and it has one.
    pub(crate) fn impostor_of(&self, source: usize, level: u8) -> Option<&impostor::GpuImpostor> {
        if level != IMPOSTOR_LEVEL {
            return None;
        }
        self.model.impostors.get(source)?.as_ref()
    }

    /// Writes this frame's cross-fades into the instance buffer (growing it when needed) and
    /// returns, by primitive, the index of its fade in `fades`. A fade of a primitive past the
    /// model, or a second one of a primitive, is ignored.
    pub(crate) fn write_fades(&mut self, fades: &[LevelFade]) -> std::collections::HashMap<usize, usize> {
        let mut by_primitive = std::collections::HashMap::new();
        if fades.is_empty() {
            // Entry 0 (no fade) is zero from the buffer's creation and every write.
            return by_primitive;
        }
        let mut data: Vec<[f32; 2]> = vec![[0.0, 0.0]; 2 * fades.len() + 1];
        for (k, f) in fades.iter().enumerate() {
            let source = f.primitive as usize;
            if !self.model.primitives.iter().any(|p| p.source == source) || by_primitive.contains_key(&source) {
                continue;
            }
            let shown = if f.shown.is_finite() {
                f.shown.clamp(0.0, 1.0)
            } else {
                1.0
            };
            data[2 * k + 1] = [shown, 1.0];
            data[2 * k + 2] = [shown, -1.0];
            by_primitive.insert(source, k);
        }
        let needed = data.len() as u64;
        if needed > self.fade_entries {
            self.fade_entries = needed.next_power_of_two();
            self.fade_buffer = fade_instance_buffer(&self.gpu.device, self.fade_entries);
        }
        self.gpu
            .queue
            .write_buffer(&self.fade_buffer, 0, bytemuck::cast_slice(&data));
        by_primitive
    }

    /// Draws `p` at `level` as one side of a cross-fade (instance `instance` of the fades'
    /// buffer).
    pub(crate) fn draw_fading(&self, pass: &mut wgpu::RenderPass<'_>, p: &GpuPrimitive, level: u8, instance: u32) {
        let m = &self.model.materials[p.material];
        let variant = MaterialVariant {
            fade: true,
            ..m.variant
        };
        let Some(pipeline) = self.scene.get(&variant) else {
            // Made with the model for every primitive with levels; without it, the new level
            // alone (a switch without the fade).
            if instance % 2 == 1 {
                self.draw_primitive(pass, p, &[level], false);
            }
            return;
        };
        pass.set_pipeline(pipeline);
        pass.set_bind_group(1, &m.bind, &[]);
        pass.set_vertex_buffer(1, self.fade_buffer.slice(..));
        p.draw_at(pass, level, instance);
    }

    /// Draws `p` (each of its material's draws, `MaterialVariant::draws`); `with_backdrop`: the
    /// eye's backdrop is made this frame.
    pub(crate) fn draw_primitive(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        p: &GpuPrimitive,
        levels: &[u8],
        with_backdrop: bool,
    ) {
        let m = &self.model.materials[p.material];
        pass.set_bind_group(1, &m.bind, &[]);
        for variant in m.variant.draws(with_backdrop) {
            // Every material's variants were prepared with its model; a miss would be our bug,
            // and skipping the draw beats a panic in the middle of a frame.
            let Some(pipeline) = self.scene.get(&variant) else {
                debug_assert!(false, "no pipeline for {variant:?}");
                continue;
            };
            pass.set_pipeline(pipeline);
            p.draw(pass, levels);
        }
    }
}

/// Which part of an eye's scene pass [`begin_scene_pass`] begins.
pub(crate) enum ScenePassPart<'a> {
    /// The whole pass, or its first half: colour cleared to the background, depth to 0
    /// (reverse-Z: infinitely far), timestamps if the frame's first pass; its depth kept only
    /// where a second half follows (`keep_depth`).
    First {
        timestamps: Option<wgpu::RenderPassTimestampWrites<'a>>,
        keep_depth: bool,
    },
    /// The second half, after the backdrop was made: what the first drew loaded, depth let go.
    OverBackdrop,
}

/// Begins an eye's scene pass into `hdr` with depth in `depth`.
pub(crate) fn begin_scene_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    hdr: &wgpu::TextureView,
    depth: &wgpu::TextureView,
    part: ScenePassPart<'_>,
) -> wgpu::RenderPass<'e> {
    let (label, colour_load, depth_load, depth_store, timestamp_writes) = match part {
        ScenePassPart::First { timestamps, keep_depth } => (
            "scene",
            wgpu::LoadOp::Clear(CLEAR_RADIANCE),
            wgpu::LoadOp::Clear(0.0),
            if keep_depth {
                wgpu::StoreOp::Store
            } else {
                wgpu::StoreOp::Discard
            },
            timestamps,
        ),
        ScenePassPart::OverBackdrop => (
            "scene, over the backdrop",
            wgpu::LoadOp::Load,
            wgpu::LoadOp::Load,
            wgpu::StoreOp::Discard,
            None,
        ),
    };
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        timestamp_writes,
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: hdr,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: colour_load,
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: depth,
            depth_ops: Some(wgpu::Operations {
                load: depth_load,
                store: depth_store,
            }),
            stencil_ops: None,
        }),
        ..Default::default()
    })
}

/// The cross-fades' instance buffer's first size (entries): 31 fades at once; it grows when a
/// frame has more.
pub(crate) const FADE_ENTRIES_AT_FIRST: u64 = 64;

pub(crate) fn fade_instance_buffer(device: &wgpu::Device, entries: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("cross-fades"),
        size: entries * 8,
        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}
