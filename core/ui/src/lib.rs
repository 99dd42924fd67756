//! The screens the core draws with egui: the menu and status banner ([`menu`]), the settings
//! ([`settings`]), the first-run screens ([`welcome`]) and the calibration screens (this
//! module).
//!
//! The calibration screens, drawn by the core with egui so that the phones and the desktop viewer
//! show the same thing: the eye-reflection slider (IPD and head offset), the blind-spot distance
//! test, the ID-1 card check of the pixel density, "this is straight on" (flat angle) and the
//! world-light reset. The physics is in [`phantogram_sensing::calibration`]; this module places things on the
//! screen and turns the viewer's answers into a [`Calibration`].
//!
//! egui (immediate mode, on wgpu through `egui-wgpu`) was chosen because it draws with the GPU
//! device the renderer already owns, takes touch and mouse the same way, and needs no platform UI
//! toolkit in the shells: they forward touches, the core draws.
//!
//! **Coordinates**: the host gives egui the display in points; `pixels_per_point` is the display's
//! pixels per point (on phones the density scale, e.g. 2.75). Targets are placed in display
//! pixels by [`phantogram_geometry::screen::Screen`] and divided by `pixels_per_point` to draw.
//!
//! **Threading**: lives on the render thread with the egui context. **Panics**: none.

pub mod accessibility;
pub mod material;
pub mod menu;
pub mod settings;
pub mod side_hint;
#[cfg(test)]
mod test_taps;
pub mod welcome;
mod widget_rects;

use egui::{Align2, Color32, Pos2, Rect, Stroke, Vec2 as EVec2};
use glam::{Vec2, Vec3};

use phantogram_geometry::screen::Screen;
use phantogram_sensing::calibration::{self, Calibration, ID1_CARD_M};

/// Which screen is showing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Page {
    Menu,
    EyeReflection,
    BlindSpot,
    CardSize,
}

/// The closed eye in the blind-spot test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClosedEye {
    Left,
    Right,
}

/// What the host must do after a frame of the calibration UI.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CalibrationAction {
    /// Make the current holding pose count as straight on (`Session::calibrate_flat_angle`).
    FlatAngleHere,
    /// Tie the world light to the room again (`Session::recalibrate_light`).
    ResetLight,
    /// The calibration changed: apply it (eye model, screen density) and save it.
    Changed(Calibration),
    /// The viewer closed the calibration screens.
    Closed,
}

/// State of the calibration screens.
#[derive(Clone, Debug)]
pub struct CalibrationUi {
    pub page: Page,
    pub calibration: Calibration,
    /// Eye-reflection targets: separation and the midpoint's offset from the screen centre,
    /// along the display's right and up, millimetres.
    pub target_separation_mm: f32,
    pub target_offset_mm: Vec2,
    pub closed_eye: ClosedEye,
    /// Blind spot: the dot's distance from the fixation mark, millimetres.
    pub dot_separation_mm: f32,
    /// Card check: drawn size relative to what the reported density makes 85.60 mm.
    pub card_scale: f32,
    /// Where the main controls were drawn last frame (points), for tests and automation.
    widget_rects: crate::widget_rects::WidgetRects,
    pending_change: Option<Calibration>,
}

impl Default for CalibrationUi {
    fn default() -> Self {
        Self {
            page: Page::Menu,
            calibration: Calibration::default(),
            target_separation_mm: 63.0,
            target_offset_mm: Vec2::ZERO,
            closed_eye: ClosedEye::Left,
            dot_separation_mm: 60.0,
            card_scale: 1.0,
            widget_rects: crate::widget_rects::WidgetRects::new(),
            pending_change: None,
        }
    }
}

/// Display pixels of the two eye-reflection targets for a separation and midpoint offset
/// (millimetres along the display's right and up from the screen centre). The inverse of
/// [`calibration::from_reflection_targets`].
pub fn reflection_targets_px(screen: &Screen, separation_mm: f32, offset_mm: Vec2) -> [Vec2; 2] {
    let right = screen.right_device();
    let up = screen.up_device();
    let centre = (right * offset_mm.x + up * offset_mm.y) * 1e-3;
    let half = right * (separation_mm * 0.5e-3);
    [
        screen.pixel_of_glass_point(centre - half),
        screen.pixel_of_glass_point(centre + half),
    ]
}

/// Display pixels of the blind-spot test's fixation mark and dot. The open eye fixates the
/// mark; the dot lies on the open eye's temporal side (towards that eye's ear), level with it.
pub fn blind_spot_marks_px(screen: &Screen, closed: ClosedEye, separation_mm: f32) -> [Vec2; 2] {
    let right = screen.right_device();
    // Fixation sits off-centre towards the nasal side so the dot has room to travel.
    let temporal = match closed {
        ClosedEye::Left => right,
        ClosedEye::Right => -right,
    };
    let half_width_m = screen.width_m() * 0.5;
    let mark = -temporal * (half_width_m * 0.6);
    [
        screen.pixel_of_glass_point(mark),
        screen.pixel_of_glass_point(mark + temporal * (separation_mm * 1e-3)),
    ]
}

/// Display pixels of the drawn card (long side along the display's horizontal) for `scale`.
pub fn card_size_px(screen: &Screen, scale: f32) -> Vec2 {
    let a = screen.pixel_of_glass_point(Vec3::ZERO);
    let b = screen.pixel_of_glass_point(screen.right_device() * ID1_CARD_M.x + screen.up_device() * ID1_CARD_M.y);
    (b - a).abs() * scale
}

impl CalibrationUi {
    /// The screens, starting at the menu, with an existing calibration.
    pub fn with_calibration(calibration: Calibration) -> Self {
        Self {
            calibration,
            ..Self::default()
        }
    }

    /// The rectangle (points) of a control drawn last frame: "eye", "blind", "card", "flat",
    /// "light", "close", "accept", "back", "slider".
    pub fn widget_rect(&self, name: &str) -> Option<Rect> {
        self.widget_rects.get(name)
    }

    /// The page's instructions and controls, in a panel along the bottom of the screen.
    fn controls(&mut self, ui: &mut egui::Ui, title: &str, body: impl FnOnce(&mut Self, &mut egui::Ui)) {
        egui::Panel::bottom("calibration controls").show(ui, |ui| {
            // Sliders wide enough to move a millimetre at a time with a finger.
            ui.spacing_mut().slider_width = (ui.available_width() * 0.6).max(150.0);
            ui.heading(title);
            body(self, ui);
        });
    }

    /// "Accept" (apply `accept`, report the change, back to the menu) and "Back" (discard).
    fn accept_back(&mut self, ui: &mut egui::Ui, accept: impl FnOnce(&mut Self)) {
        ui.horizontal(|ui| {
            let a = ui.add_sized([120.0, 40.0], egui::Button::new("Accept"));
            let b = ui.add_sized([120.0, 40.0], egui::Button::new("Back"));
            self.widget_rects.remember("accept", a.rect);
            self.widget_rects.remember("back", b.rect);
            if a.clicked() {
                accept(self);
                self.pending_change = Some(self.calibration);
                self.page = Page::Menu;
            } else if b.clicked() {
                self.page = Page::Menu;
            }
        });
    }

    /// Draws the current page into the root `ui` of one egui frame (inside
    /// `egui::Context::run_ui`) and returns what the host must do.
    pub fn show(&mut self, ui: &mut egui::Ui, screen: &Screen, pixels_per_point: f32) -> Vec<CalibrationAction> {
        let ctx = ui.ctx().clone();
        let mut actions = Vec::new();
        let ppp = if pixels_per_point.is_finite() && pixels_per_point > 0.0 {
            pixels_per_point
        } else {
            1.0
        };
        let to_points = |px: Vec2| Pos2::new(px.x / ppp, px.y / ppp);
        let painter = ctx.layer_painter(egui::LayerId::background());
        match self.page {
            Page::Menu => {
                egui::CentralPanel::default().show(ui, |ui| {
                    ui.heading("Calibration");
                    ui.label("Hold the phone as you like to look at it, then choose.");
                    let buttons: [(&'static str, &str); 6] = [
                        ("eye", "Eye distance (mirror)"),
                        ("blind", "Viewing distance (blind spot)"),
                        ("card", "Screen size (bank card)"),
                        ("flat", "This is straight on"),
                        ("light", "Light: fix to the room again"),
                        ("close", "Done"),
                    ];
                    for (name, label) in buttons {
                        let r = ui.add_sized([ui.available_width(), 48.0], egui::Button::new(label));
                        self.widget_rects.remember(name, r.rect);
                        if r.clicked() {
                            match name {
                                "eye" => self.page = Page::EyeReflection,
                                "blind" => self.page = Page::BlindSpot,
                                "card" => self.page = Page::CardSize,
                                "flat" => actions.push(CalibrationAction::FlatAngleHere),
                                "light" => actions.push(CalibrationAction::ResetLight),
                                _ => actions.push(CalibrationAction::Closed),
                            }
                        }
                    }
                    let c = &self.calibration;
                    ui.separator();
                    ui.label(format!(
                        "IPD {}, distance {}, density {}",
                        c.ipd_m.map_or("default".into(), |v| format!("{:.1} mm", v * 1e3)),
                        c.viewing_distance_m
                            .map_or("default".into(), |v| format!("{:.0} cm", v * 1e2)),
                        c.density_dpi
                            .map_or("as reported".into(), |d| format!("{:.0}×{:.0} dpi", d.x, d.y)),
                    ));
                });
            }
            Page::EyeReflection => {
                // A dark glass is a mirror: nothing of the picture may light it.
                painter.rect_filled(ctx.content_rect(), 0.0, Color32::BLACK);
                let targets = reflection_targets_px(screen, self.target_separation_mm, self.target_offset_mm);
                for t in targets {
                    let p = to_points(t);
                    let r = 10.0;
                    let stroke = Stroke::new(2.0, Color32::WHITE);
                    painter.circle_stroke(p, r, stroke);
                    painter.line_segment([p - EVec2::X * r * 1.6, p + EVec2::X * r * 1.6], stroke);
                    painter.line_segment([p - EVec2::Y * r * 1.6, p + EVec2::Y * r * 1.6], stroke);
                }
                self.controls(ui, "Eye distance", |this, ui| {
                    ui.label(
                        "The dark glass is a mirror. Close your right eye: with the left eye, look straight \
                         at its own reflection and move the targets until the left one sits on that pupil. \
                         Then close the left eye and set the separation so the right target sits on the \
                         right pupil's reflection. Each eye checks only its own target; the distance to \
                         the phone does not matter.",
                    );
                    if screen.width_m() < 0.09 {
                        ui.colored_label(Color32::YELLOW, "Turn the phone sideways: the targets need room.");
                    }
                    let r = ui.add(
                        egui::Slider::new(&mut this.target_separation_mm, 40.0..=80.0)
                            .text("separation (mm)")
                            .fixed_decimals(1),
                    );
                    this.widget_rects.remember("slider", r.rect);
                    ui.add(egui::Slider::new(&mut this.target_offset_mm.x, -30.0..=30.0).text("left/right (mm)"));
                    ui.add(egui::Slider::new(&mut this.target_offset_mm.y, -60.0..=60.0).text("up/down (mm)"));
                    this.accept_back(ui, |this| {
                        let [l, r] = reflection_targets_px(screen, this.target_separation_mm, this.target_offset_mm);
                        let result = calibration::from_reflection_targets(screen, l, r);
                        this.calibration.ipd_m = Some(result.ipd_m);
                        this.calibration.head_offset_m = Some(result.centre_device_m);
                    })
                });
            }
            Page::BlindSpot => {
                let [mark, dot] = blind_spot_marks_px(screen, self.closed_eye, self.dot_separation_mm);
                painter.rect_filled(
                    Rect::from_center_size(to_points(mark), EVec2::splat(12.0)),
                    0.0,
                    Color32::WHITE,
                );
                painter.circle_filled(to_points(dot), 8.0, Color32::from_rgb(255, 60, 60));
                self.controls(ui, "Viewing distance", |this, ui| {
                    ui.label(
                        "Hold the phone straight in front of you at your usual distance. Close one eye, \
                         look only at the white square with the other, and move the red dot away until it \
                         disappears.",
                    );
                    ui.horizontal(|ui| {
                        ui.selectable_value(&mut this.closed_eye, ClosedEye::Left, "left eye closed");
                        ui.selectable_value(&mut this.closed_eye, ClosedEye::Right, "right eye closed");
                    });
                    // The dot travels from the mark (30 % of the width off-centre) to the far edge.
                    let max_mm = screen.width_m() * 1e3 * 0.78;
                    if max_mm < 80.0 {
                        // At 30 cm the dot vanishes 72 mm from the mark: a portrait phone is too
                        // narrow.
                        ui.colored_label(Color32::YELLOW, "Turn the phone sideways: the dot needs room.");
                    }
                    let r = ui
                        .add(egui::Slider::new(&mut this.dot_separation_mm, 10.0..=max_mm.max(11.0)).text("dot (mm)"));
                    this.widget_rects.remember("slider", r.rect);
                    if let Some(d) = calibration::blind_spot_distance_m(this.dot_separation_mm * 1e-3) {
                        ui.label(format!("distance ≈ {:.0} cm", d * 1e2));
                    }
                    this.accept_back(ui, |this| {
                        this.calibration.viewing_distance_m =
                            calibration::blind_spot_distance_m(this.dot_separation_mm * 1e-3);
                    })
                });
            }
            Page::CardSize => {
                let size = card_size_px(screen, self.card_scale);
                let centre = screen.pixel_of_glass_point(Vec3::ZERO);
                let rect = Rect::from_center_size(to_points(centre), EVec2::new(size.x / ppp, size.y / ppp));
                painter.rect_stroke(rect, 8.0, Stroke::new(2.0, Color32::WHITE), egui::StrokeKind::Inside);
                painter.text(
                    rect.center(),
                    Align2::CENTER_CENTER,
                    "ID-1 card",
                    egui::FontId::proportional(14.0),
                    Color32::WHITE,
                );
                self.controls(ui, "Screen size", |this, ui| {
                    ui.label("Lay a bank card on the screen and make the outline match its edges.");
                    let r = ui.add(egui::Slider::new(&mut this.card_scale, 0.7..=1.3).text("size"));
                    this.widget_rects.remember("slider", r.rect);
                    this.accept_back(ui, |this| {
                        let px = card_size_px(screen, this.card_scale);
                        // Display pixels along the display's axes → the panel's x/y.
                        let landscape_on_panel = screen.right_device().x.abs() > 0.5;
                        let card_px_panel = if landscape_on_panel { px } else { Vec2::new(px.y, px.x) };
                        this.calibration.density_dpi =
                            calibration::density_from_card(screen.panel(), card_px_panel, landscape_on_panel)
                                .map(|p| Vec2::new(p.xdpi, p.ydpi));
                    })
                });
            }
        }
        if let Some(changed) = self.pending_change.take() {
            actions.push(CalibrationAction::Changed(changed));
        }
        actions
    }
}

/// Paints egui's output over a frame the renderer has drawn: the second half of the three-step
/// host loop (input → [`CalibrationUi::show`] in `Context::run_ui` → [`Overlay::paint`]).
pub struct Overlay {
    renderer: egui_wgpu::Renderer,
    format: wgpu::TextureFormat,
}

impl Overlay {
    pub fn new(gpu: &phantogram_render::Gpu, format: wgpu::TextureFormat) -> Self {
        Self {
            renderer: egui_wgpu::Renderer::new(&gpu.device, format, egui_wgpu::RendererOptions::default()),
            format,
        }
    }

    /// The target format this overlay was made for (a surface's may change on reconfigure).
    pub fn format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// Draws `output` (from the same `ctx`) over `target` (`size_px`, already holding the frame),
    /// and submits.
    pub fn paint(
        &mut self,
        gpu: &phantogram_render::Gpu,
        ctx: &egui::Context,
        mut output: egui::FullOutput,
        target: &wgpu::TextureView,
        size_px: [u32; 2],
    ) {
        let (device, queue) = (&gpu.device, &gpu.queue);
        for (id, deltas) in &output.textures_delta.set {
            for delta in deltas {
                self.renderer.update_texture(device, queue, *id, delta);
            }
        }
        let jobs = ctx.tessellate(std::mem::take(&mut output.shapes), output.pixels_per_point);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: size_px,
            pixels_per_point: output.pixels_per_point,
        };
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("calibration overlay"),
        });
        let extra = self
            .renderer
            .update_buffers(device, queue, &mut encoder, &jobs, &screen);
        {
            let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("calibration overlay"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            self.renderer.render(&mut pass.forget_lifetime(), &jobs, &screen);
        }
        queue.submit(extra.into_iter().chain([encoder.finish()]));
        for id in &output.textures_delta.free {
            self.renderer.free_texture(id);
        }
        // Applied above; egui insists on being told.
        output.textures_delta.clear();
    }
}

/// An [`Overlay`] for a host whose frames may be skipped and whose target may change format (a
/// window surface): made for the target's format when first painted and again when the format
/// changes, and egui's texture uploads of a frame that was not painted (egui sends each texture,
/// the font atlas included, once) kept for the next that is. Per frame: [`Self::begin`] with
/// the egui output, [`Self::paint`] from the draw (if it draws), [`Self::end`].
#[derive(Default)]
pub struct OverlayHost {
    overlay: Option<Overlay>,
    unpainted: egui::TexturesDelta,
    painted: bool,
    lost_textures: bool,
}

impl OverlayHost {
    pub fn new() -> Self {
        Self::default()
    }

    /// Puts the texture uploads of frames not painted before `output`'s own.
    pub fn begin(&mut self, output: &mut egui::FullOutput) {
        let newer = std::mem::take(&mut output.textures_delta);
        output.textures_delta = std::mem::take(&mut self.unpainted);
        output.textures_delta.append(newer);
        self.painted = false;
    }

    /// Paints `output` over `target` (`format`, `size_px`); see [`Overlay::paint`].
    pub fn paint(
        &mut self,
        gpu: &phantogram_render::Gpu,
        ctx: &egui::Context,
        output: &mut egui::FullOutput,
        target: &wgpu::TextureView,
        format: wgpu::TextureFormat,
        size_px: [u32; 2],
    ) {
        let overlay = match &mut self.overlay {
            Some(o) if o.format() == format => o,
            slot => {
                // A new painter lacks the textures its predecessor was sent.
                self.lost_textures |= slot.is_some();
                slot.insert(Overlay::new(gpu, format))
            }
        };
        overlay.paint(gpu, ctx, std::mem::take(output), target, size_px);
        self.painted = true;
    }

    /// Ends the frame: keeps what it did not upload. Returns `true` when the host must replace
    /// its egui context (a new painter was made, and only a fresh context sends every texture
    /// again).
    pub fn end(&mut self, output: &mut egui::FullOutput) -> bool {
        if !self.painted {
            let mut kept = std::mem::take(&mut self.unpainted);
            kept.append(std::mem::take(&mut output.textures_delta));
            self.unpainted = kept;
        }
        std::mem::take(&mut self.lost_textures)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use phantogram_geometry::screen::{DisplayRotation, PanelSpec};

    fn screen(rotation: DisplayRotation) -> Screen {
        Screen::new(PanelSpec::TYPICAL_PHONE, rotation).unwrap()
    }

    #[test]
    fn targets_recover_the_slider_settings_in_every_rotation() {
        for rot in [DisplayRotation::Deg0, DisplayRotation::Deg90, DisplayRotation::Deg270] {
            let s = screen(rot);
            let [l, r] = reflection_targets_px(&s, 61.5, Vec2::new(4.0, -7.0));
            // Left target left of the right one on the display, level.
            assert!(l.x < r.x && (l.y - r.y).abs() < 1e-3, "{rot:?}: {l} {r}");
            let back = calibration::from_reflection_targets(&s, l, r);
            assert!((back.ipd_m - 0.0615).abs() < 1e-5, "{rot:?}: {}", back.ipd_m);
            let centre = s.right_device() * 0.004 + s.up_device() * -0.007;
            assert!(back.centre_device_m.distance(Vec2::new(centre.x, centre.y)) < 1e-5);
        }
    }

    #[test]
    fn blind_spot_dot_is_temporal_and_card_matches_the_reported_density() {
        let s = screen(DisplayRotation::Deg0);
        let px_per_mm = s.panel().xdpi / 25.4;
        let [mark, dot] = blind_spot_marks_px(&s, ClosedEye::Left, 50.0);
        // Right eye open: the dot goes right (temporal), 50 mm away.
        assert!(dot.x > mark.x && ((dot.x - mark.x) / px_per_mm - 50.0).abs() < 0.01);
        let [mark, dot] = blind_spot_marks_px(&s, ClosedEye::Right, 50.0);
        assert!(dot.x < mark.x);
        let card = card_size_px(&s, 1.0);
        assert!((card.x / px_per_mm - 85.60).abs() < 0.01, "{card}");
    }

    /// One egui frame of the calibration UI with `events`.
    fn frame(
        ctx: &egui::Context,
        ui_state: &mut CalibrationUi,
        s: &Screen,
        events: Vec<egui::Event>,
    ) -> Vec<CalibrationAction> {
        let ppp = 2.0;
        ctx.set_pixels_per_point(ppp);
        let input = egui::RawInput {
            screen_rect: Some(Rect::from_min_size(
                Pos2::ZERO,
                EVec2::new(s.width_px() as f32 / ppp, s.height_px() as f32 / ppp),
            )),
            events,
            ..Default::default()
        };
        let mut actions = Vec::new();
        let mut output = ctx.run_ui(input, |ui| actions = ui_state.show(ui, s, ppp));
        // Nothing is painted here (no GPU in unit tests).
        output.textures_delta.clear();
        actions
    }

    /// egui uploads the font atlas once, with the first frame: if that frame is skipped (a
    /// surface timing out, the app pausing), the next frame painted must still upload it, or
    /// every later frame draws its text with a missing texture.
    #[test]
    fn a_skipped_frame_keeps_its_texture_uploads_for_the_next() {
        let ctx = egui::Context::default();
        let s = screen(DisplayRotation::Deg0);
        let mut ui = CalibrationUi::default();
        let mut host = OverlayHost::new();
        let full_atlas = |o: &egui::FullOutput| {
            o.textures_delta
                .set
                .iter()
                .any(|(id, deltas)| *id == egui::TextureId::default() && deltas.iter().any(|d| d.pos.is_none()))
        };
        let mut run = || {
            let input = egui::RawInput {
                screen_rect: Some(Rect::from_min_size(Pos2::ZERO, EVec2::new(540.0, 1200.0))),
                ..Default::default()
            };
            ctx.run_ui(input, |root| {
                ui.show(root, &s, 2.0);
            })
        };
        let mut first = run();
        assert!(full_atlas(&first), "the first frame uploads the whole font atlas");
        host.begin(&mut first);
        assert!(!host.end(&mut first), "no painter was replaced");
        let mut second = run();
        assert!(!full_atlas(&second), "egui does not send it again");
        host.begin(&mut second);
        assert!(full_atlas(&second), "the skipped frame's upload comes first");
        second.textures_delta.clear();
    }

    /// Taps the centre of a control: press in one frame, release in the next.
    fn tap(ctx: &egui::Context, ui_state: &mut CalibrationUi, s: &Screen, name: &str) -> Vec<CalibrationAction> {
        let pos = ui_state
            .widget_rect(name)
            .unwrap_or_else(|| panic!("no control {name} on {:?}", ui_state.page))
            .center();
        let button = |pressed| egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: Default::default(),
        };
        let mut actions = frame(ctx, ui_state, s, vec![egui::Event::PointerMoved(pos), button(true)]);
        actions.extend(frame(ctx, ui_state, s, vec![button(false)]));
        // Two more frames so the page the tap led to is laid out (a panel takes its size from
        // the frame before).
        actions.extend(frame(ctx, ui_state, s, vec![]));
        actions.extend(frame(ctx, ui_state, s, vec![]));
        actions
    }

    #[test]
    fn taps_walk_through_the_screens_and_report_the_calibration() {
        let ctx = egui::Context::default();
        // Landscape: the blind-spot dot needs the long side.
        let s = screen(DisplayRotation::Deg90);
        let mut ui = CalibrationUi::default();
        frame(&ctx, &mut ui, &s, vec![]);
        assert_eq!(tap(&ctx, &mut ui, &s, "flat"), vec![CalibrationAction::FlatAngleHere]);
        assert_eq!(tap(&ctx, &mut ui, &s, "light"), vec![CalibrationAction::ResetLight]);

        tap(&ctx, &mut ui, &s, "eye");
        assert_eq!(ui.page, Page::EyeReflection);
        ui.target_separation_mm = 66.0;
        frame(&ctx, &mut ui, &s, vec![]);
        let actions = tap(&ctx, &mut ui, &s, "accept");
        assert_eq!(ui.page, Page::Menu);
        let [CalibrationAction::Changed(c)] = actions.as_slice() else {
            panic!("{actions:?}")
        };
        assert!((c.ipd_m.unwrap() - 0.066).abs() < 1e-5);

        tap(&ctx, &mut ui, &s, "blind");
        assert_eq!(ui.page, Page::BlindSpot);
        ui.dot_separation_mm = 80.0;
        let actions = tap(&ctx, &mut ui, &s, "accept");
        let [CalibrationAction::Changed(c)] = actions.as_slice() else {
            panic!("{actions:?}")
        };
        // d = s / tan 13.5° = 333 mm.
        assert!((c.viewing_distance_m.unwrap() - 0.080 / 13.5f32.to_radians().tan()).abs() < 1e-4);
        assert!((c.ipd_m.unwrap() - 0.066).abs() < 1e-5, "earlier results are kept");

        tap(&ctx, &mut ui, &s, "card");
        ui.card_scale = 1.1;
        let actions = tap(&ctx, &mut ui, &s, "accept");
        let [CalibrationAction::Changed(c)] = actions.as_slice() else {
            panic!("{actions:?}")
        };
        // The card had to be drawn 10 % larger to match: the screen has 10 % more pixels per mm.
        let d = c.density_dpi.unwrap();
        assert!((d.x / s.panel().xdpi - 1.1).abs() < 1e-3, "{d}");

        // "Back" discards.
        tap(&ctx, &mut ui, &s, "eye");
        ui.target_separation_mm = 50.0;
        assert!(tap(&ctx, &mut ui, &s, "back").is_empty());
        assert_eq!(ui.page, Page::Menu);
        assert_eq!(tap(&ctx, &mut ui, &s, "close"), vec![CalibrationAction::Closed]);
    }
}
