//! What the core's screens say to a screen reader (Android's TalkBack, iOS's VoiceOver).
//!
//! egui describes every frame as an AccessKit tree (buttons, switches, sliders and text with
//! their labels, values and rectangles). AccessKit's own platform adapters do not fit here: it
//! has none for UIKit, and its Android adapter wants to own the view's accessibility delegate,
//! while both shells draw the core's screens into a surface they own. So [`AccessTree`]
//! flattens each frame's tree, in reading order, into plain [`AccessNode`]s that the bridges
//! hand over as data: Android's shell serves them as virtual views (`ExploreByTouchHelper`),
//! iOS's as `UIAccessibilityElement`s. A screen reader's "activate" comes back as
//! [`AccessTree::click_event`], an AccessKit action request that egui answers as a click on that
//! widget — the same path as a tap, so what a tap does an activation does.
//!
//! Ids are small integers, stable for a widget for as long as the tree lives (a widget that
//! goes and comes back keeps its id), as the platforms' virtual-view ids must be.
//!
//! **Threading**: plain data, owned by the render thread with the screens. **Panics**: none.

use std::collections::HashMap;

use egui::accesskit::{self, Action, NodeId, Role, Toggled};

/// What kind of control a node is, as the platforms' accessibility APIs name them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(i32)]
pub enum AccessRole {
    /// Text to read; not a control.
    Text = 0,
    Button = 1,
    /// A switch or check box: [`AccessNode::checked`] says which way.
    CheckBox = 2,
    /// One choice of several: [`AccessNode::checked`] says whether it is the chosen one.
    RadioButton = 3,
    /// A value on a scale: [`AccessNode::value`] reads it.
    Slider = 4,
    /// The picture itself, the artifact in 3-D.
    Image = 5,
}

impl AccessRole {
    fn of(role: Role) -> Option<Self> {
        Some(match role {
            Role::Button | Role::Link | Role::MenuItem | Role::Tab => Self::Button,
            Role::CheckBox | Role::Switch => Self::CheckBox,
            Role::RadioButton => Self::RadioButton,
            Role::Slider | Role::SpinButton => Self::Slider,
            // A label's text runs repeat it: the label is read, not its runs.
            Role::Label | Role::Paragraph | Role::Heading => Self::Text,
            Role::Image => Self::Image,
            _ => return None,
        })
    }
}

/// One thing a screen reader can land on.
#[derive(Clone, Debug, PartialEq)]
pub struct AccessNode {
    /// Stable while the tree lives; ≥ 1 (0 is never used: platforms reserve it or −1 for the
    /// host view).
    pub id: i32,
    pub role: AccessRole,
    pub label: String,
    /// A slider's or a field's current value, as text.
    pub value: Option<String>,
    /// A switch's or a choice's state.
    pub checked: Option<bool>,
    pub disabled: bool,
    /// Whether activating it does something ([`AccessTree::click_event`]).
    pub clickable: bool,
    /// Whether it can be stepped up and down ([`AccessTree::adjust_event`]): a slider.
    pub adjustable: bool,
    /// Left, top, right, bottom in the drawing surface's pixels (y down).
    pub bounds_px: [f32; 4],
}

/// Where a slider stands: its value, range and step.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Scale {
    value: f64,
    min: f64,
    max: f64,
    step: Option<f64>,
}

/// [`AccessNode::flags`]' bits, as both bridges hand them to the shells.
pub const FLAG_CLICKABLE: u32 = 1;
pub const FLAG_ADJUSTABLE: u32 = 2;
/// It has an on/off state, given by [`FLAG_CHECKED`].
pub const FLAG_CHECKABLE: u32 = 4;
pub const FLAG_CHECKED: u32 = 8;
pub const FLAG_DISABLED: u32 = 16;

impl AccessNode {
    /// The node's states as [`FLAG_CLICKABLE`] … bits.
    pub fn flags(&self) -> u32 {
        [
            (self.clickable, FLAG_CLICKABLE),
            (self.adjustable, FLAG_ADJUSTABLE),
            (self.checked.is_some(), FLAG_CHECKABLE),
            (self.checked == Some(true), FLAG_CHECKED),
            (self.disabled, FLAG_DISABLED),
        ]
        .into_iter()
        .filter(|(on, _)| *on)
        .fold(0, |bits, (_, flag)| bits | flag)
    }
}

/// The nodes of the last frame (see the module docs).
#[derive(Debug, Default)]
pub struct AccessTree {
    nodes: Vec<AccessNode>,
    /// Our ids by AccessKit's, and back.
    ids: HashMap<NodeId, i32>,
    kit_ids: HashMap<i32, NodeId>,
    /// An adjustable node's value, range and step, by our id.
    scales: HashMap<i32, Scale>,
    generation: u64,
}

impl AccessTree {
    /// Takes a frame's AccessKit tree as the nodes ([`Self::flatten`]).
    pub fn update(&mut self, update: &accesskit::TreeUpdate, pixels_per_point: f32) {
        let nodes = self.flatten(update, pixels_per_point);
        self.replace(nodes);
    }

    /// A frame's AccessKit tree as nodes, not yet the tree's (egui's bounds are in points:
    /// `pixels_per_point` turns them into the surface's pixels): for a caller that adds its own
    /// before [`Self::replace`], so that the generation moves once per real change. Nodes
    /// without a label or value, or off the tree, are left out; the rest in reading order
    /// (depth first from the root). Ids are given here, and the sliders' scales kept.
    pub fn flatten(&mut self, update: &accesskit::TreeUpdate, pixels_per_point: f32) -> Vec<AccessNode> {
        let by_id: HashMap<NodeId, &accesskit::Node> = update.nodes.iter().map(|(id, n)| (*id, n)).collect();
        let root = update.tree.as_ref().map(|t| t.root);
        // Each node's parent, for the controls that egui names by a label beside them.
        let parent_of: HashMap<NodeId, NodeId> = update
            .nodes
            .iter()
            .flat_map(|(id, n)| n.children().iter().map(move |c| (*c, *id)))
            .collect();
        let siblings = |id: NodeId| -> Vec<&accesskit::Node> {
            parent_of
                .get(&id)
                .and_then(|p| by_id.get(p))
                .map(|p| {
                    p.children()
                        .iter()
                        .filter(|c| **c != id)
                        .filter_map(|c| by_id.get(c).copied())
                        .collect()
                })
                .unwrap_or_default()
        };
        // Texts that name a control (`labelled_by`): read with the control, not again alone.
        let naming: std::collections::HashSet<NodeId> = update
            .nodes
            .iter()
            .flat_map(|(_, n)| n.labelled_by().iter().copied())
            .collect();
        let mut scales = HashMap::new();
        let mut nodes = Vec::new();
        let mut stack: Vec<NodeId> = root.into_iter().collect();
        let mut visited = std::collections::HashSet::new();
        while let Some(id) = stack.pop() {
            if !visited.insert(id) {
                continue; // a malformed tree with a cycle: each node once
            }
            let Some(node) = by_id.get(&id) else { continue };
            // Children in order: pushed reversed so that the first is read first.
            stack.extend(node.children().iter().rev().copied());
            if node.is_hidden() {
                continue;
            }
            let Some(role) = AccessRole::of(node.role()) else {
                continue;
            };
            if role == AccessRole::Text && naming.contains(&id) {
                continue;
            }
            // A slider's number box (egui draws one beside it) repeats the slider.
            if node.role() == Role::SpinButton && siblings(id).iter().any(|s| s.role() == Role::Slider) {
                continue;
            }
            let mut label = node.label().unwrap_or_default().trim().to_owned();
            let mut value = node
                .value()
                .map(|v| v.to_owned())
                .or_else(|| node.numeric_value().map(format_number));
            if role == AccessRole::Text {
                // Text is its value in AccessKit; to a reader it is the thing to say.
                if label.is_empty() {
                    label = value.take().unwrap_or_default();
                }
            } else if label.is_empty() && !node.labelled_by().is_empty() {
                // Named by a text elsewhere on the screen (`Response::labelled_by`).
                let names: Vec<&str> = node
                    .labelled_by()
                    .iter()
                    .filter_map(|l| by_id.get(l))
                    .filter_map(|l| l.label().or(l.value()))
                    .collect();
                label = names.join(" ").trim().to_owned();
            }
            if role != AccessRole::Text && label.is_empty() {
                // A control without a name of its own (egui's slider): the label beside it.
                let beside = siblings(id)
                    .into_iter()
                    .find(|s| s.role() == Role::Label)
                    .and_then(|s| s.value().or(s.label()).map(str::to_owned));
                label = beside.unwrap_or_default();
            }
            if label.is_empty() && value.is_none() {
                continue;
            }
            let Some(bounds) = node.bounds() else { continue };
            let ppp = f64::from(pixels_per_point);
            let bounds_px = [bounds.x0, bounds.y0, bounds.x1, bounds.y1].map(|v| (v * ppp) as f32);
            if !bounds_px.iter().all(|v| v.is_finite()) {
                continue;
            }
            let next = self.ids.len() as i32 + 1;
            let our = *self.ids.entry(id).or_insert(next);
            self.kit_ids.insert(our, id);
            let scale = match (node.numeric_value(), node.min_numeric_value(), node.max_numeric_value()) {
                (Some(value), Some(min), Some(max)) if node.supports_action(Action::SetValue) && min < max => {
                    Some(Scale {
                        value,
                        min,
                        max,
                        step: node.numeric_value_step().filter(|s| *s > 0.0),
                    })
                }
                _ => None,
            };
            if let Some(scale) = scale {
                scales.insert(our, scale);
            }
            nodes.push(AccessNode {
                id: our,
                role,
                label,
                value,
                checked: node.toggled().map(|t| t == Toggled::True),
                disabled: node.is_disabled(),
                // egui lets labels be clicked (to select their text): not an action to offer.
                clickable: role != AccessRole::Text && node.supports_action(Action::Click),
                adjustable: scale.is_some(),
                bounds_px,
            });
        }
        self.scales = scales;
        nodes
    }

    /// Sets the nodes outright (the engine's picture node when no screen shows).
    pub fn replace(&mut self, nodes: Vec<AccessNode>) {
        if nodes != self.nodes {
            self.nodes = nodes;
            self.generation += 1;
        }
    }

    pub fn nodes(&self) -> &[AccessNode] {
        &self.nodes
    }

    /// Changes each time the nodes do: a shell re-reads them (Android's `invalidateRoot`, iOS's
    /// layout-changed notification) when it moves.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// The egui event that activates node `id` (a click on its widget in the next frame), if
    /// it is one of the current nodes and can be activated.
    pub fn click_event(&self, id: i32) -> Option<egui::Event> {
        let node = self.nodes.iter().find(|n| n.id == id && n.clickable && !n.disabled)?;
        let target = *self.kit_ids.get(&node.id)?;
        Some(egui::Event::AccessKitActionRequest(accesskit::ActionRequest {
            action: Action::Click,
            target_tree: accesskit::TreeId::ROOT,
            target_node: target,
            data: None,
        }))
    }

    /// The egui event that moves slider `id` by `steps` (its own step, or a twentieth of its
    /// range where it has none; clamped to its range), as a screen reader's swipe up or down
    /// does. `None` for a node that is not adjustable.
    pub fn adjust_event(&self, id: i32, steps: i32) -> Option<egui::Event> {
        let node = self.nodes.iter().find(|n| n.id == id && n.adjustable && !n.disabled)?;
        let scale = self.scales.get(&node.id)?;
        let step = scale.step.unwrap_or((scale.max - scale.min) / 20.0);
        let value = (scale.value + f64::from(steps) * step).clamp(scale.min, scale.max);
        Some(egui::Event::AccessKitActionRequest(accesskit::ActionRequest {
            action: Action::SetValue,
            target_tree: accesskit::TreeId::ROOT,
            target_node: *self.kit_ids.get(&node.id)?,
            data: Some(accesskit::ActionData::NumericValue(value)),
        }))
    }

    /// The id the next new node gets (for nodes the engine adds itself, outside egui's tree).
    pub fn id_for(&mut self, key: &str) -> i32 {
        // A key hashed into AccessKit's id space, far from egui's hashes in practice.
        let kit = NodeId(key.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3)
        }));
        let next = self.ids.len() as i32 + 1;
        *self.ids.entry(kit).or_insert(next)
    }
}

fn format_number(v: f64) -> String {
    if (v - v.round()).abs() < 1e-9 {
        format!("{v:.0}")
    } else {
        format!("{v:.2}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs one egui frame of `show` at `ppp` with accessibility on and returns its tree.
    fn frame(ctx: &egui::Context, ppp: f32, events: Vec<egui::Event>, show: impl FnMut(&mut egui::Ui)) -> AccessTree {
        ctx.enable_accesskit();
        ctx.set_pixels_per_point(ppp);
        let input = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(400.0, 800.0))),
            events,
            ..Default::default()
        };
        let mut out = ctx.run_ui(input, show);
        out.textures_delta.clear(); // no GPU in unit tests
        let mut tree = AccessTree::default();
        tree.update(out.platform_output.accesskit_update.as_ref().expect("a tree"), ppp);
        tree
    }

    #[test]
    fn buttons_switches_and_sliders_are_read_with_their_state_and_place() {
        let ctx = egui::Context::default();
        let (mut on, mut level) = (true, 0.25f32);
        let tree = frame(&ctx, 2.0, Vec::new(), |ui| {
            ui.label("Settings");
            let _ = ui.button("Done");
            ui.checkbox(&mut on, "Floor");
            ui.add(egui::Slider::new(&mut level, 0.0..=1.0).text("In front of the glass"));
            let name = ui.label("Roughness");
            ui.add(egui::Slider::new(&mut level, 0.0..=1.0)).labelled_by(name.id);
        });
        let find = |label: &str| tree.nodes().iter().find(|n| n.label.contains(label)).cloned();
        let text = find("Settings").expect("the heading text");
        let done = find("Done").expect("the button");
        let floor = find("Floor").expect("the switch");
        assert_eq!((text.role, text.clickable), (AccessRole::Text, false));
        assert_eq!((done.role, done.clickable), (AccessRole::Button, true));
        assert_eq!((floor.role, floor.checked), (AccessRole::CheckBox, Some(true)));
        let named = tree
            .nodes()
            .iter()
            .filter(|n| n.role == AccessRole::Slider)
            .nth(1)
            .expect("a second slider");
        assert_eq!(named.label, "Roughness", "named by the text it is labelled by");
        assert!(
            !tree
                .nodes()
                .iter()
                .any(|n| n.role == AccessRole::Text && n.label == "Roughness"),
            "the naming text is read with its slider, not twice"
        );
        let slider = tree
            .nodes()
            .iter()
            .find(|n| n.role == AccessRole::Slider)
            .expect("the slider");
        assert!(
            slider.value.as_deref().is_some_and(|v| v.contains("0.25")),
            "{slider:?}"
        );
        assert_eq!(slider.label, "In front of the glass", "named by its text");
        // Its number box is not read twice; its text is read once, as the slider's name and as
        // text.
        assert_eq!(
            tree.nodes()
                .iter()
                .filter(|n| n.value.as_deref() == Some("0.25"))
                .count(),
            2
        );
        // Reading order is the screen's: the text above the button above the switch.
        let pos = |id: i32| tree.nodes().iter().position(|n| n.id == id).unwrap();
        assert!(pos(text.id) < pos(done.id) && pos(done.id) < pos(floor.id));
        // Bounds in pixels (two per point), on screen, the button below the text.
        assert!(done.bounds_px[1] >= text.bounds_px[3] - 1.0, "{done:?} {text:?}");
        assert!(done.bounds_px[2] <= 800.0 && done.bounds_px[3] <= 1600.0 && done.bounds_px[0] >= 0.0);
        assert!(
            done.bounds_px[2] - done.bounds_px[0] > 2.0 * 20.0,
            "points scaled to pixels: {done:?}"
        );
        // Ids are distinct and positive.
        let mut ids: Vec<i32> = tree.nodes().iter().map(|n| n.id).collect();
        ids.sort();
        ids.dedup();
        assert_eq!(ids.len(), tree.nodes().len());
        assert!(ids[0] >= 1);
        // Text cannot be activated; unknown ids neither.
        assert!(tree.click_event(text.id).is_none() && tree.click_event(999).is_none());
        assert_eq!(floor.flags(), FLAG_CLICKABLE | FLAG_CHECKABLE | FLAG_CHECKED);
        assert_eq!(done.flags(), FLAG_CLICKABLE);
        assert_eq!(slider.flags(), FLAG_ADJUSTABLE);
    }

    #[test]
    fn activating_a_node_clicks_its_widget_in_the_next_frame() {
        let ctx = egui::Context::default();
        let mut clicked = 0;
        let tree = frame(&ctx, 1.0, Vec::new(), |ui| {
            if ui.button("Reset").clicked() {
                clicked += 1;
            }
        });
        assert_eq!(clicked, 0);
        let reset = tree.nodes().iter().find(|n| n.label == "Reset").expect("the button");
        let event = tree.click_event(reset.id).expect("a click");
        frame(&ctx, 1.0, vec![event], |ui| {
            if ui.button("Reset").clicked() {
                clicked += 1;
            }
        });
        assert_eq!(clicked, 1, "the screen reader's activation is the button's click");
    }

    #[test]
    fn a_slider_steps_by_its_step_within_its_range() {
        let ctx = egui::Context::default();
        let mut level = 40.0f32;
        fn show(level: &mut f32) -> impl FnMut(&mut egui::Ui) + '_ {
            move |ui: &mut egui::Ui| {
                let name = ui.label("Level");
                ui.add(egui::Slider::new(level, 0.0..=100.0).step_by(5.0))
                    .labelled_by(name.id);
            }
        }
        let tree = frame(&ctx, 1.0, Vec::new(), show(&mut level));
        let slider = tree
            .nodes()
            .iter()
            .find(|n| n.label == "Level")
            .expect("the slider")
            .clone();
        assert!(slider.adjustable && !slider.clickable, "{slider:?}");
        let up = tree.adjust_event(slider.id, 2).expect("adjustable");
        frame(&ctx, 1.0, vec![up], show(&mut level));
        assert_eq!(level, 50.0, "two steps of 5");
        let tree = frame(&ctx, 1.0, Vec::new(), show(&mut level));
        let down = tree.adjust_event(slider.id, -100).unwrap();
        frame(&ctx, 1.0, vec![down], show(&mut level));
        assert_eq!(level, 0.0, "clamped to the range");
        // A button does not adjust.
        let tree = frame(&ctx, 1.0, Vec::new(), |ui| {
            let _ = ui.button("Go");
        });
        assert!(tree.adjust_event(tree.nodes()[0].id, 1).is_none());
    }

    #[test]
    fn ids_stay_with_their_widget_and_the_generation_moves_only_on_change() {
        let ctx = egui::Context::default();
        ctx.enable_accesskit();
        let mut tree = AccessTree::default();
        let run = |tree: &mut AccessTree, with_extra: bool| {
            let input = egui::RawInput {
                screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(400.0, 800.0))),
                ..Default::default()
            };
            let mut out = ctx.run_ui(input, |ui| {
                let _ = ui.button("Keep");
                if with_extra {
                    let _ = ui.button("Extra");
                }
            });
            out.textures_delta.clear();
            tree.update(out.platform_output.accesskit_update.as_ref().unwrap(), 1.0);
        };
        run(&mut tree, false);
        let keep = tree.nodes().iter().find(|n| n.label == "Keep").unwrap().id;
        let g = tree.generation();
        run(&mut tree, false);
        assert_eq!(tree.generation(), g, "nothing changed");
        // A node of the caller's own put first each frame (the engine's picture): still no
        // change from frame to frame once it is there.
        let lead = |tree: &mut AccessTree| AccessNode {
            id: tree.id_for("lead"),
            role: AccessRole::Image,
            label: "Lead".into(),
            value: None,
            checked: None,
            disabled: false,
            clickable: true,
            adjustable: false,
            bounds_px: [0.0, 0.0, 1.0, 1.0],
        };
        for _ in 0..3 {
            let input = egui::RawInput {
                screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(400.0, 800.0))),
                ..Default::default()
            };
            let mut out = ctx.run_ui(input, |ui| {
                let _ = ui.button("Keep");
            });
            out.textures_delta.clear();
            let mut nodes = tree.flatten(out.platform_output.accesskit_update.as_ref().unwrap(), 1.0);
            nodes.insert(0, lead(&mut tree));
            tree.replace(nodes);
        }
        assert_eq!(
            tree.generation(),
            g + 1,
            "the lead node added once, then nothing changed"
        );
        run(&mut tree, false);
        let g = tree.generation();
        run(&mut tree, true);
        assert!(tree.generation() > g);
        assert_eq!(tree.nodes().iter().find(|n| n.label == "Keep").unwrap().id, keep);
        let extra = tree.nodes().iter().find(|n| n.label == "Extra").unwrap().id;
        assert_ne!(extra, keep);
        assert_eq!(
            tree.nodes().last().map(|n| n.label.as_str()),
            Some("Extra"),
            "reading order"
        );
        // Gone and back: the same id.
        run(&mut tree, false);
        run(&mut tree, true);
        assert_eq!(tree.nodes().iter().find(|n| n.label == "Extra").unwrap().id, extra);
    }
}
