//! Choosing each part's level for a frame, by importance, within a triangle budget.
//!
//! The relief-texture paper ranks parts by I(A,O) = u·P(O) + v/‖P_A − P_O‖ + w·cos θ_AO + x·S(O)
//! (attention, distance, facing, size). Here its distance and size terms are measured together,
//! and in the unit that decides whether a change can be seen: the level's geometric error
//! projected into each eye in pixels of the glass (nearer or larger parts project it larger).
//! Attention and facing weigh that error:
//!
//! * attention: 1 at the attention point (the glass's centre, or where the viewer looks), falling
//!   to ½ at the far corner of the glass;
//! * facing: 1 for a part whose surface faces the eyes, falling to ½ for one facing away (its
//!   silhouette still shows, so it is never worth nothing).
//!
//! Every part starts at its coarsest level, then the part whose weighted error is largest is
//! refined one level at a time while the budget allows, until every part's weighted error is
//! below the visible threshold ([`ChooseParams::visible_px`]): the greedy order of Funkhouser and
//! Séquin's budgeted selection. Both eyes see the same level of a part (the larger of the two
//! projected errors counts): different levels in the two eyes would show as shimmer in stereo.
//!
//! Hysteresis against flicker: a part keeps its current level unless another part needs the
//! triangles more by a margin ([`ChooseParams::stickiness`]), so that a budget hovering at a
//! boundary does not toggle parts every frame. Frames: everything in the device frame (metres),
//! as the projections are.

use glam::{Vec2, Vec3};
use phantogram_geometry::projection::OffAxisProjection;

/// What the chooser knows of one part. See [`crate::PartSummary::of`].
#[derive(Clone, Debug, PartialEq)]
pub struct PartSummary {
    /// Centre of the part's bounding sphere, device frame, metres (before the frame's offset).
    pub centre_m: Vec3,
    pub radius_m: f32,
    /// Area-weighted mean normal (unit length for a flat part, shorter the more it curves).
    pub facing: Vec3,
    /// Per level, finest (the full mesh, error 0) first: triangles and geometric error, metres.
    pub levels: Vec<(u32, f32)>,
}

/// Tuning of [`Chooser`]. The defaults are chosen from first principles, not from the data:
/// see each field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChooseParams {
    /// A weighted error below this many pixels is not refined further: half a pixel is below
    /// what a rasteriser can show (an edge moves by less than one sample).
    pub visible_px: f32,
    /// How much more a part must need triangles than the current holder before the holder is
    /// coarsened for it (and below how much of `visible_px` a part may stay refined).
    pub stickiness: f32,
}

impl Default for ChooseParams {
    fn default() -> Self {
        Self {
            visible_px: 0.5,
            stickiness: 1.5,
        }
    }
}

/// The view a frame is chosen for.
#[derive(Clone, Copy, Debug)]
pub struct ChoiceView<'a> {
    /// The projections drawn (both eyes in stereo, one in mono).
    pub eyes: &'a [&'a OffAxisProjection],
    /// The frame's translation of the mesh (containment's push-back), metres.
    pub offset_m: Vec3,
    /// Where the viewer's attention is, in the first eye's projected pixels (the glass's,
    /// [`OffAxisProjection::image_px`]; its centre without a gaze), and the distance at which
    /// attention has fallen to ½ (the half-diagonal).
    pub attention_px: Vec2,
    pub attention_reach_px: f32,
}

/// Per-part levels kept from frame to frame (for the hysteresis). Not thread-safe by design: the
/// render thread owns it.
#[derive(Clone, Debug, Default)]
pub struct Chooser {
    pub params: ChooseParams,
    levels: Vec<u8>,
}

/// The outcome of one [`Chooser::choose`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ChoiceStats {
    /// Triangles drawn per eye.
    pub triangles: u64,
    /// The largest weighted error left on screen, pixels.
    pub worst_px: f32,
    /// Parts whose level changed since the last frame, and the largest error (pixels, not
    /// weighted) of a level switched to or from: the size of the visible change switching made.
    pub switched: u32,
    pub switched_px: f32,
}

impl Chooser {
    /// The levels of the last choice, one per part (0 the finest).
    pub fn levels(&self) -> &[u8] {
        &self.levels
    }

    /// Chooses each part's level for `view` within `budget_triangles` per eye (never fewer than
    /// every part's coarsest level).
    pub fn choose(&mut self, parts: &[PartSummary], view: &ChoiceView, budget_triangles: u64) -> ChoiceStats {
        let n = parts.len();
        let previous = std::mem::take(&mut self.levels);
        let had_previous = previous.len() == n;
        let weight: Vec<f32> = parts.iter().map(|p| importance(p, view)).collect();
        let coarsest = |p: &PartSummary| p.levels.len().saturating_sub(1);
        let mut level: Vec<usize> = parts.iter().map(coarsest).collect();
        let mut triangles: u64 = parts
            .iter()
            .zip(&level)
            .map(|(p, &l)| u64::from(p.levels.get(l).map_or(0, |t| t.0)))
            .sum();
        let error_px = |i: usize, l: usize| -> f32 { weight[i] * projected_error_px(&parts[i], l, view) };
        let stick = |i: usize, l: usize| -> f32 {
            // A part already at (or finer than) the level it would refine to needs it more.
            if had_previous && usize::from(previous[i]) < l {
                self.params.stickiness
            } else {
                1.0
            }
        };
        // Max-heap on the weighted error of refining part i from level l.
        let mut heap: std::collections::BinaryHeap<(OrdF32, usize)> = (0..n)
            .filter(|&i| level[i] > 0)
            .map(|i| (OrdF32(error_px(i, level[i]) * stick(i, level[i])), i))
            .collect();
        while let Some((OrdF32(key), i)) = heap.pop() {
            if key < self.params.visible_px {
                break;
            }
            let l = level[i];
            let cost = u64::from(parts[i].levels[l - 1].0).saturating_sub(u64::from(parts[i].levels[l].0));
            if triangles + cost > budget_triangles {
                // Cheaper refinements of other parts may still fit.
                continue;
            }
            triangles += cost;
            level[i] = l - 1;
            if level[i] > 0 {
                heap.push((OrdF32(error_px(i, level[i]) * stick(i, level[i])), i));
            }
        }
        let mut stats = ChoiceStats {
            triangles,
            ..ChoiceStats::default()
        };
        for i in 0..n {
            stats.worst_px = stats.worst_px.max(error_px(i, level[i]));
            if had_previous && usize::from(previous[i]) != level[i] {
                stats.switched += 1;
                let a = projected_error_px(&parts[i], level[i], view);
                let b = projected_error_px(&parts[i], usize::from(previous[i]), view);
                stats.switched_px = stats.switched_px.max(a.max(b));
            }
        }
        self.levels = level.into_iter().map(|l| l.min(usize::from(u8::MAX)) as u8).collect();
        stats
    }
}

/// The paper's attention and facing terms as a weight on the projected error: ½ to 1 each.
fn importance(part: &PartSummary, view: &ChoiceView) -> f32 {
    let centre = part.centre_m + view.offset_m;
    let Some(first) = view.eyes.first() else {
        return 1.0;
    };
    let attention = first.project(centre).map_or(0.5, |p| {
        let d = (p.pixel - view.attention_px).length() / view.attention_reach_px.max(1.0);
        1.0 - 0.5 * d.min(1.0)
    });
    let eyes_mid = view.eyes.iter().map(|e| e.eye_m).sum::<Vec3>() / view.eyes.len() as f32;
    let toward = (eyes_mid - centre).normalize_or_zero();
    let facing = 0.75 + 0.25 * part.facing.dot(toward).clamp(-1.0, 1.0);
    (attention * facing).clamp(0.25, 1.0)
}

/// Level `l`'s geometric error as seen in pixels by the eye that sees it largest: the error
/// placed at the part's point nearest that eye, across the eye's line of sight.
pub fn projected_error_px(part: &PartSummary, l: usize, view: &ChoiceView) -> f32 {
    let error_m = part.levels.get(l).map_or(0.0, |t| t.1);
    if error_m <= 0.0 {
        return 0.0;
    }
    let centre = part.centre_m + view.offset_m;
    view.eyes
        .iter()
        .map(|eye| {
            let to_centre = centre - eye.eye_m;
            let distance = to_centre.length();
            let ray = to_centre.normalize_or(Vec3::NEG_Z);
            // The part's point nearest the eye (the eye inside the sphere: just past the near
            // plane, where anything projects huge).
            let near = if distance > part.radius_m + eye.near_m {
                centre - ray * part.radius_m
            } else {
                eye.eye_m + ray * eye.near_m
            };
            let across = ray.any_orthonormal_pair();
            let (Some(p), Some(a), Some(b)) = (
                eye.project(near),
                eye.project(near + across.0 * error_m),
                eye.project(near + across.1 * error_m),
            ) else {
                return f32::INFINITY;
            };
            (a.pixel - p.pixel).length().max((b.pixel - p.pixel).length())
        })
        .fold(0.0, f32::max)
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct OrdF32(f32);

impl Eq for OrdF32 {}

impl PartialOrd for OrdF32 {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for OrdF32 {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tests::eyes_at;

    /// A part of `levels` levels: level l has 4^(k+1−l) triangles and error 0.02 mm × 4^(l−1)
    /// (about 0.3 px at level 1 for an eye 35 cm from a phone's glass, 1.3 px at level 2).
    fn part(centre: Vec3, facing: Vec3, levels: usize) -> PartSummary {
        PartSummary {
            centre_m: centre,
            radius_m: 0.005,
            facing,
            levels: (0..levels)
                .map(|l| {
                    let t = 4u32.pow((levels - 1 - l) as u32 + 2);
                    (t, if l == 0 { 0.0 } else { 0.00002 * 4f32.powi(l as i32 - 1) })
                })
                .collect(),
        }
    }

    fn view<'a>(eyes: &'a [&'a OffAxisProjection]) -> ChoiceView<'a> {
        ChoiceView {
            eyes,
            offset_m: Vec3::ZERO,
            attention_px: Vec2::new(540.0, 1200.0),
            attention_reach_px: 1320.0,
        }
    }

    #[test]
    fn an_ample_budget_refines_until_the_error_is_invisible() {
        let (l, r) = eyes_at(Vec3::new(0.0, 0.0, 0.35));
        let eyes = [&l, &r];
        let parts: Vec<PartSummary> = (0..8)
            .map(|i| part(Vec3::new(-0.02 + i as f32 * 0.005, 0.0, -0.01), Vec3::Z, 5))
            .collect();
        let mut chooser = Chooser::default();
        let stats = chooser.choose(&parts, &view(&eyes), u64::MAX);
        assert!(stats.worst_px < 0.5, "{stats:?}");
        // Not everything at full detail: the finest levels' errors are invisible already.
        let full: u64 = parts.iter().map(|p| u64::from(p.levels[0].0)).sum();
        assert!(stats.triangles < full, "{} of {full}", stats.triangles);
        // Each part at the coarsest level whose error is invisible: level 1 (level 2 shows).
        assert_eq!(chooser.levels(), &[1; 8]);
    }

    #[test]
    fn a_tight_budget_is_kept_and_spent_where_attention_is() {
        let (l, r) = eyes_at(Vec3::new(0.0, 0.0, 0.35));
        let eyes = [&l, &r];
        // Two identical parts, one at the glass's centre, one near its corner.
        let centre = part(Vec3::new(0.0, 0.0, -0.01), Vec3::Z, 5);
        let corner = part(Vec3::new(0.03, 0.07, -0.01), Vec3::Z, 5);
        let parts = vec![centre, corner];
        // Enough to refine one part to level 1 (1024 triangles), not both.
        let budget = 1300;
        let mut chooser = Chooser::default();
        let stats = chooser.choose(&parts, &view(&eyes), budget);
        assert!(stats.triangles <= budget, "{stats:?}");
        let levels = chooser.levels();
        assert!(levels[0] < levels[1], "the centre gets the detail: {levels:?}");
    }

    #[test]
    fn nearer_parts_and_parts_facing_the_eyes_get_more() {
        let (l, r) = eyes_at(Vec3::new(0.0, 0.0, 0.35));
        let eyes = [&l, &r];
        let near = part(Vec3::new(0.0, 0.01, 0.03), Vec3::Z, 5);
        let far = part(Vec3::new(0.0, -0.01, -0.06), Vec3::Z, 5);
        let v = view(&eyes);
        // Nearest points 0.315 m and 0.405 m from the eyes: 1.29× larger on the glass.
        assert!(projected_error_px(&near, 2, &v) > 1.25 * projected_error_px(&far, 2, &v));
        let facing = part(Vec3::new(0.0, 0.0, -0.01), Vec3::Z, 5);
        let away = part(Vec3::new(0.0, 0.0, -0.01), -Vec3::Z, 5);
        assert!(importance(&facing, &v) > importance(&away, &v));
    }

    #[test]
    fn a_refined_part_keeps_its_detail_against_a_slightly_needier_one() {
        let (l, r) = eyes_at(Vec3::new(0.0, 0.0, 0.35));
        let eyes = [&l, &r];
        let v = view(&eyes);
        // Room for one part's refinement only; part 1 needs it slightly more (nearer the eyes).
        let a = part(Vec3::new(-0.01, 0.0, 0.0), Vec3::Z, 3);
        let b = part(Vec3::new(0.01, 0.0, 0.002), Vec3::Z, 3);
        let ratio = projected_error_px(&b, 2, &v) / projected_error_px(&a, 2, &v);
        assert!(ratio > 1.0 && ratio < 1.3, "{ratio}");
        let budget = u64::from(a.levels[2].0 + a.levels[1].0 + b.levels[2].0);
        let parts = vec![a, b];
        let mut fresh = Chooser::default();
        fresh.choose(&parts, &v, budget);
        assert_eq!(fresh.levels(), &[2, 1], "without history the needier part wins");
        // Had part 0 the detail last frame, it keeps it (a switch would show for no real gain).
        let mut kept = Chooser {
            levels: vec![1, 2],
            ..Chooser::default()
        };
        let stats = kept.choose(&parts, &v, budget);
        assert_eq!(kept.levels(), &[1, 2]);
        assert_eq!(stats.switched, 0);
        // Without stickiness it would switch (the test can fail).
        let mut loose = Chooser {
            params: ChooseParams {
                stickiness: 1.0,
                ..ChooseParams::default()
            },
            levels: vec![1, 2],
        };
        assert_eq!(loose.choose(&parts, &v, budget).switched, 2);
    }
}
