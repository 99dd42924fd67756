//! Touch: gestures turned into the engine's actions, a lamp placed or dragged by a finger, the
//! Diorama's pieces pushed.

use super::Engine;
use crate::{
    anaglyph::Method,
    gesture::{Gesture, TouchPhase},
};
use glam::Vec3;

impl Engine {
    /// One touch event (physical pixels, nanoseconds on a monotonic clock); acts on the gesture
    /// it completes and returns it.
    pub fn touch(&mut self, phase: TouchPhase, pointer_id: i32, x_px: f32, y_px: f32, t_ns: i64) -> Option<Gesture> {
        #[cfg(feature = "ui")]
        {
            let ppp = self.pixels_per_point();
            let gestures_idle = self.gestures.is_idle();
            if let Some(screens) = self.screens.as_mut() {
                let (x_pt, y_pt) = (x_px / ppp, y_px / ppp);
                // A page takes every touch; the banner only those that start on it while no
                // gesture is under way.
                let on_banner = phase == TouchPhase::Down
                    && gestures_idle
                    && screens.pointer.is_none()
                    && screens.banner_pt.is_some_and(|r| r.contains(egui::pos2(x_pt, y_pt)));
                if screens.page.is_some() || screens.pointer == Some(pointer_id) || on_banner {
                    screens.touch(phase, pointer_id, x_pt, y_pt);
                    return None;
                }
            }
        }
        // With a lamp on, a finger's drag moves the lamp (not the view, not the Diorama's
        // bodies); taps and the other gestures still reach the recogniser (a tap opens the menu).
        if !self.touch_lamp(phase, pointer_id, [x_px, y_px]) {
            self.drag_to_turn(phase, pointer_id, [x_px, y_px]);
            self.touch_diorama(phase, pointer_id, [x_px, y_px]);
        }
        let g = self.gestures.touch(phase, pointer_id, x_px, y_px, t_ns)?;
        self.apply_gesture(g);
        Some(g)
    }

    /// A lamp on screen follows the first finger down as it moves (a tap does not move it: taps
    /// stay the menu's). Returns whether a lamp is on (its drags are then the lamp's).
    pub(super) fn touch_lamp(&mut self, phase: TouchPhase, pointer_id: i32, px: [f32; 2]) -> bool {
        if self.lamp.is_none() {
            self.lamp_finger = None;
            return false;
        }
        match (phase, self.lamp_finger) {
            (TouchPhase::Down, None) => self.lamp_finger = Some(pointer_id),
            (TouchPhase::Move, Some(id)) if id == pointer_id => {
                let at = self.glass_point_m(px);
                let orientation = self.last_device_to_world;
                if let Some(lamp) = self.lamp.as_mut() {
                    lamp.move_to(at.x, at.y, orientation);
                }
            }
            (TouchPhase::Up | TouchPhase::Cancel, Some(id)) if id == pointer_id => self.lamp_finger = None,
            _ => {}
        }
        true
    }

    /// The point of the glass (device frame, z = 0) under display pixel `px` of the target.
    pub(super) fn glass_point_m(&self, px: [f32; 2]) -> Vec3 {
        let screen = self.session.config().screen;
        screen.glass_point_of_pixel(glam::Vec2::from(px) / self.target_scale())
    }

    /// Puts a lamp over the diorama in place of the room's light (`None`: back to the room's
    /// light): a raking light ([`crate::lamp::LampSetting::raking`]) starts at the screen's left
    /// edge, a torch above its top edge; a finger then moves it ([`Self::touch`]).
    pub fn set_lamp(&mut self, setting: Option<crate::lamp::LampSetting>) {
        let screen = self.session.config().screen;
        self.lamp_finger = None;
        // The edges as the viewer sees them (the display may be turned).
        let (w, h) = (screen.width_px() as f32, screen.height_px() as f32);
        self.lamp = setting.map(|s| {
            let at = match s.anchor {
                crate::lamp::LampAnchor::Room => screen.glass_point_of_pixel(glam::Vec2::new(0.0, 0.5 * h)),
                crate::lamp::LampAnchor::Torch => screen.glass_point_of_pixel(glam::Vec2::new(0.5 * w, 0.0)),
            };
            crate::lamp::PlacedLamp::new(s, at.x, at.y)
        });
        if self.lamp.is_none() {
            self.renderer.lamp = None;
        }
    }

    /// The lamp placed, if any.
    pub fn lamp(&self) -> Option<&crate::lamp::PlacedLamp> {
        self.lamp.as_ref()
    }

    /// The Diorama's finger: a body under the first finger down (on the line from the eye
    /// through the touched point of the glass) is held and follows the finger at its depth;
    /// lifting the finger lets it go with its speed (a flick).
    pub(super) fn touch_diorama(&mut self, phase: TouchPhase, pointer_id: i32, px: [f32; 2]) {
        if self.diorama.is_none() {
            return;
        }
        let screen = self.session.config().screen;
        let scale = self.target_scale();
        let (Some(mono), Some(scene)) = (self.last_mono, self.diorama.as_deref_mut()) else {
            return;
        };
        let glass = screen.glass_point_of_pixel(glam::Vec2::new(px[0], px[1]) / scale);
        let eye = mono.eye_m;
        let Some(direction) = (glass - eye).try_normalize() else {
            return;
        };
        match (phase, self.diorama_grab) {
            (TouchPhase::Down, None) => {
                let world = scene.world();
                if let Some(i) = world.pick(eye, direction) {
                    let depth = (world.stepped_poses()[i].translation_m - eye).dot(direction);
                    scene.world_mut().grab(i, eye + direction * depth);
                    self.diorama_grab = Some((pointer_id, depth));
                }
            }
            (TouchPhase::Move, Some((id, depth))) if id == pointer_id => {
                scene.world_mut().drag_to(eye + direction * depth);
            }
            (TouchPhase::Up | TouchPhase::Cancel, Some((id, _))) if id == pointer_id => {
                scene.world_mut().release();
                self.diorama_grab = None;
            }
            _ => {}
        }
    }

    /// "Reduce motion": the first finger down drags the artifact around
    /// ([`crate::turn_by_touch`]); a drag across about a phone's width (60 mm) turns it 90°.
    pub(super) fn drag_to_turn(&mut self, phase: TouchPhase, pointer_id: i32, px: [f32; 2]) {
        const RAD_PER_MM: f32 = std::f32::consts::FRAC_PI_2 / 60.0;
        if !self.session.turning_by_touch() {
            self.drag_px = None;
            return;
        }
        match (phase, self.drag_px) {
            (TouchPhase::Down, None) => self.drag_px = Some((pointer_id, px)),
            (TouchPhase::Move, Some((id, last))) if id == pointer_id => {
                // Millimetres on the glass: the displayed image's size over the target's pixels
                // (the panel's on a phone; smaller in a desktop window or an offscreen test).
                let screen = self.session.config().screen;
                let (w_px, h_px) = self
                    .target_size()
                    .filter(|&(w, h)| w > 0 && h > 0)
                    .unwrap_or((screen.width_px(), screen.height_px()));
                let right_rad = (px[0] - last[0]) * screen.width_m() * 1e3 / w_px as f32 * RAD_PER_MM;
                let down_rad = (px[1] - last[1]) * screen.height_m() * 1e3 / h_px as f32 * RAD_PER_MM;
                self.session.turn_by_touch(right_rad, down_rad);
                self.drag_px = Some((id, px));
            }
            (TouchPhase::Up | TouchPhase::Cancel, Some((id, _))) if id == pointer_id => self.drag_px = None,
            _ => {}
        }
    }

    pub(super) fn apply_gesture(&mut self, g: Gesture) {
        self.stats.gestures += 1;
        // Without gravity yet the calibrations cannot be done; the gesture is then a no-op, as a
        // user would expect from tapping a phone that has not measured anything.
        match g {
            // In the Diorama a double tap puts everything back in the tray.
            Gesture::StraightOn => match self.diorama.as_deref_mut() {
                Some(scene) => scene.reset(),
                None => {
                    let _ = self.calibrate_flat_angle();
                }
            },
            Gesture::Calibrate => {
                self.open_calibration();
            }
            Gesture::Menu => {
                // A tap on an annotation's marker reads it; anywhere else opens the menu.
                match self.gestures.last_tap_px().and_then(|px| self.annotation_at(px)) {
                    Some(i) => {
                        self.open_annotation(i);
                    }
                    None => {
                        self.open_menu();
                    }
                }
            }
            Gesture::AnchorLight => {
                let _ = self.session.recalibrate_light();
            }
            Gesture::ToggleStereo => {
                self.method = if self.method == Method::Mono {
                    self.stereo_method
                } else {
                    Method::Mono
                };
            }
        }
    }
}
