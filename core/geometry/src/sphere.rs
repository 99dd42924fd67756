//! Directions spread evenly over the unit sphere: a Fibonacci lattice (points on a spiral from
//! pole to pole, each turned by the golden angle from the last), whose points sit close to a
//! hexagonal lattice everywhere but at the poles. Used to bin view directions, to probe lighting
//! over every normal and to test point clouds.

use glam::Vec3;

/// `n` unit vectors spread evenly over the sphere, from near +z to near −z.
pub fn fibonacci(n: usize) -> Vec<Vec3> {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - (i as f32 + 0.5) * 2.0 / n as f32;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let a = golden * i as f32;
            Vec3::new(r * a.cos(), r * a.sin(), z)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_points_are_unit_length_and_spread_evenly() {
        let points = fibonacci(1000);
        assert!(points.iter().all(|p| (p.length() - 1.0).abs() < 1e-5));
        // Equal areas hold equal counts: each of the eight octants about an eighth.
        for octant in 0..8 {
            let sign = |bit: usize| if octant >> bit & 1 == 1 { 1.0 } else { -1.0 };
            let inside = points
                .iter()
                .filter(|p| p.x * sign(0) > 0.0 && p.y * sign(1) > 0.0 && p.z * sign(2) > 0.0)
                .count();
            assert!((110..=140).contains(&inside), "{inside} in octant {octant}");
        }
    }
}
