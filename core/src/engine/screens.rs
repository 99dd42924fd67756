//! The screens drawn over the frame (welcome, menu, settings, calibration pages, annotations):
//! which is open, their actions, their accessibility nodes, and the requests they make of the
//! shell (camera permission, file picker).

#[cfg(feature = "ui")]
use super::Snapshot;
use super::{Engine, EngineError, ShellRequest};
#[cfg(feature = "ui")]
use crate::gesture::TouchPhase;
use crate::{render::Gpu, wgpu};
use glam::Vec3;

/// The least width and height, in points, the screens are laid out on (see
/// `draw_with_screens`): any real phone window is larger.
#[cfg(feature = "ui")]
pub(super) const MIN_SCREEN_PT: f32 = 240.0;

/// The text scales the screens follow ([`Engine::set_text_scale`]): Android's smallest font
/// size to twice the default.
pub const TEXT_SCALE_RANGE: std::ops::RangeInclusive<f32> = 0.85..=2.0;

/// Paints over a composed frame: the GPU, the frame's view, its format and size.
pub(super) type OverlayPaint<'a> = dyn FnMut(&Gpu, &wgpu::TextureView, wgpu::TextureFormat, [u32; 2]) + 'a;

/// Which full screen is open over the picture.
#[cfg(feature = "ui")]
pub(super) enum Page {
    Menu(crate::calibration_ui::menu::MenuUi),
    Calibration(crate::calibration_ui::CalibrationUi),
    /// The card of the annotation with this index in [`ModelInfo::annotations`].
    Annotation(usize),
    /// What the gestures do.
    Help,
    Welcome(crate::calibration_ui::welcome::WelcomeUi),
    Settings(crate::calibration_ui::settings::SettingsUi),
    Material(crate::calibration_ui::material::MaterialUi),
}

/// The screens' state on the render thread: the page open (if any), egui's context, the touches
/// waiting for the next frame, and the overlay painter (made with the first frame drawn).
#[cfg(feature = "ui")]
pub(super) struct Screens {
    pub(super) page: Option<Page>,
    /// The gallery's items, read from the library when the menu opens and after a change.
    pub(super) items: Vec<crate::calibration_ui::menu::MenuItem>,
    pub(super) ctx: egui::Context,
    pub(super) events: Vec<egui::Event>,
    pub(super) overlay: crate::calibration_ui::OverlayHost,
    /// The finger that drives the screens: the first one down; others are ignored.
    pub(super) pointer: Option<i32>,
    /// The status banner's rectangle in the last frame (points), while one shows: a touch that
    /// starts there is the banner's, any other the gestures'.
    pub(super) banner_pt: Option<egui::Rect>,
    /// The gallery's pictures as egui textures, by artifact id.
    pub(super) thumbnail_textures: std::collections::HashMap<String, egui::TextureHandle>,
    /// The banner's button (Cancel or OK) in the last frame, points.
    pub(super) banner_button_pt: Option<egui::Rect>,
}

#[cfg(feature = "ui")]
impl Screens {
    /// One touch, in points, as egui's pointer: the first finger down drives it.
    pub(super) fn touch(&mut self, phase: TouchPhase, pointer_id: i32, x_pt: f32, y_pt: f32) {
        if !(x_pt.is_finite() && y_pt.is_finite()) {
            return;
        }
        let button = |pos, pressed| egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::default(),
        };
        let pos = egui::pos2(x_pt, y_pt);
        // Every finger as egui's touch too: egui scrolls by dragging only once it has seen a
        // touch screen (`DragScroll::OnTouch`), so without these no panel scrolls under a finger.
        let touch_phase = match phase {
            TouchPhase::Down => egui::TouchPhase::Start,
            TouchPhase::Move => egui::TouchPhase::Move,
            TouchPhase::Up => egui::TouchPhase::End,
            TouchPhase::Cancel => egui::TouchPhase::Cancel,
        };
        self.events.push(egui::Event::Touch {
            device_id: egui::TouchDeviceId(0),
            id: egui::TouchId(u64::from(pointer_id as u32)),
            phase: touch_phase,
            pos,
            force: None,
        });
        match phase {
            TouchPhase::Down if self.pointer.is_none() => {
                self.pointer = Some(pointer_id);
                self.events.extend([egui::Event::PointerMoved(pos), button(pos, true)]);
            }
            TouchPhase::Move if self.pointer == Some(pointer_id) => self.events.push(egui::Event::PointerMoved(pos)),
            TouchPhase::Up if self.pointer == Some(pointer_id) => {
                self.pointer = None;
                self.events.extend([button(pos, false), egui::Event::PointerGone]);
            }
            // Taken by the system: let go far away, which egui takes for a drag, not a click.
            TouchPhase::Cancel if self.pointer == Some(pointer_id) => {
                self.pointer = None;
                let away = egui::pos2(-1.0e4, -1.0e4);
                self.events.extend([
                    egui::Event::PointerMoved(away),
                    button(away, false),
                    egui::Event::PointerGone,
                ]);
            }
            _ => {}
        }
    }
}

impl Engine {
    /// What a screen reader (TalkBack, VoiceOver) can land on in the last frame drawn, in
    /// reading order: the open screen's text and controls, or the picture itself (activating it
    /// opens the menu, as a tap does). See [`crate::calibration_ui::accessibility`].
    #[cfg(feature = "ui")]
    pub fn accessibility_nodes(&self) -> &[crate::calibration_ui::accessibility::AccessNode] {
        self.access.nodes()
    }

    /// Changes whenever [`Self::accessibility_nodes`] do: the shells re-read them then.
    #[cfg(feature = "ui")]
    pub fn accessibility_generation(&self) -> u64 {
        self.access.generation()
    }

    /// A screen reader's "activate" on node `id`: the control acts in the next frame as if
    /// tapped. `false` for an id not among the current nodes, or one that does nothing.
    #[cfg(feature = "ui")]
    pub fn accessibility_click(&mut self, id: i32) -> bool {
        if self.picture_access_node().is_some_and(|p| p.id == id)
            && self.screens.as_ref().is_none_or(|s| s.page.is_none())
        {
            return self.open_menu();
        }
        match self.access.click_event(id) {
            Some(event) => {
                self.screens().events.push(event);
                true
            }
            None => false,
        }
    }

    /// A screen reader's step up (`steps` > 0) or down on slider `id` (a swipe up or down on
    /// it): the slider moves by its step in the next frame. `false` for an id that is not an
    /// adjustable node now.
    #[cfg(feature = "ui")]
    pub fn accessibility_adjust(&mut self, id: i32, steps: i32) -> bool {
        match self.access.adjust_event(id, steps) {
            Some(event) => {
                self.screens().events.push(event);
                true
            }
            None => false,
        }
    }

    /// The picture as a screen reader finds it: the artifact's title, the whole surface.
    #[cfg(feature = "ui")]
    pub(super) fn picture_access_node(&mut self) -> Option<crate::calibration_ui::accessibility::AccessNode> {
        use crate::calibration_ui::accessibility::{AccessNode, AccessRole};
        let (w, h) = self.target_size().filter(|&(w, h)| w > 0 && h > 0)?;
        let title = match &self.model_info.artifact {
            Some(a) => a.title.clone(),
            None => self.model_info.name.clone(),
        };
        Some(AccessNode {
            id: self.access.id_for("picture"),
            role: AccessRole::Image,
            label: format!("{title}, in 3-D for red and cyan glasses. Activate for the menu."),
            value: None,
            checked: None,
            disabled: false,
            clickable: true,
            adjustable: false,
            bounds_px: [0.0, 0.0, w as f32, h as f32],
        })
    }

    /// Opens the menu: the artifact gallery, opening a file, the way to the calibration (also a
    /// single tap). Returns `false` when this build has no screens (feature `ui` off).
    pub fn open_menu(&mut self) -> bool {
        #[cfg(feature = "ui")]
        {
            if !self.menu_open() {
                let mut menu = crate::calibration_ui::menu::MenuUi::new();
                menu.lamp_on = self.lamp.is_some();
                self.screens().page = Some(Page::Menu(menu));
                self.refresh_menu_items();
            }
            true
        }
        #[cfg(not(feature = "ui"))]
        false
    }

    /// The full screen open over the picture, if any.
    #[cfg(feature = "ui")]
    pub(super) fn page(&self) -> Option<&Page> {
        self.screens.as_ref().and_then(|s| s.page.as_ref())
    }

    /// Whether the calibration screens are showing (touches then drive them, not gestures).
    pub fn calibration_open(&self) -> bool {
        #[cfg(feature = "ui")]
        return matches!(self.page(), Some(Page::Calibration(_)));
        #[cfg(not(feature = "ui"))]
        false
    }

    /// Where annotation `index`'s marker was in the last frame drawn, physical pixels of the
    /// target (the cyclopean eye's view: between the two the eyes see); `None` before a frame
    /// or for no such annotation.
    pub fn annotation_px(&self, index: usize) -> Option<[f32; 2]> {
        let a = self.model_info.annotations.get(index)?;
        let mono = self.last_mono?;
        let centre = crate::model::Model::pin_centre(a) - Vec3::Z * self.last_push_m;
        let p = mono.project(centre)?.pixel;
        let k = self.target_scale();
        Some([p.x * k, p.y * k])
    }

    /// The annotation whose marker is nearest `px` (physical pixels), within 6 mm on the glass
    /// (a fingertip).
    pub(super) fn annotation_at(&self, px: [f32; 2]) -> Option<usize> {
        let screen = self.session.config().screen;
        let reach_px = 0.006 / 0.0254 * screen.panel().xdpi * self.target_scale();
        (0..self.model_info.annotations.len())
            .filter_map(|i| {
                let [x, y] = self.annotation_px(i)?;
                let d = (x - px[0]).hypot(y - px[1]);
                (d <= reach_px).then_some((i, d))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    }

    /// Shows annotation `index`'s card (as a tap on its marker does). Returns `false` for no
    /// such annotation or without screens (feature `ui` off).
    pub fn open_annotation(&mut self, index: usize) -> bool {
        #[cfg(feature = "ui")]
        if index < self.model_info.annotations.len() {
            self.screens().page = Some(Page::Annotation(index));
            return true;
        }
        let _ = index;
        false
    }

    /// The annotation whose card is showing, if one is.
    pub fn open_annotation_index(&self) -> Option<usize> {
        #[cfg(feature = "ui")]
        if let Some(Page::Annotation(i)) = self.page() {
            return Some(*i);
        }
        None
    }

    /// Whether the menu is showing (touches then drive it, not gestures).
    pub fn menu_open(&self) -> bool {
        #[cfg(feature = "ui")]
        return matches!(self.page(), Some(Page::Menu(_)));
        #[cfg(not(feature = "ui"))]
        false
    }

    /// How the eyes are found, in words for the menu: the front camera's state.
    pub fn eyes_status(&self) -> String {
        let stats = self.stats();
        let text = if !self.face_tracking_on() {
            "Front camera off: the view follows the phone's tilt."
        } else if stats.face_tracking_stopped {
            "Face tracking stopped: the view follows the phone's tilt."
        } else if stats.eyes_from_camera {
            "The front camera is following your eyes."
        } else {
            "Front camera on, looking for your eyes (meanwhile the view follows the tilt)."
        };
        text.to_owned()
    }

    pub(super) fn face_tracking_on(&self) -> bool {
        #[cfg(feature = "face")]
        return self.face.is_some();
        #[cfg(not(feature = "face"))]
        false
    }

    /// Whether the first-run screens are showing.
    pub fn welcome_open(&self) -> bool {
        #[cfg(feature = "ui")]
        return matches!(self.page(), Some(Page::Welcome(_)));
        #[cfg(not(feature = "ui"))]
        false
    }

    /// The shell has no camera permission yet and may ask for it. Instead of the system's
    /// request out of the blue, the core shows its camera page (what the camera is for, that no
    /// picture is kept) as soon as no other screen is open — after the first-run screens, if
    /// they show — and only when the user taps "Use the camera" asks the shell
    /// ([`ShellRequest::CameraPermission`]). "Not now" leaves tilt only, until the next start.
    /// Without the `ui` feature the request is made at once.
    pub fn camera_permission_needed(&mut self) {
        #[cfg(feature = "ui")]
        {
            self.camera_page_pending = true;
            self.open_pending_camera_page();
        }
        #[cfg(not(feature = "ui"))]
        self.requests.push(ShellRequest::CameraPermission);
    }

    /// Opens the camera page if it waits and nothing else is open.
    #[cfg(feature = "ui")]
    pub(super) fn open_pending_camera_page(&mut self) {
        if self.camera_page_pending && self.page().is_none() {
            self.camera_page_pending = false;
            self.set_page(Some(Page::Welcome(crate::calibration_ui::welcome::WelcomeUi::camera())));
        }
    }

    /// The oldest request of the core's screens not yet taken (see [`ShellRequest`]); call until
    /// `None` after each frame.
    pub fn take_shell_request(&mut self) -> Option<ShellRequest> {
        (!self.requests.is_empty()).then(|| self.requests.remove(0))
    }

    #[cfg(feature = "ui")]
    pub(super) fn screens(&mut self) -> &mut Screens {
        self.screens.get_or_insert_with(|| {
            Box::new(Screens {
                page: None,
                items: Vec::new(),
                ctx: egui::Context::default(),
                events: Vec::new(),
                overlay: crate::calibration_ui::OverlayHost::new(),
                pointer: None,
                banner_pt: None,
                banner_button_pt: None,
                thumbnail_textures: std::collections::HashMap::new(),
            })
        })
    }

    /// Reads the gallery's items from the library again.
    #[cfg(feature = "ui")]
    pub(super) fn refresh_menu_items(&mut self) {
        let artifacts = self.artifacts();
        self.thumbnails.request(&artifacts);
        let screens = self.screens();
        let items = artifacts
            .into_iter()
            .map(|a| {
                let id = a.id.to_string();
                crate::calibration_ui::menu::MenuItem {
                    removable: a.id.origin == crate::library::Origin::Imported,
                    thumbnail: screens.thumbnail_textures.get(&id).map(egui::TextureHandle::id),
                    id,
                    title: a.title,
                    credit: a.credit,
                    licence: a.licence,
                }
            })
            .collect();
        screens.items = items;
    }

    /// Waits up to `timeout` until the open menu's pictures are all made (or found impossible),
    /// drawing them meanwhile; for tests and tools (the shells just keep drawing frames).
    /// Returns whether none is left to make.
    #[cfg(feature = "ui")]
    pub fn wait_for_thumbnails(&mut self, timeout: std::time::Duration) -> bool {
        let deadline = std::time::Instant::now() + timeout;
        loop {
            self.take_thumbnails();
            if self.thumbnails.pending() == 0 {
                return true;
            }
            if std::time::Instant::now() >= deadline {
                return false;
            }
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
    }

    /// Takes the gallery's finished pictures (drawing at most one a frame) into egui textures.
    #[cfg(feature = "ui")]
    pub(super) fn take_thumbnails(&mut self) {
        let renderer = &mut self.renderer;
        let new = self.thumbnails.poll(|posed| crate::thumbnails::render(renderer, posed));
        self.load_thumbnail_textures(new);
    }

    /// The gallery's pictures `ids` (made already) into egui textures of the screens' context.
    #[cfg(feature = "ui")]
    fn load_thumbnail_textures(&mut self, ids: Vec<String>) {
        let size = crate::thumbnails::THUMBNAIL_PX as usize;
        for id in ids {
            let Some(image) = self
                .thumbnails
                .get(&id)
                .map(|t| egui::ColorImage::from_rgba_unmultiplied([size, size], &t.rgba))
            else {
                continue;
            };
            let screens = self.screens();
            let texture = screens
                .ctx
                .load_texture(format!("thumbnail {id}"), image, egui::TextureOptions::LINEAR);
            for item in screens.items.iter_mut().filter(|i| i.id == id) {
                item.thumbnail = Some(texture.id());
            }
            screens.thumbnail_textures.insert(id, texture);
        }
    }

    /// A fresh egui context for the screens, with the gallery's pictures loaded into it again:
    /// a new painter (a new target format, a new device) lacks its predecessor's textures, and
    /// only a fresh context sends them all (the fonts included) again.
    #[cfg(feature = "ui")]
    pub(super) fn fresh_screens_context(&mut self) {
        let Some(screens) = self.screens.as_deref_mut() else {
            return;
        };
        screens.ctx = egui::Context::default();
        let ids: Vec<String> = screens.thumbnail_textures.drain().map(|(id, _)| id).collect();
        self.load_thumbnail_textures(ids);
    }

    /// The centre of a control of the screen showing, in the last frame drawn, in physical
    /// pixels: for tests and automation. Names are the open page's (`widget_rect` of
    /// [`crate::calibration_ui::CalibrationUi`], [`crate::calibration_ui::menu::MenuUi`],
    /// [`crate::calibration_ui::settings::SettingsUi`],
    /// [`crate::calibration_ui::material::MaterialUi`] or
    /// [`crate::calibration_ui::welcome::WelcomeUi`]); `banner` is the status banner's button
    /// (Cancel or OK) whatever page shows.
    #[cfg(feature = "ui")]
    pub fn control_px(&self, name: &str) -> Option<[f32; 2]> {
        let screens = self.screens.as_ref()?;
        let rect = match (&screens.page, name) {
            (_, "banner") => screens.banner_button_pt?,
            (Some(Page::Calibration(ui)), _) => ui.widget_rect(name)?,
            (Some(Page::Menu(ui)), _) => ui.widget_rect(name)?,
            (Some(Page::Settings(ui)), _) => ui.widget_rect(name)?,
            (Some(Page::Material(ui)), _) => ui.widget_rect(name)?,
            (Some(Page::Welcome(ui)), _) => ui.widget_rect(name)?,
            _ => return None,
        };
        let ppp = self.pixels_per_point();
        Some([rect.center().x * ppp, rect.center().y * ppp])
    }

    /// Physical pixels per egui point on this display: Android's density (dpi / 160), which iOS's
    /// scale (≈ ppi / 163) nearly equals, so controls have the platform's size; times the
    /// target's width over the panel's, so that a smaller target (the desktop viewer's window
    /// standing in for the phone) shows the phone's layout, smaller. On a phone they are equal.
    #[cfg(feature = "ui")]
    pub(super) fn pixels_per_point(&self) -> f32 {
        let screen = self.session.config().screen;
        let density = (screen.panel().xdpi / 160.0).clamp(1.0, 4.0) * self.text_scale;
        let target_width_px = self.target_size().map(|(w, _)| w);
        match target_width_px.filter(|&w| w > 0) {
            Some(w) => density * (w as f32 / screen.width_px() as f32).clamp(0.1, 10.0),
            None => density,
        }
    }

    /// The system's text size setting (Android's `Configuration.fontScale`, iOS's Dynamic Type
    /// as a ratio to the default size): the core's screens scale their text and controls
    /// together by it, within [`TEXT_SCALE_RANGE`] (beyond it the phone's screen holds too
    /// little; the galleries scroll). A scale that is not a finite positive number is an
    /// [`EngineError::InvalidArgument`].
    pub fn set_text_scale(&mut self, scale: f32) -> Result<(), EngineError> {
        if !(scale.is_finite() && scale > 0.0) {
            return Err(EngineError::InvalidArgument(format!(
                "text scale must be a positive number, got {scale}"
            )));
        }
        self.text_scale = scale.clamp(*TEXT_SCALE_RANGE.start(), *TEXT_SCALE_RANGE.end());
        Ok(())
    }

    #[cfg(feature = "ui")]
    pub(super) fn set_page(&mut self, page: Option<Page>) {
        if !matches!(page, Some(Page::Menu(_))) {
            // Pictures not started yet are not needed now; asked for again at the next menu.
            self.thumbnails.cancel_pending();
        }
        self.screens().page = page;
    }

    /// Applies and saves what the settings screen changed; a new floor, protrusion or size shows
    /// the artifact on screen again with it (loaded anew from the library in the background).
    #[cfg(feature = "ui")]
    pub(super) fn apply_settings_action(&mut self, action: crate::calibration_ui::settings::SettingsAction) {
        use crate::calibration_ui::settings::SettingsAction as A;
        match action {
            A::Changed(s) => {
                self.set_method(s.method);
                let surface_now = self.fit.placement == crate::model::Placement::Surface;
                let placing_changed = s.floor != self.floor
                    || s.protrude_fraction != self.fit.protrude_fraction
                    || s.true_size != self.fit.true_size
                    || s.surface != surface_now;
                self.floor = s.floor;
                self.fit.protrude_fraction = s.protrude_fraction;
                self.fit.true_size = s.true_size;
                if s.surface != surface_now {
                    self.fit.placement = if s.surface {
                        crate::model::Placement::Surface
                    } else {
                        crate::model::Placement::Auto
                    };
                }
                self.calibration.surface = s.surface;
                self.calibration.method = Some(s.method);
                self.calibration.floor = Some(s.floor);
                self.calibration.protrude_fraction = Some(s.protrude_fraction);
                self.calibration.true_size = s.true_size;
                self.calibration.turn_by_touch = s.turn_by_touch;
                self.session.set_turn_by_touch(s.turn_by_touch);
                if s.room_light != self.room_light_on() {
                    self.set_room_light(s.room_light);
                    self.calibration.room_light = Some(s.room_light);
                }
                self.save_calibration();
                if placing_changed && let Some(id) = self.model_info.artifact.as_ref().map(|a| a.id.clone()) {
                    self.select_artifact(id);
                }
            }
            A::Close => self.set_page(None),
        }
    }

    #[cfg(feature = "ui")]
    pub(super) fn apply_welcome_action(&mut self, action: crate::calibration_ui::welcome::WelcomeAction) {
        use crate::calibration_ui::welcome::WelcomeAction as A;
        match action {
            A::Start => {
                // The pose held now is straight on (without gravity yet, lying flat stays it).
                let _ = self.session.calibrate_flat_angle();
                self.calibration.flat_up_device = self.session.flat_up_device().or(self.calibration.flat_up_device);
                self.calibration.introduced = true;
                self.save_calibration();
                self.set_page(None);
            }
            A::GlassesSwapped(swapped) => {
                self.calibration.glasses_swapped = swapped;
                self.save_calibration();
            }
            A::Calibrate => {
                self.calibration.introduced = true;
                self.save_calibration();
                self.set_page(None);
                self.open_calibration();
            }
            A::AllowCamera => {
                self.requests.push(ShellRequest::CameraPermission);
                self.set_page(None);
            }
            A::CameraNotNow => self.set_page(None),
        }
    }

    #[cfg(feature = "ui")]
    pub(super) fn apply_menu_action(&mut self, action: crate::calibration_ui::menu::MenuAction) {
        use crate::calibration_ui::menu::MenuAction as A;
        match action {
            A::Select(id) => {
                match id.parse() {
                    Ok(id) => self.select_artifact(id),
                    Err(e) => self.loader.fail(id, format!("{e}")),
                }
                // Back to the picture, where the banner shows the progress.
                self.set_page(None);
            }
            A::Remove(id) => {
                let removed = id
                    .parse()
                    .map_err(EngineError::from)
                    .and_then(|id| self.remove_artifact(&id));
                if let Err(e) = removed {
                    self.loader.fail(id, e.to_string());
                }
                self.refresh_menu_items();
            }
            A::OpenFile => {
                self.requests.push(ShellRequest::OpenFile);
                self.set_page(None);
            }
            A::Share { side_by_side } => {
                let kind = if side_by_side {
                    Snapshot::SideBySide
                } else {
                    Snapshot::Composed
                };
                self.requests.push(ShellRequest::Share(kind));
                self.set_page(None);
            }
            A::Calibrate => {
                self.set_page(None);
                self.open_calibration();
            }
            A::Help => self.set_page(Some(Page::Help)),
            A::Settings => {
                let settings = crate::calibration_ui::settings::Settings {
                    method: self.method,
                    floor: self.floor,
                    protrude_fraction: self.fit.protrude_fraction,
                    true_size: self.fit.true_size,
                    surface: self.fit.placement == crate::model::Placement::Surface,
                    turn_by_touch: self.session.turning_by_touch(),
                    room_light: self.room_light_on(),
                };
                self.set_page(Some(Page::Settings(crate::calibration_ui::settings::SettingsUi::new(
                    settings,
                ))));
            }
            A::Material => {
                let ui = crate::calibration_ui::material::MaterialUi::new(self.appearance());
                self.set_page(Some(Page::Material(ui)));
            }
            A::Lamp => {
                // Closed at once: the next finger on the glass moves the lamp.
                let on = self.lamp.is_some();
                self.set_lamp((!on).then(crate::lamp::LampSetting::raking));
                self.set_page(None);
            }
            A::Close => self.set_page(None),
        }
    }
}
