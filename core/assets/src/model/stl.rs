//! STL, binary and ASCII: the triangle soup 3D-printing scans are published in (Scan the World's
//! museum collections, many museums' "download for printing").
//!
//! Binary is told from ASCII by its size, not its first word: a binary file is exactly
//! `84 + 50 · n` bytes for the `n` its header states, and many binary files begin with "solid"
//! too. The facet normals are not read (exporters often leave them zero or wrong; the loader
//! makes normals from the surface). An ASCII loop of more than three vertices is a fan.
//! Units and axes are the loader's business ([`super::mesh_file`]).
//! **Panics**: none; every count is checked against the file's size before it sizes anything.

use super::mesh_file::Soup;

/// Parses an STL file into a triangle soup (three positions a triangle, no sharing).
pub fn parse(bytes: &[u8]) -> Result<Soup, String> {
    if let Some(count) = binary_count(bytes) {
        let mut positions = Vec::with_capacity(count * 3);
        for facet in bytes[84..].chunks_exact(50) {
            for corner in 0..3 {
                let at = 12 + corner * 12;
                let float = |k: usize| {
                    let b = &facet[at + 4 * k..at + 4 * k + 4];
                    f32::from_le_bytes([b[0], b[1], b[2], b[3]])
                };
                positions.push([float(0), float(1), float(2)]);
            }
        }
        return Ok(Soup::triangles(positions));
    }
    let text = ascii_text(bytes);
    // Not text after "solid" (or no "solid"): a binary file whose size does not match its count.
    let binary_mismatch = || match bytes.get(80..84) {
        Some(n) => {
            let count = u32::from_le_bytes([n[0], n[1], n[2], n[3]]);
            format!(
                "neither ASCII STL (\"solid …\") nor binary STL: {count} triangles take {} bytes, the file has {}",
                84 + 50 * u64::from(count),
                bytes.len()
            )
        }
        None => "neither ASCII STL (\"solid …\") nor binary STL (84 bytes of header at least)".to_owned(),
    };
    if !text.trim_ascii_start().starts_with(b"solid") {
        return Err(binary_mismatch());
    }
    match std::str::from_utf8(text) {
        Ok(text) => parse_ascii(text),
        Err(_) => Err(binary_mismatch()),
    }
}

/// Whether `bytes` are STL as [`parse`] reads it: binary of exactly the size its count states, or
/// text beginning (after a byte-order mark and blanks) with "solid".
pub fn recognises(bytes: &[u8]) -> bool {
    binary_count(bytes).is_some() || ascii_text(bytes).trim_ascii_start().starts_with(b"solid")
}

/// The text of an ASCII STL: its bytes without a UTF-8 byte-order mark.
fn ascii_text(bytes: &[u8]) -> &[u8] {
    bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes)
}

/// The triangle count of a binary STL, when the file's size is exactly what it states.
fn binary_count(bytes: &[u8]) -> Option<usize> {
    let n = bytes.get(80..84)?;
    let count = u32::from_le_bytes([n[0], n[1], n[2], n[3]]) as usize;
    (count.checked_mul(50)?.checked_add(84)? == bytes.len()).then_some(count)
}

fn parse_ascii(text: &str) -> Result<Soup, String> {
    let mut positions = Vec::new();
    let mut in_loop: Vec<[f32; 3]> = Vec::new();
    let mut looping = false;
    for (number, line) in text.lines().enumerate() {
        let mut words = line.split_ascii_whitespace();
        match words.next() {
            Some("outer") => {
                looping = true;
                in_loop.clear();
            }
            Some("vertex") if looping => {
                let mut xyz = [0.0f32; 3];
                for c in &mut xyz {
                    *c = words
                        .next()
                        .and_then(|w| w.parse().ok())
                        .ok_or_else(|| format!("line {}: a vertex needs three numbers: {line:.80}", number + 1))?;
                }
                in_loop.push(xyz);
            }
            Some("vertex") => return Err(format!("line {}: a vertex outside an \"outer loop\"", number + 1)),
            Some("endloop") => {
                looping = false;
                if in_loop.len() < 3 {
                    return Err(format!("line {}: a loop of {} vertices", number + 1, in_loop.len()));
                }
                for k in 1..in_loop.len() - 1 {
                    positions.extend([in_loop[0], in_loop[k], in_loop[k + 1]]);
                }
            }
            _ => {}
        }
    }
    Ok(Soup::triangles(positions))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn binary(triangles: &[[[f32; 3]; 3]], header: &[u8]) -> Vec<u8> {
        let mut out = header.to_vec();
        out.resize(80, b' ');
        out.extend((triangles.len() as u32).to_le_bytes());
        for t in triangles {
            out.extend([0u8; 12]); // a zero normal, as exporters often leave it
            for p in t {
                for c in p {
                    out.extend(c.to_le_bytes());
                }
            }
            out.extend([0u8; 2]);
        }
        out
    }

    const TRIANGLE: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

    #[test]
    fn a_binary_file_beginning_with_solid_is_read_as_binary() {
        let bytes = binary(&[TRIANGLE, TRIANGLE], b"solid exported by a CAD program");
        let soup = parse(&bytes).expect("binary");
        assert_eq!(soup.positions, [TRIANGLE, TRIANGLE].concat());
    }

    #[test]
    fn an_ascii_file_is_read_and_its_quads_are_fans() {
        let text = "solid s\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 1 1 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid s\n";
        let soup = parse(text.as_bytes()).expect("ascii");
        assert_eq!(
            soup.positions,
            [
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0]
            ]
        );
    }

    #[test]
    fn a_binary_count_that_does_not_match_the_size_is_named_not_allocated() {
        let mut bytes = binary(&[TRIANGLE], b"binary");
        bytes[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
        let error = parse(&bytes).unwrap_err();
        assert!(error.contains("4294967295 triangles"), "{error}");
    }

    #[test]
    fn bad_ascii_says_where() {
        let error = parse(b"solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0\n").unwrap_err();
        assert!(error.contains("line 4"), "{error}");
        let error = parse(b"solid s\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n").unwrap_err();
        assert!(error.contains("a loop of 2 vertices"), "{error}");
    }
}
