//! Drawing a frame: the newest sensors and face turned into each eye's projection, levels of
//! detail chosen for the frame budget, the screens drawn over it, presented or kept offscreen.

#[cfg(feature = "ui")]
use super::screens::MIN_SCREEN_PT;
use super::screens::OverlayPaint;
#[cfg(feature = "ui")]
use super::screens::Page;
use super::{Engine, EngineError, Snapshot, Target};
#[cfg(feature = "ui")]
use crate::anaglyph::Method;
#[cfg(feature = "ui")]
use crate::artifacts::LoadStatus;
use crate::render::FrameInput;
#[cfg(feature = "ui")]
use crate::render::Gpu;
use crate::surface::{DrawOutcome, SurfaceStats};
#[cfg(feature = "ui")]
use crate::wgpu;
use glam::Vec3;

pub(super) fn add_surface_stats(a: SurfaceStats, b: SurfaceStats) -> SurfaceStats {
    SurfaceStats {
        presented: a.presented + b.presented,
        skipped: a.skipped + b.skipped,
        reconfigured: a.reconfigured + b.reconfigured,
        recreated: a.recreated + b.recreated,
        resumed: a.resumed + b.resumed,
        suspended: a.suspended + b.suspended,
    }
}

/// The sRGB colours of a method's two filters, left eye's first, for the glasses check: each
/// passes through its own filter only. `None` for mono (no glasses).
#[cfg(feature = "ui")]
pub(super) fn filter_colours(method: Method) -> Option<([u8; 3], [u8; 3])> {
    match method {
        Method::Mono => None,
        Method::DuboisGreenMagenta => Some(([0, 255, 0], [255, 0, 255])),
        Method::DuboisAmberBlue => Some(([255, 190, 0], [0, 0, 255])),
        Method::DuboisRedCyan | Method::HalfColor | Method::Optimized | Method::Gray | Method::Color => {
            Some(([255, 0, 0], [0, 255, 255]))
        }
    }
}

/// `width × height` sRGB RGBA pixels (rows top to bottom, as the engine's frames) as a PNG
/// file's bytes: what the share sheet, the gallery's cache and `phantogram render` write.
pub fn encode_png(width: u32, height: u32, rgba: &[u8]) -> Result<Vec<u8>, image::ImageError> {
    let mut png = Vec::new();
    image::write_buffer_with_format(
        &mut std::io::Cursor::new(&mut png),
        rgba,
        width,
        height,
        image::ExtendedColorType::Rgba8,
        image::ImageFormat::Png,
    )?;
    Ok(png)
}

/// What the renderer draws for a frame the session computed, with the mesh moved by `offset`
/// (containment's push-back). Without any orientation yet, the device is taken as lying flat
/// facing north. (Here, not in the renderer: the renderer knows nothing of the sensors.)
pub fn frame_input(view: &crate::session::FrameView, offset: Vec3) -> FrameInput<'_> {
    FrameInput {
        left: &view.left,
        right: &view.right,
        mono: &view.mono,
        toward_light: view.toward_light_device,
        device_to_world: view.device_to_world.unwrap_or(glam::Quat::IDENTITY),
        offset,
        levels: &[],
        fades: &[],
    }
}

impl Engine {
    /// Each eye's image to the filter that is really in front of it: swapped when the glasses
    /// check found the glasses on the other way round.
    pub(super) fn oriented<'a>(&self, mut input: FrameInput<'a>) -> FrameInput<'a> {
        if self.calibration.glasses_swapped {
            std::mem::swap(&mut input.left, &mut input.right);
        }
        input
    }

    /// What the renderer draws for `view` with the mesh moved by `offset`: each eye's image to
    /// its filter ([`Self::oriented`]), and the directional light from the room's sun where the
    /// configured environment has one ([`EngineConfig::sun_from_environment`](super::EngineConfig::sun_from_environment))
    /// and the room's own live light is not shown instead: towards the sun, in its colour,
    /// strength and width (the session's world light, anchored over the viewer's shoulder,
    /// otherwise).
    pub(super) fn scene_input<'a>(&mut self, view: &'a crate::session::FrameView, offset: Vec3) -> FrameInput<'a> {
        let mut input = self.oriented(frame_input(view, offset));
        if let Some(sun) = self.static_sun {
            let live_room = self.room_light_on() && self.room_light_shown.is_some();
            let lighting = &mut self.renderer.lighting;
            if live_room {
                let key = crate::render::Lighting::default();
                lighting.light_rgb = key.light_rgb;
                lighting.light_angular_radius_rad = key.light_angular_radius_rad;
            } else {
                // The sun is fixed in the room: into the device frame as the device turns.
                input.toward_light = input.device_to_world.inverse() * sun.toward;
                lighting.light_rgb = Vec3::from(sun.irradiance_rgb) * lighting.environment_intensity;
                lighting.light_angular_radius_rad = sun.half_angle_rad();
            }
        }
        input
    }

    /// Draws one frame that will be on screen at `display_t_ns` (sensor clock; `None`: for the
    /// newest sensor state, no prediction). A GPU device that was lost is replaced first, with
    /// the scene made again on the new one (`device_loss`; counted in
    /// [`EngineStats::devices_recovered`](super::EngineStats)).
    pub fn draw(&mut self, display_t_ns: Option<i64>) -> Result<DrawOutcome, EngineError> {
        if self.renderer.gpu().poll_lost() {
            self.recover_lost_device()?;
        }
        if let Some(prepared) = self.loader.poll() {
            self.install(prepared);
        }
        if let Some(g) = display_t_ns.and_then(|t| self.gestures.poll(t)) {
            self.apply_gesture(g);
        }
        if matches!(self.target, Target::Detached) {
            self.stats.frames_skipped += 1;
            return Ok(DrawOutcome::Skipped("suspended"));
        }
        self.take_face_result();
        let view = self.session.frame_at(display_t_ns)?;
        let dt_s = match (self.last_display_t_ns, display_t_ns) {
            (Some(a), Some(b)) if b > a => ((b - a) as f32 * 1e-9).min(0.1),
            _ => 1.0 / 60.0,
        };
        if display_t_ns.is_some() {
            self.last_display_t_ns = display_t_ns;
        }
        let push = match self.diorama.as_deref_mut() {
            // The Diorama keeps its bodies inside the eyes' pyramids itself (its own
            // containment, per body): the scene is not pushed back as a whole.
            Some(scene) => {
                let t_ns = display_t_ns.or(view.sensor_t_ns).unwrap_or(0);
                scene.update(&view, self.session.newest_specific_force(), t_ns);
                self.renderer.update_vertices(scene.model())?;
                0.0
            }
            None => self
                .smoother
                .follow(&self.bounds, &view.stereo_eyes_m(), &self.session.config().screen, dt_s),
        };
        self.last_push_m = push;
        self.last_mono = Some(view.mono);
        self.update_room_light(view.device_to_world);
        self.last_device_to_world = view.device_to_world;
        let centre = (self.bounds.min + self.bounds.max) * 0.5 + Vec3::Z * -push;
        self.renderer.lamp = self.lamp.as_mut().map(|l| l.lamp(view.device_to_world, centre));
        let input = self.scene_input(&view, Vec3::Z * -push);
        self.follow_seen_sides(&view, centre, display_t_ns);
        let levels = self.choose_levels(&input);
        let fades = match self.detail.as_mut() {
            Some(d) => d.fade(display_t_ns.map(|t| t as f64 * 1e-9)),
            None => Vec::new(),
        };
        let input = FrameInput {
            levels: &levels,
            fades: &fades,
            ..input
        };
        self.stats.eyes_from_camera = matches!(self.session.eye_source(), crate::eyetrack::EyeSource::Camera);
        let started = std::time::Instant::now();
        let outcome = self.draw_input(&input);
        // A frame that baked impostors took longer than the budget's choice made it: it says
        // nothing about the budget.
        let baked = std::mem::take(&mut self.baked_this_frame);
        if let (Some(detail), Ok(DrawOutcome::Presented), false) = (self.detail.as_mut(), &outcome, baked) {
            // GPU time where the device measures it (each reading once, when it arrives); the
            // frame's wall time otherwise.
            if self.renderer.times_gpu() {
                if let Some(gpu_s) = self.renderer.take_gpu_time_s() {
                    detail.frame_took(gpu_s);
                }
            } else {
                detail.frame_took(started.elapsed().as_secs_f64());
            }
        }
        outcome
    }

    /// Marks what this frame's view shows of the artifact (centred at `centre`, device frame)
    /// and takes the hint toward an unseen side. Needs display times: without them (frames
    /// drawn on request) no one can be said to linger.
    pub(super) fn follow_seen_sides(
        &mut self,
        view: &crate::session::FrameView,
        centre: Vec3,
        display_t_ns: Option<i64>,
    ) {
        self.side_hint = None;
        let (Some(seen), Some(t_ns)) = (self.seen.as_mut(), display_t_ns) else {
            return;
        };
        let [left, right] = view.stereo_eyes_m();
        let t_s = t_ns as f64 * 1e-9;
        seen.look((left + right) * 0.5 - centre, t_s);
        self.side_hint = seen.hint(t_s);
    }

    /// The hint toward an unseen side shown this frame, if any (see [`EngineConfig::side_hints`](super::EngineConfig::side_hints)).
    pub fn side_hint(&self) -> Option<phantogram_detail::seen::Hint> {
        self.side_hint
    }

    /// Each part's level of detail for the frame `input` shows (empty: all at full detail).
    /// First bakes a few of the impostors the last choice would have drawn.
    pub(super) fn choose_levels(&mut self, input: &FrameInput) -> Vec<u8> {
        let Some(detail) = self.detail.as_mut() else {
            return Vec::new();
        };
        // A failed bake stops the baking: the parts without impostors keep their polygons, and
        // the picture is the same.
        let baked = self.impostors.step(&mut self.renderer, detail);
        self.baked_this_frame = baked.is_ok_and(|n| n > 0);
        let eyes = input.eyes_drawn(self.method);
        detail.choose(&eyes, input.offset, None).to_vec()
    }

    /// The frame time the budget for big scans aims at, seconds (default
    /// [`DEFAULT_FRAME_TARGET_S`](super::DEFAULT_FRAME_TARGET_S)): their parts' levels of detail follow the measured frame
    /// times towards it. Not a finite positive number: unchanged.
    pub fn set_frame_target_s(&mut self, target_s: f64) {
        if target_s.is_finite() && target_s > 0.0 {
            self.frame_target_s = target_s;
            if let Some(d) = self.detail.as_mut() {
                d.set_target(target_s);
            }
        }
    }

    /// The big scan's impostors: baked, planned and not baked (each is baked once the chooser
    /// would draw it, a few a frame), and the GPU memory of those baked, bytes
    /// ([`crate::impostors`]).
    pub fn impostor_progress(&self) -> (usize, usize, u64) {
        (
            self.impostors.baked(),
            self.impostors.pending(),
            self.impostors.baked_bytes(),
        )
    }

    /// What the big scan's chooser did in the last frame: triangles drawn per eye, the budget,
    /// and switches (`None` for a model drawn whole).
    pub fn detail_stats(&self) -> Option<(phantogram_detail::ChoiceStats, u64)> {
        self.detail.as_ref().map(|d| (d.last_choice(), d.budget_triangles()))
    }

    /// The screens (when a page or the banner is up) and the frame, presented.
    pub(super) fn draw_input(&mut self, input: &FrameInput) -> Result<DrawOutcome, EngineError> {
        let input = *input;
        #[cfg(feature = "ui")]
        {
            self.open_pending_camera_page();
            if self.menu_open() {
                self.take_thumbnails();
            }
            let page_open = self.screens.as_ref().is_some_and(|s| s.page.is_some());
            let status = self.loader.status();
            if page_open || status != LoadStatus::Idle || self.side_hint.is_some() {
                return self.draw_with_screens(&input, status);
            } else if let Some(screens) = self.screens.as_mut() {
                screens.banner_pt = None;
                screens.banner_button_pt = None;
            }
            // The bare picture: one thing for a screen reader to land on.
            let picture = self.picture_access_node();
            self.access.replace(picture.into_iter().collect());
        }
        self.present(&input, None)
    }

    /// Draws `input` to the target, `overlay` painted over the composed frame before it is
    /// presented or read back, and counts the outcome.
    pub(super) fn present(
        &mut self,
        input: &FrameInput,
        overlay: Option<&mut OverlayPaint<'_>>,
    ) -> Result<DrawOutcome, EngineError> {
        let outcome = match &mut self.target {
            Target::Detached => DrawOutcome::Skipped("suspended"),
            Target::Window(host) => match overlay {
                Some(paint) => {
                    host.draw_with(&mut self.renderer, input, self.method, |g, v, f, s| paint(g, v, f, s))?
                }
                None => host.draw(&mut self.renderer, input, self.method)?,
            },
            Target::Offscreen { width, height } => {
                let (w, h) = (*width, *height);
                if w == 0 || h == 0 {
                    DrawOutcome::Skipped("zero-sized")
                } else {
                    let pixels = match overlay {
                        Some(paint) => self
                            .renderer
                            .render_with_overlay(input, self.method, w, h, |g, v, f, s| paint(g, v, f, s))?,
                        None => self.renderer.render(input, self.method, w, h)?,
                    };
                    self.last_frame = Some((w, h, pixels));
                    DrawOutcome::Presented
                }
            }
        };
        match outcome {
            DrawOutcome::Presented => self.stats.frames_drawn += 1,
            DrawOutcome::Skipped(_) => self.stats.frames_skipped += 1,
        }
        Ok(outcome)
    }

    /// [`Self::draw`] with the screens over the frame: one egui frame with the touches since the
    /// last (the open page, then the status banner over it), painted over the picture, then what
    /// the viewer chose is applied.
    #[cfg(feature = "ui")]
    pub(super) fn draw_with_screens(
        &mut self,
        input: &FrameInput,
        status: LoadStatus,
    ) -> Result<DrawOutcome, EngineError> {
        use crate::calibration_ui::menu::{Banner, BannerAction, show_banner};
        let size = self.target_size();
        // Nothing to lay the screens out on: the plain draw skips (and counts) the frame.
        let (w, h) = match size {
            Some((w, h)) if w > 0 && h > 0 => (w, h),
            _ => return self.present(input, None),
        };
        let ppp = self.pixels_per_point();
        let screen = self.session.config().screen;
        let current = self.model_info.artifact.as_ref().map(|a| a.id.to_string());
        self.screens();
        // Out of `self` while the frame is drawn, which the painter needs them for.
        let Some(mut screens) = self.screens.take() else {
            return self.present(input, None);
        };
        screens.ctx.set_pixels_per_point(ppp);
        // AccessKit nodes for the screen readers, every frame (a flag; egui re-enables nothing
        // by itself after the context is made anew).
        screens.ctx.enable_accesskit();
        // On a sliver of a surface (split screen, mid-resize) the screens are laid out at a
        // least size and cut off at its edges, rather than squeezed into negative widths
        // (egui asserts on those; found by the random JNI calls on a 1-pixel surface).
        let raw = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(
                egui::Pos2::ZERO,
                egui::vec2((w as f32 / ppp).max(MIN_SCREEN_PT), (h as f32 / ppp).max(MIN_SCREEN_PT)),
            )),
            events: std::mem::take(&mut screens.events),
            ..Default::default()
        };
        let banner = match status {
            LoadStatus::Idle => None,
            LoadStatus::Loading { title, fraction } => Some(Banner::Loading { title, fraction }),
            LoadStatus::Failed { title, message } => Some(Banner::Failed { title, message }),
        };
        let (mut calibration_actions, mut menu_actions) = (Vec::new(), Vec::new());
        let mut welcome_actions = Vec::new();
        let mut settings_actions = Vec::new();
        let mut material_actions = Vec::new();
        let filters = filter_colours(self.method);
        let camera_glasses = self.last_glasses;
        let mut card_closed = false;
        // Only the menu says how the eyes are found.
        let eyes_status = match &screens.page {
            Some(Page::Menu(_)) => self.eyes_status(),
            _ => String::new(),
        };
        let annotations = &self.model_info.annotations;
        // The hint only over the bare picture: in the picture's axes (x right, y down).
        let side_hint = self.side_hint.filter(|_| screens.page.is_none()).map(|h| {
            let toward = glam::Vec3::new(h.toward.x, h.toward.y, 0.0);
            [toward.dot(screen.right_device()), -toward.dot(screen.up_device())]
        });
        let mut banner_action = None;
        let mut banner_pt = None;
        let mut banner_button_pt = None;
        let (page, items) = (&mut screens.page, &screens.items);
        let mut output = screens.ctx.run_ui(raw, |root| {
            match page {
                Some(Page::Calibration(ui)) => calibration_actions = ui.show(root, &screen, ppp),
                Some(Page::Menu(menu)) => menu_actions = menu.show(root, items, current.as_deref(), &eyes_status),
                Some(Page::Help) => {
                    card_closed = crate::calibration_ui::menu::show_annotation(
                        root.ctx(),
                        "How to use it",
                        crate::calibration_ui::menu::GESTURE_HELP,
                    )
                    .0
                }
                Some(Page::Welcome(welcome)) => {
                    welcome.camera_glasses = camera_glasses;
                    welcome_actions = welcome.show(root, filters)
                }
                Some(Page::Settings(settings)) => settings_actions = settings.show(root),
                Some(Page::Material(material)) => material_actions = material.show(root),
                Some(Page::Annotation(i)) => match annotations.get(*i) {
                    Some(a) => {
                        card_closed = crate::calibration_ui::menu::show_annotation(root.ctx(), &a.title, &a.lead).0
                    }
                    None => card_closed = true,
                },
                None => {
                    if let Some(toward) = side_hint {
                        crate::calibration_ui::side_hint::show_side_hint(root.ctx(), toward, 16.0);
                    }
                }
            }
            if let Some(b) = &banner {
                let (action, area, button) = show_banner(root.ctx(), b);
                banner_action = action;
                banner_pt = Some(area);
                banner_button_pt = Some(button);
            }
        });
        screens.banner_pt = banner_pt;
        screens.banner_button_pt = banner_button_pt;
        if let Some(update) = output.platform_output.accesskit_update.take() {
            let mut nodes = self.access.flatten(&update, ppp);
            if screens.page.is_none()
                && let Some(picture) = self.picture_access_node()
            {
                // Under a banner or the hint, the picture is still there to land on (first).
                nodes.insert(0, picture);
            }
            // Once, with the picture in: the generation moves only when the nodes do.
            self.access.replace(nodes);
        }
        screens.overlay.begin(&mut output);
        let drawn = {
            let ctx = screens.ctx.clone();
            let overlay = &mut screens.overlay;
            let mut paint = |gpu: &Gpu, view: &wgpu::TextureView, format: wgpu::TextureFormat, size: [u32; 2]| {
                // egui's painter panics on a device lost since the frame began; the next frame
                // draws on a new one.
                if !gpu.is_lost() {
                    overlay.paint(gpu, &ctx, &mut output, view, format, size);
                }
            };
            self.present(input, Some(&mut paint))
        };
        // Also after a failed draw: what it did not upload is kept for the next frame.
        let fresh_context = screens.overlay.end(&mut output);
        self.screens = Some(screens);
        if fresh_context {
            self.fresh_screens_context();
        }
        let outcome = drawn?;
        for action in calibration_actions {
            self.apply_calibration_action(action);
        }
        for action in menu_actions {
            self.apply_menu_action(action);
        }
        if card_closed {
            self.set_page(None);
        }
        for action in welcome_actions {
            self.apply_welcome_action(action);
        }
        for action in settings_actions {
            self.apply_settings_action(action);
        }
        for action in material_actions {
            match action {
                crate::calibration_ui::material::MaterialAction::Changed(a) => {
                    if let Err(e) = self.set_appearance(a) {
                        // Shown all the same; the banner says it will not be remembered.
                        self.loader.fail(self.model_info.name.clone(), e.to_string());
                    }
                }
                crate::calibration_ui::material::MaterialAction::Close => self.set_page(None),
            }
        }
        match banner_action {
            Some(BannerAction::Cancel) => self.cancel_loading(),
            Some(BannerAction::Dismiss) => self.dismiss_message(),
            None => {}
        }
        Ok(outcome)
    }

    #[cfg(feature = "face")]
    pub(super) fn take_face_result(&mut self) {
        let newest = self.face.as_ref().and_then(|f| f.newest());
        if let Some(obs) = newest.filter(|o| self.last_face_t_ns != Some(o.capture_t_ns)) {
            self.last_face_t_ns = Some(obs.capture_t_ns);
            if obs.eyes_m.is_some() {
                self.last_glasses = obs.glasses;
            }
            self.session.observe_face(obs);
        }
    }

    #[cfg(not(feature = "face"))]
    pub(super) fn take_face_result(&mut self) {
        let _ = self.last_face_t_ns;
    }

    /// The current view as a picture to share, at the target's size (the screen's when
    /// detached), without the screens drawn over it: width, height and sRGB RGBA pixels.
    pub fn snapshot(&mut self, kind: Snapshot) -> Result<(u32, u32, Vec<u8>), EngineError> {
        let screen = self.session.config().screen;
        let (w, h) = self
            .target_size()
            .filter(|&(w, h)| w > 0 && h > 0)
            .unwrap_or((screen.width_px(), screen.height_px()));
        let view = self.session.frame_at(self.last_display_t_ns)?;
        let input = self.scene_input(&view, Vec3::Z * -self.last_push_m);
        Ok(match kind {
            Snapshot::Composed => (w, h, self.renderer.render(&input, self.method, w, h)?),
            Snapshot::SideBySide => (w * 2, h, self.renderer.render_side_by_side(&input, w, h)?),
        })
    }

    /// [`Self::snapshot`] as a PNG file's bytes, for the platform's share sheet.
    pub fn snapshot_png(&mut self, kind: Snapshot) -> Result<Vec<u8>, EngineError> {
        let (w, h, pixels) = self.snapshot(kind)?;
        encode_png(w, h, &pixels).map_err(|e| EngineError::Share(e.to_string()))
    }

    /// The last offscreen frame: width, height and 8-bit sRGB RGBA pixels, rows top to bottom.
    pub fn last_frame(&self) -> Result<(u32, u32, &[u8]), EngineError> {
        self.last_frame
            .as_ref()
            .map(|(w, h, p)| (*w, *h, p.as_slice()))
            .ok_or(EngineError::NoFrame)
    }
}
