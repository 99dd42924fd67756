//! How a model's layer textures ([`super::LayerTextures`]) are packed for the GPU, and what that
//! costs in memory.
//!
//! The fragment stage has one texture binding left for the twelve layer slots, so a material's
//! layer images are the layers of one 2D array texture, all of one size: smaller images are
//! resized up to the largest the material uses. Materials whose arrays would have the same size
//! share one ([`LayerArrays::of`]), up to [`MAX_LAYERS`] images in it, so that a model whose
//! materials use the same packed texture, or each their own images of one size, holds every
//! image once. Materials of other sizes get other arrays: resizing a 256² decal's images up to a
//! 4096² body's would cost hundreds of megabytes.
//!
//! What the arrays take beyond the images' own decoded copies ([`LayerArrays::extra_bytes`]: the
//! resizing up, an image in two arrays or two colour spaces) is charged against the model's
//! [`crate::budget::ResourceBudget`] like any other allocation (the loader, and
//! [`crate::budget::model_bytes`]): a file of a few hundred bytes could otherwise ask for one
//! 8192² image beside two hundred 1² ones, each a layer of its own material, and have the GPU
//! allocate 65 GiB.
//!
//! The plan is a pure function of the materials and the images' sizes: the renderer recomputes it
//! and gets the same arrays the loader charged. Pure data; no panics.

use super::{Image, LayerSlot, Material};

/// Most layers in one array: `max_texture_array_layers` on the weakest device the renderer
/// supports (GLES 3.0's minimum, and wgpu's downlevel limits).
pub const MAX_LAYERS: usize = 256;

/// One 2D array texture of layer images.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LayerArray {
    /// Its layers in order: an image's index and whether it is read as colour (sRGB codes; its
    /// mips are averaged in linear light). An image read both ways is two layers.
    pub images: Vec<(usize, bool)>,
    /// Every layer's size, pixels: the largest width and height among the images of the
    /// materials that read it.
    pub width: u32,
    pub height: u32,
}

impl LayerArray {
    /// Bytes it takes on the GPU, with every layer's mip chain, on the backend that takes the
    /// most (OpenGL's spare layer: [`crate::budget::array_layers`]).
    pub fn bytes(&self) -> u64 {
        self.bytes_on(true)
    }

    /// Bytes it takes on the GPU, with every layer's mip chain, on OpenGL (ES) (`opengl`) or
    /// another backend.
    pub fn bytes_on(&self, opengl: bool) -> u64 {
        let layers = crate::budget::array_layers(self.width, self.height, self.images.len() as u32, opengl);
        u64::from(layers).saturating_mul(crate::budget::ResourceBudget::texture_bytes(self.width, self.height))
    }
}

/// Where one material reads its layer textures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MaterialLayers {
    /// Index into [`LayerArrays::arrays`].
    pub array: usize,
    /// The layer each slot reads ([`LayerSlot::ALL`] order), none where it has no texture.
    pub layer_of_slot: [Option<u32>; 12],
}

/// A model's layer arrays and which one each material reads.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LayerArrays {
    pub arrays: Vec<LayerArray>,
    /// By material index; none for a material without layer textures.
    pub materials: Vec<Option<MaterialLayers>>,
}

impl LayerArrays {
    /// The arrays for `materials` over `images`. Each material goes into the first array of its
    /// size that has room for the images it adds, or a new one. Slots naming an image that does
    /// not exist are left out (as the renderer reads them: no texture).
    pub fn of(materials: &[Material], images: &[Image]) -> Self {
        let mut plan = Self::default();
        for material in materials {
            let keys = keys_of(material, images.len());
            if keys.is_empty() {
                plan.materials.push(None);
                continue;
            }
            let width = keys.iter().map(|(i, _)| images[*i].width.max(1)).max().unwrap_or(1);
            let height = keys.iter().map(|(i, _)| images[*i].height.max(1)).max().unwrap_or(1);
            let fits = |array: &LayerArray| {
                (array.width, array.height) == (width, height)
                    && array.images.len() + keys.iter().filter(|k| !array.images.contains(k)).count() <= MAX_LAYERS
            };
            let array = match plan.arrays.iter().position(fits) {
                Some(a) => a,
                None => {
                    plan.arrays.push(LayerArray {
                        images: Vec::new(),
                        width,
                        height,
                    });
                    plan.arrays.len() - 1
                }
            };
            let layers = &mut plan.arrays[array].images;
            let mut layer_of_slot = [None; 12];
            for (k, slot) in LayerSlot::ALL.into_iter().enumerate() {
                let Some(key) = key_of(material, slot, images.len()) else {
                    continue;
                };
                let layer = layers.iter().position(|l| *l == key).unwrap_or_else(|| {
                    layers.push(key);
                    layers.len() - 1
                });
                layer_of_slot[k] = Some(layer as u32);
            }
            plan.materials.push(Some(MaterialLayers { array, layer_of_slot }));
        }
        plan
    }

    /// Bytes every array takes on the GPU, on the backend that takes the most
    /// ([`LayerArray::bytes`]).
    pub fn bytes(&self) -> u64 {
        self.bytes_on(true)
    }

    /// Bytes every array takes on the GPU on OpenGL (ES) (`opengl`) or another backend.
    pub fn bytes_on(&self, opengl: bool) -> u64 {
        self.arrays
            .iter()
            .map(|a| a.bytes_on(opengl))
            .fold(0, u64::saturating_add)
    }

    /// Bytes the arrays take beyond the decoded images they stand for: all of them, less the
    /// images that no material's own slots upload and that are therefore on the GPU only as
    /// layers (each counted once).
    pub fn extra_bytes(&self, materials: &[Material], images: &[Image]) -> u64 {
        let mut own = vec![false; images.len()];
        for (t, _) in materials.iter().flat_map(|m| m.own_slot_textures()).flatten() {
            if let Some(o) = own.get_mut(t.image) {
                *o = true;
            }
        }
        let mut credited = vec![false; images.len()];
        let mut credit = 0u64;
        for &(i, _) in self.arrays.iter().flat_map(|a| &a.images) {
            if !own[i] && !credited[i] {
                credited[i] = true;
                credit = credit.saturating_add(crate::budget::ResourceBudget::texture_bytes(
                    images[i].width,
                    images[i].height,
                ));
            }
        }
        self.bytes().saturating_sub(credit)
    }
}

/// The layer a slot's texture needs: its image and colour space; none without a texture or
/// with an image that does not exist.
fn key_of(material: &Material, slot: LayerSlot, image_count: usize) -> Option<(usize, bool)> {
    let t = material.layer_textures.get(slot)?;
    (t.image < image_count).then_some((t.image, slot.is_colour()))
}

/// The distinct layers `material` needs, in order of first use.
fn keys_of(material: &Material, image_count: usize) -> Vec<(usize, bool)> {
    let mut keys = Vec::new();
    for slot in LayerSlot::ALL {
        if let Some(key) = key_of(material, slot, image_count)
            && !keys.contains(&key)
        {
            keys.push(key);
        }
    }
    keys
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::budget::ResourceBudget;
    use crate::model::TextureRef;

    fn texture(image: usize) -> Option<TextureRef> {
        Some(TextureRef {
            image,
            tex_coord: 0,
            transform: Default::default(),
            sampler: Default::default(),
        })
    }

    fn image(side: u32) -> Image {
        Image {
            name: format!("{side}²"),
            width: side,
            height: side,
            rgba8: Vec::new(),
            basis: None,
        }
    }

    fn with(slots: &[(LayerSlot, usize)]) -> Material {
        let mut m = Material::default();
        for &(slot, i) in slots {
            m.layer_textures.set(slot, texture(i));
        }
        m
    }

    #[test]
    fn slots_share_a_layer_per_image_and_colour_space() {
        // A varnish's share in R and its roughness in G of one image (as glTF's samples pack
        // them), the sheen's colour (sRGB) and roughness (linear) of another: three layers.
        // An image the model lacks: no layer.
        let m = with(&[
            (LayerSlot::ClearCoat, 0),
            (LayerSlot::ClearCoatRoughness, 0),
            (LayerSlot::SheenColor, 1),
            (LayerSlot::SheenRoughness, 1),
            (LayerSlot::Specular, 7),
        ]);
        let plan = LayerArrays::of(&[m, Material::default()], &[image(4), image(2)]);
        assert_eq!(
            plan.arrays,
            [LayerArray {
                images: vec![(0, false), (1, true), (1, false)],
                width: 4,
                height: 4
            }]
        );
        let mut layers = [None; 12];
        layers[0] = Some(0);
        layers[1] = Some(0);
        layers[4] = Some(1);
        layers[5] = Some(2);
        assert_eq!(
            plan.materials,
            [
                Some(MaterialLayers {
                    array: 0,
                    layer_of_slot: layers
                }),
                None
            ]
        );
    }

    #[test]
    fn materials_of_one_size_share_an_array_and_other_sizes_get_their_own() {
        let materials = [
            with(&[(LayerSlot::ClearCoat, 0), (LayerSlot::SheenColor, 1)]),
            // Shares image 0 and adds image 2, of the same size: the same array.
            with(&[(LayerSlot::ClearCoat, 0), (LayerSlot::Iridescence, 2)]),
            // A small decal's: an array of its own size.
            with(&[(LayerSlot::ClearCoat, 3)]),
        ];
        let images = [image(64), image(64), image(64), image(8)];
        let plan = LayerArrays::of(&materials, &images);
        assert_eq!(plan.arrays.len(), 2);
        assert_eq!(plan.arrays[0].images, [(0, false), (1, true), (2, false)]);
        assert_eq!(
            (plan.arrays[1].images.as_slice(), plan.arrays[1].width),
            (&[(3, false)][..], 8)
        );
        let arrays: Vec<usize> = plan.materials.iter().map(|m| m.expect("has layers").array).collect();
        assert_eq!(arrays, [0, 0, 1]);
        // The second material reads image 0 where the first put it.
        assert_eq!(plan.materials[1].expect("has layers").layer_of_slot[0], Some(0));
        assert_eq!(plan.materials[1].expect("has layers").layer_of_slot[10], Some(2));
        // Every image once, each at its own size: nothing beyond the images themselves, but
        // the spare layer OpenGL gives the array of one layer (8²), charged on every backend.
        assert_eq!(
            plan.extra_bytes(&materials, &images),
            ResourceBudget::texture_bytes(8, 8)
        );
        assert_eq!(plan.bytes_on(false), plan.bytes() - ResourceBudget::texture_bytes(8, 8));
    }

    #[test]
    fn an_array_holds_at_most_max_layers() {
        // One material per image, all of one size: MAX_LAYERS in the first array, the rest in a
        // second.
        let count = MAX_LAYERS + 3;
        let materials: Vec<Material> = (0..count).map(|i| with(&[(LayerSlot::ClearCoat, i)])).collect();
        let images: Vec<Image> = (0..count).map(|_| image(2)).collect();
        let plan = LayerArrays::of(&materials, &images);
        let sizes: Vec<usize> = plan.arrays.iter().map(|a| a.images.len()).collect();
        assert_eq!(sizes, [MAX_LAYERS, 3]);
    }

    #[test]
    fn what_resizing_up_costs_is_extra() {
        // One material with a 64² varnish map and a 1² sheen colour: two 64² layers, one of them
        // beyond the images' own bytes.
        let materials = [with(&[(LayerSlot::ClearCoat, 0), (LayerSlot::SheenColor, 1)])];
        let images = [image(64), image(1)];
        let plan = LayerArrays::of(&materials, &images);
        let layer = ResourceBudget::texture_bytes(64, 64);
        assert_eq!(plan.bytes(), 2 * layer);
        assert_eq!(
            plan.extra_bytes(&materials, &images),
            2 * layer - layer - ResourceBudget::texture_bytes(1, 1)
        );
        // The varnish map also uploaded as a base colour: its layer is all extra.
        let mut both = materials[0].clone();
        both.base_color_texture = texture(0);
        let materials = [both];
        assert_eq!(
            LayerArrays::of(&materials, &images).extra_bytes(&materials, &images),
            2 * layer - ResourceBudget::texture_bytes(1, 1)
        );
    }
}
