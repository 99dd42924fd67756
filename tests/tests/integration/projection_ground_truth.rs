//! Off-axis projection against ground truth: every point must land on the pixel where the ray from
//! the eye to it crosses the glass. The reference here is computed independently in f64 from the
//! panel's physical size and a table of display axes, not from the library's screen mapping.

use phantogram::eyes::EyeModel;
use phantogram::glam::{DVec2, DVec3, Vec3};
use phantogram::projection::{DepthRange, OffAxisProjection};
use phantogram::screen::{DisplayRotation, PanelSpec, Screen};
use phantogram::synthetic::Noise;

/// Display right and up in the device frame for each rotation (Android `Surface.ROTATION_*`: the
/// device turned counter-clockwise by the angle), as the crate docs define them.
fn display_axes(rotation: DisplayRotation) -> (DVec3, DVec3) {
    match rotation {
        DisplayRotation::Deg0 => (DVec3::X, DVec3::Y),
        DisplayRotation::Deg90 => (-DVec3::Y, DVec3::X),
        DisplayRotation::Deg180 => (-DVec3::X, -DVec3::Y),
        DisplayRotation::Deg270 => (DVec3::Y, -DVec3::X),
    }
}

/// Ground truth: pixel where the eye → point ray crosses the glass (z = 0).
fn reference_pixel(panel: PanelSpec, rotation: DisplayRotation, eye: DVec3, p: DVec3) -> DVec2 {
    let t = eye.z / (eye.z - p.z);
    let hit = eye + (p - eye) * t;
    let w_m = panel.width_px as f64 / panel.xdpi as f64 * 0.0254;
    let h_m = panel.height_px as f64 / panel.ydpi as f64 * 0.0254;
    let (right, up) = display_axes(rotation);
    let quarter = matches!(rotation, DisplayRotation::Deg90 | DisplayRotation::Deg270);
    let (disp_w_m, disp_h_m, disp_w_px, disp_h_px) = if quarter {
        (h_m, w_m, panel.height_px as f64, panel.width_px as f64)
    } else {
        (w_m, h_m, panel.width_px as f64, panel.height_px as f64)
    };
    DVec2::new(
        (hit.dot(right) / disp_w_m + 0.5) * disp_w_px,
        (0.5 - hit.dot(up) / disp_h_m) * disp_h_px,
    )
}

const ROTATIONS: [DisplayRotation; 4] = [
    DisplayRotation::Deg0,
    DisplayRotation::Deg90,
    DisplayRotation::Deg180,
    DisplayRotation::Deg270,
];

#[test]
fn every_point_lands_where_its_ray_crosses_the_glass() {
    let panels = [
        PanelSpec::TYPICAL_PHONE,
        // A landscape-native tablet with non-square pixels.
        PanelSpec {
            width_px: 2560,
            height_px: 1600,
            xdpi: 274.0,
            ydpi: 276.5,
        },
    ];
    let mut rng = Noise::new(2026);
    let mut max_err_px = 0.0f64;
    let mut checked = 0u32;
    for panel in panels {
        for rotation in ROTATIONS {
            let screen = Screen::new(panel, rotation).unwrap();
            for _ in 0..500 {
                // Eye 20–60 cm from the screen centre, up to 45° off the normal, any azimuth.
                let r = 0.2 + 0.4 * rng.uniform();
                let off = 45f64.to_radians() * rng.uniform();
                let az = std::f64::consts::TAU * rng.uniform();
                let cyclopean = DVec3::new(off.sin() * az.cos(), off.sin() * az.sin(), off.cos()) * r;
                let eyes = EyeModel::default().stereo_pair(&screen, cyclopean.as_vec3());
                for eye in [eyes.left_m, eyes.right_m] {
                    let proj = OffAxisProjection::new(&screen, eye, DepthRange::default()).unwrap();
                    let eye64 = eye.as_dvec3();
                    for _ in 0..20 {
                        // A point 15 cm behind to 6 cm in front of the glass, on a ray through a
                        // random spot of the glass (a margin beyond the edges included).
                        let u = -0.2 + 1.4 * rng.uniform();
                        let v = -0.2 + 1.4 * rng.uniform();
                        let half = screen.half_extent_device_m().as_dvec2();
                        let g = DVec3::new((2.0 * u - 1.0) * half.x, (2.0 * v - 1.0) * half.y, 0.0);
                        let z = -0.15 + 0.21 * rng.uniform();
                        let p = eye64 + (g - eye64) * ((eye64.z - z) / eye64.z);
                        let got = proj.project(p.as_vec3()).expect("in front of the eye");
                        let want = reference_pixel(panel, rotation, eye64, p);
                        let err = got.pixel.as_dvec2().distance(want);
                        max_err_px = max_err_px.max(err);
                        checked += 1;
                        assert!(
                            err <= 0.25,
                            "{rotation:?} eye {eye} point {p}: pixel {} vs {want} ({err} px)",
                            got.pixel
                        );
                        assert!(got.depth > 0.0 && got.depth < 1.0, "depth {} clipped", got.depth);
                    }
                }
            }
        }
    }
    println!("reprojection: {checked} eye/point pairs, max error {max_err_px:.4} px");
}

#[test]
fn protruding_point_is_not_clipped_and_sorts_in_front() {
    let screen = Screen::default();
    for cyclopean in [
        Vec3::new(0.03, -0.02, 0.3),
        Vec3::new(0.141, 0.0, 0.141),
        Vec3::new(0.0, 0.0, 0.2),
    ] {
        let eyes = EyeModel::default().stereo_pair(&screen, cyclopean);
        for eye in [eyes.left_m, eyes.right_m, eyes.cyclopean_m] {
            let proj = OffAxisProjection::new(&screen, eye, DepthRange::default()).unwrap();
            // A point 5 cm in front of the glass above a spot inside the screen, seen from this
            // eye, and a point 5 cm behind the glass on the same ray.
            let glass = Vec3::new(0.01, 0.02, 0.0);
            let dir = (glass - eye).normalize();
            let front = eye + dir * ((eye.z - 0.05) / -dir.z);
            let behind = eye + dir * ((eye.z + 0.05) / -dir.z);
            assert!((front.z - 0.05).abs() < 1e-5 && (behind.z + 0.05).abs() < 1e-5);
            let f = proj.project(front).unwrap();
            let b = proj.project(behind).unwrap();
            assert!(f.ndc.abs().max_element() <= 1.0, "front point outside the frustum");
            assert!(
                f.depth > 0.0 && f.depth <= 1.0,
                "front point clipped: depth {}",
                f.depth
            );
            assert!(b.depth > 0.0 && b.depth < 1.0);
            assert!(f.pixel.distance(b.pixel) < 1e-2, "same ray, same pixel");
            // Reverse-Z: greater depth is nearer.
            assert!(
                f.depth > b.depth,
                "front {} must sort before behind {}",
                f.depth,
                b.depth
            );
            // Precision at the glass: 0.1 mm apart along the ray still resolves in f32 depth.
            let near_glass = proj.project(eye + dir * ((eye.z - 0.0001) / -dir.z)).unwrap();
            let at_glass = proj.project(glass).unwrap();
            assert!(near_glass.depth > at_glass.depth);
        }
    }
}
