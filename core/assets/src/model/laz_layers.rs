//! A check of a LAZ file's layered chunks before the `laz` decoder reads them. LASzip stores the
//! points of LAS 1.4's formats 6–10 in chunks of layers (one a field: positions, intensities,
//! colours…, item versions 3 and 4): a chunk is its first point stored whole, its point count,
//! the byte size of each layer, then the layers. The decoder allocates each layer's buffer at its
//! stated size before it reads the layer, so one damaged size (a download gone wrong, or a
//! hostile file) asks for up to 4 GiB a layer: found by fuzzing, 1.5 GiB from a file of 3.7 kB.
//!
//! [`check`] walks the chunks as the decoder will read them (in order, each right after the one
//! before; the chunk table is not needed) and refuses a chunk whose layers would run past the
//! end of the file. What it does not refuse costs at most the file's length a layer. Files of
//! the older, point-wise formats (0–5, item versions 1 and 2) allocate nothing by the stream's
//! word and pass unchecked.
//!
//! **Panics**: none (every read and sum is checked). Cost: a few bytes read a chunk.

use laz::laszip::ChunkTable;
use laz::{LazItemType, LazVlr};

use super::le_fields;

/// The LASzip record's user and number.
const LASZIP_USER: &[u8] = b"laszip encoded";
const LASZIP_RECORD: u16 = 22204;

/// Refuses (with the reason) a LAZ whose layered chunks claim layers longer than what follows
/// them in `bytes`. `offset_to_points` and `points` are the header's; the LASzip record is found
/// among the header's records. A file that is not layered, or whose records do not parse (the
/// decoder's to report), passes. **Important**: the chunk table's count must have been checked
/// against the file's length first (`las::check_header`): the table is read here, and `laz`
/// allocates it at the count it states.
pub fn check(bytes: &[u8], offset_to_points: u64, points: u64) -> Result<(), String> {
    let Some(vlr) = laszip_record(bytes) else {
        return Ok(());
    };
    let Some(layout) = layout(vlr.items()) else {
        return Ok(());
    };
    let len = bytes.len() as u64;
    // Variable-sized chunks hold the counts the chunk table gives, as the decoder reads them
    // (each chunk's own count only where the table cannot be read).
    let table: Option<Vec<u64>> = if vlr.uses_variable_size_chunks() {
        let mut source = std::io::Cursor::new(bytes);
        source.set_position(offset_to_points);
        ChunkTable::read_from(&mut source, &vlr)
            .ok()
            .map(|table| table.as_ref().iter().map(|entry| entry.point_count).collect())
    } else {
        None
    };
    // The chunk table's offset (8 bytes) opens the point data.
    let mut at = offset_to_points.saturating_add(8);
    let mut left = points;
    let mut chunk = 0usize;
    while left > 0 {
        let end = match chunk_end(bytes, at, layout, len) {
            ChunkEnd::Fits(end) => end,
            // The decoder fails reading these, before it allocates a layer.
            ChunkEnd::SizesCut => return Ok(()),
            ChunkEnd::Overruns { claimed, room } => {
                return Err(format!(
                    "its compressed chunk at byte {at} claims layers of {claimed} bytes; the file has {room} after them"
                ));
            }
        };
        // A chunk holds the record's chunk size, or (variable-sized chunks) the table's count
        // for it, else its own.
        let in_chunk = match &table {
            _ if !vlr.uses_variable_size_chunks() => u64::from(vlr.chunk_size()),
            Some(counts) => counts.get(chunk).copied().unwrap_or(0),
            None => le_fields::u32_at(bytes, at.saturating_add(layout.first_point)).map_or(0, u64::from),
        };
        at = end;
        chunk += 1;
        left = left.saturating_sub(in_chunk.max(1));
    }
    Ok(())
}

/// A layered chunk's shape: the bytes of its first point stored whole and its number of layers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layout {
    pub first_point: u64,
    pub layers: u64,
}

/// Where a layered chunk's layers end, by its stated sizes.
#[derive(Debug, PartialEq)]
pub enum ChunkEnd {
    /// At this byte, within the limit.
    Fits(u64),
    /// The sizes themselves run past the limit.
    SizesCut,
    /// The layers claim more than the limit leaves after the sizes.
    Overruns { claimed: u64, room: u64 },
}

/// Where the layers of the chunk at `at` end, read from `bytes` no further than `limit` (at most
/// `bytes`' length).
pub fn chunk_end(bytes: &[u8], at: u64, layout: Layout, limit: u64) -> ChunkEnd {
    let limit = limit.min(bytes.len() as u64);
    // Its first point, its point count (4), then a size (4) a layer.
    let sizes_at = at.saturating_add(layout.first_point).saturating_add(4);
    let sizes_end = sizes_at.saturating_add(layout.layers.saturating_mul(4));
    if sizes_end > limit {
        return ChunkEnd::SizesCut;
    }
    let claimed = (0..layout.layers)
        .map(|k| le_fields::u32_at(bytes, sizes_at + 4 * k).map_or(0, u64::from))
        .fold(0u64, u64::saturating_add);
    let room = limit - sizes_end;
    if claimed > room {
        ChunkEnd::Overruns { claimed, room }
    } else {
        ChunkEnd::Fits(sizes_end + claimed)
    }
}

/// The LASzip record among the header's records (not the extended ones, which LASzip does not
/// use), parsed by `laz`.
pub fn laszip_record(bytes: &[u8]) -> Option<LazVlr> {
    let mut at = usize::from(le_fields::u16_at(bytes, 94)?);
    let records = le_fields::u32_at(bytes, 100)?;
    for _ in 0..records {
        // A record's header: reserved (2), user (16), number (2), length (2), description (32).
        let user = bytes.get(at.checked_add(2)?..at.checked_add(18)?)?;
        let number = le_fields::u16_at(bytes, at as u64 + 18)?;
        let length = usize::from(le_fields::u16_at(bytes, at as u64 + 20)?);
        let data_at = at.checked_add(54)?;
        let data = bytes.get(data_at..data_at.checked_add(length)?)?;
        let user_end = user.iter().position(|&b| b == 0).unwrap_or(user.len());
        if &user[..user_end] == LASZIP_USER && number == LASZIP_RECORD {
            return LazVlr::from_buffer(data).ok();
        }
        at = data_at + length;
    }
    None
}

/// The shape of a chunk of `items`, where they are layered (versions 3 and 4, as the decoder
/// chooses by the first item); `None` for point-wise ones. The sizes are the decoder's own for
/// each field, not the record's word for them.
pub fn layout(items: &[laz::LazItem]) -> Option<Layout> {
    if !matches!(items.first()?.version(), 3 | 4) {
        return None;
    }
    items.iter().try_fold(
        Layout {
            first_point: 0,
            layers: 0,
        },
        |sum, item| {
            let (first_point, layers) = match item.item_type() {
                LazItemType::Point14 => (30, 9),
                LazItemType::RGB14 => (6, 1),
                LazItemType::RGBNIR14 => (8, 2),
                LazItemType::WavePacket14 => (29, 1),
                LazItemType::Byte14(n) => (u64::from(n), u64::from(n)),
                // Not a layered item: the decoder refuses the file.
                _ => return None,
            };
            Some(Layout {
                first_point: sum.first_point + first_point,
                layers: sum.layers + layers,
            })
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn test_data(file: &str) -> Vec<u8> {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data/las")
            .join(file);
        std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
    }

    fn header(bytes: &[u8]) -> (u64, u64) {
        let offset = u64::from(u32::from_le_bytes(bytes[96..100].try_into().unwrap()));
        let legacy = u32::from_le_bytes(bytes[107..111].try_into().unwrap());
        let count = if legacy > 0 {
            u64::from(legacy)
        } else {
            u64::from_le_bytes(bytes[247..255].try_into().unwrap())
        };
        (offset, count)
    }

    /// The reference LASzip's layered files (point format 7: a Point14 and an RGB14 item, ten
    /// layers) pass, and the chunk is where the walk finds it.
    #[test]
    fn layered_files_from_the_reference_encoder_pass() {
        for file in ["reference-sphere-200.laz", "reference-sphere-200-feet.laz"] {
            let bytes = test_data(file);
            let (offset, count) = header(&bytes);
            assert_eq!(count, 200);
            let vlr = laszip_record(&bytes).expect("the LASzip record");
            assert_eq!(
                layout(vlr.items()),
                Some(Layout {
                    first_point: 36,
                    layers: 10
                }),
                "{file}"
            );
            assert_eq!(check(&bytes, offset, count), Ok(()), "{file}");
        }
        // Point-wise (format 2): nothing to check.
        let bytes = test_data("sphere-50.laz");
        let vlr = laszip_record(&bytes).expect("the LASzip record");
        assert_eq!(layout(vlr.items()), None);
    }

    /// One layer's size made huge (as the fuzzer found, which then took 1.5 GiB): refused.
    #[test]
    fn a_layer_longer_than_the_file_is_refused() {
        let bytes = test_data("reference-sphere-200.laz");
        let (offset, count) = header(&bytes);
        let sizes_at = (offset + 8 + 36 + 4) as usize;
        for layer in [0, 4, 9] {
            let mut damaged = bytes.clone();
            damaged[sizes_at + 4 * layer..sizes_at + 4 * layer + 4].copy_from_slice(&0xFFFF_FFF0u32.to_le_bytes());
            let err = check(&damaged, offset, count).unwrap_err();
            assert!(err.contains("claims layers of"), "{err}");
        }
        // The fuzzer's input itself (the reference file in feet with its points overwritten by
        // part of its coordinate system's text).
        let found = test_data("huge-layer.laz");
        let (offset, count) = header(&found);
        assert!(check(&found, offset, count).is_err());
    }

    /// A file cut inside its chunk's sizes, or without a LASzip record, passes: the decoder
    /// reports it without allocating by its word.
    #[test]
    fn what_the_decoder_fails_on_first_passes() {
        let bytes = test_data("reference-sphere-200.laz");
        let (offset, count) = header(&bytes);
        let cut = &bytes[..(offset + 8 + 36 + 10) as usize];
        assert_eq!(check(cut, offset, count), Ok(()));
        assert_eq!(check(&bytes[..120], offset, count), Ok(()));
    }
}
