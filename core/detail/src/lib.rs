//! Big scans under a frame budget (the relief-texture paper's mixed representation, polygon
//! half).
//!
//! Museum scans come at millions of triangles and a phantogram draws every frame twice. On load,
//! [`prepare`] splits each big primitive into spatial parts ([`parts`]) and gives each part a
//! level-of-detail chain ([`lod`], meshoptimizer) stored in [`Primitive::lods`]. Every frame,
//! [`Detail::choose`] picks each part's level by importance within a triangle budget
//! ([`choose`]), and the budget follows the measured frame time ([`budget`]). The renderer draws
//! the chosen levels; everything else about the model (bounds, picking, physics, the shadow's
//! fit) keeps using the full meshes.
//!
//! The parts and levels of a scan are kept on disk and reused when the same scan is opened again
//! ([`cache`], [`prepare_cached`]).
//!
//! A part may also have the paper's relief-texture impostor (baked and drawn by the renderer,
//! `phantogram_render::impostor`; the engine gives it to [`Detail::set_impostor`]), which the
//! chooser weighs as one more option. A part that changes level cross-fades from the old one
//! to the new over a quarter second ([`fade`], [`Detail::fade`]).
//!
//! Frames and units: the model's frame is the device frame (metres), as everywhere in the
//! engine. Threading: [`prepare`] runs on the loader thread (seconds for millions of triangles);
//! [`Detail`] is the render thread's. Nothing here panics on any mesh.

pub mod budget;
pub mod cache;
pub mod choose;
pub mod fade;
pub mod lod;
pub mod parts;
pub mod seen;

use glam::{Vec2, Vec3};
use phantogram_assets::model::{Model, Primitive};
use phantogram_geometry::projection::OffAxisProjection;

pub use budget::BudgetController;
pub use choose::{ChoiceStats, ChoiceView, ChooseParams, Chooser, ImpostorSummary, PartSummary};

/// How [`prepare`] splits a scan.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DetailParams {
    /// A model with more triangles than this is split and given levels; smaller ones are drawn
    /// whole (a phone's GPU draws half a million triangles twice within a frame).
    pub min_model_triangles: usize,
    /// Triangles per part: small enough that the chooser can spend detail where it is seen,
    /// large enough that a 10 M-triangle scan stays within a few hundred draw calls per eye.
    pub part_triangles: usize,
    /// No level is made below this many triangles per part.
    pub coarsest_triangles: usize,
}

impl Default for DetailParams {
    fn default() -> Self {
        Self {
            min_model_triangles: 500_000,
            part_triangles: 32_768,
            coarsest_triangles: 64,
        }
    }
}

/// What [`prepare`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PrepareReport {
    pub parts: usize,
    /// Index bytes the coarser levels added.
    pub added_index_bytes: u64,
    /// The parts and levels came from the cache ([`cache`]) rather than being made.
    pub from_cache: bool,
}

/// Splits `model`'s big primitives into parts with level-of-detail chains (see the crate docs),
/// when the model is bigger than `params.min_model_triangles`; otherwise leaves it as it is.
/// `progress` is called with the fraction done (0 to 1).
pub fn prepare(model: &mut Model, params: &DetailParams, progress: impl FnMut(f32)) -> PrepareReport {
    prepare_cached(model, params, None, progress)
}

/// [`prepare`], keeping what it made in `cache_dir` and taking it from there when the same
/// model was prepared before ([`cache`]). A cache that cannot be read or written only costs
/// the time to make the parts again.
pub fn prepare_cached(
    model: &mut Model,
    params: &DetailParams,
    cache_dir: Option<&std::path::Path>,
    mut progress: impl FnMut(f32),
) -> PrepareReport {
    if model.triangle_count() <= params.min_model_triangles {
        return PrepareReport::default();
    }
    let key = cache_dir.map(|_| cache::key(model, params));
    if let (Some(dir), Some(key)) = (cache_dir, key) {
        // The recipe holds about two indices per triangle; a file much larger is not ours.
        let bound = 64 + 16 * (model.triangle_count() as u64 * 3 + model.primitives.len() as u64 * 8);
        if let Some(report) = cache::load(dir, key, bound).and_then(|r| apply(model, &r)) {
            progress(1.0);
            return PrepareReport {
                from_cache: true,
                ..report
            };
        }
    }
    let recipe = make_recipe(model, params, &mut progress);
    let report = apply(model, &recipe).unwrap_or_default();
    if let (Some(dir), Some(key)) = (cache_dir, key) {
        // Not kept: made again next time (a full disk, a read-only folder).
        let _ = cache::store(dir, key, &recipe);
    }
    progress(1.0);
    report
}

/// Splits and simplifies: the recipe [`apply`] follows.
fn make_recipe(model: &Model, params: &DetailParams, progress: &mut impl FnMut(f32)) -> cache::Recipe {
    let total = model.triangle_count().max(1) as f32;
    let mut done = 0usize;
    let mut items = Vec::new();
    let mut slot = Vec::new();
    for (source, p) in model.primitives.iter().enumerate() {
        let source = source as u32;
        let triangles = p.mesh.indices.len() / 3;
        if p.is_floor || triangles <= params.coarsest_triangles * 4 {
            items.push(cache::Item::Kept { source });
            done += triangles;
            continue;
        }
        for ids in parts::split_triangles(p, params.part_triangles) {
            let mut part = parts::part_of(p, &ids, &mut slot);
            lod::build(&mut part, params.coarsest_triangles);
            done += ids.len();
            progress(done as f32 / total);
            items.push(cache::Item::Part {
                source,
                triangles: ids,
                lods: part.lods,
            });
        }
    }
    cache::Recipe { items }
}

/// Rebuilds `model`'s primitives as `recipe` says; `None` (and the model unchanged) when the
/// recipe does not fit the model (a damaged or foreign cache).
fn apply(model: &mut Model, recipe: &cache::Recipe) -> Option<PrepareReport> {
    let mut report = PrepareReport::default();
    let mut out = Vec::with_capacity(recipe.items.len());
    let mut slot = Vec::new();
    for item in &recipe.items {
        match item {
            cache::Item::Kept { source } => out.push(model.primitives.get(*source as usize)?.clone()),
            cache::Item::Part {
                source,
                triangles,
                lods,
            } => {
                let p = model.primitives.get(*source as usize)?;
                let count = (p.mesh.indices.len() / 3) as u32;
                if triangles.iter().any(|&t| t >= count) {
                    return None;
                }
                let mut part = parts::part_of(p, triangles, &mut slot);
                let n = part.mesh.vertices.len() as u32;
                for lod in lods {
                    if !lod.indices.len().is_multiple_of(3)
                        || lod.indices.iter().any(|&v| v >= n)
                        || !(lod.error_m.is_finite() && lod.error_m >= 0.0)
                    {
                        return None;
                    }
                }
                part.lods = lods.clone();
                report.parts += 1;
                report.added_index_bytes += lods.iter().map(|l| l.indices.len() as u64 * 4).sum::<u64>();
                out.push(part);
            }
        }
    }
    model.primitives = out;
    Some(report)
}

impl PartSummary {
    /// The chooser's summary of a primitive: bounding sphere, mean normal, levels.
    pub fn of(p: &Primitive) -> Self {
        let (centre_m, radius_m) = p.mesh.bounds().map_or((Vec3::ZERO, 0.0), |b| {
            let c = (b.min + b.max) * 0.5;
            let r = p
                .mesh
                .vertices
                .iter()
                .map(|v| Vec3::from(v.position).distance(c))
                .fold(0.0, f32::max);
            (c, r)
        });
        let mut area_normal = Vec3::ZERO;
        let mut area = 0.0;
        for t in p.mesh.indices.chunks_exact(3) {
            let q = |k: usize| {
                p.mesh
                    .vertices
                    .get(t[k] as usize)
                    .map_or(Vec3::ZERO, |v| Vec3::from(v.position))
            };
            let n = (q(1) - q(0)).cross(q(2) - q(0));
            area_normal += n;
            area += n.length();
        }
        let facing = if area > 0.0 { area_normal / area } else { Vec3::ZERO };
        let mut levels = vec![((p.mesh.indices.len() / 3) as u32, 0.0)];
        levels.extend(p.lods.iter().map(|l| ((l.indices.len() / 3) as u32, l.error_m)));
        Self {
            centre_m,
            radius_m,
            facing,
            levels,
            impostor: None,
        }
    }
}

/// A prepared scan's per-frame choice: the parts' summaries, the chooser and the budget.
#[derive(Clone, Debug)]
pub struct Detail {
    /// One per model primitive (a primitive without levels has one level).
    parts: Vec<PartSummary>,
    chooser: Chooser,
    fades: fade::Fades,
    budget: BudgetController,
    last: ChoiceStats,
}

impl Detail {
    /// For `model` as [`prepare`] left it, aiming at `target_frame_s` per frame. `None` when no
    /// primitive has levels (nothing to choose).
    pub fn new(model: &Model, target_frame_s: f64) -> Option<Self> {
        if model.primitives.iter().all(|p| p.lods.is_empty()) {
            return None;
        }
        let parts: Vec<PartSummary> = model.primitives.iter().map(PartSummary::of).collect();
        let min: u64 = parts
            .iter()
            .map(|p| u64::from(p.levels.last().map_or(0, |l| l.0)))
            .sum();
        let max: u64 = parts.iter().map(|p| u64::from(p.levels[0].0)).sum();
        Some(Self {
            parts,
            chooser: Chooser::default(),
            fades: fade::Fades::default(),
            // The first frames at what a phone draws twice within a frame (the size from which
            // scans are split), not at full detail: the controller takes it from there.
            budget: BudgetController::new(target_frame_s, min, max)
                .starting_at(DetailParams::default().min_model_triangles as u64),
            last: ChoiceStats::default(),
        })
    }

    /// After a frame that took `frame_s` (GPU time, or wall time): the budget follows it.
    pub fn frame_took(&mut self, frame_s: f64) {
        self.budget.update(frame_s, self.last.triangles);
    }

    /// Sets the frame time aimed at.
    pub fn set_target(&mut self, target_frame_s: f64) {
        self.budget.target_s = target_frame_s;
    }

    /// The budget the next frame is chosen within, triangles per eye.
    pub fn budget_triangles(&self) -> u64 {
        self.budget.budget()
    }

    /// Chooses the levels for a frame seen by `eyes` with the mesh moved by `offset_m`, attention
    /// at `attention_px` (in the first eye's projected pixels, the glass's whatever size the
    /// frame is rendered at; `None`: the glass's centre). Returns one level per model primitive.
    pub fn choose(&mut self, eyes: &[&OffAxisProjection], offset_m: Vec3, attention_px: Option<Vec2>) -> &[u8] {
        let budget = self.budget.budget();
        self.choose_within(eyes, offset_m, attention_px, budget)
    }

    /// [`Detail::choose`] within `budget_triangles` per eye instead of the controller's budget
    /// (`u64::MAX`: every part at the coarsest level whose error is invisible).
    pub fn choose_within(
        &mut self,
        eyes: &[&OffAxisProjection],
        offset_m: Vec3,
        attention_px: Option<Vec2>,
        budget_triangles: u64,
    ) -> &[u8] {
        let image_px = eyes.first().map_or(Vec2::ONE, |e| e.image_px());
        let view = ChoiceView {
            eyes,
            offset_m,
            attention_px: attention_px.unwrap_or(image_px * 0.5),
            attention_reach_px: image_px.length() * 0.5,
        };
        self.last = self.chooser.choose(&self.parts, &view, budget_triangles);
        self.chooser.levels()
    }

    /// Gives part `index` (the model's primitive) its impostor, planned or baked, or takes it
    /// away (`None`); an index past the parts is ignored.
    pub fn set_impostor(&mut self, index: usize, impostor: Option<ImpostorSummary>) {
        if let Some(p) = self.parts.get_mut(index) {
            p.impostor = impostor;
        }
    }

    /// The parts whose planned impostors the last [`Detail::choose`] would have drawn, in
    /// order ([`Chooser::worth_baking`]): the impostors worth baking now.
    pub fn impostors_worth_baking(&self) -> &[usize] {
        self.chooser.worth_baking()
    }

    /// The parts the chooser weighs, one per model primitive.
    pub fn parts(&self) -> &[PartSummary] {
        &self.parts
    }

    /// The cross-fades of the frame the last [`Detail::choose`] chose, shown at display time
    /// `now_s` (`None`: frames drawn on request, which switch at once); call once a frame.
    pub fn fade(&mut self, now_s: Option<f64>) -> Vec<phantogram_assets::model::LevelFade> {
        self.fades.update(self.chooser.levels(), now_s)
    }

    /// What the last [`Detail::choose`] did.
    pub fn last_choice(&self) -> ChoiceStats {
        self.last
    }

    /// Forces every part to `level` (clamped to its chain) for the next frames' comparison
    /// renders; [`Detail::choose`] overrides it.
    pub fn all_at(&self, level: u8) -> Vec<u8> {
        self.parts
            .iter()
            .map(|p| level.min(p.levels.len().saturating_sub(1) as u8))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use phantogram_assets::model::{Material, Mesh, Vertex};
    use phantogram_geometry::projection::DepthRange;
    use phantogram_geometry::screen::{DisplayRotation, PanelSpec, Screen};

    /// A flat `w × h` grid of unit cells in z = 0, facing +z.
    pub(crate) fn grid(w: u32, h: u32) -> Primitive {
        bumpy_grid(w, h, 0.0)
    }

    /// A `w × h` grid of unit cells with a smooth bump field of height `amplitude` (cells' units).
    pub(crate) fn bumpy_grid(w: u32, h: u32, amplitude: f32) -> Primitive {
        let mut mesh = Mesh::default();
        for y in 0..=h {
            for x in 0..=w {
                let z = amplitude * ((x as f32 * 0.7).sin() * (y as f32 * 0.5).cos());
                mesh.vertices.push(Vertex {
                    position: [x as f32, y as f32, z],
                    normal: [0.0, 0.0, 1.0],
                    tangent: [1.0, 0.0, 0.0, 1.0],
                    color: [1.0; 4],
                    material: [1.0, 1.0],
                    ..Vertex::default()
                });
            }
        }
        for y in 0..h {
            for x in 0..w {
                let i = y * (w + 1) + x;
                mesh.indices
                    .extend_from_slice(&[i, i + 1, i + w + 2, i, i + w + 2, i + w + 1]);
            }
        }
        Primitive {
            mesh,
            material: 0,
            is_floor: false,
            lods: Vec::new(),
        }
    }

    /// Both eyes 63 mm apart around `mid` over a 1080 × 2400 phone's glass.
    pub(crate) fn eyes_at(mid: Vec3) -> (OffAxisProjection, OffAxisProjection) {
        let screen = Screen::new(
            PanelSpec {
                width_px: 1080,
                height_px: 2400,
                xdpi: 400.0,
                ydpi: 400.0,
            },
            DisplayRotation::Deg0,
        )
        .unwrap();
        let depth = DepthRange::default();
        let half = Vec3::X * 0.0315;
        (
            OffAxisProjection::new(&screen, mid - half, depth).unwrap(),
            OffAxisProjection::new(&screen, mid + half, depth).unwrap(),
        )
    }

    #[test]
    fn prepare_splits_only_big_models_and_every_part_gets_levels() {
        let mut small = Model {
            primitives: vec![bumpy_grid(32, 32, 0.3)],
            materials: vec![Material::default()],
            ..Model::default()
        };
        let params = DetailParams {
            min_model_triangles: 5000,
            part_triangles: 1024,
            coarsest_triangles: 16,
        };
        let before = small.clone();
        assert_eq!(prepare(&mut small, &params, |_| {}).parts, 0);
        assert_eq!(small, before);
        assert!(Detail::new(&small, 0.033).is_none());

        let mut big = Model {
            primitives: vec![bumpy_grid(80, 64, 0.3)],
            materials: vec![Material::default()],
            ..Model::default()
        };
        let triangles = big.triangle_count();
        let mut fractions = Vec::new();
        let report = prepare(&mut big, &params, |f| fractions.push(f));
        assert_eq!(big.triangle_count(), triangles, "parts keep every triangle");
        assert_eq!(report.parts, big.primitives.len());
        assert!(report.parts >= 10);
        assert!(big.primitives.iter().all(|p| !p.lods.is_empty()));
        assert!(fractions.windows(2).all(|w| w[0] <= w[1]) && fractions.last() == Some(&1.0));
        let detail = Detail::new(&big, 0.033).expect("levels");
        assert_eq!(detail.all_at(200).len(), big.primitives.len());
    }

    #[test]
    fn a_cached_preparation_gives_the_same_model_and_damage_means_a_rebuild() {
        let dir = std::env::temp_dir().join(format!("phantogram-detail-prepare-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let params = DetailParams {
            min_model_triangles: 5000,
            part_triangles: 1024,
            coarsest_triangles: 16,
        };
        let source = Model {
            primitives: vec![bumpy_grid(80, 64, 0.3), bumpy_grid(4, 4, 0.0)],
            materials: vec![Material::default()],
            ..Model::default()
        };
        let mut made = source.clone();
        let first = prepare_cached(&mut made, &params, Some(&dir), |_| {});
        assert!(!first.from_cache && first.parts > 10);
        let mut cached = source.clone();
        let second = prepare_cached(&mut cached, &params, Some(&dir), |_| {});
        assert!(second.from_cache, "{second:?}");
        assert_eq!(cached, made, "the cache gives the very same parts and levels");
        // Another placement of the same scan is another key: made afresh.
        let mut moved = source.clone();
        moved.transform(glam::Mat4::from_translation(Vec3::X));
        assert!(!prepare_cached(&mut moved, &params, Some(&dir), |_| {}).from_cache);
        // A damaged file is not used.
        let file = cache::path(&dir, cache::key(&source, &params));
        let mut bytes = std::fs::read(&file).unwrap();
        let last = bytes.len() - 1;
        bytes[last] ^= 1;
        std::fs::write(&file, bytes).unwrap();
        let mut again = source.clone();
        let third = prepare_cached(&mut again, &params, Some(&dir), |_| {});
        assert!(!third.from_cache);
        assert_eq!(again, made);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn without_a_gaze_attention_is_at_the_glass_centre() {
        // Two like parts 1.6 cm across, one at the glass's centre, one near its corner, with
        // room in the budget for one refinement: the centre's gets it.
        let part_at = |at: Vec3| {
            let mut p = bumpy_grid(16, 16, 0.3);
            p.mesh.transform(glam::Mat4::from_scale_rotation_translation(
                Vec3::splat(0.001),
                glam::Quat::IDENTITY,
                at - Vec3::new(0.008, 0.008, 0.0),
            ));
            lod::build(&mut p, 16);
            p
        };
        let model = Model {
            primitives: vec![part_at(Vec3::ZERO), part_at(Vec3::new(0.024, 0.06, 0.0))],
            materials: vec![Material::default()],
            ..Model::default()
        };
        let mut detail = Detail::new(&model, 0.033).expect("levels");
        let summary = PartSummary::of(&model.primitives[0]);
        let k = summary.levels.len() - 1;
        let coarsest: u64 = 2 * u64::from(summary.levels[k].0);
        let step = u64::from(summary.levels[k - 1].0 - summary.levels[k].0);
        let (l, r) = eyes_at(Vec3::new(0.0, 0.0, 0.35));
        let levels = detail.choose_within(&[&l, &r], Vec3::ZERO, None, coarsest + step);
        assert!(levels[0] < levels[1], "{levels:?}");
    }

    #[test]
    fn a_summary_faces_where_the_surface_does() {
        let s = PartSummary::of(&grid(4, 4));
        assert!((s.facing - Vec3::Z).length() < 1e-5, "{}", s.facing);
        assert!((s.centre_m - Vec3::new(2.0, 2.0, 0.0)).length() < 1e-5);
        assert!((s.radius_m - 8f32.sqrt()).abs() < 1e-4);
        assert_eq!(s.levels, vec![(32, 0.0)]);
    }
}
