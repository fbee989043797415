//! The message definitions of a map: its search path (the user's
//! `--msg-path` folders, the map's `msg_path`, `AMENT_PREFIX_PATH`, the
//! carried definitions) loaded into a [`Registry`], and the whole check of
//! a map file with it.

use crate::check::check_parsed;
use crate::map::{self, Map};
use crate::msgs::{Registry, SearchPath};
use situ_compiler::codes;
use situ_compiler::model::Model;
use situ_grammar::diag::{Diagnostic, FileId};
use std::path::{Path, PathBuf};

/// The search path of `map` (file `file`, in folder `map_dir`): the `user`
/// folders first, then the map's `msg_path` (relative to `map_dir`), then
/// `AMENT_PREFIX_PATH`, then the carried definitions; with E0423 for each
/// `msg_path` entry that is not a folder.
pub fn search_path(map: &Map, map_dir: &Path, user: &[PathBuf], file: FileId) -> (SearchPath, Vec<Diagnostic>) {
    let mut folders = user.to_vec();
    let mut found = Vec::new();
    for entry in &map.msg_path {
        let dir = map_dir.join(&entry.value);
        if dir.is_dir() {
            folders.push(dir);
        } else {
            found.push(
                Diagnostic::error(
                    codes::ROS2_BAD_MSG_PATH,
                    format!("`msg_path` entry `{}` is not a folder", entry.value),
                    file,
                    entry.span,
                    format!("{} is not a folder", dir.display()),
                )
                .with_help(
                    "write the path from the map's folder to a package, a folder of packages or a prefix with `share/`",
                ),
            );
        }
    }
    (SearchPath::new(&folders), found)
}

/// The registry of `map`'s search path (see [`search_path`]) and the
/// findings of its `msg_path`.
pub fn registry_of(map: &Map, map_dir: &Path, user: &[PathBuf], file: FileId) -> (Registry, Vec<Diagnostic>) {
    let (search, found) = search_path(map, map_dir, user, file);
    let registry = if search == SearchPath::carried() { Registry::carried() } else { Registry::load(&search) };
    (registry, found)
}

/// Every finding of the map `text` (file `file`, in folder `map_dir`)
/// against the rules' `model`, its message types read from its search
/// path with the `user` folders first; and the registry it was checked
/// with (`None` when the map does not parse).
pub fn check_map_file(
    model: &Model,
    text: &str,
    map_dir: &Path,
    user: &[PathBuf],
    file: FileId,
) -> (Vec<Diagnostic>, Option<Registry>) {
    let parsed = match map::parse(text, file) {
        Ok(m) => m,
        Err(d) => return (vec![*d], None),
    };
    let (registry, mut found) = registry_of(&parsed, map_dir, user, file);
    found.extend(check_parsed(model, &parsed, &registry, file));
    found.sort_by_key(|d| (d.primary.span.start, d.code));
    (found, Some(registry))
}
