//! The settings screen, opened from the menu: which glasses (red/cyan, green/magenta,
//! amber/blue, or none for a plain picture), whether tilting the phone or a finger turns the
//! artifact ("reduce motion"), the diorama's floor, how much of a loaded model stands in front
//! of the glass, whether loaded models keep their true size, surface mode (artifacts lying
//! in the glass at true size), and the light (the studio's, or the room's own from the camera).
//! It scrolls when a large system
//! text size makes it taller than the screen.
//!
//! The host gives the current settings when it opens the screen and applies (and saves) each
//! [`SettingsAction::Changed`]. **Threading**: the render thread. **Panics**: none.

use egui::{Rect, RichText};
use phantogram_geometry::anaglyph::Method;

use crate::menu::CONTROL_HEIGHT_PT;

/// What the screen sets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    pub method: Method,
    pub floor: bool,
    /// Fraction of a loaded model's height in front of the glass, 0 to 1.
    pub protrude_fraction: f32,
    pub true_size: bool,
    /// Surface mode: artifacts at true size with their front in the glass (coins, paintings).
    pub surface: bool,
    /// "Reduce motion": a finger turns the artifact; tilting the phone does nothing.
    pub turn_by_touch: bool,
    /// The light: the room's own, seen by the front camera (`true`), or the studio's.
    pub room_light: bool,
}

/// What the host must do after a frame of the settings screen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SettingsAction {
    Changed(Settings),
    Close,
}

/// The glasses the screen offers, with the method each means.
pub const GLASSES: [(&str, &str, Method); 4] = [
    ("red-cyan", "Red / cyan", Method::DuboisRedCyan),
    ("green-magenta", "Green / magenta", Method::DuboisGreenMagenta),
    ("amber-blue", "Amber / blue", Method::DuboisAmberBlue),
    ("none", "No glasses (flat picture)", Method::Mono),
];

/// The settings screen's state.
#[derive(Clone, Debug)]
pub struct SettingsUi {
    pub settings: Settings,
    widget_rects: crate::widget_rects::WidgetRects,
}

impl SettingsUi {
    pub fn new(settings: Settings) -> Self {
        Self {
            settings,
            widget_rects: crate::widget_rects::WidgetRects::new(),
        }
    }

    /// The rectangle (points) of a control drawn last frame: the glasses by key (`red-cyan`,
    /// `green-magenta`, `amber-blue`, `none`), `turn-by-touch`, `floor`, `protrude`,
    /// `true-size`, `surface`, `room-light`, `done`.
    pub fn widget_rect(&self, name: &str) -> Option<Rect> {
        self.widget_rects.get(name)
    }

    /// A button that switches `value`, its label saying the state.
    fn switch(&mut self, ui: &mut egui::Ui, name: &'static str, width: f32, value: &mut bool, on: &str, off: &str) {
        let r = ui.add_sized(
            [width, CONTROL_HEIGHT_PT],
            egui::Button::new(RichText::new(if *value { on } else { off }).size(17.0)).selected(*value),
        );
        self.widget_rects.remember(name, r.rect);
        if r.clicked() {
            *value = !*value;
        }
    }

    pub fn show(&mut self, ui: &mut egui::Ui) -> Vec<SettingsAction> {
        let before = self.settings;
        let mut actions = Vec::new();
        egui::CentralPanel::default().show(ui, |ui| {
            egui::ScrollArea::vertical().auto_shrink([false, false]).show(ui, |ui| {
                // One width for every control (a slider's own layout may widen the rest).
                let full = ui.available_width().max(0.0);
                ui.heading(RichText::new("Settings").size(24.0));
                ui.add_space(6.0);
                ui.label(RichText::new("Glasses").size(18.0));
                for (key, label, method) in GLASSES {
                    let chosen = self.settings.method == method
                        || (key == "red-cyan" && !GLASSES.iter().any(|g| g.2 == self.settings.method));
                    let r = ui.add_sized(
                        [full, CONTROL_HEIGHT_PT],
                        egui::Button::new(RichText::new(label).size(17.0)).selected(chosen),
                    );
                    self.widget_rects.remember(key, r.rect);
                    if r.clicked() {
                        self.settings.method = method;
                    }
                }
                ui.add_space(10.0);
                let mut turn = self.settings.turn_by_touch;
                self.switch(
                    ui,
                    "turn-by-touch",
                    full,
                    &mut turn,
                    "Turn it with a finger (tilting does nothing)",
                    "Look around it by tilting the phone",
                );
                self.settings.turn_by_touch = turn;
                ui.add_space(6.0);
                let mut floor = self.settings.floor;
                self.switch(
                    ui,
                    "floor",
                    full,
                    &mut floor,
                    "Floor under the artifact: on",
                    "Floor under the artifact: off",
                );
                self.settings.floor = floor;
                ui.add_space(6.0);
                let name =
                    ui.label(RichText::new("Your own files: how much stands in front of the glass (%)").size(16.0));
                // Room for the value box beside the slider.
                ui.spacing_mut().slider_width = (full - 80.0).max(100.0);
                ui.spacing_mut().interact_size.y = CONTROL_HEIGHT_PT;
                let mut percent = self.settings.protrude_fraction * 100.0;
                // Named for a screen reader by the text above it.
                let r = ui
                    .add(egui::Slider::new(&mut percent, 0.0..=100.0).step_by(5.0))
                    .labelled_by(name.id);
                self.widget_rects.remember("protrude", r.rect);
                self.settings.protrude_fraction = (percent / 100.0).clamp(0.0, 1.0);
                let mut true_size = self.settings.true_size;
                self.switch(
                    ui,
                    "true-size",
                    full,
                    &mut true_size,
                    "Size: as in the file (true size)",
                    "Size: fitted to the screen",
                );
                self.settings.true_size = true_size;
                let mut surface = self.settings.surface;
                self.switch(
                    ui,
                    "surface",
                    full,
                    &mut surface,
                    "Surface mode: lying in the glass, true size",
                    "Surface mode: off",
                );
                self.settings.surface = surface;
                let mut room_light = self.settings.room_light;
                self.switch(
                    ui,
                    "room-light",
                    full,
                    &mut room_light,
                    "Light: your room's, seen by the camera",
                    "Light: the studio's",
                );
                self.settings.room_light = room_light;
                ui.add_space(10.0);
                if self.widget_rects.wide_button(ui, "done", "Done", full) {
                    actions.push(SettingsAction::Close);
                }
            });
        });
        if self.settings != before {
            actions.insert(0, SettingsAction::Changed(self.settings));
        }
        actions
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(ctx: &egui::Context, s: &mut SettingsUi, events: Vec<egui::Event>) -> Vec<SettingsAction> {
        let mut actions = Vec::new();
        crate::test_taps::frame(ctx, events, |ui| actions = s.show(ui));
        actions
    }

    fn tap(ctx: &egui::Context, s: &mut SettingsUi, name: &str) -> Vec<SettingsAction> {
        let pos = s.widget_rect(name).unwrap_or_else(|| panic!("no {name}")).center();
        let mut actions = Vec::new();
        crate::test_taps::tap(pos, |events| actions.extend(frame(ctx, s, events)));
        actions
    }

    #[test]
    fn taps_choose_the_glasses_floor_and_size_and_each_change_is_reported() {
        let ctx = egui::Context::default();
        let start = Settings {
            method: Method::DuboisRedCyan,
            floor: true,
            protrude_fraction: 0.4,
            true_size: false,
            surface: false,
            turn_by_touch: false,
            room_light: false,
        };
        let mut s = SettingsUi::new(start);
        frame(&ctx, &mut s, vec![]);
        frame(&ctx, &mut s, vec![]);
        for name in [
            "red-cyan",
            "none",
            "turn-by-touch",
            "floor",
            "true-size",
            "surface",
            "room-light",
            "done",
        ] {
            assert!(
                s.widget_rect(name).unwrap().height() >= CONTROL_HEIGHT_PT - 0.5,
                "{name}"
            );
        }
        let changed = |m: Method, floor: bool, true_size: bool| {
            SettingsAction::Changed(Settings {
                method: m,
                floor,
                protrude_fraction: 0.4,
                true_size,
                surface: false,
                turn_by_touch: false,
                room_light: false,
            })
        };
        assert_eq!(
            tap(&ctx, &mut s, "amber-blue"),
            vec![changed(Method::DuboisAmberBlue, true, false)]
        );
        assert_eq!(
            tap(&ctx, &mut s, "floor"),
            vec![changed(Method::DuboisAmberBlue, false, false)]
        );
        assert_eq!(
            tap(&ctx, &mut s, "true-size"),
            vec![changed(Method::DuboisAmberBlue, false, true)]
        );
        assert_eq!(tap(&ctx, &mut s, "none"), vec![changed(Method::Mono, false, true)]);
        assert_eq!(
            tap(&ctx, &mut s, "turn-by-touch"),
            vec![SettingsAction::Changed(Settings {
                turn_by_touch: true,
                ..s.settings
            })]
        );
        assert!(s.settings.turn_by_touch);
        let before = s.settings;
        assert_eq!(
            tap(&ctx, &mut s, "room-light"),
            vec![SettingsAction::Changed(Settings {
                room_light: true,
                ..before
            })]
        );
        assert_eq!(tap(&ctx, &mut s, "done"), vec![SettingsAction::Close]);
    }
}
