//! Reading a root file and everything it includes: decoding, parsing, and the
//! include graph (relative paths, each file once, cycles refused).

use crate::codes;
use crate::loader::Loader;
use crate::source::{SourceFile, SourceMap};
use situ_grammar::ast::{File, Item, Span};
use situ_grammar::diag::{Diagnostic, FileId};
use situ_grammar::ItemCache;
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

/// How deep includes may nest: the root includes a file at depth 1, which
/// includes one at depth 2, and so on. Deeper is E0009: loading recurses
/// once per level, and no real layout of files needs more.
pub const MAX_INCLUDE_DEPTH: usize = 64;

/// Every file of one compilation, parsed.
#[derive(Debug, Clone, Default)]
pub struct Loaded {
    pub sources: SourceMap,
    /// The parsed files, each after the files it includes (the root last), so
    /// that items are in declaration order: an include stands for its items.
    pub files: Vec<(FileId, File)>,
    pub diagnostics: Vec<Diagnostic>,
    /// The identities of the files read (canonical paths), in reading order.
    pub sources_identities: Vec<PathBuf>,
}

/// The root file could not be read at all (a usage or I/O error, not a finding).
#[derive(Debug)]
pub struct RootError {
    pub path: PathBuf,
    pub error: std::io::Error,
}

impl std::fmt::Display for RootError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "cannot read `{}`: {}", self.path.display(), self.error)
    }
}

impl std::error::Error for RootError {}

/// Loads `root` and its includes.
pub fn load(root: &Path, loader: &dyn Loader) -> Result<Loaded, RootError> {
    load_cached(root, loader, None)
}

/// [`load`], every file parsed through `cache` when there is one (a tool that
/// loads the same files again after each edit: only the items an edit
/// touched are parsed again); the result is the same.
pub fn load_cached(root: &Path, loader: &dyn Loader, cache: Option<&mut ItemCache>) -> Result<Loaded, RootError> {
    let bytes = loader.read(root).map_err(|error| RootError { path: root.to_path_buf(), error })?;
    let identity = loader.identity(root).unwrap_or_else(|_| root.to_path_buf());
    let mut state = LoadState::new(loader, Loaded::default());
    state.cache = cache;
    state.visit(root, identity, bytes);
    Ok(state.loaded)
}

/// Loads `root` and its includes, then each of `extra` (a file of scripts or
/// tests written beside the rules, say) with its includes; a file is read
/// once, whoever includes it. The extra files see the root's declarations as
/// if the root included them at its end.
pub fn load_with(root: &Path, extra: &[&Path], loader: &dyn Loader) -> Result<Loaded, RootError> {
    let mut loaded = load(root, loader)?;
    for path in extra {
        let bytes = loader.read(path).map_err(|error| RootError { path: path.to_path_buf(), error })?;
        let identity = loader.identity(path).unwrap_or_else(|_| path.to_path_buf());
        if loaded.sources_identities.contains(&identity) {
            continue;
        }
        let mut state = LoadState::new(loader, loaded);
        state.visit(path, identity, bytes);
        loaded = state.loaded;
    }
    Ok(loaded)
}

/// Loads a source given as text (no includes are possible unless `loader` serves them).
pub fn load_text(name: &str, text: &str, loader: &dyn Loader) -> Loaded {
    let mut state = LoadState::new(loader, Loaded::default());
    state.visit(Path::new(name), PathBuf::from(name), text.as_bytes().to_vec());
    state.loaded
}

struct LoadState<'a> {
    loader: &'a dyn Loader,
    loaded: Loaded,
    /// Identities of the files read so far.
    seen: HashSet<PathBuf>,
    /// Identities of the files being read, root first, with the names they
    /// were reached by: an include of one of these is a cycle.
    stack: Vec<(PathBuf, String)>,
    /// Where each identity of `stack` is in it.
    on_stack: HashMap<PathBuf, usize>,
    /// Where parses are kept between loads, if anywhere.
    cache: Option<&'a mut ItemCache>,
}

impl<'a> LoadState<'a> {
    fn new(loader: &'a dyn Loader, loaded: Loaded) -> Self {
        let seen = loaded.sources_identities.iter().cloned().collect();
        LoadState { loader, loaded, seen, stack: Vec::new(), on_stack: HashMap::new(), cache: None }
    }

    fn visit(&mut self, path: &Path, identity: PathBuf, bytes: Vec<u8>) -> FileId {
        self.seen.insert(identity.clone());
        self.loaded.sources_identities.push(identity.clone());
        let name = path.display().to_string();
        let text = match String::from_utf8(bytes) {
            Ok(text) => text,
            Err(err) => {
                let at = err.utf8_error().valid_up_to();
                let lossy = String::from_utf8_lossy(err.as_bytes()).into_owned();
                // Point at the first bad byte, in the lossy text's offsets.
                let offset = String::from_utf8_lossy(&err.as_bytes()[..at]).len();
                let id = self.loaded.sources.add(SourceFile::new(name, lossy));
                self.loaded.diagnostics.push(
                    Diagnostic::error(
                        codes::NOT_UTF8,
                        format!("this file is not UTF-8 text (invalid byte at offset {at})"),
                        id,
                        Span::new(offset, offset + '\u{FFFD}'.len_utf8()),
                        "not UTF-8",
                    )
                    .with_help("situ sources are UTF-8; is this the right file?"),
                );
                return id;
            }
        };
        let id = self.loaded.sources.add(SourceFile::new(name, text));
        let text = &self.loaded.sources.get(id).text;
        let parsed = match self.cache.as_deref_mut() {
            Some(cache) => cache.parse(text, id),
            None => situ_grammar::parse(text, id),
        };
        self.loaded.diagnostics.extend(parsed.errors);
        self.on_stack.insert(identity.clone(), self.stack.len());
        self.stack.push((identity, self.loaded.sources.get(id).name.clone()));
        for item in &parsed.file.items {
            if let Item::Include(inc) = item {
                self.include(path, id, &inc.path.value, inc.path.span);
            }
        }
        if let Some((identity, _)) = self.stack.pop() {
            self.on_stack.remove(&identity);
        }
        self.loaded.files.push((id, parsed.file));
        id
    }

    fn include(&mut self, from: &Path, from_id: FileId, target: &str, span: Span) {
        let path = from.parent().unwrap_or(Path::new("")).join(target);
        let identity = match self.loader.identity(&path) {
            Ok(identity) => identity,
            Err(err) => return self.not_found(&path, from_id, span, &err),
        };
        if let Some(&pos) = self.on_stack.get(&identity) {
            // Named as the user wrote them, not by their canonical paths.
            let back = path.display().to_string();
            let cycle: Vec<&str> =
                self.stack[pos..].iter().map(|(_, name)| name.as_str()).chain([back.as_str()]).collect();
            self.loaded.diagnostics.push(
                Diagnostic::error(codes::INCLUDE_CYCLE, "include cycle", from_id, span, "this include closes a cycle")
                    .with_help(format!("the files include each other: {}", cycle.join(" -> ")))
                    .with_witness(serde_json::json!({ "cycle": cycle })),
            );
            return;
        }
        if self.seen.contains(&identity) {
            return; // included before: each file is read once
        }
        if self.stack.len() > MAX_INCLUDE_DEPTH {
            return self.too_deep(&path, from_id, span);
        }
        match self.loader.read(&path) {
            Ok(bytes) => {
                self.visit(&path, identity, bytes);
            }
            Err(err) => self.not_found(&path, from_id, span, &err),
        }
    }

    /// An include one level deeper than [`MAX_INCLUDE_DEPTH`]: the file is not
    /// read, and the help names the chain (its ends, when it is long).
    fn too_deep(&mut self, path: &Path, from_id: FileId, span: Span) {
        let target = path.display().to_string();
        let chain: Vec<&str> = self.stack.iter().map(|(_, name)| name.as_str()).chain([target.as_str()]).collect();
        let brief = if chain.len() > 6 {
            format!("{} -> … -> {}", chain[..3].join(" -> "), chain[chain.len() - 3..].join(" -> "))
        } else {
            chain.join(" -> ")
        };
        self.loaded.diagnostics.push(
            Diagnostic::error(
                codes::INCLUDE_TOO_DEEP,
                format!("include chain too deep: more than {MAX_INCLUDE_DEPTH} files, each included by the previous"),
                from_id,
                span,
                format!("this include would be level {}", self.stack.len()),
            )
            .with_help(format!(
                "the chain is {brief}; include the files from one file higher up instead of each from the previous"
            ))
            .with_witness(serde_json::json!({ "limit": MAX_INCLUDE_DEPTH, "chain": chain })),
        );
    }

    fn not_found(&mut self, path: &Path, from_id: FileId, span: Span, err: &std::io::Error) {
        self.loaded.diagnostics.push(
            Diagnostic::error(
                codes::INCLUDE_NOT_FOUND,
                format!("cannot include `{}`: {err}", path.display()),
                from_id,
                span,
                "included here",
            )
            .with_help("include paths are relative to the file that includes them"),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::loader::MemLoader;

    /// `a0.situ` includes `a1.situ`, which includes `a2.situ`, … up to `a{n-1}`.
    fn chain(n: usize) -> MemLoader {
        (0..n).fold(MemLoader::new(), |l, i| {
            let text = if i + 1 < n { format!("include \"a{}.situ\"\n", i + 1) } else { "states { A initial }".into() };
            l.with(format!("a{i}.situ"), text)
        })
    }

    #[test]
    fn a_chain_at_the_depth_limit_loads_whole() {
        let loaded = load(Path::new("a0.situ"), &chain(MAX_INCLUDE_DEPTH + 1)).unwrap();
        assert!(loaded.diagnostics.is_empty(), "{:?}", loaded.diagnostics);
        assert_eq!(loaded.files.len(), MAX_INCLUDE_DEPTH + 1);
    }

    #[test]
    fn a_chain_past_the_limit_stops_at_the_include_too_deep() {
        let loaded = load(Path::new("a0.situ"), &chain(20_000)).unwrap();
        let codes: Vec<&str> = loaded.diagnostics.iter().map(|d| d.code).collect();
        assert_eq!(codes, [codes::INCLUDE_TOO_DEEP], "one finding, no stack trouble");
        let d = &loaded.diagnostics[0];
        assert_eq!(loaded.sources.get(d.primary.file).name, format!("a{MAX_INCLUDE_DEPTH}.situ"));
        // Only the files up to the limit are read.
        assert_eq!(loaded.files.len(), MAX_INCLUDE_DEPTH + 1);
        let chain = d.witness.as_ref().unwrap()["chain"].as_array().unwrap().len();
        assert_eq!(chain, MAX_INCLUDE_DEPTH + 2);
    }

    #[test]
    fn a_cycle_is_still_a_cycle_and_a_shared_file_is_read_once() {
        let loader = MemLoader::new()
            .with("root.situ", "include \"a.situ\"\ninclude \"b.situ\"\n")
            .with("a.situ", "include \"common.situ\"\n")
            .with("b.situ", "include \"common.situ\"\ninclude \"root.situ\"\n")
            .with("common.situ", "states { A initial }");
        let loaded = load(Path::new("root.situ"), &loader).unwrap();
        let codes: Vec<&str> = loaded.diagnostics.iter().map(|d| d.code).collect();
        assert_eq!(codes, [codes::INCLUDE_CYCLE]);
        assert_eq!(loaded.files.len(), 4, "common.situ once");
    }
}
