//! A texture that a mesh format names by file (OBJ's `map_Kd`, USD's `UsdUVTexture`), decoded
//! from its bytes within the budget: charged from its header before decoding, scaled down where
//! the budget asks, left out with a warning when it cannot be decoded (as a viewer does).
//!
//! **Panics**: none (the decoders' errors become warnings).

use std::path::Path;

use super::Image;
use super::encoded_image::Encoded;
use super::loader::{ModelError, over_budget};
use crate::budget::Spending;

/// `raw` (the file `name`, of the model at `path`) decoded; `None`, with a warning, where it is
/// not an image this loader decodes. Over the budget is the model's error.
pub(super) fn decode(
    name: &str,
    raw: &[u8],
    path: &Path,
    spending: &mut Spending,
    warnings: &mut Vec<String>,
) -> Result<Option<Image>, ModelError> {
    let memory = spending.budget().memory_bytes;
    let what = || format!("texture {name:.80}");
    let header = match Encoded::probe(raw) {
        Ok(header) => header,
        Err(message) => {
            warnings.push(format!("{}: {message}: left out", what()));
            return Ok(None);
        }
    };
    let fitted = spending
        .charge_image(what, header.width, header.height)
        .map_err(|e| over_budget(path, e))?;
    match header.decode(raw, fitted, memory) {
        Ok(decoded) => {
            warnings.extend(header.scaled_down_note(&what(), fitted));
            Ok(Some(Image {
                name: name.to_owned(),
                width: decoded.width(),
                height: decoded.height(),
                rgba8: decoded.into_raw(),
                basis: None,
            }))
        }
        Err(message) => {
            warnings.push(format!("{}: {message}: left out", what()));
            Ok(None)
        }
    }
}
