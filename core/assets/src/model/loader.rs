//! The glTF 2.0 loader: documents, accessors, Draco, materials and images,
//! Smithsonian Voyager scenes, into a [`Model`] (see the parent module's docs for what it reads
//! and how it fails).

use std::path::{Path, PathBuf};

use base64::Engine as _;
use glam::{Mat4, Quat, Vec3};
use gltf::accessor::{DataType, Dimensions};
use thiserror::Error;

use super::LayerSlot;
use super::encoded_image::Encoded;
use super::instancing;
use super::meshopt_views::{self, DecodedViews};
use super::point_cloud;
use super::skin;
use super::spec_gloss::{self, SpecGloss};
use super::tangents::{TangentUv, generate_tangents};
use super::texture_info::TextureInfo;
use super::topology;
use super::*;
use crate::budget::{OverBudget, ResourceBudget, Spending};
use crate::progress::{Progress, Span};
use phantogram_files::text::excerpt;

/// Largest Voyager scene read: its JSON lists derivatives and annotations, kilobytes in practice.
const MAX_SCENE_BYTES: u64 = 16 << 20;

/// Largest coordinate a vertex may have, in the model's units after its node transforms: beyond
/// it (or non-finite) the bounds and the fit to the screen overflow, and the frame is blank.
pub const MAX_COORDINATE: f32 = 1e9;

/// Extensions this loader implements; a file requiring any other fails to load, one merely
/// using another loads with a warning naming it.
pub const SUPPORTED_EXTENSIONS: [&str; 21] = [
    "KHR_draco_mesh_compression",
    "EXT_mesh_gpu_instancing",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
    "KHR_mesh_quantization",
    "KHR_texture_transform",
    "KHR_materials_emissive_strength",
    "KHR_materials_unlit",
    "EXT_texture_webp",
    "KHR_texture_basisu",
    "KHR_materials_pbrSpecularGlossiness",
    super::layers::EXTENSIONS[0],
    super::layers::EXTENSIONS[1],
    super::layers::EXTENSIONS[2],
    super::layers::EXTENSIONS[3],
    super::layers::EXTENSIONS[4],
    super::layers::EXTENSIONS[5],
    super::layers::EXTENSIONS[6],
    super::layers::EXTENSIONS[7],
    super::layers::EXTENSIONS[8],
    super::layers::EXTENSIONS[9],
];

#[derive(Debug, Error)]
pub enum ModelError {
    /// The I/O error is part of the message, deliberately not a `source()`: chain printers
    /// (`anyhow`'s `{:#}`) would show it twice, and the shells show the message alone.
    #[error("{}: {error}", path.display())]
    Io { path: PathBuf, error: std::io::Error },
    /// The file is not one of its format (`format`: "glTF", "STL", "PLY", "OBJ", "point
    /// cloud") as written.
    #[error("{}: not a valid {format} file: {message}", path.display())]
    Parse {
        path: PathBuf,
        format: &'static str,
        message: String,
    },
    #[error(
            "{}: requires the glTF extension {name}, which is not supported (supported: {})",
            path.display(),
            SUPPORTED_EXTENSIONS.join(", ")
        )]
    UnsupportedExtension { path: PathBuf, name: String },
    #[error("{}: {what}: {message}", path.display())]
    Data {
        path: PathBuf,
        what: String,
        message: String,
    },
    #[error("{}: no triangles to draw", path.display())]
    Empty { path: PathBuf },
    /// The file asks for more than the device's [`ResourceBudget`] allows.
    #[error("{}: {error}", path.display())]
    OverBudget { path: PathBuf, error: OverBudget },
    /// A Voyager scene (`*.svx.json`) that cannot be read as one.
    #[error("{}: not a valid Voyager scene: {message}", path.display())]
    Scene { path: PathBuf, message: String },
    /// A folder or a Voyager scene that names no model file this loader can open.
    #[error("{}: {message}", path.display())]
    NotAModel { path: PathBuf, message: String },
    /// The load was given up ([`Progress::cancel`]).
    #[error("{}: loading was cancelled", path.display())]
    Cancelled { path: PathBuf },
}

pub(super) fn over_budget(path: &Path, error: OverBudget) -> ModelError {
    ModelError::OverBudget {
        path: path.to_path_buf(),
        error,
    }
}

/// The bytes of a buffer view, checked against its buffer (decoded first if compressed).
fn view_bytes_of<'b>(
    path: &Path,
    buffers: &'b [Vec<u8>],
    decoded: &'b DecodedViews,
    view: &gltf::buffer::View,
) -> Result<&'b [u8], ModelError> {
    if let Some(bytes) = decoded.bytes(view) {
        return Ok(bytes);
    }
    let data = |message: &str| ModelError::Data {
        path: path.to_path_buf(),
        what: format!("bufferView {}", view.index()),
        message: message.to_owned(),
    };
    let buf = buffers
        .get(view.buffer().index())
        .ok_or_else(|| data("buffer missing"))?;
    let end = view.offset().checked_add(view.length());
    end.and_then(|end| buf.get(view.offset()..end))
        .ok_or_else(|| data("extends past the end of its buffer"))
}

struct Ctx<'a> {
    path: &'a Path,
    buffers: Vec<Vec<u8>>,
    decoded: DecodedViews,
    spending: std::cell::RefCell<Spending>,
}

impl Ctx<'_> {
    /// Fails unless a transient buffer of `bytes` fits what is left of the budget.
    fn check_bytes(&self, what: impl FnOnce() -> String, bytes: u64) -> Result<(), ModelError> {
        self.spending
            .borrow()
            .check_bytes(what, bytes)
            .map_err(|e| over_budget(self.path, e))
    }

    fn data(&self, what: impl Into<String>, message: impl Into<String>) -> ModelError {
        ModelError::Data {
            path: self.path.to_path_buf(),
            what: what.into(),
            message: message.into(),
        }
    }

    fn view_bytes(&self, view: &gltf::buffer::View) -> Result<&[u8], ModelError> {
        view_bytes_of(self.path, &self.buffers, &self.decoded, view)
    }

    /// Reads an accessor as `f32` rows of `n` components (normalised integers mapped to
    /// [0, 1] or [−1, 1] as the spec says; other integers converted as they are).
    fn read_f32(&self, accessor: &gltf::Accessor, n: usize) -> Result<Vec<f32>, ModelError> {
        let what = || format!("accessor {}", accessor.index());
        // Components the accessor lacks (a VEC3 colour read as four) stay zero; the caller
        // asks for what the attribute's semantic needs.
        let comps = accessor.dimensions().multiplicity();
        let count = accessor.count();
        let ty = accessor.data_type();
        let size = ty.size();
        let normalized = accessor.normalized();
        let convert = |bytes: &[u8]| -> f32 {
            match ty {
                DataType::F32 => f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]),
                DataType::U8 => {
                    let v = bytes[0] as f32;
                    if normalized { v / 255.0 } else { v }
                }
                DataType::I8 => {
                    let v = bytes[0] as i8 as f32;
                    if normalized { (v / 127.0).max(-1.0) } else { v }
                }
                DataType::U16 => {
                    let v = u16::from_le_bytes([bytes[0], bytes[1]]) as f32;
                    if normalized { v / 65535.0 } else { v }
                }
                DataType::I16 => {
                    let v = i16::from_le_bytes([bytes[0], bytes[1]]) as f32;
                    if normalized { (v / 32767.0).max(-1.0) } else { v }
                }
                DataType::U32 => u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]) as f32,
            }
        };
        let elem = size * comps;
        let data = match accessor.view() {
            Some(view) => {
                let bytes = self.view_bytes(&view)?;
                let stride = view.stride().unwrap_or(elem);
                if stride < elem {
                    return Err(self.data(what(), "byte stride smaller than one element"));
                }
                // One past the last byte read; None when it overflows.
                let end = |last: usize| {
                    last.checked_mul(stride)?
                        .checked_add(accessor.offset())?
                        .checked_add(elem)
                };
                let fits = count
                    .checked_sub(1)
                    .is_none_or(|last| end(last).is_some_and(|e| e <= bytes.len()));
                if !fits {
                    return Err(self.data(what(), "extends past the end of its buffer view"));
                }
                Some((bytes, stride))
            }
            // No data in the file: zeros (plus any sparse values), so the count alone sizes
            // the output, checked against the budget below.
            None => None,
        };
        // Every size was checked before this allocation: a damaged count must give an
        // error, not an allocation failure (which aborts rather than unwinds).
        self.check_bytes(what, (count as u64).saturating_mul(n as u64 * 4))?;
        let mut out = vec![0.0f32; count * n];
        if let Some((bytes, stride)) = data {
            let start = accessor.offset();
            for i in 0..count {
                let base = start + i * stride;
                for c in 0..n.min(comps) {
                    out[i * n + c] = convert(&bytes[base + c * size..base + (c + 1) * size]);
                }
            }
        }
        if let Some(sparse) = accessor.sparse() {
            if sparse.count() == 0 {
                // glTF 2.0: `accessor.sparse.count` is at least 1.
                return Err(self.data(what(), "sparse with a count of 0"));
            }
            let idx_view = sparse.indices().view();
            let idx_bytes = self.view_bytes(&idx_view)?;
            let idx_size = match sparse.indices().index_type() {
                gltf::accessor::sparse::IndexType::U8 => 1,
                gltf::accessor::sparse::IndexType::U16 => 2,
                gltf::accessor::sparse::IndexType::U32 => 4,
            };
            let val_bytes = self.view_bytes(&sparse.values().view())?;
            // Offsets may be anything in a damaged file: ranges that overflow are out of range.
            let range = |offset: usize, k: usize, len: usize| {
                let start = k.checked_mul(len)?.checked_add(offset)?;
                Some(start..start.checked_add(len)?)
            };
            for k in 0..sparse.count() {
                let ib = range(sparse.indices().offset(), k, idx_size)
                    .and_then(|r| idx_bytes.get(r))
                    .ok_or_else(|| self.data(what(), "sparse indices out of range"))?;
                let i = match idx_size {
                    1 => ib[0] as usize,
                    2 => u16::from_le_bytes([ib[0], ib[1]]) as usize,
                    _ => u32::from_le_bytes([ib[0], ib[1], ib[2], ib[3]]) as usize,
                };
                if i >= count {
                    return Err(self.data(what(), "sparse index past the accessor's count"));
                }
                let vb = range(sparse.values().offset(), k, elem)
                    .and_then(|r| val_bytes.get(r))
                    .ok_or_else(|| self.data(what(), "sparse values out of range"))?;
                for c in 0..n.min(comps) {
                    out[i * n + c] = convert(&vb[c * size..(c + 1) * size]);
                }
            }
        }
        Ok(out)
    }

    fn read_indices(&self, accessor: &gltf::Accessor) -> Result<Vec<u32>, ModelError> {
        if accessor.dimensions() != Dimensions::Scalar
            || !matches!(accessor.data_type(), DataType::U8 | DataType::U16 | DataType::U32)
        {
            return Err(self.data(
                format!("accessor {}", accessor.index()),
                "indices must be unsigned scalars",
            ));
        }
        Ok(self.read_f32(accessor, 1)?.into_iter().map(|v| v as u32).collect())
    }
}

/// The structural checks gltf-rs makes in `Gltf::from_slice`, less those that would reject
/// files we load correctly. gltf-rs's accessors index its arrays unchecked (`node.children()`,
/// `primitive.material()`, `texture.source()`, `accessor.data_type()` …), so an index out of
/// range or an unknown enum value must be caught here, before any of them is called, or a
/// damaged file panics the loader. We parse without validation because gltf-rs rejects
/// every required extension it does not implement itself (Draco among them), and we name an
/// unsupported one ourselves. Not fatal here:
/// * `Unsupported`: required extensions, checked against [`SUPPORTED_EXTENSIONS`] before;
/// * a missing `bufferView` on an accessor: Draco-compressed primitives' accessors have none
///   (and the core spec fills such an accessor with zeros, as [`Ctx::read_f32`] does);
/// * a missing or malformed `min`/`max` on a `POSITION` accessor: we compute bounds ourselves.
fn check_structure(root: &gltf::json::Root) -> Result<(), String> {
    use gltf::json::validation::{Error, Validate};
    // gltf-json's own check of POSITION's min/max indexes the accessors unchecked: make sure
    // it can before running it.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            for (semantic, index) in &prim.attributes {
                if index.value() >= root.accessors.len() {
                    return Err(format!(
                        "meshes[{m}].primitives[{p}].attributes.{}: accessor {} does not exist",
                        semantic.to_string(),
                        index.value()
                    ));
                }
            }
        }
    }
    // gltf-rs's `Image::source` unwraps these two (glTF 2.0 requires them; its validation does
    // not check them): found by fuzzing.
    for (i, image) in root.images.iter().enumerate() {
        match (&image.buffer_view, &image.uri, &image.mime_type) {
            (Some(_), _, None) => return Err(format!("images[{i}]: a bufferView without a mimeType")),
            (None, None, _) => return Err(format!("images[{i}]: neither a uri nor a bufferView")),
            _ => {}
        }
    }
    // A texture's image named by an extension, by index as its `source` would be
    // (`texture_image`).
    for (t, texture) in root.textures.iter().enumerate() {
        for name in IMAGE_EXTENSIONS {
            let extension = texture.extensions.as_ref().and_then(|e| e.others.get(name));
            if let Some(source) = extension.and_then(|w| w.get("source"))
                && source.as_u64().is_none_or(|i| i >= root.images.len() as u64)
            {
                return Err(format!(
                    "textures[{t}].extensions.{name}.source: image {source} does not exist"
                ));
            }
        }
    }
    let mut errors = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |path, error| {
        let path = path().to_string();
        let position_bounds = path.contains("POSITION") && (path.ends_with(".min") || path.ends_with(".max"));
        let tolerated = match error {
            Error::Unsupported => true,
            Error::Missing => position_bounds || (path.starts_with("accessors[") && path.ends_with(".bufferView")),
            Error::Invalid => position_bounds,
            _ => false,
        };
        if !tolerated {
            errors.push(format!("{path}: {error}"));
        }
    });
    match errors.len() {
        0 => Ok(()),
        1 => Err(errors.swap_remove(0)),
        n => Err(format!("{} (and {} more)", errors[0], n - 1)),
    }
}

fn data_uri(uri: &str) -> Option<Result<Vec<u8>, base64::DecodeError>> {
    let rest = uri.strip_prefix("data:")?;
    let (_, payload) = rest.split_once(";base64,")?;
    Some(base64::engine::general_purpose::STANDARD.decode(payload))
}

/// The bytes a buffer or image `uri` names: a `data:` URI, or a file inside the model's folder
/// ([`resolve_inside`]), at most `max_bytes` of it.
fn load_uri(path: &Path, uri: &str, max_bytes: u64) -> Result<Vec<u8>, ModelError> {
    if let Some(decoded) = data_uri(uri) {
        return decoded.map_err(|e| ModelError::Parse {
            format: "glTF",
            path: path.to_path_buf(),
            message: format!("bad data URI: {e}"),
        });
    }
    let folder = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let file = resolve_inside(folder, uri).map_err(|message| ModelError::Data {
        path: path.to_path_buf(),
        what: format!("URI {}", excerpt(uri)),
        message,
    })?;
    phantogram_files::read_regular_file(&file, max_bytes).map_err(|error| ModelError::Io { path: file, error })
}

/// Where a relative URI points inside `folder`, or why it may not be followed.
///
/// A model may name files only in its own folder and the folders below it: no scheme
/// (`file:`, `http:`), no absolute path, no `..` (also percent-encoded, `%2e%2e`), no symbolic
/// link leading out. A downloaded model could otherwise read whatever the app may read (its
/// private files on a phone, `/etc/passwd`, `/dev/zero`). Regular files only: checked by the
/// read, [`phantogram_files::read_regular_file`].
pub fn resolve_inside(folder: &Path, uri: &str) -> Result<PathBuf, String> {
    let scheme_len = uri.find(':').filter(|&i| {
        i > 0
            && uri[..i]
                .bytes()
                .all(|b| b.is_ascii_alphanumeric() || b"+-.".contains(&b))
    });
    if scheme_len.is_some() {
        return Err("names another location (a URI scheme); only files beside the model are read".into());
    }
    let decoded = percent_decode(uri).ok_or("is not valid percent-encoded UTF-8")?;
    if decoded.contains(['\0', '\\']) {
        return Err("holds a NUL or a backslash, which no portable file name has".into());
    }
    let relative = Path::new(&decoded);
    if !relative
        .components()
        .all(|c| matches!(c, std::path::Component::Normal(_) | std::path::Component::CurDir))
    {
        return Err(
            "leaves the model's folder (an absolute path or `..`); only files beside the model are read".into(),
        );
    }
    let base = std::fs::canonicalize(folder).map_err(|e| format!("the model's folder: {e}"))?;
    let resolved = std::fs::canonicalize(base.join(relative)).map_err(|e| e.to_string())?;
    if !resolved.starts_with(&base) {
        return Err("is a link leading out of the model's folder; only files beside the model are read".into());
    }
    Ok(resolved)
}

/// RFC 3986 percent-decoding; `None` when the result is not UTF-8. A `%` not followed by two
/// hex digits stays as it is (file names in the wild hold a bare `%`).
fn percent_decode(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let hex = |b: u8| (b as char).to_digit(16);
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%'
            && let (Some(hi), Some(lo)) = (
                bytes.get(i + 1).copied().and_then(hex),
                bytes.get(i + 2).copied().and_then(hex),
            )
        {
            out.push((hi * 16 + lo) as u8);
            i += 3;
            continue;
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8(out).ok()
}

fn sampler_of(t: &gltf::Texture) -> Sampler {
    use gltf::texture::{MagFilter, MinFilter, WrappingMode};
    let s = t.sampler();
    let wrap = |w: WrappingMode| match w {
        WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
        WrappingMode::Repeat => Wrap::Repeat,
    };
    let (min_linear, mip_linear) = match s.min_filter() {
        Some(MinFilter::Nearest | MinFilter::NearestMipmapNearest) => (false, false),
        Some(MinFilter::NearestMipmapLinear) => (false, true),
        Some(MinFilter::LinearMipmapNearest) => (true, false),
        _ => (true, true),
    };
    Sampler {
        mag_linear: !matches!(s.mag_filter(), Some(MagFilter::Nearest)),
        min_linear,
        mip_linear,
        wrap_u: wrap(s.wrap_s()),
        wrap_v: wrap(s.wrap_t()),
    }
}

/// Texture extensions that name an image in place of the texture's `source`, with its own
/// codec: WebP, and KTX 2.0 with Basis Universal ([`super::encoded_image`]).
const IMAGE_EXTENSIONS: [&str; 2] = ["EXT_texture_webp", "KHR_texture_basisu"];

/// The image a texture shows: its `source` (PNG or JPEG), or else the image one of
/// [`IMAGE_EXTENSIONS`] names (a file made for the web may carry only those). Where both are
/// given, `source` is the fallback the extensions define; it is preferred because every texture
/// is uploaded as RGBA8 anyway, and the fallback is the lossless copy (a Basis texture is a
/// lossy recompression). `None` when it names no image (glTF 2.0 lets an extension we do not
/// know supply it).
fn texture_image(t: &gltf::Texture) -> Option<usize> {
    t.source().map(|i| i.index()).or_else(|| {
        IMAGE_EXTENSIONS.iter().find_map(|name| {
            let source = t.extension_value(name)?.get("source")?.as_u64()?;
            usize::try_from(source).ok()
        })
    })
}

/// A texture reference; `transform` is `KHR_texture_transform` with its optional texCoord
/// override. `None` (and a warning) for a texture whose image we cannot find ([`texture_image`]).
fn texture_ref(
    t: &gltf::Texture,
    tex_coord: u32,
    transform: Option<(UvTransform, Option<u32>)>,
    what: &str,
    warnings: &mut Vec<String>,
) -> Option<TextureRef> {
    let Some(image) = texture_image(t) else {
        warnings.push(format!(
            "{what}: texture {} has no image this loader reads; left out",
            t.index()
        ));
        return None;
    };
    let (transform, tex_coord) = match transform {
        Some((uv, set)) => (uv, set.unwrap_or(tex_coord)),
        None => (UvTransform::default(), tex_coord),
    };
    Some(TextureRef {
        image,
        tex_coord: tex_coord.min(1),
        transform,
        sampler: sampler_of(t),
    })
}

fn typed_transform(tt: gltf::texture::TextureTransform) -> (UvTransform, Option<u32>) {
    let uv = UvTransform {
        offset: tt.offset(),
        rotation_rad: tt.rotation(),
        scale: tt.scale(),
    };
    (uv, tt.tex_coord())
}

/// `KHR_texture_transform` on a normal or occlusion texture. gltf-rs types the extension
/// only on `textureInfo`, so here it is read from the raw extension object; a malformed one
/// is reported in `warnings` and the texture used untransformed.
fn raw_transform(
    value: Option<&serde_json::Value>,
    what: &str,
    warnings: &mut Vec<String>,
) -> Option<(UvTransform, Option<u32>)> {
    let value = value?;
    match serde_json::from_value::<gltf::json::extensions::texture::TextureTransform>(value.clone()) {
        Ok(tt) => Some((
            UvTransform {
                offset: tt.offset.0,
                rotation_rad: tt.rotation.0,
                scale: tt.scale.0,
            },
            tt.tex_coord,
        )),
        Err(e) => {
            warnings.push(format!("{what}: KHR_texture_transform ignored ({e})"));
            None
        }
    }
}

fn material_of(m: &gltf::Material, warnings: &mut Vec<String>) -> Material {
    let pbr = m.pbr_metallic_roughness();
    let name = m.name().unwrap_or("unnamed");
    let mut info = |i: Option<gltf::texture::Info>, slot: &str| {
        let i = i?;
        let what = format!("material {name}, {slot} texture");
        texture_ref(
            &i.texture(),
            i.tex_coord(),
            i.texture_transform().map(typed_transform),
            &what,
            warnings,
        )
    };
    let base_color_texture = info(pbr.base_color_texture(), "base colour");
    let metallic_roughness_texture = info(pbr.metallic_roughness_texture(), "metallic-roughness");
    let emissive_texture = info(m.emissive_texture(), "emissive");
    let normal_texture = m.normal_texture().and_then(|n| {
        let what = format!("material {name}, normal texture");
        let transform = raw_transform(n.extension_value("KHR_texture_transform"), &what, warnings);
        Some((
            texture_ref(&n.texture(), n.tex_coord(), transform, &what, warnings)?,
            n.scale(),
        ))
    });
    let occlusion_texture = m.occlusion_texture().and_then(|o| {
        let what = format!("material {name}, occlusion texture");
        let transform = raw_transform(o.extension_value("KHR_texture_transform"), &what, warnings);
        Some((
            texture_ref(&o.texture(), o.tex_coord(), transform, &what, warnings)?,
            o.strength(),
        ))
    });
    let strength = m.emissive_strength().unwrap_or(1.0);
    let e = m.emissive_factor();
    let layers = Layers::from_extensions(|name| m.extension_value(name), &format!("material {name}"), warnings);
    Material {
        name: name.to_owned(),
        // glTF colour factors are linear already.
        base_color: pbr.base_color_factor(),
        metallic: pbr.metallic_factor(),
        roughness: pbr.roughness_factor(),
        emissive: [e[0] * strength, e[1] * strength, e[2] * strength],
        alpha: match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => AlphaMode::Mask(m.alpha_cutoff().unwrap_or(0.5)),
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        },
        double_sided: m.double_sided(),
        unlit: m.unlit(),
        base_color_texture,
        metallic_roughness_texture,
        normal_texture,
        occlusion_texture,
        emissive_texture,
        // Read with the document's textures (`extension_texture`).
        transmission_texture: None,
        thickness_texture: None,
        scenery: false,
        layers,
        layer_textures: Default::default(),
    }
}

/// `material` in the specular–glossiness workflow `value` describes
/// (`KHR_materials_pbrSpecularGlossiness`), converted to metallic–roughness (`spec_gloss`): from
/// the factors, or texel by texel into new images appended to `images` (charged to `spending`).
/// A malformed extension is ignored with a warning.
fn with_spec_gloss(
    material: &mut Material,
    value: &serde_json::Value,
    doc: &gltf::Document,
    images: &mut Vec<Image>,
    spending: &std::cell::RefCell<Spending>,
    warnings: &mut Vec<String>,
) -> Result<(), OverBudget> {
    let name = material.name.clone();
    let sg: SpecGloss = match spec_gloss::read(value) {
        Ok(sg) => sg,
        Err(e) => {
            warnings.push(format!(
                "material {name}: KHR_materials_pbrSpecularGlossiness ignored ({e})"
            ));
            return Ok(());
        }
    };
    let image_count = images.len();
    let mut texture = |info: &TextureInfo, slot: &str| {
        texture_of_info(
            doc,
            info,
            &format!("material {name}, {slot} texture"),
            image_count,
            warnings,
        )
    };
    let diffuse_texture = sg.diffuse_texture.as_ref().and_then(|i| texture(i, "diffuse"));
    let sg_texture = sg
        .specular_glossiness_texture
        .as_ref()
        .and_then(|i| texture(i, "specular-glossiness"));
    let diffuse = [sg.diffuse[0], sg.diffuse[1], sg.diffuse[2]];
    let Some(sg_texture) = sg_texture else {
        let metallic = spec_gloss::metallic(diffuse, sg.specular);
        let [r, g, b] = spec_gloss::base_colour(diffuse, sg.specular, metallic);
        material.base_color = [r, g, b, sg.diffuse[3]];
        material.metallic = metallic;
        material.roughness = 1.0 - sg.glossiness;
        material.base_color_texture = diffuse_texture;
        material.metallic_roughness_texture = None;
        return Ok(());
    };
    // The base colour is baked with the specular only where both textures cover the surface alike.
    let alike = diffuse_texture.filter(|d| (d.tex_coord, d.transform) == (sg_texture.tex_coord, sg_texture.transform));
    let (metal_rough, base) = spec_gloss::bake(&sg, &images[sg_texture.image], alike.map(|d| &images[d.image]));
    let mut add = |image: Image| -> Result<usize, OverBudget> {
        spending
            .borrow_mut()
            .charge_image(|| format!("material {name}: {}", image.name), image.width, image.height)?;
        images.push(image);
        Ok(images.len() - 1)
    };
    material.metallic_roughness_texture = Some(TextureRef {
        image: add(metal_rough)?,
        ..sg_texture
    });
    material.metallic = 1.0;
    material.roughness = 1.0;
    match (base, alike) {
        (Some(base), Some(d)) => {
            material.base_color_texture = Some(TextureRef { image: add(base)?, ..d });
            material.base_color = [1.0; 4];
        }
        _ => {
            material.base_color_texture = diffuse_texture;
            material.base_color = sg.diffuse;
        }
    }
    Ok(())
}

/// The texture a `textureInfo` of an extension's JSON names (`what` names it in warnings); `None`
/// (and a warning) where the texture or its image does not exist.
fn texture_of_info(
    doc: &gltf::Document,
    info: &TextureInfo,
    what: &str,
    image_count: usize,
    warnings: &mut Vec<String>,
) -> Option<TextureRef> {
    let Some(t) = doc.textures().nth(info.index) else {
        warnings.push(format!("{what}: texture {} does not exist; left out", info.index));
        return None;
    };
    let transform = raw_transform(info.transform.as_ref(), what, warnings);
    texture_ref(&t, info.tex_coord, transform, what, warnings).filter(|r| r.image < image_count)
}

/// The texture under `key` in a material extension's object (`value`) of `material` (`slot`
/// names it in warnings); a malformed one is left out with a warning.
fn extension_texture(
    material: &Material,
    value: &serde_json::Value,
    key: &str,
    slot: &str,
    doc: &gltf::Document,
    image_count: usize,
    warnings: &mut Vec<String>,
) -> Option<TextureRef> {
    let what = format!("material {}, {slot} texture", material.name);
    match TextureInfo::read(value, key) {
        Ok(info) => texture_of_info(doc, &info?, &what, image_count, warnings),
        Err(e) => {
            warnings.push(format!("{what}: {e}; left out"));
            None
        }
    }
}

/// Each joint's world matrix times its inverse bind matrix (identity where the skin gives
/// none), for [`skin::apply`].
fn skin_matrices(ctx: &Ctx, s: &gltf::Skin, node_worlds: &[Mat4]) -> Result<Vec<Mat4>, ModelError> {
    let what = || format!("skin {}", s.index());
    let joints: Vec<usize> = s.joints().map(|j| j.index()).collect();
    let inverse_binds = match s.inverse_bind_matrices() {
        Some(accessor) => {
            if accessor.dimensions() != Dimensions::Mat4 || accessor.count() < joints.len() {
                return Err(ctx.data(
                    what(),
                    format!(
                        "inverseBindMatrices must be {} MAT4s (accessor {})",
                        joints.len(),
                        accessor.index()
                    ),
                ));
            }
            ctx.read_f32(&accessor, 16)?
                .chunks_exact(16)
                .map(Mat4::from_cols_slice)
                .collect()
        }
        None => vec![Mat4::IDENTITY; joints.len()],
    };
    joints
        .iter()
        .zip(&inverse_binds)
        .map(|(&j, inverse_bind)| {
            node_worlds
                .get(j)
                .map(|world| *world * *inverse_bind)
                .ok_or_else(|| ctx.data(what(), format!("joint node {j} does not exist")))
        })
        .collect()
}

/// How much `world` stretches a length: its linear part's largest column (exact for the similarity
/// transforms glTF's nodes are in practice: rotation, uniform scale); 1 where that is not a
/// positive finite number.
fn length_scale(world: Mat4) -> f32 {
    let linear = glam::Mat3::from_mat4(world);
    let scale = linear
        .x_axis
        .length()
        .max(linear.y_axis.length())
        .max(linear.z_axis.length());
    if scale.is_finite() && scale > 0.0 { scale } else { 1.0 }
}

/// The transforms of a node's `EXT_mesh_gpu_instancing` instances, `None` without the extension
/// ([`instancing`]). Each attribute must be the extension's type (`TRANSLATION` and `SCALE`
/// VEC3, `ROTATION` VEC4, integer rotations normalised), all of one count.
fn instance_transforms(ctx: &Ctx, doc: &gltf::Document, node: &gltf::Node) -> Result<Option<Vec<Mat4>>, ModelError> {
    let Some(extension) = node.extension_value("EXT_mesh_gpu_instancing") else {
        return Ok(None);
    };
    let what = format!("node {} (EXT_mesh_gpu_instancing)", node.index());
    let attributes = extension.get("attributes").and_then(|a| a.as_object());
    let mut count = None;
    let mut read = |name: &str, dimensions: Dimensions| -> Result<Option<Vec<f32>>, ModelError> {
        let Some(index) = attributes.and_then(|a| a.get(name)) else {
            return Ok(None);
        };
        let accessor = index
            .as_u64()
            .and_then(|i| doc.accessors().nth(usize::try_from(i).ok()?))
            .ok_or_else(|| ctx.data(&what, format!("{name}: accessor {index} does not exist")))?;
        if accessor.dimensions() != dimensions {
            return Err(ctx.data(
                &what,
                format!(
                    "{name}: accessor {} is {:?}, not {dimensions:?}",
                    accessor.index(),
                    accessor.dimensions()
                ),
            ));
        }
        if *count.get_or_insert(accessor.count()) != accessor.count() {
            return Err(ctx.data(&what, "its attributes have different counts"));
        }
        ctx.read_f32(&accessor, dimensions.multiplicity()).map(Some)
    };
    let translation = read("TRANSLATION", Dimensions::Vec3)?;
    let rotation = read("ROTATION", Dimensions::Vec4)?;
    let scale = read("SCALE", Dimensions::Vec3)?;
    // No attribute: glTF leaves the count undefined; one instance where the node stands.
    let count = count.unwrap_or(1);
    // Each instance's matrix, and its world matrix after it (`Mat4`: 64 bytes), before either
    // is made: an accessor with no data reads as zeros, so its count alone sizes them.
    ctx.check_bytes(|| what.clone(), (count as u64).saturating_mul(128))?;
    instancing::matrices(count, translation.as_deref(), rotation.as_deref(), scale.as_deref())
        .map(Some)
        .map_err(|message| ctx.data(what, message))
}

/// Attribute data of one primitive before assembly.
#[derive(Default)]
struct Attributes {
    positions: Vec<f32>,
    normals: Option<Vec<f32>>,
    tangents: Option<Vec<f32>>,
    uv0: Option<Vec<f32>>,
    uv1: Option<Vec<f32>>,
    colors: Option<(Vec<f32>, usize)>,
    indices: Option<Vec<u32>>,
    /// `JOINTS_0` and `WEIGHTS_0`, four per vertex each, where both are present.
    skin: Option<(Vec<f32>, Vec<f32>)>,
}

/// The shapes glTF 2.0 allows each attribute we read ("Meshes", attribute table): a `NORMAL`
/// pointing at an index accessor, or a scalar `COLOR_0`, is a damaged file, not data to reshape.
fn allowed_dimensions(semantic: &gltf::Semantic) -> &'static [Dimensions] {
    use gltf::Semantic;
    match semantic {
        Semantic::Positions | Semantic::Normals => &[Dimensions::Vec3],
        Semantic::Tangents => &[Dimensions::Vec4],
        Semantic::TexCoords(_) => &[Dimensions::Vec2],
        Semantic::Joints(_) | Semantic::Weights(_) => &[Dimensions::Vec4],
        Semantic::Colors(_) => &[Dimensions::Vec3, Dimensions::Vec4],
    }
}

fn read_plain(ctx: &Ctx, prim: &gltf::Primitive) -> Result<Attributes, ModelError> {
    use gltf::Semantic;
    let mut a = Attributes::default();
    let what = || format!("mesh primitive {}", prim.index());
    for (semantic, accessor) in prim.attributes() {
        let allowed = allowed_dimensions(&semantic);
        if !allowed.contains(&accessor.dimensions()) {
            return Err(ctx.data(
                what(),
                format!(
                    "attribute {} is a {:?} accessor (accessor {}); glTF allows {allowed:?}",
                    semantic.to_string(),
                    accessor.dimensions(),
                    accessor.index()
                ),
            ));
        }
    }
    // The vertices and indices this primitive will become, before any is read.
    let count = |a: Option<gltf::Accessor>| a.map_or(0, |a| a.count() as u64);
    let vertices = count(prim.get(&Semantic::Positions));
    let indices = prim.indices().map_or(vertices, |i| i.count() as u64);
    ctx.check_bytes(what, ResourceBudget::mesh_bytes(vertices, indices))?;
    for (semantic, accessor) in prim.attributes() {
        match semantic {
            Semantic::Positions => a.positions = ctx.read_f32(&accessor, 3)?,
            Semantic::Normals => a.normals = Some(ctx.read_f32(&accessor, 3)?),
            Semantic::Tangents => a.tangents = Some(ctx.read_f32(&accessor, 4)?),
            Semantic::TexCoords(0) => a.uv0 = Some(ctx.read_f32(&accessor, 2)?),
            Semantic::TexCoords(1) => a.uv1 = Some(ctx.read_f32(&accessor, 2)?),
            Semantic::Colors(0) => {
                let n = accessor.dimensions().multiplicity();
                a.colors = Some((ctx.read_f32(&accessor, n)?, n));
            }
            _ => {}
        }
    }
    if let Some(idx) = prim.indices() {
        a.indices = Some(ctx.read_indices(&idx)?);
    }
    if let (Some(joints), Some(weights)) = (prim.get(&Semantic::Joints(0)), prim.get(&Semantic::Weights(0))) {
        a.skin = Some((ctx.read_f32(&joints, 4)?, ctx.read_f32(&weights, 4)?));
    }
    Ok(a)
}

/// Morph targets at the weights the file gives (the node's, else the mesh's): glTF draws a mesh
/// with weights at its targets' weighted sum, and no animation is played here, so these are the
/// pose it shows. `POSITION`, `NORMAL` and `TANGENT` displacements (VEC3, one per vertex) are
/// added; normals and tangents are renormalised with the node's transform.
fn apply_morph_targets(
    ctx: &Ctx,
    prim: &gltf::Primitive,
    weights: &[f32],
    a: &mut Attributes,
) -> Result<(), ModelError> {
    let vertices = a.positions.len() / 3;
    for (i, target) in prim.morph_targets().enumerate() {
        let w = weights.get(i).copied().unwrap_or(0.0);
        if w == 0.0 || !w.is_finite() {
            continue;
        }
        let what = || format!("mesh primitive {} morph target {i}", prim.index());
        let read = |accessor: gltf::Accessor| -> Result<Vec<f32>, ModelError> {
            if accessor.dimensions() != Dimensions::Vec3 || accessor.count() != vertices {
                return Err(ctx.data(
                    what(),
                    format!(
                        "accessor {} is {} {:?}, not {vertices} VEC3 displacements",
                        accessor.index(),
                        accessor.count(),
                        accessor.dimensions()
                    ),
                ));
            }
            ctx.read_f32(&accessor, 3)
        };
        if let Some(accessor) = target.positions() {
            for (p, d) in a.positions.iter_mut().zip(read(accessor)?) {
                *p += w * d;
            }
        }
        if let (Some(normals), Some(accessor)) = (a.normals.as_mut(), target.normals()) {
            for (n, d) in normals.iter_mut().zip(read(accessor)?) {
                *n += w * d;
            }
        }
        if let (Some(tangents), Some(accessor)) = (a.tangents.as_mut(), target.tangents()) {
            // Tangents are xyzw; the target moves xyz.
            for (t, d) in tangents.chunks_exact_mut(4).zip(read(accessor)?.chunks_exact(3)) {
                for c in 0..3 {
                    t[c] += w * d[c];
                }
            }
        }
    }
    Ok(())
}

fn read_draco(
    ctx: &Ctx,
    prim: &gltf::Primitive,
    ext: &gltf::json::Value,
    views: &[gltf::buffer::View],
) -> Result<Attributes, ModelError> {
    let what = || format!("mesh primitive {} (Draco)", prim.index());
    let view_index = ext
        .get("bufferView")
        .and_then(|v| v.as_u64())
        .ok_or_else(|| ctx.data(what(), "KHR_draco_mesh_compression without a bufferView"))?;
    let view = views
        .get(view_index as usize)
        .ok_or_else(|| ctx.data(what(), format!("bufferView {view_index} does not exist")))?;
    let mut buffer = draco_core::DecoderBuffer::new(ctx.view_bytes(view)?);
    let mut decoder = draco_core::MeshDecoder::new();
    let mut mesh = draco_core::Mesh::new();
    // draco-core is a young pure-Rust port: should it panic on a damaged stream, that is
    // this file's error, not the app's end. The half-decoded mesh is dropped unused.
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| decoder.decode(&mut buffer, &mut mesh)))
        .map_err(|_| ctx.data(what(), "Draco decoder failed on a damaged stream"))?
        .map_err(|e| ctx.data(what(), format!("Draco decoding failed: {e}")))?;
    let n = mesh.num_points();
    let attrs = ext
        .get("attributes")
        .and_then(|v| v.as_object())
        .ok_or_else(|| ctx.data(what(), "KHR_draco_mesh_compression without attributes"))?;
    let get = |name: &str, comps: usize| -> Result<Option<Vec<f32>>, ModelError> {
        let Some(id) = attrs.get(name).and_then(|v| v.as_u64()) else {
            return Ok(None);
        };
        let att = mesh
            .attribute_by_unique_id(id as u32)
            .ok_or_else(|| ctx.data(what(), format!("Draco attribute {id} ({name}) missing")))?;
        Ok(Some(att.read_f32s(n, comps)))
    };
    let positions = get("POSITION", 3)?.ok_or_else(|| ctx.data(what(), "no POSITION"))?;
    let colors = match attrs.get("COLOR_0").and_then(|v| v.as_u64()) {
        Some(id) => {
            let comps = mesh
                .attribute_by_unique_id(id as u32)
                .map_or(4, |a| a.num_components() as usize)
                .clamp(3, 4);
            get("COLOR_0", comps)?.map(|c| (c, comps))
        }
        None => None,
    };
    let indices = mesh.faces().iter().flat_map(|f| f.iter().map(|p| p.0)).collect();
    Ok(Attributes {
        positions,
        normals: get("NORMAL", 3)?,
        tangents: get("TANGENT", 4)?,
        uv0: get("TEXCOORD_0", 2)?,
        uv1: get("TEXCOORD_1", 2)?,
        colors,
        indices: Some(indices),
        // Joints and weights in a Draco stream are not read: such a mesh is placed by its node.
        skin: None,
    })
}

/// Builds the vertices; computes smooth normals where the file has none, and tangents from
/// `tangent_uv` (the material's normal map's coordinates).
fn assemble(ctx: &Ctx, a: Attributes, tangent_uv: TangentUv, what: &str) -> Result<Mesh, ModelError> {
    let n = a.positions.len() / 3;
    let check = |v: &Option<Vec<f32>>, comps: usize, name: &str| -> Result<(), ModelError> {
        match v {
            Some(v) if v.len() != n * comps => {
                Err(ctx.data(what.to_owned(), format!("{name} count differs from POSITION")))
            }
            _ => Ok(()),
        }
    };
    check(&a.normals, 3, "NORMAL")?;
    check(&a.tangents, 4, "TANGENT")?;
    check(&a.uv0, 2, "TEXCOORD_0")?;
    check(&a.uv1, 2, "TEXCOORD_1")?;
    let indices = a.indices.unwrap_or_else(|| (0..n as u32).collect());
    if !indices.len().is_multiple_of(3) {
        return Err(ctx.data(what.to_owned(), "index count is not a multiple of 3"));
    }
    if let Some(bad) = indices.iter().find(|&&i| i as usize >= n) {
        return Err(ctx.data(what.to_owned(), format!("index {bad} past the {n} vertices")));
    }
    let mut mesh = Mesh {
        vertices: (0..n)
            .map(|i| {
                let p = [a.positions[i * 3], a.positions[i * 3 + 1], a.positions[i * 3 + 2]];
                let normal = a
                    .normals
                    .as_ref()
                    .map_or([0.0; 3], |v| [v[i * 3], v[i * 3 + 1], v[i * 3 + 2]]);
                let tangent = a.tangents.as_ref().map_or([1.0, 0.0, 0.0, 1.0], |v| {
                    [v[i * 4], v[i * 4 + 1], v[i * 4 + 2], v[i * 4 + 3]]
                });
                let uv0 = a.uv0.as_ref().map_or([0.0; 2], |v| [v[i * 2], v[i * 2 + 1]]);
                let uv1 = a.uv1.as_ref().map_or([0.0; 2], |v| [v[i * 2], v[i * 2 + 1]]);
                let color = a.colors.as_ref().map_or([1.0; 4], |(v, c)| {
                    let k = i * c;
                    [v[k], v[k + 1], v[k + 2], if *c == 4 { v[k + 3] } else { 1.0 }]
                });
                Vertex {
                    position: p,
                    normal,
                    tangent,
                    uv: [uv0[0], uv0[1], uv1[0], uv1[1]],
                    color,
                    material: [1.0, 1.0],
                }
            })
            .collect(),
        indices,
    };
    if a.normals.is_none() {
        mesh.smooth_normals();
    }
    if a.tangents.is_none() && a.uv0.is_some() {
        generate_tangents(&mut mesh, tangent_uv.on(a.uv1.is_some()));
    }
    Ok(mesh)
}

/// The orientation a Smithsonian Voyager scene gives this model file: Voyager scenes
/// (`scene.svx.json` beside the derivatives) store scans in their scanner's frame and rotate
/// them upright in `models[].rotation`. `None` when there is no such scene, it does not list
/// this file, or it cannot be read (the model then loads as stored).
pub fn voyager_rotation(model_path: &Path) -> Option<Quat> {
    let file_name = model_path.file_name()?.to_str()?;
    let text = phantogram_files::read_regular_file(&model_path.parent()?.join(VOYAGER_SCENE), MAX_SCENE_BYTES).ok()?;
    let scene: serde_json::Value = serde_json::from_slice(&text).ok()?;
    let (model, _, _) = voyager_assets(&scene).find(|(_, _, uri)| *uri == file_name)?;
    let r: Vec<f32> = model
        .get("rotation")?
        .as_array()?
        .iter()
        .filter_map(|v| v.as_f64().map(|x| x as f32))
        .collect();
    let q = Quat::from_xyzw(*r.first()?, *r.get(1)?, *r.get(2)?, *r.get(3)?);
    // A damaged scene (1e300 does not fit an f32) leaves the model as stored.
    (q.is_finite() && q.length() > 0.5).then(|| q.normalize())
}

/// Most annotations read from one scene, and the longest title and text kept (characters).
const MAX_ANNOTATIONS: usize = 256;
const MAX_TITLE_CHARS: usize = 120;
const MAX_LEAD_CHARS: usize = 1000;

/// The annotations a Voyager scene gives the model it lists as `model_path`'s file
/// (`models[].annotations[]`: `id`, `title`, `lead`, `position` and `direction` in the model's
/// own coordinates, as Voyager's `IAnnotation` defines them). None when there is no such scene
/// or it cannot be read (the model then loads without them); an annotation without a finite
/// position is skipped.
pub fn voyager_annotations(scene: &Path, model_path: &Path) -> Vec<Annotation> {
    let Some(file_name) = model_path.file_name().and_then(|n| n.to_str()) else {
        return Vec::new();
    };
    let Ok(text) = phantogram_files::read_regular_file(scene, MAX_SCENE_BYTES) else {
        return Vec::new();
    };
    let Ok(json) = serde_json::from_slice::<serde_json::Value>(&text) else {
        return Vec::new();
    };
    let Some((model, _, _)) = voyager_assets(&json).find(|(_, _, uri)| *uri == file_name) else {
        return Vec::new();
    };
    let cut = |v: Option<&serde_json::Value>, max: usize| -> String {
        phantogram_files::text::truncate_chars(v.and_then(|v| v.as_str()).unwrap_or("").trim(), max)
    };
    let vec3 = |v: Option<&serde_json::Value>| -> Option<Vec3> {
        let a = v?.as_array()?;
        let f = |i: usize| a.get(i)?.as_f64().map(|x| x as f32);
        let p = Vec3::new(f(0)?, f(1)?, f(2)?);
        (p.is_finite() && p.abs().max_element() <= MAX_COORDINATE).then_some(p)
    };
    model
        .get("annotations")
        .and_then(|a| a.as_array())
        .into_iter()
        .flatten()
        .filter(|a| a.get("visible").and_then(|v| v.as_bool()) != Some(false))
        .filter_map(|a| {
            Some(Annotation {
                id: cut(a.get("id"), MAX_TITLE_CHARS),
                title: cut(a.get("title"), MAX_TITLE_CHARS),
                lead: cut(a.get("lead"), MAX_LEAD_CHARS),
                position: vec3(a.get("position"))?,
                direction: vec3(a.get("direction"))
                    .and_then(|d| d.try_normalize())
                    .unwrap_or(Vec3::Y),
            })
        })
        .take(MAX_ANNOTATIONS)
        .collect()
}

/// Why `version` (a glTF `asset.version`) is not one this loader reads, if it is not.
fn not_gltf2_version(version: &str) -> Option<String> {
    (version.split('.').next() != Some("2")).then(|| format!("asset version {version:?}; this loader reads glTF 2.0"))
}

/// For a file that did not parse as glTF 2.0: whether it says it is another version (a GLB
/// container's header, or the JSON's `asset.version`).
fn not_gltf2(bytes: &[u8]) -> Option<String> {
    if let Some(header) = bytes.strip_prefix(b"glTF") {
        let version = u32::from_le_bytes(header.get(..4)?.try_into().ok()?);
        return (version != 2).then(|| format!("GLB version {version}; this loader reads glTF 2.0"));
    }
    let json: serde_json::Value = serde_json::from_slice(bytes).ok()?;
    not_gltf2_version(json.get("asset")?.get("version")?.as_str()?)
}

/// Every asset a Voyager scene lists, with the model and derivative that list it:
/// `models[].derivatives[].assets[].uri`.
fn voyager_assets(scene: &serde_json::Value) -> impl Iterator<Item = (&serde_json::Value, &serde_json::Value, &str)> {
    fn array<'a>(v: &'a serde_json::Value, key: &str) -> impl Iterator<Item = &'a serde_json::Value> + use<'a> {
        v.get(key).and_then(|x| x.as_array()).into_iter().flatten()
    }
    array(scene, "models").flat_map(move |model| {
        array(model, "derivatives").flat_map(move |derivative| {
            array(derivative, "assets")
                .filter_map(|asset| asset.get("uri")?.as_str())
                .map(move |uri| (model, derivative, uri))
        })
    })
}

/// The Voyager scene file's name, which a Smithsonian download folder holds beside its scans.
const VOYAGER_SCENE: &str = "scene.svx.json";

/// The scan a Voyager scene (`scene.svx.json`, or a folder holding one) offers for viewing:
/// its best-quality "Web3D" derivative present beside it (High, then Medium, Low, Thumb: the
/// downloads usually hold some of them).
pub fn voyager_scan(scene_or_folder: &Path) -> Result<PathBuf, ModelError> {
    let mut scans = voyager_scans(scene_or_folder)?;
    Ok(scans.swap_remove(0))
}

/// A lighter scan of the same artifact to show while [`voyager_scan`]'s loads: the
/// lowest-quality "Web3D" derivative present (Voyager's own viewer shows its "Thumb" first and
/// refines it the same way), `None` when the scene offers only one scan here or cannot be read.
pub fn voyager_preview(scene_or_folder: &Path) -> Option<PathBuf> {
    let scans = voyager_scans(scene_or_folder).ok()?;
    scans
        .last()
        .filter(|lightest| Some(*lightest) != scans.first())
        .cloned()
}

/// The "Web3D" scans a Voyager scene lists and that are present beside it, best first (never
/// empty).
fn voyager_scans(scene_or_folder: &Path) -> Result<Vec<PathBuf>, ModelError> {
    let scene_path = if scene_or_folder.is_dir() {
        scene_or_folder.join(VOYAGER_SCENE)
    } else {
        scene_or_folder.to_path_buf()
    };
    let not_a_model = |message: String| ModelError::NotAModel {
        path: scene_or_folder.to_path_buf(),
        message,
    };
    let text = phantogram_files::read_regular_file(&scene_path, MAX_SCENE_BYTES).map_err(|error| {
        if scene_or_folder.is_dir() && error.kind() == std::io::ErrorKind::NotFound {
            not_a_model(format!(
                "a folder without a Voyager scene ({VOYAGER_SCENE}): give the .gltf or .glb file"
            ))
        } else {
            ModelError::Io {
                path: scene_path.clone(),
                error,
            }
        }
    })?;
    let scene: serde_json::Value = serde_json::from_slice(&text).map_err(|e| ModelError::Scene {
        path: scene_path.clone(),
        message: e.to_string(),
    })?;
    let folder = scene_path.parent().unwrap_or(Path::new("."));
    let is = |v: &serde_json::Value, key: &str, want: &str| v.get(key).and_then(|x| x.as_str()) == Some(want);
    let mut offered: Vec<(usize, &str)> = voyager_assets(&scene)
        .filter(|(_, d, _)| is(d, "usage", "Web3D"))
        .filter_map(|(_, d, uri)| {
            let rank = ["High", "Medium", "Low", "Thumb"]
                .iter()
                .position(|q| is(d, "quality", q))?;
            // Only glTF files, by plain names beside the scene: a scene must not point elsewhere.
            let gltf = uri.ends_with(".glb") || uri.ends_with(".gltf");
            let beside = Path::new(uri).file_name() == Some(std::ffi::OsStr::new(uri));
            (gltf && beside).then_some((rank, uri))
        })
        .collect();
    offered.sort();
    if offered.is_empty() {
        return Err(not_a_model("the Voyager scene lists no glTF scan".into()));
    }
    let present: Vec<PathBuf> = offered
        .iter()
        .map(|(_, uri)| folder.join(uri))
        .filter(|p| p.is_file())
        .collect();
    if present.is_empty() {
        let names: Vec<&str> = offered.iter().map(|(_, u)| *u).collect();
        return Err(not_a_model(format!(
            "none of the scans the Voyager scene lists is here ({})",
            names.join(", ")
        )));
    }
    Ok(present)
}

/// Loads a model as its publisher meant it to be seen: [`load_gltf`], then the orientation of a
/// Voyager scene beside the file, if any ([`voyager_rotation`]). `path` may also be a Voyager
/// scene or a folder holding one: its best scan present is loaded ([`voyager_scan`]).
pub fn load_model(path: &Path) -> Result<Model, ModelError> {
    load_model_within(path, ResourceBudget::default())
}

/// [`load_model`] within `budget` (module docs of [`crate::budget`]).
pub fn load_model_within(path: &Path, budget: ResourceBudget) -> Result<Model, ModelError> {
    load_model_with(path, budget, &Progress::new())
}

/// [`load_model_within`], reporting to `progress` and giving up when it is cancelled
/// ([`ModelError::Cancelled`]).
pub fn load_model_with(path: &Path, budget: ResourceBudget, progress: &Progress) -> Result<Model, ModelError> {
    // Scans published as meshes rather than glTF: STL, PLY and OBJ, by their extension.
    if !path.is_dir()
        && let Some(format) = super::mesh_file::MeshFormat::of(path)
    {
        return super::mesh_file::load(path, format, budget, progress);
    }
    // Any `*.svx.json` is a Voyager scene (downloads rename them), never a glTF file.
    let is_scene = path.is_dir()
        || path
            .file_name()
            .and_then(|n| n.to_str())
            .is_some_and(|n| n.to_ascii_lowercase().ends_with(".svx.json"));
    let scan;
    // The scene the annotations come from: the one given, or the one beside the scan.
    let scene = if path.is_dir() {
        path.join(VOYAGER_SCENE)
    } else if is_scene {
        path.to_path_buf()
    } else {
        path.parent().unwrap_or(Path::new(".")).join(VOYAGER_SCENE)
    };
    let path = if is_scene {
        scan = voyager_scan(path)?;
        &scan
    } else {
        path
    };
    let mut model = load_gltf_with(path, budget, progress)?;
    // In the scan's own coordinates, like its vertices: turned and fitted with them.
    model.annotations = voyager_annotations(&scene, path);
    if let Some(q) = voyager_rotation(path) {
        model.transform(Mat4::from_quat(q));
        model
            .warnings
            .push("oriented by the Voyager scene beside it (scene.svx.json)".into());
    }
    Ok(model)
}

/// Loads a `.gltf` or `.glb` file, in the file's own frame.
pub fn load_gltf(path: &Path) -> Result<Model, ModelError> {
    load_gltf_within(path, ResourceBudget::default())
}

/// [`load_gltf`] within `budget` (module docs of [`crate::budget`]).
pub fn load_gltf_within(path: &Path, budget: ResourceBudget) -> Result<Model, ModelError> {
    load_gltf_with(path, budget, &Progress::new())
}

/// Shares of a load's progress: reading the file and its buffers, decoding the images, building
/// the meshes (Draco decoding, tangents). The rest is the caller's (fitting, uploading).
const READ_SHARE: [f32; 2] = [0.0, 0.1];
const IMAGES_SHARE: [f32; 2] = [0.1, 0.5];
const MESHES_SHARE: [f32; 2] = [0.5, 0.9];

/// The bytes of the model file at `path`: one larger than the whole budget is refused by name
/// (over budget) before it is read.
pub(super) fn read_model_file(path: &Path, spending: &Spending) -> Result<Vec<u8>, ModelError> {
    if let Ok(meta) = std::fs::metadata(path)
        && meta.is_file()
    {
        spending
            .check_bytes(|| "the file".to_owned(), meta.len())
            .map_err(|e| over_budget(path, e))?;
    }
    phantogram_files::read_regular_file(path, spending.budget().memory_bytes).map_err(|error| ModelError::Io {
        path: path.to_path_buf(),
        error,
    })
}

/// A model's name: its file's name without the extension.
pub(super) fn model_name(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// [`load_gltf_within`], reporting to `progress` and giving up when it is cancelled.
pub fn load_gltf_with(path: &Path, budget: ResourceBudget, progress: &Progress) -> Result<Model, ModelError> {
    let cancelled = |_| ModelError::Cancelled {
        path: path.to_path_buf(),
    };
    let read = Span::new(progress, READ_SHARE[0], READ_SHARE[1]);
    read.step(0.0).map_err(cancelled)?;
    let mut spending = Spending::new(budget);
    let bytes = read_model_file(path, &spending)?;
    read.step(0.5).map_err(cancelled)?;
    let gltf = gltf::Gltf::from_slice_without_validation(&bytes).map_err(|e| ModelError::Parse {
        format: "glTF",
        path: path.to_path_buf(),
        // A glTF 1.0 file fails here on its different layout: say so rather than how.
        message: not_gltf2(&bytes).unwrap_or_else(|| e.to_string()),
    })?;
    let doc = &gltf.document;
    if let Some(name) = doc.extensions_required().find(|e| !SUPPORTED_EXTENSIONS.contains(e)) {
        return Err(ModelError::UnsupportedExtension {
            path: path.to_path_buf(),
            name: name.to_owned(),
        });
    }
    // glTF 1.0 (and the JSON of other formats with an "asset" version, such as a Voyager
    // scene) can also parse into an empty glTF 2.0 document: "no triangles to draw".
    if let Some(message) = not_gltf2_version(&doc.as_json().asset.version) {
        return Err(ModelError::Parse {
            format: "glTF",
            path: path.to_path_buf(),
            message,
        });
    }
    check_structure(doc.as_json()).map_err(|message| ModelError::Parse {
        format: "glTF",
        path: path.to_path_buf(),
        message,
    })?;
    let mut buffers = Vec::new();
    for b in doc.buffers() {
        // A compressed file's fallback (for readers without meshopt) is not needed, and
        // usually has no data at all.
        if meshopt_views::is_fallback(&b) {
            buffers.push(Vec::new());
            continue;
        }
        let data = match b.source() {
            gltf::buffer::Source::Bin => gltf.blob.clone().ok_or_else(|| ModelError::Parse {
                format: "glTF",
                path: path.to_path_buf(),
                message: "buffer refers to a GLB binary chunk that is missing".into(),
            })?,
            gltf::buffer::Source::Uri(uri) => load_uri(path, uri, budget.memory_bytes)?,
        };
        if data.len() < b.length() {
            return Err(ModelError::Parse {
                format: "glTF",
                path: path.to_path_buf(),
                message: format!(
                    "buffer {} is {} bytes, shorter than its declared {}",
                    b.index(),
                    data.len(),
                    b.length()
                ),
            });
        }
        buffers.push(data);
    }
    let views: Vec<gltf::buffer::View> = doc.views().collect();
    let decoded = meshopt_views::decode_all(doc, &buffers, &spending).map_err(|e| match e {
        meshopt_views::DecodeError::Data { view, message } => ModelError::Data {
            path: path.to_path_buf(),
            what: format!("bufferView {view} ({})", meshopt_views::NAMES[0]),
            message,
        },
        meshopt_views::DecodeError::OverBudget(error) => over_budget(path, error),
    })?;
    read.step(1.0).map_err(cancelled)?;

    // Read the encoded images in order, then decode them on every core (the largest part of
    // loading a textured scan); the first failure in file order is the one reported.
    // Each image's size is read from its header and charged before any is decoded: twelve
    // images naming one 8192² PNG are twelve textures.
    let mut encoded = Vec::new();
    for img in doc.images() {
        let (raw, name): (Vec<u8>, String) = match img.source() {
            gltf::image::Source::View { view, .. } => {
                let bytes = view_bytes_of(path, &buffers, &decoded, &view)?;
                (bytes.to_vec(), format!("image {}", img.index()))
            }
            gltf::image::Source::Uri { uri, .. } => (load_uri(path, uri, budget.memory_bytes)?, excerpt(uri)),
        };
        let what = || format!("image {} ({name})", img.index());
        let data_error = |message: String| ModelError::Data {
            path: path.to_path_buf(),
            what: what(),
            message,
        };
        // glTF images are PNG or JPEG, WebP with `EXT_texture_webp` or KTX 2.0 with
        // `KHR_texture_basisu`; anything else (an EXR, say) is refused before a decoder meant for
        // other files sees it.
        let header = Encoded::probe(&raw).map_err(data_error)?;
        let fitted = spending
            .charge_image(what, header.width, header.height)
            .map_err(|e| over_budget(path, e))?;
        encoded.push((img.index(), raw, name, header, fitted));
    }
    let images_share = Span::new(progress, IMAGES_SHARE[0], IMAGES_SHARE[1]);
    let decoded_count = std::sync::atomic::AtomicUsize::new(0);
    let image_count = encoded.len().max(1) as f32;
    let images = crate::parallel::map(&encoded, |(index, raw, name, header, fitted)| {
        let what = || format!("image {index} ({name})");
        // A cancelled load skips the images not yet begun (the error is reported below).
        if progress.is_cancelled() {
            return Err((what(), "cancelled".to_owned()));
        }
        let (decoded, level) = header
            .decode_with_level(raw, *fitted, budget.memory_bytes)
            .map_err(|e| (what(), e))?;
        let done = decoded_count.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        images_share.advance(done as f32 / image_count);
        // Larger than the device's textures: the user is told it was scaled down.
        let note = header.scaled_down_note(&what(), *fitted);
        // A Basis Universal texture is kept beside its texels for the GPU's own block formats.
        let basis = level.map(|level| BasisSource {
            ktx2: std::sync::Arc::from(raw.as_slice()),
            level,
        });
        Ok((
            Image {
                name: name.clone(),
                width: decoded.width(),
                height: decoded.height(),
                rgba8: decoded.into_raw(),
                basis,
            },
            note,
        ))
    })
    .into_iter()
    .collect::<Result<Vec<(Image, Option<String>)>, _>>()
    .map_err(|(what, message)| {
        if progress.is_cancelled() {
            ModelError::Cancelled {
                path: path.to_path_buf(),
            }
        } else {
            ModelError::Data {
                path: path.to_path_buf(),
                what,
                message,
            }
        }
    })?;
    let (mut images, image_notes): (Vec<Image>, Vec<Option<String>>) = images.into_iter().unzip();
    // The KTX 2.0 files kept are charged too; one that does not fit is dropped (its texels are
    // drawn from the RGBA8 copy).
    for image in &mut images {
        if let Some(basis) = &image.basis
            && spending.charge_bytes(String::new, basis.ktx2.len() as u64).is_err()
        {
            image.basis = None;
        }
    }
    images_share.step(1.0).map_err(cancelled)?;
    drop(encoded); // the compressed copies are not needed while the meshes are built
    let ctx = Ctx {
        path,
        buffers,
        decoded,
        spending: std::cell::RefCell::new(spending),
    };

    // Extensions used but not required: the file is meant to be viewable without them.
    let mut warnings: Vec<String> = doc
        .extensions_used()
        .filter(|e| !SUPPORTED_EXTENSIONS.contains(e))
        .map(|e| {
            format!(
                "uses the glTF extension {}, which this viewer does not implement: shown without it",
                excerpt(e)
            )
        })
        .chain(image_notes.into_iter().flatten())
        .collect();
    let mut materials = Vec::with_capacity(doc.materials().len() + 1);
    for m in doc.materials() {
        let mut material = material_of(&m, &mut warnings);
        if let Some(value) = m.extension_value("KHR_materials_transmission") {
            material.transmission_texture = extension_texture(
                &material,
                value,
                "transmissionTexture",
                "transmission",
                doc,
                images.len(),
                &mut warnings,
            );
        }
        if let Some(value) = m.extension_value("KHR_materials_volume") {
            material.thickness_texture = extension_texture(
                &material,
                value,
                "thicknessTexture",
                "thickness",
                doc,
                images.len(),
                &mut warnings,
            );
        }
        for slot in LayerSlot::ALL {
            let (extension, field) = slot.field();
            if let Some(value) = m.extension_value(extension) {
                let name = field.trim_end_matches("Texture");
                let texture = extension_texture(&material, value, field, name, doc, images.len(), &mut warnings);
                material.layer_textures.set(slot, texture);
                if slot == LayerSlot::ClearCoatNormal && texture.is_some() {
                    let scale = value.get(field).and_then(|t| t.get("scale"));
                    match scale.map(|s| s.as_f64().map(|s| s as f32).filter(|s| s.is_finite())) {
                        None => {}
                        Some(Some(scale)) => material.layer_textures.clear_coat_normal_scale = scale,
                        Some(None) => warnings.push(format!(
                            "material {}, {name} texture: its scale is not a number; 1 used",
                            material.name
                        )),
                    }
                }
            }
        }
        if let Some(value) = m.extension_value("KHR_materials_pbrSpecularGlossiness") {
            with_spec_gloss(&mut material, value, doc, &mut images, &ctx.spending, &mut warnings)
                .map_err(|e| over_budget(path, e))?;
        }
        materials.push(material);
    }
    let default_material = materials.len();
    materials.push(Material::default());

    let mut model = Model {
        name: model_name(path),
        images,
        warnings,
        ..Model::default()
    };
    let scene = doc.default_scene().or_else(|| doc.scenes().next());
    let roots: Vec<gltf::Node> = match &scene {
        Some(s) => s.nodes().collect(),
        // No scene: every node that is nobody's child, as a scene listing them would.
        None => {
            let mut is_child = vec![false; doc.nodes().len()];
            for child in doc.nodes().flat_map(|n| n.children()) {
                is_child[child.index()] = true;
            }
            doc.nodes().filter(|n| !is_child[n.index()]).collect()
        }
    };
    // The hierarchy must be disjoint strict trees (glTF 2.0, "Nodes and Hierarchy"); a
    // node met twice would loop forever or draw twice.
    let mut visited = vec![false; doc.nodes().len()];
    let meshes_share = Span::new(progress, MESHES_SHARE[0], MESHES_SHARE[1]);
    // The primitives the file declares: drawn ones may be more (instancing) or fewer.
    let declared_primitives = doc.meshes().map(|m| m.primitives().len()).sum::<usize>().max(1) as f32;
    let mut built_primitives = 0usize;
    // Every node's world matrix, for the joints of skins (which need not lie on the path to the
    // mesh they move).
    let node_worlds = if doc.skins().len() > 0 {
        let mut parent = vec![None; doc.nodes().len()];
        for n in doc.nodes() {
            for c in n.children() {
                parent[c.index()] = Some(n.index());
            }
        }
        let local: Vec<Mat4> = doc
            .nodes()
            .map(|n| Mat4::from_cols_array_2d(&n.transform().matrix()))
            .collect();
        skin::node_worlds(&local, &parent)
    } else {
        Vec::new()
    };
    // A volume's thickness is in the mesh's own units, which a node's scale changes: materials
    // with a volume drawn at another scale get a copy with their lengths scaled, by (material,
    // scale).
    let mut scaled_volumes: std::collections::HashMap<(usize, u32), usize> = std::collections::HashMap::new();
    let mut stack: Vec<(gltf::Node, Mat4)> = roots.into_iter().map(|n| (n, Mat4::IDENTITY)).collect();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut visited[node.index()], true) {
            return Err(ModelError::Parse {
                format: "glTF",
                path: path.to_path_buf(),
                message: format!(
                    "node {} is reached twice in the scene's hierarchy (a cycle, or a node with two parents)",
                    node.index()
                ),
            });
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(mesh) = node.mesh() {
            // The node's joint matrices, made by its first skinned primitive and kept for the
            // others.
            let mut joint_matrices: Option<Vec<Mat4>> = None;
            let instances = instance_transforms(&ctx, doc, &node)?;
            if instances.is_some() && node.skin().is_some() {
                model.warnings.push(format!(
                    "node {}: a skinned mesh is drawn once, where its joints put it (EXT_mesh_gpu_instancing ignored)",
                    node.index()
                ));
            }
            for prim in mesh.primitives() {
                let what = format!("mesh {} primitive {}", mesh.index(), prim.index());
                ctx.spending
                    .borrow_mut()
                    .charge_primitive(|| format!("{what} (in node {})", node.index()))
                    .map_err(|e| over_budget(path, e))?;
                let draco = prim.extension_value("KHR_draco_mesh_compression");
                // Lines have no surface to show; points are drawn as discs (`point_cloud`).
                // Draco's decoder hands back faces, whose relation to a strip or fan (or to
                // points) the extension leaves to the encoder.
                let points = prim.mode() == gltf::mesh::Mode::Points;
                let drawn = match prim.mode() {
                    gltf::mesh::Mode::Triangles => true,
                    gltf::mesh::Mode::TriangleStrip | gltf::mesh::Mode::TriangleFan | gltf::mesh::Mode::Points => {
                        draco.is_none()
                    }
                    _ => false,
                };
                if !drawn {
                    model
                        .warnings
                        .push(format!("{what}: {:?} primitives are not drawn", prim.mode()));
                    continue;
                }
                let mut attributes = match draco {
                    Some(ext) => read_draco(&ctx, &prim, ext, &views)?,
                    None => read_plain(&ctx, &prim)?,
                };
                if let Some(weights) = node.weights().or(mesh.weights())
                    && prim.morph_targets().len() > 0
                {
                    if draco.is_some() {
                        model.warnings.push(format!(
                            "{what}: morph targets of a Draco primitive are not applied (drawn as its base shape)"
                        ));
                    } else {
                        apply_morph_targets(&ctx, &prim, weights, &mut attributes)?;
                    }
                }
                // A point cloud's points (its indices, else every vertex) pass through the mesh
                // builder as degenerate triangles, which it checks and keeps; the discs are made
                // once the points stand where the node puts them.
                let had_normals = attributes.normals.is_some();
                let mut discs = 0;
                if points {
                    let count = (attributes.positions.len() / 3) as u32;
                    let sequence = attributes.indices.take().unwrap_or_else(|| (0..count).collect());
                    discs = point_cloud::charge_discs(&mut ctx.spending.borrow_mut(), sequence.len(), || {
                        format!("{what}'s discs (in node {})", node.index())
                    })
                    .map_err(|e| over_budget(path, e))?;
                    attributes.indices = Some(sequence.iter().flat_map(|&i| [i, i, i]).collect());
                } else if prim.mode() != gltf::mesh::Mode::Triangles {
                    let count = (attributes.positions.len() / 3) as u32;
                    let sequence = attributes.indices.take().unwrap_or_else(|| (0..count).collect());
                    attributes.indices = topology::triangle_list(prim.mode(), sequence);
                    if attributes.indices.as_ref().is_none_or(Vec::is_empty) {
                        model
                            .warnings
                            .push(format!("{what}: a {:?} without a triangle is not drawn", prim.mode()));
                        continue;
                    }
                }
                // Charged before the mesh is built (for Draco, its counts are known only now).
                let vertices = (attributes.positions.len() / 3) as u64;
                let indices = attributes.indices.as_ref().map_or(vertices, |i| i.len() as u64);
                ctx.spending
                    .borrow_mut()
                    .charge_bytes(
                        || format!("{what} (in node {})", node.index()),
                        ResourceBudget::mesh_bytes(vertices, indices),
                    )
                    .map_err(|e| over_budget(path, e))?;
                let skin_data = attributes.skin.take();
                let tangent_uv = TangentUv::of(materials.get(prim.material().index().unwrap_or(default_material)));
                let mut m = assemble(&ctx, attributes, tangent_uv, &what)?;
                built_primitives += 1;
                meshes_share
                    .step(built_primitives as f32 / declared_primitives)
                    .map_err(cancelled)?;
                match (node.skin(), skin_data) {
                    // glTF: a skinned mesh is placed by its joints alone, its node's transform
                    // ignored.
                    (Some(s), Some((joints, weights))) => {
                        if joint_matrices.is_none() {
                            joint_matrices = Some(skin_matrices(&ctx, &s, &node_worlds)?);
                        }
                        let matrices = joint_matrices.as_deref().unwrap_or_default();
                        skin::apply(&mut m, &joints, &weights, matrices)
                            .map_err(|e| ctx.data(format!("{what} (skin {})", s.index()), e))?;
                    }
                    _ => match &instances {
                        // Each further copy charged before it is made.
                        Some(list) => {
                            let copies = list.len().saturating_sub(1) as u64;
                            ctx.spending
                                .borrow_mut()
                                .charge_bytes(
                                    || format!("{what} ({} instances in node {})", list.len(), node.index()),
                                    ResourceBudget::mesh_bytes(
                                        vertices.saturating_mul(copies),
                                        indices.saturating_mul(copies),
                                    ),
                                )
                                .map_err(|e| over_budget(path, e))?;
                            let worlds: Vec<Mat4> = list.iter().map(|instance| world * *instance).collect();
                            m = instancing::replicate(&m, &worlds);
                        }
                        None => m.transform(world),
                    },
                }
                if points {
                    let cloud: Vec<Vertex> = m
                        .indices
                        .iter()
                        .step_by(3)
                        .filter_map(|&i| m.vertices.get(i as usize))
                        .map(|v| Vertex {
                            // The builder's smooth normals of degenerate triangles are no normals.
                            normal: if had_normals { v.normal } else { [0.0; 3] },
                            ..*v
                        })
                        .collect();
                    m = point_cloud::surfels(&cloud, discs);
                    if m.indices.is_empty() {
                        model
                            .warnings
                            .push(format!("{what}: points all in one place are not drawn"));
                        continue;
                    }
                }
                // Checked after the node transforms, which can overflow finite positions too.
                if let Some((i, position)) = m.out_of_range_vertex() {
                    return Err(ctx.data(
                        what,
                        format!(
                            "vertex {i} lies at {position:?}, not a finite position within ±{MAX_COORDINATE:e} (in node {})",
                            node.index()
                        ),
                    ));
                }
                let mut material = prim.material().index().unwrap_or(default_material);
                // Discs show from both sides (an estimated normal may face in); the material is
                // copied so that triangles sharing it keep theirs.
                if points && let Some(single) = materials.get(material).filter(|m| !m.double_sided) {
                    materials.push(Material {
                        double_sided: true,
                        ..single.clone()
                    });
                    material = materials.len() - 1;
                }
                // Where the node puts the mesh (not for a skinned one, which its joints place).
                let scale = if node.skin().is_some() {
                    1.0
                } else {
                    length_scale(world)
                };
                if scale != 1.0 && materials.get(material).is_some_and(|m| m.layers.thickness > 0.0) {
                    material = *scaled_volumes.entry((material, scale.to_bits())).or_insert_with(|| {
                        let mut copy = materials[material].clone();
                        copy.layers.scale_lengths(scale);
                        materials.push(copy);
                        materials.len() - 1
                    });
                }
                model.primitives.push(Primitive {
                    mesh: m,
                    material,
                    is_floor: false,
                    lods: Vec::new(),
                });
            }
        }
        for child in node.children() {
            stack.push((child, world));
        }
    }
    for p in &model.primitives {
        let mat = &materials[p.material];
        if let Some(t) = mat.textures().find(|(t, _)| t.image >= model.images.len()) {
            return Err(ctx.data(
                format!("material {}", mat.name),
                format!("texture image {} does not exist", t.0.image),
            ));
        }
    }
    model.materials = materials;
    // What the GPU's layer texture arrays take beyond the images, charged last: unlike the
    // meshes and images they can be left out, and the artifact still shows.
    let layer_arrays = LayerArrays::of(&model.materials, &model.images);
    let charged = ctx.spending.borrow_mut().charge_bytes(
        || format!("the layer textures' {} arrays", layer_arrays.arrays.len()),
        layer_arrays.extra_bytes(&model.materials, &model.images),
    );
    if let Err(e) = charged {
        for m in &mut model.materials {
            for slot in LayerSlot::ALL {
                m.layer_textures.set(slot, None);
            }
        }
        model.warnings.push(format!(
            "{e}: the varnish, sheen, specular, diffuse transmission, anisotropy and iridescence textures were left out"
        ));
    }
    meshes_share.step(1.0).map_err(cancelled)?;
    if model.triangle_count() == 0 {
        return Err(ModelError::Empty {
            path: path.to_path_buf(),
        });
    }
    join_and_check_draws(&mut model, path, &ctx.spending.borrow())?;
    Ok(model)
}

/// Whether every vertex of `mesh` (the part `what` of the model at `path`) lies at a finite
/// position within ±[`MAX_COORDINATE`]; else the error naming the first that does not.
pub(super) fn check_positions(mesh: &Mesh, path: &Path, what: impl FnOnce() -> String) -> Result<(), ModelError> {
    match mesh.out_of_range_vertex() {
        Some((i, position)) => Err(ModelError::Data {
            path: path.to_path_buf(),
            what: what(),
            message: format!("vertex {i} lies at {position:?}, not a finite position within ±{MAX_COORDINATE:e}"),
        }),
        None => Ok(()),
    }
}

/// A model read from a mesh format, finished as glTF's are: refused when it has no triangle to
/// draw, its parts joined and its draws checked ([`join_and_check_draws`]).
pub(super) fn finish_mesh_model(mut model: Model, path: &Path, spending: &Spending) -> Result<Model, ModelError> {
    if model.triangle_count() == 0 {
        return Err(ModelError::Empty {
            path: path.to_path_buf(),
        });
    }
    join_and_check_draws(&mut model, path, spending)?;
    Ok(model)
}

/// Joins `model`'s small primitives that share a material ([`super::join`]) and checks what is
/// then drawn against the budget's primitives.
pub(super) fn join_and_check_draws(model: &mut Model, path: &Path, spending: &Spending) -> Result<(), ModelError> {
    // Not a warning: nothing the file asked for is lost.
    model.join_small_primitives();
    spending
        .check_drawn_primitives(|| "the model".to_owned(), model.primitives.len() as u64)
        .map_err(|e| over_budget(path, e))
}
