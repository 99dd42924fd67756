//! PLY (the Stanford polygon format), ASCII and binary of either byte order: what laser
//! scanners and photogrammetry tools write, often with a colour per vertex.
//!
//! Read: the `vertex` element's `x y z`, `nx ny nz` (when all three are there) and
//! `red green blue [alpha]` (8-bit, or 0–1 floats; a Gaussian-splat file's `f_dc_0..2` colour
//! where these are absent), and the `face` element's index list (`vertex_indices` or
//! `vertex_index`; polygons become fans; without faces the file is a point cloud). A splat file's
//! points are drawn as `point_cloud`'s discs: those less than half opaque are left out, and a
//! flat splat's plane (from its scales and rotation) is its disc's ([`splat_normal`]). Every other
//! element and property is skipped, list properties included. Texture coordinates and
//! `TextureFile` comments are not read: such a scan shows its vertex colours, or none.
//! **Panics**: none; an element's count is held to what the rest of the file can hold (at least a
//! byte an element in binary, two characters in ASCII) before it sizes anything.

use super::mesh_file::Soup;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

#[derive(Debug)]
struct Property {
    name: String,
    /// `Some(count type)` for a list property.
    list: Option<Scalar>,
    scalar: Scalar,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

/// Reads values one at a time from the body, in the file's encoding.
struct Body<'a> {
    bytes: &'a [u8],
    at: usize,
    encoding: Encoding,
}

impl Body<'_> {
    fn value(&mut self, scalar: Scalar) -> Result<f64, String> {
        if self.encoding == Encoding::Ascii {
            let rest = &self.bytes[self.at..];
            let start = rest
                .iter()
                .position(|b| !b.is_ascii_whitespace())
                .ok_or("the file ends inside an element")?;
            let len = rest[start..]
                .iter()
                .position(|b| b.is_ascii_whitespace())
                .unwrap_or(rest.len() - start);
            self.at += start + len;
            let word = std::str::from_utf8(&rest[start..start + len]).map_err(|_| "a value that is not text")?;
            return word
                .parse::<f64>()
                .map_err(|_| format!("\"{word:.40}\" is not a number"));
        }
        let size = scalar.size();
        let raw = self
            .bytes
            .get(self.at..self.at + size)
            .ok_or("the file ends inside an element")?;
        self.at += size;
        let mut b = [0u8; 8];
        b[..size].copy_from_slice(raw);
        if self.encoding == Encoding::Big {
            b[..size].reverse();
        }
        Ok(match scalar {
            Scalar::I8 => f64::from(b[0] as i8),
            Scalar::U8 => f64::from(b[0]),
            Scalar::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
            Scalar::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
            Scalar::I32 => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::F64 => f64::from_le_bytes(b),
        })
    }

    fn left(&self) -> usize {
        self.bytes.len() - self.at
    }
}

/// Parses a PLY file into an indexed mesh.
pub fn parse(bytes: &[u8]) -> Result<Soup, String> {
    let (encoding, elements, body) = header(bytes)?;
    let mut body = Body {
        bytes,
        at: body,
        encoding,
    };
    let mut soup = Soup::default();
    let mut saw_faces = false;
    for element in &elements {
        // Each element takes at least a byte in binary (a property of a byte, or a list's count)
        // and two characters in ASCII: a count the rest of the file cannot hold is damage.
        let least = match encoding {
            Encoding::Ascii => 2,
            _ => element
                .properties
                .iter()
                .map(|p| p.list.unwrap_or(p.scalar).size())
                .sum::<usize>(),
        };
        if element.count == 0 {
            continue;
        }
        if element.properties.is_empty() {
            return Err(format!("element {} has entries but no properties", element.name));
        }
        if element.count > body.left() / least {
            return Err(format!(
                "element {} claims {} entries, more than the rest of the file holds",
                element.name, element.count
            ));
        }
        match element.name.as_str() {
            "vertex" => read_vertices(&mut body, element, &mut soup)?,
            "face" => {
                read_faces(&mut body, element, &mut soup)?;
                saw_faces = true;
            }
            _ => {
                for _ in 0..element.count {
                    for property in &element.properties {
                        skip(&mut body, property)?;
                    }
                }
            }
        }
    }
    // Without faces it is a point cloud: handed back with no indices (`point_cloud` draws it).
    if !saw_faces && soup.positions.is_empty() {
        return Err("neither faces nor vertices".to_owned());
    }
    if let Some(&bad) = soup.indices.iter().find(|&&i| i as usize >= soup.positions.len()) {
        return Err(format!(
            "a face names vertex {bad}, of {} vertices",
            soup.positions.len()
        ));
    }
    Ok(soup)
}

fn header(bytes: &[u8]) -> Result<(Encoding, Vec<Element>, usize), String> {
    let end = bytes
        .windows(10)
        .position(|w| w == b"end_header")
        .ok_or("no \"end_header\": not a PLY file, or cut short")?;
    // The body starts after the end_header line's line break (\n, or \r\n).
    let mut body = end + 10;
    while bytes.get(body).is_some_and(|&b| b == b'\r' || b == b' ') {
        body += 1;
    }
    if bytes.get(body) == Some(&b'\n') {
        body += 1;
    }
    let text = std::str::from_utf8(&bytes[..end]).map_err(|_| "a header that is not text")?;
    let mut lines = text.lines();
    if lines.next().map(str::trim) != Some("ply") {
        return Err("not a PLY file (its first line is not \"ply\")".to_owned());
    }
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    for line in lines {
        let words: Vec<&str> = line.split_ascii_whitespace().collect();
        match words.as_slice() {
            ["format", kind, _version] => {
                encoding = Some(match *kind {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::Little,
                    "binary_big_endian" => Encoding::Big,
                    other => return Err(format!("unknown PLY format \"{other:.40}\"")),
                })
            }
            ["element", name, count] => elements.push(Element {
                name: (*name).to_owned(),
                count: count
                    .parse()
                    .map_err(|_| format!("element {name:.40}: \"{count:.40}\" is not a count"))?,
                properties: Vec::new(),
            }),
            ["property", "list", count, item, name] => {
                let element = elements.last_mut().ok_or("a property before any element")?;
                let scalar = |t: &str| Scalar::parse(t).ok_or_else(|| format!("unknown PLY type \"{t:.40}\""));
                element.properties.push(Property {
                    name: (*name).to_owned(),
                    list: Some(scalar(count)?),
                    scalar: scalar(item)?,
                });
            }
            ["property", kind, name] => {
                let element = elements.last_mut().ok_or("a property before any element")?;
                element.properties.push(Property {
                    name: (*name).to_owned(),
                    list: None,
                    scalar: Scalar::parse(kind).ok_or_else(|| format!("unknown PLY type \"{kind:.40}\""))?,
                });
            }
            [] | ["comment", ..] | ["obj_info", ..] => {}
            _ => return Err(format!("a header line PLY does not have: \"{line:.60}\"")),
        }
    }
    Ok((encoding.ok_or("no \"format\" line")?, elements, body))
}

fn skip(body: &mut Body, property: &Property) -> Result<(), String> {
    match property.list {
        Some(count) => {
            let n = list_len(body, count)?;
            for _ in 0..n {
                body.value(property.scalar)?;
            }
        }
        None => {
            body.value(property.scalar)?;
        }
    }
    Ok(())
}

/// A list's length, held to what the rest of the file can hold.
fn list_len(body: &mut Body, count: Scalar) -> Result<usize, String> {
    let n = body.value(count)?;
    if !(n >= 0.0 && n <= body.left() as f64) {
        return Err(format!("a list of {n} values, more than the rest of the file holds"));
    }
    Ok(n as usize)
}

fn read_vertices(body: &mut Body, element: &Element, soup: &mut Soup) -> Result<(), String> {
    let find = |name: &str| {
        element
            .properties
            .iter()
            .position(|p| p.name == name && p.list.is_none())
    };
    let xyz = [find("x"), find("y"), find("z")];
    let [Some(x), Some(y), Some(z)] = xyz else {
        return Err("vertices without x, y and z".to_owned());
    };
    let normal = match [find("nx"), find("ny"), find("nz")] {
        [Some(a), Some(b), Some(c)] => Some([a, b, c]),
        _ => None,
    };
    let colour = match [find("red"), find("green"), find("blue")] {
        [Some(r), Some(g), Some(b)] => Some([r, g, b, find("alpha").unwrap_or(usize::MAX)]),
        _ => None,
    };
    // A Gaussian-splat PLY (3D Gaussian Splatting's layout) has no red/green/blue: its colour is
    // the spherical-harmonic DC term, shown as 0.5 + Y₀₀·f_dc per channel (Y₀₀ = 1/(2√π)), on
    // the scale of the photographs it was fitted to (sRGB).
    let dc = match (colour, [find("f_dc_0"), find("f_dc_1"), find("f_dc_2")]) {
        (None, [Some(r), Some(g), Some(b)]) => Some([r, g, b]),
        _ => None,
    };
    // Its opacity (a logit) and its shape (the log of each axis's standard deviation, and the
    // axes' rotation as an unnormalised w x y z quaternion).
    let opacity = dc.and(find("opacity"));
    let shape = match (
        [find("scale_0"), find("scale_1"), find("scale_2")],
        [find("rot_0"), find("rot_1"), find("rot_2"), find("rot_3")],
    ) {
        ([Some(a), Some(b), Some(c)], [Some(w), Some(i), Some(j), Some(k)]) if dc.is_some() => {
            Some(([a, b, c], [w, i, j, k]))
        }
        _ => None,
    };
    soup.positions.reserve(element.count);
    let mut values = vec![0.0f64; element.properties.len()];
    let mut splat_normals = Vec::new();
    for _ in 0..element.count {
        for (value, property) in values.iter_mut().zip(&element.properties) {
            if property.list.is_some() {
                skip(body, property)?;
            } else {
                *value = body.value(property.scalar)?;
            }
        }
        // A splat less than half opaque at its centre (logit below 0) is haze where it is drawn
        // (and often a floater the fitting left in the air): an opaque disc would misstate it.
        if opacity.is_some_and(|k| values[k] < 0.0) {
            continue;
        }
        soup.positions
            .push([values[x] as f32, values[y] as f32, values[z] as f32]);
        if let Some((scales, rotation)) = shape {
            let normal = splat_normal(scales.map(|k| values[k]), rotation.map(|k| values[k]));
            splat_normals.push(soup.positions.len() - 1);
            soup.normals.get_or_insert_with(Vec::new).push(normal);
        } else if let Some([a, b, c]) = normal {
            soup.normals
                .get_or_insert_with(Vec::new)
                .push([values[a] as f32, values[b] as f32, values[c] as f32]);
        }
        if let Some(channels) = colour {
            // 8-bit channels are 0–255, float ones 0–1; colours are sRGB-encoded, like glTF's
            // COLOR_0 is not (it is linear): converted where the mesh is built.
            let scale = |k: usize| match element.properties[k].scalar {
                Scalar::F32 | Scalar::F64 => 1.0,
                Scalar::U16 => 1.0 / 65535.0,
                _ => 1.0 / 255.0,
            };
            let channel = |k: usize| values.get(k).map_or(1.0, |v| (v * scale(k)).clamp(0.0, 1.0) as f32);
            soup.colors.get_or_insert_with(Vec::new).push(channels.map(channel));
        }
        if let Some(channels) = dc {
            let y00 = 0.5 / std::f64::consts::PI.sqrt();
            let [r, g, b] = channels.map(|k| (0.5 + y00 * values[k]).clamp(0.0, 1.0) as f32);
            soup.colors.get_or_insert_with(Vec::new).push([r, g, b, 1.0]);
        }
    }
    // A splat's axis faces either way: turned away from the cloud's centre, as a scanned object
    // is seen from outside (as `point_cloud` turns the normals it estimates).
    if let Some(normals) = soup.normals.as_mut().filter(|_| !splat_normals.is_empty()) {
        let n = soup.positions.len().max(1) as f64;
        let centre = soup.positions.iter().fold([0.0f64; 3], |c, p| {
            [
                c[0] + f64::from(p[0]) / n,
                c[1] + f64::from(p[1]) / n,
                c[2] + f64::from(p[2]) / n,
            ]
        });
        for i in splat_normals {
            let (p, normal) = (soup.positions[i], &mut normals[i]);
            let outwards: f64 = (0..3)
                .map(|k| (f64::from(p[k]) - centre[k]) * f64::from(normal[k]))
                .sum();
            if outwards < 0.0 {
                *normal = normal.map(|v| -v);
            }
        }
    }
    Ok(())
}

/// The plane a Gaussian splat lies in, as its normal: the axis of its smallest standard deviation
/// (`log_scales`, natural log), turned by `rotation` (w x y z, any length), where that axis is at
/// most half the next smallest: a splat at least twice as wide as it is thick lies in a surface
/// (the fitting flattens the splats of a surface into it). A rounder splat says nothing of its
/// surface's direction: zero, so that `point_cloud` estimates it from the neighbours. Zero too for
/// a rotation of no length or non-finite values.
fn splat_normal(log_scales: [f64; 3], rotation: [f64; 4]) -> [f32; 3] {
    let mut axes = [0usize, 1, 2];
    axes.sort_by(|&a, &b| log_scales[a].total_cmp(&log_scales[b]));
    let flat = log_scales[axes[0]] + std::f64::consts::LN_2 <= log_scales[axes[1]];
    let [w, x, y, z] = rotation;
    let length = (w * w + x * x + y * y + z * z).sqrt();
    if !(flat && length.is_finite() && length > 0.0) {
        return [0.0; 3];
    }
    let q = glam::DQuat::from_xyzw(x / length, y / length, z / length, w / length);
    let mut axis = glam::DVec3::ZERO;
    axis[axes[0]] = 1.0;
    (q * axis).as_vec3().to_array()
}

fn read_faces(body: &mut Body, element: &Element, soup: &mut Soup) -> Result<(), String> {
    let indices = element
        .properties
        .iter()
        .position(|p| p.list.is_some() && (p.name == "vertex_indices" || p.name == "vertex_index"))
        .ok_or("faces without a vertex_indices list")?;
    let mut polygon = Vec::new();
    for _ in 0..element.count {
        for (k, property) in element.properties.iter().enumerate() {
            if k != indices {
                skip(body, property)?;
                continue;
            }
            let count = property.list.ok_or("faces without a vertex_indices list")?;
            let n = list_len(body, count)?;
            polygon.clear();
            for _ in 0..n {
                let i = body.value(property.scalar)?;
                if !(i >= 0.0 && i <= f64::from(u32::MAX)) {
                    return Err(format!("a face names vertex {i}"));
                }
                polygon.push(i as u32);
            }
            for k in 1..polygon.len().saturating_sub(1) {
                soup.indices.extend([polygon[0], polygon[k], polygon[k + 1]]);
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &str = "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 255 0 0\n1 0 0 0 255 0\n1 1 0 0 0 255\n0 1 0 255 255 255\n4 0 1 2 3\n";

    #[test]
    fn an_ascii_quad_with_colours_is_two_triangles() {
        let soup = parse(ASCII.as_bytes()).expect("parses");
        assert_eq!(soup.positions.len(), 4);
        assert_eq!(soup.indices, [0, 1, 2, 0, 2, 3]);
        assert_eq!(soup.colors.as_ref().map(|c| c[1]), Some([0.0, 1.0, 0.0, 1.0]));
        assert!(soup.normals.is_none());
    }

    /// A Gaussian-splat PLY's points (3D Gaussian Splatting's layout: normals of zero, colour as
    /// the SH DC term, opacity, scales and rotation): coloured by the DC term.
    #[test]
    fn a_gaussian_splat_ply_is_coloured_by_its_dc_term() {
        let text = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float f_dc_0\nproperty float f_dc_1\nproperty float f_dc_2\nproperty float opacity\nproperty float scale_0\nproperty float rot_0\nend_header\n0 0 0 0 0 0 0 1.7724539 -1.7724539 2.0 -4 1\n1 0 0 0 0 0 10 -10 0.5 1.0 -4 1\n";
        let soup = parse(text.as_bytes()).expect("parses");
        assert!(soup.indices.is_empty(), "a point cloud");
        let colors = soup.colors.expect("coloured");
        // 0.5 + f/(2√π): 0 → 0.5, √π → 1, −√π → 0; beyond the range clamped.
        let expected = [[0.5, 1.0, 0.0, 1.0], [1.0, 0.0, 0.641, 1.0]];
        for (c, e) in colors.iter().zip(expected) {
            assert!(
                c.iter().zip(e).all(|(a, b)| (a - b).abs() < 1e-3),
                "{c:?} against {e:?}"
            );
        }
    }

    /// A splat file's haze is left out and its flat splats give their discs' planes: four splats
    /// around a centre below them (3D Gaussian Splatting's properties, normals of zero): one
    /// under half opaque (left out), two flat ones turned so that their thin axis is along x
    /// and along y (their normals, turned away from the centre), and a round one (no normal: its
    /// neighbours decide).
    #[test]
    fn a_splat_files_haze_is_left_out_and_its_flat_splats_give_their_planes() {
        let header = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float f_dc_0\nproperty float f_dc_1\nproperty float f_dc_2\nproperty float opacity\nproperty float scale_0\nproperty float scale_1\nproperty float scale_2\nproperty float rot_0\nproperty float rot_1\nproperty float rot_2\nproperty float rot_3\nend_header\n";
        // Rotations (w x y z, unnormalised): 90° about y takes the thin z axis to ±x; 90° about x
        // takes it to ∓y.
        let body = [
            "0 0 5 0 0 0 0 0 0 -0.2 0 0 -3 1 0 0 0",   // haze: opacity logit below 0
            "-2 0 1 0 0 0 0 0 0 3 -1 -1 -4 2 0 2 0",   // thin along z, turned to x; at −x
            "0 2 1 0 0 0 0 0 0 3 -1 -1 -4 1 1 0 0",    // thin along z, turned to y; at +y
            "0 0 -3 0 0 0 0 0 0 3 -1 -1 -1.2 1 0 0 0", // round: scales within a factor of 2
        ];
        let soup = parse(format!("{header}{}\n", body.join("\n")).as_bytes()).expect("parses");
        assert_eq!(soup.positions, [[-2.0, 0.0, 1.0], [0.0, 2.0, 1.0], [0.0, 0.0, -3.0]]);
        let normals = soup.normals.expect("the splats' normals");
        let near = |a: [f32; 3], b: [f32; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-5);
        assert!(near(normals[0], [-1.0, 0.0, 0.0]), "{:?}", normals[0]);
        assert!(near(normals[1], [0.0, 1.0, 0.0]), "{:?}", normals[1]);
        assert_eq!(normals[2], [0.0; 3]);
        assert_eq!(soup.colors.map(|c| c.len()), Some(3));
    }

    /// The same quad, binary, with a skipped element and a skipped list property before the faces.
    fn binary(big: bool) -> Vec<u8> {
        let order = if big {
            "binary_big_endian"
        } else {
            "binary_little_endian"
        };
        let mut out = format!(
            "ply\nformat {order} 1.0\nelement vertex 4\nproperty double x\nproperty double y\nproperty double z\nproperty float nx\nproperty float ny\nproperty float nz\nelement material 1\nproperty list uchar uchar name\nelement face 1\nproperty uchar flags\nproperty list uchar uint vertex_indices\nend_header\n"
        )
        .into_bytes();
        let mut put = |bytes: &[u8]| {
            let mut b = bytes.to_vec();
            if big {
                b.reverse();
            }
            out.extend(b);
        };
        for p in [[0.0f64, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]] {
            for c in p {
                put(&c.to_le_bytes());
            }
            for c in [0.0f32, 0.0, 1.0] {
                put(&c.to_le_bytes());
            }
        }
        put(&[3]);
        put(b"a");
        put(b"b");
        put(b"c");
        put(&[7]);
        put(&[4]);
        for i in [0u32, 1, 2, 3] {
            put(&i.to_le_bytes());
        }
        out
    }

    #[test]
    fn binary_files_of_both_byte_orders_read_the_same() {
        for big in [false, true] {
            let soup = parse(&binary(big)).expect("parses");
            assert_eq!(soup.positions[2], [1.0, 1.0, 0.0], "big endian {big}");
            assert_eq!(soup.indices, [0, 1, 2, 0, 2, 3], "big endian {big}");
            assert_eq!(soup.normals.as_ref().map(|n| n[3]), Some([0.0, 0.0, 1.0]));
        }
    }

    #[test]
    fn damage_is_named_not_allocated() {
        let cases = [
            (ASCII.replace("vertex 4", "vertex 4000000000"), "claims 4000000000"),
            (ASCII.replace("4 0 1 2 3", "4 0 1 2 9"), "vertex 9"),
            (ASCII.replace("4 0 1 2 3", "400000 0 1 2 3"), "a list of 400000"),
            (ASCII.replace("end_header", "end_headr"), "end_header"),
            (ASCII.replace("format ascii", "format text"), "unknown PLY format"),
            (
                "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n".to_owned(),
                "neither faces nor vertices",
            ),
            (
                ASCII.replace("0 1 0 255 255 255", "0 1 zero 255 255 255"),
                "\"zero\" is not a number",
            ),
        ];
        for (text, expected) in cases {
            let error = parse(text.as_bytes()).unwrap_err();
            assert!(error.contains(expected), "{expected}: {error}");
        }
        let mut cut = binary(false);
        cut.truncate(cut.len() - 3);
        assert!(parse(&cut).unwrap_err().contains("ends inside"));
    }
}
