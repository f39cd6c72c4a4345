//! Decompression of one Blosc 1 chunk, as OpenVDB writes them (LZ4 with byte shuffling).
//!
//! The chunk format is Blosc 1's (`README_CHUNK_FORMAT.rst` of c-blosc 1.21): a 16-byte header
//! (version, codec version, flags, type size, uncompressed bytes, block bytes, chunk bytes), then,
//! unless the chunk is a plain copy (flag 0x02), one `i32` start offset per block; each block is
//! one stream, or `typesize` streams when it was split (flag 0x10 clear, a whole block), each an
//! `i32` length and that many bytes of the codec's output (the raw bytes when the length is the
//! stream's size). Flag 0x01 says the bytes were shuffled: byte `j` of element `i` stored at `j *
//! elements + i`. The codec is flags >> 5: 1 for LZ4 (OpenVDB's `bloscCompress`), 3 for zlib. No
//! Rust crate decodes Blosc without building its C library; this is the subset OpenVDB needs.

use std::io::Read as _;

/// Bytes of a Blosc 1 chunk header.
const HEADER_BYTES: usize = 16;
/// Flag: the bytes were shuffled by element.
const BYTE_SHUFFLE: u8 = 0x01;
/// Flag: the chunk holds its bytes uncompressed.
const MEMCPYED: u8 = 0x02;
/// Flag: the bits were shuffled (not used by OpenVDB).
const BIT_SHUFFLE: u8 = 0x04;
/// Flag: blocks were not split into one stream per byte of an element.
const DONT_SPLIT: u8 = 0x10;
/// Codec number of LZ4 and LZ4HC.
const CODEC_LZ4: u8 = 1;
/// Codec number of zlib.
const CODEC_ZLIB: u8 = 3;

/// Decompresses a Blosc 1 chunk into exactly `expected` bytes; the error says what is wrong.
pub(super) fn decompress(chunk: &[u8], expected: usize) -> Result<Vec<u8>, String> {
    let header: &[u8; HEADER_BYTES] = chunk
        .get(..HEADER_BYTES)
        .and_then(|h| h.try_into().ok())
        .ok_or("a Blosc chunk shorter than its 16-byte header")?;
    let flags = header[2];
    let type_bytes = usize::from(header[3]).max(1);
    let word =
        |at: usize| u32::from_le_bytes(header[at..at + 4].try_into().expect("4 bytes")) as usize;
    let (bytes, block_bytes) = (word(4), word(8));
    if bytes != expected {
        return Err(format!(
            "a Blosc chunk of {bytes} bytes where {expected} were expected"
        ));
    }
    if flags & MEMCPYED != 0 {
        return chunk
            .get(HEADER_BYTES..HEADER_BYTES + bytes)
            .map(<[u8]>::to_vec)
            .ok_or_else(|| "a Blosc chunk shorter than the bytes it copies".to_string());
    }
    if flags & BIT_SHUFFLE != 0 {
        return Err("a Blosc chunk with bit shuffling, which OpenVDB does not write".into());
    }
    if block_bytes == 0 {
        return Err("a Blosc chunk with blocks of 0 bytes".into());
    }
    let codec = flags >> 5;
    let blocks = bytes.div_ceil(block_bytes);
    let mut out = Vec::with_capacity(bytes);
    for block in 0..blocks {
        let start = chunk
            .get(HEADER_BYTES + 4 * block..HEADER_BYTES + 4 * block + 4)
            .map(|b| i32::from_le_bytes(b.try_into().expect("4 bytes")))
            .ok_or("a Blosc chunk shorter than its block offsets")?;
        let size = block_bytes.min(bytes - block * block_bytes);
        let split = flags & DONT_SPLIT == 0 && size == block_bytes;
        let streams = if split { type_bytes } else { 1 };
        let mut raw = Vec::with_capacity(size);
        let mut at = usize::try_from(start).map_err(|_| "a negative Blosc block offset")?;
        for _ in 0..streams {
            let length = chunk
                .get(at..at + 4)
                .map(|b| i32::from_le_bytes(b.try_into().expect("4 bytes")))
                .ok_or("a Blosc stream past the end of its chunk")?;
            let length = usize::try_from(length).map_err(|_| "a negative Blosc stream length")?;
            let stream = chunk
                .get(at + 4..at + 4 + length)
                .ok_or("a Blosc stream past the end of its chunk")?;
            raw.extend(decode_stream(codec, stream, size / streams)?);
            at += 4 + length;
        }
        if flags & BYTE_SHUFFLE != 0 {
            raw = unshuffle(&raw, type_bytes);
        }
        out.extend(raw);
    }
    Ok(out)
}

/// One stream of `size` bytes: stored raw when its length is its size, else the codec's output.
fn decode_stream(codec: u8, stream: &[u8], size: usize) -> Result<Vec<u8>, String> {
    if stream.len() == size {
        return Ok(stream.to_vec());
    }
    let mut out = vec![0u8; size];
    let written = match codec {
        CODEC_LZ4 => lz4_flex::block::decompress_into(stream, &mut out)
            .map_err(|e| format!("a Blosc LZ4 stream does not decode: {e}"))?,
        CODEC_ZLIB => {
            let mut decoder = flate2::read::ZlibDecoder::new(stream).take(size as u64);
            out.clear();
            decoder
                .read_to_end(&mut out)
                .map_err(|e| format!("a Blosc zlib stream does not decode: {e}"))?
        }
        other => {
            let name = ["BloscLZ", "LZ4", "Snappy", "zlib", "Zstd"]
                .get(usize::from(other))
                .unwrap_or(&"an unknown codec");
            return Err(format!(
                "a Blosc chunk compressed with {name}, which cloudscape does not read"
            ));
        }
    };
    if written != size {
        return Err(format!(
            "a Blosc stream of {written} bytes where {size} were expected"
        ));
    }
    Ok(out)
}

/// Undoes Blosc's byte shuffle of elements of `type_bytes` bytes (trailing bytes stay in place).
fn unshuffle(shuffled: &[u8], type_bytes: usize) -> Vec<u8> {
    let elements = shuffled.len() / type_bytes;
    let mut out = shuffled.to_vec();
    for (j, plane) in shuffled
        .chunks_exact(elements.max(1))
        .take(type_bytes)
        .enumerate()
    {
        if elements == 0 {
            break;
        }
        for (i, byte) in plane.iter().enumerate() {
            out[i * type_bytes + j] = *byte;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chunk of one block holding `streams` LZ4 streams of `payload`, shuffled by 4 bytes.
    fn chunk(values: &[f32], split: bool) -> Vec<u8> {
        let raw: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let elements = values.len();
        let mut shuffled = vec![0u8; raw.len()];
        for i in 0..elements {
            for j in 0..4 {
                shuffled[j * elements + i] = raw[i * 4 + j];
            }
        }
        let streams: Vec<Vec<u8>> = if split {
            shuffled
                .chunks(elements)
                .map(lz4_flex::block::compress)
                .collect()
        } else {
            vec![lz4_flex::block::compress(&shuffled)]
        };
        let flags = BYTE_SHUFFLE | (CODEC_LZ4 << 5) | if split { 0 } else { DONT_SPLIT };
        let mut out = vec![2, 1, flags, 4];
        out.extend((raw.len() as u32).to_le_bytes());
        out.extend((raw.len() as u32).to_le_bytes());
        out.extend(0u32.to_le_bytes());
        out.extend(((HEADER_BYTES + 4) as i32).to_le_bytes());
        for s in streams {
            out.extend((s.len() as i32).to_le_bytes());
            out.extend(s);
        }
        out
    }

    #[test]
    fn shuffled_lz4_chunks_decode_split_or_not() {
        let values: Vec<f32> = (0..512).map(|i| (i % 17) as f32 * 0.125).collect();
        let raw: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        for split in [false, true] {
            assert_eq!(decompress(&chunk(&values, split), raw.len()).unwrap(), raw);
        }
    }

    #[test]
    fn broken_chunks_are_errors_not_panics() {
        let good = chunk(&[1.0; 64], false);
        assert!(decompress(&good, 100).unwrap_err().contains("256 bytes"));
        for cut in [0, 10, 16, 19, 22, good.len() - 1] {
            assert!(decompress(&good[..cut], 256).is_err(), "cut at {cut}");
        }
        let mut snappy = good.clone();
        snappy[2] = (snappy[2] & 0x1f) | (2 << 5);
        assert!(decompress(&snappy, 256).unwrap_err().contains("Snappy"));
    }
}
