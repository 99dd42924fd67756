//! A LAZ file's chunks decoded on several threads. LASzip compresses points in chunks (50 000
//! points each by default) that decode independently of one another, and its chunk table says
//! where each begins; decoding was most of a big scan's load (58 % of a 5-million-point file's,
//! on one thread), and phones have six to eight cores.
//!
//! * **Trust**: [`plan`] takes the chunk table only where it agrees with the file: every chunk
//!   within the bytes after the point data's start, their points adding up to the header's count,
//!   each chunk's decoded records within [`CHUNK_BYTES`], and each layered chunk's layers
//!   within its own bytes (`laz_layers`: the decoder allocates them at their stated sizes). Any
//!   doubt gives `None`, and the file is read by the sequential decoder, as it always was.
//! * **Memory**: [`decode`] holds the decoded records of one chunk a thread (at most
//!   [`CHUNK_BYTES`] each); the caller keeps what it picks from them.
//!
//! **Threading**: [`decode`] is called from `crate::parallel::map`, a chunk an item; each call
//! is independent. **Panics**: none of its own; the decoder's on damaged data propagate to the
//! caller, which catches them (`las`).

use laz::LazVlr;
use laz::laszip::{ChunkTable, ChunkTableEntry};

use super::las::CHUNK_BYTES;
use super::laz_layers::{self, ChunkEnd};

/// One chunk: its bytes in the file and its points' place among the file's.
#[derive(Debug, Clone, PartialEq)]
pub struct Chunk {
    pub start: usize,
    pub byte_count: usize,
    pub points: u64,
    /// The index (in the file) of its first point.
    pub first_index: u64,
}

/// The chunks of a LAZ file and how to decode them (see the module docs).
#[derive(Debug)]
pub struct Plan {
    vlr: LazVlr,
    pub chunks: Vec<Chunk>,
    /// The bytes of one decoded record (the header's record length).
    record_len: usize,
}

/// The chunks of the LAZ in `bytes`, where its chunk table can be trusted (see the module docs);
/// `offset_to_points`, `points` and `record_len` are the header's.
pub fn plan(bytes: &[u8], offset_to_points: u64, points: u64, record_len: usize) -> Option<Plan> {
    let vlr = laz_layers::laszip_record(bytes)?;
    let items_len: u64 = vlr.items().iter().map(|item| u64::from(item.size())).sum();
    if items_len == 0 || items_len != record_len as u64 {
        return None;
    }
    let most_points = (CHUNK_BYTES / record_len) as u64;
    let mut source = std::io::Cursor::new(bytes);
    source.set_position(offset_to_points);
    let table = ChunkTable::read_from(&mut source, &vlr).ok()?;
    let layout = laz_layers::layout(vlr.items());
    let len = bytes.len() as u64;
    // The chunk table's offset (8 bytes) opens the point data.
    let mut at = offset_to_points.checked_add(8)?;
    let mut first_index = 0u64;
    let mut chunks = Vec::with_capacity(table.len());
    for entry in table.as_ref() {
        // Fixed-size chunks: the table's counts are the chunk size; the last holds the rest.
        let in_chunk = if vlr.uses_variable_size_chunks() {
            entry.point_count
        } else {
            u64::from(vlr.chunk_size()).min(points.checked_sub(first_index)?)
        };
        let end = at.checked_add(entry.byte_count)?;
        if in_chunk == 0 || in_chunk > most_points || entry.byte_count == 0 || end > len {
            return None;
        }
        if let Some(layout) = layout
            && !matches!(laz_layers::chunk_end(bytes, at, layout, end), ChunkEnd::Fits(_))
        {
            return None;
        }
        chunks.push(Chunk {
            start: usize::try_from(at).ok()?,
            byte_count: usize::try_from(entry.byte_count).ok()?,
            points: in_chunk,
            first_index,
        });
        first_index += in_chunk;
        at = end;
    }
    (first_index == points).then_some(Plan {
        vlr,
        chunks,
        record_len,
    })
}

/// The decoded records of `chunk` of `plan`'s file, `bytes`.
pub fn decode(plan: &Plan, bytes: &[u8], chunk: &Chunk) -> Result<Vec<u8>, laz::LasZipError> {
    // Within CHUNK_BYTES (`plan`).
    let mut records = vec![0u8; chunk.points as usize * plan.record_len];
    let entry = ChunkTableEntry {
        point_count: chunk.points,
        byte_count: chunk.byte_count as u64,
    };
    // One chunk: decoded on this thread.
    laz::par_decompress(
        &bytes[chunk.start..chunk.start + chunk.byte_count],
        &mut records,
        &plan.vlr,
        &[entry],
    )?;
    Ok(records)
}

#[cfg(test)]
mod tests {
    use super::super::las::tests::laz_file;
    use super::*;

    fn header(bytes: &[u8]) -> (u64, u64, usize) {
        let header = las::Header::new(std::io::Cursor::new(bytes)).unwrap();
        let offset = u64::from(u32::from_le_bytes(bytes[96..100].try_into().unwrap()));
        (
            offset,
            header.number_of_points(),
            usize::from(header.point_format().len()),
        )
    }

    /// Three chunks of 50 000, 50 000 and 20 001 points, one after the other from the point
    /// data's start, for both kinds of compression.
    #[test]
    fn the_chunks_follow_the_table() {
        for format in [3, 7] {
            let bytes = laz_file(120_001, format);
            let (offset, points, record_len) = header(&bytes);
            let plan = plan(&bytes, offset, points, record_len).expect("trusted");
            let counts: Vec<(u64, u64)> = plan.chunks.iter().map(|c| (c.points, c.first_index)).collect();
            assert_eq!(
                counts,
                [(50_000, 0), (50_000, 50_000), (20_001, 100_000)],
                "format {format}"
            );
            assert_eq!(plan.chunks[0].start as u64, offset + 8);
            for pair in plan.chunks.windows(2) {
                assert_eq!(pair[0].start + pair[0].byte_count, pair[1].start);
            }
            let records = decode(&plan, &bytes, &plan.chunks[2]).expect("decoded");
            assert_eq!(records.len(), 20_001 * record_len);
        }
    }

    /// A table that disagrees with the header or the file is not trusted (the sequential
    /// decoder then reads the file, or reports it).
    #[test]
    fn a_table_that_disagrees_is_not_trusted() {
        let bytes = laz_file(120_001, 7);
        let (offset, points, record_len) = header(&bytes);
        assert!(plan(&bytes, offset, points, record_len).is_some());
        // More points than the chunks hold, or fewer (fixed-size chunks do not store their
        // counts: a count off by less than a chunk's is seen only by the decoder, which then
        // runs out of bytes, in order or not).
        assert!(plan(&bytes, offset, points + 50_000, record_len).is_none());
        assert!(plan(&bytes, offset, points - 30_000, record_len).is_none());
        // Records of another length than the compressed items'.
        assert!(plan(&bytes, offset, points, record_len + 1).is_none());
        // Cut short: the table (at the end) is gone, and the chunks run past the end.
        assert!(plan(&bytes[..bytes.len() - 100], offset, points, record_len).is_none());
        // A layer of the second chunk claiming more than its chunk holds.
        let second = plan(&bytes, offset, points, record_len).unwrap().chunks[1].start;
        let mut damaged = bytes.clone();
        let sizes_at = second + 36 + 4;
        damaged[sizes_at..sizes_at + 4].copy_from_slice(&0x00FF_FFFFu32.to_le_bytes());
        assert!(plan(&damaged, offset, points, record_len).is_none());
    }
}
