//! The material screen, opened from the menu: the artifact on screen as found (its file's
//! material) or in one of the Ward presets (matte, glazed, polished, patinated, brushed metal,
//! silk, lacquer), and sliders for its colour tint, roughness, metalness, specular strength and a
//! clear coat — or, with a Ward preset, for its gloss and its roughness along and across the
//! grain, and a choice of its surface's texture map (smooth, brushed grooves, woven threads). Every change is reported at once, so the artifact shows it in the next frame. It takes
//! the lower part of the screen ([`PANEL_FRACTION`]) and scrolls there, so the artifact stays in
//! view above it.
//!
//! The host gives the artifact's current [`Appearance`] when it opens the screen, applies each
//! [`MaterialAction::Changed`] (and remembers it for that artifact). **Threading**: the render
//! thread. **Panics**: none.

use egui::{Rect, RichText};
use phantogram_render::Appearance;
use phantogram_render::ward::{WardMap, WardPreset};

use crate::menu::CONTROL_HEIGHT_PT;

/// The share of the screen's height the panel takes (from the bottom); the artifact shows above.
pub const PANEL_FRACTION: f32 = 0.4;

/// What the host must do after a frame of the material screen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaterialAction {
    Changed(Appearance),
    Close,
}

/// The material screen's state.
#[derive(Clone, Debug)]
pub struct MaterialUi {
    pub appearance: Appearance,
    widget_rects: crate::widget_rects::WidgetRects,
}

/// The key of a preset's button: `preset-` and its name with dashes (`preset-brushed-metal`).
pub fn preset_key(preset: WardPreset) -> &'static str {
    match preset {
        WardPreset::Matte => "preset-matte",
        WardPreset::Glazed => "preset-glazed",
        WardPreset::Polished => "preset-polished",
        WardPreset::Patinated => "preset-patinated",
        WardPreset::BrushedMetal => "preset-brushed-metal",
        WardPreset::Silk => "preset-silk",
        WardPreset::Lacquer => "preset-lacquer",
    }
}

/// The key of a texture map's button: `map-` and its store key (`map-woven`).
pub fn map_key(map: WardMap) -> &'static str {
    match map {
        WardMap::Uniform => "map-uniform",
        WardMap::Brushed => "map-brushed",
        WardMap::Woven => "map-woven",
    }
}

/// The words a texture map's button shows.
fn map_label(map: WardMap) -> &'static str {
    match map {
        WardMap::Uniform => "Smooth",
        WardMap::Brushed => "Grooves",
        WardMap::Woven => "Woven",
    }
}

impl MaterialUi {
    pub fn new(appearance: Appearance) -> Self {
        Self {
            appearance: appearance.sanitised(),
            widget_rects: crate::widget_rects::WidgetRects::new(),
        }
    }

    /// The rectangle (points) of a control drawn last frame: `as-found`, the presets
    /// ([`preset_key`]), the sliders `tint-red`, `tint-green`, `tint-blue`, `roughness`,
    /// `metalness`, `specular`, `clear-coat`, `coat-roughness`, with a Ward preset `gloss`,
    /// `along`, `across` and the texture maps ([`map_key`]); and `done`.
    pub fn widget_rect(&self, name: &str) -> Option<Rect> {
        self.widget_rects.get(name)
    }

    /// A labelled percentage slider over `value` in [0, `max`]; returns whether it moved.
    fn slider(&mut self, ui: &mut egui::Ui, name: &'static str, label: &str, value: &mut f32, max: f32) -> bool {
        let text = ui.label(RichText::new(label).size(16.0));
        let mut percent = *value * 100.0;
        let r = ui
            .add(
                egui::Slider::new(&mut percent, 0.0..=max * 100.0)
                    .step_by(1.0)
                    .suffix(" %"),
            )
            .labelled_by(text.id);
        self.widget_rects.remember(name, r.rect);
        if r.changed() {
            *value = (percent / 100.0).clamp(0.0, max);
        }
        r.changed()
    }

    /// A roughness slider (1–100 %, logarithmic: the sharp end matters most).
    fn roughness_slider(&mut self, ui: &mut egui::Ui, name: &'static str, label: &str, value: &mut f32) -> bool {
        let text = ui.label(RichText::new(label).size(16.0));
        let mut percent = *value * 100.0;
        let r = ui
            .add(
                egui::Slider::new(&mut percent, 1.0..=100.0)
                    .logarithmic(true)
                    .suffix(" %"),
            )
            .labelled_by(text.id);
        self.widget_rects.remember(name, r.rect);
        if r.changed() {
            *value = (percent / 100.0).clamp(0.01, 1.0);
        }
        r.changed()
    }

    pub fn show(&mut self, ui: &mut egui::Ui) -> Vec<MaterialAction> {
        let before = self.appearance;
        let mut actions = Vec::new();
        // The lower part of the screen, so that the artifact stays in view above it and each
        // change can be seen as it is made.
        let height = ui.ctx().content_rect().height() * PANEL_FRACTION;
        egui::Panel::bottom("material")
            .resizable(false)
            .exact_size(height)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().auto_shrink([false, false]).show(ui, |ui| {
                    let full = ui.available_width().max(0.0);
                    ui.heading(RichText::new("Material").size(24.0));
                    ui.label("Try the artifact in another material. It is kept for this artifact.");
                    ui.add_space(6.0);
                    // Presets, two to a row; "as found" first.
                    // Never negative, however narrow the screen (egui asserts on negative sizes).
                    let half = ((full - ui.spacing().item_spacing.x) / 2.0).max(0.0);
                    let mut choices: Vec<(&'static str, &'static str, Option<WardPreset>)> =
                        vec![("as-found", "As found", None)];
                    choices.extend(WardPreset::ALL.map(|p| (preset_key(p), p.name(), Some(p))));
                    for row in choices.chunks(2) {
                        ui.horizontal(|ui| {
                            for (key, label, preset) in row {
                                let chosen = match preset {
                                    None => self.appearance.is_default(),
                                    Some(p) => self.appearance.ward == Some(p.material()),
                                };
                                let r = ui.add_sized(
                                    [half, CONTROL_HEIGHT_PT],
                                    egui::Button::new(RichText::new(*label).size(17.0)).selected(chosen),
                                );
                                self.widget_rects.remember(*key, r.rect);
                                if r.clicked() {
                                    self.appearance = preset.map_or_else(Appearance::default, Appearance::preset);
                                }
                            }
                        });
                    }
                    ui.add_space(8.0);
                    ui.spacing_mut().slider_width = (full - 90.0).max(100.0);
                    ui.spacing_mut().interact_size.y = CONTROL_HEIGHT_PT;
                    let mut a = self.appearance;
                    for (c, (name, label)) in [
                        ("tint-red", "Colour: red"),
                        ("tint-green", "Colour: green"),
                        ("tint-blue", "Colour: blue"),
                    ]
                    .into_iter()
                    .enumerate()
                    {
                        self.slider(ui, name, label, &mut a.tint[c], 1.0);
                    }
                    match &mut a.ward {
                        Some(ward) => {
                            // Gloss scales the lobe's albedo, keeping its colour; the diffuse part
                            // yields so that the two never exceed one.
                            let mut gloss = ward.rho_s.iter().copied().fold(0.0, f32::max);
                            if self.slider(ui, "gloss", "Gloss", &mut gloss, 1.0) {
                                let old = ward.rho_s.iter().copied().fold(0.0, f32::max).max(1e-3);
                                ward.rho_s = ward.rho_s.map(|s| if old > 1e-3 { s * gloss / old } else { gloss });
                            }
                            self.roughness_slider(ui, "along", "Roughness along the grain", &mut ward.alpha_x);
                            self.roughness_slider(ui, "across", "Roughness across the grain", &mut ward.alpha_y);
                            // The surface's structure: three buttons in a row, the chosen one lit.
                            ui.label(RichText::new("Surface").size(16.0));
                            let third = ((full - 2.0 * ui.spacing().item_spacing.x) / 3.0).max(0.0);
                            ui.horizontal(|ui| {
                                for map in WardMap::ALL {
                                    let r = ui.add_sized(
                                        [third, CONTROL_HEIGHT_PT],
                                        egui::Button::new(RichText::new(map_label(map)).size(17.0))
                                            .selected(ward.map == map),
                                    );
                                    self.widget_rects.remember(map_key(map), r.rect);
                                    if r.clicked() {
                                        ward.map = map;
                                    }
                                }
                            });
                        }
                        None => {
                            let mut roughness = a.roughness.unwrap_or(0.5);
                            if self.slider(ui, "roughness", "Roughness", &mut roughness, 1.0) {
                                a.roughness = Some(roughness);
                            }
                            let mut metalness = a.metalness.unwrap_or(0.0);
                            if self.slider(ui, "metalness", "Metal", &mut metalness, 1.0) {
                                a.metalness = Some(metalness);
                            }
                            self.slider(ui, "specular", "Shine of the surface", &mut a.specular, 2.0);
                        }
                    }
                    self.slider(ui, "clear-coat", "Clear coat (varnish)", &mut a.clear_coat, 1.0);
                    self.slider(
                        ui,
                        "coat-roughness",
                        "Roughness of the coat",
                        &mut a.clear_coat_roughness,
                        1.0,
                    );
                    self.appearance = a.sanitised();
                    ui.add_space(10.0);
                    if self.widget_rects.wide_button(ui, "done", "Done", full) {
                        actions.push(MaterialAction::Close);
                    }
                });
            });
        if self.appearance != before {
            actions.insert(0, MaterialAction::Changed(self.appearance));
        }
        actions
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(ctx: &egui::Context, s: &mut MaterialUi, events: Vec<egui::Event>) -> Vec<MaterialAction> {
        let mut actions = Vec::new();
        crate::test_taps::frame(ctx, events, |ui| actions = s.show(ui));
        actions
    }

    fn tap(ctx: &egui::Context, s: &mut MaterialUi, name: &str) -> Vec<MaterialAction> {
        let pos = s.widget_rect(name).unwrap_or_else(|| panic!("no {name}")).center();
        let mut actions = Vec::new();
        crate::test_taps::tap(pos, |events| actions.extend(frame(ctx, s, events)));
        actions
    }

    /// Scrolls the panel until the control `name` is within its visible part.
    fn scroll_to(ctx: &egui::Context, s: &mut MaterialUi, name: &str) {
        let (top, bottom) = (844.0 * (1.0 - PANEL_FRACTION), 844.0);
        for _ in 0..10 {
            let r = s.widget_rect(name).unwrap_or_else(|| panic!("no {name}"));
            if r.top() >= top && r.bottom() <= bottom {
                return;
            }
            let wheel = egui::Event::MouseWheel {
                unit: egui::MouseWheelUnit::Point,
                delta: egui::vec2(0.0, (top + bottom) / 2.0 - r.center().y),
                phase: egui::TouchPhase::Move,
                source: egui::MouseWheelSource::Wheel,
                modifiers: Default::default(),
            };
            frame(ctx, s, vec![egui::Event::PointerMoved(egui::pos2(195.0, 700.0)), wheel]);
            for _ in 0..20 {
                frame(ctx, s, vec![]);
            }
        }
        panic!("{name} never scrolled into view");
    }

    #[test]
    fn presets_and_sliders_report_each_change_at_once() {
        let ctx = egui::Context::default();
        let mut s = MaterialUi::new(Appearance::default());
        frame(&ctx, &mut s, vec![]);
        frame(&ctx, &mut s, vec![]);
        for name in [
            "as-found",
            "preset-glazed",
            "preset-lacquer",
            "roughness",
            "clear-coat",
            "done",
        ] {
            let r = s.widget_rect(name).unwrap_or_else(|| panic!("no {name}"));
            assert!(r.height() >= CONTROL_HEIGHT_PT - 0.5, "{name} is tall enough to tap");
        }
        // A preset: reported, and the Ward sliders replace roughness and metal.
        let glazed = Appearance::preset(WardPreset::Glazed);
        assert_eq!(
            tap(&ctx, &mut s, "preset-glazed"),
            vec![MaterialAction::Changed(glazed)]
        );
        frame(&ctx, &mut s, vec![]);
        assert!(s.widget_rect("along").is_some() && s.widget_rect("gloss").is_some());
        // Its surface woven, then smooth again: each reported with the rest unchanged.
        scroll_to(&ctx, &mut s, map_key(WardMap::Woven));
        let woven = tap(&ctx, &mut s, map_key(WardMap::Woven));
        let Some(MaterialAction::Changed(w)) = woven.first() else {
            panic!("the weave was reported: {woven:?}")
        };
        assert_eq!(w.ward.map(|w| w.map), Some(WardMap::Woven));
        assert_eq!(
            tap(&ctx, &mut s, map_key(WardMap::Uniform)),
            vec![MaterialAction::Changed(glazed)]
        );
        for map in WardMap::ALL {
            let r = s.widget_rect(map_key(map)).expect("a map button");
            assert!(
                r.height() >= CONTROL_HEIGHT_PT - 0.5 && r.width() >= 60.0,
                "{map:?}: {r:?}"
            );
        }
        // Dragging the clear-coat slider to its right end: a full coat, reported in that frame.
        scroll_to(&ctx, &mut s, "clear-coat");
        let r = s.widget_rect("clear-coat").expect("slider");
        let (from, to) = (
            r.left_center() + egui::vec2(4.0, 0.0),
            r.right_center() - egui::vec2(60.0, 0.0),
        );
        let button = |pos, pressed| egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: Default::default(),
        };
        let mut actions = frame(&ctx, &mut s, vec![egui::Event::PointerMoved(from), button(from, true)]);
        actions.extend(frame(&ctx, &mut s, vec![egui::Event::PointerMoved(to)]));
        actions.extend(frame(&ctx, &mut s, vec![button(to, false), egui::Event::PointerGone]));
        let Some(MaterialAction::Changed(coated)) = actions.last() else {
            panic!("the drag reported a change: {actions:?}")
        };
        assert!(coated.clear_coat > 0.9, "{coated:?}");
        assert_eq!(coated.ward, glazed.ward);
        // Back to the file's own material; then done.
        scroll_to(&ctx, &mut s, "as-found");
        assert_eq!(
            tap(&ctx, &mut s, "as-found"),
            vec![MaterialAction::Changed(Appearance::default())]
        );
        // Done is below the fold on a phone: scrolled to, then tapped.
        scroll_to(&ctx, &mut s, "done");
        assert_eq!(tap(&ctx, &mut s, "done"), vec![MaterialAction::Close]);
    }
}
