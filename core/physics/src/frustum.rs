//! Front-space containment, the paper's way: each eye sees the scene through the screen as
//! through a window, so what stands in front of the glass must stay inside the pyramid from the
//! eye to the screen's four edges — or the window's frame cuts it in that eye's image, the
//! depth cue the stereo pair then contradicts. The paper deforms a pyramid mesh (the screen as
//! base, the eye as tip, the base face removed) to match the frustum and lets the physics keep
//! the objects inside it; here each side of the pyramid is a plane through the eye and one screen
//! edge, one [`EyePlane`] per side and eye, eight in all.
//!
//! The planes matter only in front of the glass: behind it, what the window's frame hides is
//! simply behind a window (and for an eye low over the glass a plane cuts deep into the tray
//! there, so it must not act). The physics therefore gets each side as a finite slab standing on
//! the glass ([`side_prism`]): the pyramid's side face from the screen's edge to the eye,
//! thickened outwards without ever reaching below the glass.

use glam::Vec3;
use phantogram_geometry::screen::Screen;

/// A plane of an eye's pyramid: points `p` with `normal · p ≥ offset_m` are inside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EyePlane {
    /// Unit normal, pointing into the pyramid.
    pub normal: Vec3,
    pub offset_m: f32,
}

impl EyePlane {
    /// Signed distance of `p` from the plane, positive inside.
    pub fn distance_m(&self, p: Vec3) -> f32 {
        self.normal.dot(p) - self.offset_m
    }

    /// A point on the plane (the one nearest the origin).
    pub fn point_m(&self) -> Vec3 {
        self.normal * self.offset_m
    }
}

/// The four sides of the pyramid from `eye_m` through the screen's edges (lower, right, upper,
/// left), normals inward. `None` when the eye is not in front of the glass (no window to look
/// through) or not finite.
pub fn eye_pyramid(screen: &Screen, eye_m: Vec3) -> Option<[EyePlane; 4]> {
    if !eye_m.is_finite() || eye_m.z <= 1e-3 {
        return None;
    }
    let c = screen.corners();
    let lower_left = c.lower_left;
    let lower_right = c.lower_right;
    let upper_left = c.upper_left;
    let upper_right = lower_right + (upper_left - lower_left);
    let centre = (lower_left + upper_right) * 0.5;
    let side = |a: Vec3, b: Vec3| -> Option<EyePlane> {
        let mut normal = (b - a).cross(eye_m - a).try_normalize()?;
        if normal.dot(centre - a) < 0.0 {
            normal = -normal;
        }
        Some(EyePlane {
            normal,
            offset_m: normal.dot(a),
        })
    };
    Some([
        side(lower_left, lower_right)?,
        side(lower_right, upper_right)?,
        side(upper_right, upper_left)?,
        side(upper_left, lower_left)?,
    ])
}

/// Both eyes' pyramids: eight planes, the left eye's first.
pub fn stereo_pyramids(screen: &Screen, eyes_m: [Vec3; 2]) -> Option<[EyePlane; 8]> {
    let l = eye_pyramid(screen, eyes_m[0])?;
    let r = eye_pyramid(screen, eyes_m[1])?;
    Some([l[0], l[1], l[2], l[3], r[0], r[1], r[2], r[3]])
}

/// The collider of one pyramid side: the face from the screen's edge `a`–`b` (on the glass) to
/// the eye, thickened by `thickness_m` away from the pyramid but never below the glass, as six
/// points whose convex hull is the slab. The edge is lengthened by `overlap_m` at both ends so
/// that neighbouring sides leave no gap at the corners. `None` for a degenerate face.
pub fn side_prism(
    plane: &EyePlane,
    a: Vec3,
    b: Vec3,
    eye_m: Vec3,
    thickness_m: f32,
    overlap_m: f32,
) -> Option<[Vec3; 6]> {
    let along = (b - a).try_normalize()?;
    let (a, b) = (a - along * overlap_m, b + along * overlap_m);
    // Outwards, but level or upwards: a slab that dipped below the glass would cut into the tray.
    let out = -plane.normal;
    let out = Vec3::new(out.x, out.y, out.z.max(0.0)).try_normalize()?;
    if out.dot(plane.normal) >= 0.0 {
        return None;
    }
    let d = out * thickness_m;
    Some([a, b, eye_m, a + d, b + d, eye_m + d])
}

/// The four edges of the screen on the glass, in [`eye_pyramid`]'s order (lower, right, upper,
/// left), each as its two ends.
pub fn screen_edges(screen: &Screen) -> [(Vec3, Vec3); 4] {
    let c = screen.corners();
    let upper_right = c.lower_right + (c.upper_left - c.lower_left);
    [
        (c.lower_left, c.lower_right),
        (c.lower_right, upper_right),
        (upper_right, c.upper_left),
        (c.upper_left, c.lower_left),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use phantogram_geometry::projection::{DepthRange, OffAxisProjection};

    #[test]
    fn inside_the_pyramid_is_inside_the_eyes_image() {
        let screen = Screen::default();
        let eye = Vec3::new(0.02, -0.05, 0.3);
        let planes = eye_pyramid(&screen, eye).unwrap();
        let proj = OffAxisProjection::new(&screen, eye, DepthRange::default()).unwrap();
        // Points in front of the glass: inside all four planes ⇔ projected inside the screen.
        let mut checked = 0;
        for i in 0..20 {
            for j in 0..20 {
                for k in 1..6 {
                    let p = Vec3::new((i as f32 - 9.5) * 0.005, (j as f32 - 9.5) * 0.01, k as f32 * 0.02);
                    let inside = planes.iter().all(|pl| pl.distance_m(p) >= 0.0);
                    let ndc = proj.project(p).unwrap().ndc;
                    let on_screen = ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0;
                    // Exactly on an edge either may round either way.
                    let margin = planes.iter().map(|pl| pl.distance_m(p).abs()).fold(f32::MAX, f32::min);
                    if margin > 1e-5 {
                        assert_eq!(inside, on_screen, "{p}: {ndc}");
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked > 1500);
        // The eye itself is on every plane; the screen's centre inside all.
        for pl in planes {
            assert!(pl.distance_m(eye).abs() < 1e-6);
            assert!(pl.distance_m(Vec3::ZERO) > 0.0);
            assert!((pl.point_m().dot(pl.normal) - pl.offset_m).abs() < 1e-6);
        }
        assert!(eye_pyramid(&screen, Vec3::new(0.0, 0.0, -0.1)).is_none());
        assert!(eye_pyramid(&screen, Vec3::NAN).is_none());
    }

    #[test]
    fn side_slabs_stand_on_the_glass_outside_the_pyramid() {
        let screen = Screen::default();
        // An eye low over the glass, far to the right: its planes cut into the tray behind the
        // glass, the slabs must not.
        for eye in [Vec3::new(0.0, -0.05, 0.3), Vec3::new(0.3, 0.0, 0.05)] {
            let planes = eye_pyramid(&screen, eye).unwrap();
            for (plane, (a, b)) in planes.iter().zip(screen_edges(&screen)) {
                let points = side_prism(plane, a, b, eye, 0.05, 0.02).unwrap();
                for p in points {
                    assert!(p.z >= -1e-6, "below the glass: {p}");
                    assert!(plane.distance_m(p) <= 1e-5, "inside the pyramid: {p}");
                }
                // The face itself lies on the plane.
                for p in &points[..3] {
                    assert!(plane.distance_m(*p).abs() < 1e-5);
                }
            }
        }
    }
}
