//! Small constructors every GPU module needs: buffers filled at creation, 2D textures, texel
//! uploads, and the fragment stage's bind group layout entries. One copy of each, so that the passes differ only in what they draw.

use super::device::GpuRenderer;

/// A buffer initialized with `data` (size rounded up to wgpu's copy alignment, at least 4).
pub(crate) fn buffer_with(
    r: &GpuRenderer,
    label: &str,
    data: &[u8],
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    let b = r.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: (data.len() as u64)
            .next_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT)
            .max(4),
        usage: usage | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    r.queue.write_buffer(&b, 0, data);
    b
}

/// A `width × height` 2D texture, one mip level, one sample.
pub(crate) fn texture_2d(
    r: &GpuRenderer,
    label: &str,
    width: u32,
    height: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    r.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// Writes tightly packed rows of 4-byte texels (`data`) into the whole of `texture`.
pub(crate) fn write_texels(r: &GpuRenderer, texture: &wgpu::Texture, data: &[u8]) {
    let size = texture.size();
    r.queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        data,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(4 * size.width),
            rows_per_image: Some(size.height),
        },
        size,
    );
}

/// A layout entry for the fragment stage: an unfilterable 2D float texture at `binding`, read
/// with `textureLoad` (an RGBA8 color, or a depth buffer as its f32 values).
pub(crate) fn fragment_texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// A layout entry for the fragment stage: a uniform buffer at `binding`, bound whole.
pub(crate) fn fragment_uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// The clear value that stores the RGBA8 bytes `c` exactly (each `k/255`, which the unorm
/// conversion rounds back to k).
pub(crate) fn clear_color(c: [u8; 4]) -> wgpu::Color {
    let [r, g, b, a] = c.map(|v| v as f64 / 255.0);
    wgpu::Color { r, g, b, a }
}
