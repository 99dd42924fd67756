//! Cross-fades between a part's levels, so that a switch does not pop.
//!
//! When the chooser moves a part to another level (or to or from its impostor), both are drawn
//! for [`FADE_S`]: the new one on a growing fraction of the pixels, the old one on the rest — a
//! screen-door cross-fade (the renderer picks the pixels by a fixed per-pixel threshold, so each
//! pixel changes once, from old to new, during the fade). A part switched again while fading
//! fades from whichever of its two levels showed more. Fades follow display time: frames drawn
//! without one (on request) switch at once.
//!
//! Threading: the render thread's, with [`crate::Detail`]. Panics: none.

use phantogram_assets::model::LevelFade;

/// How long a cross-fade lasts, seconds: a quarter second, about the eye's temporal
/// integration of a gradual change (a change spread over it reads as a transition, not a pop).
pub const FADE_S: f64 = 0.25;

/// The fades under way, one slot per part.
#[derive(Clone, Debug, Default)]
pub struct Fades {
    /// Per part: the level fading out and when the fade began, seconds.
    active: Vec<Option<(u8, f64)>>,
    /// The levels of the last frame.
    previous: Vec<u8>,
}

impl Fades {
    /// This frame's fades for parts at `levels` at display time `now_s` (`None`: no clock, no
    /// fades).
    pub fn update(&mut self, levels: &[u8], now_s: Option<f64>) -> Vec<LevelFade> {
        let Some(now_s) = now_s.filter(|t| t.is_finite()) else {
            self.active = vec![None; levels.len()];
            self.previous = levels.to_vec();
            return Vec::new();
        };
        if self.previous.len() != levels.len() || self.active.len() != levels.len() {
            // Another model, or the first frame: nothing to fade from.
            self.active = vec![None; levels.len()];
            self.previous = levels.to_vec();
            return Vec::new();
        }
        let mut fades = Vec::new();
        for (i, &level) in levels.iter().enumerate() {
            let before = self.previous[i];
            if level != before {
                let from = match self.active[i] {
                    // Mid-fade: out goes whichever of the two showed more.
                    Some((old, start)) if progress(now_s, start) < 0.5 => old,
                    _ => before,
                };
                self.active[i] = (from != level).then_some((from, now_s));
            }
            if let Some((from, start)) = self.active[i] {
                let shown = progress(now_s, start);
                if shown >= 1.0 {
                    self.active[i] = None;
                } else {
                    fades.push(LevelFade {
                        primitive: i as u32,
                        from,
                        shown: shown as f32,
                    });
                }
            }
        }
        self.previous.clear();
        self.previous.extend_from_slice(levels);
        fades
    }
}

/// How far a fade begun at `start_s` is at `now_s`, 0 to 1. A fade's first frame already shows
/// a little of the new level (a frame's worth at 60 Hz), so that no frame draws both for
/// nothing.
fn progress(now_s: f64, start_s: f64) -> f64 {
    ((now_s - start_s) / FADE_S + 1.0 / (60.0 * FADE_S)).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_switch_fades_in_over_a_quarter_second_and_then_stops() {
        let mut fades = Fades::default();
        assert!(fades.update(&[2, 2], Some(0.0)).is_empty());
        let f = fades.update(&[1, 2], Some(0.1));
        assert_eq!(f.len(), 1);
        assert_eq!((f[0].primitive, f[0].from), (0, 2));
        assert!(f[0].shown > 0.0 && f[0].shown < 0.1, "{f:?}");
        let mut shown = f[0].shown;
        let mut t = 0.1;
        loop {
            t += 1.0 / 60.0;
            let f = fades.update(&[1, 2], Some(t));
            if f.is_empty() {
                break;
            }
            assert!(f[0].shown > shown, "grows: {f:?}");
            shown = f[0].shown;
        }
        assert!((t - 0.1 - FADE_S).abs() < 2.0 / 60.0, "ended after {:.3} s", t - 0.1);
        assert!(fades.update(&[1, 2], Some(t + 1.0)).is_empty());
    }

    #[test]
    fn a_part_switched_back_mid_fade_fades_from_what_showed_more() {
        let mut fades = Fades::default();
        fades.update(&[3], Some(0.0));
        fades.update(&[2], Some(1.0));
        // Early in the fade the old level (3) still showed more: back to 3 is no change at all.
        assert!(fades.update(&[3], Some(1.02)).is_empty());
        // Late in a fade the new one showed more: switching on fades from it.
        fades.update(&[1], Some(2.0));
        let f = fades.update(&[0], Some(2.2));
        assert_eq!(f.len(), 1);
        assert_eq!(f[0].from, 1);
        assert!(f[0].shown < 0.1);
    }

    #[test]
    fn without_a_clock_switches_are_immediate() {
        let mut fades = Fades::default();
        fades.update(&[2], None);
        assert!(fades.update(&[1], None).is_empty());
        fades.update(&[1], Some(0.0));
        assert!(fades.update(&[0], None).is_empty());
        // A model with other parts: nothing to fade from.
        assert!(fades.update(&[0, 1], Some(0.1)).is_empty());
    }
}
