//! The model's layer textures (assets crate, `model::LayerTextures`: varnish and its normal map,
//! specular, sheen, diffuse transmission, anisotropy and iridescence) as 2D array textures, one
//! layer per image, so that a material's twelve slots take one texture binding and one sampler
//! (`layer_textures` and `layer_sampler` in `scene.wgsl`; the fragment stage has 16 texture
//! bindings, 14 of them taken before). Which arrays there are, which images they hold and which
//! one each material reads is the assets crate's `model::LayerArrays` (the plan the loader
//! charged against the memory budget); this module makes them.
//!
//! Invariants: every layer of an array has the array's size and the full mip chain (smaller
//! images are resized bilinearly up to it); colour slots' images are stored as their sRGB codes
//! in a linear format (their mips averaged in linear light) and decoded by the shader after
//! filtering, since one array has one format. A material reads its array with the sampler of its
//! first slot that has a texture (glTF lets each texture have its own; the layer textures of one
//! material share theirs in practice).
//!
//! Render thread only (uploads through the queue; the mip chains are built on every core); no
//! panics: slots naming an image the model lacks read as having none.

use phantogram_assets::model::{LayerArray, LayerArrays, LayerSlot, Material, Model};

use crate::Gpu;
use crate::upload::{create_rgba8_texture, create_sampler, mip_chain, write_mip_chain};

/// A material's layer textures on the GPU.
pub(crate) struct GpuLayerTextures {
    /// Its array's layers together (`texture_2d_array`).
    pub(crate) view: wgpu::TextureView,
    pub(crate) sampler: wgpu::Sampler,
    /// The layer each slot reads ([`LayerSlot::ALL`] order), none where it has no texture.
    pub(crate) layer_of_slot: [Option<u32>; 12],
}

/// The model's layer arrays ([`LayerArrays::of`]) uploaded: each material's share of them (by
/// material index; none for a material without layer textures), and the bytes they take.
pub(crate) fn upload_all(gpu: &Gpu, model: &Model) -> (Vec<Option<GpuLayerTextures>>, u64) {
    let plan = LayerArrays::of(&model.materials, &model.images);
    let views: Vec<wgpu::TextureView> = plan.arrays.iter().map(|a| upload_array(gpu, model, a)).collect();
    let materials = model
        .materials
        .iter()
        .zip(&plan.materials)
        .map(|(material, layers)| {
            let layers = layers.as_ref()?;
            Some(GpuLayerTextures {
                view: views.get(layers.array)?.clone(),
                sampler: create_sampler(&gpu.device, &first_texture(material, &layers.layer_of_slot)?.sampler),
                layer_of_slot: layers.layer_of_slot,
            })
        })
        .collect();
    (materials, plan.bytes_on(gpu.is_opengl()))
}

/// The texture of `material`'s first slot that has a layer.
fn first_texture(
    material: &Material,
    layer_of_slot: &[Option<u32>; 12],
) -> Option<phantogram_assets::model::TextureRef> {
    LayerSlot::ALL
        .into_iter()
        .zip(layer_of_slot)
        .find_map(|(slot, layer)| layer.and(material.layer_textures.get(slot)))
}

/// One array of `model`'s images.
fn upload_array(gpu: &Gpu, model: &Model, array: &LayerArray) -> wgpu::TextureView {
    let (width, height) = (array.width.max(1), array.height.max(1));
    // Each layer's mip chain on every core, as the model's other textures are built.
    let chains = phantogram_assets::parallel::map(&array.images, |&(i, colour)| {
        let rgba8 = model.images.get(i).map_or_else(
            || vec![255; (width * height * 4) as usize],
            |image| resized(image.width, image.height, &image.rgba8, width, height),
        );
        mip_chain(width, height, &rgba8, colour)
    });
    let levels = chains.first().map_or(1, |c| c.len() as u32);
    // Read as an array: a layer more on OpenGL where it would not be one (`Gpu::array_layers`).
    let layers = gpu.array_layers(width, height, chains.len().max(1) as u32);
    let texture = create_rgba8_texture(gpu, "layer textures", (width, height, layers), levels, false);
    for (layer, chain) in chains.iter().enumerate() {
        write_mip_chain(gpu, &texture, layer as u32, chain);
    }
    texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    })
}

/// What a material without layer textures binds: one white texel in one layer.
pub(crate) fn placeholder(gpu: &Gpu) -> wgpu::TextureView {
    let texture = create_rgba8_texture(gpu, "no layer textures", (1, 1, gpu.array_layers(1, 1, 1)), 1, false);
    write_mip_chain(gpu, &texture, 0, &[(1, 1, vec![255; 4])]);
    texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    })
}

/// `rgba8` (`width × height`) resized bilinearly to `to_width × to_height` (texel centres
/// aligned, edges clamped; each channel as stored); the data itself where the size is the same.
fn resized(width: u32, height: u32, rgba8: &[u8], to_width: u32, to_height: u32) -> Vec<u8> {
    if (width, height) == (to_width, to_height) || width == 0 || height == 0 {
        return rgba8.to_vec();
    }
    let texel = |x: u32, y: u32, c: usize| -> f32 {
        let i = ((y.min(height - 1) * width + x.min(width - 1)) * 4) as usize + c;
        rgba8.get(i).copied().unwrap_or(255) as f32
    };
    let mut out = Vec::with_capacity((to_width * to_height * 4) as usize);
    for y in 0..to_height {
        let sy = ((y as f32 + 0.5) * height as f32 / to_height as f32 - 0.5).max(0.0);
        let (y0, fy) = (sy.floor() as u32, sy.fract());
        for x in 0..to_width {
            let sx = ((x as f32 + 0.5) * width as f32 / to_width as f32 - 0.5).max(0.0);
            let (x0, fx) = (sx.floor() as u32, sx.fract());
            for c in 0..4 {
                let top = texel(x0, y0, c) * (1.0 - fx) + texel(x0 + 1, y0, c) * fx;
                let bottom = texel(x0, y0 + 1, c) * (1.0 - fx) + texel(x0 + 1, y0 + 1, c) * fx;
                out.push((top * (1.0 - fy) + bottom * fy).round().clamp(0.0, 255.0) as u8);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resizing_keeps_flat_colour_and_stretches_steps() {
        let flat = [10, 20, 30, 40].repeat(4);
        assert_eq!(resized(2, 2, &flat, 4, 4), [10, 20, 30, 40].repeat(16));
        // Black | white, 2 × 1 to 4 × 1: the outer texels keep their value, the inner ones blend.
        let step = [0, 0, 0, 255, 255, 255, 255, 255];
        let wide = resized(2, 1, &step, 4, 1);
        let reds: Vec<u8> = wide.chunks(4).map(|t| t[0]).collect();
        assert_eq!(reds, [0, 64, 191, 255]);
        assert_eq!(resized(2, 1, &step, 2, 1), step);
    }
}
