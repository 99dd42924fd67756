//! Checks an OpenEXR file's sizes before the `image` crate decodes it.
//!
//! Why: a damaged EXR must give an error, but two things in the decoders we use let one abort the
//! whole process on an impossible allocation (found by flipping bytes of the environment maps in
//! `../shared/data/env`; 8 of 1800 mutants aborted, 2 more ran for minutes):
//!
//! * `image` bounds its memory by the *display* window, but `exr` decodes the *data* window, which
//!   a file may set to anything (a flipped high byte makes it 2³¹ pixels wide);
//! * `exr`'s DWAA/DWAB decoder (new in 1.74) allocates from the counts stored inside each chunk
//!   (uncompressed sizes, numbers of AC and DC coefficients) without bounding them by the chunk's
//!   pixels.
//!
//! So before decoding, [`check`] reads the headers and every chunk's leading counters (not the
//! pixels) and refuses a data window over [`MAX_DATA_WINDOW_TEXELS`] or DWA counters larger than
//! the chunk's pixels can need. The limits are generous: they reject only files no writer makes.
//! Reading the chunks costs one extra pass over the file (a few megabytes for an environment map).
//!
//! Pure function, no panics on any input; safe to call from any thread.

use exr::block::chunk::{Chunk, CompressedBlock};
use exr::compression::Compression;
use exr::meta::header::Header;
use std::io::{BufReader, Read, Seek, SeekFrom};

/// The most texels a layer's data window may hold: `image`'s own 512 MiB decode limit at 16 bytes
/// per RGBA f32 texel (an 8192 × 4096 environment is exactly this).
pub const MAX_DATA_WINDOW_TEXELS: usize = 1 << 25;

/// Bytes in a DWA chunk's leading counters: eleven little-endian u64 (OpenEXR's
/// `internal_dwa_compressor.h`).
const DWA_COUNTERS_BYTES: usize = 11 * 8;

/// Checks the EXR file read from `source`; `Err` says what is wrong with it.
pub fn check(mut source: impl Read + Seek) -> Result<(), String> {
    let io = |e: std::io::Error| e.to_string();
    source.seek(SeekFrom::Start(0)).map_err(io)?;
    // Not pedantic, as `image` reads it: this check must not refuse files that decode.
    let reader = exr::block::read(BufReader::new(&mut source), false).map_err(|e| e.to_string())?;
    let headers = reader.meta_data().headers.clone();
    for (layer, header) in headers.iter().enumerate() {
        let (width, height) = (header.layer_size.0, header.layer_size.1);
        if width
            .checked_mul(height)
            .is_none_or(|texels| texels > MAX_DATA_WINDOW_TEXELS)
        {
            return Err(format!(
                "layer {layer}'s data window is {width}×{height} pixels, more than the {} pixels \
                 this loader accepts: damaged file?",
                MAX_DATA_WINDOW_TEXELS
            ));
        }
    }
    drop(reader);
    check_chunk_sizes(&mut source)?;
    if !headers
        .iter()
        .any(|h| matches!(h.compression, Compression::DWAA(_) | Compression::DWAB(_)))
    {
        return Ok(());
    }
    // The chunks where the offset tables put them, as `image`'s decoder reads them.
    source.seek(SeekFrom::Start(0)).map_err(io)?;
    let reader = exr::block::read(BufReader::new(&mut source), false).map_err(|e| e.to_string())?;
    for chunk in reader.filter_chunks(false, |_, _, _| true).map_err(|e| e.to_string())? {
        check_dwa_chunk(&headers, &chunk.map_err(|e| e.to_string())?)?;
    }
    Ok(())
}

/// Refuses a chunk that states more bytes than the file holds after it. `exr` reserves a flat
/// chunk's stated size before reading it (up to the largest block the header allows, which a
/// data window of [`MAX_DATA_WINDOW_TEXELS`] lets reach gigabytes), so a 500-byte file could make
/// it reserve 1.8 GB (found by `cargo xtask fuzz environment`). Each chunk is looked at where the
/// offset tables put it, as `image`'s decoder reads it; deep chunks (which `exr` reads in steps,
/// and `image` refuses) are left alone.
fn check_chunk_sizes(source: &mut (impl Read + Seek)) -> Result<(), String> {
    let io = |e: std::io::Error| e.to_string();
    let file_len = source.seek(SeekFrom::End(0)).map_err(io)?;
    source.seek(SeekFrom::Start(0)).map_err(io)?;
    let mut counted = CountingReader {
        inner: BufReader::new(&mut *source),
        read: 0,
    };
    let meta = exr::meta::MetaData::read_from_buffered(&mut counted, false).map_err(|e| e.to_string())?;
    let tables_start = counted.read;
    drop(counted);
    let chunk_count = meta.headers.iter().map(|h| h.chunk_count as u64).sum::<u64>();
    if chunk_count.saturating_mul(8) > file_len.saturating_sub(tables_start) {
        return Err(format!(
            "the file's offset tables list {chunk_count} chunks, more than its {file_len} bytes can \
             hold: damaged file?"
        ));
    }
    source.seek(SeekFrom::Start(tables_start)).map_err(io)?;
    let mut offsets = vec![0u8; (chunk_count * 8) as usize];
    source.read_exact(&mut offsets).map_err(io)?;
    let multilayer = meta.requirements.is_multilayer();
    let mut word = [0u8; 4];
    for offset in offsets.chunks_exact(8) {
        let offset = u64::from_le_bytes(offset.try_into().unwrap_or_default());
        // An offset outside the file: `exr` reports that itself, allocating nothing.
        if offset >= file_len || source.seek(SeekFrom::Start(offset)).is_err() {
            continue;
        }
        let mut read_i32 = |source: &mut dyn Read| source.read_exact(&mut word).ok().map(|()| i32::from_le_bytes(word));
        let layer = if multilayer { read_i32(source) } else { Some(0) };
        let Some(header) = layer
            .and_then(|l| usize::try_from(l).ok())
            .and_then(|l| meta.headers.get(l))
        else {
            continue;
        };
        if header.deep {
            continue;
        }
        // The block's coordinates: y for scan lines; tile x, y and level x, y for tiles.
        let coordinates = match header.blocks {
            exr::meta::BlockDescription::ScanLines => 4,
            exr::meta::BlockDescription::Tiles(_) => 16,
        };
        if source.seek(SeekFrom::Current(coordinates)).is_err() {
            continue;
        }
        let Some(stated) = read_i32(source).and_then(|n| u64::try_from(n).ok()) else {
            continue;
        };
        let at = source.stream_position().map_err(io)?;
        let left = file_len.saturating_sub(at);
        if stated > left && stated <= header.max_block_byte_size() as u64 {
            return Err(format!(
                "a chunk at byte {offset} gives its size as {stated} bytes, more than the {left} \
                 left in the file: damaged file?"
            ));
        }
    }
    Ok(())
}

/// Counts the bytes read through it (where the headers end).
struct CountingReader<R> {
    inner: R,
    read: u64,
}

impl<R: Read> Read for CountingReader<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.read += n as u64;
        Ok(n)
    }
}

/// Bounds the counters of one chunk of a DWA-compressed layer by the pixels of its block.
fn check_dwa_chunk(headers: &[Header], chunk: &Chunk) -> Result<(), String> {
    let Some(header) = headers.get(chunk.layer_index) else {
        return Err(format!(
            "a chunk names layer {}, which the file lacks",
            chunk.layer_index
        ));
    };
    if !matches!(header.compression, Compression::DWAA(_) | Compression::DWAB(_)) {
        return Ok(());
    }
    let data = match &chunk.compressed_block {
        CompressedBlock::ScanLine(block) => &block.compressed_pixels_le,
        CompressedBlock::Tile(block) => &block.compressed_pixels_le,
        // Deep data is refused by the decoder itself, before any DWA decoding.
        _ => return Ok(()),
    };
    let block = header
        .get_block_data_indices(&chunk.compressed_block)
        .and_then(|indices| header.get_absolute_block_pixel_coordinates(indices))
        .map_err(|e| e.to_string())?;
    let (width, height) = (block.size.0, block.size.1);
    let channels = header.channels.list.len();
    let raw_bytes = width
        .saturating_mul(height)
        .saturating_mul(header.channels.bytes_per_pixel);
    // Stored uncompressed (the writer does that when compression would not help), or empty.
    if data.is_empty() || data.len() == raw_bytes {
        return Ok(());
    }
    let Some(counters) = data.get(..DWA_COUNTERS_BYTES) else {
        return Err("a DWA chunk is shorter than its header".to_owned());
    };
    let counter = |i: usize| {
        let mut le = [0u8; 8];
        le.copy_from_slice(&counters[8 * i..8 * i + 8]);
        u64::from_le_bytes(le)
    };
    // DCT blocks are 8 × 8 pixels; each channel has one DC and up to 63 AC values per block.
    let dct_blocks = width
        .div_ceil(8)
        .saturating_mul(height.div_ceil(8))
        .saturating_mul(channels);
    let limits = [
        (1, "unknown-data size", raw_bytes),
        // The RLE token stream: at worst a count byte per 127 literal bytes.
        (6, "RLE stream size", raw_bytes.saturating_mul(2).saturating_add(64)),
        (7, "RLE data size", raw_bytes),
        (8, "AC coefficient count", dct_blocks.saturating_mul(64)),
        (9, "DC coefficient count", dct_blocks),
    ];
    for (index, what, limit) in limits {
        let value = counter(index);
        if value > limit as u64 {
            return Err(format!(
                "a DWA chunk of {width}×{height} pixels gives its {what} as {value}, more than \
                 its pixels can need ({limit}): damaged file?"
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::ImageEncoder;
    use std::io::Cursor;

    /// A valid 16 × 16 RGB float EXR, written by `image` (through `exr`).
    fn small_exr() -> Vec<u8> {
        let pixels: Vec<u8> = (0..16 * 16 * 3).flat_map(|i| (i as f32 * 0.01).to_le_bytes()).collect();
        let mut out = Cursor::new(Vec::new());
        image::codecs::openexr::OpenExrEncoder::new(&mut out)
            .write_image(&pixels, 16, 16, image::ExtendedColorType::Rgb32F)
            .expect("writes");
        out.into_inner()
    }

    #[test]
    fn a_chunk_that_states_more_bytes_than_the_file_holds_is_refused() {
        let file = small_exr();
        assert_eq!(check(Cursor::new(&file)), Ok(()));
        // Cut short inside its last chunk: that chunk's stated size is more than is left.
        let cut = &file[..file.len() - 5];
        let err = check(Cursor::new(cut)).expect_err("refused");
        assert!(err.contains("left in the file"), "{err}");
    }
}
