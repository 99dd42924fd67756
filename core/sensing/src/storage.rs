//! Where the desktop tools keep per-user files (the calibration here, the face models in
//! `phantogram`). The phone shells pass their app-private folders instead and never use this.

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
