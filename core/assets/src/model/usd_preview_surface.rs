//! A USD material's `UsdPreviewSurface` as the stage holds it: the portable surface every USD tool writes
//! (Apple's, Blender's, Houdini's exporters; `usd_from_gltf`), a metallic–roughness model close
//! to glTF's.
//!
//! Each input is a constant, a texture (a `UsdUVTexture` connected to it: its file, which of its
//! outputs — `rgb`, `r`, `g`, `b`, `a` — and its wrap modes and scale) or unset (the schema's
//! fallback). Connections through a material's or node graph's interface inputs are followed
//! (at most [`MAX_HOPS`]); any other node between a texture and the surface (a multiply, say)
//! is not evaluated: the input reads as unset, with a warning. Read: diffuse and emissive colour,
//! metallic, roughness, opacity and its threshold, normal and occlusion maps. Not read: clear
//! coat, index of refraction, displacement; the specular workflow (`useSpecularWorkflow`) is read
//! as a dielectric, with a warning.
//!
//! A texture's coordinates ([`Coords`]) are followed from its `st` input: through
//! `UsdTransform2d` nodes (composed: scale, then counter-clockwise rotation in degrees, then
//! translation, each in USD's st frame, t up) to a `UsdPrimvarReader_float2`, whose `varname`
//! names the mesh's primvar. Unconnected, or reaching another kind of node (with a warning), the
//! texture reads the mesh's texture coordinates untransformed.
//!
//! Colours are linear (USD's `color3f`). **Panics**: none.

use glam::{Affine2, Vec2};
use openusd::{sdf, usd};

use super::Wrap;

/// Connections followed from an input to the node that gives its value (interface inputs of
/// materials and node graphs nest a few deep; this bounds a cycle).
pub const MAX_HOPS: usize = 8;

/// Which of a texture's outputs an input reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    Rgb,
    R,
    G,
    B,
    A,
}

impl Channel {
    /// The texel byte this channel reads (red for `rgb`, where one value is wanted).
    pub fn offset(self) -> usize {
        match self {
            Channel::Rgb | Channel::R => 0,
            Channel::G => 1,
            Channel::B => 2,
            Channel::A => 3,
        }
    }
}

/// A `UsdUVTexture` an input reads.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureInput {
    /// The file as authored (relative to the layer that names it).
    pub file: String,
    pub channel: Channel,
    /// `inputs:scale` (multiplies the texel).
    pub scale: [f32; 4],
    pub wrap: [Wrap; 2],
    pub coords: Coords,
}

/// Where a texture reads its coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct Coords {
    /// The primvar (its name without `primvars:`, as the reader's `varname` gives it); `None`
    /// where no reader names one: the mesh's texture coordinates, found by name.
    pub primvar: Option<String>,
    /// The coordinates the texture is sampled at, from the primvar's: `UsdTransform2d`s composed,
    /// in USD's st frame (s right, t up from the image's bottom).
    pub st_transform: Affine2,
}

impl Default for Coords {
    fn default() -> Self {
        Self {
            primvar: None,
            st_transform: Affine2::IDENTITY,
        }
    }
}

/// One input of the surface.
#[derive(Clone, Debug, PartialEq)]
pub enum Input<T> {
    Unset,
    Value(T),
    Texture(TextureInput),
}

impl<T: Copy> Input<T> {
    /// The constant, or `fallback` where there is none (unset or a texture).
    pub fn value_or(&self, fallback: T) -> T {
        match self {
            Input::Value(v) => *v,
            _ => fallback,
        }
    }

    pub fn texture(&self) -> Option<&TextureInput> {
        match self {
            Input::Texture(t) => Some(t),
            _ => None,
        }
    }
}

/// A material's `UsdPreviewSurface`.
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    pub diffuse: Input<[f32; 3]>,
    pub emissive: Input<[f32; 3]>,
    pub metallic: Input<f32>,
    pub roughness: Input<f32>,
    pub opacity: Input<f32>,
    pub opacity_threshold: f32,
    pub normal: Option<TextureInput>,
    pub occlusion: Option<TextureInput>,
}

impl Surface {
    /// Its textures, in the order of the fields.
    pub fn textures(&self) -> impl Iterator<Item = &TextureInput> {
        [
            self.diffuse.texture(),
            self.emissive.texture(),
            self.metallic.texture(),
            self.roughness.texture(),
            self.opacity.texture(),
            self.normal.as_ref(),
            self.occlusion.as_ref(),
        ]
        .into_iter()
        .flatten()
    }

    /// The primvars its textures name, each once, in the order of [`Surface::textures`]:
    /// the first is read as the model's first set of texture coordinates, the second as its
    /// second (a third has no place: its textures read the first).
    pub fn primvars(&self) -> Vec<&str> {
        let mut names: Vec<&str> = Vec::new();
        for name in self.textures().filter_map(|t| t.coords.primvar.as_deref()) {
            if !names.contains(&name) {
                names.push(name);
            }
        }
        names
    }
}

/// The surface of the material at `material`; `None` (with a warning) where it has none this
/// reads. Errors are the reader's, as text.
pub fn read(stage: &usd::Stage, material: &sdf::Path, warnings: &mut Vec<String>) -> Result<Option<Surface>, String> {
    let name = material.as_str();
    let prim = stage.prim(material.clone()).map_err(text)?;
    if prim.type_name().map_err(text)?.as_ref().map(|t| t.as_str()) != Some("Material") {
        warnings.push(format!("{name:.80} is bound as a material but is none: shown plain"));
        return Ok(None);
    }
    // The surface: what the material's universal surface output connects to (through node
    // graphs' outputs), else its MaterialX one.
    let mut shader = None;
    for output in ["outputs:surface", "outputs:mtlx:surface"] {
        let mut at = material.append_property(output).map_err(text)?;
        for _ in 0..MAX_HOPS {
            let Some(next) = stage
                .attribute(at.clone())
                .map_err(text)?
                .connections()
                .map_err(text)?
                .into_iter()
                .next()
            else {
                break;
            };
            let node = next.prim_path();
            if shader_id(stage, &node)?.is_some() {
                shader = Some(node);
                break;
            }
            at = next;
        }
        if shader.is_some() {
            break;
        }
    }
    let Some(shader) = shader else {
        warnings.push(format!("material {name:.80} has no surface: shown plain"));
        return Ok(None);
    };
    let id = shader_id(stage, &shader)?;
    if id.as_deref() != Some("UsdPreviewSurface") {
        warnings.push(format!(
            "material {name:.80}'s surface is {:.40}, not a UsdPreviewSurface: shown plain",
            id.as_deref().unwrap_or("unnamed")
        ));
        return Ok(None);
    }
    let surface = shader;
    let mut reader = InputReader {
        stage,
        surface,
        material: name,
        warnings,
    };
    // The specular workflow's colour has no place in glTF's model: a dielectric, whatever
    // `metallic` (unused in that workflow) says.
    let specular_workflow = reader.scalar("useSpecularWorkflow")?.value_or(0.0) != 0.0;
    let metallic = if specular_workflow {
        reader.warnings.push(format!(
            "material {name:.80} uses the specular workflow: read as a dielectric (metallic 0)"
        ));
        Input::Value(0.0)
    } else {
        reader.scalar("metallic")?
    };
    Ok(Some(Surface {
        diffuse: reader.colour("diffuseColor")?,
        emissive: reader.colour("emissiveColor")?,
        metallic,
        roughness: reader.scalar("roughness")?,
        opacity: reader.scalar("opacity")?,
        opacity_threshold: reader.scalar("opacityThreshold")?.value_or(0.0),
        normal: reader.colour("normal")?.texture().cloned(),
        occlusion: reader.scalar("occlusion")?.texture().cloned(),
    }))
}

/// Reads the inputs of one surface shader.
struct InputReader<'a> {
    stage: &'a usd::Stage,
    surface: sdf::Path,
    material: &'a str,
    warnings: &'a mut Vec<String>,
}

/// What an input's connections lead to.
enum Source {
    Value(sdf::Value),
    Texture(TextureInput),
    Nothing,
}

impl InputReader<'_> {
    fn colour(&mut self, input: &str) -> Result<Input<[f32; 3]>, String> {
        Ok(match self.source(input)? {
            Source::Texture(t) => Input::Texture(t),
            Source::Value(v) => vec3(&v).map_or(Input::Unset, |v| Input::Value(v.map(|c| c as f32))),
            Source::Nothing => Input::Unset,
        })
    }

    fn scalar(&mut self, input: &str) -> Result<Input<f32>, String> {
        Ok(match self.source(input)? {
            Source::Texture(t) => Input::Texture(t),
            Source::Value(v) => scalar(&v).map_or(Input::Unset, |v| Input::Value(v as f32)),
            Source::Nothing => Input::Unset,
        })
    }

    /// Follows `inputs:<input>`'s connections to a value or a texture.
    fn source(&mut self, input: &str) -> Result<Source, String> {
        let mut at = self.surface.append_property(format!("inputs:{input}")).map_err(text)?;
        for _ in 0..MAX_HOPS {
            let attribute = self.stage.attribute(at.clone()).map_err(text)?;
            let Some(next) = attribute.connections().map_err(text)?.into_iter().next() else {
                return Ok(attribute
                    .get::<sdf::Value>()
                    .map_err(text)?
                    .map_or(Source::Nothing, Source::Value));
            };
            let node = next.prim_path();
            let property = next.as_str().rsplit_once('.').map_or("", |(_, p)| p).to_owned();
            if let Some(output) = property.strip_prefix("outputs:")
                && let Some(id) = shader_id(self.stage, &node)?
            {
                if id == "UsdUVTexture" {
                    return self.texture(&node, output, input);
                }
                self.warnings.push(format!(
                    "material {:.80}: its {input} comes from a {id:.40} node, which is not evaluated: left at its default",
                    self.material
                ));
                return Ok(Source::Nothing);
            }
            // An interface input of a material or node graph: its value, or where it connects.
            at = next;
        }
        self.warnings.push(format!(
            "material {:.80}: its {input} goes through more than {MAX_HOPS} connections: left at its default",
            self.material
        ));
        Ok(Source::Nothing)
    }

    /// The `UsdUVTexture` at `node`, read through its output `output`.
    fn texture(&mut self, node: &sdf::Path, output: &str, input: &str) -> Result<Source, String> {
        let channel = match output {
            "rgb" => Channel::Rgb,
            "r" => Channel::R,
            "g" => Channel::G,
            "b" => Channel::B,
            "a" => Channel::A,
            other => {
                self.warnings.push(format!(
                    "material {:.80}: its {input} reads a texture's output {other:.20}, which is none: left at its default",
                    self.material
                ));
                return Ok(Source::Nothing);
            }
        };
        let inputs = |name: &str| -> Result<Option<sdf::Value>, String> {
            let path = node.append_property(format!("inputs:{name}")).map_err(text)?;
            value_through(self.stage, path)
        };
        let Some(file) = inputs("file")?.and_then(|v| match v {
            sdf::Value::AssetPath(a) => Some(a.asset_path().to_owned()),
            sdf::Value::String(s) => Some(s),
            _ => None,
        }) else {
            self.warnings.push(format!(
                "material {:.80}: the texture for its {input} names no file: left at its default",
                self.material
            ));
            return Ok(Source::Nothing);
        };
        let scale = inputs("scale")?
            .and_then(|v| vec4(&v))
            .map_or([1.0; 4], |s| s.map(|c| c as f32));
        let wrap = |name: &str| -> Result<Wrap, String> {
            Ok(match inputs(name)?.as_ref().and_then(token) {
                Some("mirror") => Wrap::MirroredRepeat,
                Some("clamp") | Some("black") => Wrap::ClampToEdge,
                // `repeat`, and `useMetadata` where no image format here carries any.
                _ => Wrap::Repeat,
            })
        };
        Ok(Source::Texture(TextureInput {
            file,
            channel,
            scale,
            wrap: [wrap("wrapS")?, wrap("wrapT")?],
            coords: self.coords(node, input)?,
        }))
    }

    /// Where the texture at `node` (read for the surface's `input`) takes its coordinates:
    /// its `st` input followed through interface inputs and `UsdTransform2d`s to a primvar
    /// reader.
    fn coords(&mut self, node: &sdf::Path, input: &str) -> Result<Coords, String> {
        let mut coords = Coords::default();
        let mut at = node.append_property("inputs:st").map_err(text)?;
        for _ in 0..MAX_HOPS {
            let attribute = self.stage.attribute(at.clone()).map_err(text)?;
            let Some(next) = attribute.connections().map_err(text)?.into_iter().next() else {
                // Unconnected (or a constant): the mesh's own coordinates.
                return Ok(coords);
            };
            let node = next.prim_path();
            let is_output = next
                .as_str()
                .rsplit_once('.')
                .is_some_and(|(_, p)| p.starts_with("outputs:"));
            if is_output && let Some(id) = shader_id(self.stage, &node)? {
                let inputs = |name: &str| -> Result<Option<sdf::Value>, String> {
                    value_through(
                        self.stage,
                        node.append_property(format!("inputs:{name}")).map_err(text)?,
                    )
                };
                match id.as_str() {
                    "UsdPrimvarReader_float2" => {
                        coords.primvar = inputs("varname")?
                            .as_ref()
                            .and_then(token)
                            .filter(|n| !n.is_empty())
                            .map(|n| n.strip_prefix("primvars:").unwrap_or(n).to_owned());
                        return Ok(coords);
                    }
                    "UsdTransform2d" => {
                        let pair = |v: Option<sdf::Value>, fallback: f32| {
                            v.as_ref().and_then(vec2).map_or(Vec2::splat(fallback), |p| p.as_vec2())
                        };
                        let scale = pair(inputs("scale")?, 1.0);
                        let translation = pair(inputs("translation")?, 0.0);
                        let rotation_deg = inputs("rotation")?.as_ref().and_then(scalar).unwrap_or(0.0) as f32;
                        // Reached from the texture's side: this one applies after those found
                        // before it are (outer ∘ inner).
                        coords.st_transform *=
                            Affine2::from_scale_angle_translation(scale, rotation_deg.to_radians(), translation);
                        at = node.append_property("inputs:in").map_err(text)?;
                        continue;
                    }
                    other => {
                        self.warnings.push(format!(
                            "material {:.80}: the texture for its {input} takes its coordinates from a {other:.40} node, which is not evaluated: the mesh's own are used",
                            self.material
                        ));
                        return Ok(Coords::default());
                    }
                }
            }
            at = next;
        }
        self.warnings.push(format!(
            "material {:.80}: the coordinates of the texture for its {input} go through more than {MAX_HOPS} connections: the mesh's own are used",
            self.material
        ));
        Ok(Coords::default())
    }
}

/// The value of the attribute at `path`, through its connections (an interface input).
fn value_through(stage: &usd::Stage, mut path: sdf::Path) -> Result<Option<sdf::Value>, String> {
    for _ in 0..MAX_HOPS {
        let attribute = stage.attribute(path.clone()).map_err(text)?;
        match attribute.connections().map_err(text)?.into_iter().next() {
            Some(next) => path = next,
            None => return attribute.get::<sdf::Value>().map_err(text),
        }
    }
    Ok(None)
}

/// The `info:id` of the shader at `node`; `None` where it is not a shader.
fn shader_id(stage: &usd::Stage, node: &sdf::Path) -> Result<Option<String>, String> {
    let prim = stage.prim(node.clone()).map_err(text)?;
    if prim.type_name().map_err(text)?.as_ref().map(|t| t.as_str()) != Some("Shader") {
        return Ok(None);
    }
    let id = stage
        .attribute(node.append_property("info:id").map_err(text)?)
        .map_err(text)?
        .get::<sdf::Value>()
        .map_err(text)?;
    Ok(Some(id.as_ref().and_then(token).unwrap_or("unnamed").to_owned()))
}

/// A reader's error as text (with its causes).
pub fn text(error: impl std::fmt::Display) -> String {
    format!("{error:#}")
}

/// A number, of any of USD's scalar types.
pub fn scalar(value: &sdf::Value) -> Option<f64> {
    match value {
        sdf::Value::Double(v) => Some(*v),
        sdf::Value::Float(v) => Some(f64::from(*v)),
        sdf::Value::Half(v) => Some(f64::from(v.to_f32())),
        sdf::Value::Int(v) => Some(f64::from(*v)),
        sdf::Value::Bool(v) => Some(if *v { 1.0 } else { 0.0 }),
        _ => None,
    }
    .filter(|v| v.is_finite())
}

/// A 3-vector, of any precision.
pub fn vec3(value: &sdf::Value) -> Option<[f64; 3]> {
    let v = match value {
        sdf::Value::Vec3f(v) => [v.x, v.y, v.z].map(f64::from),
        sdf::Value::Vec3d(v) => [v.x, v.y, v.z],
        sdf::Value::Vec3h(v) => [v.x, v.y, v.z].map(|c| f64::from(c.to_f32())),
        _ => return None,
    };
    v.iter().all(|c| c.is_finite()).then_some(v)
}

/// A 2-vector, of any precision.
fn vec2(value: &sdf::Value) -> Option<glam::DVec2> {
    let v = match value {
        sdf::Value::Vec2f(v) => [v.x, v.y].map(f64::from),
        sdf::Value::Vec2d(v) => [v.x, v.y],
        sdf::Value::Vec2h(v) => [v.x, v.y].map(|c| f64::from(c.to_f32())),
        _ => return None,
    };
    v.iter().all(|c| c.is_finite()).then(|| glam::DVec2::from(v))
}

/// A 4-vector, of any precision.
fn vec4(value: &sdf::Value) -> Option<[f64; 4]> {
    let v = match value {
        sdf::Value::Vec4f(v) => [v.x, v.y, v.z, v.w].map(f64::from),
        sdf::Value::Vec4d(v) => [v.x, v.y, v.z, v.w],
        sdf::Value::Vec4h(v) => [v.x, v.y, v.z, v.w].map(|c| f64::from(c.to_f32())),
        _ => return None,
    };
    v.iter().all(|c| c.is_finite()).then_some(v)
}

/// A token's (or string's) text.
pub fn token(value: &sdf::Value) -> Option<&str> {
    match value {
        sdf::Value::Token(t) => Some(t.as_str()),
        sdf::Value::String(s) => Some(s),
        _ => None,
    }
}
