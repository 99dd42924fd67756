//! Point clouds in ASPRS LAS (versions 1.0–1.4, every point format) and in LAZ, LASzip's
//! compressed form of it: what laser scanners and photogrammetry tools export besides PLY and
//! text. Decoded by the `las` crate (LAZ through its `laz` port of LASzip); this module picks
//! the points and turns them into a [`Soup`].
//!
//! * **Points kept**: a scan may hold hundreds of millions. Every `stride`-th point is kept, the
//!   stride chosen from the header's count so that at most [`RAW_POINTS_KEPT`] remain (four
//!   times the discs a cloud may become, so that `point_cloud::kept` still has room to thin them
//!   evenly in space). Points the file classifies as noise (ASPRS classes 7 and 18) or flags as
//!   withheld (deleted) are left out.
//! * **Frame**: the header's scale and offset applied, then metres in the units of the file's
//!   coordinate system (feet, degrees: `las_crs`), with +Z up, turned by the caller into glTF's
//!   +Y up, and taken about their centre (`scan_points`).
//! * **Colour**: the RGB of point formats 2, 3, 5, 7, 8 and 10 (sRGB). LAS asks for 16-bit
//!   values, but many writers store 8-bit ones: when no kept channel exceeds 255 they are taken
//!   as 8-bit. Without colour (or with colour fields left at zero), the intensity shades the
//!   points (`scan_points`).
//!
//! **Threads**: a LAZ whose chunk table can be trusted is decoded a chunk a thread, as many
//! chunks at a time as the calling rayon pool has threads (`laz_chunks`; 3.1 s → 2.2 s for a
//! 5-million-point file on two cores); any other file in order, on the calling thread.
//!
//! **Budget**: the caller read the file within the budget; points are decoded in chunks of at
//! most [`CHUNK_BYTES`] (one a thread), so a header that claims more points than the file holds
//! costs no more than that (a plain LAS is refused before decoding, a LAZ fails at the file's
//! end: both are named as cut short), and at most [`RAW_POINTS_KEPT`] points are
//! held (32 bytes each: about 19 MB) whatever the file's size. What the decoders would allocate
//! on a header's word alone is checked first (`check_header`). **Progress**: `keep_going` is
//! told the share decoded after each chunk (each window of chunks) and stops the work by
//! returning `false`. **Panics**: none; the LAZ decoder's own on a damaged chunk table are
//! caught, whichever thread they happen on, and reported as the file's error.

use std::io::Cursor;

use las::{PointData, PointDataBuilder, Reader};

use super::las_crs::Units;
use super::laz_chunks;
use super::le_fields;
use super::mesh_file::Soup;
use super::scan_points::{CUT_SHORT, RAW_POINTS_KEPT, ScanPoints};

/// The most bytes of decoded records held at once.
pub const CHUNK_BYTES: usize = 8 << 20;

/// ASPRS classes "low point (noise)" and "high noise" (LAS 1.4, table 17).
const NOISE_CLASSES: [u8; 2] = [7, 18];

/// Whether `bytes` begin as a LAS or LAZ file does (its signature, "LASF").
pub fn recognises(bytes: &[u8]) -> bool {
    bytes.starts_with(b"LASF")
}

/// The cloud in `bytes` (see the module docs); `Ok(None)` when `keep_going` stopped it.
pub fn parse(bytes: Vec<u8>, keep_going: impl FnMut(f64) -> bool) -> Result<Option<Soup>, String> {
    parse_keeping(bytes, RAW_POINTS_KEPT, keep_going)
}

/// [`parse`], keeping at most `most` points.
fn parse_keeping(bytes: Vec<u8>, most: u64, keep_going: impl FnMut(f64) -> bool) -> Result<Option<Soup>, String> {
    check_header(&bytes)?;
    // The LAZ decoder indexes its chunk table without checking it against the chunks it meets
    // (a damaged table panics; found by fuzzing): that is this file's error, not the app's end.
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| decode(bytes, most, keep_going, true)))
        .map_err(|_| "the LAS/LAZ decoder failed on damaged data".to_owned())?
}

/// The points of a file whose header passed [`check_header`], as [`parse_keeping`] returns them.
/// With `in_parallel`, a LAZ's chunks are decoded on several threads (`laz_chunks`) where its
/// chunk table can be trusted; the sequential decoder reads every other file.
fn decode(
    bytes: Vec<u8>,
    most: u64,
    mut keep_going: impl FnMut(f64) -> bool,
    in_parallel: bool,
) -> Result<Option<Soup>, String> {
    let header = las::Header::new(Cursor::new(&bytes[..])).map_err(|e| decoding_error(&e, None))?;
    let units = Units::of(&header);
    let total = header.number_of_points();
    let stride = total.div_ceil(most.max(1)).max(1);
    let record_len = usize::from(header.point_format().len()).max(1);
    let offset_to_points = le_fields::u32_at(&bytes, 96).map_or(0, u64::from);
    let plan = (in_parallel && header.point_format().is_compressed)
        .then(|| laz_chunks::plan(&bytes, offset_to_points, total, record_len))
        .flatten();
    let mut picked = Picked::default();
    if let Some(plan) = plan {
        // A window of as many chunks as there are threads at a time: a chunk's records each.
        for window in plan.chunks.chunks(rayon::current_num_threads().max(1)) {
            let parts = crate::parallel::map(window, |chunk| {
                let records = laz_chunks::decode(&plan, &bytes, chunk)
                    .map_err(|e| decoding_error(&las::Error::LasZipError(e), Some(total)))?;
                let data = PointDataBuilder::new()
                    .for_header(&header)
                    .build_from_bytes(records)
                    .map_err(|e| e.to_string())?;
                let mut part = Picked::default();
                part.take(&data, chunk.first_index, stride)?;
                Ok::<_, String>(part)
            });
            for part in parts {
                picked.append(part?);
            }
            if !keep_going(picked.read as f64 / total.max(1) as f64) {
                return Ok(None);
            }
        }
    } else {
        let mut reader = Reader::new(Cursor::new(bytes)).map_err(|e| decoding_error(&e, None))?;
        let chunk = (CHUNK_BYTES / record_len).max(1) as u64;
        let mut data = PointDataBuilder::new().for_header(reader.header()).build();
        loop {
            let n = reader
                .fill_points(chunk, &mut data)
                .map_err(|e| decoding_error(&e, Some(total)))?;
            if n == 0 {
                break;
            }
            picked.take(&data, picked.read, stride)?;
            if !keep_going(picked.read as f64 / total.max(1) as f64) {
                return Ok(None);
            }
        }
    }
    let Picked {
        mut positions,
        colours,
        intensities,
        read,
    } = picked;
    if positions.is_empty() {
        return Err(if read == 0 {
            "no points".to_owned()
        } else {
            "the points read are all classified as noise or withheld (deleted)".to_owned()
        });
    }
    units.to_metres(&mut positions);
    let coloured = colours.len() == positions.len();
    Ok(Some(
        ScanPoints {
            positions,
            colours: if coloured { rgb_colours(&colours) } else { Vec::new() },
            intensities: intensities.into_iter().map(f32::from).collect(),
        }
        .into_soup(),
    ))
}

/// The points kept from the records decoded so far, in the file's order.
#[derive(Debug, Default)]
struct Picked {
    positions: Vec<[f64; 3]>,
    /// One a position where the records have colour.
    colours: Vec<[u16; 3]>,
    intensities: Vec<u16>,
    /// Records decoded.
    read: u64,
}

impl Picked {
    /// Keeps every `stride`-th of `data`'s records (the file's `first`, `first` + 1, …) that is
    /// neither noise nor withheld.
    fn take(&mut self, data: &PointData, first: u64, stride: u64) -> Result<(), String> {
        let mut rgb = data.rgb();
        let columns = data
            .x()
            .zip(data.y())
            .zip(data.z())
            .zip(data.classification())
            .zip(data.intensity())
            .zip(withheld(data));
        for (at, (((((x, y), z), class), intensity), withheld)) in (first..).zip(columns) {
            let colour = rgb.as_mut().and_then(Iterator::next);
            if !at.is_multiple_of(stride) || NOISE_CLASSES.contains(&class) || withheld {
                continue;
            }
            if !(x.is_finite() && y.is_finite() && z.is_finite()) {
                return Err(format!(
                    "point {at} lies at ({x}, {y}, {z}): the header's scale or offset is not a number"
                ));
            }
            self.positions.push([x, y, z]);
            if let Some((r, g, b)) = colour {
                self.colours.push([r, g, b]);
            }
            self.intensities.push(intensity);
        }
        self.read += data.len() as u64;
        Ok(())
    }

    /// Adds the points picked from the records after these.
    fn append(&mut self, mut after: Picked) {
        self.positions.append(&mut after.positions);
        self.colours.append(&mut after.colours);
        self.intensities.append(&mut after.intensities);
        self.read += after.read;
    }
}

/// Refuses what the `las` and `laz` crates would take on trust from a file (they were written for
/// files, not for hostile input; each case below was an abort, two found by fuzzing): a point
/// count whose records' end overflows 64 bits (added and multiplied unchecked), an extended
/// record (LAS 1.4) longer than what follows it in the file, a LAZ chunk table of more chunks
/// than the file could hold (both allocated at the length stated before anything is read), and
/// a LAZ chunk whose layers run past the file's end (each allocated at its stated size:
/// `laz_layers`). Each LAZ chunk begins with one point stored whole, so a file holds at most its
/// length over the record length of chunks. A plain LAS shorter than its points is cut short.
fn check_header(bytes: &[u8]) -> Result<(), String> {
    // Offsets come from the file: every read is checked (`le_fields`).
    let u16_at = |at: u64| le_fields::u16_at(bytes, at);
    let u32_at = |at: u64| le_fields::u32_at(bytes, at);
    let u64_at = |at: u64| le_fields::u64_at(bytes, at);
    let cut = || "the header is cut short".to_owned();
    let minor = *bytes.get(25).ok_or_else(cut)?;
    let header_size = u16_at(94).ok_or_else(cut)?;
    let offset_to_points = u32_at(96).ok_or_else(cut)?;
    let record_len = u16_at(105).ok_or_else(cut)?;
    let legacy_count = u32_at(107).ok_or_else(cut)?;
    // LAS 1.4's header (375 bytes) adds the extended records' place and a 64-bit point count.
    let extended = minor >= 4 && header_size >= 375;
    let count = match (legacy_count, extended) {
        (0, true) => u64_at(247).ok_or_else(cut)?,
        (n, _) => u64::from(n),
    };
    let end = count
        .checked_mul(u64::from(record_len))
        .and_then(|b| b.checked_add(u64::from(offset_to_points)))
        .ok_or_else(|| format!("the header claims {count} points, more than any file holds"))?;
    let compressed = bytes.get(104).is_some_and(|format| format & 0xC0 != 0);
    if !compressed && end > bytes.len() as u64 {
        return Err(format!(
            "{CUT_SHORT}: its {count} points end at byte {end}, the file at byte {}",
            bytes.len()
        ));
    }
    if compressed {
        // LASzip's chunk table: its offset (8 bytes) opens the point data, or, where the writer
        // could not go back to set it, closes the file; the table holds a version and a count.
        // Read as `laz` reads it: signed, and taken from the file's end when not past the start.
        let start = i64::from(offset_to_points);
        let signed_at = |at: u64| u64_at(at).map(|v| v as i64);
        let table = match signed_at(u64::from(offset_to_points)) {
            Some(at) if at > start => Some(at),
            Some(_) => signed_at((bytes.len() as u64).saturating_sub(8)).filter(|&at| at > start),
            None => None,
        };
        // Past the start, so not negative.
        let chunks = table.and_then(|at| u32_at((at as u64).checked_add(4)?));
        let most = bytes.len() as u64 / u64::from(record_len.max(1));
        if let Some(chunks) = chunks
            && u64::from(chunks) > most
        {
            return Err(format!(
                "its compressed points claim {chunks} chunks; a file of {} bytes holds at most {most}",
                bytes.len()
            ));
        }
        // The layers of each chunk (point formats 6–10), allocated at their stated sizes; after
        // the table's count is known to be sound, as this reads the table.
        super::laz_layers::check(bytes, u64::from(offset_to_points), count)?;
    }
    if extended {
        let start = u64_at(235).ok_or_else(cut)?;
        let records = u32_at(243).ok_or_else(cut)?;
        // The crate reads the first extended record where both are set; its length is 20 bytes in.
        let length = start.checked_add(20).and_then(u64_at);
        if start > 0
            && records > 0
            && let Some(length) = length
        {
            let room = (bytes.len() as u64).saturating_sub(start.saturating_add(60));
            if length > room {
                return Err(format!(
                    "an extended record at byte {start} claims {length} bytes; the file has {room} after it"
                ));
            }
        }
    }
    Ok(())
}

/// Each record's "withheld" flag: the point is to be treated as deleted (LAS 1.4, tables 7 and
/// 15). Bit 7 of the classification byte in point formats 0–5, bit 2 of the classification
/// flags in 6–10 (byte 15 of the record either way); `PointData` has no column for it.
fn withheld(data: &PointData) -> impl Iterator<Item = bool> + '_ {
    let mask = if data.format().is_extended {
        0b0000_0100
    } else {
        0b1000_0000
    };
    data.raw_bytes()
        .chunks_exact(data.record_len().max(1))
        .map(move |record| record.get(15).is_some_and(|&flags| flags & mask != 0))
}

/// A decoder's error as the user reads it: running out of bytes is a file cut short (the header's
/// check finds that before decoding for plain LAS, so this is LAZ's compressed points).
/// `points` is the header's count, where it was read.
fn decoding_error(error: &las::Error, points: Option<u64>) -> String {
    let io = match error {
        las::Error::Io(e) | las::Error::LasZipError(laz::LasZipError::IoError(e)) => Some(e),
        _ => None,
    };
    match (io.map(std::io::Error::kind), points) {
        (Some(std::io::ErrorKind::UnexpectedEof), Some(n)) => {
            format!("{CUT_SHORT}: its compressed points end before the {n} its header counts")
        }
        (Some(std::io::ErrorKind::UnexpectedEof), None) => {
            format!("{CUT_SHORT}: it ends before the records its header points to")
        }
        _ => error.to_string(),
    }
}

/// The points' RGB as sRGB 0–1: 16-bit values, or 8-bit ones where none exceeds 255.
fn rgb_colours(colours: &[[u16; 3]]) -> Vec<[f32; 3]> {
    let eight_bit = colours.iter().flatten().all(|&c| c <= 255);
    let full = if eight_bit { 255.0 } else { 65535.0 };
    colours.iter().map(|c| c.map(|v| f32::from(v) / full)).collect()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// `points` in a file written by the `las` crate's writer: point `format` (LAS 1.2, or 1.4
    /// for formats 6–10), LAZ-compressed (fixed chunks of 50 000 points) or not.
    pub(crate) fn written(format: u8, compressed: bool, points: impl IntoIterator<Item = las::Point>) -> Vec<u8> {
        let mut builder = las::Builder::from((1, if format >= 6 { 4 } else { 2 }));
        builder.point_format = las::point::Format::new(format).expect("format");
        builder.point_format.is_compressed = compressed;
        let header = builder.into_header().expect("header");
        let mut writer = las::Writer::new(Cursor::new(Vec::new()), header).expect("writer");
        for point in points {
            writer.write_point(point).expect("point");
        }
        writer.into_inner().expect("written").into_inner()
    }

    /// `n` points of a LAZ by [`written`]: point format 3 (point-wise compression) or 7
    /// (layered), a spiral with every 13th point noise, colour and intensity varying along it.
    pub(crate) fn laz_file(n: u32, format: u8) -> Vec<u8> {
        written(
            format,
            true,
            (0..n).map(|i| {
                let t = f64::from(i) * 1e-3;
                las::Point {
                    x: t.cos() * (1.0 + t),
                    y: t.sin() * (1.0 + t),
                    z: t * 0.1,
                    intensity: (i % 4000) as u16,
                    classification: if i % 13 == 0 {
                        las::point::Classification::LowPoint
                    } else {
                        las::point::Classification::Ground
                    },
                    color: Some(las::Color::new((i % 65536) as u16, 1000, (i / 7 % 65536) as u16)),
                    gps_time: Some(t),
                    ..las::Point::default()
                }
            }),
        )
    }

    /// Withheld points (deleted) are left out whichever way the format stores the flag: the
    /// classification byte's bit 7 (format 3) or the classification flags' bit 2 (format 7).
    #[test]
    fn withheld_points_are_left_out_in_every_format() {
        for format in [3, 7] {
            let bytes = written(
                format,
                false,
                (0..10).map(|i| las::Point {
                    x: f64::from(i),
                    y: f64::from(i % 3),
                    is_withheld: i % 4 == 1,
                    color: Some(las::Color::new(100, 100, 100)),
                    gps_time: Some(0.0),
                    ..las::Point::default()
                }),
            );
            let soup = all(bytes).unwrap();
            // Points 1, 5 and 9 withheld.
            assert_eq!(soup.positions.len(), 7, "format {format}");
        }
    }

    /// How [`recompressed`] cuts the points into chunks.
    pub(crate) enum Chunking {
        /// Chunks of these many points, then one of the rest, as COPC files have them: the
        /// chunk table holds each chunk's count.
        Variable(Vec<usize>),
        /// Chunks of this many points.
        Fixed(u32),
    }

    /// The plain (uncompressed) LAS `plain`, of no records beyond its header's, as a LAZ cut into
    /// chunks as `chunking` says, compressed by `laz`'s own compressor: the LASzip record added
    /// after the header's records, the point data's offset and the compressed flag set.
    pub(crate) fn recompressed(plain: &[u8], chunking: Chunking) -> Vec<u8> {
        let u32_at = |at: usize| u32::from_le_bytes(plain[at..at + 4].try_into().unwrap());
        let offset = u32_at(96) as usize;
        let format = plain[104];
        let record_len = usize::from(u16::from_le_bytes(plain[105..107].try_into().unwrap()));
        let records = &plain[offset..];
        assert_eq!(records.len() % record_len, 0);
        let builder = laz::LazVlrBuilder::default().with_point_format(format, 0).unwrap();
        let vlr = match &chunking {
            Chunking::Variable(_) => builder.with_variable_chunk_size(),
            Chunking::Fixed(n) => builder.with_fixed_chunk_size(*n),
        }
        .build();
        let mut payload = Vec::new();
        vlr.write_to(&mut payload).unwrap();
        let mut out = plain[..offset].to_vec();
        out.extend_from_slice(&[0; 2]);
        out.extend_from_slice(b"laszip encoded\0\0");
        out.extend_from_slice(&22204u16.to_le_bytes());
        out.extend_from_slice(&(payload.len() as u16).to_le_bytes());
        out.extend_from_slice(&[0; 32]);
        out.extend_from_slice(&payload);
        let records_at = out.len() as u32;
        out[96..100].copy_from_slice(&records_at.to_le_bytes());
        out[100..104].copy_from_slice(&(u32_at(100) + 1).to_le_bytes());
        out[104] = format | 0x80;
        let mut stream = Cursor::new(out);
        stream.set_position(u64::from(records_at));
        let mut compressor = laz::LasZipCompressor::new(stream, vlr).unwrap();
        match chunking {
            Chunking::Variable(counts) => {
                let mut at = 0usize;
                for n in counts {
                    let end = records.len().min(at + n * record_len);
                    compressor.compress_many(&records[at..end]).unwrap();
                    compressor.finish_current_chunk().unwrap();
                    at = end;
                }
                // The rest: `done` ends the last chunk.
                compressor.compress_many(&records[at..]).unwrap();
            }
            Chunking::Fixed(_) => compressor.compress_many(records).unwrap(),
        }
        compressor.done().unwrap();
        compressor.into_inner().into_inner()
    }

    /// LAZ files of chunks cut other ways than the `las` writer's (variable-sized, as COPC writes
    /// them, and fixed chunks of 1 000): decoded in parallel and in order, every point as in the
    /// plain file, point-wise (format 3) and layered (format 6).
    #[test]
    fn chunks_of_every_size_decode_alike() {
        for format in [3u8, 6] {
            let plain = written(
                format,
                false,
                (0..5_000u32).map(|i| {
                    let t = f64::from(i) * 1e-2;
                    las::Point {
                        x: t.cos(),
                        y: t.sin(),
                        z: t * 0.01,
                        intensity: (i % 1000) as u16,
                        color: (format == 3).then(|| las::Color::new((i * 13) as u16, 7, 9)),
                        gps_time: Some(t),
                        ..las::Point::default()
                    }
                }),
            );
            let expected = all(plain.clone()).unwrap();
            assert_eq!(expected.positions.len(), 5_000);
            for (chunking, counts) in [
                (
                    Chunking::Variable(vec![1_000, 2_500, 700]),
                    vec![1_000, 2_500, 700, 800],
                ),
                (Chunking::Fixed(1_000), vec![1_000; 5]),
            ] {
                let laz = recompressed(&plain, chunking);
                let offset = u64::from(u32::from_le_bytes(laz[96..100].try_into().unwrap()));
                let plan = laz_chunks::plan(
                    &laz,
                    offset,
                    5_000,
                    usize::from(u16::from_le_bytes(laz[105..107].try_into().unwrap())),
                )
                .expect("a trusted chunk table");
                assert_eq!(
                    plan.chunks.iter().map(|c| c.points).collect::<Vec<_>>(),
                    counts,
                    "format {format}"
                );
                for in_parallel in [true, false] {
                    let soup = decode(laz.clone(), RAW_POINTS_KEPT, |_| true, in_parallel)
                        .unwrap()
                        .unwrap();
                    assert_eq!(
                        soup.positions, expected.positions,
                        "format {format}, {counts:?}, parallel {in_parallel}"
                    );
                    assert_eq!(soup.colors, expected.colors, "format {format}, {counts:?}");
                }
                assert_eq!(check_header(&laz), Ok(()));
            }
        }
    }

    /// 60 points on a helix as a plain LAS 1.4 in point format 6 (layered when compressed): the
    /// points of `chunked-60.laz`.
    fn helix_60() -> Vec<u8> {
        written(
            6,
            false,
            (0..60u32).map(|i| {
                let t = f64::from(i) * 0.3;
                las::Point {
                    x: t.cos(),
                    y: t.sin(),
                    z: t * 0.05,
                    intensity: (i * 1000) as u16,
                    gps_time: Some(t),
                    ..las::Point::default()
                }
            }),
        )
    }

    /// Writes `tests/data/las/chunked-60.laz` (kept in the repository: a regression input and a
    /// fuzz seed whose chunks are several and variable-sized).
    #[test]
    #[ignore = "writes a file kept in the repository; run by hand to make it again"]
    fn write_chunked_60() {
        let laz = recompressed(&helix_60(), Chunking::Variable(vec![20, 25]));
        std::fs::write(
            concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/las/chunked-60.laz"),
            laz,
        )
        .unwrap();
    }

    /// `chunked-60.laz` (written once by `write_chunked_60`): three variable-sized chunks of 20,
    /// 25 and 15 points, decoded in parallel and in order to the plain file's points.
    #[test]
    fn a_kept_file_of_variable_chunks_decodes_alike() {
        let laz = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/las/chunked-60.laz")).unwrap();
        let offset = u64::from(u32::from_le_bytes(laz[96..100].try_into().unwrap()));
        let plan = laz_chunks::plan(&laz, offset, 60, 30).expect("a trusted chunk table");
        assert_eq!(plan.chunks.iter().map(|c| c.points).collect::<Vec<_>>(), [20, 25, 15]);
        let expected = all(helix_60()).unwrap();
        for in_parallel in [true, false] {
            let soup = decode(laz.clone(), RAW_POINTS_KEPT, |_| true, in_parallel)
                .unwrap()
                .unwrap();
            assert_eq!(soup.positions, expected.positions, "parallel {in_parallel}");
        }
    }

    /// Decoding a LAZ's chunks on several threads gives exactly the points (and the progress
    /// and stopping) of decoding it in order: point-wise and layered, several chunks with the
    /// last one short, a stride (7) that does not divide the chunks, and the reference encoder's file.
    #[test]
    fn chunks_decoded_in_parallel_are_the_points_decoded_in_order() {
        let reference = std::fs::read(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/data/las/reference-sphere-200-feet.laz"
        ))
        .unwrap();
        for (what, bytes, most) in [
            ("format 3", laz_file(120_001, 3), RAW_POINTS_KEPT),
            ("format 7", laz_file(120_001, 7), 17_143),
            ("reference", reference, RAW_POINTS_KEPT),
        ] {
            let offset = u64::from(u32::from_le_bytes(bytes[96..100].try_into().unwrap()));
            let header = las::Header::new(Cursor::new(&bytes[..])).unwrap();
            let record_len = usize::from(header.point_format().len());
            let plan = laz_chunks::plan(&bytes, offset, header.number_of_points(), record_len)
                .unwrap_or_else(|| panic!("{what}: a trusted chunk table"));
            let expected_chunks = header.number_of_points().div_ceil(50_000) as usize;
            assert_eq!(plan.chunks.len(), expected_chunks, "{what}");
            let mut shares = (Vec::new(), Vec::new());
            let mut run = |in_parallel: bool| {
                let seen = if in_parallel { &mut shares.0 } else { &mut shares.1 };
                decode(
                    bytes.clone(),
                    most,
                    |share| {
                        seen.push(share);
                        true
                    },
                    in_parallel,
                )
                .unwrap()
                .unwrap()
            };
            let (parallel, in_order) = (run(true), run(false));
            assert!(!parallel.positions.is_empty(), "{what}");
            assert_eq!(parallel.positions, in_order.positions, "{what}");
            assert_eq!(parallel.colors, in_order.colors, "{what}");
            assert_eq!(shares.0.last(), Some(&1.0), "{what}: {:?}", shares.0);
            assert!(shares.0.windows(2).all(|w| w[0] < w[1]), "{what}: {:?}", shares.0);
            assert!(
                decode(bytes.clone(), most, |_| false, true).unwrap().is_none(),
                "{what}"
            );
        }
    }

    /// A LAS 1.2 file written byte by byte from the specification (not by the crate that reads
    /// it): point format 2 (with RGB) or 0, `scale` and `offset` per axis, each point's integer
    /// coordinates, class, intensity and colour.
    pub(crate) fn las_bytes(
        with_rgb: bool,
        scale: [f64; 3],
        offset: [f64; 3],
        points: &[([i32; 3], u8, u16, [u16; 3])],
    ) -> Vec<u8> {
        let record_len: u16 = if with_rgb { 26 } else { 20 };
        let mut b = Vec::new();
        b.extend_from_slice(b"LASF");
        b.extend_from_slice(&[0; 4]); // file source id, global encoding
        b.extend_from_slice(&[0; 16]); // project GUID
        b.extend_from_slice(&[1, 2]); // version 1.2
        b.extend_from_slice(&[0; 64]); // system identifier, generating software
        b.extend_from_slice(&[1, 0, 0xEA, 0x07]); // day 1 of 2026
        b.extend_from_slice(&227u16.to_le_bytes()); // header size
        b.extend_from_slice(&227u32.to_le_bytes()); // offset to point data
        b.extend_from_slice(&0u32.to_le_bytes()); // variable-length records
        b.push(if with_rgb { 2 } else { 0 });
        b.extend_from_slice(&record_len.to_le_bytes());
        b.extend_from_slice(&(points.len() as u32).to_le_bytes());
        b.extend_from_slice(&(points.len() as u32).to_le_bytes()); // first returns
        b.extend_from_slice(&[0; 16]); // other returns
        for s in scale {
            b.extend_from_slice(&s.to_le_bytes());
        }
        for o in offset {
            b.extend_from_slice(&o.to_le_bytes());
        }
        for k in 0..3 {
            let world = |p: &([i32; 3], u8, u16, [u16; 3])| f64::from(p.0[k]) * scale[k] + offset[k];
            let max = points.iter().map(world).fold(f64::NEG_INFINITY, f64::max);
            let min = points.iter().map(world).fold(f64::INFINITY, f64::min);
            b.extend_from_slice(&max.to_le_bytes());
            b.extend_from_slice(&min.to_le_bytes());
        }
        assert_eq!(b.len(), 227);
        for (xyz, class, intensity, rgb) in points {
            for v in xyz {
                b.extend_from_slice(&v.to_le_bytes());
            }
            b.extend_from_slice(&intensity.to_le_bytes());
            b.push(0b0000_1001); // return 1 of 1
            b.push(*class);
            b.extend_from_slice(&[0, 0, 0, 0]); // scan angle, user data, point source id
            if with_rgb {
                for c in rgb {
                    b.extend_from_slice(&c.to_le_bytes());
                }
            }
        }
        b
    }

    fn all(bytes: Vec<u8>) -> Result<Soup, String> {
        parse(bytes, |_| true).map(|s| s.expect("not stopped"))
    }

    #[test]
    fn georeferenced_millimetres_survive_and_colours_are_read() {
        // 500 km east, 4000 km north, millimetre steps: f32 alone would round to 0.25 / 0.5 m.
        let points = [
            ([0, 0, 0], 1, 100, [65535, 0, 0]),
            ([1, 2, 3], 2, 200, [0, 32768, 0]),
            ([1000, 1000, 1000], 2, 300, [0, 0, 65535]),
        ];
        let soup = all(las_bytes(true, [0.001; 3], [500_000.0, 4_000_000.0, 100.0], &points)).unwrap();
        assert_eq!(soup.positions.len(), 3);
        let d = |a: usize, b: usize, k: usize| soup.positions[b][k] - soup.positions[a][k];
        for (k, want) in [0.001f32, 0.002, 0.003].into_iter().enumerate() {
            assert!((d(0, 1, k) - want).abs() < 1e-6, "axis {k}: {}", d(0, 1, k));
        }
        // About the bounds' centre.
        assert!((soup.positions[0][0] + 0.5).abs() < 1e-6 && (soup.positions[2][2] - 0.5).abs() < 1e-6);
        let colors = soup.colors.expect("format 2 has RGB");
        assert_eq!(colors[0], [1.0, 0.0, 0.0, 1.0]);
        assert!((colors[1][1] - 0.5).abs() < 1e-4);
        assert!(soup.indices.is_empty() && soup.normals.is_none());
    }

    #[test]
    fn eight_bit_colours_in_sixteen_bit_fields_are_taken_as_eight_bit() {
        let points = [([0, 0, 0], 1, 0, [255, 128, 0]), ([1, 0, 0], 1, 0, [0, 0, 255])];
        let colors = all(las_bytes(true, [0.01; 3], [0.0; 3], &points))
            .unwrap()
            .colors
            .unwrap();
        assert_eq!(colors[0][0], 1.0);
        assert!((colors[0][1] - 128.0 / 255.0).abs() < 1e-6);
        assert_eq!(colors[1][2], 1.0);
    }

    #[test]
    fn without_colour_the_intensity_shades_the_points_and_noise_is_left_out() {
        // 200 points of intensity 1000 and one glint of 60000: the glint does not set white.
        let mut points: Vec<([i32; 3], u8, u16, [u16; 3])> =
            (0..200).map(|i| ([i, i % 7, 0], 2, 1000, [0; 3])).collect();
        points.push(([5, 5, 5], 1, 60000, [0; 3]));
        points.push(([6, 6, 6], 1, 250, [0; 3])); // a quarter of white, as linear albedo
        points.push(([9000, 9000, 9000], 7, 500, [0; 3])); // low noise, far away
        points.push(([-9000, 0, 0], 18, 500, [0; 3])); // high noise
        points.push(([0, -9000, 0], 0x80 | 2, 500, [0; 3])); // ground, but withheld (deleted)
        let soup = all(las_bytes(false, [0.01; 3], [0.0; 3], &points)).unwrap();
        assert_eq!(
            soup.positions.len(),
            202,
            "the two noise points and the withheld one are left out"
        );
        let colors = soup.colors.expect("greys from the intensity");
        assert!(
            (colors[0][0] - 1.0).abs() < 1e-6,
            "the 99th percentile is white: {:?}",
            colors[0]
        );
        assert!((colors[200][0] - 1.0).abs() < 1e-6, "brighter than that is clipped");
        let quarter = colors[201][0];
        assert!((quarter - 0.537).abs() < 0.002, "linear 0.25 is sRGB 0.537: {quarter}");
        // Colour fields left at zero are no colour: the intensity shades the points.
        let unfilled = all(las_bytes(true, [0.01; 3], [0.0; 3], &points)).unwrap();
        assert_eq!(unfilled.colors.as_ref(), Some(&colors));
        // Without intensities either: no colours at all.
        let dark: Vec<_> = points.iter().map(|&(p, c, _, rgb)| (p, c, 0, rgb)).collect();
        assert!(
            all(las_bytes(false, [0.01; 3], [0.0; 3], &dark))
                .unwrap()
                .colors
                .is_none()
        );
    }

    #[test]
    fn a_large_cloud_is_strided_to_the_points_kept() {
        let points: Vec<_> = (0..1000).map(|i| ([i, 0, i % 3], 1, 10, [0; 3])).collect();
        let bytes = las_bytes(false, [0.01; 3], [0.0; 3], &points);
        // At most 100 of 1000: every tenth, from the first.
        let strided = parse_keeping(bytes.clone(), 100, |_| true).unwrap().unwrap();
        assert_eq!(strided.positions.len(), 100);
        let x0 = strided.positions[0][0];
        assert!(
            (strided.positions[1][0] - x0 - 0.1).abs() < 1e-5,
            "{:?}",
            &strided.positions[..2]
        );
        // Within RAW_POINTS_KEPT the file is read whole, and the work can be stopped.
        assert_eq!(all(bytes.clone()).unwrap().positions.len(), 1000);
        assert!(parse(bytes, |_| false).unwrap().is_none());
    }

    #[test]
    fn damaged_files_are_errors() {
        let points: Vec<_> = (0..10).map(|i| ([i, 0, 0], 1, 10, [0; 3])).collect();
        let good = las_bytes(true, [0.01; 3], [0.0; 3], &points);
        // Cut inside the points, the header's count is more than the file holds.
        assert!(all(good[..good.len() - 13].to_vec()).is_err());
        // Cut inside the header.
        assert!(all(good[..100].to_vec()).is_err());
        // No points, and only noise.
        assert_eq!(all(las_bytes(true, [0.01; 3], [0.0; 3], &[])).unwrap_err(), "no points");
        let noise: Vec<_> = (0..10).map(|i| ([i, 0, 0], 7, 10, [0; 3])).collect();
        assert!(
            all(las_bytes(true, [0.01; 3], [0.0; 3], &noise))
                .unwrap_err()
                .contains("noise")
        );
        // A scale that is not a number.
        let nan = las_bytes(true, [f64::NAN, 0.01, 0.01], [0.0; 3], &points);
        assert!(all(nan).is_err());
    }

    /// `bytes` (a LAS 1.2 file of [`las_bytes`]) as LAS 1.4: its header grown to 375 bytes, with
    /// `count` as the 64-bit point count (the legacy one zero) and, where given, an extended
    /// record after the points that states `evlr_length` bytes.
    fn as_las_1_4(bytes: &[u8], count: u64, evlr_length: Option<u64>) -> Vec<u8> {
        let mut b = bytes[..227].to_vec();
        b[25] = 4;
        b[94..96].copy_from_slice(&375u16.to_le_bytes());
        b[96..100].copy_from_slice(&375u32.to_le_bytes());
        b[107..111].copy_from_slice(&0u32.to_le_bytes());
        b[111..131].copy_from_slice(&[0; 20]);
        let points = &bytes[227..];
        let evlr_at = 375 + points.len() as u64;
        b.extend_from_slice(&0u64.to_le_bytes()); // waveform data
        b.extend_from_slice(&evlr_length.map_or(0, |_| evlr_at).to_le_bytes());
        b.extend_from_slice(&u32::from(evlr_length.is_some()).to_le_bytes());
        b.extend_from_slice(&count.to_le_bytes());
        b.extend_from_slice(&[0; 120]); // points by return
        assert_eq!(b.len(), 375);
        b.extend_from_slice(points);
        if let Some(length) = evlr_length {
            b.extend_from_slice(&[0; 20]); // reserved, user id, record id
            b.extend_from_slice(&length.to_le_bytes());
            b.extend_from_slice(&[0; 32]); // description
            b.extend_from_slice(&[7; 16]); // 16 bytes of data
        }
        b
    }

    #[test]
    fn hostile_headers_are_errors_not_aborts() {
        let points: Vec<_> = (0..10).map(|i| ([i, 0, 0], 1, 10, [0; 3])).collect();
        let v12 = las_bytes(true, [0.01; 3], [0.0; 3], &points);
        // The same file as LAS 1.4 reads alike, with or without an honest extended record.
        assert_eq!(all(as_las_1_4(&v12, 10, None)).unwrap().positions.len(), 10);
        assert_eq!(all(as_las_1_4(&v12, 10, Some(16))).unwrap().positions.len(), 10);
        // An extended record stating far more than the file holds: the crate would allocate it.
        let err = all(as_las_1_4(&v12, 10, Some(1 << 60))).unwrap_err();
        assert!(err.contains("extended record"), "{err}");
        // A point count whose records' end overflows 64 bits.
        let err = all(as_las_1_4(&v12, u64::MAX / 8, None)).unwrap_err();
        assert!(err.contains("more than any file holds"), "{err}");
        // An extended record placed at the very end of the address space: no field there.
        let mut far = as_las_1_4(&v12, 10, Some(16));
        far[235..243].copy_from_slice(&(u64::MAX - 25).to_le_bytes());
        assert!(all(far).is_err());
    }

    #[test]
    fn a_laz_chunk_table_claiming_more_chunks_than_the_file_holds_is_an_error() {
        let laz = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/las/sphere-50.laz")).unwrap();
        assert_eq!(all(laz.clone()).unwrap().positions.len(), 50);
        let points_at = u32::from_le_bytes(laz[96..100].try_into().unwrap()) as usize;
        let table = i64::from_le_bytes(laz[points_at..points_at + 8].try_into().unwrap()) as usize;
        let mut forged = laz.clone();
        forged[table + 4..table + 8].copy_from_slice(&0x7fff_ffffu32.to_le_bytes());
        let err = all(forged.clone()).unwrap_err();
        assert!(err.contains("chunks"), "{err}");
        // The same table found through the file's last 8 bytes, where a writer that could not
        // go back puts its offset (the first one then negative).
        let mut from_the_end = forged;
        from_the_end[points_at..points_at + 8].copy_from_slice(&(-1i64).to_le_bytes());
        from_the_end.extend_from_slice(&(table as i64).to_le_bytes());
        let err = all(from_the_end).unwrap_err();
        assert!(err.contains("chunks"), "{err}");
    }

    /// A layered LAZ (point format 7) whose first chunk's first layer claims 4 GiB: refused
    /// before the decoder allocates it (without the check, 4 GiB is allocated and the read then
    /// fails as a file cut short). The fuzzer's input that took 1.5 GiB likewise.
    #[test]
    fn a_laz_layer_claiming_more_than_the_file_holds_is_an_error() {
        let laz = std::fs::read(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/data/las/reference-sphere-200.laz"
        ))
        .unwrap();
        assert_eq!(all(laz.clone()).unwrap().positions.len(), 200);
        let points_at = u32::from_le_bytes(laz[96..100].try_into().unwrap()) as usize;
        // After the table's offset (8), the first point stored whole (36) and the count (4).
        let sizes_at = points_at + 8 + 36 + 4;
        let mut forged = laz;
        forged[sizes_at..sizes_at + 4].copy_from_slice(&0xFFFF_FFF0u32.to_le_bytes());
        let err = all(forged).unwrap_err();
        assert!(err.contains("claims layers of"), "{err}");
        let found = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/las/huge-layer.laz")).unwrap();
        let err = all(found).unwrap_err();
        assert!(err.contains("claims layers of"), "{err}");
    }

    #[test]
    fn a_damaged_chunk_table_that_panicked_the_decoder_is_an_error() {
        let found = std::fs::read(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/data/las/damaged-chunk-table.laz"
        ))
        .unwrap();
        let err = all(found).unwrap_err();
        assert!(err.contains("damaged"), "{err}");
    }

    #[test]
    fn a_las_file_is_recognised_by_its_signature() {
        assert!(recognises(&las_bytes(true, [0.01; 3], [0.0; 3], &[])));
        assert!(!recognises(b"ply\nformat ascii 1.0\n"));
    }
}
