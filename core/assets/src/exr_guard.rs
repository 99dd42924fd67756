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
use std::io::{BufReader, Read, Seek};

/// The most texels a layer's data window may hold: `image`'s own 512 MiB decode limit at 16 bytes
/// per RGBA f32 texel (an 8192 × 4096 environment is exactly this).
pub const MAX_DATA_WINDOW_TEXELS: usize = 1 << 25;

/// Bytes in a DWA chunk's leading counters: eleven little-endian u64 (OpenEXR's
/// `internal_dwa_compressor.h`).
const DWA_COUNTERS_BYTES: usize = 11 * 8;

/// Checks the EXR file read from `source`; `Err` says what is wrong with it.
pub fn check(source: impl Read + Seek) -> Result<(), String> {
    // Not pedantic, as `image` reads it: this check must not refuse files that decode.
    let reader = exr::block::read(BufReader::new(source), false).map_err(|e| e.to_string())?;
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
    if !headers
        .iter()
        .any(|h| matches!(h.compression, Compression::DWAA(_) | Compression::DWAB(_)))
    {
        return Ok(());
    }
    for chunk in reader.all_chunks(false).map_err(|e| e.to_string())? {
        check_dwa_chunk(&headers, &chunk.map_err(|e| e.to_string())?)?;
    }
    Ok(())
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
