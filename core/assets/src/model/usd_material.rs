//! The glTF material for a USD material's `UsdPreviewSurface` (`usd_preview_surface`), its
//! textures found among the stage's files and decoded within the budget.
//!
//! * **Textures** are named relative to the layer that authored them, which the reader does not
//!   say: each layer read is tried as the anchor, the root first; in a package, the one file of
//!   that name is the last resort. Each file is decoded once; one that cannot be found or decoded
//!   is left out with a warning.
//! * **Metallic and roughness**: constants, or glTF's one texture (roughness in G, metallic in B):
//!   the file itself where it already is that (the same file, read through its `g` and `b`), else
//!   packed from the files and channels named (the second resampled to the first's size).
//! * **Opacity**: a constant, or a texture's channel: the diffuse texture's alpha as it is, any
//!   other written into the colour texture's alpha (the second image resampled to the first's
//!   size; white colour where there is no colour texture); a cut-off where a threshold is set.
//!   An opacity texture placed otherwise than the colour's (its coordinates or wrap) cannot share
//!   glTF's one colour texture: drawn opaque, with a warning.
//! * **Coordinates**: each texture's `UsdTransform2d`s become glTF's texture transform
//!   ([`uv_transform`]); the primvars the material's textures name are its first and second sets
//!   of texture coordinates, in the order [`Surface::primvars`] gives (the mesh reader puts them
//!   there).
//!
//! **Panics**: none.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use super::loader::ModelError;
use super::usd_files::{Files, anchored};
use glam::{Affine2, Mat2, Vec2};

use super::usd_preview_surface::{Channel, Coords, Input, Surface, TextureInput};
use super::{AlphaMode, Image, Material, Sampler, TextureRef, UvTransform};
use crate::budget::Spending;

/// The textures of a stage, read and decoded once each.
pub(super) struct Textures<'a> {
    pub files: &'a Files,
    /// The layers read (each tried as the anchor of a texture's path).
    pub layers: &'a [String],
    /// The model's file (for messages).
    pub path: &'a Path,
    pub decoded: HashMap<String, Option<Arc<Image>>>,
}

impl Textures<'_> {
    /// The texture file `file` (as authored in some layer), decoded; `None` (with a warning)
    /// where it cannot be found or decoded.
    fn get(
        &mut self,
        file: &str,
        spending: &mut Spending,
        warnings: &mut Vec<String>,
    ) -> Result<Option<Arc<Image>>, ModelError> {
        if let Some(known) = self.decoded.get(file) {
            return Ok(known.clone());
        }
        // The layer naming it is not known here: each layer read is tried as its anchor, the
        // root first; in a package, the one file of that name is the last resort.
        let mut candidates: Vec<String> = self.layers.iter().filter_map(|l| anchored(file, Some(l))).collect();
        candidates.extend(anchored(file, None));
        let base = file.rsplit('/').next().unwrap_or(file);
        let by_name: Vec<&str> = self
            .files
            .names()
            .into_iter()
            .filter(|n| n.rsplit('/').next() == Some(base))
            .collect();
        if let [only] = by_name.as_slice() {
            candidates.push((*only).to_owned());
        }
        let mut raw = Err("names a place outside the artifact's files".to_owned());
        for candidate in &candidates {
            raw = self.files.read(candidate);
            if raw.is_ok() {
                break;
            }
        }
        let image = match raw {
            Ok(raw) => super::file_texture::decode(file, &raw, self.path, spending, warnings)?.map(Arc::new),
            Err(message) => {
                warnings.push(format!("texture {file:.80} not read ({message}): left out"));
                None
            }
        };
        self.decoded.insert(file.to_owned(), image.clone());
        Ok(image)
    }
}

/// The glTF material for the surface of the USD material `name`.
pub(super) fn material_of(
    name: &str,
    surface: &Surface,
    textures: &mut Textures,
    spending: &mut Spending,
    images: &mut Vec<Arc<Image>>,
    warnings: &mut Vec<String>,
) -> Result<Material, ModelError> {
    let mut material = Material {
        name: name.rsplit('/').next().unwrap_or(name).to_owned(),
        base_color: [0.18, 0.18, 0.18, 1.0],
        metallic: 0.0,
        roughness: 0.5,
        ..Material::default()
    };
    let add = |image: &Arc<Image>, images: &mut Vec<Arc<Image>>| {
        // The same texture for two inputs is one image: the same decoded file (one `Arc` from
        // `Textures`), else the same name and texels.
        images
            .iter()
            .position(|i| Arc::ptr_eq(i, image) || (i.name == image.name && i.rgba8 == image.rgba8))
            .unwrap_or_else(|| {
                images.push(Arc::clone(image));
                images.len() - 1
            })
    };
    let primvars = surface.primvars();
    let reference = |image: usize, input: &TextureInput, warnings: &mut Vec<String>| TextureRef {
        image,
        tex_coord: coordinate_set(&input.coords, &primvars),
        transform: uv_transform(input.coords.st_transform, name, warnings),
        sampler: Sampler {
            wrap_u: input.wrap[0],
            wrap_v: input.wrap[1],
            ..Sampler::default()
        },
    };
    if let Some(third) = primvars.get(2) {
        warnings.push(format!(
            "material {name:.80}: its textures read more than two sets of texture coordinates: those reading {third:.40} and after read {:.40}",
            primvars[0]
        ));
    }
    // Diffuse colour, and opacity where it is the same texture's alpha.
    let mut base_image = None;
    match &surface.diffuse {
        Input::Value(c) => material.base_color[..3].copy_from_slice(c),
        Input::Texture(t) => {
            if let Some(image) = textures.get(&t.file, spending, warnings)? {
                let rgb = if t.channel == Channel::Rgb {
                    image
                } else {
                    Arc::new(packed(
                        &[
                            (Some((&image, t.channel)), 0),
                            (Some((&image, t.channel)), 1),
                            (Some((&image, t.channel)), 2),
                        ],
                        &image.name,
                    ))
                };
                material.base_color = [t.scale[0], t.scale[1], t.scale[2], 1.0];
                base_image = Some((rgb, t.clone()));
            }
        }
        Input::Unset => {}
    }
    // Whether the colour texture's alpha is the opacity: its own, or another texture's channel
    // written into it (glTF's one place for a texture's opacity).
    let mut alpha_textured = false;
    match &surface.opacity {
        Input::Value(o) => material.base_color[3] = o.clamp(0.0, 1.0),
        Input::Texture(t) => match &base_image {
            Some((_, diffuse))
                if diffuse.file == t.file
                    && diffuse.coords == t.coords
                    && t.channel == Channel::A
                    && diffuse.channel == Channel::Rgb =>
            {
                material.base_color[3] = t.scale[3];
                alpha_textured = true;
            }
            Some((_, diffuse)) if diffuse.coords != t.coords || diffuse.wrap != t.wrap => {
                warnings.push(format!(
                    "material {name:.80}: its opacity texture is placed otherwise than its colour's: drawn opaque"
                ));
            }
            _ => {
                if let Some(opacity) = textures.get(&t.file, spending, warnings)? {
                    let channel = t.channel;
                    let (colour, input) = match base_image.take() {
                        Some((colour, input)) => (Some(colour), input),
                        None => (None, t.clone()),
                    };
                    let rgb = |c: Channel| colour.as_ref().map(|i| (i, c));
                    let label = format!("{} (colour, opacity)", material.name);
                    // Charged like any decoded texture: the combined image is a new one.
                    let (w, h) = colour
                        .as_ref()
                        .map_or((opacity.width, opacity.height), |c| (c.width, c.height));
                    spending
                        .charge_bytes(|| label.clone(), u64::from(w) * u64::from(h) * 4)
                        .map_err(|e| super::loader::over_budget(textures.path, e))?;
                    let combined = packed(
                        &[
                            (rgb(Channel::R), 0),
                            (rgb(Channel::G), 1),
                            (rgb(Channel::B), 2),
                            (Some((&opacity, channel)), 3),
                        ],
                        &label,
                    );
                    base_image = Some((Arc::new(combined), input));
                    material.base_color[3] = t.scale[channel.offset()];
                    alpha_textured = true;
                }
            }
        },
        Input::Unset => {}
    }
    let see_through = alpha_textured || material.base_color[3] < 1.0;
    material.alpha = match (see_through, surface.opacity_threshold) {
        (false, _) => AlphaMode::Opaque,
        (true, cut) if cut > 0.0 => AlphaMode::Mask(cut),
        (true, _) => AlphaMode::Blend,
    };
    if let Some((image, input)) = &base_image {
        let index = add(image, images);
        material.base_color_texture = Some(reference(index, input, warnings));
    }
    // Metallic and roughness: constants, or textures packed as glTF's (G roughness, B metallic).
    let roughness_texture = match surface.roughness.texture() {
        Some(t) => textures.get(&t.file, spending, warnings)?.map(|i| (i, t.clone())),
        None => None,
    };
    let metallic_texture = match surface.metallic.texture() {
        Some(t) => textures.get(&t.file, spending, warnings)?.map(|i| (i, t.clone())),
        None => None,
    };
    material.roughness = surface.roughness.value_or(0.5).clamp(0.0, 1.0);
    material.metallic = surface.metallic.value_or(0.0).clamp(0.0, 1.0);
    if let Some((_, first)) = roughness_texture.as_ref().or(metallic_texture.as_ref()) {
        if let (Some((_, r)), Some((_, m))) = (&roughness_texture, &metallic_texture)
            && r.coords != m.coords
        {
            warnings.push(format!(
                "material {name:.80}: its metallic and roughness textures are placed differently: both read where the roughness is"
            ));
        }
        let image = match (&roughness_texture, &metallic_texture) {
            // Already glTF's: one file read through its g and b.
            (Some((r, rt)), Some((m, mt)))
                if Arc::ptr_eq(r, m) && rt.channel == Channel::G && mt.channel == Channel::B =>
            {
                Arc::clone(r)
            }
            _ => {
                let r = roughness_texture.as_ref().map(|(i, t)| (i, t.channel));
                let m = metallic_texture.as_ref().map(|(i, t)| (i, t.channel));
                let label = format!("{} (roughness, metallic)", material.name);
                Arc::new(packed(&[(None, 0), (r, 1), (m, 2)], &label))
            }
        };
        if let Some((_, t)) = &roughness_texture {
            material.roughness = t.scale[0];
        }
        if let Some((_, t)) = &metallic_texture {
            material.metallic = t.scale[0];
        }
        let index = add(&image, images);
        material.metallic_roughness_texture = Some(reference(index, first, warnings));
    }
    if let Some(t) = &surface.normal
        && let Some(image) = textures.get(&t.file, spending, warnings)?
    {
        let index = add(&image, images);
        material.normal_texture = Some((reference(index, t, warnings), 1.0));
    }
    if let Some(t) = &surface.occlusion
        && let Some(image) = textures.get(&t.file, spending, warnings)?
    {
        let image = if t.channel.offset() == 0 {
            image
        } else {
            Arc::new(packed(
                &[(Some((&image, t.channel)), 0)],
                &format!("{} (occlusion)", image.name),
            ))
        };
        let index = add(&image, images);
        material.occlusion_texture = Some((reference(index, t, warnings), t.scale[0]));
    }
    match &surface.emissive {
        Input::Value(c) => material.emissive = *c,
        Input::Texture(t) => {
            if let Some(image) = textures.get(&t.file, spending, warnings)? {
                let index = add(&image, images);
                material.emissive = [t.scale[0], t.scale[1], t.scale[2]];
                material.emissive_texture = Some(reference(index, t, warnings));
            }
        }
        Input::Unset => {}
    }
    Ok(material)
}

/// The set of texture coordinates (0 or 1) a texture reads: where its primvar is among the
/// material's `primvars` ([`Surface::primvars`]); the first for one that names none, or a third.
fn coordinate_set(coords: &Coords, primvars: &[&str]) -> u32 {
    coords
        .primvar
        .as_deref()
        .and_then(|name| primvars.iter().position(|p| *p == name))
        .filter(|&i| i < 2)
        .map_or(0, |i| i as u32)
}

/// A texture's `UsdTransform2d`s (`st_transform`, in USD's st frame, t up) as glTF's texture
/// transform on the mesh's coordinates, whose v the reader stores as 1 − t (`usd_mesh`).
///
/// With `F(x, y) = (x, 1 − y)`: `uv' = F(A(F(uv))) = D·L·D·uv + D·(L·(0, 1) + t) + (0, 1)`,
/// `D = diag(1, −1)`, `A = L·st + t`. For one transform (`L = R(θ)·S`) that is exactly glTF's
/// `T·R·S` with the rotation θ, the scale S and the offset `(tx − sy·sin θ, 1 − ty − sy·cos θ)`:
/// what the USD working group's conversion of Khronos's TextureTransformTest holds for each of
/// its materials (e.g. "All": θ 17.188734°, S 1.5, t (0.24328034, −0.33300462) against glTF's
/// rotation 0.3, scale 1.5, offset (−0.2, −0.1)). Composed transforms whose scales differ may
/// shear, which glTF's cannot: the shear is left out, with a warning.
fn uv_transform(st_transform: Affine2, material: &str, warnings: &mut Vec<String>) -> UvTransform {
    let d = Mat2::from_diagonal(Vec2::new(1.0, -1.0));
    let m = d * st_transform.matrix2 * d;
    let offset = d * (st_transform.matrix2 * Vec2::Y + st_transform.translation) + Vec2::Y;
    // m = [[c·sx, s·sy], [−s·sx, c·sy]] (glTF's rows): its first column is sx·(c, −s).
    let (first, second) = (m.x_axis, m.y_axis);
    let scale_x = first.length();
    let rotation_rad = if scale_x > 0.0 { (-first.y).atan2(first.x) } else { 0.0 };
    let (s, c) = rotation_rad.sin_cos();
    let scale_y = second.dot(Vec2::new(s, c));
    let shear = second.dot(Vec2::new(c, -s));
    if shear.abs() > 1e-4 * scale_x.abs().max(scale_y.abs()) {
        warnings.push(format!(
            "material {material:.80}: a texture's coordinates are sheared by its transforms: drawn without the shear"
        ));
    }
    let transform = UvTransform {
        offset: offset.to_array(),
        rotation_rad,
        scale: [scale_x, scale_y],
    };
    if transform.rows().iter().flatten().all(|v| v.is_finite()) {
        transform
    } else {
        UvTransform::default()
    }
}

/// A channel of an image, or none (white).
type Source<'a> = Option<(&'a Arc<Image>, Channel)>;

/// An image whose channels are channels of source images (each pair: the source and its channel,
/// the channel written, 0–3) (resampled to the
/// first source's size, nearest texel), white where no source is given, alpha opaque unless
/// set.
fn packed(sources: &[(Source, usize)], name: &str) -> Image {
    let (width, height) = sources
        .iter()
        .find_map(|(s, _)| s.map(|(i, _)| (i.width.max(1), i.height.max(1))))
        .unwrap_or((1, 1));
    let mut rgba8 = vec![255u8; width as usize * height as usize * 4];
    for (source, out) in sources {
        let Some((image, channel)) = source else { continue };
        let (w, h) = (image.width.max(1) as usize, image.height.max(1) as usize);
        for y in 0..height as usize {
            let sy = y * h / height as usize;
            for x in 0..width as usize {
                let sx = x * w / width as usize;
                let texel = image
                    .rgba8
                    .get((sy * w + sx) * 4 + channel.offset())
                    .copied()
                    .unwrap_or(255);
                rgba8[(y * width as usize + x) * 4 + out] = texel;
            }
        }
    }
    Image {
        name: name.to_owned(),
        width,
        height,
        rgba8,
        basis: None,
    }
}
