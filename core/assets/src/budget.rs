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

/// What one artifact may take. See the module docs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ResourceBudget {
    /// Bytes of one copy of the artifact in memory: vertices, indices and decoded textures
    /// (with their mip chains) together. Also the largest file read for it.
    pub memory_bytes: u64,
    /// Largest image side, pixels: the GPU's `max_texture_dimension_2d`.
    pub max_image_side_px: u32,
    /// Most primitives drawn (meshes × the nodes that instance them): each is a draw call per
    /// eye and pass.
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

    /// Charges one drawn primitive.
    pub fn charge_primitive(&mut self, what: impl FnOnce() -> String) -> Result<(), OverBudget> {
        if self.primitives >= self.budget.max_primitives {
            return Err(OverBudget {
                what: what(),
                needed: self.primitives + 1,
                left: 0,
                limit: self.budget.max_primitives,
                limit_name: "ResourceBudget::max_primitives",
                unit: "drawn primitives",
            });
        }
        self.primitives += 1;
        Ok(())
    }

    /// Charges a decoded `width × height` texture (with its mips), or fails without charging when
    /// a side is over the limit or its bytes over what is left.
    pub fn charge_image(&mut self, what: impl Fn() -> String, width: u32, height: u32) -> Result<(), OverBudget> {
        let side = width.max(height);
        if side > self.budget.max_image_side_px {
            return Err(OverBudget {
                what: format!("{} ({width}×{height})", what()),
                needed: u64::from(side),
                left: u64::from(self.budget.max_image_side_px),
                limit: u64::from(self.budget.max_image_side_px),
                limit_name: "ResourceBudget::max_image_side_px",
                unit: "pixels a side",
            });
        }
        self.charge_bytes(
            || format!("{} ({width}×{height})", what()),
            ResourceBudget::texture_bytes(width, height),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        s.charge_primitive(|| "p".into()).unwrap();
        s.charge_primitive(|| "p".into()).unwrap();
        assert!(s.charge_primitive(|| "p".into()).is_err());
        let e = s.charge_image(|| "image 0".into(), 17, 1).unwrap_err();
        assert!(e.to_string().contains("max_image_side_px"), "{e}");
        // 8×8 RGBA with mips: 256 + 85 = 341 bytes of the 400 left; a second does not fit.
        s.charge_image(|| "image 1".into(), 8, 8).unwrap();
        assert_eq!(ResourceBudget::texture_bytes(8, 8), 341);
        let e = s.charge_image(|| "image 2".into(), 8, 8).unwrap_err();
        assert_eq!((e.needed, e.left), (341, 59));
    }
}
