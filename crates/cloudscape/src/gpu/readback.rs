//! Copying textures and buffers back to the CPU, for tests, screenshots and image output.
//!
//! Every function blocks until the GPU has finished all submitted work and the copy is mapped.
//! A lost device is not something a caller can recover from here, so these functions panic on it
//! with wgpu's message.

use super::GpuContext;

/// The texels of mip level 0 of `texture`, every layer or depth slice, rows tightly packed (no
/// row padding).
///
/// Works for any colour format with a fixed block size (uncompressed or block-compressed); the
/// texture needs [`wgpu::TextureUsages::COPY_SRC`]. wgpu requires each copied row to start on a
/// multiple of [`wgpu::COPY_BYTES_PER_ROW_ALIGNMENT`] (256) bytes: the padding is stripped here.
///
/// # Panics
/// For formats without a single block size (depth-stencil, multi-planar) and on device loss.
pub fn read_texture(ctx: &GpuContext, texture: &wgpu::Texture) -> Vec<u8> {
    let layout = RowLayout::of(texture);
    let slices = texture.size().depth_or_array_layers;
    let staging = staging_buffer(
        ctx,
        layout.padded_row_bytes * u64::from(layout.rows) * u64::from(slices),
    );
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &staging,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(layout.padded_row_bytes as u32),
                rows_per_image: Some(layout.rows),
            },
        },
        texture.size(),
    );
    ctx.queue.submit([encoder.finish()]);
    let padded = map_and_copy(ctx, &staging);
    padded
        .chunks_exact(layout.padded_row_bytes as usize)
        .flat_map(|row| &row[..layout.row_bytes as usize])
        .copied()
        .collect()
}

/// The texels of an [`wgpu::TextureFormat::Rgba16Float`] texture, row by row, as `f32`.
///
/// # Panics
/// When the texture has another format, and on device loss.
pub fn read_texture_rgba16f(ctx: &GpuContext, texture: &wgpu::Texture) -> Vec<[f32; 4]> {
    assert_format(texture, wgpu::TextureFormat::Rgba16Float);
    let texels: Vec<[half::f16; 4]> = bytemuck::pod_collect_to_vec(&read_texture(ctx, texture));
    texels
        .into_iter()
        .map(|texel| texel.map(half::f16::to_f32))
        .collect()
}

/// The texels of an [`wgpu::TextureFormat::Rgba32Float`] texture, row by row.
///
/// # Panics
/// When the texture has another format, and on device loss.
pub fn read_texture_rgba32f(ctx: &GpuContext, texture: &wgpu::Texture) -> Vec<[f32; 4]> {
    assert_format(texture, wgpu::TextureFormat::Rgba32Float);
    bytemuck::pod_collect_to_vec(&read_texture(ctx, texture))
}

/// The whole contents of `buffer` as a vector of `T`.
///
/// The buffer needs [`wgpu::BufferUsages::COPY_SRC`]; it is copied into a mappable staging buffer.
///
/// # Panics
/// When the buffer size is not a multiple of `size_of::<T>()` or of
/// [`wgpu::COPY_BUFFER_ALIGNMENT`] (4), and on device loss.
pub fn read_buffer<T: bytemuck::Pod>(ctx: &GpuContext, buffer: &wgpu::Buffer) -> Vec<T> {
    let size = buffer.size();
    assert!(
        size.is_multiple_of(size_of::<T>() as u64),
        "read_buffer: a buffer of {size} bytes does not hold whole elements of {} bytes",
        size_of::<T>()
    );
    let staging = staging_buffer(ctx, size);
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
    ctx.queue.submit([encoder.finish()]);
    bytemuck::pod_collect_to_vec(&map_and_copy(ctx, &staging))
}

/// Byte sizes of one texture row as stored (tight) and as copied (padded to 256 bytes).
struct RowLayout {
    row_bytes: u64,
    padded_row_bytes: u64,
    rows: u32,
}

impl RowLayout {
    fn of(texture: &wgpu::Texture) -> RowLayout {
        let format = texture.format();
        let block_bytes = format
            .block_copy_size(None)
            .unwrap_or_else(|| panic!("read_texture: {format:?} has no single block size to copy"));
        let (block_width, block_height) = format.block_dimensions();
        let blocks_per_row = texture.width().div_ceil(block_width);
        let row_bytes = u64::from(blocks_per_row) * u64::from(block_bytes);
        let alignment = u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        RowLayout {
            row_bytes,
            padded_row_bytes: row_bytes.div_ceil(alignment) * alignment,
            rows: texture.height().div_ceil(block_height),
        }
    }
}

fn assert_format(texture: &wgpu::Texture, expected: wgpu::TextureFormat) {
    let format = texture.format();
    assert_eq!(
        format, expected,
        "expected a {expected:?} texture, got {format:?}"
    );
}

fn staging_buffer(ctx: &GpuContext, size: u64) -> wgpu::Buffer {
    ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback staging"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Maps a staging buffer after the submitted copies finish, and copies its bytes out.
fn map_and_copy(ctx: &GpuContext, staging: &wgpu::Buffer) -> Vec<u8> {
    let slice = staging.slice(..);
    let (sender, receiver) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |result| {
        // The receiver lives until `recv` below returns, so a failed send cannot happen.
        let _ = sender.send(result);
    });
    ctx.device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("GPU device lost while reading back");
    receiver
        .recv()
        .expect("wgpu dropped the map callback")
        .expect("mapping the readback buffer failed");
    let bytes = slice
        .get_mapped_range()
        .expect("readback buffer not mapped")
        .to_vec();
    staging.unmap();
    bytes
}
