//! The first-run screens: what a phantogram is and how to hold the phone (with a picture drawn
//! here), the glasses check that finds which filter is on which eye, and "Start", which makes the
//! pose the phone is held in now count as straight on.
//!
//! The glasses check shows two rings on black, each in one filter's colour: through a filter
//! only the ring of its own colour shows. With the left eye closed, the right eye sees the ring of
//! the right filter's colour — unless the glasses are on the other way round, and then the
//! engine swaps the eyes' images. "Both" or "neither" means no glasses, or glasses of other
//! colours than the chosen method's.
//!
//! The camera page says what the front camera is for before the system asks for it (a request
//! out of the blue is the one most people refuse): "Use the camera" makes the engine ask the
//! shell to show the system's permission request; "Not now" keeps tilt only.
//!
//! **Threading**: the render thread. **Panics**: none.

use egui::{Align2, Color32, FontId, Pos2, Rect, RichText, Stroke, Vec2};

use crate::menu::CONTROL_HEIGHT_PT;

/// Which first-run screen is showing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WelcomePage {
    Intro,
    Glasses,
    /// The check's outcome, in words, until "Continue".
    GlassesResult(GlassesFinding),
    /// What the front camera is for, before the system's permission request.
    Camera,
}

/// What the glasses check found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GlassesFinding {
    RightWayRound,
    Swapped,
    /// Both rings or neither: not on, or other colours.
    Unclear,
}

/// What the host must do after a frame of the first-run screens.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WelcomeAction {
    /// Take the current pose as straight on, note the first run as done, close.
    Start,
    /// The glasses are on the other way round (`true`) or not.
    GlassesSwapped(bool),
    /// Note the first run as done and open the calibration screens.
    Calibrate,
    /// The user wants the camera: show the system's permission request.
    AllowCamera,
    /// The user declined the camera for now: close the page.
    CameraNotNow,
}

/// The two filters' colours, left eye's first (sRGB), for the rings.
pub type FilterColours = ([u8; 3], [u8; 3]);

/// The first-run screens' state.
#[derive(Clone, Debug)]
pub struct WelcomeUi {
    pub page: WelcomePage,
    /// The glasses the front camera sees on the viewer, when it does: the check then says
    /// which way round they look to be on (the viewer still answers).
    pub camera_glasses: Option<phantogram_sensing::glasses::GlassesSeen>,
    widget_rects: crate::widget_rects::WidgetRects,
}

impl Default for WelcomeUi {
    fn default() -> Self {
        Self {
            page: WelcomePage::Intro,
            camera_glasses: None,
            widget_rects: crate::widget_rects::WidgetRects::new(),
        }
    }
}

impl WelcomeUi {
    pub fn new() -> Self {
        Self::default()
    }

    /// The camera page on its own (when the shell reports the permission missing).
    pub fn camera() -> Self {
        Self {
            page: WelcomePage::Camera,
            ..Self::default()
        }
    }

    /// The rectangle (points) of a control drawn last frame: `start`, `glasses`, `calibrate`,
    /// `left-ring`, `right-ring`, `unclear`, `continue`, `allow-camera`, `not-now`; and the
    /// rings themselves, `ring-left` and `ring-right`.
    pub fn widget_rect(&self, name: &str) -> Option<Rect> {
        self.widget_rects.get(name)
    }

    fn button(&mut self, ui: &mut egui::Ui, name: &'static str, label: &str) -> bool {
        let r = ui.add_sized(
            [ui.available_width(), CONTROL_HEIGHT_PT],
            egui::Button::new(RichText::new(label).size(17.0)),
        );
        self.widget_rects.remember(name, r.rect);
        r.clicked()
    }

    /// Draws the current page into the root `ui`; `filters` are the chosen method's filter
    /// colours (`None`: mono, no glasses to check).
    pub fn show(&mut self, ui: &mut egui::Ui, filters: Option<FilterColours>) -> Vec<WelcomeAction> {
        let mut actions = Vec::new();
        let black = egui::Frame::central_panel(ui.style()).fill(Color32::BLACK);
        match self.page {
            WelcomePage::Intro => {
                scrolling_page(ui, black, |ui| {
                    ui.heading(RichText::new("A window onto the artifact").size(24.0));
                    ui.add_space(6.0);
                    let (rect, _) =
                        ui.allocate_exact_size(Vec2::new(ui.available_width(), 170.0), egui::Sense::hover());
                    pose_picture(ui.painter(), rect);
                    ui.label(
                        RichText::new("The phone tilted back, like a picture on a table.")
                            .size(13.0)
                            .color(Color32::from_gray(170)),
                    );
                    ui.add_space(6.0);
                    let glasses = match filters {
                        Some(_) => "Put on the coloured glasses. ",
                        None => "",
                    };
                    ui.label(
                        RichText::new(format!(
                            "{glasses}Hold the phone about 30 cm from your eyes, tilted back like a picture \
                             lying on a table, and look down into it: the artifact stands on the screen as if \
                             it were really there. Tilt the phone to look around it."
                        ))
                        .size(16.0),
                    );
                    ui.label(
                        RichText::new(
                            "When you hold it comfortably, tap Start: that pose becomes \"straight on\". \
                             Tap the picture once for the artifacts and settings.",
                        )
                        .size(16.0),
                    );
                    ui.add_space(8.0);
                    if filters.is_some() && self.button(ui, "glasses", "Check my glasses") {
                        self.page = WelcomePage::Glasses;
                    }
                    if self.button(ui, "start", "Start") {
                        actions.push(WelcomeAction::Start);
                    }
                    if self.button(ui, "calibrate", "Calibrate for my eyes (optional)") {
                        actions.push(WelcomeAction::Calibrate);
                    }
                });
            }
            WelcomePage::Glasses => {
                scrolling_page(ui, black, |ui| {
                    ui.heading(RichText::new("Which way are the glasses on?").size(22.0));
                    ui.label(
                        RichText::new("Close your LEFT eye. Which ring do you see with your right eye?").size(17.0),
                    );
                    if let Some(seen) = self.camera_glasses {
                        ui.label(RichText::new(camera_glasses_note(&seen)).size(15.0));
                    }
                    let (rect, _) =
                        ui.allocate_exact_size(Vec2::new(ui.available_width(), 180.0), egui::Sense::hover());
                    let (left, right) = filters.unwrap_or(([255, 0, 0], [0, 255, 255]));
                    let rgb = |c: [u8; 3]| Color32::from_rgb(c[0], c[1], c[2]);
                    let r = (rect.height() * 0.35).min(rect.width() * 0.18);
                    for (name, x, colour) in [("ring-left", 0.27, left), ("ring-right", 0.73, right)] {
                        let centre = Pos2::new(rect.left() + rect.width() * x, rect.center().y);
                        ui.painter()
                            .circle_stroke(centre, r, Stroke::new(r * 0.28, rgb(colour)));
                        self.widget_rects
                            .remember(name, Rect::from_center_size(centre, Vec2::splat(2.0 * r)));
                    }
                    ui.add_space(6.0);
                    if self.button(ui, "left-ring", "The ring on the left") {
                        self.page = WelcomePage::GlassesResult(GlassesFinding::Swapped);
                        actions.push(WelcomeAction::GlassesSwapped(true));
                    }
                    if self.button(ui, "right-ring", "The ring on the right") {
                        self.page = WelcomePage::GlassesResult(GlassesFinding::RightWayRound);
                        actions.push(WelcomeAction::GlassesSwapped(false));
                    }
                    if self.button(ui, "unclear", "Both, or neither") {
                        self.page = WelcomePage::GlassesResult(GlassesFinding::Unclear);
                    }
                });
            }
            WelcomePage::GlassesResult(finding) => {
                scrolling_page(ui, black, |ui| {
                    let text = match finding {
                        GlassesFinding::RightWayRound => "Your glasses are the right way round.",
                        GlassesFinding::Swapped => {
                            "Your glasses are on the other way round (or made that way): the picture is now \
                             swapped to match them."
                        }
                        GlassesFinding::Unclear => {
                            "Each eye should see one ring only. Check that the glasses are on, and that their \
                             colours are the ones chosen in the menu (tap the picture once, then Settings)."
                        }
                    };
                    ui.label(RichText::new(text).size(18.0));
                    ui.add_space(8.0);
                    if self.button(ui, "continue", "Continue") {
                        self.page = WelcomePage::Intro;
                    }
                });
            }
            WelcomePage::Camera => {
                scrolling_page(ui, black, |ui| {
                    ui.heading(RichText::new("Follow your eyes with the camera?").size(22.0));
                    ui.add_space(6.0);
                    let (rect, _) =
                        ui.allocate_exact_size(Vec2::new(ui.available_width(), 150.0), egui::Sense::hover());
                    camera_picture(ui.painter(), rect);
                    ui.add_space(6.0);
                    ui.label(
                        RichText::new(
                            "The front camera can find your eyes, so the artifact keeps its place in 3D when \
                             you move your head, not only when you tilt the phone.",
                        )
                        .size(16.0),
                    );
                    ui.label(
                        RichText::new(
                            "The pictures are looked at on the phone and forgotten at once: nothing is stored or \
                             sent anywhere. Without the camera, tilting the phone still works.",
                        )
                        .size(16.0),
                    );
                    ui.add_space(8.0);
                    if self.button(ui, "allow-camera", "Use the camera") {
                        actions.push(WelcomeAction::AllowCamera);
                    }
                    if self.button(ui, "not-now", "Not now") {
                        actions.push(WelcomeAction::CameraNotNow);
                    }
                });
            }
        }
        actions
    }
}

/// A first-run page on black that scrolls when it is taller than the screen (a large system
/// text size): its buttons stay reachable.
fn scrolling_page(ui: &mut egui::Ui, frame: egui::Frame, body: impl FnOnce(&mut egui::Ui)) {
    egui::CentralPanel::default().frame(frame).show(ui, |ui| {
        egui::ScrollArea::vertical().auto_shrink([false, false]).show(ui, body);
    });
}

/// The holding pose, side on: the eye, the sight line of about 30 cm, and the phone tilted back
/// on its lower edge with the artifact standing on it.
fn pose_picture(painter: &egui::Painter, rect: Rect) {
    let ink = Color32::from_gray(210);
    let accent = Color32::from_rgb(255, 190, 90);
    let stroke = Stroke::new(2.0, ink);
    let s = (rect.width() / 300.0).min(rect.height() / 170.0);
    let at = |x: f32, y: f32| {
        Pos2::new(
            rect.left() + (rect.width() - 300.0 * s) * 0.5 + x * s,
            rect.top() + y * s,
        )
    };
    // The eye, upper left: an almond and its pupil, looking down to the right.
    let eye = at(40.0, 40.0);
    painter.circle_stroke(eye, 12.0 * s, stroke);
    painter.circle_filled(eye + Vec2::new(4.0, 3.0) * s, 4.5 * s, ink);
    // The phone: its lower edge, nearer the eye, resting on the table, its top raised 35° away
    // from the eye, so that the glass faces up towards the eye.
    let foot = at(120.0, 150.0);
    let tilt = 35f32.to_radians();
    let length = 120.0 * s;
    let along = Vec2::new(tilt.cos(), -tilt.sin());
    let top = foot + along * length;
    painter.line_segment([foot, top], Stroke::new(6.0 * s, ink));
    painter.line_segment(
        [at(90.0, 152.0), at(290.0, 152.0)],
        Stroke::new(1.0, Color32::from_gray(120)),
    );
    // The artifact standing out of the glass, towards the eye.
    let mid = foot + along * length * 0.5;
    let normal = Vec2::new(-tilt.sin(), -tilt.cos());
    let base = mid + normal * 3.0 * s;
    painter.add(egui::Shape::convex_polygon(
        vec![base - along * 9.0 * s, base + along * 9.0 * s, base + normal * 26.0 * s],
        accent,
        Stroke::NONE,
    ));
    // The sight line with its length.
    let target = mid + normal * 12.0 * s;
    let dashes = 12;
    for k in 0..dashes {
        if k % 2 == 0 {
            let a = eye + (target - eye) * (k as f32 / dashes as f32);
            let b = eye + (target - eye) * ((k + 1) as f32 / dashes as f32);
            painter.line_segment([a, b], Stroke::new(1.5, ink));
        }
    }
    let label = eye + (target - eye) * 0.5 + Vec2::new(8.0, -14.0) * s;
    painter.text(
        label,
        Align2::LEFT_BOTTOM,
        "about 30 cm",
        FontId::proportional(14.0),
        ink,
    );
}

/// A phone seen from the front, its front camera looking at a face.
fn camera_picture(painter: &egui::Painter, rect: Rect) {
    let ink = Color32::from_gray(210);
    let accent = Color32::from_rgb(255, 190, 90);
    let s = (rect.width() / 300.0).min(rect.height() / 150.0);
    let at = |x: f32, y: f32| {
        Pos2::new(
            rect.left() + (rect.width() - 300.0 * s) * 0.5 + x * s,
            rect.top() + y * s,
        )
    };
    // The phone, upright, with its camera dot at the top.
    let phone = Rect::from_min_max(at(40.0, 10.0), at(110.0, 140.0));
    painter.rect_stroke(phone, 8.0 * s, Stroke::new(2.0, ink), egui::StrokeKind::Inside);
    let lens = at(75.0, 20.0);
    painter.circle_filled(lens, 4.0 * s, accent);
    // The face, right: head, two eyes.
    let head = at(230.0, 70.0);
    painter.circle_stroke(head, 45.0 * s, Stroke::new(2.0, ink));
    for dx in [-16.0, 16.0] {
        painter.circle_filled(head + Vec2::new(dx, -8.0) * s, 5.0 * s, ink);
    }
    // The camera's view, a dashed cone from the lens around the face, the eyes ringed.
    for target in [head + Vec2::new(-20.0, -52.0) * s, head + Vec2::new(-20.0, 52.0) * s] {
        let dashes = 12;
        for k in (0..dashes).step_by(2) {
            let a = lens + (target - lens) * (k as f32 / dashes as f32);
            let b = lens + (target - lens) * ((k + 1) as f32 / dashes as f32);
            painter.line_segment([a, b], Stroke::new(1.5, accent));
        }
    }
    for dx in [-16.0, 16.0] {
        painter.circle_stroke(head + Vec2::new(dx, -8.0) * s, 9.0 * s, Stroke::new(1.5, accent));
    }
}

/// What the camera's view of the glasses says, in words for the check.
fn camera_glasses_note(seen: &phantogram_sensing::glasses::GlassesSeen) -> String {
    let way = if seen.swapped() {
        "so they look to be on the other way round"
    } else {
        "the usual way"
    };
    format!(
        "The camera sees {} over your left eye and {} over your right: {way}.",
        seen.left.name(),
        seen.right.name()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(ctx: &egui::Context, ui_state: &mut WelcomeUi, events: Vec<egui::Event>) -> Vec<WelcomeAction> {
        let mut actions = Vec::new();
        let filters = Some(([255, 0, 0], [0, 255, 255]));
        crate::test_taps::frame(ctx, events, |ui| actions = ui_state.show(ui, filters));
        actions
    }

    fn tap(ctx: &egui::Context, ui_state: &mut WelcomeUi, name: &str) -> Vec<WelcomeAction> {
        let pos = ui_state
            .widget_rect(name)
            .unwrap_or_else(|| panic!("no {name}"))
            .center();
        let mut actions = Vec::new();
        crate::test_taps::tap(pos, |events| actions.extend(frame(ctx, ui_state, events)));
        actions
    }

    #[test]
    fn the_glasses_check_reports_which_way_round_and_start_takes_the_pose() {
        let ctx = egui::Context::default();
        let mut w = WelcomeUi::new();
        frame(&ctx, &mut w, vec![]);
        tap(&ctx, &mut w, "glasses");
        assert_eq!(w.page, WelcomePage::Glasses);
        let (l, r) = (
            w.widget_rect("ring-left").unwrap(),
            w.widget_rect("ring-right").unwrap(),
        );
        assert!(l.center().x < r.center().x && !l.intersects(r), "two separate rings");
        // The right eye sees the left ring: its filter is the left one's colour.
        assert_eq!(
            tap(&ctx, &mut w, "left-ring"),
            vec![WelcomeAction::GlassesSwapped(true)]
        );
        assert_eq!(w.page, WelcomePage::GlassesResult(GlassesFinding::Swapped));
        tap(&ctx, &mut w, "continue");
        tap(&ctx, &mut w, "glasses");
        assert_eq!(
            tap(&ctx, &mut w, "right-ring"),
            vec![WelcomeAction::GlassesSwapped(false)]
        );
        tap(&ctx, &mut w, "continue");
        tap(&ctx, &mut w, "glasses");
        assert_eq!(tap(&ctx, &mut w, "unclear"), vec![], "no glasses: nothing changes");
        tap(&ctx, &mut w, "continue");
        assert_eq!(w.page, WelcomePage::Intro);
        assert_eq!(tap(&ctx, &mut w, "start"), vec![WelcomeAction::Start]);
        assert_eq!(tap(&ctx, &mut w, "calibrate"), vec![WelcomeAction::Calibrate]);
        for name in ["start", "glasses", "calibrate"] {
            assert!(w.widget_rect(name).unwrap().height() >= CONTROL_HEIGHT_PT - 0.5);
        }
    }

    #[test]
    fn the_camera_page_asks_before_the_system_does() {
        let ctx = egui::Context::default();
        let mut w = WelcomeUi::camera();
        frame(&ctx, &mut w, vec![]);
        assert_eq!(tap(&ctx, &mut w, "allow-camera"), vec![WelcomeAction::AllowCamera]);
        assert_eq!(tap(&ctx, &mut w, "not-now"), vec![WelcomeAction::CameraNotNow]);
        for name in ["allow-camera", "not-now"] {
            assert!(w.widget_rect(name).unwrap().height() >= CONTROL_HEIGHT_PT - 0.5);
        }
    }

    #[test]
    fn the_check_says_which_way_round_the_camera_sees_the_glasses() {
        use phantogram_sensing::glasses::{Filter, GlassesSeen};
        let usual = GlassesSeen {
            left: Filter::Red,
            right: Filter::Cyan,
            strength: 2.0,
        };
        assert_eq!(
            camera_glasses_note(&usual),
            "The camera sees red over your left eye and cyan over your right: the usual way."
        );
        let swapped = GlassesSeen {
            left: Filter::Blue,
            right: Filter::Amber,
            strength: 1.0,
        };
        assert!(camera_glasses_note(&swapped).contains("blue over your left eye"));
        assert!(camera_glasses_note(&swapped).contains("other way round"));
    }
}
