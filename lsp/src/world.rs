//! The open documents and what the compiler says of them.
//!
//! Every open document is a root of a compilation; the compiler reads it and
//! its includes through [`DocLoader`], which serves open buffers before the
//! file system. A file is answered for by its *primary* analysis: that of an
//! open file that includes it, if there is one (the names it uses may be
//! declared there), otherwise its own.

use crate::data::Location;
use crate::index::Index;
use crate::runs::Board;
use crate::text::{path_to_uri, LineIndex};
use situ_compiler::loader::{normalize, FsLoader, Loader};
use situ_compiler::Checked;
use situ_grammar::ast;
use situ_grammar::diag::FileId;
use situ_grammar::ItemCache;
use std::collections::{BTreeMap, BTreeSet};
use std::io;
use std::path::{Path, PathBuf};

/// An open document.
#[derive(Debug, Clone)]
pub struct Doc {
    pub uri: String,
    pub text: String,
    pub version: i32,
    pub lines: LineIndex,
}

impl Doc {
    pub fn new(uri: String, text: String, version: i32) -> Doc {
        let lines = LineIndex::new(&text);
        Doc { uri, text, version, lines }
    }
}

/// Reads open documents from memory, every other file from the disk.
pub struct DocLoader<'a> {
    pub docs: &'a BTreeMap<PathBuf, Doc>,
}

impl Loader for DocLoader<'_> {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        match self.docs.get(&normalize(path)) {
            Some(doc) if doc.text.len() as u64 > situ_compiler::loader::MAX_FILE_BYTES => {
                Err(io::Error::new(io::ErrorKind::InvalidData, "larger than the limit for a source file"))
            }
            Some(doc) => Ok(doc.text.clone().into_bytes()),
            None => FsLoader.read(path),
        }
    }

    fn identity(&self, path: &Path) -> io::Result<PathBuf> {
        let path = normalize(path);
        if self.docs.contains_key(&path) {
            return Ok(path);
        }
        Ok(std::fs::canonicalize(&path).unwrap_or(path))
    }
}

/// One compilation: a root and its includes, checked.
#[derive(Debug)]
pub struct Analysis {
    pub root: PathBuf,
    pub checked: Checked,
    /// The AST of every file, by [`FileId`].
    pub asts: Vec<ast::File>,
    /// The path of every file, by [`FileId`].
    pub paths: Vec<PathBuf>,
    /// The URI of every file, by [`FileId`] (an open document's own).
    pub uris: Vec<String>,
    pub lines: Vec<LineIndex>,
    pub index: Index,
    /// Whether the diagnostics are all there are: the static checks ran, or
    /// they would find nothing more (there are errors), or they are skipped.
    pub complete: bool,
    /// The static checks were skipped: the compilation is too large.
    pub skipped: bool,
}

/// Above this many rules, the server does not run the static checks (their
/// searches grow faster than the rules do); `situ check` does.
pub const MAX_RULES_CHECKED: usize = 2_000;

impl Analysis {
    /// `full`: with the static checks; otherwise without them (`check_quick`).
    pub fn new(root: &Path, docs: &BTreeMap<PathBuf, Doc>, full: bool) -> Option<Analysis> {
        Analysis::with_cache(root, docs, full, None)
    }

    /// [`Analysis::new`], the quick check parsing through `cache` when there
    /// is one (only the items an edit touched are parsed again).
    pub fn with_cache(
        root: &Path,
        docs: &BTreeMap<PathBuf, Doc>,
        full: bool,
        cache: Option<&mut ItemCache>,
    ) -> Option<Analysis> {
        let loader = DocLoader { docs };
        let (checked, mut files) = match cache {
            _ if full => (situ_compiler::check(root, &loader).ok()?, Vec::new()),
            Some(cache) => situ_compiler::check_quick_cached(root, &loader, cache).ok()?,
            None => situ_compiler::check_quick(root, &loader).ok()?,
        };
        // The files by id (the quick check gives them in include order).
        files.sort_by_key(|(id, _)| *id);
        let mut parsed = files.into_iter().peekable();
        let mut asts = Vec::with_capacity(checked.sources.len());
        let mut paths = Vec::with_capacity(checked.sources.len());
        let mut lines = Vec::with_capacity(checked.sources.len());
        let mut uris = Vec::with_capacity(checked.sources.len());
        for (id, file) in checked.sources.iter() {
            // A file that is not UTF-8 has no AST: an empty one stands for it.
            let ast = match parsed.peek() {
                Some((pid, _)) if *pid == id => {
                    parsed.next().map(|(_, f)| f).unwrap_or(ast::File { items: Vec::new() })
                }
                _ if full => situ_grammar::parse(&file.text, id).file,
                _ => ast::File { items: Vec::new() },
            };
            asts.push(ast);
            let path = normalize(Path::new(&file.name));
            uris.push(docs.get(&path).map_or_else(|| path_to_uri(&path), |d| d.uri.clone()));
            paths.push(path);
            lines.push(LineIndex::new(&file.text));
        }
        let files: Vec<(FileId, &ast::File)> = asts.iter().enumerate().map(|(i, f)| (FileId(i as u32), f)).collect();
        let index = Index::build(&files);
        let rules = asts.iter().flat_map(|f| &f.items).filter(|i| matches!(i, ast::Item::Rule(_))).count();
        // An error (but a bad `allow`, found after the static checks) means the static checks do not run.
        let errors = checked
            .diagnostics
            .iter()
            .any(|d| d.severity == situ_compiler::Severity::Error && d.code != situ_compiler::codes::BAD_ALLOW);
        let skipped = !full && !errors && rules > MAX_RULES_CHECKED;
        let complete = full || errors || skipped;
        Some(Analysis { root: root.to_path_buf(), checked, asts, paths, uris, lines, index, complete, skipped })
    }

    pub fn file_of(&self, path: &Path) -> Option<FileId> {
        self.paths.iter().position(|p| p == path).map(|i| FileId(i as u32))
    }

    pub fn text(&self, file: FileId) -> &str {
        &self.checked.sources.get(file).text
    }

    pub fn uri(&self, file: FileId) -> String {
        self.uris[file.0 as usize].clone()
    }

    pub fn range(&self, file: FileId, span: ast::Span) -> lsp_types::Range {
        self.lines[file.0 as usize].range(self.text(file), span)
    }

    pub fn location(&self, file: FileId, span: ast::Span) -> Location {
        Location { uri: self.uri(file), range: self.range(file, span) }
    }
}

/// A whole check to run away from the server loop: the root, the
/// generation of its documents, and a copy of them.
#[derive(Debug)]
pub struct Job {
    pub root: PathBuf,
    pub generation: u64,
    pub docs: BTreeMap<PathBuf, Doc>,
}

impl Job {
    pub fn run(&self) -> Option<Analysis> {
        Analysis::new(&self.root, &self.docs, true)
    }
}

/// The documents and their analyses.
#[derive(Debug, Default)]
pub struct World {
    pub docs: BTreeMap<PathBuf, Doc>,
    pub analyses: BTreeMap<PathBuf, Analysis>,
    /// Roots to check again before the next answer.
    dirty: BTreeSet<PathBuf>,
    /// Per root, the generation of its documents: it grows at every change.
    generations: BTreeMap<PathBuf, u64>,
    next_generation: u64,
    /// The verdicts of the properties and tests, run on open and save.
    pub verdicts: Board,
    /// The items' parses of the last quick checks, so that a change parses
    /// again only the items it touched; it keeps the items of the last
    /// [`World::refresh`] only.
    pub parses: ItemCache,
    /// Analyses replaced by newer ones, dropped by [`World::drop_retired`]
    /// once the diagnostics are out (freeing a large program's analysis takes
    /// a while: not between a change and its diagnostics).
    retired: Vec<Analysis>,
}

impl World {
    pub fn open(&mut self, path: PathBuf, doc: Doc) {
        self.docs.insert(path.clone(), doc);
        self.touch(&path);
    }

    /// The document changed: its analysis and those that include it are stale.
    pub fn touch(&mut self, path: &Path) {
        let mut roots = vec![path.to_path_buf()];
        roots.extend(self.analyses.iter().filter(|(_, a)| a.paths.iter().any(|p| p == path)).map(|(r, _)| r.clone()));
        for root in roots {
            self.next_generation += 1;
            self.generations.insert(root.clone(), self.next_generation);
            self.dirty.insert(root);
        }
    }

    pub fn close(&mut self, path: &Path) {
        self.verdicts.forget(path);
        self.docs.remove(path);
        self.analyses.remove(path);
        self.dirty.remove(path);
        // Those that include it read it from the disk now.
        self.touch(path);
        self.dirty.remove(path);
    }

    /// Checks the stale roots again without the static checks; the whole
    /// checks still to run (each on a copy of the documents), or `None` when
    /// nothing was stale.
    pub fn refresh(&mut self) -> Option<Vec<Job>> {
        if self.dirty.is_empty() {
            return None;
        }
        let mut jobs = Vec::new();
        for root in std::mem::take(&mut self.dirty) {
            if !self.docs.contains_key(&root) {
                self.analyses.remove(&root);
                continue;
            }
            match Analysis::with_cache(&root, &self.docs, false, Some(&mut self.parses)) {
                Some(a) => {
                    if !a.complete {
                        let generation = self.generations.get(&root).copied().unwrap_or(0);
                        jobs.push(Job { root: root.clone(), generation, docs: self.docs.clone() });
                    }
                    self.retired.extend(self.analyses.insert(root, a));
                }
                None => {
                    self.analyses.remove(&root);
                }
            }
        }
        self.parses.end_round();
        Some(jobs)
    }

    /// The generation of the documents of `root` (it grows at every change).
    pub fn generation(&self, root: &Path) -> u64 {
        self.generations.get(root).copied().unwrap_or(0)
    }

    /// A whole check is done: kept if no change came since its job.
    pub fn accept(&mut self, root: PathBuf, generation: u64, analysis: Analysis) -> bool {
        let current = self.generations.get(&root).copied().unwrap_or(0);
        if current != generation || !self.docs.contains_key(&root) || self.dirty.contains(&root) {
            return false;
        }
        self.retired.extend(self.analyses.insert(root, analysis));
        true
    }

    /// Drops the analyses that newer ones replaced.
    pub fn drop_retired(&mut self) {
        self.retired.clear();
    }

    /// Checks everything stale, the static checks included, here and now.
    pub fn refresh_fully(&mut self) {
        for job in self.refresh().unwrap_or_default() {
            if let Some(a) = job.run() {
                self.accept(job.root.clone(), job.generation, a);
            }
        }
        self.drop_retired();
    }

    /// The analysis that answers for `path`, and the file's id in it.
    pub fn primary(&self, path: &Path) -> Option<(&Analysis, FileId)> {
        let includer = self.analyses.iter().find(|(root, a)| root.as_path() != path && a.file_of(path).is_some());
        let a = includer.map(|(_, a)| a).or_else(|| self.analyses.get(path))?;
        Some((a, a.file_of(path)?))
    }

    /// Every file some analysis covers.
    pub fn covered(&self) -> BTreeSet<PathBuf> {
        self.analyses.values().flat_map(|a| a.paths.iter().cloned()).collect()
    }
}

/// A world with one open document, checked in full, for the features' tests.
#[cfg(test)]
pub fn world_of(name: &str, text: &str) -> (World, PathBuf) {
    let path = PathBuf::from(format!("/nonexistent/situ-lsp/{name}.situ"));
    let mut w = World::default();
    w.open(path.clone(), Doc::new(path_to_uri(&path), text.into(), 1));
    w.refresh_fully();
    (w, path)
}

/// A small program for the features' tests: a comment, a table without a row
/// for `RD` (W0311), an event nobody reads (`F`, W0308).
#[cfg(test)]
pub const SMALL: &str = "// a\n// b\nstates { IT initial RD final }\nagent A sensor {\n    event E\n    event F\n    function f\n    table {\n        IT => run f()\n    }\n}\nrule r { when state == IT and E then RD }\n";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_whole_check_overtaken_by_an_edit_is_dropped() {
        let path = PathBuf::from("/tmp/situ-lsp-generations.situ");
        let text = "states { IT initial RD final }\nagent A sensor { event E event F }\nrule r { when state == IT and E then RD }";
        let mut w = World::default();
        w.open(path.clone(), Doc::new(path_to_uri(&path), text.into(), 1));
        let jobs = w.refresh().unwrap();
        assert_eq!(jobs.len(), 1, "no error: the static checks are still to run");
        assert!(!w.analyses[&path].complete);
        let late = jobs[0].run().unwrap();
        w.touch(&path); // an edit comes first
        assert!(!w.accept(path.clone(), jobs[0].generation, late));
        let jobs = w.refresh().unwrap();
        let fresh = jobs[0].run().unwrap();
        assert!(w.accept(path.clone(), jobs[0].generation, fresh));
        let a = &w.analyses[&path];
        assert!(a.complete);
        assert!(a.checked.diagnostics.iter().any(|d| d.code == "W0308"), "F is never read");
    }

    #[test]
    fn an_included_file_is_answered_for_by_its_includer() {
        let dir = std::env::temp_dir().join(format!("situ-lsp-world-{}", std::process::id()));
        let main = dir.join("main.situ");
        let common = dir.join("common.situ");
        let mut w = World::default();
        w.open(
            main.clone(),
            Doc::new(path_to_uri(&main), "include \"common.situ\"\nrule r { when E then B }".into(), 1),
        );
        w.open(
            common.clone(),
            Doc::new(path_to_uri(&common), "states { A initial B }\nagent X sensor { event E }".into(), 1),
        );
        assert!(w.refresh().is_some());
        assert!(w.refresh().is_none());
        let (a, file) = w.primary(&common).unwrap();
        assert_eq!(a.root, main);
        assert_eq!(a.paths[file.0 as usize], common);
        assert!(a.checked.errors() == 0, "{:?}", a.checked.diagnostics);
        // An edit of the included file checks the includer again.
        w.docs.get_mut(&common).unwrap().text = "states { A initial }\nagent X sensor { event E }".into();
        w.touch(&common);
        w.refresh_fully();
        let (a, _) = w.primary(&main).unwrap();
        assert_eq!(a.checked.errors(), 1);
        w.close(&main);
        w.refresh_fully();
        assert_eq!(w.primary(&common).unwrap().0.root, common);
        assert!(w.primary(&main).is_none());
    }

    #[test]
    fn a_change_parses_again_the_item_it_touched_only() {
        let path = PathBuf::from("/nonexistent/situ-lsp/cache.situ");
        let mut w = World::default();
        w.open(path.clone(), Doc::new(path_to_uri(&path), SMALL.into(), 1));
        w.refresh();
        let parsed = w.parses.misses();
        assert_eq!(parsed, 3, "states, agent, rule");
        // The event's name grows: the rule after it moves, and is not parsed again.
        let edited = SMALL.replace("event E\n", "event EV\n");
        w.docs.get_mut(&path).unwrap().text = edited.clone();
        w.touch(&path);
        w.refresh();
        assert_eq!(w.parses.misses(), parsed + 1);
        assert_eq!(w.parses.len(), 3, "the agent's old parse is dropped");
        let cached = &w.analyses[&path];
        let fresh = Analysis::new(&path, &w.docs, false).unwrap();
        assert_eq!(cached.asts, fresh.asts);
        assert_eq!(cached.checked.diagnostics, fresh.checked.diagnostics);
        assert!(cached.checked.diagnostics.iter().any(|d| d.code == "E0104"), "E is undefined now");
    }
}
