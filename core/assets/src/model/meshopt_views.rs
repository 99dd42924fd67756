//! `EXT_meshopt_compression` (and its ratified twin `KHR_meshopt_compression`): buffer views
//! stored compressed by meshoptimizer's codecs, as `gltfpack -c` writes them.
//!
//! A compressed view names its compressed bytes in its extension (`buffer`, `byteOffset`,
//! `byteLength`) and what they decode to (`count` elements of `byteStride` bytes, a `mode` and
//! an optional `filter`); the view's own `buffer` is then usually a *fallback* buffer with no
//! data at all, marked `"fallback": true`, which is never read. Each compressed view is decoded
//! once, up front, into a buffer of its own; accessors and images then read it like any view
//! ([`DecodedViews::bytes`]).
//!
//! Decoding is meshoptimizer's (the `meshopt` crate, already linked for the level-of-detail
//! chains): its decoders are written for untrusted input — they read no more than the bytes
//! given and write no more than `count × byteStride`, and fail with an error code on a damaged
//! stream — so a hostile file yields a named error, never a read outside the buffer. The
//! decoded size is charged to the load's budget before anything is allocated.
//!
//! **Panics**: none. **Threading**: plain functions.

use gltf::buffer::View;
use serde_json::Value;

use crate::budget::Spending;

/// The extension's two names; the bitstream and the JSON are the same (the KHR one adds the
/// `COLOR` filter, accepted under either name).
pub const NAMES: [&str; 2] = ["EXT_meshopt_compression", "KHR_meshopt_compression"];

fn extension_of<'a>(value: impl Fn(&str) -> Option<&'a Value>) -> Option<&'a Value> {
    NAMES.iter().find_map(|name| value(name))
}

/// Whether `buffer` is a compressed file's fallback, whose data is never needed (and usually
/// absent).
pub fn is_fallback(buffer: &gltf::Buffer) -> bool {
    extension_of(|name| buffer.extension_value(name))
        .and_then(|ext| ext.get("fallback"))
        .and_then(Value::as_bool)
        .unwrap_or(false)
}

/// How a view's bytes were compressed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    /// Vertex attributes: `meshopt_decodeVertexBuffer`.
    Attributes,
    /// A triangle list's indices: `meshopt_decodeIndexBuffer`.
    Triangles,
    /// Any other index sequence: `meshopt_decodeIndexSequence`.
    Indices,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Filter {
    None,
    Octahedral,
    Quaternion,
    Exponential,
    Color,
}

/// One compressed view's extension, checked.
#[derive(Clone, Copy, Debug)]
struct Compressed {
    buffer: usize,
    offset: usize,
    length: usize,
    stride: usize,
    count: usize,
    mode: Mode,
    filter: Filter,
}

fn parse(ext: &Value) -> Result<Compressed, String> {
    let number = |key: &str, default: Option<usize>| -> Result<usize, String> {
        match ext.get(key) {
            None => default.ok_or_else(|| format!("the extension has no {key}")),
            Some(v) => v
                .as_u64()
                .and_then(|n| usize::try_from(n).ok())
                .ok_or_else(|| format!("{key} is not a whole number")),
        }
    };
    let word = |key: &str| {
        ext.get(key)
            .map(|v| v.as_str().ok_or_else(|| format!("{key} is not a string")))
    };
    let mode = match word("mode").transpose()? {
        Some("ATTRIBUTES") => Mode::Attributes,
        Some("TRIANGLES") => Mode::Triangles,
        Some("INDICES") => Mode::Indices,
        Some(other) => return Err(format!("unknown mode {other}")),
        None => return Err("the extension has no mode".to_owned()),
    };
    let filter = match word("filter").transpose()? {
        None | Some("NONE") => Filter::None,
        Some("OCTAHEDRAL") => Filter::Octahedral,
        Some("QUATERNION") => Filter::Quaternion,
        Some("EXPONENTIAL") => Filter::Exponential,
        Some("COLOR") => Filter::Color,
        Some(other) => return Err(format!("unknown filter {other}")),
    };
    let c = Compressed {
        buffer: number("buffer", None)?,
        offset: number("byteOffset", Some(0))?,
        length: number("byteLength", None)?,
        stride: number("byteStride", None)?,
        count: number("count", None)?,
        mode,
        filter,
    };
    // The limits the codecs themselves have (and the format's spec states).
    let stride_ok = match c.mode {
        Mode::Attributes => c.stride.is_multiple_of(4) && (4..=256).contains(&c.stride),
        Mode::Triangles | Mode::Indices => c.stride == 2 || c.stride == 4,
    };
    if !stride_ok {
        return Err(format!("byteStride {} is not allowed in mode {:?}", c.stride, c.mode));
    }
    if c.mode == Mode::Triangles && !c.count.is_multiple_of(3) {
        return Err(format!("{} indices are not whole triangles", c.count));
    }
    let filter_ok = match c.filter {
        Filter::None => true,
        _ if c.mode != Mode::Attributes => false,
        Filter::Octahedral | Filter::Color => c.stride == 4 || c.stride == 8,
        Filter::Quaternion => c.stride == 8,
        Filter::Exponential => true, // any multiple of 4, checked above
    };
    if !filter_ok {
        return Err(format!(
            "filter {:?} cannot apply to mode {:?} with byteStride {}",
            c.filter, c.mode, c.stride
        ));
    }
    Ok(c)
}

/// The decoded bytes of every compressed view of a document, by view index.
#[derive(Debug, Default)]
pub struct DecodedViews {
    /// Words, so that the filters (which work on 16- and 32-bit integers) get aligned memory;
    /// with the decoded length in bytes.
    views: Vec<Option<(Vec<u32>, usize)>>,
}

impl DecodedViews {
    /// The decoded bytes of `view`, `None` for a view stored plainly.
    pub fn bytes(&self, view: &View) -> Option<&[u8]> {
        let (words, len) = self.views.get(view.index())?.as_ref()?;
        bytemuck::cast_slice::<u32, u8>(words).get(..*len)
    }
}

/// Why a compressed view could not be decoded: which view, and why (the caller adds the file).
#[derive(Debug)]
pub enum DecodeError {
    Data { view: usize, message: String },
    OverBudget(crate::budget::OverBudget),
}

/// Decodes every compressed view of `doc` from `buffers`, charging each decoded size to
/// `spending` first.
pub fn decode_all(doc: &gltf::Document, buffers: &[Vec<u8>], spending: &Spending) -> Result<DecodedViews, DecodeError> {
    let mut decoded = DecodedViews::default();
    for view in doc.views() {
        let Some(ext) = extension_of(|name| view.extension_value(name)) else {
            continue;
        };
        let data = |message: String| DecodeError::Data {
            view: view.index(),
            message,
        };
        let c = parse(ext).map_err(data)?;
        let size = c
            .count
            .checked_mul(c.stride)
            .ok_or_else(|| data(format!("{} elements of {} bytes overflow", c.count, c.stride)))?;
        spending
            .check_bytes(|| format!("bufferView {} decompressed", view.index()), size as u64)
            .map_err(DecodeError::OverBudget)?;
        let source = c
            .offset
            .checked_add(c.length)
            .and_then(|end| buffers.get(c.buffer)?.get(c.offset..end))
            .ok_or_else(|| data("the compressed bytes lie outside their buffer".to_owned()))?;
        let words = decode(&c, source).map_err(data)?;
        if decoded.views.len() <= view.index() {
            decoded.views.resize_with(view.index() + 1, || None);
        }
        decoded.views[view.index()] = Some((words, size));
    }
    Ok(decoded)
}

fn decode(c: &Compressed, source: &[u8]) -> Result<Vec<u32>, String> {
    use meshopt::ffi;
    let size = c.count * c.stride;
    let mut words = vec![0u32; size.div_ceil(4)];
    let destination = words.as_mut_ptr().cast::<std::ffi::c_void>();
    // SAFETY: `destination` holds at least `count × stride` bytes (the words were sized for
    // them) and `source` is a live slice of `source.len()` bytes; meshoptimizer's decoders
    // write at most `count × stride` bytes and read at most `source.len()`, whatever the
    // stream holds (they are documented as safe for untrusted input), and return non-zero
    // on a stream that does not decode. The strides were checked against each codec's
    // preconditions in `parse` (their asserts would otherwise abort).
    let status = unsafe {
        match c.mode {
            Mode::Attributes => {
                ffi::meshopt_decodeVertexBuffer(destination, c.count, c.stride, source.as_ptr(), source.len())
            }
            Mode::Triangles => {
                ffi::meshopt_decodeIndexBuffer(destination, c.count, c.stride, source.as_ptr(), source.len())
            }
            Mode::Indices => {
                ffi::meshopt_decodeIndexSequence(destination, c.count, c.stride, source.as_ptr(), source.len())
            }
        }
    };
    if status != 0 {
        return Err(format!(
            "the compressed stream does not decode (meshoptimizer error {status})"
        ));
    }
    // SAFETY: the filters rewrite `count` elements of `stride` bytes in place, within the
    // decoded buffer; it is 4-byte aligned (u32 words), which the 16- and 32-bit filters need,
    // and each filter's stride was checked in `parse`.
    unsafe {
        match c.filter {
            Filter::None => {}
            Filter::Octahedral => ffi::meshopt_decodeFilterOct(destination, c.count, c.stride),
            Filter::Quaternion => ffi::meshopt_decodeFilterQuat(destination, c.count, c.stride),
            Filter::Exponential => ffi::meshopt_decodeFilterExp(destination, c.count, c.stride),
            Filter::Color => ffi::meshopt_decodeFilterColor(destination, c.count, c.stride),
        }
    }
    Ok(words)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn extensions_are_checked_before_any_codec_sees_them() {
        let ok = json!({"buffer": 0, "byteLength": 10, "byteStride": 12, "count": 5, "mode": "ATTRIBUTES"});
        let c = parse(&ok).unwrap();
        assert_eq!((c.offset, c.filter), (0, Filter::None));
        let bad = |v: Value, needle: &str| {
            let e = parse(&v).unwrap_err();
            assert!(e.contains(needle), "{e}");
        };
        bad(
            json!({"buffer": 0, "byteLength": 10, "byteStride": 6, "count": 5, "mode": "ATTRIBUTES"}),
            "byteStride 6",
        );
        bad(
            json!({"buffer": 0, "byteLength": 10, "byteStride": 260, "count": 5, "mode": "ATTRIBUTES"}),
            "byteStride 260",
        );
        bad(
            json!({"buffer": 0, "byteLength": 10, "byteStride": 4, "count": 4, "mode": "TRIANGLES"}),
            "whole triangles",
        );
        bad(
            json!({"buffer": 0, "byteLength": 10, "byteStride": 1, "count": 3, "mode": "INDICES"}),
            "byteStride 1",
        );
        bad(
            json!({"buffer": 0, "byteLength": 10, "byteStride": 12, "count": 5, "mode": "ATTRIBUTES", "filter": "OCTAHEDRAL"}),
            "Octahedral",
        );
        bad(
            json!({"buffer": 0, "byteLength": 10, "byteStride": 4, "count": 3, "mode": "TRIANGLES", "filter": "EXPONENTIAL"}),
            "Exponential",
        );
        bad(
            json!({"buffer": 0, "byteLength": 10, "byteStride": 4, "count": 3, "mode": "STRIPS"}),
            "unknown mode",
        );
        bad(
            json!({"buffer": -1, "byteLength": 10, "byteStride": 4, "count": 3, "mode": "INDICES"}),
            "buffer is not",
        );
        bad(
            json!({"byteLength": 10, "byteStride": 4, "count": 3, "mode": "INDICES"}),
            "no buffer",
        );
    }

    #[test]
    fn a_vertex_stream_decodes_to_what_was_encoded_and_damage_is_an_error() {
        let vertices: Vec<[f32; 3]> = (0..50).map(|i| [i as f32 * 0.5, (i * i) as f32, -(i as f32)]).collect();
        let encoded = meshopt::encoding::encode_vertex_buffer(&vertices).unwrap();
        let c = Compressed {
            buffer: 0,
            offset: 0,
            length: encoded.len(),
            stride: 12,
            count: vertices.len(),
            mode: Mode::Attributes,
            filter: Filter::None,
        };
        let words = decode(&c, &encoded).unwrap();
        assert_eq!(bytemuck::cast_slice::<u32, [f32; 3]>(&words), &vertices[..]);
        // Cut short: an error, not garbage.
        let cut = &encoded[..encoded.len() / 2];
        assert!(decode(&Compressed { length: cut.len(), ..c }, cut).is_err());
        // Not a meshopt stream at all.
        assert!(decode(&c, &[0u8; 40]).is_err());
    }
}
