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
//!
//! ## Impostors
//! A part with a relief-texture impostor ([`ImpostorSummary`]) has it as one more option: its
//! error is half a texel's diagonal, its cost is fill, not triangles — every pixel it covers
//! casts a ray of about two steps per texel across the box — counted in triangles at
//! [`ChooseParams::impostor_step_triangles`] per step. Each frame a part's options (its levels
//! and the impostor) are reduced to those that no other option beats in both cost and error,
//! and refinement walks that chain from the cheapest. So the impostor is drawn where it is the
//! cheaper way to a given error: parts of many triangles that cover few pixels. A phantogram
//! seen from arm's length at a phone's resolution mostly makes parts large on the glass, and
//! there the polygons win.

use glam::{Vec2, Vec3};
use phantogram_assets::model::IMPOSTOR_LEVEL;
use phantogram_geometry::projection::OffAxisProjection;

/// A part's relief-texture impostor, as the chooser weighs it: planned (its resolution known,
/// so its error and cost) and, once the renderer has made it, baked. Only baked impostors are
/// drawn; [`worth_baking`] says which planned ones the chooser would draw.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImpostorSummary {
    /// How far a surface point it draws can lie from the true surface, metres.
    pub error_m: f32,
    /// Texels along a side of each face's map.
    pub texels: u32,
    pub baked: bool,
}

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
    /// The part's impostor, where one is planned or baked.
    pub impostor: Option<ImpostorSummary>,
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
    /// What one step of an impostor's ray in one pixel costs, in triangles (see the module
    /// docs). Measured on this project's machine by `cargo xtask bench detail` (lavapipe); a
    /// phone GPU's figure is not measured — the budget controller corrects the sum of costs
    /// to the measured frame time, not this ratio between the two kinds.
    pub impostor_step_triangles: f32,
}

impl Default for ChooseParams {
    fn default() -> Self {
        Self {
            visible_px: 0.5,
            stickiness: 1.5,
            impostor_step_triangles: IMPOSTOR_STEP_TRIANGLES,
        }
    }
}

/// [`ChooseParams::impostor_step_triangles`]' default: 0.109 and 0.119 measured by `cargo
/// xtask bench detail` in two runs on this project's machine (lavapipe, the turtle made big:
/// every part as its impostor against every part at full detail, both over the coarsest
/// frame; see `benchmarks/detail.md`).
pub const IMPOSTOR_STEP_TRIANGLES: f32 = 0.115;

/// One way to draw a part: its level code (an index into its levels, or [`IMPOSTOR_LEVEL`]),
/// its cost (triangles, or their equivalent) and its error on the glass (pixels, unweighted).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Candidate {
    code: u8,
    cost: u64,
    error_px: f32,
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
    /// Parts whose planned impostor the last choice would have drawn (see [`worth_baking`]).
    worth_baking: Vec<usize>,
}

/// The outcome of one [`Chooser::choose`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ChoiceStats {
    /// Triangles drawn per eye, with each impostor's cost in triangles.
    pub triangles: u64,
    /// The largest weighted error left on screen, pixels.
    pub worst_px: f32,
    /// Parts whose level changed since the last frame, and the largest error (pixels, not
    /// weighted) of a level switched to or from: the size of the visible change switching made.
    pub switched: u32,
    pub switched_px: f32,
    /// Parts drawn as impostors.
    pub impostors: u32,
}

impl Chooser {
    /// The levels of the last choice, one per part (0 the finest; [`IMPOSTOR_LEVEL`] for an
    /// impostor).
    pub fn levels(&self) -> &[u8] {
        &self.levels
    }

    /// The parts, in order, whose planned (not yet baked) impostor would have been among their
    /// options in the last choice: the impostors worth baking.
    pub fn worth_baking(&self) -> &[usize] {
        &self.worth_baking
    }

    /// Chooses each part's level for `view` within `budget_triangles` per eye (never fewer than
    /// every part's cheapest option).
    pub fn choose(&mut self, parts: &[PartSummary], view: &ChoiceView, budget_triangles: u64) -> ChoiceStats {
        let n = parts.len();
        let previous = std::mem::take(&mut self.levels);
        let had_previous = previous.len() == n;
        let weight: Vec<f32> = parts.iter().map(|p| importance(p, view)).collect();
        // Each part's options worth having, costliest (finest) first; and, from the same
        // candidates, the planned impostors that would be among them once baked.
        let mut worth_baking = Vec::new();
        let chains: Vec<Vec<Candidate>> = parts
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let all = candidates(p, view, &self.params);
                if p.impostor.is_none_or(|imp| imp.baked) {
                    return front(all);
                }
                if front(all.clone()).iter().any(|c| c.code == IMPOSTOR_LEVEL) {
                    worth_baking.push(i);
                }
                front(all.into_iter().filter(|c| c.code != IMPOSTOR_LEVEL).collect())
            })
            .collect();
        self.worth_baking = worth_baking;
        let mut pos: Vec<usize> = chains.iter().map(|c| c.len().saturating_sub(1)).collect();
        let mut triangles: u64 = chains
            .iter()
            .zip(&pos)
            .map(|(c, &k)| c.get(k).map_or(0, |o| o.cost))
            .sum();
        let error_px = |i: usize, k: usize| -> f32 { weight[i] * chains[i].get(k).map_or(0.0, |o| o.error_px) };
        // Where last frame's choice sits in this frame's chain (none: it is no longer worth
        // having, and nothing holds the part to it).
        let previous_pos: Vec<Option<usize>> = (0..n)
            .map(|i| {
                had_previous
                    .then(|| chains[i].iter().position(|o| o.code == previous[i]))
                    .flatten()
            })
            .collect();
        let stick = |i: usize, k: usize| -> f32 {
            // A part already at (or finer than) the option it would refine to needs it more.
            if previous_pos[i].is_some_and(|p| p < k) {
                self.params.stickiness
            } else {
                1.0
            }
        };
        // Max-heap on the weighted error of refining part i from its position k.
        let mut heap: std::collections::BinaryHeap<(OrdF32, usize)> = (0..n)
            .filter(|&i| pos[i] > 0)
            .map(|i| (OrdF32(error_px(i, pos[i]) * stick(i, pos[i])), i))
            .collect();
        while let Some((OrdF32(key), i)) = heap.pop() {
            if key < self.params.visible_px {
                break;
            }
            let k = pos[i];
            let cost = chains[i][k - 1].cost.saturating_sub(chains[i][k].cost);
            if triangles.saturating_add(cost) > budget_triangles {
                // Cheaper refinements of other parts may still fit.
                continue;
            }
            triangles += cost;
            pos[i] = k - 1;
            if pos[i] > 0 {
                heap.push((OrdF32(error_px(i, pos[i]) * stick(i, pos[i])), i));
            }
        }
        let mut stats = ChoiceStats {
            triangles,
            ..ChoiceStats::default()
        };
        let codes: Vec<u8> = (0..n).map(|i| chains[i].get(pos[i]).map_or(0, |o| o.code)).collect();
        for i in 0..n {
            stats.worst_px = stats.worst_px.max(error_px(i, pos[i]));
            if codes[i] == IMPOSTOR_LEVEL {
                stats.impostors += 1;
            }
            if had_previous && previous[i] != codes[i] {
                stats.switched += 1;
                let a = code_error_px(&parts[i], codes[i], view);
                let b = code_error_px(&parts[i], previous[i], view);
                stats.switched_px = stats.switched_px.max(a.max(b));
            }
        }
        self.levels = codes;
        stats
    }
}

/// Whether `part`'s planned impostor would be one of its options for `view` (no other option
/// beats it in both cost and error) once baked: an impostor worth making now. (The chooser
/// records the same for every part as it chooses: [`Chooser::worth_baking`].)
pub fn worth_baking(part: &PartSummary, view: &ChoiceView, params: &ChooseParams) -> bool {
    part.impostor.is_some_and(|i| !i.baked)
        && front(candidates(part, view, params))
            .iter()
            .any(|c| c.code == IMPOSTOR_LEVEL)
}

/// `part`'s options for `view` that no other beats in both cost and error, costliest first;
/// its impostor among them only if baked.
#[cfg(test)]
fn options(part: &PartSummary, view: &ChoiceView, params: &ChooseParams) -> Vec<Candidate> {
    let mut all = candidates(part, view, params);
    if part.impostor.is_some_and(|i| !i.baked) {
        all.retain(|c| c.code != IMPOSTOR_LEVEL);
    }
    front(all)
}

/// Every way to draw `part` for `view`: its levels and its impostor (planned or baked).
fn candidates(part: &PartSummary, view: &ChoiceView, params: &ChooseParams) -> Vec<Candidate> {
    // Level codes stop short of the impostor's (a chain that long is not made).
    let mut all: Vec<Candidate> = part
        .levels
        .iter()
        .enumerate()
        .take(usize::from(IMPOSTOR_LEVEL))
        .map(|(l, &(triangles, _))| Candidate {
            code: l as u8,
            cost: u64::from(triangles),
            error_px: projected_error_px(part, l, view),
        })
        .collect();
    if let Some(imp) = part.impostor {
        all.push(Candidate {
            code: IMPOSTOR_LEVEL,
            cost: impostor_cost(part, &imp, view, params),
            error_px: projected_px(part, imp.error_m, view),
        });
    }
    all
}

/// The candidates no other beats in both cost and error, costliest first.
fn front(mut all: Vec<Candidate>) -> Vec<Candidate> {
    // Cheapest first; keep each option that is more exact than every cheaper one kept.
    all.sort_by(|a, b| a.cost.cmp(&b.cost).then(a.error_px.total_cmp(&b.error_px)));
    let mut kept: Vec<Candidate> = Vec::with_capacity(all.len());
    for o in all {
        if kept.last().is_none_or(|k| o.error_px < k.error_px) {
            kept.push(o);
        }
    }
    kept.reverse();
    kept
}

/// An impostor's cost in triangles: the pixels its box covers in the eye that sees it largest
/// (the part's bounding sphere's disc), times the ray's steps per pixel (two per texel along
/// the box, the mean chord about one box side), times a step's cost.
pub fn impostor_cost(part: &PartSummary, imp: &ImpostorSummary, view: &ChoiceView, params: &ChooseParams) -> u64 {
    let radius_px = projected_px(part, part.radius_m, view);
    if !radius_px.is_finite() {
        return u64::MAX / 4;
    }
    let pixels = std::f32::consts::PI * radius_px * radius_px;
    let steps = 2.0 * imp.texels as f32;
    (pixels * steps * params.impostor_step_triangles).ceil().min(1e15) as u64 + 12
}

/// The error of the option `code` stands for, pixels (unweighted).
fn code_error_px(part: &PartSummary, code: u8, view: &ChoiceView) -> f32 {
    if code == IMPOSTOR_LEVEL {
        part.impostor.map_or(0.0, |i| projected_px(part, i.error_m, view))
    } else {
        projected_error_px(part, usize::from(code), view)
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
    projected_px(part, part.levels.get(l).map_or(0.0, |t| t.1), view)
}

/// A length `error_m` at the part's point nearest the eye that sees it largest, across that
/// eye's line of sight, in pixels.
pub fn projected_px(part: &PartSummary, error_m: f32, view: &ChoiceView) -> f32 {
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
            impostor: None,
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
            worth_baking: Vec::new(),
        };
        assert_eq!(loose.choose(&parts, &v, budget).switched, 2);
    }

    /// A heavy part (a million triangles) with a 64-texel impostor, centred `z` from the glass.
    fn heavy(z: f32) -> PartSummary {
        PartSummary {
            centre_m: Vec3::new(0.0, 0.0, z),
            radius_m: 0.01,
            facing: Vec3::Z,
            levels: vec![(1_000_000, 0.0), (100_000, 0.0004), (10_000, 0.002), (1_000, 0.006)],
            impostor: Some(ImpostorSummary {
                error_m: 0.00022,
                texels: 64,
                baked: true,
            }),
        }
    }

    #[test]
    fn an_impostor_is_drawn_where_it_is_the_cheaper_way_to_an_error() {
        let (l, r) = eyes_at(Vec3::new(0.0, 0.0, 0.35));
        let eyes = [&l, &r];
        let v = view(&eyes);
        // A metre behind the glass the part covers a few thousand pixels: its impostor costs less
        // than its second level and shows less error, so within that budget it is drawn.
        let far = heavy(-1.0);
        let chain = options(&far, &v, &ChooseParams::default());
        let imp = chain
            .iter()
            .find(|c| c.code == IMPOSTOR_LEVEL)
            .expect("the impostor is worth having far away");
        assert!(
            imp.cost < 100_000 && imp.error_px < projected_error_px(&far, 1, &v),
            "{chain:?}"
        );
        assert!(
            !chain.iter().any(|c| c.code == 1),
            "level 1 is beaten in cost and error: {chain:?}"
        );
        let mut chooser = Chooser::default();
        let stats = chooser.choose(std::slice::from_ref(&far), &v, 90_000);
        assert_eq!(chooser.levels(), &[IMPOSTOR_LEVEL], "{stats:?}");
        assert_eq!(stats.impostors, 1);
        assert!(stats.triangles == imp.cost && stats.triangles <= 90_000);
        // Without its impostor the same budget leaves it at level 2, five times the error.
        let bare = PartSummary {
            impostor: None,
            ..far.clone()
        };
        let mut chooser = Chooser::default();
        chooser.choose(std::slice::from_ref(&bare), &v, 90_000);
        assert_eq!(chooser.levels(), &[2]);
        // Unbounded, the full mesh (the impostor's error is visible at this distance).
        let mut chooser = Chooser::default();
        chooser.choose(std::slice::from_ref(&far), &v, u64::MAX);
        assert_eq!(chooser.levels(), &[0]);
        // At the glass the part is large on screen: every pixel's ray costs more than the
        // triangles it replaces, and the impostor is not an option.
        let near = heavy(-0.01);
        let chain = options(&near, &v, &ChooseParams::default());
        assert!(!chain.iter().any(|c| c.code == IMPOSTOR_LEVEL), "{chain:?}");
        let mut chooser = Chooser::default();
        chooser.choose(std::slice::from_ref(&near), &v, 90_000);
        assert_ne!(chooser.levels()[0], IMPOSTOR_LEVEL);
        // Planned but not baked: never drawn, and worth baking only where it would be.
        let unbaked = |p: &PartSummary| PartSummary {
            impostor: p.impostor.map(|i| ImpostorSummary { baked: false, ..i }),
            ..p.clone()
        };
        let mut chooser = Chooser::default();
        chooser.choose(&[unbaked(&far)], &v, 90_000);
        assert_eq!(chooser.levels(), &[2]);
        assert!(worth_baking(&unbaked(&far), &v, &ChooseParams::default()));
        assert!(!worth_baking(&unbaked(&near), &v, &ChooseParams::default()));
        assert!(!worth_baking(&far, &v, &ChooseParams::default()), "baked already");
        // The chooser records the same as it chooses.
        let mut chooser = Chooser::default();
        chooser.choose(&[unbaked(&near), unbaked(&far), far.clone()], &v, 90_000);
        assert_eq!(chooser.worth_baking(), &[1]);
    }
}
