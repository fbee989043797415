//! Types of map expressions against a message: every field path (or
//! constant) is looked up in the registry of message definitions, every
//! operator and function checked. The findings are
//! sorted by kind so that each check of [`crate::check`] reports its own.
//!
//! The second argument of `any all count min max mean find` is typed in the
//! scope of an element of the array: a bare name is a field of the element,
//! `it` the element itself, and nothing outside the element is visible.

use crate::expr::{self, BinOp, Expr, Func, Reducer, Step};
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
    /// E0409: an operator, reducer or function applied to the wrong type.
    pub mismatches: Vec<Diagnostic>,
    /// E0419: a division by a constant zero.
    pub zero_divisions: Vec<Diagnostic>,
    /// E0420: an index that is not an integer.
    pub indexes: Vec<Diagnostic>,
    /// The parsed expression.
    pub expr: Option<Expr>,
    /// The paths that name a constant (`STATUS_ABORTED`,
    /// `DiagnosticStatus.ERROR`), by their range, and its value: what the
    /// translator puts in their place.
    pub constants: Vec<(expr::Range, ConstValue)>,
}

/// Parses and types `text` (a `when` or a payload value) on message `msg`
/// of the registry `reg`.
pub fn type_of(text: &Str, msg: &'static str, reg: &Registry, file: FileId) -> Typed {
    let mut out = Typed::default();
    match expr::parse(&text.value) {
        Err(e) => {
            let span = text.sub(e.range.0, e.range.1);
            let help = e.help.unwrap_or_else(|| {
                "an expression is made of field paths (`a.b[0]`, `a[-1]`), numbers, strings, functions \
                 (`min(ranges)`, `any(status, level >= 2)`), `+ - * /`, comparisons, `and or not`"
                    .into()
            });
            out.syntax.push(
                Diagnostic::error(
                    codes::ROS2_BAD_EXPRESSION,
                    format!("malformed expression: {}", e.message),
                    file,
                    span,
                    e.label.unwrap_or(e.message),
                )
                .with_help(help),
            );
        }
        Ok(e) => {
            let mut cx = Cx { text, msg, reg, file, out: &mut out, scope: None };
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
    /// The element scope of the innermost `any(array, …)` and its kind.
    scope: Option<Scope>,
}

/// The scope of the second argument of a function over elements.
#[derive(Debug, Clone)]
struct Scope {
    /// The type of an element.
    el: Ty,
    /// The function, for the findings.
    func: &'static str,
    /// The text of the array, for the findings.
    array: String,
}

/// The type of field `name` of message `m`: where typing reads the definitions.
fn field_of(reg: &Registry, m: &'static str, name: &str) -> Option<Ty> {
    reg.field(m, name).map(|t| Ty::of(&t))
}

/// The names of the fields of message `m`, in order.
fn field_names(reg: &Registry, m: &'static str) -> Vec<&'static str> {
    reg.fields(m).into_iter().map(|(n, _)| n).collect()
}

/// Whether `t` is a message with numeric fields of every one of `names`.
fn has_numbers(reg: &Registry, t: &Ty, names: &[&str]) -> bool {
    match t {
        Ty::Msg(m) => names.iter().all(|n| field_of(reg, m, n).is_some_and(|f| f.is_numeric())),
        _ => false,
    }
}

/// The value of an expression of numbers only (`1 - 1`), folded.
pub fn constant(e: &Expr) -> Option<f64> {
    let v = match e {
        Expr::Number(n, _) => *n,
        Expr::Neg(inner, _) => -constant(inner)?,
        Expr::Binary(op, l, r, _) => {
            let (a, b) = (constant(l)?, constant(r)?);
            match op {
                BinOp::Add => a + b,
                BinOp::Sub => a - b,
                BinOp::Mul => a * b,
                BinOp::Div if b != 0.0 => a / b,
                _ => return None,
            }
        }
        Expr::Call(Func::Abs, args, _) => constant(args.first()?)?.abs(),
        Expr::Call(Func::Sqrt, args, _) => constant(args.first()?)?.sqrt(),
        Expr::Call(Func::Hypot, args, _) => constant(args.first()?)?.hypot(constant(args.get(1)?)?),
        _ => return None,
    };
    v.is_finite().then_some(v)
}

impl Cx<'_> {
    fn mismatch(&mut self, range: expr::Range, message: String, label: String, help: &str) -> Option<Ty> {
        let span = self.text.sub(range.0, range.1);
        self.out
            .mismatches
            .push(Diagnostic::error(codes::ROS2_TYPE_MISMATCH, message, self.file, span, label).with_help(help));
        None
    }

    /// E0403: a path that does not name a value of the message.
    fn unknown(
        &mut self,
        range: expr::Range,
        message: String,
        label: impl Into<String>,
        help: impl Into<String>,
    ) -> Option<Ty> {
        let span = self.text.sub(range.0, range.1);
        self.out
            .paths
            .push(Diagnostic::error(codes::ROS2_UNKNOWN_FIELD, message, self.file, span, label).with_help(help));
        None
    }

    /// E0403: an index on `t`, which is not an array.
    fn not_an_array(&mut self, range: expr::Range, t: &Ty) -> Option<Ty> {
        let message = format!("an index on {}, which is not an array", t.describe());
        self.unknown(range, message, "not an array", "index an array field: `status[0]`, `status_list[-1]`")
    }

    /// E0403: index `i` outside a fixed-size array of `n`.
    fn out_of_array(&mut self, range: expr::Range, i: impl std::fmt::Display, n: usize) -> Option<Ty> {
        let help = format!("an index of this array is from 0 to {} (or -{n} to -1)", n.saturating_sub(1));
        self.unknown(
            range,
            format!("index {i} is out of the array of {n}"),
            format!("the array has {n} elements"),
            help,
        )
    }

    /// A type mismatch of a function's argument, with the function's usage.
    fn bad_arg(&mut self, f: Func, arg: &Expr, needs: &str, found: &Ty) -> Option<Ty> {
        let r = arg.range();
        let span = self.text.sub(r.0, r.1);
        self.out.mismatches.push(
            Diagnostic::error(
                codes::ROS2_TYPE_MISMATCH,
                format!("`{}` needs {needs}, found {}", f.name(), found.describe()),
                self.file,
                span,
                format!("not {needs}"),
            )
            .with_help(format!("write {}", f.usage())),
        );
        None
    }

    fn excerpt(&self, r: expr::Range) -> String {
        self.text.value.get(r.0..r.1).unwrap_or("…").to_string()
    }

    fn ty(&mut self, e: &Expr) -> Option<Ty> {
        match e {
            Expr::Number(n, _) => Some(if n.fract() == 0.0 { Ty::Int } else { Ty::Float }),
            Expr::Str(..) => Some(Ty::Str),
            Expr::Bool(..) => Some(Ty::Bool),
            Expr::Path(steps, r) => self.path(steps, *r),
            Expr::Neg(inner, r) => match self.ty(inner)? {
                t if t.is_numeric() => Some(t),
                t => self.mismatch(
                    *r,
                    format!("`-` needs a number, found {}", t.describe()),
                    "not a number".into(),
                    "`-` negates a number: apply it to a numeric field",
                ),
            },
            Expr::Not(inner, r) => match self.ty(inner)? {
                Ty::Bool => Some(Ty::Bool),
                t => self.mismatch(
                    *r,
                    format!("`not` needs a condition, found {}", t.describe()),
                    "not a condition".into(),
                    "`not` negates a condition: compare the value first, e.g. `not (x > 1)`",
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
                        "`len(array)` counts the elements; `min max mean` take an array of numbers, or an array \
                         and a number of its element: `max(status, level)`",
                    ),
                }
            }
            Expr::Call(f, args, r) => self.call(*f, args, *r),
            Expr::Member(base, name, nr, _) => {
                let t = self.ty(base)?;
                self.path_from(t, &[Step::Field(name.clone(), *nr)])
            }
            Expr::At(base, index, _) => {
                let (bt, it) = (self.ty(base), self.index(index));
                it?;
                self.element(bt?, index)
            }
            Expr::Binary(op, l, r, range) => {
                if *op == BinOp::Div && constant(r) == Some(0.0) {
                    self.zero_division(r);
                }
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
                let help = match op {
                    BinOp::Add | BinOp::Sub | BinOp::Mul | BinOp::Div => "`+ - * /` take two numbers",
                    BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge => {
                        "`< <= > >=` compare two numbers; strings and booleans compare with `==` and `!=`"
                    }
                    BinOp::Eq | BinOp::Ne => "`==` and `!=` compare two numbers, two strings or two booleans",
                    BinOp::And | BinOp::Or => {
                        "`and` and `or` join conditions: compare the values first, e.g. `x > 0 and y > 0`"
                    }
                };
                self.mismatch(
                    *range,
                    format!("`{o}` does not apply to {} and {}", lt.describe(), rt.describe()),
                    format!("{} {o} {}", lt.describe(), rt.describe()),
                    help,
                )
            }
        }
    }

    /// E0403 for `Type.NAME` where `Type` is `msg` or the type of one of
    /// its fields but has no constant `NAME`.
    fn missing_constant(&self, msg: &'static str, steps: &[Step]) -> Option<Diagnostic> {
        let [Step::Field(ty, _), Step::Field(name, r)] = steps else { return None };
        if self.reg.field(msg, ty).is_some() || (ty == "it" && self.scope.is_some()) {
            return None;
        }
        let def = self.reg.reachable(msg, ty).into_iter().next()?;
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

    /// A field path, or a constant: `NAME` of the element's message in an
    /// element's scope, then of the message; `Type.NAME` of a message
    /// reachable from either.
    fn path(&mut self, steps: &[Step], range: expr::Range) -> Option<Ty> {
        let element = match self.scope.as_ref().map(|s| &s.el) {
            Some(Ty::Msg(m)) => Some(*m),
            _ => None,
        };
        for msg in element.into_iter().chain([self.msg]) {
            if let Some((ty, value)) = constant_of(self.reg, msg, steps) {
                self.out.constants.push((range, value));
                return Some(ty);
            }
        }
        if let Some(found) = self.missing_constant(element.unwrap_or(self.msg), steps) {
            self.out.paths.push(found);
            return None;
        }
        let Some(scope) = self.scope.clone() else { return self.path_from(Ty::Msg(self.msg), steps) };
        let Some((Step::Field(name, r), rest)) = steps.split_first() else { return None };
        let is_field = match &scope.el {
            Ty::Msg(m) => field_of(self.reg, m, name).is_some(),
            _ => false,
        };
        if name == "it" && !is_field {
            return self.path_from(scope.el, rest);
        }
        if !is_field {
            return self.not_in_scope(&scope, name, *r);
        }
        self.path_from(scope.el, steps)
    }

    /// E0403: a name in an element's scope that is not a field of the element.
    fn not_in_scope(&mut self, scope: &Scope, name: &str, r: expr::Range) -> Option<Ty> {
        let (f, array) = (scope.func, &scope.array);
        let (message, help) = match &scope.el {
            Ty::Msg(m) => {
                let all = field_names(self.reg, m);
                let near = suggest(name, all.iter().copied()).map(|s| format!("did you mean `{s}`? ")).unwrap_or_default();
                (
                    format!("`{m}`, an element of `{array}`, has no field `{name}`"),
                    format!(
                        "{near}in `{f}({array}, …)` a name is a field of the element: {}; `it` is the element; \
                         nothing outside the element is visible there",
                        all.join(", ")
                    ),
                )
            }
            el => (
                format!("`{name}` is not a name in `{f}({array}, …)`: an element of `{array}` is {}", el.describe()),
                format!("write `it` for the element, e.g. `{f}({array}, it > 0)`; nothing outside the element is visible there"),
            ),
        };
        self.unknown(r, message, "not a field of the element", help)
    }

    fn path_from(&mut self, start: Ty, steps: &[Step]) -> Option<Ty> {
        let mut ty = start;
        for step in steps {
            ty = match (step, &ty) {
                (Step::Field(name, r), Ty::Msg(m)) => match field_of(self.reg, m, name) {
                    Some(t) => t,
                    None => {
                        let mut all = field_names(self.reg, m);
                        let fields = all.len();
                        let constants = self.reg.constants(m);
                        all.extend(constants.iter().map(|c| c.name.as_str()));
                        let near = suggest(name, all.iter().copied());
                        let listed = match (fields == 0, constants.is_empty()) {
                            (true, true) => format!("`{m}` has no fields"),
                            (_, true) => format!("`{m}` has: {}", all.join(", ")),
                            (true, false) => format!("`{m}` has no fields; its constants: {}", all.join(", ")),
                            (false, false) => {
                                let (f, c) = all.split_at(fields);
                                format!("`{m}` has: {}; its constants: {}", f.join(", "), c.join(", "))
                            }
                        };
                        let help = match near {
                            Some(s) => format!("did you mean `{s}`? {listed}"),
                            None => listed,
                        };
                        return self.unknown(
                            *r,
                            format!("`{m}` has no field `{name}`"),
                            format!("not a field of `{m}`"),
                            help,
                        );
                    }
                },
                (Step::Index(i, r), Ty::Array(el, size)) => {
                    if let Some(n) = size.filter(|n| usize::try_from(*i).map_or(true, |i| i >= *n)) {
                        return self.out_of_array(*r, i, n);
                    }
                    Ty::of(el)
                }
                (Step::Field(name, r), t) => {
                    let help = match t {
                        Ty::Array(..) => format!("pick an element first: `[0]`, `[-1]`, or `find(array, …).{name}`"),
                        _ => format!("remove `.{name}`: only messages have fields"),
                    };
                    let message = format!("`.{name}` of {}, which has no fields", t.describe());
                    return self.unknown(*r, message, "no such field", help);
                }
                (Step::Index(_, r), t) => {
                    let t = t.clone();
                    return self.not_an_array(*r, &t);
                }
            };
        }
        Some(ty)
    }

    /// E0419: `x / 0`, `x / (1 - 1)`.
    fn zero_division(&mut self, divisor: &Expr) {
        let r = divisor.range();
        let span = self.text.sub(r.0, r.1);
        self.out.zero_divisions.push(
            Diagnostic::error(
                codes::ROS2_ZERO_DIVISION,
                format!("division by zero: `{}` is always 0", self.excerpt(r)),
                self.file,
                span,
                "this is 0",
            )
            .with_help(
                "divide by a number that is not zero, or by a field; the value would never be defined, \
                 so the entry would never post its event",
            ),
        );
    }

    /// The type of an index: `Some(())` for an integer; E0420 otherwise.
    fn index(&mut self, index: &Expr) -> Option<()> {
        let r = index.range();
        let written = self.excerpt(r);
        // A literal written as a number (`0.0`, `-1.0`, `1e3`), even whole.
        let literal = match index {
            Expr::Neg(inner, _) => inner.as_ref(),
            e => e,
        };
        let (found, help) = match literal {
            Expr::Number(n, lr) if !self.excerpt(*lr).bytes().all(|b| b.is_ascii_digit()) => {
                let n = if matches!(index, Expr::Neg(..)) { -n } else { *n };
                let whole = if n.fract() == 0.0 { format!("write `[{n}]`; ") } else { String::new() };
                (format!("`{written}`"), format!("{whole}an index is a whole number written with digits"))
            }
            _ => match self.ty(index)? {
                Ty::Int => return Some(()),
                Ty::Str => (
                    "a string".into(),
                    "to pick an element by a field, write `find(array, name == 'x')`; for a name in a parallel \
                     array, `position[index(name, 'x')]`"
                        .into(),
                ),
                t => (t.describe(), "an index is an integer: `[0]` the first element, `[-1]` the last".into()),
            },
        };
        let span = self.text.sub(r.0, r.1);
        self.out.indexes.push(
            Diagnostic::error(
                codes::ROS2_BAD_INDEX,
                format!("an index must be an integer, found {found}"),
                self.file,
                span,
                "not an integer",
            )
            .with_help(help),
        );
        None
    }

    /// The element of `array` at the integer `index` (`a[-1]`, `a[i]`).
    fn element(&mut self, array: Ty, index: &Expr) -> Option<Ty> {
        let r = index.range();
        let Ty::Array(el, size) = array else { return self.not_an_array(r, &array) };
        if let (Some(n), Some(i)) = (size, constant(index)) {
            let at = if i < 0.0 { i + n as f64 } else { i };
            if at < 0.0 || at >= n as f64 {
                return self.out_of_array(r, i, n);
            }
        }
        Some(Ty::of(&el))
    }

    /// The type of a function's call.
    fn call(&mut self, f: Func, args: &[Expr], _: expr::Range) -> Option<Ty> {
        let [first, rest @ ..] = args else { return None };
        if f.over_elements() {
            let el = self.elements(f, first)?;
            let body = rest.first()?;
            let scope = Scope { el: el.clone(), func: f.name(), array: self.excerpt(first.range()) };
            let saved = self.scope.replace(scope);
            let t = self.ty(body);
            self.scope = saved;
            let t = t?;
            return match f {
                Func::Min | Func::Max if t.is_numeric() => Some(t),
                Func::Mean if t.is_numeric() => Some(Ty::Float),
                Func::Min | Func::Max | Func::Mean => self.bad_arg(f, body, "a number of the element", &t),
                _ if t != Ty::Bool => self.bad_arg(f, body, "a condition on the element", &t),
                Func::Count => Some(Ty::Int),
                Func::Find => Some(el),
                _ => Some(Ty::Bool),
            };
        }
        match f {
            Func::Index => {
                let (array, value) = (self.ty(first), rest.first().and_then(|v| self.ty(v)));
                let (array, value) = (array?, value?);
                let Ty::Array(el, _) = &array else { return self.bad_arg(f, first, "an array", &array) };
                let el = Ty::of(el);
                let needs = match &el {
                    t if t.is_numeric() && value.is_numeric() => return Some(Ty::Int),
                    Ty::Str | Ty::Bool if el == value => return Some(Ty::Int),
                    t if t.is_numeric() => "a number".to_string(),
                    Ty::Str | Ty::Bool => el.describe(),
                    _ => return self.bad_arg(f, first, "an array of numbers, strings or booleans", &array),
                };
                self.bad_arg(f, rest.first()?, &needs, &value)
            }
            Func::Abs => match self.ty(first)? {
                t if t.is_numeric() => Some(t),
                t => self.bad_arg(f, first, "a number", &t),
            },
            Func::Sqrt => match self.ty(first)? {
                t if t.is_numeric() => Some(Ty::Float),
                t => self.bad_arg(f, first, "a number", &t),
            },
            Func::Hypot => {
                let (a, b) = (self.ty(first), rest.first().and_then(|b| self.ty(b)));
                let (a, b) = (a?, b?);
                match (a.is_numeric(), b.is_numeric()) {
                    (true, true) => Some(Ty::Float),
                    (false, _) => self.bad_arg(f, first, "a number", &a),
                    (true, false) => self.bad_arg(f, rest.first()?, "a number", &b),
                }
            }
            Func::Norm => match self.ty(first)? {
                Ty::Array(el, _) if Ty::of(&el).is_numeric() => Some(Ty::Float),
                t if has_numbers(self.reg, &t, &["x", "y", "z"]) => Some(Ty::Float),
                t => self.bad_arg(f, first, "a vector (numeric `x y z`, or an array of numbers)", &t),
            },
            _ => match self.ty(first)? {
                t if has_numbers(self.reg, &t, &["x", "y", "z", "w"]) => Some(Ty::Float),
                t => self.bad_arg(f, first, "a quaternion (numeric `x y z w`)", &t),
            },
        }
    }

    /// The type of an element of the array `e`, the first argument of `f`.
    fn elements(&mut self, f: Func, e: &Expr) -> Option<Ty> {
        match self.ty(e)? {
            Ty::Array(el, _) => Some(Ty::of(&el)),
            t => self.bad_arg(f, e, "an array", &t),
        }
    }
}

/// The type and value of the constant a path names on `msg`, if it names
/// one (see [`Registry::path_constant`]).
fn constant_of(reg: &Registry, msg: &str, steps: &[Step]) -> Option<(Ty, ConstValue)> {
    let names: Vec<&str> = steps
        .iter()
        .map(|s| match s {
            Step::Field(n, _) => Some(n.as_str()),
            Step::Index(..) => None,
        })
        .collect::<Option<_>>()?;
    let c = reg.path_constant(msg, &names)?;
    let ty = match (&c.value, c.ty) {
        (ConstValue::Bool(_), _) => Ty::Bool,
        (ConstValue::Str(_), _) => Ty::Str,
        (_, p) if idl::Prim::is_float(p) => Ty::Float,
        (ConstValue::Float(_), _) | (ConstValue::Int(_), _) => Ty::Int,
    };
    Some((ty, c.value.clone()))
}

#[cfg(test)]
#[path = "types_tests.rs"]
mod tests;
