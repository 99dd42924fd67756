//! Uploads: a model's buffers, materials and textures (with their mip chains, averaged in linear
//! light) and samplers.

use super::*;
use phantogram_assets::model::TextureRef;

pub(super) use phantogram_geometry::srgb::{code_to_linear as srgb_to_linear, linear_to_code as linear_to_srgb};

/// The full mip chain of an RGBA8 image (2×2 box filter; odd sizes clamp at the edge). Colour
/// data is averaged in linear light, alpha and data textures as stored.
pub fn mip_chain(width: u32, height: u32, rgba8: &[u8], srgb: bool) -> Vec<(u32, u32, Vec<u8>)> {
    let mut levels = vec![(width, height, rgba8.to_vec())];
    while let Some((w, h, data)) = levels.last().filter(|(w, h, _)| *w > 1 || *h > 1) {
        let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
        let mut next = vec![0u8; (nw * nh * 4) as usize];
        for y in 0..nh {
            for x in 0..nw {
                for c in 0..4 {
                    let mut sum = 0.0f32;
                    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        let sx = (2 * x + dx).min(w - 1);
                        let sy = (2 * y + dy).min(h - 1);
                        let v = data[((sy * w + sx) * 4 + c) as usize];
                        sum += if srgb && c < 3 {
                            srgb_to_linear(v)
                        } else {
                            v as f32 / 255.0
                        };
                    }
                    let avg = sum * 0.25;
                    next[((y * nw + x) * 4 + c) as usize] = if srgb && c < 3 {
                        linear_to_srgb(avg)
                    } else {
                        (avg * 255.0 + 0.5) as u8
                    };
                }
            }
        }
        levels.push((nw, nh, next));
    }
    levels
}

pub(super) fn upload_texture(
    gpu: &Gpu,
    label: &str,
    width: u32,
    height: u32,
    rgba8: &[u8],
    srgb: bool,
) -> wgpu::TextureView {
    upload_mip_chain(gpu, label, width, height, &mip_chain(width, height, rgba8, srgb), srgb)
}

/// Uploads a texture from its mip levels ([`mip_chain`]).
pub(super) fn upload_mip_chain(
    gpu: &Gpu,
    label: &str,
    width: u32,
    height: u32,
    levels: &[(u32, u32, Vec<u8>)],
    srgb: bool,
) -> wgpu::TextureView {
    let texture = create_rgba8_texture(gpu, label, (width, height, 1), levels.len() as u32, srgb);
    write_mip_chain(gpu, &texture, 0, levels);
    texture.create_view(&Default::default())
}

/// An RGBA8 texture of `(width, height, layers)` with `level_count` mip levels, to be written
/// ([`write_mip_chain`]) and sampled; its texels decoded from sRGB where `srgb`.
pub(super) fn create_rgba8_texture(
    gpu: &Gpu,
    label: &str,
    (width, height, layers): (u32, u32, u32),
    level_count: u32,
    srgb: bool,
) -> wgpu::Texture {
    gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: layers,
        },
        mip_level_count: level_count,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: if srgb {
            wgpu::TextureFormat::Rgba8UnormSrgb
        } else {
            wgpu::TextureFormat::Rgba8Unorm
        },
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}

/// Writes RGBA8 mip `levels` ([`mip_chain`]) into array layer `layer` of `texture`.
pub(super) fn write_mip_chain(gpu: &Gpu, texture: &wgpu::Texture, layer: u32, levels: &[(u32, u32, Vec<u8>)]) {
    for (level, (w, h, data)) in levels.iter().enumerate() {
        gpu.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: level as u32,
                origin: wgpu::Origin3d { x: 0, y: 0, z: layer },
                aspect: wgpu::TextureAspect::All,
            },
            data,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(w * 4),
                rows_per_image: Some(*h),
            },
            wgpu::Extent3d {
                width: *w,
                height: *h,
                depth_or_array_layers: 1,
            },
        );
    }
}

pub(super) fn create_sampler(device: &wgpu::Device, s: &Sampler) -> wgpu::Sampler {
    let address = |w: Wrap| match w {
        Wrap::Repeat => wgpu::AddressMode::Repeat,
        Wrap::ClampToEdge => wgpu::AddressMode::ClampToEdge,
        Wrap::MirroredRepeat => wgpu::AddressMode::MirrorRepeat,
    };
    let filter = |linear: bool| {
        if linear {
            wgpu::FilterMode::Linear
        } else {
            wgpu::FilterMode::Nearest
        }
    };
    device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("material"),
        address_mode_u: address(s.wrap_u),
        address_mode_v: address(s.wrap_v),
        mag_filter: filter(s.mag_linear),
        min_filter: filter(s.min_linear),
        mipmap_filter: if s.mip_linear {
            wgpu::MipmapFilterMode::Linear
        } else {
            wgpu::MipmapFilterMode::Nearest
        },
        ..Default::default()
    })
}

pub(super) fn upload_model(gpu: &Gpu, layout: &wgpu::BindGroupLayout, model: &Model) -> GpuModel {
    let device = &gpu.device;
    // Each image once per colour space it is used in; the mip chains are built on every core
    // (a good part of a textured scan's time to first frame), then uploaded in turn.
    // (The layer extensions' textures go into arrays shared by the materials: `layer_textures`.)
    let mut used: Vec<(usize, bool)> = Vec::new();
    for m in &model.materials {
        for (t, srgb) in m.own_slot_textures().into_iter().flatten() {
            if t.image < model.images.len() && !used.contains(&(t.image, srgb)) {
                used.push((t.image, srgb));
            }
        }
    }
    // A Basis Universal texture in the device's block format where it gives a whole chain.
    let block_format = crate::block_textures::format_for(device);
    let chains = phantogram_assets::parallel::map(&used, |&(image, srgb)| {
        let img = &model.images[image];
        let blocks = img
            .basis
            .as_ref()
            .zip(block_format)
            .and_then(|(b, f)| Some((f, b.blocks(f)?)));
        blocks.ok_or_else(|| mip_chain(img.width, img.height, &img.rgba8, srgb))
    });
    let mut texture_bytes = 0u64;
    let views: std::collections::HashMap<(usize, bool), wgpu::TextureView> = used
        .iter()
        .zip(chains)
        .map(|(&(image, srgb), levels)| {
            let img = &model.images[image];
            let view = match levels {
                Ok((format, blocks)) => {
                    let (view, bytes) = crate::block_textures::upload(gpu, &img.name, format, srgb, &blocks);
                    texture_bytes += bytes;
                    view
                }
                Err(levels) => {
                    texture_bytes += levels.iter().map(|(_, _, l)| l.len() as u64).sum::<u64>();
                    upload_mip_chain(gpu, &img.name, img.width, img.height, &levels, srgb)
                }
            };
            ((image, srgb), view)
        })
        .collect();
    let white = upload_texture(gpu, "white", 1, 1, &[255, 255, 255, 255], false);
    let flat_normal = upload_texture(gpu, "flat normal", 1, 1, &[128, 128, 255, 255], false);
    let default_sampler = create_sampler(device, &Sampler::default());
    let no_layer_textures = crate::layer_textures::placeholder(gpu);
    let (layer_textures, layer_texture_bytes) = crate::layer_textures::upload_all(gpu, model);
    let mut layer_textures = layer_textures.into_iter();
    let glass_shadows = model.materials.iter().any(|m| m.transmits());
    let materials = model
        .materials
        .iter()
        .map(|m| {
            let transmits = m.transmits();
            let layer_textures = layer_textures.next().flatten();
            let layer_of_slot = layer_textures.as_ref().map_or([None; 12], |l| l.layer_of_slot);
            let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("material"),
                contents: bytemuck::bytes_of(&MaterialUniform::new(m, layer_of_slot)),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let fallbacks = [&white, &white, &flat_normal, &white, &white, &white, &white];
            let slots: Vec<(Option<(TextureRef, bool)>, &wgpu::TextureView)> =
                m.own_slot_textures().into_iter().zip(fallbacks).collect();
            let samplers: Vec<wgpu::Sampler> = slots
                .iter()
                .map(|(t, _)| t.map_or_else(|| default_sampler.clone(), |(t, _)| create_sampler(device, &t.sampler)))
                .collect();
            let mut entries = vec![wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform.as_entire_binding(),
            }];
            let mut textures = [false; 7];
            for (i, (t, fallback)) in slots.iter().enumerate() {
                let found = t.and_then(|(t, srgb)| views.get(&(t.image, srgb)));
                textures[i] = found.is_some();
                let view = found.unwrap_or(fallback);
                entries.push(wgpu::BindGroupEntry {
                    binding: 1 + 2 * i as u32,
                    resource: wgpu::BindingResource::TextureView(view),
                });
                entries.push(wgpu::BindGroupEntry {
                    binding: 2 + 2 * i as u32,
                    resource: wgpu::BindingResource::Sampler(&samplers[i]),
                });
            }
            entries.push(wgpu::BindGroupEntry {
                binding: 15,
                resource: wgpu::BindingResource::TextureView(
                    layer_textures.as_ref().map_or(&no_layer_textures, |l| &l.view),
                ),
            });
            entries.push(wgpu::BindGroupEntry {
                binding: 16,
                resource: wgpu::BindingResource::Sampler(
                    layer_textures.as_ref().map_or(&default_sampler, |l| &l.sampler),
                ),
            });
            GpuMaterial {
                bind: device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(&m.name),
                    layout,
                    entries: &entries,
                }),
                variant: MaterialVariant {
                    // A volume's front faces carry its whole absorption (`scene.wgsl`): its back
                    // faces would filter what is behind it a second time.
                    double_sided: m.double_sided && !(transmits && m.layers.thickness > 0.0),
                    cull_front: false,
                    // What light passes through is drawn with the blended surfaces: after the
                    // opaque ones, back to front, hiding nothing.
                    blend: m.alpha == AlphaMode::Blend || transmits,
                    textures,
                    mask: matches!(m.alpha, AlphaMode::Mask(_)),
                    fade: false,
                    layer: if transmits { DrawLayer::Light } else { DrawLayer::Whole },
                    backdrop: m.blurs_or_bends(),
                    // A layer texture scales a factor even where the factors are the core
                    // material's (a specular texture over the default strength).
                    layers: m.layers != Layers::default() || layer_textures.is_some(),
                    layer_textures: layer_textures.is_some(),
                    glass_shadows,
                },
                blurs: m.blurs(),
                _uniform: uniform,
            }
        })
        .collect();
    // A mesh larger than one buffer (the device's `max_buffer_size`) is drawn in pieces.
    let max_bytes = device.limits().max_buffer_size;
    let max_vertices = (max_bytes / std::mem::size_of::<phantogram_assets::model::Vertex>() as u64) as usize;
    let max_indices = (max_bytes / 4) as usize;
    // `lods`: the primitive's coarser levels, over the same vertices (none for a piece).
    let piece = |source: usize,
                 p: &phantogram_assets::model::Primitive,
                 mesh: &phantogram_assets::model::Mesh,
                 lods: &[phantogram_assets::model::Lod]| {
        // One index buffer: the full mesh's, then each level's (copied only when there are
        // levels: a big mesh without them is uploaded from where it is).
        let mut levels = Vec::with_capacity(lods.len() + 1);
        levels.push(0..mesh.indices.len() as u32);
        let level_errors_m: Vec<f32> = std::iter::once(0.0).chain(lods.iter().map(|l| l.error_m)).collect();
        let indices: std::borrow::Cow<[u32]> = if lods.is_empty() {
            std::borrow::Cow::Borrowed(&mesh.indices)
        } else {
            let mut all = mesh.indices.clone();
            for lod in lods {
                let start = all.len() as u32;
                all.extend_from_slice(&lod.indices);
                levels.push(start..all.len() as u32);
            }
            std::borrow::Cow::Owned(all)
        };
        GpuPrimitive {
            vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("vertices"),
                contents: bytemuck::cast_slice(&mesh.vertices),
                // COPY_DST: moving bodies (the Diorama) rewrite them in place each frame.
                usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
            }),
            vertex_count: mesh.vertices.len(),
            indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("indices"),
                contents: bytemuck::cast_slice(&indices),
                usage: wgpu::BufferUsages::INDEX,
            }),
            levels,
            level_errors_m,
            source,
            material: p.material.min(model.materials.len().saturating_sub(1)),
            // The whole primitive's centre, for the transparent pieces' back-to-front order.
            centre: p.mesh.bounds().map_or(Vec3::ZERO, |b| (b.min + b.max) * 0.5),
            bounds: mesh.bounds(),
            is_floor: p.is_floor,
        }
    };
    let mut primitives = Vec::new();
    for (source, p) in model
        .primitives
        .iter()
        .enumerate()
        .filter(|(_, p)| !p.mesh.indices.is_empty())
    {
        let all_indices = p.mesh.indices.len() + p.lods.iter().map(|l| l.indices.len()).sum::<usize>();
        if p.mesh.vertices.len() <= max_vertices && all_indices <= max_indices {
            primitives.push(piece(source, p, &p.mesh, &p.lods));
        } else {
            // Pieces of a mesh too big for one buffer are drawn at full detail (a scan that
            // big is split into parts with levels before it gets here: `phantogram-detail`).
            primitives.extend(
                p.mesh
                    .split_to_fit(max_vertices, max_indices)
                    .iter()
                    .map(|m| piece(source, p, m, &[])),
            );
        }
    }
    let fallback = phantogram_geometry::containment::Aabb::new(Vec3::splat(-0.05), Vec3::splat(0.05));
    let bounds = model.bounds().unwrap_or(fallback);
    let standing = model.bounds_of(|p| !p.is_floor).unwrap_or(bounds);
    GpuModel {
        primitives,
        materials,
        bounds,
        standing,
        impostors: Vec::new(),
        texture_bytes: texture_bytes.saturating_add(layer_texture_bytes),
    }
}
