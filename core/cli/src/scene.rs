//! What `view` and `render` show, and the [`Engine`] that shows it: both commands drive the same
//! embedding API as the phone shells (model loading, fitting, floor, environment, containment,
//! rendering), so the desktop runs the phones' frame pipeline.

use std::path::PathBuf;

use anyhow::{Result, bail};
use phantogram::anaglyph::Method;
use phantogram::engine::{Engine, EngineConfig};
use phantogram::model::{DioramaFit, Placement};
use winit::event_loop::EventLoop;

/// What is shown, and how: shared by `view` and `render`, so that the window previews exactly
/// what the frames will hold.
#[derive(clap::Args)]
pub struct SceneArgs {
    /// A glTF 2.0 model (.gltf or .glb), a Smithsonian Voyager folder or its scene.svx.json
    /// (its best scan present), a USD package or layer (.usdz, .usd, .usda, .usdc), an .stl,
    /// .ply or .obj scan, a point cloud as text (.xyz, .pts), or a laser scan (.las, .laz, .e57);
    /// the default artifact when omitted.
    model: Option<PathBuf>,
    /// One of the built-in artifacts instead: amphora (the default), medal or tablet; or the
    /// Diorama (marbles, dice, coins and vessels in a tray, under the log's gravity).
    #[arg(long, value_name = "NAME", conflicts_with = "model")]
    artifact: Option<String>,
    /// Fraction of a loaded model's height that stands in front of the glass.
    #[arg(long, default_value_t = 0.4)]
    protrude: f32,
    /// How a model is placed: standing out of the glass, facing the viewer from within it
    /// (reliefs, tablets), auto (facing when thin front to back), or surface (surface mode: true
    /// size, its front in the glass, for coins, paintings and manuscripts; built-ins too).
    #[arg(long, value_enum, default_value = "auto")]
    placement: PlacementArg,
    /// Leave out the diorama floor under the model (and the shadow cast on it).
    #[arg(long)]
    no_floor: bool,
    /// An equirectangular HDR environment (.hdr or .exr, world frame) to light the artifact;
    /// a generated neutral studio when omitted.
    #[arg(long)]
    environment: Option<PathBuf>,
    /// Keep --environment's sun in its image (and the default key light over the viewer's
    /// shoulder) instead of lighting with it as the directional light, with its shadow.
    #[arg(long, requires = "environment", conflicts_with = "environment_from_camera")]
    sun_in_image: bool,
    /// Light the artifact with the room as a phone's front camera would see it along this
    /// sensor log, looking into --environment (which then is the room, not the light): the live
    /// room light replayed on the desktop, captured before the first frame.
    #[arg(long, value_name = "LOG", requires = "environment")]
    environment_from_camera: Option<PathBuf>,
    /// With --environment-from-camera: the phone's rear camera looks into the room too, at the
    /// same time as the front one (as phones that run both cameras at once do).
    #[arg(long, requires = "environment_from_camera")]
    rear_camera: bool,
    /// A lamp in place of the room's light: raking (a spot light low at the screen's left edge,
    /// fixed in the room: for reading inscriptions) or torch (held by the phone above its top
    /// edge).
    #[arg(long, value_enum, value_name = "LAMP")]
    lamp: Option<LampArg>,
    /// Show the artifact in one of the Ward material presets instead of its own material (not
    /// remembered): matte, glazed, polished, patinated, brushed-metal, silk or lacquer.
    #[arg(long, value_name = "PRESET")]
    material: Option<String>,
}

/// The preset called `name` on the command line (its name with dashes for spaces).
fn material_preset(name: &str) -> Result<phantogram::ward::WardPreset> {
    use phantogram::ward::WardPreset;
    WardPreset::ALL
        .into_iter()
        .find(|p| p.name().replace(' ', "-") == name)
        .ok_or_else(|| {
            let names: Vec<String> = WardPreset::ALL.iter().map(|p| p.name().replace(' ', "-")).collect();
            anyhow::anyhow!("--material {name:?} is not a preset (choose from {})", names.join(", "))
        })
}

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum LampArg {
    Raking,
    Torch,
}

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum PlacementArg {
    Auto,
    Standing,
    Facing,
    Surface,
}

impl SceneArgs {
    /// Checks the settings and makes the engine (files are read before any GPU work, so a bad
    /// one is reported at once, with or without a GPU). Prints what was loaded and on what.
    /// `interactive`: someone looks at it (the viewer: hints toward unseen sides), rather than a
    /// recording being made (`render`).
    ///
    /// `window`: for the viewer, where its event loop goes, made once the files are read and
    /// before the device, which is opened for its display (OpenGL presents to no window
    /// otherwise); none for offscreen work.
    pub fn engine(
        &self,
        method: Method,
        calibration_path: Option<PathBuf>,
        interactive: bool,
        window: Option<&mut Option<EventLoop<()>>>,
    ) -> Result<Engine> {
        if !(0.0..=1.0).contains(&self.protrude) {
            bail!("--protrude must be a fraction between 0 and 1, got {}", self.protrude);
        }
        let artifact = match &self.artifact {
            Some(name) => {
                let mut known: Vec<&str> = phantogram::builtin::BUILT_INS.iter().map(|b| b.key).collect();
                known.push("diorama");
                if !known.contains(&name.as_str()) {
                    bail!(
                        "--artifact {name:?} is not a built-in artifact (choose from {})",
                        known.join(", ")
                    );
                }
                Some(phantogram::library::ArtifactId::built_in(name))
            }
            None => None,
        };
        let material = self.material.as_deref().map(material_preset).transpose()?;
        let sweep = match (&self.environment_from_camera, &self.environment) {
            (Some(log), Some(room)) => Some(crate::room_capture::RoomSweep::prepare(room, log, self.rear_camera)?),
            _ => None,
        };
        let config = EngineConfig {
            method,
            model_path: self.model.clone(),
            artifact,
            // With a camera replay the environment is the room the camera looks into.
            environment_path: if self.environment_from_camera.is_some() {
                None
            } else {
                self.environment.clone()
            },
            sun_from_environment: !self.sun_in_image,
            room_light: self.environment_from_camera.is_some(),
            fit: DioramaFit {
                placement: match self.placement {
                    PlacementArg::Auto => Placement::Auto,
                    PlacementArg::Standing => Placement::Standing,
                    PlacementArg::Facing => Placement::Facing,
                    PlacementArg::Surface => Placement::Surface,
                },
                protrude_fraction: self.protrude,
                ..DioramaFit::default()
            },
            floor: !self.no_floor,
            calibration_path,
            // Files dropped on the viewer's window are kept, as a phone keeps those it opens.
            library_dir: phantogram::library_dir(),
            side_hints: interactive,
            ..EngineConfig::default()
        };
        let mut engine = match window {
            Some(slot) => {
                // A missing display is said as such, not as a device that failed to open.
                let mut no_display = None;
                let engine = Engine::with_gpu_from(
                    || {
                        let event_loop = crate::viewer::event_loop().map_err(|e| {
                            let said = phantogram::render::RenderError::Device(format!("{e:#}"));
                            no_display = Some(e);
                            said
                        })?;
                        let display = Box::new(event_loop.owned_display_handle());
                        *slot = Some(event_loop);
                        phantogram::render::Gpu::for_display(display, None)
                    },
                    config,
                );
                match (engine, no_display) {
                    (Err(_), Some(e)) => return Err(e),
                    (engine, _) => engine?,
                }
            }
            None => Engine::new(config)?,
        };
        match self.lamp {
            Some(LampArg::Raking) => engine.set_lamp(Some(phantogram::lamp::LampSetting::raking())),
            Some(LampArg::Torch) => engine.set_lamp(Some(phantogram::lamp::LampSetting::torch())),
            None => {}
        }
        if let Some(sweep) = &sweep {
            sweep.feed(&engine)?;
        }
        if let Some(preset) = material {
            // Shown, not remembered: the command line's library is the user's own.
            engine.show_appearance(phantogram::render::Appearance::preset(preset));
        }
        if let Some(path) = &self.model {
            let info = engine.model_info();
            for w in &info.warnings {
                eprintln!("warning: {}: {w}", path.display());
            }
            // The model's name is its file's: it tells which scan a Voyager scene or folder gave.
            eprintln!(
                "{}: {}, {} triangles, {} materials, {} images",
                path.display(),
                info.name,
                info.triangles,
                info.materials,
                info.images
            );
        }
        if let Some(w) = engine.calibration_warning() {
            eprintln!("warning: {w}");
        }
        eprintln!("rendering on {}", engine.renderer().gpu().describe());
        Ok(engine)
    }
}
