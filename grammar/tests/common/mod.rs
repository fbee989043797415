//! What the grammar's test binaries share.

use std::path::{Path, PathBuf};

/// Every `.situ` file under `dir`, recursively, sorted; build output and
/// hidden folders aside; none if `dir` is missing.
pub fn situ_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    let mut paths: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
    paths.sort();
    for path in paths {
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        if path.is_dir() {
            if !name.starts_with('.') && name != "target" && name != "node_modules" {
                situ_files(&path, out);
            }
        } else if name.ends_with(".situ") {
            out.push(path);
        }
    }
}
