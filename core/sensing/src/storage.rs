//! Where the desktop tools keep per-user files: the calibration, the face models, the artifact
//! library. The phone shells pass their app-private folders instead and never use this.

use std::path::PathBuf;

/// `$override_var` if set, else `$xdg_var/phantogram/name`, else `~/home_dir/phantogram/name`.
/// `None` only when none of those variables is set.
pub fn user_path(override_var: &str, xdg_var: &str, home_dir: &str, name: &str) -> Option<PathBuf> {
    if let Some(p) = std::env::var_os(override_var) {
        return Some(PathBuf::from(p));
    }
    let base = std::env::var_os(xdg_var)
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(home_dir)))?;
    Some(base.join("phantogram").join(name))
}

/// Where `cargo xtask models` puts the face-tracking models and where `phantogram_vision` looks
/// for them: `$PHANTOGRAM_MODELS` if set, else `$XDG_CACHE_HOME/phantogram/models`, else
/// `~/.cache/phantogram/models`. `None` only without any of those variables.
pub fn face_models_dir() -> Option<PathBuf> {
    user_path("PHANTOGRAM_MODELS", "XDG_CACHE_HOME", ".cache", "models")
}

/// Where the desktop viewer keeps the artifacts opened in it (and their thumbnails):
/// `$PHANTOGRAM_LIBRARY` if set, else `$XDG_DATA_HOME/phantogram/library`, else
/// `~/.local/share/phantogram/library`. `None` only without any of those variables.
pub fn library_dir() -> Option<PathBuf> {
    user_path("PHANTOGRAM_LIBRARY", "XDG_DATA_HOME", ".local/share", "library")
}
