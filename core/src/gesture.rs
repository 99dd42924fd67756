//! Touch gestures of the phone app: the few commands a phantogram needs without any on-screen
//! control (the artifact fills the screen, and buttons would sit in the picture).
//!
//! * **single tap** (one finger, no second tap following) → [`Gesture::Menu`]: open the menu
//!   (the artifact gallery, opening a file, calibration); recognised once the double tap's time
//!   has passed, at the next [`Gestures::poll`] or touch;
//! * **double tap** (one finger) → [`Gesture::StraightOn`]: the current holding pose counts as
//!   straight on (the flat-angle calibration);
//! * **long press** (one finger held still) → [`Gesture::AnchorLight`]: tie the light to the room
//!   again at the current pose;
//! * **two-finger tap** → [`Gesture::ToggleStereo`]: anaglyph ↔ mono (for a viewer without
//!   glasses);
//! * **three-finger tap** → [`Gesture::Calibrate`]: open the calibration screens (eye distance,
//!   viewing distance, screen size, flat angle, light), where touches then drive the screens.
//!
//! Touches arrive as the platforms deliver them (Android `MotionEvent`, iOS `UITouch`): one event
//! per pointer and phase, in physical pixels, on a monotonic clock in nanoseconds. Movement beyond
//! the slop (3 mm on the glass, from the display density) turns a touch into a drag, which is no
//! gesture. A long press is recognised while the finger is still down, at the first event or
//! [`Gestures::poll`] after the hold time.
//!
//! Plain data, no threads, no panics: events out of order or with unknown pointers are ignored.

use phantogram_sensing::clock::elapsed_ns;

/// What the shell reports for one pointer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TouchPhase {
    Down,
    Move,
    Up,
    /// The system took the touch (a system gesture, the app losing focus): no gesture.
    Cancel,
}

impl TouchPhase {
    /// From the numbering of the C ABI and the JNI bridge: 0 down, 1 move, 2 up, 3 cancel.
    pub fn from_code(code: i32) -> Option<Self> {
        match code {
            0 => Some(Self::Down),
            1 => Some(Self::Move),
            2 => Some(Self::Up),
            3 => Some(Self::Cancel),
            _ => None,
        }
    }
}

/// A recognised command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Gesture {
    StraightOn,
    AnchorLight,
    ToggleStereo,
    Calibrate,
    Menu,
}

impl Gesture {
    /// The number the C ABI and the JNI bridge report for a touch's outcome: 0 none, 1 straight
    /// on, 2 light re-anchored, 3 stereo toggled, 4 calibration screens opened, 5 menu opened.
    pub fn code(gesture: Option<Gesture>) -> i32 {
        match gesture {
            None => 0,
            Some(Gesture::StraightOn) => 1,
            Some(Gesture::AnchorLight) => 2,
            Some(Gesture::ToggleStereo) => 3,
            Some(Gesture::Calibrate) => 4,
            Some(Gesture::Menu) => 5,
        }
    }
}

/// Longest press that still counts as a tap, ns.
const TAP_MAX_NS: i64 = 300_000_000;
/// Longest gap between the two taps of a double tap, ns.
const DOUBLE_TAP_GAP_NS: i64 = 350_000_000;
/// Hold time of a long press, ns.
const LONG_PRESS_NS: i64 = 600_000_000;
/// Movement that turns a touch into a drag, metres on the glass.
const SLOP_M: f32 = 0.003;

#[derive(Clone, Copy, Debug)]
struct Pointer {
    id: i32,
    down_t_ns: i64,
    down_px: [f32; 2],
    moved: bool,
}

/// The recogniser.
#[derive(Clone, Debug)]
pub struct Gestures {
    slop_px: f32,
    down: Vec<Pointer>,
    /// Most pointers down at once in the current touch sequence, and whether any moved.
    sequence_max: usize,
    sequence_moved: bool,
    sequence_start_ns: i64,
    long_press_fired: bool,
    /// End time of a single tap awaiting its second.
    last_tap_ns: Option<i64>,
    /// Where the last single tap was, physical pixels.
    last_tap_px: Option<[f32; 2]>,
}

impl Gestures {
    /// A recogniser for a display of `pixels_per_inch` (Android `xdpi`, iOS points per inch ×
    /// scale). Nonsense densities fall back to 400 ppi.
    pub fn new(pixels_per_inch: f32) -> Self {
        let ppi = if pixels_per_inch.is_finite() && pixels_per_inch > 50.0 {
            pixels_per_inch
        } else {
            400.0
        };
        Self {
            slop_px: SLOP_M / 0.0254 * ppi,
            down: Vec::new(),
            sequence_max: 0,
            sequence_moved: false,
            sequence_start_ns: 0,
            long_press_fired: false,
            last_tap_ns: None,
            last_tap_px: None,
        }
    }

    /// Where the last single tap ([`Gesture::Menu`]) was, physical pixels: what it was on.
    pub fn last_tap_px(&self) -> Option<[f32; 2]> {
        self.last_tap_px
    }

    /// Whether no finger is down (a touch starting now begins a new sequence).
    pub fn is_idle(&self) -> bool {
        self.down.is_empty()
    }

    /// Feeds one pointer event; returns the gesture it completes, if any.
    pub fn touch(&mut self, phase: TouchPhase, pointer_id: i32, x_px: f32, y_px: f32, t_ns: i64) -> Option<Gesture> {
        if !(x_px.is_finite() && y_px.is_finite()) {
            return None;
        }
        if let Some(g) = self.poll(t_ns) {
            // A long press completed before this event arrived; the event still updates the state.
            self.apply(phase, pointer_id, [x_px, y_px], t_ns);
            return Some(g);
        }
        self.apply(phase, pointer_id, [x_px, y_px], t_ns)
    }

    /// Checks for a long press, or a single tap that no second tap followed, at `t_ns` (call once
    /// a frame).
    pub fn poll(&mut self, t_ns: i64) -> Option<Gesture> {
        if let Some(prev) = self.last_tap_ns
            && self.down.is_empty()
            && elapsed_ns(prev, t_ns) > DOUBLE_TAP_GAP_NS + TAP_MAX_NS
        {
            self.last_tap_ns = None;
            return Some(Gesture::Menu);
        }
        match self.down.as_slice() {
            [p] if self.sequence_max == 1
                && !self.sequence_moved
                && !p.moved
                && !self.long_press_fired
                && elapsed_ns(p.down_t_ns, t_ns) >= LONG_PRESS_NS =>
            {
                self.long_press_fired = true;
                self.last_tap_ns = None;
                Some(Gesture::AnchorLight)
            }
            _ => None,
        }
    }

    fn apply(&mut self, phase: TouchPhase, id: i32, at: [f32; 2], t_ns: i64) -> Option<Gesture> {
        match phase {
            TouchPhase::Down => {
                if self.down.is_empty() {
                    self.sequence_max = 0;
                    self.sequence_moved = false;
                    self.sequence_start_ns = t_ns;
                    self.long_press_fired = false;
                }
                self.down.retain(|p| p.id != id);
                self.down.push(Pointer {
                    id,
                    down_t_ns: t_ns,
                    down_px: at,
                    moved: false,
                });
                self.sequence_max = self.sequence_max.max(self.down.len());
                None
            }
            TouchPhase::Move => {
                let slop = self.slop_px;
                if let Some(p) = self.down.iter_mut().find(|p| p.id == id) {
                    let (dx, dy) = (at[0] - p.down_px[0], at[1] - p.down_px[1]);
                    if dx.hypot(dy) > slop {
                        p.moved = true;
                        self.sequence_moved = true;
                    }
                }
                None
            }
            TouchPhase::Cancel => {
                self.down.clear();
                self.sequence_moved = true;
                self.last_tap_ns = None;
                None
            }
            TouchPhase::Up => {
                let before = self.down.len();
                self.down.retain(|p| p.id != id);
                if self.down.len() == before || !self.down.is_empty() {
                    return None;
                }
                // The whole sequence ended.
                let duration = elapsed_ns(self.sequence_start_ns, t_ns);
                let tap = !self.sequence_moved && !self.long_press_fired && (0..=TAP_MAX_NS).contains(&duration);
                if !tap {
                    self.last_tap_ns = None;
                    return None;
                }
                match self.sequence_max {
                    1 => match self.last_tap_ns.take() {
                        Some(prev) if elapsed_ns(prev, t_ns) <= DOUBLE_TAP_GAP_NS + TAP_MAX_NS => {
                            Some(Gesture::StraightOn)
                        }
                        _ => {
                            self.last_tap_ns = Some(t_ns);
                            self.last_tap_px = Some(at);
                            None
                        }
                    },
                    2 => {
                        self.last_tap_ns = None;
                        Some(Gesture::ToggleStereo)
                    }
                    3 => {
                        self.last_tap_ns = None;
                        Some(Gesture::Calibrate)
                    }
                    _ => {
                        self.last_tap_ns = None;
                        None
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: i64 = 1_000_000;

    fn tap(g: &mut Gestures, t_ms: i64, x: f32) -> Option<Gesture> {
        assert_eq!(g.touch(TouchPhase::Down, 0, x, 100.0, t_ms * MS), None);
        g.touch(TouchPhase::Up, 0, x + 2.0, 100.0, (t_ms + 80) * MS)
    }

    #[test]
    fn double_tap_makes_the_pose_straight_on_and_a_single_tap_opens_the_menu() {
        let mut g = Gestures::new(420.0);
        assert_eq!(tap(&mut g, 0, 500.0), None);
        assert_eq!(g.poll(300 * MS), None, "a second tap may still come");
        assert_eq!(tap(&mut g, 250, 505.0), Some(Gesture::StraightOn));
        assert_eq!(g.poll(5000 * MS), None, "a double tap is no single tap");
        // A third tap starts afresh rather than completing another double tap.
        assert_eq!(tap(&mut g, 6000, 505.0), None);
        assert_eq!(g.poll(6300 * MS), None);
        assert_eq!(g.poll(6800 * MS), Some(Gesture::Menu));
        assert_eq!(g.poll(9000 * MS), None, "once");
        // Taps too far apart in time are two single taps: the next touch reports the first.
        let mut g = Gestures::new(420.0);
        assert_eq!(tap(&mut g, 0, 500.0), None);
        assert_eq!(
            g.touch(TouchPhase::Down, 0, 500.0, 100.0, 2000 * MS),
            Some(Gesture::Menu)
        );
        assert_eq!(g.touch(TouchPhase::Up, 0, 500.0, 100.0, 2080 * MS), None);
        assert_eq!(g.poll(3000 * MS), Some(Gesture::Menu));
        assert_eq!(Gesture::code(Some(Gesture::Menu)), 5);
    }

    #[test]
    fn a_drag_is_no_gesture() {
        let mut g = Gestures::new(420.0);
        // 3 mm at 420 ppi is about 50 px.
        g.touch(TouchPhase::Down, 0, 100.0, 100.0, 0);
        g.touch(TouchPhase::Move, 0, 200.0, 100.0, 40 * MS);
        assert_eq!(g.touch(TouchPhase::Up, 0, 200.0, 100.0, 80 * MS), None);
        assert_eq!(tap(&mut g, 200, 100.0), None, "the drag does not count as a first tap");
        assert_eq!(
            g.poll(10_000 * MS),
            Some(Gesture::Menu),
            "the tap after the drag is a single tap"
        );
        g.touch(TouchPhase::Down, 0, 100.0, 100.0, 11_000 * MS);
        g.touch(TouchPhase::Move, 0, 200.0, 100.0, 11_040 * MS);
        g.touch(TouchPhase::Up, 0, 200.0, 100.0, 11_080 * MS);
        assert_eq!(g.poll(20_000 * MS), None, "a drag alone opens nothing");
    }

    #[test]
    fn long_press_anchors_the_light_once() {
        let mut g = Gestures::new(420.0);
        g.touch(TouchPhase::Down, 7, 300.0, 300.0, 0);
        assert_eq!(g.poll(500 * MS), None);
        g.touch(TouchPhase::Move, 7, 310.0, 300.0, 550 * MS); // within the slop
        assert_eq!(g.poll(650 * MS), Some(Gesture::AnchorLight));
        assert_eq!(g.poll(900 * MS), None);
        assert_eq!(g.touch(TouchPhase::Up, 7, 310.0, 300.0, 1000 * MS), None);
        // A long press that moved first is a drag.
        g.touch(TouchPhase::Down, 7, 300.0, 300.0, 2000 * MS);
        g.touch(TouchPhase::Move, 7, 400.0, 300.0, 2100 * MS);
        assert_eq!(g.poll(3000 * MS), None);
    }

    #[test]
    fn two_finger_tap_toggles_stereo_and_cancel_forgets_everything() {
        let mut g = Gestures::new(420.0);
        g.touch(TouchPhase::Down, 0, 300.0, 300.0, 0);
        g.touch(TouchPhase::Down, 1, 500.0, 300.0, 20 * MS);
        assert_eq!(g.touch(TouchPhase::Up, 0, 300.0, 300.0, 100 * MS), None);
        assert_eq!(
            g.touch(TouchPhase::Up, 1, 500.0, 300.0, 120 * MS),
            Some(Gesture::ToggleStereo)
        );
        g.touch(TouchPhase::Down, 0, 300.0, 300.0, 1000 * MS);
        g.touch(TouchPhase::Cancel, 0, 300.0, 300.0, 1050 * MS);
        assert_eq!(g.touch(TouchPhase::Up, 0, 300.0, 300.0, 1060 * MS), None);
        assert_eq!(tap(&mut g, 1100, 300.0), None);
        assert_eq!(TouchPhase::from_code(4), None);
        assert_eq!(Gesture::code(None), 0);
        assert_eq!(Gesture::code(Some(Gesture::ToggleStereo)), 3);
        assert_eq!(TouchPhase::from_code(2), Some(TouchPhase::Up));
        // NaN positions are ignored.
        assert_eq!(g.touch(TouchPhase::Down, 0, f32::NAN, 0.0, 0), None);
    }

    #[test]
    fn three_finger_tap_opens_the_calibration_and_four_do_nothing() {
        let mut g = Gestures::new(420.0);
        for (i, x) in [200.0, 400.0, 600.0].into_iter().enumerate() {
            g.touch(TouchPhase::Down, i as i32, x, 300.0, i as i64 * 10 * MS);
        }
        assert_eq!(g.touch(TouchPhase::Up, 0, 200.0, 300.0, 100 * MS), None);
        assert_eq!(g.touch(TouchPhase::Up, 2, 600.0, 300.0, 110 * MS), None);
        assert_eq!(
            g.touch(TouchPhase::Up, 1, 400.0, 300.0, 120 * MS),
            Some(Gesture::Calibrate)
        );
        assert_eq!(Gesture::code(Some(Gesture::Calibrate)), 4);
        for i in 0..4 {
            g.touch(TouchPhase::Down, i, 100.0 * i as f32, 300.0, 1000 * MS);
        }
        let ends: Vec<_> = (0..4)
            .map(|i| g.touch(TouchPhase::Up, i, 100.0 * i as f32, 300.0, 1100 * MS))
            .collect();
        assert!(ends.iter().all(Option::is_none), "{ends:?}");
    }
}
