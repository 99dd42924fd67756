//! The directional albedo of stretched lobes, for the image light of an anisotropic material:
//! GGX stretched along a surface direction (`KHR_materials_anisotropy`, brushed metal in glTF) and
//! the anisotropic Ward lobe (the visitor's materials). `scene.wgsl` scales the prefiltered
//! environment by the lobe's albedo towards the view and takes from it the light that leaves after
//! further bounces and what the layer below receives; a lamp's light uses the same albedo for
//! those. The round lobes' tables ([`super::brdf_lut`], [`super::ward_albedo`]) have no axis for
//! how long the lobe is nor for where the view looks along it, so an anisotropic lobe read them at
//! one roughness: GGX at its smaller one (as Khronos's glTF Sample Viewer does), up to twice what
//! the lobe itself sends back (strength 1 seen face on: 1.0 against the lobe's 0.54), and Ward at
//! the round lobe of the same mean square slope, up to 26 % off seen along an axis at n·v 0.1
//! (`benchmarks/ibl.md`).
//!
//! The table: [`TILES`] × [`TILES`] tiles of [`TILE`] × [`TILE`] entries, laid out below the
//! round lobes' table in the same texture (`scene.wgsl`'s `anisotropic_albedo` reads it). Tile
//! (c, r) holds lobes whose short roughness is `r / (TILES − 1)` of their long one, seen from the
//! azimuth `c / (TILES − 1)` of a quarter turn from the long axis; within it, column i is n·v
//! [`super::table_axis`]`(i, TILE)`, row j the long roughness α = `table_axis(j, TILE)²` (held at
//! the lobe's sharpest). Each entry holds the stretched GGX lobe's split sum, F0·a + F90·b
//! (Schlick's Fresnel, height-correlated Smith masking: `scene.wgsl`'s `ggx_anisotropic` and
//! `smith_visibility_anisotropic`), and the Ward lobe's albedo. Between tiles the reader
//! interpolates linearly, within a tile bilinearly (the texture's filter): [`read`] is the CPU
//! twin of the shader's read. The azimuth axis is the angle itself, not its squared cosine: near
//! grazing the albedo turns with it fast along the long axis, and the angle's nodes halved the
//! worst error there (7.5 → 4.7 % for GGX, 10 → 4.6 % for Ward, below n·v 0.15).
//!
//! Pure functions; rows on every core ([`crate::parallel::map`]); no panics.

use glam::Vec3;

use crate::ward::WardLobe;

/// Entries along each axis of a tile (n·v and the long roughness).
pub const TILE: usize = 16;
/// Tiles along each of the two other axes (the view's azimuth and the lobe's ratio of
/// roughnesses).
pub const TILES: usize = 4;
/// The table's width and height in entries.
pub const SIDE: usize = TILE * TILES;
/// GGX's sharpest lobe the table holds (the renderer's least roughness, 0.045, squared).
pub const GGX_LEAST_ALPHA: f32 = 0.045 * 0.045;
/// Stratified samples per entry for GGX, as a side of their grid (its visible normals, whose
/// weights are at most 1).
pub const GGX_GRID: usize = 16;
/// The same for Ward (its own sampling): the table read between its nodes comes as close to fine
/// integrals with 12 × 12 as with 16 × 16 (2.5 % and 2.7 % at worst above n·v 0.15, 1000 lobes),
/// at half the cost.
pub const WARD_GRID: usize = 12;

/// One entry: the stretched GGX lobe's split sum (F0 scale, F90 scale) and the Ward lobe's
/// albedo.
pub type Entry = [f32; 3];

/// The table, `SIDE × SIDE` entries, row by row (see the module docs for the layout).
pub fn anisotropic_albedo_table() -> Vec<Entry> {
    let rows: Vec<usize> = (0..SIDE).collect();
    crate::parallel::map(&rows, |&y| {
        let (tile_row, j) = (y / TILE, y % TILE);
        (0..SIDE)
            .map(|x| {
                let (tile_col, i) = (x / TILE, x % TILE);
                let node = Node {
                    n_dot_v: super::table_axis(i, TILE),
                    long_y: super::table_axis(j, TILE),
                    ratio: super::table_axis(tile_row, TILES),
                    azimuth_rad: super::table_axis(tile_col, TILES) * std::f32::consts::FRAC_PI_2,
                };
                node.entry()
            })
            .collect::<Vec<_>>()
    })
    .concat()
}

/// Where an entry stands.
#[derive(Clone, Copy, Debug)]
struct Node {
    n_dot_v: f32,
    /// √ of the long roughness α.
    long_y: f32,
    /// The short roughness over the long one.
    ratio: f32,
    /// The view's azimuth from the long axis, 0 to π/2.
    azimuth_rad: f32,
}

impl Node {
    fn view(&self) -> Vec3 {
        view_at(self.n_dot_v.max(1e-3), self.azimuth_rad)
    }

    fn entry(&self) -> Entry {
        let v = self.view();
        let long = (self.long_y * self.long_y).max(GGX_LEAST_ALPHA);
        let [a, b] = ggx_split_sum(v, long, (long * self.ratio).max(GGX_LEAST_ALPHA), GGX_GRID);
        let ward_long = (self.long_y * self.long_y).max(*crate::ward::ALPHA_RANGE.start());
        let ward = WardLobe::new(ward_long, ward_long * self.ratio).directional_albedo(v, WARD_GRID);
        [a, b, ward]
    }
}

/// The unit view at `n_dot_v` and `azimuth_rad` from +x (surface frame, +z the normal).
pub fn view_at(n_dot_v: f32, azimuth_rad: f32) -> Vec3 {
    let s = (1.0 - n_dot_v * n_dot_v).max(0.0).sqrt();
    Vec3::new(s * azimuth_rad.cos(), s * azimuth_rad.sin(), n_dot_v)
}

/// Smith's Λ of the GGX lobe (αx, αy) for the direction `w` (unit, surface frame, above it).
pub(crate) fn smith_lambda(w: Vec3, alpha_x: f32, alpha_y: f32) -> f32 {
    let (x, y) = (alpha_x * w.x, alpha_y * w.y);
    let z2 = (w.z * w.z).max(1e-12);
    0.5 * ((1.0 + (x * x + y * y) / z2).sqrt() - 1.0)
}

/// A visible normal of the GGX lobe (αx, αy) seen from `v` for the uniforms (u1, u2) (Heitz,
/// "Sampling the GGX Distribution of Visible Normals", JCGT 2018).
pub(crate) fn visible_normal(v: Vec3, alpha_x: f32, alpha_y: f32, u1: f32, u2: f32) -> Vec3 {
    let vh = Vec3::new(alpha_x * v.x, alpha_y * v.y, v.z).normalize();
    let len2 = vh.x * vh.x + vh.y * vh.y;
    let t1 = if len2 > 0.0 {
        Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt()
    } else {
        Vec3::X
    };
    let t2 = vh.cross(t1);
    let r = u1.sqrt();
    let phi = std::f32::consts::TAU * u2;
    let p1 = r * phi.cos();
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
    let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    Vec3::new(alpha_x * nh.x, alpha_y * nh.y, nh.z.max(1e-6)).normalize()
}

/// The stretched GGX lobe's (αx along +x, αy along +y) directional albedo towards `v` (unit,
/// surface frame) as a split sum: F0·a + F90·b with Schlick's Fresnel, height-correlated Smith
/// masking, single bounce. Its visible normals on a `grid × grid` stratified set of uniforms:
/// each sample's weight is G2 / G1(v), at most 1.
pub fn ggx_split_sum(v: Vec3, alpha_x: f32, alpha_y: f32, grid: usize) -> [f32; 2] {
    if v.z <= 0.0 || grid == 0 {
        return [0.0, 0.0];
    }
    let lambda_v = smith_lambda(v, alpha_x, alpha_y);
    let (mut a, mut b) = (0.0f64, 0.0f64);
    for i in 0..grid {
        for j in 0..grid {
            let (u1, u2) = ((i as f32 + 0.5) / grid as f32, (j as f32 + 0.5) / grid as f32);
            let h = visible_normal(v, alpha_x, alpha_y, u1, u2);
            let v_dot_h = v.dot(h).max(0.0);
            let l = h * 2.0 * v_dot_h - v;
            if l.z <= 0.0 {
                continue;
            }
            let weight = (1.0 + lambda_v) / (1.0 + lambda_v + smith_lambda(l, alpha_x, alpha_y));
            let fc = (1.0 - v_dot_h).powi(5);
            a += f64::from((1.0 - fc) * weight);
            b += f64::from(fc * weight);
        }
    }
    let n = (grid * grid) as f64;
    [(a / n) as f32, (b / n) as f32]
}

/// The table read as `scene.wgsl`'s `anisotropic_albedo` reads it: a lobe of long roughness
/// `alpha_long` and short `alpha_short` seen at `n_dot_v` and `azimuth_rad` from the long axis
/// (any quadrant); bilinear within tiles, linear between them. `table` as
/// [`anisotropic_albedo_table`] makes it (a shorter one reads as zeros).
pub fn read(table: &[Entry], n_dot_v: f32, alpha_long: f32, alpha_short: f32, azimuth_rad: f32) -> Entry {
    let ratio = if alpha_long > 0.0 {
        (alpha_short / alpha_long).clamp(0.0, 1.0)
    } else {
        1.0
    };
    let across = |f: f32| {
        let scaled = f.clamp(0.0, 1.0) * (TILES - 1) as f32;
        let first = (scaled.floor() as usize).min(TILES - 2);
        (first, scaled - first as f32)
    };
    // The azimuth folded into the first quadrant: the lobes are symmetric about both axes.
    let folded = azimuth_rad.sin().abs().atan2(azimuth_rad.cos().abs());
    let ((c0, tc), (r0, tr)) = (across(folded / std::f32::consts::FRAC_PI_2), across(ratio));
    let at = [n_dot_v, alpha_long.max(0.0).sqrt()];
    let in_tile = |col: usize, row: usize| super::table_bilinear(table, SIDE, (col * TILE, row * TILE), TILE, at);
    let mix = |a: Entry, b: Entry, t: f32| [0, 1, 2].map(|k| a[k] + (b[k] - a[k]) * t);
    mix(
        mix(in_tile(c0, r0), in_tile(c0 + 1, r0), tc),
        mix(in_tile(c0, r0 + 1), in_tile(c0 + 1, r0 + 1), tc),
        tr,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reproducible stream of uniforms in [0, 1] (xorshift).
    fn uniforms(mut seed: u32) -> impl FnMut() -> f32 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed as f32 / u32::MAX as f32
        }
    }

    /// The stretched GGX lobe's single-bounce albedo (F = 1) by plain quadrature over the
    /// hemisphere of light directions: D·G2/(4 n·l n·v)·n·l, nothing shared with the sampling of
    /// visible normals but the formulas `scene.wgsl` uses.
    fn quadrature(v: Vec3, alpha_x: f32, alpha_y: f32, steps: usize) -> f64 {
        let mut sum = 0.0f64;
        // θ as sin²θ = 1 − u² would crowd the lobe's peak; a sharp lobe needs fine steps near
        // the mirror direction, so the steps run in u = cos θ, and φ uniformly.
        for i in 0..steps {
            let cos_t = (i as f64 + 0.5) / steps as f64;
            let sin_t = (1.0 - cos_t * cos_t).sqrt();
            for k in 0..4 * steps {
                let phi = std::f64::consts::TAU * (k as f64 + 0.5) / (4 * steps) as f64;
                let l = Vec3::new((sin_t * phi.cos()) as f32, (sin_t * phi.sin()) as f32, cos_t as f32);
                let h = (l + v).normalize();
                let d = {
                    let f = Vec3::new(alpha_y * h.x, alpha_x * h.y, alpha_x * alpha_y * h.z);
                    let a2 = alpha_x * alpha_y;
                    let w2 = a2 / f.length_squared().max(1e-12);
                    f64::from(a2 * w2 * w2 / std::f32::consts::PI)
                };
                let g2 = 1.0 / (1.0 + smith_lambda(v, alpha_x, alpha_y) + smith_lambda(l, alpha_x, alpha_y));
                let brdf = d * f64::from(g2) / (4.0 * f64::from(l.z) * f64::from(v.z));
                // dω = d(cos θ) dφ.
                sum += brdf * f64::from(l.z) * (1.0 / steps as f64) * (std::f64::consts::TAU / (4 * steps) as f64);
            }
        }
        sum
    }

    #[test]
    fn the_visible_normals_sum_what_the_hemisphere_integral_does() {
        // Rough enough lobes for the plain quadrature to resolve; the sampling itself does not
        // depend on how sharp the lobe is.
        for (ax, ay, n_dot_v, az) in [
            (0.5f32, 0.5f32, 0.7f32, 0.0f32),
            (0.8, 0.2, 0.5, 0.3),
            (0.3, 0.9, 0.3, 1.2),
            (1.0, 0.4, 0.9, 2.0),
        ] {
            let v = view_at(n_dot_v, az);
            let [a, b] = ggx_split_sum(v, ax, ay, 64);
            let direct = quadrature(v, ax, ay, 400);
            assert!(
                (f64::from(a + b) / direct - 1.0).abs() < 0.01,
                "αx {ax}, αy {ay}, n·v {n_dot_v}: visible normals {}, quadrature {direct}",
                a + b
            );
        }
    }

    #[test]
    fn a_round_lobe_is_what_the_split_sum_table_holds() {
        // The round lobes' table samples half vectors by GGX's own density (Hammersley): an
        // independent integral of the same lobe.
        let size = 16;
        let round = super::super::brdf_lut(size);
        for (i, j) in [(3usize, 4usize), (8, 8), (12, 14), (15, 10), (5, 15)] {
            let (n_dot_v, roughness) = (super::super::table_axis(i, size), super::super::table_axis(j, size));
            let alpha = (roughness * roughness).max(GGX_LEAST_ALPHA);
            let [a, b] = ggx_split_sum(view_at(n_dot_v, 0.4), alpha, alpha, 64);
            let [ra, rb] = round[j * size + i];
            assert!(
                (a - ra).abs() < 0.01 && (b - rb).abs() < 0.01,
                "n·v {n_dot_v}, roughness {roughness}: ({a}, {b}) against the round table's ({ra}, {rb})"
            );
        }
    }

    #[test]
    fn every_entry_is_an_albedo() {
        let table = anisotropic_albedo_table();
        assert_eq!(table.len(), SIDE * SIDE);
        for [a, b, ward] in table {
            // The split sum's parts are reflectances; Ward's normalisation bounds its albedo by 1
            // (`ward` module), the stratified sum lands within a little of it.
            assert!(a >= 0.0 && b >= 0.0 && a + b <= 1.0 + 1e-3, "{a} {b}");
            assert!((0.0..=1.0 + 5e-3).contains(&ward), "{ward}");
        }
    }

    #[test]
    fn the_table_between_its_nodes_is_the_lobes_own_albedo() {
        // 1000 lobes drawn at random (n·v, long roughness, ratio, azimuth in any quadrant), the
        // read against integrals on a fine grid. Measured: above n·v 0.15 within 2.5 % (GGX and
        // Ward alike), below within 6.6 %; the reads this table replaced, GGX at its short
        // roughness and Ward at the round lobe of the same mean square slope, were off by up to
        // 82 % and 10 % above n·v 0.15 (300 lobes).
        let table = anisotropic_albedo_table();
        let mut next = uniforms(12345);
        let mut worst = [[0.0f32; 2]; 2];
        for _ in 0..1000 {
            let n_dot_v = 0.05 + 0.95 * next();
            let long_y = 0.2 + 0.8 * next();
            let (along, ratio) = (long_y * long_y, next());
            let short = along * ratio;
            let azimuth = std::f32::consts::TAU * next();
            let v = view_at(n_dot_v, azimuth);
            let [a, b] = ggx_split_sum(v, along.max(GGX_LEAST_ALPHA), short.max(GGX_LEAST_ALPHA), 64);
            let ward = WardLobe::new(along, short).directional_albedo(v, 64);
            let r = read(&table, n_dot_v, along, short, azimuth);
            let grazing = usize::from(n_dot_v < 0.15);
            let off = [((r[0] + r[1]) / (a + b) - 1.0).abs(), (r[2] / ward - 1.0).abs()];
            for k in 0..2 {
                worst[grazing][k] = worst[grazing][k].max(off[k]);
            }
        }
        assert!(
            worst[0].iter().all(|&w| w < 0.03) && worst[1].iter().all(|&w| w < 0.08),
            "worst (GGX, Ward) above n·v 0.15 {:?}, below {:?}",
            worst[0],
            worst[1]
        );
    }

    #[test]
    fn a_round_ward_lobe_is_what_its_own_table_holds() {
        let size = 16;
        let round = super::super::ward_albedo_table(size);
        let table = anisotropic_albedo_table();
        for (i, j) in [(3usize, 6usize), (8, 10), (12, 15), (15, 12)] {
            let (n_dot_v, y) = (super::super::table_axis(i, size), super::super::table_axis(j, size));
            let (alpha, own) = (y * y, round[j * size + i]);
            let read = read(&table, n_dot_v, alpha, alpha, 0.7)[2];
            assert!(
                (read / own - 1.0).abs() < 0.02,
                "n·v {n_dot_v}, α {alpha}: {read} against {own}"
            );
        }
    }

    #[test]
    fn a_short_table_reads_as_zeros() {
        assert_eq!(read(&[], 0.5, 0.3, 0.1, 0.2), [0.0; 3]);
    }
}
