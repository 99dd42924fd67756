//! Where each named control of a screen was drawn in the last frame (points): what the
//! engine's `control_px` and the tap-driven tests aim at. One per screen.
//!
//! Plain data; **panics**: none.

use std::borrow::Cow;

use egui::Rect;

/// The controls' rectangles by name, the newest for each name.
#[derive(Clone, Debug, Default)]
pub struct WidgetRects(Vec<(Cow<'static, str>, Rect)>);

impl WidgetRects {
    pub fn new() -> Self {
        Self::default()
    }

    /// The rectangle `name` was drawn in last, if it was.
    pub fn get(&self, name: &str) -> Option<Rect> {
        self.0.iter().find(|(n, _)| n == name).map(|(_, r)| *r)
    }

    /// A button `width` points wide and a finger's height tall with `label` (17 pt), drawn now
    /// and remembered as `name`; whether it was tapped.
    pub fn wide_button(&mut self, ui: &mut egui::Ui, name: &'static str, label: &str, width: f32) -> bool {
        let r = ui.add_sized(
            [width, crate::menu::CONTROL_HEIGHT_PT],
            egui::Button::new(egui::RichText::new(label).size(17.0)),
        );
        self.remember(name, r.rect);
        r.clicked()
    }

    /// Notes that `name` was drawn in `rect` (replacing where it was before).
    pub fn remember(&mut self, name: impl Into<Cow<'static, str>>, rect: Rect) {
        let name = name.into();
        self.0.retain(|(n, _)| *n != name);
        self.0.push((name, rect));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_newest_rectangle_of_each_name_is_kept() {
        let mut w = WidgetRects::new();
        let a = Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
        let b = Rect::from_min_max(egui::pos2(2.0, 2.0), egui::pos2(3.0, 3.0));
        w.remember("done", a);
        w.remember(format!("item:{}", 7), b);
        w.remember("done", b);
        assert_eq!(w.get("done"), Some(b));
        assert_eq!(w.get("item:7"), Some(b));
        assert_eq!(w.get("close"), None);
    }
}
