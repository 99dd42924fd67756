//! Anaglyph composition: each output pixel is `clamp(L·left + R·right)` with two 3×3 matrices
//! applied to the two eyes' colours **in linear light** (display-referred, after tone mapping,
//! before the sRGB transfer function). Least-squares methods are derived for linear RGB; applying
//! them to gamma-encoded values, as many implementations do, increases ghosting.
//!
//! Sources of the matrices:
//! * Dubois least-squares projection: E. Dubois, "Conversion of a stereo pair to anaglyph with
//!   the least-squares projection method", University of Ottawa, March 2009 (red–cyan), and the
//!   green–magenta and amber–blue matrices published with it on Dubois' site (LCD variants).
//!   A later LCD red–cyan set (0.456, 0.500, 0.176, …) also circulates; we use the paper's.
//! * Grey, colour, half-colour: the classic channel-selection anaglyphs (Rec. 601 luma).
//! * Optimized: P. Wimmer's "optimized anaglyph" (left red from 0.7·G + 0.3·B, avoiding the
//!   retinal rivalry of saturated reds).
//!
//! Rows are output channels (R, G, B); columns input channels.

use std::fmt;
use std::str::FromStr;

/// How the two eyes' images become one picture.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Method {
    /// Dubois least-squares red–cyan (the default: least ghosting with common glasses).
    #[default]
    DuboisRedCyan,
    DuboisGreenMagenta,
    DuboisAmberBlue,
    HalfColor,
    Optimized,
    Gray,
    /// Plain colour anaglyph: left red channel, right green and blue.
    Color,
    /// No stereo: the cyclopean eye's image, in full colour.
    Mono,
}

/// A row-major 3×3 matrix.
pub type Mat3x3 = [[f32; 3]; 3];

const Z: [f32; 3] = [0.0; 3];
const LUMA_601: [f32; 3] = [0.299, 0.587, 0.114];

impl Method {
    pub const ALL: [Method; 8] = [
        Method::DuboisRedCyan,
        Method::DuboisGreenMagenta,
        Method::DuboisAmberBlue,
        Method::HalfColor,
        Method::Optimized,
        Method::Gray,
        Method::Color,
        Method::Mono,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Method::DuboisRedCyan => "dubois",
            Method::DuboisGreenMagenta => "dubois-green-magenta",
            Method::DuboisAmberBlue => "dubois-amber-blue",
            Method::HalfColor => "half-color",
            Method::Optimized => "optimized",
            Method::Gray => "gray",
            Method::Color => "color",
            Method::Mono => "mono",
        }
    }

    pub fn is_stereo(self) -> bool {
        self != Method::Mono
    }

    /// `(left, right)` matrices. For [`Method::Mono`], identity and zero (the renderer draws the
    /// cyclopean view into the "left" input).
    pub fn matrices(self) -> (Mat3x3, Mat3x3) {
        match self {
            Method::DuboisRedCyan => (
                [
                    [0.437, 0.449, 0.164],
                    [-0.062, -0.062, -0.024],
                    [-0.048, -0.050, -0.017],
                ],
                [[-0.011, -0.032, -0.007], [0.377, 0.761, 0.009], [-0.026, -0.093, 1.234]],
            ),
            Method::DuboisGreenMagenta => (
                [[-0.062, -0.158, -0.039], [0.284, 0.668, 0.143], [-0.015, -0.027, 0.021]],
                [[0.529, 0.705, 0.024], [-0.016, -0.015, -0.065], [0.009, 0.075, 0.937]],
            ),
            Method::DuboisAmberBlue => (
                [[1.062, -0.205, 0.299], [-0.026, 0.908, 0.068], [-0.038, -0.173, 0.022]],
                [[-0.016, -0.123, -0.017], [0.006, 0.062, -0.017], [0.094, 0.185, 0.911]],
            ),
            Method::HalfColor => ([LUMA_601, Z, Z], [Z, [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
            Method::Optimized => ([[0.0, 0.7, 0.3], Z, Z], [Z, [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
            Method::Gray => ([LUMA_601, Z, Z], [Z, LUMA_601, LUMA_601]),
            Method::Color => ([[1.0, 0.0, 0.0], Z, Z], [Z, [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
            Method::Mono => ([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], [Z, Z, Z]),
        }
    }

    /// The reference composition of one pixel, linear RGB in and out (clamped to [0, 1]).
    pub fn compose(self, left: [f32; 3], right: [f32; 3]) -> [f32; 3] {
        let (l, r) = self.matrices();
        let mut out = [0.0; 3];
        for (c, o) in out.iter_mut().enumerate() {
            let v: f32 = (0..3).map(|k| l[c][k] * left[k] + r[c][k] * right[k]).sum();
            *o = v.clamp(0.0, 1.0);
        }
        out
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[derive(Debug, thiserror::Error, PartialEq)]
#[error(
    "unknown anaglyph method {0:?}; one of: dubois, dubois-green-magenta, dubois-amber-blue, half-color, optimized, gray, color, mono"
)]
pub struct UnknownMethod(pub String);

impl FromStr for Method {
    type Err = UnknownMethod;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let key = s.trim().to_ascii_lowercase().replace('_', "-");
        Method::ALL
            .into_iter()
            .find(|m| m.name() == key || (key == "red-cyan" && *m == Method::DuboisRedCyan))
            .ok_or_else(|| UnknownMethod(s.to_owned()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The published coefficients, typed in from the sources cited in the module docs, row by
    /// row: red–cyan from Dubois (2009), Table/eq. for the least-squares projection; green–magenta
    /// and amber–blue from the LCD matrices on Dubois' site.
    #[test]
    fn dubois_matrices_match_the_published_coefficients() {
        let published: [(Method, [f32; 18]); 3] = [
            (
                Method::DuboisRedCyan,
                [
                    0.437, 0.449, 0.164, -0.062, -0.062, -0.024, -0.048, -0.050, -0.017, //
                    -0.011, -0.032, -0.007, 0.377, 0.761, 0.009, -0.026, -0.093, 1.234,
                ],
            ),
            (
                Method::DuboisGreenMagenta,
                [
                    -0.062, -0.158, -0.039, 0.284, 0.668, 0.143, -0.015, -0.027, 0.021, //
                    0.529, 0.705, 0.024, -0.016, -0.015, -0.065, 0.009, 0.075, 0.937,
                ],
            ),
            (
                Method::DuboisAmberBlue,
                [
                    1.062, -0.205, 0.299, -0.026, 0.908, 0.068, -0.038, -0.173, 0.022, //
                    -0.016, -0.123, -0.017, 0.006, 0.062, -0.017, 0.094, 0.185, 0.911,
                ],
            ),
        ];
        for (method, coeffs) in published {
            let (l, r) = method.matrices();
            let ours: Vec<f32> = l.iter().chain(r.iter()).flatten().copied().collect();
            assert_eq!(ours, coeffs.to_vec(), "{method}");
        }
    }

    #[test]
    fn channel_methods_route_the_eyes_to_the_right_filters() {
        // White left, black right: only the left filter's channel lights up (red for red–cyan).
        let white = [1.0; 3];
        let black = [0.0; 3];
        assert_eq!(Method::Color.compose(white, black), [1.0, 0.0, 0.0]);
        assert_eq!(Method::Color.compose(black, white), [0.0, 1.0, 1.0]);
        assert!(
            Method::Gray
                .compose(white, white)
                .iter()
                .all(|c| (c - 1.0).abs() < 1e-6)
        );
        let d = Method::DuboisRedCyan.compose(white, black);
        assert!(d[0] > 0.9 && d[1] == 0.0 && d[2] == 0.0, "{d:?}");
        assert_eq!(Method::Mono.compose([0.2, 0.4, 0.6], white), [0.2, 0.4, 0.6]);
        assert!(!Method::Mono.is_stereo());
    }

    #[test]
    fn names_round_trip() {
        for m in Method::ALL {
            assert_eq!(m.name().parse::<Method>(), Ok(m));
        }
        assert_eq!("Red_Cyan".parse::<Method>(), Ok(Method::DuboisRedCyan));
        assert!("purple".parse::<Method>().unwrap_err().to_string().contains("dubois"));
    }
}
