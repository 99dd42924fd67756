//! The hint toward a side of the artifact not seen yet: an arrow at the edge of the picture
//! pointing the way to tilt, with a short line of text beside it. Drawn over the composed frame,
//! so it lies at the glass in both eyes (no disparity), where a finger and the eyes expect
//! screen furniture. It takes no touches: the picture under it still turns and taps.
//!
//! Which way comes from `phantogram_detail::seen` (via the engine); here only where it goes on
//! the screen. Threading: the render thread's egui context. Panics: none.

use egui::{Color32, Pos2, Stroke, Vec2};

/// What the hint says, beside its arrow.
pub const HINT_TEXT: &str = "Tilt this way to see another side";

/// Draws the hint toward `toward` (a direction in the picture, x right, y down; need not be unit
/// length) on `ctx`'s foreground, inside `margin_pt` of the screen's edge. Returns where the
/// arrow's tip is (points), `None` for a direction of zero length.
pub fn show_side_hint(ctx: &egui::Context, toward: [f32; 2], margin_pt: f32) -> Option<Pos2> {
    let dir = Vec2::new(toward[0], toward[1]);
    let len = dir.length();
    if !(len.is_finite() && len > 0.0) {
        return None;
    }
    let dir = dir / len;
    let screen = ctx.content_rect().shrink(margin_pt);
    let centre = screen.center();
    // From the centre along `dir` to the inset edge.
    let half = screen.size() * 0.5;
    let reach = [(half.x, dir.x), (half.y, dir.y)]
        .iter()
        .filter(|(_, d)| d.abs() > 1e-6)
        .map(|(h, d)| h / d.abs())
        .fold(f32::INFINITY, f32::min);
    let tip = centre + dir * reach;
    // A long head on a shaft: unmistakably an arrow at any angle.
    let (head, half_width, shaft) = (26.0, 13.0, 30.0);
    let base = tip - dir * head;
    let across = Vec2::new(-dir.y, dir.x);
    let painter = ctx.layer_painter(egui::LayerId::new(
        egui::Order::Foreground,
        egui::Id::unique("side hint"),
    ));
    let fill = Color32::from_rgba_unmultiplied(255, 214, 90, 240);
    let outline = Stroke::new(2.0, Color32::from_black_alpha(200));
    let tail = base - dir * shaft;
    painter.line_segment([tail, base], Stroke::new(10.0, Color32::from_black_alpha(200)));
    painter.line_segment([tail, base], Stroke::new(6.0, fill));
    painter.add(egui::Shape::convex_polygon(
        vec![tip, base + across * half_width, base - across * half_width],
        fill,
        outline,
    ));
    // The text further in, on a dark plate that reads on any picture, kept on the screen.
    let font = egui::FontId::proportional(17.0);
    let galley = painter.layout_no_wrap(HINT_TEXT.to_owned(), font, Color32::WHITE);
    let plate = galley.size() + Vec2::splat(12.0);
    let extent = dir.x.abs() * plate.x * 0.5 + dir.y.abs() * plate.y * 0.5;
    let rect = egui::Rect::from_center_size(tail - dir * (6.0 + extent), plate);
    let rect = rect.translate(Vec2::new(
        (screen.left() - rect.left()).max(0.0) + (screen.right() - rect.right()).min(0.0),
        (screen.top() - rect.top()).max(0.0) + (screen.bottom() - rect.bottom()).min(0.0),
    ));
    painter.rect_filled(rect, 8.0, Color32::from_black_alpha(170));
    painter.galley(rect.min + Vec2::splat(6.0), galley, Color32::WHITE);
    Some(tip)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tip_for(toward: [f32; 2]) -> Option<Pos2> {
        let ctx = egui::Context::default();
        let mut tip = None;
        let raw = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(Pos2::ZERO, egui::vec2(400.0, 800.0))),
            ..Default::default()
        };
        let mut out = ctx.run_ui(raw, |ui| tip = show_side_hint(ui.ctx(), toward, 16.0));
        // No GPU here: the font atlas is not uploaded.
        out.textures_delta.clear();
        tip
    }

    #[test]
    fn the_arrow_sits_at_the_edge_it_points_to() {
        let left = tip_for([-1.0, 0.0]).unwrap();
        assert!((left.x - 16.0).abs() < 0.5 && (left.y - 400.0).abs() < 0.5, "{left:?}");
        let up = tip_for([0.0, -3.0]).unwrap();
        assert!((up.y - 16.0).abs() < 0.5 && (up.x - 200.0).abs() < 0.5, "{up:?}");
        // A diagonal reaches the nearer edge (the sides of a tall screen).
        let corner = tip_for([1.0, 1.0]).unwrap();
        assert!((corner.x - 384.0).abs() < 0.5 && corner.y < 784.0, "{corner:?}");
        assert!(tip_for([0.0, 0.0]).is_none());
        assert!(tip_for([f32::NAN, 1.0]).is_none());
    }
}
