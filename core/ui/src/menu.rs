//! The menu a single tap opens — the artifact gallery (choose what to look at, remove what was
//! imported, open a file of your own) and the way to the calibration screens — and the status
//! banner that shows loading progress and failures over the picture, menu open or not.
//!
//! Drawn by egui like the calibration screens, so that both phones and the desktop viewer show the
//! same thing from the same code. Controls are at least 48 points tall (Android's minimum touch
//! target; iOS asks for 44), text at egui's body size times the display's density.
//!
//! The host gives the items and the banner's state each frame and acts on the returned actions
//! (this module owns no engine state). **Threading**: the render thread. **Panics**: none.

use egui::{Align2, Color32, Rect, RichText};

/// Height of every control, points (Android's 48 dp minimum touch target).
pub const CONTROL_HEIGHT_PT: f32 = 48.0;

/// An artifact as the gallery lists it.
#[derive(Clone, Debug, PartialEq)]
pub struct MenuItem {
    /// The library's id, as text (`builtin:medal`, …).
    pub id: String,
    pub title: String,
    pub credit: Option<String>,
    pub licence: Option<String>,
    /// Imported by the user: may be removed.
    pub removable: bool,
    /// Its picture, drawn by the renderer (an egui texture the host registered); `None` until
    /// made, or when it cannot be.
    pub thumbnail: Option<egui::TextureId>,
}

/// What the host must do after a frame of the menu.
#[derive(Clone, Debug, PartialEq)]
pub enum MenuAction {
    /// Show this artifact (and close the menu).
    Select(String),
    /// Remove this imported artifact from the library (confirmed by a second tap).
    Remove(String),
    /// Ask the platform for a file (Android's document picker, iOS's document browser).
    OpenFile,
    /// Share the view through the platform's share sheet: as the red/cyan picture, or as a
    /// side-by-side stereo pair (`side_by_side`).
    Share {
        side_by_side: bool,
    },
    /// Open the calibration screens instead.
    Calibrate,
    /// Open the settings screen instead.
    Settings,
    /// Open the material screen for the artifact on screen.
    Material,
    /// Show what the gestures do.
    Help,
    /// Put a lamp over the diorama that a finger moves, or take it away (back to the room's
    /// light).
    Lamp,
    Close,
}

/// The menu's state: which removal awaits confirmation, whether a lamp is on (the lamp
/// button's label), and where the controls were drawn.
#[derive(Clone, Debug, Default)]
pub struct MenuUi {
    confirm_remove: Option<String>,
    /// A lamp shines in place of the room's light (set by the host when it opens the menu).
    pub lamp_on: bool,
    widget_rects: crate::widget_rects::WidgetRects,
}

impl MenuUi {
    pub fn new() -> Self {
        Self::default()
    }

    /// The rectangle (points) of a control drawn last frame: `item:<id>`, `thumb:<id>` (its
    /// picture), `remove:<id>`, `open`, `share`, `share-pair`, `help`, `material`, `lamp`,
    /// `settings`, `calibrate`, `close`.
    pub fn widget_rect(&self, name: &str) -> Option<Rect> {
        self.widget_rects.get(name)
    }

    /// Draws the menu into the root `ui` of one egui frame; `current` is the id on screen and
    /// `status` a line on how the eyes are found (the front camera's state).
    pub fn show(
        &mut self,
        ui: &mut egui::Ui,
        items: &[MenuItem],
        current: Option<&str>,
        status: &str,
    ) -> Vec<MenuAction> {
        let mut actions = Vec::new();
        egui::Panel::bottom("menu buttons").show(ui, |ui| {
            ui.add_space(6.0);
            // The view as it is now (the menu is not in the picture), two ways, side by side.
            ui.horizontal(|ui| {
                // Never negative, however narrow the screen (egui asserts on negative sizes).
                let half = ((ui.available_width() - ui.spacing().item_spacing.x) / 2.0).max(0.0);
                for (name, label, side_by_side) in [
                    ("share", "Share the picture", false),
                    ("share-pair", "Share as a stereo pair", true),
                ] {
                    // Wrapped: at a large system text size the label takes two lines rather
                    // than widening the row past the screen.
                    let r = ui.add_sized(
                        [half, CONTROL_HEIGHT_PT],
                        egui::Button::new(RichText::new(label).size(16.0)).wrap(),
                    );
                    self.widget_rects.remember(name, r.rect);
                    if r.clicked() {
                        actions.push(MenuAction::Share { side_by_side });
                    }
                }
            });
            let lamp = if self.lamp_on {
                "Back to the room's light"
            } else {
                "A lamp to move with your finger"
            };
            let buttons = [
                ("open", "Open a file of your own…"),
                ("help", "How to use it"),
                ("material", "Material (glaze, metal, varnish…)"),
                ("lamp", lamp),
                ("settings", "Settings (glasses, size, floor)"),
                ("calibrate", "Calibration"),
                ("close", "Done"),
            ];
            for (name, label) in buttons {
                let r = ui.add_sized(
                    [ui.available_width(), CONTROL_HEIGHT_PT],
                    egui::Button::new(RichText::new(label).size(17.0)).wrap(),
                );
                self.widget_rects.remember(name, r.rect);
                if r.clicked() {
                    actions.push(match name {
                        "open" => MenuAction::OpenFile,
                        "calibrate" => MenuAction::Calibrate,
                        "settings" => MenuAction::Settings,
                        "material" => MenuAction::Material,
                        "lamp" => MenuAction::Lamp,
                        "help" => MenuAction::Help,
                        _ => MenuAction::Close,
                    });
                }
            }
            ui.add_space(6.0);
        });
        egui::CentralPanel::default().show(ui, |ui| {
            ui.heading(RichText::new("Artifacts").size(24.0));
            ui.label(RichText::new(status).color(Color32::from_rgb(150, 200, 255)));
            ui.label("Tap one to look at it. Files you open are kept here.");
            ui.add_space(8.0);
            egui::ScrollArea::vertical().show(ui, |ui| {
                for item in items {
                    self.item(ui, item, current == Some(item.id.as_str()), &mut actions);
                }
            });
        });
        actions
    }

    fn item(&mut self, ui: &mut egui::Ui, item: &MenuItem, on_screen: bool, actions: &mut Vec<MenuAction>) {
        let confirming = self.confirm_remove.as_deref() == Some(item.id.as_str());
        ui.horizontal(|ui| {
            let remove_w = if item.removable { 96.0 } else { 0.0 };
            // The picture, left of the title; a tap on it chooses the artifact too.
            let side = CONTROL_HEIGHT_PT * 1.4;
            let (rect, picture) = ui.allocate_exact_size(egui::Vec2::splat(side), egui::Sense::click());
            ui.painter()
                .rect_filled(rect, 6.0, ui.visuals().widgets.inactive.weak_bg_fill);
            if let Some(texture) = item.thumbnail {
                let uv = Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
                ui.painter().image(texture, rect.shrink(2.0), uv, Color32::WHITE);
            }
            self.widget_rects.remember(format!("thumb:{}", item.id), rect);
            if picture.clicked() {
                self.confirm_remove = None;
                actions.push(MenuAction::Select(item.id.clone()));
            }
            let mut text = egui::text::LayoutJob::default();
            let title_colour = if on_screen {
                Color32::from_rgb(255, 210, 120)
            } else {
                ui.visuals().strong_text_color()
            };
            text.append(
                &item.title,
                0.0,
                egui::TextFormat::simple(egui::FontId::proportional(18.0), title_colour),
            );
            let small = [item.credit.as_deref(), item.licence.as_deref()]
                .into_iter()
                .flatten()
                .collect::<Vec<_>>()
                .join(" · ");
            if !small.is_empty() {
                text.append(
                    &format!("\n{small}"),
                    0.0,
                    egui::TextFormat::simple(egui::FontId::proportional(13.0), ui.visuals().text_color()),
                );
            }
            let width = (ui.available_width() - remove_w).max(CONTROL_HEIGHT_PT);
            let r = ui.add_sized(
                [width, CONTROL_HEIGHT_PT * 1.4],
                egui::Button::new(text).selected(on_screen).wrap(),
            );
            self.widget_rects.remember(format!("item:{}", item.id), r.rect);
            if r.clicked() {
                self.confirm_remove = None;
                actions.push(MenuAction::Select(item.id.clone()));
            }
            if item.removable {
                let label = if confirming { "Remove?" } else { "Remove" };
                let fill = if confirming {
                    Color32::from_rgb(150, 40, 30)
                } else {
                    ui.visuals().widgets.inactive.weak_bg_fill
                };
                let r = ui.add_sized(
                    [remove_w - 8.0, CONTROL_HEIGHT_PT * 1.4],
                    egui::Button::new(label).fill(fill),
                );
                self.widget_rects.remember(format!("remove:{}", item.id), r.rect);
                if r.clicked() {
                    if confirming {
                        self.confirm_remove = None;
                        actions.push(MenuAction::Remove(item.id.clone()));
                    } else {
                        self.confirm_remove = Some(item.id.clone());
                    }
                }
            }
        });
        ui.add_space(4.0);
    }
}

/// A card across the bottom of the screen, over everything (the banner, an annotation, the
/// help): `body` fills it; returns the card's rectangle (points).
fn bottom_card(ctx: &egui::Context, id: &str, body: impl FnOnce(&mut egui::Ui)) -> Rect {
    let width = (ctx.content_rect().width() - 24.0).max(100.0);
    egui::Area::new(egui::Id::unique(id))
        .anchor(Align2::CENTER_BOTTOM, [0.0, -12.0])
        .order(egui::Order::Foreground)
        // Shown at once: a fading card would be unreadable for its first frames.
        .fade_in(false)
        .show(ctx, |ui| {
            egui::Frame::popup(ui.style()).show(ui, |ui| {
                ui.set_width(width - 16.0);
                body(ui);
            });
        })
        .response
        .rect
}

/// Draws an annotation's card (its title and text) at the bottom of the screen; returns `true`
/// when the viewer closed it, and the card's rectangle (points).
pub fn show_annotation(ctx: &egui::Context, title: &str, lead: &str) -> (bool, Rect) {
    let mut closed = false;
    let rect = bottom_card(ctx, "annotation card", |ui| {
        ui.label(RichText::new(title).size(20.0).color(Color32::from_rgb(255, 190, 90)));
        if !lead.is_empty() {
            ui.label(RichText::new(lead).size(16.0));
        }
        let r = ui.add_sized([ui.available_width(), CONTROL_HEIGHT_PT], egui::Button::new("Close"));
        closed = r.clicked();
    });
    (closed, rect)
}

/// What the gestures do, for the help card.
pub const GESTURE_HELP: &str = "Tilt the phone to look around the artifact.\n\
    Tap once: this menu (on an amber dot: what it marks).\n\
    Tap twice: the way you hold the phone now counts as straight on.\n\
    Hold one finger still: the light stays where it is in the room.\n\
    Tap with two fingers: coloured glasses on or off (a flat picture).\n\
    Tap with three fingers: calibration.";

/// What the banner shows.
#[derive(Clone, Debug, PartialEq)]
pub enum Banner {
    Loading { title: String, fraction: f32 },
    Failed { title: String, message: String },
}

/// What the viewer asked of the banner.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BannerAction {
    /// Give up the load under way.
    Cancel,
    /// The failure was read.
    Dismiss,
}

/// Draws the banner at the bottom of the screen, over everything; returns the viewer's action and
/// the banner's rectangle (points: touches inside it belong to the banner, not to gestures) and
/// its button's.
pub fn show_banner(ctx: &egui::Context, banner: &Banner) -> (Option<BannerAction>, Rect, Rect) {
    let mut action = None;
    let mut button = Rect::NOTHING;
    let area = bottom_card(ctx, "status banner", |ui| match banner {
        Banner::Loading { title, fraction } => {
            ui.label(RichText::new(format!("Opening {title}…")).size(17.0));
            ui.add(egui::ProgressBar::new(fraction.clamp(0.0, 1.0)).show_percentage());
            let r = ui.add_sized([ui.available_width(), CONTROL_HEIGHT_PT], egui::Button::new("Cancel"));
            button = r.rect;
            if r.clicked() {
                action = Some(BannerAction::Cancel);
            }
        }
        Banner::Failed { title, message } => {
            ui.label(
                RichText::new(format!("Could not open {title}"))
                    .size(17.0)
                    .color(Color32::from_rgb(255, 140, 120)),
            );
            ui.label(message);
            ui.label("The artifact you were looking at stays on screen.");
            let r = ui.add_sized([ui.available_width(), CONTROL_HEIGHT_PT], egui::Button::new("OK"));
            button = r.rect;
            if r.clicked() {
                action = Some(BannerAction::Dismiss);
            }
        }
    });
    (action, area, button)
}

#[cfg(test)]
mod tests {
    use super::*;
    use egui::{Pos2, Vec2};

    fn items() -> Vec<MenuItem> {
        vec![
            MenuItem {
                id: "builtin:amphora".into(),
                title: "Painted amphora".into(),
                credit: Some("Generated".into()),
                licence: None,
                removable: false,
                thumbnail: None,
            },
            MenuItem {
                id: "imported:jar-1".into(),
                title: "Jar".into(),
                credit: None,
                licence: Some("CC0".into()),
                removable: true,
                thumbnail: None,
            },
        ]
    }

    fn frame(ctx: &egui::Context, menu: &mut MenuUi, events: Vec<egui::Event>) -> Vec<MenuAction> {
        let mut actions = Vec::new();
        crate::test_taps::frame(ctx, events, |ui| {
            actions = menu.show(ui, &items(), Some("builtin:amphora"), "Camera off")
        });
        actions
    }

    fn tap(ctx: &egui::Context, menu: &mut MenuUi, name: &str) -> Vec<MenuAction> {
        let pos = menu.widget_rect(name).unwrap_or_else(|| panic!("no {name}")).center();
        let mut actions = Vec::new();
        crate::test_taps::tap(pos, |events| actions.extend(frame(ctx, menu, events)));
        actions
    }

    #[test]
    fn taps_select_open_calibrate_close_and_remove_after_confirming() {
        let ctx = egui::Context::default();
        let mut menu = MenuUi::new();
        frame(&ctx, &mut menu, vec![]);
        frame(&ctx, &mut menu, vec![]);
        for name in [
            "item:builtin:amphora",
            "item:imported:jar-1",
            "remove:imported:jar-1",
            "open",
            "share",
            "share-pair",
            "close",
        ] {
            let r = menu.widget_rect(name).unwrap_or_else(|| panic!("{name} not drawn"));
            assert!(
                r.height() >= CONTROL_HEIGHT_PT - 0.5,
                "{name}: {r:?} is smaller than a finger"
            );
        }
        assert!(
            menu.widget_rect("remove:builtin:amphora").is_none(),
            "built-in ones stay"
        );
        assert_eq!(
            tap(&ctx, &mut menu, "item:imported:jar-1"),
            vec![MenuAction::Select("imported:jar-1".into())]
        );
        assert_eq!(
            tap(&ctx, &mut menu, "thumb:builtin:amphora"),
            vec![MenuAction::Select("builtin:amphora".into())],
            "the picture chooses too"
        );
        assert_eq!(tap(&ctx, &mut menu, "remove:imported:jar-1"), vec![], "asks first");
        assert_eq!(
            tap(&ctx, &mut menu, "remove:imported:jar-1"),
            vec![MenuAction::Remove("imported:jar-1".into())]
        );
        assert_eq!(tap(&ctx, &mut menu, "open"), vec![MenuAction::OpenFile]);
        assert_eq!(
            tap(&ctx, &mut menu, "share"),
            vec![MenuAction::Share { side_by_side: false }]
        );
        assert_eq!(
            tap(&ctx, &mut menu, "share-pair"),
            vec![MenuAction::Share { side_by_side: true }]
        );
        assert_eq!(tap(&ctx, &mut menu, "calibrate"), vec![MenuAction::Calibrate]);
        assert_eq!(tap(&ctx, &mut menu, "settings"), vec![MenuAction::Settings]);
        assert_eq!(tap(&ctx, &mut menu, "help"), vec![MenuAction::Help]);
        assert_eq!(tap(&ctx, &mut menu, "close"), vec![MenuAction::Close]);
    }

    #[test]
    fn the_banner_offers_cancel_while_loading_and_ok_after_a_failure() {
        let ctx = egui::Context::default();
        let run = |banner: &Banner, events: Vec<egui::Event>| {
            let input = egui::RawInput {
                screen_rect: Some(Rect::from_min_size(Pos2::ZERO, Vec2::new(390.0, 844.0))),
                events,
                ..Default::default()
            };
            let mut result = (None, Rect::NOTHING, Rect::NOTHING);
            let mut out = ctx.run_ui(input, |ui| result = show_banner(ui.ctx(), banner));
            out.textures_delta.clear();
            result
        };
        for (banner, expected) in [
            (
                Banner::Loading {
                    title: "Turtle".into(),
                    fraction: 0.4,
                },
                BannerAction::Cancel,
            ),
            (
                Banner::Failed {
                    title: "x.glb".into(),
                    message: "not a valid glTF file".into(),
                },
                BannerAction::Dismiss,
            ),
        ] {
            run(&banner, vec![]);
            let (_, area, button) = run(&banner, vec![]);
            assert!(
                area.contains(button.center()) && area.max.y <= 844.0 && area.min.y > 422.0,
                "{area:?}"
            );
            let pos = button.center();
            let press = |pressed| egui::Event::PointerButton {
                pos,
                button: egui::PointerButton::Primary,
                pressed,
                modifiers: Default::default(),
            };
            run(&banner, vec![egui::Event::PointerMoved(pos), press(true)]);
            let (action, _, _) = run(&banner, vec![press(false)]);
            assert_eq!(action, Some(expected));
        }
    }
}
