//! The resource budget: how much of the device one artifact may take, checked before anything
//! is allocated for it.
//!
//! A file from outside says how big its contents are (an accessor's count, an image's width, a
//! node tree's fan-out) and a few hundred bytes can claim gigabytes: an accessor without data of
//! count 22 M, twelve images naming one 8192² PNG, a mesh instanced by forty nodes, a JPEG header
//! claiming 23000². The loader charges every lasting allocation (vertices, indices, decoded
//! texels with their mip chain) and every drawn primitive against one budget *before* making
//! it, and a file that does not fit fails with an error naming the limit. Transient buffers
//! (an accessor being read, an image being decoded) are bounded by what is left of it.
//!
//! The limits come from the target device ([`ResourceBudget::PHONE`] by default): the phone
//! holds the artifact twice (the CPU copy the app keeps to rebuild its GPU objects after a
//! pause, and the GPU's), in memory a mid-range phone shares with everything else.

use crate::model::Vertex;

/// Largest image side decoded at all, pixels (a 16384² RGBA image is 1 GiB): larger images are
/// refused by their header. Images within it but over [`ResourceBudget::max_image_side_px`] are
/// decoded and scaled down to fit the device.
pub const MAX_DECODED_SIDE_PX: u32 = 16384;

/// `width × height` scaled down, aspect kept, so that neither side exceeds `max_side` (at least
/// one pixel each); unchanged when it fits.
pub fn fit_within(width: u32, height: u32, max_side: u32) -> (u32, u32) {
    let side = width.max(height);
    if side <= max_side || side == 0 {
        return (width, height);
    }
    let scale = f64::from(max_side) / f64::from(side);
    let shrink = |v: u32| ((f64::from(v) * scale).round() as u32).clamp(1, max_side);
    (shrink(width), shrink(height))
}

/// What one artifact may take. See the module docs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ResourceBudget {
    /// Bytes of one copy of the artifact in memory: vertices, indices and decoded textures
    /// (with their mip chains) together. Also the largest file read for it.
    pub memory_bytes: u64,
    /// Largest texture side, pixels: the GPU's `max_texture_dimension_2d`. Larger images (up to
    /// [`MAX_DECODED_SIDE_PX`]) are scaled down to it on load.
    pub max_image_side_px: u32,
    /// Most primitives drawn (meshes × the nodes that instance them, after the small ones that
    /// share a material are joined: [`crate::model::join`]): each is a draw call per eye and
    /// pass. A file may declare up to [`READ_PRIMITIVES_PER_DRAWN`] times as many.
    pub max_primitives: u64,
}

impl ResourceBudget {
    /// A mid-range phone: 384 MiB for one copy (two copies and the decoders' transient buffers
    /// stay under 1 GiB), images up to 8192 px a side (wgpu's default texture limit, which the
    /// phone GPUs wgpu supports reach), 4096 draw calls.
    pub const PHONE: Self = Self {
        memory_bytes: 384 << 20,
        max_image_side_px: 8192,
        max_primitives: 4096,
    };

    /// Bytes a mesh of `vertices` and `indices` takes in memory.
    pub fn mesh_bytes(vertices: u64, indices: u64) -> u64 {
        vertices
            .saturating_mul(std::mem::size_of::<Vertex>() as u64)
            .saturating_add(indices.saturating_mul(4))
    }

    /// Bytes a `width × height` RGBA8 texture takes with its mip chain (4/3 of the base level).
    pub fn texture_bytes(width: u32, height: u32) -> u64 {
        let base = u64::from(width) * u64::from(height) * 4;
        base + base / 3
    }
}

/// Layers a device allocates for a 2D array texture of `layers` layers of `width × height` that a
/// shader reads as an array (`texture_2d_array`): `layers`, except on OpenGL (ES) (`opengl`),
/// where wgpu makes a texture of one layer a plain 2D texture and one of a multiple of six square
/// layers a cube map, neither of which reads as an array there: one more layer, never read,
/// keeps it one. The renderer allocates by this; the budget charges with `opengl` set (the most
/// any backend takes), as it is made without knowing the device.
pub fn array_layers(width: u32, height: u32, layers: u32, opengl: bool) -> u32 {
    let plain_or_cube = layers == 1 || (width == height && layers.is_multiple_of(6));
    if opengl && plain_or_cube { layers + 1 } else { layers }
}

/// Bytes `model` takes in memory, as the loader charged them: vertices, indices (every level
/// of detail's too), textures with their mip chains (and the KTX 2.0 files kept beside them), and what the GPU's layer texture arrays
/// take beyond those textures ([`crate::model::LayerArrays::extra_bytes`]).
pub fn model_bytes(model: &crate::model::Model) -> u64 {
    let meshes = model
        .primitives
        .iter()
        .map(|p| {
            let indices = p.mesh.indices.len() + p.lods.iter().map(|l| l.indices.len()).sum::<usize>();
            ResourceBudget::mesh_bytes(p.mesh.vertices.len() as u64, indices as u64)
        })
        .fold(0u64, u64::saturating_add);
    let images = model
        .images
        .iter()
        .map(|i| {
            let kept = i.basis.as_ref().map_or(0, |b| b.ktx2.len() as u64);
            ResourceBudget::texture_bytes(i.width, i.height).saturating_add(kept)
        })
        .fold(0u64, u64::saturating_add);
    let layer_arrays =
        crate::model::LayerArrays::of(&model.materials, &model.images).extra_bytes(&model.materials, &model.images);
    meshes.saturating_add(images).saturating_add(layer_arrays)
}

impl Default for ResourceBudget {
    fn default() -> Self {
        Self::PHONE
    }
}

/// Over budget: what needed how much, and the limit (named by its field) it exceeds.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{what} needs {needed} {unit}, over the budget of {limit} ({limit_name}; {left} left)")]
pub struct OverBudget {
    pub what: String,
    pub needed: u64,
    pub left: u64,
    pub limit: u64,
    pub limit_name: &'static str,
    pub unit: &'static str,
}

/// Most primitives a file may declare for each one drawn. Small primitives that share a material
/// are joined after loading ([`crate::model::join`]), so a file of many parts (a CAD export of
/// 20 000 pieces) can still be drawn within [`ResourceBudget::max_primitives`]; but each primitive
/// read costs its own allocations and bookkeeping before it is joined, so a file declaring more
/// than this many per draw is refused while it is read. 16 admits 65 536 on a phone.
pub const READ_PRIMITIVES_PER_DRAWN: u64 = 16;

/// The running account of one load.
#[derive(Debug)]
pub struct Spending {
    budget: ResourceBudget,
    bytes: u64,
    primitives: u64,
}

impl Spending {
    pub fn new(budget: ResourceBudget) -> Self {
        Self {
            budget,
            bytes: 0,
            primitives: 0,
        }
    }

    pub fn budget(&self) -> &ResourceBudget {
        &self.budget
    }

    /// Bytes not yet charged.
    pub fn bytes_left(&self) -> u64 {
        self.budget.memory_bytes.saturating_sub(self.bytes)
    }

    /// Fails unless `bytes` more would fit, without charging them (a transient buffer).
    pub fn check_bytes(&self, what: impl FnOnce() -> String, bytes: u64) -> Result<(), OverBudget> {
        if bytes > self.bytes_left() {
            return Err(OverBudget {
                what: what(),
                needed: bytes,
                left: self.bytes_left(),
                limit: self.budget.memory_bytes,
                limit_name: "ResourceBudget::memory_bytes",
                unit: "bytes",
            });
        }
        Ok(())
    }

    /// Charges `bytes` that last (a mesh, a texture), or fails without charging.
    pub fn charge_bytes(&mut self, what: impl FnOnce() -> String, bytes: u64) -> Result<(), OverBudget> {
        self.check_bytes(what, bytes)?;
        self.bytes += bytes;
        Ok(())
    }

    /// Charges one primitive read, before joining ([`READ_PRIMITIVES_PER_DRAWN`]).
    pub fn charge_primitive(&mut self, what: impl FnOnce() -> String) -> Result<(), OverBudget> {
        let limit = self.budget.max_primitives.saturating_mul(READ_PRIMITIVES_PER_DRAWN);
        if self.primitives >= limit {
            return Err(OverBudget {
                what: what(),
                needed: self.primitives + 1,
                left: 0,
                limit,
                limit_name: "ResourceBudget::max_primitives × READ_PRIMITIVES_PER_DRAWN",
                unit: "primitives read",
            });
        }
        self.primitives += 1;
        Ok(())
    }

    /// Checks the primitives a loaded model draws (`drawn`, after joining) against
    /// [`ResourceBudget::max_primitives`]; `what` names the model.
    pub fn check_drawn_primitives(&self, what: impl FnOnce() -> String, drawn: u64) -> Result<(), OverBudget> {
        if drawn > self.budget.max_primitives {
            return Err(OverBudget {
                what: what(),
                needed: drawn,
                left: self.budget.max_primitives,
                limit: self.budget.max_primitives,
                limit_name: "ResourceBudget::max_primitives",
                unit: "drawn primitives",
            });
        }
        Ok(())
    }

    /// Charges a decoded `width × height` texture (with its mips), or fails without charging when
    /// a side is over the limit or its bytes over what is left.
    pub fn charge_image(
        &mut self,
        what: impl Fn() -> String,
        width: u32,
        height: u32,
    ) -> Result<(u32, u32), OverBudget> {
        let side = width.max(height);
        if side > MAX_DECODED_SIDE_PX {
            return Err(OverBudget {
                what: format!("{} ({width}×{height})", what()),
                needed: u64::from(side),
                left: u64::from(MAX_DECODED_SIDE_PX),
                limit: u64::from(MAX_DECODED_SIDE_PX),
                limit_name: "budget::MAX_DECODED_SIDE_PX",
                unit: "pixels a side",
            });
        }
        let (w, h) = fit_within(width, height, self.budget.max_image_side_px);
        if (w, h) != (width, height) {
            // Decoded whole, then scaled down: both held for a moment.
            self.check_bytes(
                || format!("{} ({width}×{height}) while it is scaled down to {w}×{h}", what()),
                (u64::from(width) * u64::from(height) * 4).saturating_add(ResourceBudget::texture_bytes(w, h)),
            )?;
        }
        self.charge_bytes(|| format!("{} ({w}×{h})", what()), ResourceBudget::texture_bytes(w, h))?;
        Ok((w, h))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// OpenGL's spare layer: for one layer and for six (or twelve) square ones, nowhere else.
    #[test]
    fn opengl_arrays_that_would_be_plain_or_cube_take_a_spare_layer() {
        for (w, h, layers, on_gl) in [
            (64, 64, 1, 2),
            (64, 32, 1, 2),
            (64, 64, 2, 2),
            (64, 64, 6, 7),
            (64, 64, 12, 13),
            (64, 32, 6, 6),
            (64, 64, 7, 7),
        ] {
            assert_eq!(array_layers(w, h, layers, true), on_gl, "{w}×{h}×{layers}");
            assert_eq!(array_layers(w, h, layers, false), layers);
        }
    }

    #[test]
    fn charges_add_up_and_the_error_names_the_limit() {
        let mut s = Spending::new(ResourceBudget {
            memory_bytes: 1000,
            max_image_side_px: 16,
            max_primitives: 2,
        });
        s.charge_bytes(|| "a".into(), 600).unwrap();
        // A transient check does not charge.
        s.check_bytes(|| "b".into(), 400).unwrap();
        let e = s.charge_bytes(|| "mesh 3".into(), 401).unwrap_err();
        assert_eq!((e.needed, e.left, e.limit), (401, 400, 1000));
        assert!(
            e.to_string().contains("mesh 3") && e.to_string().contains("ResourceBudget::memory_bytes"),
            "{e}"
        );
        // Two drawn, so 32 read (before joining).
        for _ in 0..2 * READ_PRIMITIVES_PER_DRAWN {
            s.charge_primitive(|| "p".into()).unwrap();
        }
        let e = s.charge_primitive(|| "p".into()).unwrap_err();
        assert!(e.to_string().contains("33 primitives read"), "{e}");
        assert!(s.check_drawn_primitives(|| "m".into(), 2).is_ok());
        let e = s.check_drawn_primitives(|| "the model".into(), 3).unwrap_err();
        assert!(e.to_string().contains("the model needs 3 drawn primitives"), "{e}");
        let e = s.charge_image(|| "image 0".into(), 20000, 1).unwrap_err();
        assert!(e.to_string().contains("MAX_DECODED_SIDE_PX"), "{e}");
        // 8×8 RGBA with mips: 256 + 85 = 341 bytes of the 400 left; a second does not fit.
        assert_eq!(s.charge_image(|| "image 1".into(), 8, 8), Ok((8, 8)));
        assert_eq!(ResourceBudget::texture_bytes(8, 8), 341);
        let e = s.charge_image(|| "image 2".into(), 8, 8).unwrap_err();
        assert_eq!((e.needed, e.left), (341, 59));
    }

    #[test]
    fn images_over_the_device_limit_are_charged_at_the_size_they_are_scaled_to() {
        let mut s = Spending::new(ResourceBudget {
            memory_bytes: 10_000,
            max_image_side_px: 16,
            max_primitives: 2,
        });
        // 32×8 becomes 16×4: 256 + 85 bytes charged; the 1024-byte original only checked.
        assert_eq!(s.charge_image(|| "image 0".into(), 32, 8), Ok((16, 4)));
        assert_eq!(s.bytes_left(), 10_000 - ResourceBudget::texture_bytes(16, 4));
        // Decoding a 64×64 original needs 16 KiB for a moment: over what is left.
        let e = s.charge_image(|| "image 1".into(), 64, 64).unwrap_err();
        assert!(e.to_string().contains("scaled down to 16×16"), "{e}");
        assert_eq!(fit_within(17, 1, 16), (16, 1));
        assert_eq!(fit_within(3, 1000, 16), (1, 16));
        assert_eq!(fit_within(8, 8, 16), (8, 8));
    }
}
