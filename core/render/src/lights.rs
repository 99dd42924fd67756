//! The lights the renderer draws with: the world-fixed directional light ([`Lighting`]) and the
//! placed [`Lamp`], each with the view its shadow map is rendered from.

use crate::SHADOW_SIZE;
use glam::{Mat4, Vec3};

/// A lamp in place of the directional light: a point light, or a spot light with a cone, in
/// mesh coordinates (the device frame, metres), with its shadows from a perspective shadow map,
/// or from a cube of them when it stands among what it shadows ([`point_shadow`](crate::point_shadow)).
/// The engine places it each frame (held like a torch, or fixed in the room, or where a finger
/// put it); see `phantogram::lamp`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lamp {
    pub position_m: Vec3,
    /// The cone's axis (any length; normalised here). Unused by a point light.
    pub axis: Vec3,
    /// Half-angle of the cone, radians (a spot light), up to just under 90°; `None`: a point
    /// light shining every way.
    pub cone_half_angle_rad: Option<f32>,
    /// Radiant intensity, linear RGB per steradian: the irradiance at 1 m head-on.
    pub intensity_rgb: Vec3,
}

impl Lamp {
    /// The uniform's three rows (see `EyeUniform::lamp`); zero (off) for `None` or a lamp with
    /// non-finite numbers.
    pub(crate) fn uniform(lamp: Option<&Lamp>) -> [[f32; 4]; 3] {
        let Some(l) = lamp.filter(|l| l.is_finite()) else {
            return [[0.0; 4]; 3];
        };
        let axis = l.axis.normalize_or(-Vec3::Z);
        let (cos_outer, cos_inner) = match l.cone_half_angle_rad {
            // The last tenth of the cone fades (a soft edge, as a real spot has).
            Some(a) => {
                let a = a.clamp(0.01, 1.55);
                (a.cos(), (a * 0.9).cos())
            }
            None => (-2.0, -1.0),
        };
        [
            l.position_m.extend(1.0).to_array(),
            axis.extend(cos_outer).to_array(),
            l.intensity_rgb.max(Vec3::ZERO).extend(cos_inner).to_array(),
        ]
    }

    /// Whether every number is finite (a lamp that is not shines nowhere: off).
    pub(crate) fn is_finite(&self) -> bool {
        self.position_m.is_finite()
            && self.axis.is_finite()
            && self.intensity_rgb.is_finite()
            && self.cone_half_angle_rad.is_none_or(f32::is_finite)
    }

    /// Direction towards the lamp from `point`, for choosing what casts shadows.
    pub(crate) fn toward_from(&self, point: Vec3) -> Vec3 {
        (self.position_m - point).normalize_or(Vec3::Z)
    }
}

/// The perspective shadow view of a lamp over `bounds` (mesh coordinates) and the size of a
/// texel at the bounds' centre in metres; `None` when the lamp is within the bounds' sphere (no
/// single view sees all it shadows: the renderer then draws a cube of views, [`point_shadow`](crate::point_shadow)).
pub fn lamp_view_proj(bounds: &phantogram_geometry::containment::Aabb, lamp: &Lamp) -> Option<(Mat4, f32)> {
    let centre = (bounds.min + bounds.max) * 0.5;
    let radius = (bounds.max - bounds.min).length() * 0.5 + 1e-4;
    let to_centre = centre - lamp.position_m;
    let distance = to_centre.length();
    if !distance.is_finite() || distance <= radius * 1.05 {
        return None;
    }
    let forward = to_centre / distance;
    let up = if forward.z.abs() < 0.9 { Vec3::Z } else { Vec3::Y };
    let view = Mat4::look_at_rh(lamp.position_m, centre, up);
    // The cone that holds the bounds' sphere, with a margin of a few texels.
    let half = (radius / distance).asin() * (1.0 + 4.0 / SHADOW_SIZE as f32);
    let near = (distance - radius).max(1e-3);
    let proj = Mat4::perspective_rh(2.0 * half, 1.0, near, distance + radius);
    let texel = 2.0 * distance * half.tan() / SHADOW_SIZE as f32;
    Some((proj * view, texel))
}

/// Lighting shared by both eyes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lighting {
    /// Radiance of the directional light, linear RGB.
    pub light_rgb: Vec3,
    /// Angular radius of the directional light's source, radians: 0 for a point at infinity
    /// (the default key light), a room's sun's ([`phantogram_assets::ibl::sun`]) otherwise. Its
    /// highlights widen by it, and its shadows soften over the penumbra the source's width gives
    /// (`scene.wgsl`'s `soft_shadow`; the shadow map's view widens to hold it,
    /// [`light_view_proj`]); a lamp is a point whatever this says.
    pub light_angular_radius_rad: f32,
    /// Scale of the environment's light ([`phantogram_assets::ibl`]).
    pub environment_intensity: f32,
    /// Linear exposure multiplier before tone mapping.
    pub exposure: f32,
    /// Shadows from the directional light (one shadow map per frame, shared by both eyes).
    pub shadows: bool,
}

impl Default for Lighting {
    fn default() -> Self {
        Self {
            light_rgb: Vec3::new(3.2, 3.05, 2.85),
            light_angular_radius_rad: 0.0,
            environment_intensity: 1.0,
            exposure: 1.0,
            shadows: true,
        }
    }
}

/// The orthographic light view over `bounds` (mesh coordinates) and its texel size in metres,
/// for a light `angular_radius_rad` in radius (0: sharp shadows).
///
/// A light with a width shadows receivers beside the casters' outline too, by as far as its
/// penumbra reaches (`scene.wgsl`'s `soft_shadow`), so the view widens by that: the distance
/// along the light from a blocker to a receiver, at most the casters' depth along it or, for the
/// floor at their base, their height over the light's elevation (taken as at least 0.1), times
/// tan β; at most the casters' radius, which halves the map's resolution at worst (a source
/// several degrees across, low over the horizon). A sun's half a degree widens it by under 1 %.
pub fn light_view_proj(
    bounds: &phantogram_geometry::containment::Aabb,
    toward_light: Vec3,
    angular_radius_rad: f32,
) -> (Mat4, f32) {
    let l = toward_light.normalize_or(Vec3::Z);
    let centre = (bounds.min + bounds.max) * 0.5;
    let radius = (bounds.max - bounds.min).length() * 0.5 + 1e-4;
    let up = if l.z.abs() < 0.9 { Vec3::Z } else { Vec3::Y };
    let view = Mat4::look_at_rh(centre + l * (2.0 * radius), centre, up);
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for c in bounds.corners() {
        let p = view.transform_point3(c);
        lo = lo.min(p);
        hi = hi.max(p);
    }
    // Two texels of margin on every side so PCF taps at the edge stay inside, and the penumbra's
    // reach.
    let margin = (hi.x - lo.x).max(hi.y - lo.y) / SHADOW_SIZE as f32 * 2.0
        + penumbra_reach_m(bounds, l, radius, angular_radius_rad);
    let proj = Mat4::orthographic_rh(
        lo.x - margin,
        hi.x + margin,
        lo.y - margin,
        hi.y + margin,
        -hi.z - margin,
        -lo.z + margin,
    );
    let texel = ((hi.x - lo.x).max(hi.y - lo.y) + 2.0 * margin) / SHADOW_SIZE as f32;
    (proj * view, texel)
}

/// How far beyond the casters' outline a light `beta_rad` in radius shadows (m), for
/// [`light_view_proj`]: casters within `bounds` (of half-diagonal `radius`), lit along `l`.
fn penumbra_reach_m(bounds: &phantogram_geometry::containment::Aabb, l: Vec3, radius: f32, beta_rad: f32) -> f32 {
    if beta_rad.is_nan() || beta_rad <= 0.0 {
        return 0.0;
    }
    let height = bounds.max.z - bounds.min.z;
    let along = (2.0 * radius).max(height / l.z.abs().max(0.1));
    (along * beta_rad.min(1.5).tan()).min(radius)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wide_lights_view_widens_by_its_penumbras_reach() {
        // Casters 60 mm across and 20 mm tall, lit from 60° up: a point-like light's view is
        // the casters' outline and two texels; a light 0.05 rad in radius widens it on each side
        // by 2 × the half-diagonal × tan 0.05 (the casters' depth along the light outreaches
        // their height over the elevation here), and no source widens it beyond the
        // half-diagonal.
        let bounds =
            phantogram_geometry::containment::Aabb::new(Vec3::new(-0.03, -0.03, -0.02), Vec3::new(0.03, 0.03, 0.0));
        let toward = Vec3::new(0.0, -60f32.to_radians().cos(), 60f32.to_radians().sin());
        let width = |beta: f32| {
            let (m, _) = light_view_proj(&bounds, toward, beta);
            // The view's width across x (world x is the view's x here: the light has none).
            2.0 / m.x_axis.x.abs()
        };
        let sharp = width(0.0);
        let radius = (bounds.max - bounds.min).length() * 0.5 + 1e-4;
        // Two texels of margin each side of the outline: the view is (1 + 4 / SHADOW_SIZE) of it.
        let outline = sharp / (1.0 + 4.0 / SHADOW_SIZE as f32);
        assert!((outline - 0.06).abs() < 1e-4, "outline {outline}");
        let wide = width(0.05);
        let expected = 2.0 * 2.0 * radius * 0.05f32.tan();
        assert!(
            ((wide - sharp) / expected - 1.0).abs() < 1e-3,
            "widened by {} against {expected}",
            wide - sharp
        );
        let widest = width(1.4);
        assert!(((widest - sharp) / (2.0 * radius) - 1.0).abs() < 1e-3, "{widest}");
        assert_eq!(width(f32::NAN), sharp);
    }

    #[test]
    fn a_lamps_shadow_view_holds_what_it_shadows() {
        let bounds =
            phantogram_geometry::containment::Aabb::new(Vec3::new(-0.02, -0.03, -0.01), Vec3::new(0.02, 0.03, 0.01));
        let lamp = Lamp {
            position_m: Vec3::new(-0.06, 0.0, 0.02),
            axis: Vec3::X,
            cone_half_angle_rad: Some(1.0),
            intensity_rgb: Vec3::ONE,
        };
        let (m, texel) = lamp_view_proj(&bounds, &lamp).expect("outside the bounds");
        assert!(texel > 0.0 && texel < 1e-3, "{texel}");
        for c in bounds.corners() {
            let p = m.project_point3(c);
            assert!(
                p.x.abs() <= 1.0 && p.y.abs() <= 1.0 && (0.0..=1.0).contains(&p.z),
                "{c} → {p}"
            );
        }
        // Inside what it would shadow: no single view, no shadows.
        let inside = Lamp {
            position_m: Vec3::ZERO,
            ..lamp
        };
        assert!(lamp_view_proj(&bounds, &inside).is_none());
        // Off or broken: the uniform says off.
        assert_eq!(Lamp::uniform(None)[0][3], 0.0);
        let broken = Lamp {
            position_m: Vec3::NAN,
            ..lamp
        };
        assert_eq!(Lamp::uniform(Some(&broken))[0][3], 0.0);
        let point = Lamp {
            cone_half_angle_rad: None,
            ..lamp
        };
        assert_eq!(Lamp::uniform(Some(&point))[1][3], -2.0, "a point light has no cone");
    }
}
