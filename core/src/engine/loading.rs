//! Choosing, importing and loading artifacts: the library's entries, loading off the render
//! thread with progress and cancel, and installing a loaded model (impostors planned, fit).

use super::{Engine, EngineError, appearance_key};
use crate::artifacts::{LoadStatus, ModelInfo};
use crate::containment::ContainmentSmoother;

/// The impostors planned for `model` and announced to its `detail` (none without levels of
/// detail): within what the artifact's memory budget leaves of it, on `renderer`'s device.
pub(super) fn impostors_for(
    model: &crate::model::Model,
    detail: Option<&mut phantogram_detail::Detail>,
    memory_bytes: u64,
    renderer: &crate::render::Renderer,
) -> crate::impostors::ImpostorBaker {
    let Some(detail) = detail else {
        return Default::default();
    };
    let left = memory_bytes.saturating_sub(crate::budget::model_bytes(model));
    crate::impostors::ImpostorBaker::plan_for(model, left, renderer.gpu().is_opengl(), detail)
}

pub(super) fn load_error(e: crate::artifacts::LoadError) -> EngineError {
    match e {
        crate::artifacts::LoadError::Library(e) => EngineError::Library(e),
        crate::artifacts::LoadError::Render(e) => EngineError::Render(e),
        crate::artifacts::LoadError::Cancelled => EngineError::InvalidArgument("loading was cancelled".into()),
        crate::artifacts::LoadError::Read { name, error } => EngineError::InvalidArgument(format!("{name}: {error}")),
    }
}

/// The Diorama's entry in the artifact library.
pub(super) fn diorama_entry() -> crate::library::ArtifactEntry {
    crate::library::ArtifactEntry {
        id: crate::library::ArtifactId::built_in("diorama"),
        title: "Diorama: tilt to roll marbles".into(),
        credit: Some(crate::builtin::CREDIT.into()),
        licence: Some(crate::builtin::LICENCE.into()),
        model_path: None,
    }
}

impl Engine {
    /// What is on screen ([`EngineConfig::model_path`](super::EngineConfig::model_path), or the library's artifact).
    pub fn model_info(&self) -> &ModelInfo {
        &self.model_info
    }

    /// Every artifact the library offers (built in, bundled, imported), for the gallery.
    pub fn artifacts(&self) -> Vec<crate::library::ArtifactEntry> {
        let mut list = self.loader.library().list();
        // The Diorama is a scene, not a file: listed after the built-in artifacts.
        let after_built_ins = list
            .iter()
            .position(|e| e.id.origin != crate::library::Origin::BuiltIn)
            .unwrap_or(list.len());
        list.insert(after_built_ins, diorama_entry());
        list
    }

    /// Starts showing an artifact of the library: loaded in the background (see
    /// [`crate::artifacts`]); the artifact on screen stays until it is ready. Progress and
    /// failure: [`Self::loading_status`].
    pub fn select_artifact(&mut self, id: crate::library::ArtifactId) {
        if id.to_string() == crate::diorama::DIORAMA_ID {
            self.loader.cancel();
            self.show_diorama();
            return;
        }
        let placing = self.placing();
        self.loader.start(crate::artifacts::Request::Select(id), placing);
    }

    /// Shows the Diorama in place of the artifact (made at once: no file to load).
    pub(super) fn show_diorama(&mut self) {
        let screen = self.session.config().screen;
        let scene = match crate::diorama::DioramaScene::new(&screen) {
            Ok(scene) => scene,
            Err(e) => {
                self.loader.fail("Diorama".into(), e.to_string());
                return;
            }
        };
        if let Err(e) = self.renderer.set_model(scene.model()) {
            self.loader.fail("Diorama".into(), e.to_string());
            return;
        }
        let model = scene.model();
        self.bounds = model.bounds().unwrap_or(self.bounds);
        self.model_info = ModelInfo::of(model, Some(diorama_entry()));
        self.renderer.appearance = self.appearances.get(&appearance_key(&self.model_info));
        self.smoother = ContainmentSmoother::default();
        self.detail = None;
        self.impostors = Default::default();
        self.seen = None;
        self.side_hint = None;
        self.diorama = Some(Box::new(scene));
        self.diorama_grab = None;
    }

    /// The Diorama on screen, if it is.
    pub fn diorama(&self) -> Option<&crate::diorama::DioramaScene> {
        self.diorama.as_deref()
    }

    /// Imports a file the user opened (its display name and bytes: a `.glb`, `.gltf`, `.stl`, `.ply`, `.obj`, `.xyz`, `.pts`, `.las`, `.laz`, `.e57`, `.usdz` or `.zip`)
    /// into the library and shows it when loaded, in the background as [`Self::select_artifact`].
    pub fn import_artifact(&mut self, name: &str, bytes: Vec<u8>) {
        self.import_artifact_from(name, crate::artifacts::FileSource::Bytes(bytes));
    }

    /// As [`Self::import_artifact`], the content read on the loader's thread when it is a
    /// reader (see [`crate::artifacts::FileSource`]).
    pub fn import_artifact_from(&mut self, name: &str, source: crate::artifacts::FileSource) {
        let placing = self.placing();
        self.loader.start(
            crate::artifacts::Request::Import {
                name: name.to_owned(),
                source,
            },
            placing,
        );
    }

    /// Removes an imported artifact from the library (if it is on screen, it stays there until
    /// another is chosen).
    pub fn remove_artifact(&mut self, id: &crate::library::ArtifactId) -> Result<(), EngineError> {
        Ok(self.loader.library().remove(id)?)
    }

    /// Gives up the load under way; the artifact on screen stays.
    pub fn cancel_loading(&mut self) {
        self.loader.cancel();
    }

    /// Loading progress, or why the last load failed (until [`Self::dismiss_message`]).
    pub fn loading_status(&self) -> LoadStatus {
        self.loader.status()
    }

    /// The user has read the failure message.
    pub fn dismiss_message(&mut self) {
        self.loader.dismiss();
    }

    /// Waits up to `timeout` for the load under way and shows its artifact (for the desktop
    /// tools and tests; the shells just keep drawing, which takes finished loads in turn).
    /// Returns whether a new artifact is now on screen.
    pub fn wait_for_artifact(&mut self, timeout: std::time::Duration) -> bool {
        match self.loader.wait(timeout) {
            Some(prepared) => self.install(prepared),
            None => false,
        }
    }

    pub(super) fn placing(&self) -> crate::artifacts::Placing {
        crate::artifacts::Placing {
            screen: self.session.config().screen,
            fit: self.fit,
            floor: self.floor,
            memory_bytes: self.loader.budget().memory_bytes,
        }
    }

    /// Uploads a loaded artifact in place of the one on screen; on failure the old one stays
    /// and the reason goes to [`Self::loading_status`].
    pub(super) fn install(&mut self, prepared: crate::artifacts::Prepared) -> bool {
        match self.renderer.set_model(&prepared.model) {
            Ok(()) => {
                self.diorama = None;
                self.diorama_grab = None;
                self.detail = prepared.detail.map(|mut d| {
                    d.set_target(self.frame_target_s);
                    d
                });
                self.impostors = impostors_for(
                    &prepared.model,
                    self.detail.as_mut(),
                    self.loader.budget().memory_bytes,
                    &self.renderer,
                );
                // The best scan taking over from its preview is the same artifact: what was
                // seen of it stays seen.
                let same_artifact = self.model_info.preview
                    && self.model_info.artifact.as_ref().map(|a| &a.id)
                        == prepared.info.artifact.as_ref().map(|a| &a.id);
                if !(same_artifact && self.seen.is_some()) {
                    self.seen = self.side_hints.then_some(prepared.seen);
                }
                self.side_hint = None;
                self.bounds = prepared.bounds;
                self.model_info = prepared.info;
                self.renderer.appearance = self.appearances.get(&appearance_key(&self.model_info));
                self.smoother = ContainmentSmoother::default();
                self.model = prepared.model;
                true
            }
            Err(e) => {
                let title = prepared.info.artifact.map_or(prepared.info.name, |a| a.title);
                self.loader.fail(title, e.to_string());
                false
            }
        }
    }
}
