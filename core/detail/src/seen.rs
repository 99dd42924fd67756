//! Which sides of the artifact the viewer has seen, and which way to tilt to see one not yet
//! seen (the relief-texture paper's TangibleScreen advice).
//!
//! The artifact's surface is summarised once by its normals: its triangles binned by normal into
//! [`DIRECTIONS`] directions spread evenly over the sphere (a Fibonacci lattice), each bin's
//! area and mean normal, in the device frame — the artifact's frame on the glass. A patch of surface counts as seen once the viewer
//! has looked at it from within [`SEEN_WITHIN_RAD`] of its normal (a surface seen more
//! obliquely shows too little of itself). Each frame the view direction — from the artifact's
//! centre to the eyes — marks what it shows. When the viewer lingers (the view direction stays
//! within [`LINGER_WITHIN_RAD`] for [`LINGER_S`]) and a reachable view would show enough unseen
//! surface, [`SeenSides::hint`] names that view: the one revealing the most unseen area, as the
//! paper ranks faces by unseen area.
//!
//! Reachable: the eyes are in front of the glass, and tilting a phone moves them by at most
//! [`MAX_TILT_RAD`] from the glass's normal; surface facing into the phone (an artifact's base
//! on the floor) can never be seen by tilting and is left out of every count. Occlusion is not
//! modelled: a hollow or a side hidden behind a part of the artifact counts as seen when its
//! normal was faced.
//!
//! Plain data owned by the render thread; never panics.

use glam::{Vec2, Vec3};
use phantogram_assets::model::Model;

/// How many directions the surface's normals are binned into.
pub const DIRECTIONS: usize = 64;
/// A surface counts as seen from views within this angle of its normal.
pub const SEEN_WITHIN_RAD: f32 = 55.0 * std::f32::consts::PI / 180.0;
/// The most a phone is tilted to look at its artifact from the side, from the glass's normal.
pub const MAX_TILT_RAD: f32 = 60.0 * std::f32::consts::PI / 180.0;
/// The view lingers while it stays within this angle ...
pub const LINGER_WITHIN_RAD: f32 = 8.0 * std::f32::consts::PI / 180.0;
/// ... for this long.
pub const LINGER_S: f64 = 2.5;
/// A hint is worth showing when its view would reveal at least this fraction of the reachable
/// surface.
pub const MIN_REVEAL: f32 = 0.08;

/// Which way to tilt: the hint [`SeenSides::hint`] gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hint {
    /// Direction on the glass towards the side to look at (device x right, y up; unit length):
    /// tilt the phone so that this edge comes up towards the viewer.
    pub toward: Vec2,
    /// The view to take, unit vector from the artifact towards the eyes, device frame.
    pub view: Vec3,
    /// Fraction of the reachable surface that view would reveal.
    pub reveals: f32,
}

/// See the module docs.
#[derive(Clone, Debug)]
pub struct SeenSides {
    directions: Vec<Vec3>,
    /// Area facing each direction, square metres (0 for unreachable directions).
    area: Vec<f32>,
    seen: Vec<bool>,
    reachable_area: f32,
    /// The view being lingered on and since when (seconds).
    linger: Option<(Vec3, f64)>,
}

impl SeenSides {
    /// Summarises `model`'s surface (the floor excluded).
    pub fn new(model: &Model) -> Self {
        let bins = phantogram_geometry::sphere::fibonacci(DIRECTIONS);
        let mut area = vec![0.0f32; DIRECTIONS];
        // Area-weighted normals per bin: the bin's direction is its surfaces' mean normal, not
        // the lattice point (up to ~15° away from it).
        let mut normal_sum = vec![Vec3::ZERO; DIRECTIONS];
        for p in model.primitives.iter().filter(|p| !p.is_floor) {
            let v = &p.mesh.vertices;
            for t in p.mesh.indices.chunks_exact(3) {
                let q = |k: usize| v.get(t[k] as usize).map_or(Vec3::ZERO, |v| Vec3::from(v.position));
                let n = (q(1) - q(0)).cross(q(2) - q(0));
                let a = n.length() * 0.5;
                if a > 0.0 && a.is_finite() {
                    let b = nearest(&bins, n / (2.0 * a));
                    area[b] += a;
                    normal_sum[b] += n * 0.5;
                }
            }
        }
        let directions: Vec<Vec3> = normal_sum
            .iter()
            .zip(&bins)
            .map(|(n, b)| n.try_normalize().unwrap_or(*b))
            .collect();
        // Surfaces no reachable view sees within SEEN_WITHIN_RAD are left out.
        for (d, a) in directions.iter().zip(area.iter_mut()) {
            if !reachable_sees(*d) {
                *a = 0.0;
            }
        }
        let reachable_area = area.iter().sum();
        Self {
            seen: vec![false; DIRECTIONS],
            directions,
            area,
            reachable_area,
            linger: None,
        }
    }

    /// The viewer looks from `view` (from the artifact's centre towards the eyes, device frame)
    /// at time `t_s`.
    pub fn look(&mut self, view: Vec3, t_s: f64) {
        let Some(view) = view.try_normalize() else {
            return;
        };
        let cos_seen = SEEN_WITHIN_RAD.cos();
        for (d, seen) in self.directions.iter().zip(self.seen.iter_mut()) {
            if d.dot(view) >= cos_seen {
                *seen = true;
            }
        }
        match self.linger {
            Some((at, _)) if at.angle_between(view) <= LINGER_WITHIN_RAD => {}
            _ => self.linger = Some((view, t_s)),
        }
    }

    /// The fraction of the reachable surface seen so far.
    pub fn seen_fraction(&self) -> f32 {
        if self.reachable_area <= 0.0 {
            return 1.0;
        }
        let seen: f32 = self
            .area
            .iter()
            .zip(&self.seen)
            .filter(|(_, s)| **s)
            .map(|(a, _)| a)
            .sum();
        seen / self.reachable_area
    }

    /// While the viewer has lingered (see the module docs) at time `t_s`: the reachable view
    /// that would reveal the most unseen surface, if it reveals at least [`MIN_REVEAL`].
    pub fn hint(&self, t_s: f64) -> Option<Hint> {
        let (_, since) = self.linger?;
        if t_s - since < LINGER_S {
            return None;
        }
        self.best_view()
    }

    /// The reachable view revealing the most unseen surface (lingering or not).
    pub fn best_view(&self) -> Option<Hint> {
        if self.reachable_area <= 0.0 {
            return None;
        }
        let cos_seen = SEEN_WITHIN_RAD.cos();
        // Ranked by the unseen area as that view shows it (projected: surfaces faced squarely
        // count fully), so that of two views revealing the same sides the one facing them wins.
        let (view, _, revealed) = candidate_views()
            .map(|v| {
                let unseen = self
                    .directions
                    .iter()
                    .zip(&self.area)
                    .zip(&self.seen)
                    .filter(|((d, _), seen)| !**seen && d.dot(v) >= cos_seen);
                let shown: f32 = unseen.clone().map(|((d, a), _)| a * d.dot(v)).sum();
                let area: f32 = unseen.map(|((_, a), _)| a).sum();
                (v, shown, area)
            })
            .max_by(|a, b| a.1.total_cmp(&b.1))?;
        let reveals = revealed / self.reachable_area;
        let toward = view.truncate().try_normalize()?;
        (reveals >= MIN_REVEAL).then_some(Hint { toward, view, reveals })
    }
}

/// Views a tilt can reach: within [`MAX_TILT_RAD`] of +z, every 5° of tilt and 10° around.
fn candidate_views() -> impl Iterator<Item = Vec3> {
    (1..=12).flat_map(|i| {
        let tilt = MAX_TILT_RAD * i as f32 / 12.0;
        (0..36).map(move |j| {
            let around = std::f32::consts::TAU * j as f32 / 36.0;
            Vec3::new(tilt.sin() * around.cos(), tilt.sin() * around.sin(), tilt.cos())
        })
    })
}

/// Whether a surface facing `d` can be seen within [`SEEN_WITHIN_RAD`] from some reachable view.
fn reachable_sees(d: Vec3) -> bool {
    // The reachable views are a cone about +z of half-angle MAX_TILT_RAD.
    d.angle_between(Vec3::Z) <= MAX_TILT_RAD + SEEN_WITHIN_RAD
}

fn nearest(directions: &[Vec3], n: Vec3) -> usize {
    directions
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.dot(n).total_cmp(&b.1.dot(n)))
        .map_or(0, |(i, _)| i)
}

#[cfg(test)]
mod tests {
    use super::*;
    use phantogram_assets::model::Mesh;

    /// A box standing on the glass (base at z = 0): `sides` are the half-extents, so a longer
    /// x extent means larger ±y faces.
    fn standing_box(half: Vec3) -> Model {
        let mut mesh = Mesh::default();
        mesh.push_cube(Vec3::ZERO, 1.0, [1.0; 4]);
        mesh.transform(glam::Mat4::from_scale_rotation_translation(
            half,
            glam::Quat::IDENTITY,
            Vec3::Z * half.z,
        ));
        Model::from_painted_mesh("box", mesh)
    }

    #[test]
    fn from_the_front_the_hint_points_at_the_largest_unseen_side() {
        // A box 2 cm wide (x), 6 cm deep (y), 2 cm tall: its ±x faces are the largest sides.
        let model = standing_box(Vec3::new(0.01, 0.03, 0.01));
        let mut seen = SeenSides::new(&model);
        // Straight on, then a little to the right: the top and the +x face are seen.
        seen.look(Vec3::Z, 0.0);
        seen.look(Vec3::new(0.7, 0.0, 0.7), 1.0);
        assert!(seen.hint(1.5).is_none(), "no hint before the viewer lingers");
        seen.look(Vec3::new(0.7, 0.05, 0.7), 2.0);
        let hint = seen.hint(5.0).expect("a hint after lingering");
        // The −x face (6 × 2 cm) is the largest unseen one: look from the left.
        assert!(hint.toward.x < -0.9, "{hint:?}");
        assert!(hint.reveals > 0.2 && hint.reveals < 0.6, "{hint:?}");
        // Once seen, the next largest are ±y (2 × 2 cm each).
        seen.look(Vec3::new(-0.7, 0.0, 0.7), 6.0);
        let next = seen.best_view().expect("±y unseen");
        assert!(next.toward.y.abs() > 0.9, "{next:?}");
        seen.look(Vec3::new(0.0, 0.7, 0.7), 7.0);
        seen.look(Vec3::new(0.0, -0.7, 0.7), 8.0);
        assert!(seen.best_view().is_none(), "everything reachable seen");
        assert!(seen.seen_fraction() > 0.99, "{}", seen.seen_fraction());
    }

    #[test]
    fn the_base_on_the_floor_never_counts_and_moving_is_not_lingering() {
        let model = standing_box(Vec3::splat(0.02));
        let mut seen = SeenSides::new(&model);
        // Top and four sides are reachable, the base (−z) is not: 5 of 6 faces.
        let total: f32 = 6.0 * 0.04 * 0.04;
        assert!(
            (seen.reachable_area / total - 5.0 / 6.0).abs() < 0.02,
            "{}",
            seen.reachable_area / total
        );
        // Sweeping around without pause: no hint, however long.
        for k in 0..100 {
            let a = k as f32 * 0.3;
            seen.look(Vec3::new(0.3 * a.cos(), 0.3 * a.sin(), 1.0), k as f64 * 0.1);
            assert!(seen.hint(k as f64 * 0.1).is_none());
        }
    }
}
