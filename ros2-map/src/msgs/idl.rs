//! The parser of ROS 2 interface definitions: `.msg`, `.srv` and `.action`
//! files as `rosidl_adapter` reads them.
//!
//! A line is a comment (`# …`), blank, a field `TYPE name [default]` or a
//! constant `TYPE NAME=value`. A type is a primitive (`bool byte char int8 …
//! uint64 float32 float64 string wstring`, `string<=N`), a message (`Name` of
//! the same package or `pkg/Name`), and an optional array suffix: `[]`
//! unbounded, `[N]` fixed, `[<=N]` bounded. A `.srv` is a request, `---`, a
//! response; an `.action` a goal, `---`, a result, `---`, a feedback.
//! Every error is an [`IdlError`] with its line; nothing here panics.

use std::fmt;

/// A primitive type, as written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Prim {
    Bool,
    Byte,
    Char,
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
    /// `string` or `string<=N`.
    String(Option<usize>),
    /// `wstring` or `wstring<=N`.
    WString(Option<usize>),
}

const NAMES: [(&str, Prim); 13] = [
    ("bool", Prim::Bool),
    ("byte", Prim::Byte),
    ("char", Prim::Char),
    ("int8", Prim::I8),
    ("uint8", Prim::U8),
    ("int16", Prim::I16),
    ("uint16", Prim::U16),
    ("int32", Prim::I32),
    ("uint32", Prim::U32),
    ("int64", Prim::I64),
    ("uint64", Prim::U64),
    ("float32", Prim::F32),
    ("float64", Prim::F64),
];

impl Prim {
    /// The primitive named `name` (`string<=10` included), if it is one.
    pub fn of(name: &str) -> Result<Option<Prim>, String> {
        if let Some(p) = NAMES.iter().find(|(n, _)| *n == name).map(|(_, p)| *p) {
            return Ok(Some(p));
        }
        for (word, wide) in [("string", false), ("wstring", true)] {
            let Some(rest) = name.strip_prefix(word) else { continue };
            let bound = match rest {
                "" => None,
                r => match r.strip_prefix("<=").map(str::parse::<usize>) {
                    Some(Ok(n)) if n > 0 => Some(n),
                    _ => return Err(format!("`{name}`: a bounded string is `{word}<=N` with N > 0")),
                },
            };
            return Ok(Some(if wide { Prim::WString(bound) } else { Prim::String(bound) }));
        }
        Ok(None)
    }

    /// Whether it is an integer type (`byte` and `char` included).
    pub fn is_int(self) -> bool {
        !matches!(self, Prim::Bool | Prim::F32 | Prim::F64 | Prim::String(_) | Prim::WString(_))
    }

    pub fn is_float(self) -> bool {
        matches!(self, Prim::F32 | Prim::F64)
    }

    pub fn is_string(self) -> bool {
        matches!(self, Prim::String(_) | Prim::WString(_))
    }

    /// The range of an integer type, as `i128`.
    fn int_range(self) -> Option<(i128, i128)> {
        Some(match self {
            Prim::I8 => (i8::MIN.into(), i8::MAX.into()),
            Prim::Byte | Prim::Char | Prim::U8 => (0, u8::MAX.into()),
            Prim::I16 => (i16::MIN.into(), i16::MAX.into()),
            Prim::U16 => (0, u16::MAX.into()),
            Prim::I32 => (i32::MIN.into(), i32::MAX.into()),
            Prim::U32 => (0, u32::MAX.into()),
            Prim::I64 => (i64::MIN.into(), i64::MAX.into()),
            Prim::U64 => (0, u64::MAX.into()),
            _ => return None,
        })
    }
}

impl fmt::Display for Prim {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Prim::String(None) => write!(f, "string"),
            Prim::String(Some(n)) => write!(f, "string<={n}"),
            Prim::WString(None) => write!(f, "wstring"),
            Prim::WString(Some(n)) => write!(f, "wstring<={n}"),
            p => write!(f, "{}", NAMES.iter().find(|(_, q)| q == p).map_or("?", |(n, _)| n)),
        }
    }
}

/// The element type of a field.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Base {
    Prim(Prim),
    /// A message, by its full name (`geometry_msgs/msg/Pose`).
    Msg(String),
}

/// Whether a field is an array, and of which kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Array {
    Not,
    /// `T[]`.
    Unbounded,
    /// `T[N]`.
    Fixed(usize),
    /// `T[<=N]`.
    Bounded(usize),
}

/// The type of a field.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TypeRef {
    pub base: Base,
    pub array: Array,
}

/// One field of a message.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    pub name: String,
    pub ty: TypeRef,
    /// The default value as written, if any.
    pub default: Option<String>,
    /// Its line in the file (1-based).
    pub line: usize,
}

/// The value of a constant.
#[derive(Debug, Clone, PartialEq)]
pub enum ConstValue {
    Bool(bool),
    /// Every integer type (a `uint64` above `i64::MAX` is a float).
    Int(i64),
    Float(f64),
    Str(String),
}

/// One constant of a message (`uint8 POWER_SUPPLY_STATUS_CHARGING = 1`).
#[derive(Debug, Clone, PartialEq)]
pub struct Constant {
    pub name: String,
    pub ty: Prim,
    pub value: ConstValue,
    pub line: usize,
}

/// One message definition: a `.msg` file, or a part of a `.srv`/`.action`.
#[derive(Debug, Clone, PartialEq)]
pub struct MsgDef {
    /// Its full name (`sensor_msgs/msg/JointState`, `pkg/action/Name_Goal`).
    pub name: String,
    pub fields: Vec<Field>,
    pub constants: Vec<Constant>,
    /// Its text as written (the schema a bag records).
    pub text: String,
}

impl MsgDef {
    /// The package of the message.
    pub fn package(&self) -> &str {
        self.name.split('/').next().unwrap_or("")
    }

    /// The field `name`.
    pub fn field(&self, name: &str) -> Option<&Field> {
        self.fields.iter().find(|f| f.name == name)
    }

    /// The constant `name`.
    pub fn constant(&self, name: &str) -> Option<&Constant> {
        self.constants.iter().find(|c| c.name == name)
    }
}

/// A definition that does not parse: where and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IdlError {
    /// The file, as given to the parser (a path, or `carried:pkg/msg/X.msg`).
    pub file: String,
    /// 1-based; 0 for the whole file.
    pub line: usize,
    pub message: String,
}

impl fmt::Display for IdlError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line == 0 {
            write!(f, "{}: {}", self.file, self.message)
        } else {
            write!(f, "{}:{}: {}", self.file, self.line, self.message)
        }
    }
}

impl std::error::Error for IdlError {}

/// The kind of a definition file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Msg,
    Srv,
    Action,
}

impl Kind {
    /// The kind of a file by its extension (`msg`, `srv`, `action`).
    pub fn of_extension(ext: &str) -> Option<Kind> {
        match ext {
            "msg" => Some(Kind::Msg),
            "srv" => Some(Kind::Srv),
            "action" => Some(Kind::Action),
            _ => None,
        }
    }

    /// The folder of the kind in a package (`msg`, `srv`, `action`).
    pub fn folder(self) -> &'static str {
        match self {
            Kind::Msg => "msg",
            Kind::Srv => "srv",
            Kind::Action => "action",
        }
    }
}

/// Parses the file `text` of package `pkg` defining `name` (the file's
/// stem) of `kind`: one message for a `.msg`; `Name_Request` and
/// `Name_Response` for a `.srv`; `Name_Goal`, `Name_Result`,
/// `Name_Feedback` and `Name_FeedbackMessage` for an `.action`. `file` names
/// the file in errors.
pub fn parse_file(file: &str, pkg: &str, name: &str, kind: Kind, text: &str) -> Result<Vec<MsgDef>, IdlError> {
    let err = |line: usize, message: String| IdlError { file: file.to_string(), line, message };
    if !is_type_name(name) {
        return Err(err(0, format!("`{name}` is not a type name (an upper-case letter, then letters and digits)")));
    }
    if !is_package_name(pkg) {
        return Err(err(0, format!("`{pkg}` is not a package name (lower case letters, digits and `_`)")));
    }
    let parts = split_parts(text);
    let names: Vec<String> = match kind {
        Kind::Msg => vec![name.to_string()],
        Kind::Srv => vec![format!("{name}_Request"), format!("{name}_Response")],
        Kind::Action => vec![format!("{name}_Goal"), format!("{name}_Result"), format!("{name}_Feedback")],
    };
    if parts.len() != names.len() {
        let want = names.len() - 1;
        return Err(err(
            parts.last().map_or(0, |p| p.0),
            format!(
                "a .{} has {want} `---` separator{}, this one has {}",
                kind.folder(),
                plural(want),
                parts.len() - 1
            ),
        ));
    }
    let mut out = Vec::new();
    for ((first, lines), n) in parts.into_iter().zip(&names) {
        let full = format!("{pkg}/{}/{n}", kind.folder());
        out.push(parse_msg(file, pkg, &full, first, &lines)?);
    }
    if kind == Kind::Action {
        let full = format!("{pkg}/action/{name}_FeedbackMessage");
        let text = format!("unique_identifier_msgs/UUID goal_id\n{name}_Feedback feedback\n");
        let feedback = Base::Msg(format!("{pkg}/action/{name}_Feedback"));
        let uuid = Base::Msg("unique_identifier_msgs/msg/UUID".into());
        let field = |name: &str, base| Field {
            name: name.into(),
            ty: TypeRef { base, array: Array::Not },
            default: None,
            line: 0,
        };
        out.push(MsgDef {
            name: full,
            fields: vec![field("goal_id", uuid), field("feedback", feedback)],
            constants: Vec::new(),
            text,
        });
    }
    Ok(out)
}

fn plural(n: usize) -> &'static str {
    if n == 1 {
        ""
    } else {
        "s"
    }
}

/// The parts of a file between `---` lines: the line of each part's
/// first line and its lines.
fn split_parts(text: &str) -> Vec<(usize, Vec<&str>)> {
    let mut parts = vec![(1, Vec::new())];
    for (i, line) in text.lines().enumerate() {
        if line.trim() == "---" {
            parts.push((i + 2, Vec::new()));
        } else if let Some(last) = parts.last_mut() {
            last.1.push(line);
        }
    }
    parts
}

/// A message name: an upper-case letter, then letters and digits.
fn is_type_name(s: &str) -> bool {
    s.starts_with(|c: char| c.is_ascii_uppercase()) && s.chars().all(|c| c.is_ascii_alphanumeric())
}

fn is_package_name(s: &str) -> bool {
    s.starts_with(|c: char| c.is_ascii_lowercase())
        && s.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
}

fn is_field_name(s: &str) -> bool {
    s.starts_with(|c: char| c.is_ascii_lowercase())
        && s.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
        && !s.ends_with('_')
        && !s.contains("__")
}

fn is_constant_name(s: &str) -> bool {
    s.starts_with(|c: char| c.is_ascii_uppercase())
        && s.chars().all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_')
}

/// One message: `lines` start at line `first` of `file`.
fn parse_msg(file: &str, pkg: &str, full: &str, first: usize, lines: &[&str]) -> Result<MsgDef, IdlError> {
    let mut def = MsgDef { name: full.to_string(), fields: Vec::new(), constants: Vec::new(), text: String::new() };
    let mut text = lines.join("\n");
    if !text.is_empty() {
        text.push('\n');
    }
    def.text = text;
    for (i, raw) in lines.iter().enumerate() {
        let line = first + i;
        let err = |message: String| IdlError { file: file.to_string(), line, message };
        let body = raw.trim();
        if body.is_empty() || body.starts_with('#') {
            continue;
        }
        let (ty, rest) = split_word(body);
        let rest = rest.trim_start();
        if rest.is_empty() || rest.starts_with('#') {
            return Err(err(format!("`{ty}` has no name: a field is `TYPE name`, a constant `TYPE NAME=value`")));
        }
        let name_end = rest.find(|c: char| c.is_whitespace() || c == '=' || c == '#').unwrap_or(rest.len());
        let (name, after) = rest.split_at(name_end);
        let after = after.trim_start();
        let ty = parse_type(ty, pkg).map_err(err)?;
        let seen = |n: &str| def.fields.iter().any(|f| f.name == n) || def.constants.iter().any(|c| c.name == n);
        if seen(name) {
            return Err(err(format!("`{name}` is defined twice")));
        }
        if let Some(value) = after.strip_prefix('=') {
            let prim = match (&ty.base, ty.array) {
                (Base::Prim(p), Array::Not) => *p,
                _ => {
                    return Err(err(format!(
                        "constant `{name}`: a constant is of a primitive type, not an array or a message"
                    )))
                }
            };
            if !is_constant_name(name) {
                return Err(err(format!("`{name}` is not a constant name (upper case letters, digits and `_`)")));
            }
            let value = constant(prim, value.trim_start()).map_err(|m| err(format!("constant `{name}`: {m}")))?;
            def.constants.push(Constant { name: name.to_string(), ty: prim, value, line });
        } else {
            if !is_field_name(name) {
                return Err(err(format!(
                    "`{name}` is not a field name (lower case letters, digits and `_`, no `__` and no `_` at the end)"
                )));
            }
            let default = strip_comment(after).trim();
            let default = (!default.is_empty()).then(|| default.to_string());
            def.fields.push(Field { name: name.to_string(), ty, default, line });
        }
    }
    Ok(def)
}

/// The first word of a line (up to a blank or a `#`), and the rest.
fn split_word(s: &str) -> (&str, &str) {
    let end = s.find(|c: char| c.is_whitespace() || c == '#').unwrap_or(s.len());
    s.split_at(end)
}

/// The text before a `#` that is not inside quotes.
fn strip_comment(s: &str) -> &str {
    let mut quote = None;
    for (i, c) in s.char_indices() {
        match (quote, c) {
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), c) if c == q => quote = None,
            (None, '#') => return &s[..i],
            _ => {}
        }
    }
    s
}

/// The type written `ty` in package `pkg`.
pub fn parse_type(ty: &str, pkg: &str) -> Result<TypeRef, String> {
    let (elem, array) = match ty.find('[') {
        None => (ty, Array::Not),
        Some(at) => {
            let (elem, suffix) = ty.split_at(at);
            let inner = suffix
                .strip_prefix('[')
                .and_then(|s| s.strip_suffix(']'))
                .ok_or_else(|| format!("`{ty}`: an array is `T[]`, `T[N]` or `T[<=N]`"))?;
            let size = |s: &str| match s.parse::<usize>() {
                Ok(n) if n > 0 => Ok(n),
                _ => Err(format!("`{ty}`: the size of an array is a whole number above 0")),
            };
            let array = match inner {
                "" => Array::Unbounded,
                s => match s.strip_prefix("<=") {
                    Some(n) => Array::Bounded(size(n)?),
                    None => Array::Fixed(size(s)?),
                },
            };
            (elem, array)
        }
    };
    let base = match Prim::of(elem)? {
        Some(p) => Base::Prim(p),
        None => Base::Msg(message_name(elem, pkg)?),
    };
    Ok(TypeRef { base, array })
}

/// The full name of a message type written `ty` in package `pkg`: `Name`
/// (same package), `pkg/Name` or `pkg/msg/Name`.
fn message_name(ty: &str, pkg: &str) -> Result<String, String> {
    let parts: Vec<&str> = ty.split('/').collect();
    let bad = || format!("`{ty}` is not a type: a primitive, `Name`, `package/Name` or `package/msg/Name`");
    match parts.as_slice() {
        [n] if is_type_name(n) => Ok(format!("{pkg}/msg/{n}")),
        [p, n] if is_package_name(p) && is_type_name(n) => Ok(format!("{p}/msg/{n}")),
        [p, "msg", n] if is_package_name(p) && is_type_name(n) => Ok(ty.to_string()),
        _ => Err(bad()),
    }
}

/// The value of a constant of type `prim` written `text` (a comment may follow).
fn constant(prim: Prim, text: &str) -> Result<ConstValue, String> {
    if prim.is_string() {
        let t = text.trim();
        for q in ['"', '\''] {
            if let Some(body) = t.strip_prefix(q) {
                let Some(end) = body.find(q) else { return Err(format!("the string {t} is not closed")) };
                let after = body[end + 1..].trim();
                if !after.is_empty() && !after.starts_with('#') {
                    return Err(format!("`{after}` after the string"));
                }
                return Ok(ConstValue::Str(body[..end].to_string()));
            }
        }
        // Unquoted: the whole rest of the line, as rosidl reads it.
        return Ok(ConstValue::Str(t.to_string()));
    }
    let t = strip_comment(text).trim();
    if t.is_empty() {
        return Err("no value after `=`".into());
    }
    match prim {
        Prim::Bool => match t {
            "true" | "True" | "1" => Ok(ConstValue::Bool(true)),
            "false" | "False" | "0" => Ok(ConstValue::Bool(false)),
            _ => Err(format!("`{t}` is not a bool (true or false)")),
        },
        Prim::F32 | Prim::F64 => t.parse::<f64>().map(ConstValue::Float).map_err(|_| format!("`{t}` is not a number")),
        p => {
            let (lo, hi) = p.int_range().ok_or_else(|| format!("a constant of type {p}"))?;
            let v = parse_int(t).ok_or_else(|| format!("`{t}` is not an integer"))?;
            if v < lo || v > hi {
                return Err(format!("{v} is out of the range of {p} ({lo} to {hi})"));
            }
            Ok(i64::try_from(v).map_or(ConstValue::Float(v as f64), ConstValue::Int))
        }
    }
}

fn parse_int(t: &str) -> Option<i128> {
    let (neg, digits) = match t.strip_prefix('-') {
        Some(d) => (true, d),
        None => (false, t.strip_prefix('+').unwrap_or(t)),
    };
    let v = match digits.get(..2) {
        Some("0x" | "0X") => i128::from_str_radix(&digits[2..], 16).ok()?,
        Some("0b" | "0B") => i128::from_str_radix(&digits[2..], 2).ok()?,
        Some("0o" | "0O") => i128::from_str_radix(&digits[2..], 8).ok()?,
        _ => digits.parse::<i128>().ok()?,
    };
    Some(if neg { -v } else { v })
}

#[cfg(test)]
#[path = "idl_tests.rs"]
mod tests;
