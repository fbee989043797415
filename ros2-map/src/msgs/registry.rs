//! The loaded set of message definitions ([`Registry`]) and its lookups.
//! One registry serves the checks, the typing of expressions, the CDR
//! decoder, the evaluator and the bridge; it is cheap to clone.

use super::idl::{self, Array, Base, Constant, IdlError, MsgDef};
use super::search::{self, SearchPath};
use super::{full_name, intern, FieldType, Prim};
use std::collections::{BTreeMap, BTreeSet};
use std::sync::{Arc, OnceLock};

/// The message definitions situ knows, from one [`SearchPath`].
#[derive(Debug, Clone)]
pub struct Registry {
    inner: Arc<Inner>,
}

#[derive(Debug)]
struct Inner {
    /// Every package, from the first place of the search path that has it.
    packages: BTreeMap<String, Package>,
    search: SearchPath,
}

/// The types of a package by full name: a definition, or why it has none.
type Types = BTreeMap<String, Result<Arc<MsgDef>, IdlError>>;

/// One package: its files, read and parsed the first time one of its types
/// is looked up.
#[derive(Debug)]
struct Package {
    place: String,
    files: Vec<search::Found>,
    types: OnceLock<Types>,
}

impl Package {
    fn types(&self) -> &Types {
        self.types.get_or_init(|| {
            let mut types = Types::new();
            for f in &self.files {
                let parsed = match f.text() {
                    Ok(text) => idl::parse_file(&f.file, &f.package, &f.name, f.kind, &text),
                    Err(e) => Err(IdlError { file: f.file.clone(), line: 0, message: e }),
                };
                match parsed {
                    Ok(defs) => {
                        for d in defs {
                            types.insert(d.name.clone(), Ok(Arc::new(d)));
                        }
                    }
                    Err(e) => {
                        // The types the file would define, so that naming one says why it is missing.
                        let base = format!("{}/{}/{}", f.package, f.kind.folder(), f.name);
                        let names: Vec<String> = match f.kind {
                            idl::Kind::Msg => vec![base],
                            idl::Kind::Srv => vec![format!("{base}_Request"), format!("{base}_Response")],
                            idl::Kind::Action => ["_Goal", "_Result", "_Feedback", "_FeedbackMessage"]
                                .iter()
                                .map(|s| format!("{base}{s}"))
                                .collect(),
                        };
                        for n in names {
                            types.insert(n, Err(e.clone()));
                        }
                    }
                }
            }
            types
        })
    }
}

/// Why a type named by the map cannot be used.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum TypeError {
    /// Not `package/msg/Name` nor `package/Name`.
    Malformed,
    /// No place of the search path has the package.
    UnknownPackage { package: String },
    /// The package is known, the type is not in it.
    UnknownType { package: String, known: Vec<String> },
    /// Its definition, or the definition of a type it uses, does not parse
    /// or names a type that cannot be found.
    Broken(IdlError),
}

impl Registry {
    /// The definitions situ carries, loaded once per process.
    pub fn carried() -> Registry {
        static CARRIED: OnceLock<Registry> = OnceLock::new();
        CARRIED.get_or_init(|| Registry::load(&SearchPath::carried())).clone()
    }

    /// The definitions of `search`, the first place of a package winning.
    /// Only the folders are listed here; a package's files are read and
    /// parsed when one of its types is first looked up, and the files that
    /// do not read or parse are kept as errors of their types.
    pub fn load(search: &SearchPath) -> Registry {
        let mut packages = BTreeMap::new();
        for place in &search.places {
            for (package, files) in search::packages(place) {
                packages.entry(package).or_insert_with(|| Package {
                    place: place.to_string(),
                    files,
                    types: OnceLock::new(),
                });
            }
        }
        Registry { inner: Arc::new(Inner { packages, search: search.clone() }) }
    }

    /// The entry of a type by its full name, its package loaded.
    fn entry(&self, full: &str) -> Option<&Result<Arc<MsgDef>, IdlError>> {
        let package = full.split('/').next()?;
        self.inner.packages.get(package)?.types().get(full)
    }

    /// The search path it was loaded from.
    pub fn search_path(&self) -> &SearchPath {
        &self.inner.search
    }

    /// The definition of a type (`pkg/msg/Name`, `pkg/Name`, or a full
    /// name of a service or action part), if it parsed.
    pub fn def(&self, name: &str) -> Option<&MsgDef> {
        let full = if name.split('/').count() == 3 { name.to_string() } else { full_name(name)? };
        self.entry(&full)?.as_ref().ok().map(|d| &**d)
    }

    /// The full name of a type whose definition and every definition it
    /// uses load, or why not.
    pub fn resolve(&self, name: &str) -> Result<&'static str, TypeError> {
        let full = if name.split('/').count() == 3 && !name.contains("//") {
            name.to_string()
        } else {
            full_name(name).ok_or(TypeError::Malformed)?
        };
        if self.entry(&full).is_none() {
            let package = full.split('/').next().unwrap_or("").to_string();
            if !self.inner.packages.contains_key(&package) {
                return Err(TypeError::UnknownPackage { package });
            }
            let known = self.package_types(&package);
            return Err(TypeError::UnknownType { package, known });
        }
        let mut seen = BTreeSet::new();
        self.check_deps(&full, &mut seen).map_err(TypeError::Broken)?;
        Ok(intern(&full))
    }

    fn check_deps(&self, full: &str, seen: &mut BTreeSet<String>) -> Result<(), IdlError> {
        if !seen.insert(full.to_string()) {
            return Ok(());
        }
        let def = match self.entry(full) {
            Some(Ok(d)) => d.clone(),
            Some(Err(e)) => return Err(e.clone()),
            None => return Ok(()),
        };
        for f in &def.fields {
            let Base::Msg(dep) = &f.ty.base else { continue };
            match self.entry(dep) {
                Some(_) => self.check_deps(dep, seen)?,
                None => {
                    let file = self.file_of(full);
                    return Err(IdlError {
                        file,
                        line: f.line,
                        message: format!("field `{}` of `{full}` is of type `{dep}`, which is not found", f.name),
                    });
                }
            }
        }
        Ok(())
    }

    /// The file a type was loaded from, as errors name it.
    fn file_of(&self, full: &str) -> String {
        let package = full.split('/').next().unwrap_or("");
        let place = self.inner.packages.get(package).map_or("?", |p| p.place.as_str());
        format!("{full} (from {place})")
    }

    /// The full name of a type that resolves (see [`Registry::resolve`]).
    pub fn lookup(&self, name: &str) -> Option<&'static str> {
        self.resolve(name).ok()
    }

    /// Every type that parsed, by full name (every package is read).
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.inner.packages.values().flat_map(|p| p.types().iter()).filter(|(_, d)| d.is_ok()).map(|(n, _)| n.as_str())
    }

    /// Every known package and the place it comes from.
    pub fn packages(&self) -> impl Iterator<Item = (&str, &str)> {
        self.inner.packages.iter().map(|(n, p)| (n.as_str(), p.place.as_str()))
    }

    /// The short names of the messages of `package` (`msg` only), sorted.
    pub fn package_types(&self, package: &str) -> Vec<String> {
        let prefix = format!("{package}/msg/");
        let Some(p) = self.inner.packages.get(package) else { return Vec::new() };
        p.types().keys().filter_map(|n| n.strip_prefix(&prefix)).map(str::to_string).collect()
    }

    /// The fields of a message, in order, with their types as expressions see them.
    pub fn fields(&self, msg: &str) -> Vec<(&'static str, FieldType)> {
        let Some(def) = self.def(msg) else { return Vec::new() };
        def.fields.iter().map(|f| (intern(&f.name), field_type(&f.ty))).collect()
    }

    /// The type of one field of a message, if it has that field.
    pub fn field(&self, msg: &str, name: &str) -> Option<FieldType> {
        self.def(msg)?.field(name).map(|f| field_type(&f.ty))
    }

    /// The constants of a message.
    pub fn constants(&self, msg: &str) -> &[Constant] {
        self.def(msg).map_or(&[], |d| d.constants.as_slice())
    }

    /// The constant `name` of a message.
    pub fn constant(&self, msg: &str, name: &str) -> Option<&Constant> {
        self.def(msg)?.constant(name)
    }

    /// The constant a field path names on message `msg`, if it names one
    /// and is not a field: `NAME`, a constant of `msg`; or `Type.NAME`, a
    /// constant of the message whose short name is `Type`, when `Type` is
    /// `msg` or the type of one of its fields, at any depth.
    pub fn path_constant(&self, msg: &str, path: &[&str]) -> Option<&Constant> {
        let root = self.def(msg)?;
        match path {
            [name] if root.field(name).is_none() => root.constant(name),
            [ty, name] if root.field(ty).is_none() => self.reachable(msg, ty).iter().find_map(|d| d.constant(name)),
            _ => None,
        }
    }

    /// The messages whose short name is `short` among `msg` and the types
    /// of its fields, at any depth.
    pub fn reachable(&self, msg: &str, short: &str) -> Vec<&MsgDef> {
        let mut out = Vec::new();
        let Some(root) = self.def(msg) else { return out };
        let mut queue = vec![root.name.clone()];
        let mut seen = BTreeSet::new();
        while let Some(t) = queue.pop() {
            if !seen.insert(t.clone()) {
                continue;
            }
            let Some(def) = self.def(&t) else { continue };
            if t.rsplit('/').next() == Some(short) {
                out.push(def);
            }
            queue.extend(deps(def));
        }
        out
    }

    /// The `ros2msg` schema of a type as rosbag2 records it: its text, then
    /// the text of every type it uses (depth first, each once), each after
    /// a line of 80 `=` and `MSG: package/msg/Name`.
    pub fn schema(&self, name: &str) -> Option<String> {
        let def = self.def(name)?;
        let mut out = def.text.clone();
        let mut seen = BTreeSet::from([def.name.clone()]);
        let mut stack: Vec<String> = deps(def).into_iter().rev().collect();
        while let Some(dep) = stack.pop() {
            if !seen.insert(dep.clone()) {
                continue;
            }
            let Some(d) = self.def(&dep) else { continue };
            if !out.ends_with('\n') {
                out.push('\n');
            }
            out.push_str(&format!("{}\nMSG: {dep}\n{}", "=".repeat(80), d.text));
            stack.extend(deps(d).into_iter().rev());
        }
        Some(out)
    }
}

/// The message types a definition's fields use, in order, each once.
fn deps(def: &MsgDef) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for f in &def.fields {
        if let Base::Msg(m) = &f.ty.base {
            if !out.contains(m) {
                out.push(m.clone());
            }
        }
    }
    out
}

/// The type of a field as expressions see it.
pub fn field_type(t: &idl::TypeRef) -> FieldType {
    let elem = match &t.base {
        Base::Prim(p) if p.is_int() => FieldType::Prim(Prim::Int),
        Base::Prim(p) if p.is_float() => FieldType::Prim(Prim::Float),
        Base::Prim(p) if p.is_string() => FieldType::Prim(Prim::String),
        Base::Prim(_) => FieldType::Prim(Prim::Bool),
        Base::Msg(m) => FieldType::Msg(intern(m)),
    };
    match t.array {
        Array::Not => elem,
        Array::Fixed(n) => FieldType::Array(Box::new(elem), Some(n)),
        Array::Unbounded | Array::Bounded(_) => FieldType::Array(Box::new(elem), None),
    }
}

#[cfg(test)]
#[path = "registry_tests.rs"]
mod tests;
