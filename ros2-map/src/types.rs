//! Types of map expressions against a message: every field path (or
//! constant) is looked up in the registry of message definitions, every
//! operator checked. The findings are sorted by kind so that each check of
//! [`crate::check`] reports its own.

use crate::expr::{self, BinOp, Expr, Reducer, Step};
use crate::map::Str;
use crate::msgs::idl::{self, ConstValue};
use crate::msgs::{FieldType, Prim, Registry};
use situ_compiler::codes;
use situ_compiler::suggest::suggest;
use situ_grammar::diag::{Diagnostic, FileId};

/// The type of a value of an expression.
#[derive(Debug, Clone, PartialEq)]
pub enum Ty {
    Int,
    Float,
    Bool,
    Str,
    Msg(&'static str),
    Array(FieldType, Option<usize>),
}

impl Ty {
    pub fn is_numeric(&self) -> bool {
        matches!(self, Ty::Int | Ty::Float)
    }

    fn of(t: &FieldType) -> Ty {
        match t {
            FieldType::Prim(Prim::Bool) => Ty::Bool,
            FieldType::Prim(Prim::Int) => Ty::Int,
            FieldType::Prim(Prim::Float) => Ty::Float,
            FieldType::Prim(Prim::String) => Ty::Str,
            FieldType::Msg(m) => Ty::Msg(m),
            FieldType::Array(e, n) => Ty::Array((**e).clone(), *n),
        }
    }

    /// Values of the type, in the plural.
    fn plural(&self) -> String {
        match self {
            Ty::Int => "integers".into(),
            Ty::Float => "numbers".into(),
            Ty::Bool => "booleans".into(),
            Ty::Str => "strings".into(),
            Ty::Msg(m) => format!("`{m}` messages"),
            Ty::Array(..) => "arrays".into(),
        }
    }

    /// How the type is named in findings.
    pub fn describe(&self) -> String {
        match self {
            Ty::Int => "an integer".into(),
            Ty::Float => "a number".into(),
            Ty::Bool => "a boolean".into(),
            Ty::Str => "a string".into(),
            Ty::Msg(m) => format!("a `{m}` message"),
            Ty::Array(e, _) => format!("an array of {}", Ty::of(e).plural()),
        }
    }
}

/// What typing one expression found.
#[derive(Debug, Default)]
pub struct Typed {
    /// `None` when the expression has an error.
    pub ty: Option<Ty>,
    /// E0404: the expression does not parse.
    pub syntax: Vec<Diagnostic>,
    /// E0403: a field path that is not in the message.
    pub paths: Vec<Diagnostic>,
    /// E0409: an operator or reducer applied to the wrong type.
    pub mismatches: Vec<Diagnostic>,
    /// The parsed expression.
    pub expr: Option<Expr>,
}

/// Parses and types `text` (a `when` or a payload value) on message `msg`
/// of the registry `reg`.
pub fn type_of(text: &Str, msg: &'static str, reg: &Registry, file: FileId) -> Typed {
    let mut out = Typed::default();
    match expr::parse(&text.value) {
        Err(e) => {
            let span = text.sub(e.range.0, e.range.1);
            out.syntax.push(Diagnostic::error(
                codes::ROS2_BAD_EXPRESSION,
                format!("malformed expression: {}", e.message),
                file,
                span,
                e.message,
            ).with_help("an expression is made of field paths (`a.b[0]`), numbers, strings, `min max mean len`, `+ - * /`, comparisons, `and or not`"));
        }
        Ok(e) => {
            let mut cx = Cx { text, msg, reg, file, out: &mut out };
            let ty = cx.ty(&e);
            out.ty = ty;
            out.expr = Some(e);
        }
    }
    out
}

struct Cx<'a> {
    text: &'a Str,
    msg: &'static str,
    reg: &'a Registry,
    file: FileId,
    out: &'a mut Typed,
}

impl Cx<'_> {
    fn mismatch(&mut self, range: expr::Range, message: String, label: String) -> Option<Ty> {
        let span = self.text.sub(range.0, range.1);
        self.out.mismatches.push(Diagnostic::error(codes::ROS2_TYPE_MISMATCH, message, self.file, span, label));
        None
    }

    fn ty(&mut self, e: &Expr) -> Option<Ty> {
        match e {
            Expr::Number(n, _) => Some(if n.fract() == 0.0 { Ty::Int } else { Ty::Float }),
            Expr::Str(..) => Some(Ty::Str),
            Expr::Bool(..) => Some(Ty::Bool),
            Expr::Path(steps, _) => self.path(steps),
            Expr::Neg(inner, r) => match self.ty(inner)? {
                t if t.is_numeric() => Some(t),
                t => self.mismatch(*r, format!("`-` needs a number, found {}", t.describe()), "not a number".into()),
            },
            Expr::Not(inner, r) => match self.ty(inner)? {
                Ty::Bool => Some(Ty::Bool),
                t => self.mismatch(
                    *r,
                    format!("`not` needs a condition, found {}", t.describe()),
                    "not a condition".into(),
                ),
            },
            Expr::Reduce(red, arg, r) => {
                let t = self.ty(arg)?;
                let name = match red {
                    Reducer::Min => "min",
                    Reducer::Max => "max",
                    Reducer::Mean => "mean",
                    Reducer::Len => "len",
                };
                match (&t, red) {
                    (Ty::Array(..), Reducer::Len) => Some(Ty::Int),
                    (Ty::Array(el, _), _) if Ty::of(el).is_numeric() => {
                        Some(if *red == Reducer::Mean { Ty::Float } else { Ty::of(el) })
                    }
                    _ => self.mismatch(
                        *r,
                        format!(
                            "`{name}` needs an array{}, found {}",
                            if *red == Reducer::Len { "" } else { " of numbers" },
                            t.describe()
                        ),
                        format!("`{name}` of {}", t.describe()),
                    ),
                }
            }
            Expr::Binary(op, l, r, range) => {
                let (lt, rt) = (self.ty(l), self.ty(r));
                let (lt, rt) = (lt?, rt?);
                let ok = match op {
                    BinOp::Add | BinOp::Sub | BinOp::Mul | BinOp::Div => {
                        if lt.is_numeric() && rt.is_numeric() {
                            let int = lt == Ty::Int && rt == Ty::Int && *op != BinOp::Div;
                            return Some(if int { Ty::Int } else { Ty::Float });
                        }
                        false
                    }
                    BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge => lt.is_numeric() && rt.is_numeric(),
                    BinOp::Eq | BinOp::Ne => {
                        (lt.is_numeric() && rt.is_numeric()) || (lt == rt && matches!(lt, Ty::Bool | Ty::Str))
                    }
                    BinOp::And | BinOp::Or => lt == Ty::Bool && rt == Ty::Bool,
                };
                if ok {
                    return Some(Ty::Bool);
                }
                let o = op.text();
                self.mismatch(
                    *range,
                    format!("`{o}` does not apply to {} and {}", lt.describe(), rt.describe()),
                    format!("{} {o} {}", lt.describe(), rt.describe()),
                )
            }
        }
    }

    /// E0403 for `Type.NAME` where `Type` is the message or the type of one
    /// of its fields but has no constant `NAME`.
    fn missing_constant(&self, steps: &[Step]) -> Option<Diagnostic> {
        let [Step::Field(ty, _), Step::Field(name, r)] = steps else { return None };
        if self.reg.field(self.msg, ty).is_some() {
            return None;
        }
        let def = self.reg.reachable(self.msg, ty).into_iter().next()?;
        let names: Vec<&str> = def.constants.iter().map(|c| c.name.as_str()).collect();
        let listed = match names.as_slice() {
            [] => format!("`{}` has no constants", def.name),
            _ => format!("`{}` has the constants: {}", def.name, names.join(", ")),
        };
        let help = match suggest(name, names.iter().copied()) {
            Some(s) => format!("did you mean `{ty}.{s}`? {listed}"),
            None => listed,
        };
        let message = format!("`{}` has no constant `{name}`", def.name);
        let span = self.text.sub(r.0, r.1);
        Some(Diagnostic::error(codes::ROS2_UNKNOWN_FIELD, message, self.file, span, "not a constant").with_help(help))
    }

    fn path(&mut self, steps: &[Step]) -> Option<Ty> {
        if let Some(ty) = constant_type(self.reg, self.msg, steps) {
            return Some(ty);
        }
        if let Some(found) = self.missing_constant(steps) {
            self.out.paths.push(found);
            return None;
        }
        let mut ty = Ty::Msg(self.msg);
        for step in steps {
            ty = match (step, &ty) {
                (Step::Field(name, r), Ty::Msg(m)) => match self.reg.field(m, name) {
                    Some(t) => Ty::of(&t),
                    None => {
                        let fields = self.reg.fields(m);
                        let mut all: Vec<&str> = fields.iter().map(|(n, _)| *n).collect();
                        let constants = self.reg.constants(m);
                        all.extend(constants.iter().map(|c| c.name.as_str()));
                        let near = suggest(name, all.iter().copied());
                        let listed = match (fields.is_empty(), constants.is_empty()) {
                            (true, true) => format!("`{m}` has no fields"),
                            (_, true) => format!("`{m}` has: {}", all.join(", ")),
                            (true, false) => format!("`{m}` has no fields; its constants: {}", all.join(", ")),
                            (false, false) => {
                                let (f, c) = all.split_at(fields.len());
                                format!("`{m}` has: {}; its constants: {}", f.join(", "), c.join(", "))
                            }
                        };
                        let help = match near {
                            Some(s) => format!("did you mean `{s}`? {listed}"),
                            None => listed,
                        };
                        let span = self.text.sub(r.0, r.1);
                        self.out.paths.push(
                            Diagnostic::error(
                                codes::ROS2_UNKNOWN_FIELD,
                                format!("`{m}` has no field `{name}`"),
                                self.file,
                                span,
                                format!("not a field of `{m}`"),
                            )
                            .with_help(help),
                        );
                        return None;
                    }
                },
                (Step::Index(i, r), Ty::Array(el, size)) => {
                    if let Some(n) = size.filter(|n| usize::try_from(*i).map_or(true, |i| i >= *n)) {
                        let span = self.text.sub(r.0, r.1);
                        self.out.paths.push(Diagnostic::error(
                            codes::ROS2_UNKNOWN_FIELD,
                            format!("index {i} is out of the array of {n}"),
                            self.file,
                            span,
                            format!("the array has {n} elements"),
                        ));
                        return None;
                    }
                    Ty::of(el)
                }
                (Step::Field(name, r), t) => {
                    let span = self.text.sub(r.0, r.1);
                    self.out.paths.push(Diagnostic::error(
                        codes::ROS2_UNKNOWN_FIELD,
                        format!("`.{name}` of {}, which has no fields", t.describe()),
                        self.file,
                        span,
                        "no such field",
                    ));
                    return None;
                }
                (Step::Index(_, r), t) => {
                    let span = self.text.sub(r.0, r.1);
                    self.out.paths.push(Diagnostic::error(
                        codes::ROS2_UNKNOWN_FIELD,
                        format!("an index on {}, which is not an array", t.describe()),
                        self.file,
                        span,
                        "not an array",
                    ));
                    return None;
                }
            };
        }
        Some(ty)
    }
}

/// The type of the constant a path names on `msg`, if it names one (see
/// [`Registry::path_constant`]).
fn constant_type(reg: &Registry, msg: &str, steps: &[Step]) -> Option<Ty> {
    let names: Vec<&str> = steps
        .iter()
        .map(|s| match s {
            Step::Field(n, _) => Some(n.as_str()),
            Step::Index(..) => None,
        })
        .collect::<Option<_>>()?;
    let c = reg.path_constant(msg, &names)?;
    Some(match (&c.value, c.ty) {
        (ConstValue::Bool(_), _) => Ty::Bool,
        (ConstValue::Str(_), _) => Ty::Str,
        (_, p) if idl::Prim::is_float(p) => Ty::Float,
        (ConstValue::Float(_), _) | (ConstValue::Int(_), _) => Ty::Int,
    })
}
