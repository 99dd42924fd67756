//! The points a laser scanner's file gave (LAS/LAZ: `las`; E57: `e57`), before they become a
//! [`Soup`]: positions in the file's own frame in double precision, each point's colour where the
//! file has one, and its intensity.
//!
//! * **Centre**: the positions are taken about the centre of their bounds before they become the
//!   `f32` a vertex holds, so that a georeferenced scan (hundreds of kilometres east) keeps its
//!   millimetres.
//! * **Colour**: the file's, where it has any that is not black throughout (a format with colour
//!   fields a writer never filled reads as all zeros); else each point's intensity as grey: a
//!   laser's return grows with the surface's reflectance, so the intensity over its 99th
//!   percentile is taken as the linear albedo (intensities have no fixed scale, and a few glints
//!   would otherwise darken the rest). Shown as raw codes instead, as some scanner software
//!   does, an aerial test scan's median return drew at a tenth of white: near black once lit.
//!   With neither, no colour (the caller's plain material).
//!
//! **Panics**: none.

use phantogram_geometry::srgb::from_linear;

use super::mesh_file::Soup;
use super::point_cloud::MAX_SURFELS;

/// The most points kept from one scanner's file: four times the discs a cloud may become, so
/// that `point_cloud::kept` still has room to thin them evenly in space.
pub const RAW_POINTS_KEPT: u64 = 4 * MAX_SURFELS as u64;

/// How a scanner's file that ends before its header says it does is named to the user.
pub const CUT_SHORT: &str = "the file is cut short (a download or copy that stopped early?)";

/// See the module docs.
#[derive(Debug, Default)]
pub struct ScanPoints {
    pub positions: Vec<[f64; 3]>,
    /// sRGB, 0–1, one a position where the file has colour; empty where it has none.
    pub colours: Vec<[f32; 3]>,
    /// One a position, on the file's own scale (at least 0); empty where it has none.
    pub intensities: Vec<f32>,
}

impl ScanPoints {
    /// `other`'s points after these (a file's scans or chunks, read apart, put in order).
    pub fn append(&mut self, mut other: ScanPoints) {
        self.positions.append(&mut other.positions);
        self.colours.append(&mut other.colours);
        self.intensities.append(&mut other.intensities);
    }

    /// The soup of these points (see the module docs): no normals, no triangles.
    pub fn into_soup(self) -> Soup {
        let (low, high) = self
            .positions
            .iter()
            .fold(([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]), |(lo, hi), p| {
                (
                    std::array::from_fn(|k| lo[k].min(p[k])),
                    std::array::from_fn(|k| hi[k].max(p[k])),
                )
            });
        let centre: [f64; 3] = std::array::from_fn(|k| (low[k] + high[k]) * 0.5);
        let n = self.positions.len();
        let coloured = self.colours.len() == n && self.colours.iter().any(|c| c.iter().any(|&v| v > 0.0));
        let colors = if coloured {
            Some(self.colours.iter().map(|&[r, g, b]| [r, g, b, 1.0]).collect())
        } else if self.intensities.len() == n {
            intensity_greys(&self.intensities)
        } else {
            None
        };
        Soup {
            positions: self
                .positions
                .iter()
                .map(|p| std::array::from_fn(|k| (p[k] - centre[k]) as f32))
                .collect(),
            normals: None,
            colors,
            indices: Vec::new(),
        }
    }
}

/// Grey (sRGB) from each intensity as linear albedo, the 99th percentile white; `None` where
/// none is above zero (or there are none).
fn intensity_greys(intensities: &[f32]) -> Option<Vec<[f32; 4]>> {
    let mut sorted: Vec<f32> = intensities.iter().map(|i| i.max(0.0)).collect();
    let at = sorted.len().checked_sub(1)?.min(sorted.len() * 99 / 100);
    let (_, &mut white, _) = sorted.select_nth_unstable_by(at, f32::total_cmp);
    let white = if white > 0.0 {
        white
    } else {
        intensities.iter().copied().fold(0.0, f32::max)
    };
    (white > 0.0).then(|| {
        intensities
            .iter()
            .map(|&i| {
                let g = from_linear((i / white).clamp(0.0, 1.0));
                [g, g, g, 1.0]
            })
            .collect()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn georeferenced_millimetres_survive_about_the_centre() {
        let soup = ScanPoints {
            positions: vec![[500_000.0, 4_000_000.0, 100.0], [500_000.001, 4_000_000.002, 101.0]],
            ..ScanPoints::default()
        }
        .into_soup();
        assert!((soup.positions[1][0] - soup.positions[0][0] - 0.001).abs() < 1e-6);
        assert!((soup.positions[0][2] + 0.5).abs() < 1e-6 && (soup.positions[1][2] - 0.5).abs() < 1e-6);
        assert!(soup.colors.is_none() && soup.normals.is_none() && soup.indices.is_empty());
    }

    #[test]
    fn colour_else_intensity_as_linear_albedo_else_none() {
        let positions = vec![[0.0; 3]; 202];
        let mut intensities = vec![1000.0; 200];
        intensities.push(60000.0); // a glint: it does not set white
        intensities.push(250.0); // a quarter of white
        let greys = ScanPoints {
            positions: positions.clone(),
            colours: vec![[0.0; 3]; 202], // fields never filled
            intensities: intensities.clone(),
        }
        .into_soup()
        .colors
        .expect("greys");
        assert!((greys[0][0] - 1.0).abs() < 1e-6 && (greys[200][0] - 1.0).abs() < 1e-6);
        assert!(
            (greys[201][0] - 0.537).abs() < 0.002,
            "linear 0.25 is sRGB 0.537: {:?}",
            greys[201]
        );
        let mut colours = vec![[0.0; 3]; 202];
        colours[5] = [0.5, 0.25, 0.0];
        let coloured = ScanPoints {
            positions: positions.clone(),
            colours,
            intensities,
        }
        .into_soup()
        .colors
        .expect("colours");
        assert_eq!(coloured[5], [0.5, 0.25, 0.0, 1.0]);
        let dark = ScanPoints {
            positions,
            colours: Vec::new(),
            intensities: vec![0.0; 202],
        };
        assert!(dark.into_soup().colors.is_none());
    }
}
