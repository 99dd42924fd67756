//! Driving the screens by simulated taps in the unit tests: one egui frame with some events on
//! a phone-sized screen, and a finger's tap (pressed in one frame, lifted in the next, then a
//! frame for the screen to settle).

use egui::{Pos2, Rect, Vec2};

/// One frame of `show` on a 390 × 844 point screen with `events`; its textures are dropped (no
/// GPU in unit tests).
pub fn frame(ctx: &egui::Context, events: Vec<egui::Event>, show: impl FnMut(&mut egui::Ui)) {
    let input = egui::RawInput {
        screen_rect: Some(Rect::from_min_size(Pos2::ZERO, Vec2::new(390.0, 844.0))),
        events,
        ..Default::default()
    };
    let mut out = ctx.run_ui(input, show);
    out.textures_delta.clear();
}

/// A tap at `pos`, one frame at a time through `frame`.
pub fn tap(pos: Pos2, mut frame: impl FnMut(Vec<egui::Event>)) {
    let button = |pressed| egui::Event::PointerButton {
        pos,
        button: egui::PointerButton::Primary,
        pressed,
        modifiers: Default::default(),
    };
    frame(vec![egui::Event::PointerMoved(pos), button(true)]);
    frame(vec![button(false), egui::Event::PointerGone]);
    frame(vec![]);
}
