//! Point clouds as text, a point a line: `.xyz` (CloudCompare's and most scanner software's ASCII
//! export) and `.pts` (Leica's: the point count on the first line, then `x y z intensity r g b`).
//!
//! Each line holds `x y z`, then optionally a colour or a normal, or an intensity and then a
//! colour, separated by spaces, tabs, commas or semicolons; `#` and `//` lines are comments.
//! What the columns after `x y z` are is decided once for the file, from every line: 3 of them
//! are a normal where each line's three make a unit vector, else a colour where they are whole
//! numbers 0–255 (or fractions 0–1 in every line); 4 are an intensity and a colour; 6 are a
//! colour and a normal (or a normal and a colour, whichever triple is the unit vector); other
//! counts keep only `x y z`. Every line must have the first line's count of columns; a line that
//! does not, or a field that is not a number, is an error naming its line.
//!
//! **Frame**: metres with +Z up, as laser scanners write them, turned by the caller into glTF's
//! +Y up. A georeferenced cloud's coordinates (hundreds of kilometres east, thousands north) are
//! taken about the centre of its bounds, in double precision, before they become the `f32` a
//! vertex holds, so its millimetres survive.
//!
//! **Budget**: the caller read the file within the budget; a point is at least six bytes of it
//! ("0 0 0\n"), so nothing here allocates more than the file's size implies. **Panics**: none.

use super::mesh_file::Soup;

/// The columns after `x y z`.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Extra {
    None,
    Colour { at: usize, scale: f64 },
    Normal { at: usize },
    Both { colour: usize, scale: f64, normal: usize },
}

/// Whether `bytes` looks like such a cloud: its first line that is not a comment (after a PTS
/// count) holds 3 to 10 numbers and nothing else.
pub fn recognises(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(4096)];
    let head = head.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(head);
    // The head may end inside a character: what came before it is judged.
    let valid = std::str::from_utf8(head).map_or_else(|e| e.valid_up_to(), str::len);
    let Ok(text) = std::str::from_utf8(&head[..valid]) else {
        return false;
    };
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty() && !is_comment(l));
    let Some(first) = lines.next() else { return false };
    let first = if fields(first).count() == 1 && first.parse::<u64>().is_ok() {
        match lines.next() {
            Some(line) => line,
            None => return false,
        }
    } else {
        first
    };
    let numbers: Vec<Option<f64>> = fields(first).map(|f| f.parse::<f64>().ok()).collect();
    (3..=10).contains(&numbers.len()) && numbers.iter().all(Option::is_some)
}

/// The cloud in `bytes`: positions about the bounds' centre (see the module docs), with the
/// colours (sRGB 0–1) and normals the columns hold. Two passes over the text, the first to judge
/// the columns and find the bounds, so that nothing but the points themselves is kept.
pub fn parse(bytes: &[u8]) -> Result<Soup, String> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let text = std::str::from_utf8(bytes).map_err(|e| format!("not text: {e}"))?;
    let mut columns = None;
    let mut count = 0usize;
    let mut low = [f64::INFINITY; 3];
    let mut high = [f64::NEG_INFINITY; 3];
    // Over every row: whether the triples from columns 3, 4 and 6 are unit vectors, whole
    // numbers 0–255 or fractions 0–1 (see `Judged`).
    let mut judged = [Judged::default(); 3];
    for_each_point(text, &mut columns, |values| {
        count += 1;
        for k in 0..3 {
            low[k] = low[k].min(values[k]);
            high[k] = high[k].max(values[k]);
        }
        for (j, at) in judged.iter_mut().zip(TRIPLES_AT) {
            if let Some(triple) = values.get(at..at + 3) {
                j.see(triple);
            }
        }
    })?;
    let Some(columns) = columns.filter(|_| count > 0) else {
        return Err("no points".to_owned());
    };
    let extra = extra_columns(columns, &judged);
    let centre: [f64; 3] = std::array::from_fn(|k| (low[k] + high[k]) * 0.5);
    let mut soup = Soup {
        positions: Vec::with_capacity(count),
        ..Soup::default()
    };
    let (colour_at, normal_at) = match extra {
        Extra::None => (None, None),
        Extra::Colour { at, scale } => (Some((at, scale)), None),
        Extra::Normal { at } => (None, Some(at)),
        Extra::Both { colour, scale, normal } => (Some((colour, scale)), Some(normal)),
    };
    if colour_at.is_some() {
        soup.colors = Some(Vec::with_capacity(count));
    }
    if normal_at.is_some() {
        soup.normals = Some(Vec::with_capacity(count));
    }
    let mut columns = Some(columns);
    for_each_point(text, &mut columns, |r| {
        soup.positions.push(std::array::from_fn(|k| (r[k] - centre[k]) as f32));
        if let (Some((at, scale)), Some(colors)) = (colour_at, soup.colors.as_mut()) {
            let c = |k: usize| (r[at + k] * scale).clamp(0.0, 1.0) as f32;
            colors.push([c(0), c(1), c(2), 1.0]);
        }
        if let (Some(at), Some(normals)) = (normal_at, soup.normals.as_mut()) {
            normals.push([r[at] as f32, r[at + 1] as f32, r[at + 2] as f32]);
        }
    })?;
    Ok(soup)
}

/// Calls `point` with each point line's numbers, in order, after checking that every line has
/// `columns` of them (the first point line's count where `columns` is `None`). Skips comments,
/// blank lines and a PTS count alone on the first line.
fn for_each_point(text: &str, columns: &mut Option<usize>, mut point: impl FnMut(&[f64])) -> Result<(), String> {
    let mut values = Vec::with_capacity(10);
    let mut first = true;
    for (number, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || is_comment(line) {
            continue;
        }
        values.clear();
        for f in fields(line) {
            let v = f
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("line {}: {:?} is not a number", number + 1, excerpt(f)))?;
            values.push(v);
            if values.len() > 10 {
                break;
            }
        }
        // Leica's PTS: the point count alone on the first line.
        let was_first = std::mem::replace(&mut first, false);
        if was_first && values.len() == 1 {
            continue;
        }
        let expected = *columns.get_or_insert(values.len());
        if !(3..=10).contains(&expected) {
            return Err(format!(
                "line {}: {expected} columns; a point is x y z and up to 7 more",
                number + 1
            ));
        }
        if values.len() != expected {
            return Err(format!(
                "line {}: {} columns where the first point has {expected}",
                number + 1,
                values.len()
            ));
        }
        point(&values);
    }
    Ok(())
}

/// What a triple of columns has been in every row so far.
#[derive(Clone, Copy, Debug)]
struct Judged {
    unit: bool,
    bytes: bool,
    fractions: bool,
}

impl Default for Judged {
    fn default() -> Self {
        Self {
            unit: true,
            bytes: true,
            fractions: true,
        }
    }
}

impl Judged {
    fn see(&mut self, t: &[f64]) {
        let n2: f64 = t.iter().map(|v| v * v).sum();
        self.unit &= (n2 - 1.0).abs() < 0.02;
        self.bytes &= t.iter().all(|&v| v.fract() == 0.0 && (0.0..=255.0).contains(&v));
        self.fractions &= t.iter().all(|&v| (0.0..=1.0).contains(&v));
    }

    /// The factor to 0–1 if a colour: 1/255 for whole numbers 0–255, 1 for fractions.
    fn colour_scale(&self) -> Option<f64> {
        if self.bytes {
            Some(1.0 / 255.0)
        } else if self.fractions {
            Some(1.0)
        } else {
            None
        }
    }
}

/// Where the triples that may be a colour or a normal start: after x y z; after an intensity;
/// after a first triple.
const TRIPLES_AT: [usize; 3] = [3, 4, 6];

/// What the columns after `x y z` hold (see the module docs), from `columns` and how the
/// triples at [`TRIPLES_AT`] were judged over every row.
fn extra_columns(columns: usize, judged: &[Judged; 3]) -> Extra {
    let [at3, at4, at6] = judged;
    match columns - 3 {
        3 if at3.unit => Extra::Normal { at: 3 },
        3 => at3
            .colour_scale()
            .map_or(Extra::None, |scale| Extra::Colour { at: 3, scale }),
        // An intensity, then the colour (PTS).
        4 => at4
            .colour_scale()
            .map_or(Extra::None, |scale| Extra::Colour { at: 4, scale }),
        6 if at6.unit => at3.colour_scale().map_or(Extra::Normal { at: 6 }, |scale| Extra::Both {
            colour: 3,
            scale,
            normal: 6,
        }),
        6 if at3.unit => at6.colour_scale().map_or(Extra::Normal { at: 3 }, |scale| Extra::Both {
            colour: 6,
            scale,
            normal: 3,
        }),
        _ => Extra::None,
    }
}

fn is_comment(line: &str) -> bool {
    line.starts_with('#') || line.starts_with("//")
}

fn fields(line: &str) -> impl Iterator<Item = &str> {
    line.split(|c: char| c.is_ascii_whitespace() || c == ',' || c == ';')
        .filter(|f| !f.is_empty())
}

/// A field as shown in an error: at most 24 characters.
fn excerpt(field: &str) -> String {
    field.chars().take(24).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_points_are_taken_about_their_centre() {
        let soup = parse(b"# a scan\n1 2 3\n3 4 5\n").expect("parses");
        assert_eq!(soup.positions, [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]);
        assert!(soup.colors.is_none() && soup.normals.is_none() && soup.indices.is_empty());
    }

    #[test]
    fn georeferenced_millimetres_survive() {
        // 500 km east, 4 000 km north: an f32 there steps by 0.5 m; about the centre, by far
        // less than a millimetre.
        let soup = parse(b"500000.001 4000000.002 100.0\n500000.101 4000000.102 100.1\n").expect("parses");
        let [a, b] = [soup.positions[0], soup.positions[1]];
        for k in 0..3 {
            assert!((b[k] - a[k] - 0.1).abs() < 1e-6, "{a:?} {b:?}");
        }
    }

    #[test]
    fn the_columns_after_xyz_are_told_apart() {
        // Colour, 8-bit, comma-separated.
        let soup = parse(b"0,0,0,255,0,0\n1,0,0,0,128,255\n").expect("parses");
        assert_eq!(soup.colors.expect("colours")[1], [0.0, 128.0 / 255.0, 1.0, 1.0]);
        // A normal (unit vectors), tab-separated.
        let soup = parse(b"0\t0\t0\t0\t0\t1\n1\t0\t0\t0.6\t0.8\t0\n").expect("parses");
        assert_eq!(soup.normals.expect("normals")[1], [0.6, 0.8, 0.0]);
        assert!(soup.colors.is_none());
        // A colour of fractions and a normal, in either order.
        for text in [
            "0 0 0 0.5 0.25 1 0 0 1\n1 1 1 1 1 1 1 0 0\n",
            "0 0 0 0 0 1 0.5 0.25 1\n1 1 1 1 0 0 1 1 1\n",
        ] {
            let soup = parse(text.as_bytes()).expect("parses");
            assert_eq!(soup.colors.expect("colours")[0], [0.5, 0.25, 1.0, 1.0], "{text}");
            assert_eq!(soup.normals.expect("normals")[0], [0.0, 0.0, 1.0], "{text}");
        }
        // Leica's PTS: the count, then x y z intensity r g b.
        let soup = parse(b"2\n0 0 0 -1200 10 20 30\n1 1 1 850 40 50 60\n").expect("parses");
        assert_eq!(soup.positions.len(), 2);
        assert_eq!(
            soup.colors.expect("colours")[1],
            [40.0 / 255.0, 50.0 / 255.0, 60.0 / 255.0, 1.0]
        );
        // Three more columns that are neither: left out.
        let soup = parse(b"0 0 0 -5 300 2.5\n1 1 1 7 8 9\n").expect("parses");
        assert!(soup.colors.is_none() && soup.normals.is_none());
    }

    #[test]
    fn a_bad_line_is_named() {
        let err = parse(b"0 0 0\n1 1 1\n2 2 x\n").unwrap_err();
        assert!(err.contains("line 3") && err.contains("\"x\""), "{err}");
        let err = parse(b"0 0 0\n1 1 1 1\n").unwrap_err();
        assert!(err.contains("line 2") && err.contains("4 columns"), "{err}");
        let err = parse(b"0 0\n").unwrap_err();
        assert!(err.contains("line 1") && err.contains("2 columns"), "{err}");
        assert_eq!(parse(b"# nothing\n").unwrap_err(), "no points");
        assert!(parse(b"0 0 nan\n").unwrap_err().contains("line 1"));
        assert!(parse(b"\xff\xfe0 0 0\n").is_err());
    }

    #[test]
    fn a_cloud_is_recognised_by_its_first_point() {
        assert!(recognises(b"# CloudCompare\n1.5 2 3 255 0 0\n"));
        assert!(recognises(b"2\n0 0 0 -1200 10 20 30\n"));
        assert!(recognises(b"0;0;0\n"));
        assert!(!recognises(b"v 0 0 0\n"), "an OBJ vertex");
        assert!(!recognises(b"solid x\n"));
        assert!(!recognises(b"0 0\n"));
        assert!(!recognises(b"12\n"));
        assert!(!recognises(b"{\"asset\":{}}"));
    }
}
