//! A material's layer textures (assets crate, `model::LayerTextures`: varnish and its normal map,
//! specular, sheen, diffuse transmission, anisotropy and iridescence) as one 2D array texture, one layer per image they
//! use, so that the twelve slots take one texture binding and one sampler (`layer_textures` and `layer_sampler`
//! in `scene.wgsl`; the fragment stage has 16 texture bindings, 14 of them taken before).
//!
//! Materials whose layer slots use the same images (in the same order of first use) share one
//! array ([`Arrays`]), as a model's materials often share one packed texture.
//!
//! Invariants: every layer has the size of the largest image used (smaller ones are resized
//! bilinearly up to it: the layers of an array share their size) and the full mip chain; colour
//! slots' images are stored as their sRGB codes in a linear format (their mips averaged in
//! linear light) and decoded by the shader after filtering, since one array has one format.
//! The array is read with the sampler of the first slot that has a texture (glTF lets each
//! texture have its own; the layer textures of one material share theirs in practice).
//!
//! Render thread only (uploads through the queue; the mip chains are built on every core); no
//! panics: slots naming an image the model lacks read as having none.

use phantogram_assets::model::{LayerSlot, Material, Model};

use crate::Gpu;
use crate::upload::{create_rgba8_texture, create_sampler, mip_chain, write_mip_chain};

/// A material's layer textures on the GPU.
pub(crate) struct GpuLayerTextures {
    /// The layers together (`texture_2d_array`).
    pub(crate) view: wgpu::TextureView,
    pub(crate) sampler: wgpu::Sampler,
    /// The layer each slot reads ([`LayerSlot::ALL`] order), none where it has no texture.
    pub(crate) layer_of_slot: [Option<u32>; 12],
}

/// The images a material's layer slots use, once per colour space, and the layer of each slot
/// ([`LayerSlot::ALL`] order): slots naming an image the model lacks have none.
pub(crate) fn layers_of(material: &Material, image_count: usize) -> (Vec<(usize, bool)>, [Option<u32>; 12]) {
    let mut images: Vec<(usize, bool)> = Vec::new();
    let mut layer_of_slot = [None; 12];
    for (k, slot) in LayerSlot::ALL.into_iter().enumerate() {
        let Some(t) = material.layer_textures.get(slot) else {
            continue;
        };
        if t.image >= image_count {
            continue;
        }
        let key = (t.image, slot.is_colour());
        let layer = images.iter().position(|i| *i == key).unwrap_or_else(|| {
            images.push(key);
            images.len() - 1
        });
        layer_of_slot[k] = Some(layer as u32);
    }
    (images, layer_of_slot)
}

/// The arrays made so far for a model, by the images (and colour spaces) of their layers in
/// order: materials whose layer slots use the same images share one.
pub(crate) type Arrays = std::collections::HashMap<Vec<(usize, bool)>, wgpu::TextureView>;

/// `material`'s layer textures from `model`'s images, uploaded or found in `made`; `None` where
/// it has none.
pub(crate) fn upload(gpu: &Gpu, model: &Model, material: &Material, made: &mut Arrays) -> Option<GpuLayerTextures> {
    let (images, layer_of_slot) = layers_of(material, model.images.len());
    if images.is_empty() {
        return None;
    }
    let first = LayerSlot::ALL
        .into_iter()
        .zip(layer_of_slot)
        .find_map(|(slot, layer)| layer.and(material.layer_textures.get(slot)))?;
    let sampler = create_sampler(&gpu.device, &first.sampler);
    if let Some(view) = made.get(&images) {
        return Some(GpuLayerTextures {
            view: view.clone(),
            sampler,
            layer_of_slot,
        });
    }
    let width = images.iter().map(|(i, _)| model.images[*i].width).max()?.max(1);
    let height = images.iter().map(|(i, _)| model.images[*i].height).max()?.max(1);
    // Each layer's mip chain on every core, as the model's other textures are built.
    let chains = phantogram_assets::parallel::map(&images, |&(i, colour)| {
        let image = &model.images[i];
        let rgba8 = resized(image.width, image.height, &image.rgba8, width, height);
        mip_chain(width, height, &rgba8, colour)
    });
    let texture = create_rgba8_texture(
        gpu,
        "layer textures",
        (width, height, images.len() as u32),
        chains[0].len() as u32,
        false,
    );
    for (layer, chain) in chains.iter().enumerate() {
        write_mip_chain(gpu, &texture, layer as u32, chain);
    }
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    made.insert(images, view.clone());
    Some(GpuLayerTextures {
        view,
        sampler,
        layer_of_slot,
    })
}

/// What a material without layer textures binds: one white texel in one layer.
pub(crate) fn placeholder(gpu: &Gpu) -> wgpu::TextureView {
    let texture = create_rgba8_texture(gpu, "no layer textures", (1, 1, 1), 1, false);
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
    use phantogram_assets::model::TextureRef;

    fn texture(image: usize) -> Option<TextureRef> {
        Some(TextureRef {
            image,
            tex_coord: 0,
            transform: Default::default(),
            sampler: Default::default(),
        })
    }

    #[test]
    fn slots_share_a_layer_per_image_and_colour_space() {
        let mut m = Material::default();
        // A varnish's share in R and its roughness in G of one image (as glTF's samples pack
        // them), the sheen's colour (sRGB) and roughness (linear) of another: three layers.
        m.layer_textures.set(LayerSlot::ClearCoat, texture(0));
        m.layer_textures.set(LayerSlot::ClearCoatRoughness, texture(0));
        m.layer_textures.set(LayerSlot::SheenColor, texture(1));
        m.layer_textures.set(LayerSlot::SheenRoughness, texture(1));
        // An image the model lacks: no layer.
        m.layer_textures.set(LayerSlot::Specular, texture(7));
        let (images, layers) = layers_of(&m, 2);
        assert_eq!(images, [(0, false), (1, true), (1, false)]);
        assert_eq!(
            layers,
            [
                Some(0),
                Some(0),
                None,
                None,
                Some(1),
                Some(2),
                None,
                None,
                None,
                None,
                None,
                None
            ]
        );
        assert_eq!(layers_of(&Material::default(), 2).0, []);
    }

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
