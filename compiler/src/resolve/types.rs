//! Payload types: field types, literals against a field's type, and which
//! operators apply to which type.

use super::Cx;
use crate::codes;
use crate::model::{Type, Value};
use situ_grammar::ast::{self, Span};
use situ_grammar::diag::{Diagnostic, FileId};

/// The type of a declared field; a symbol listed twice is a duplicate.
pub(super) fn field_type(cx: &mut Cx, file: FileId, ty: &ast::FieldType) -> Type {
    match ty {
        ast::FieldType::F64 => Type::F64,
        ast::FieldType::I64 => Type::I64,
        ast::FieldType::Bool => Type::Bool,
        ast::FieldType::Symbols(symbols) => {
            let mut names: Vec<String> = Vec::new();
            for (i, s) in symbols.iter().enumerate() {
                if let Some(first) = symbols[..i].iter().find(|f| f.name == s.name) {
                    cx.duplicate("symbol", &s.name, file, s.span, Cx::origin(file, first.span));
                } else {
                    names.push(s.name.clone());
                }
            }
            Type::Symbols(names)
        }
    }
}

/// What kind of value a literal is, for messages.
fn describe(lit: &ast::LiteralValue) -> String {
    match lit {
        ast::LiteralValue::Float(f) if !f.is_finite() => format!("the float `{f}`"),
        ast::LiteralValue::Float(_) => "a float".into(),
        ast::LiteralValue::Int(_) => "an integer".into(),
        ast::LiteralValue::Bool(_) => "a boolean".into(),
        ast::LiteralValue::Symbol(s) => format!("the symbol `{s}`"),
    }
}

/// Checks a literal against the type of `field`; the typed value if it fits.
pub(super) fn literal(cx: &mut Cx, file: FileId, lit: &ast::Literal, ty: &Type, field: &str) -> Option<Value> {
    use ast::LiteralValue as L;
    // `NaN` and `inf` are float literals, but still name a symbol of that
    // name where the field is an enumeration.
    let non_finite_name = match &lit.value {
        L::Float(f) if f.is_nan() => Some("NaN"),
        L::Float(f) if *f == f64::INFINITY => Some("inf"),
        _ => None,
    };
    if let (Some(name), Type::Symbols(symbols)) = (non_finite_name, ty) {
        if let Some(i) = symbols.iter().position(|x| x == name) {
            return Some(Value::Symbol(i as u32));
        }
    }
    let value = match (&lit.value, ty) {
        (L::Float(f), Type::F64) => Some(Value::F64(*f)),
        (L::Int(i), Type::F64) => Some(Value::F64(*i as f64)),
        (L::Int(i), Type::I64) => Some(Value::I64(*i)),
        (L::Bool(b), Type::Bool) => Some(Value::Bool(*b)),
        (L::Symbol(s), Type::Symbols(symbols)) => match symbols.iter().position(|x| x == s) {
            Some(i) => Some(Value::Symbol(i as u32)),
            None => {
                let mut d = Diagnostic::error(
                    codes::UNKNOWN_SYMBOL,
                    format!("`{s}` is not a value of field `{field}`"),
                    file,
                    lit.span,
                    "unknown symbol",
                )
                .with_help(format!("`{field}` is one of: {}", symbols.join(", ")));
                if let Some(close) = crate::suggest::suggest(s, symbols.iter().map(String::as_str)) {
                    d = d.with_fix(format!("change to `{close}`"), file, lit.span, close);
                }
                cx.diags.push(d);
                return None;
            }
        },
        _ => None,
    };
    if value.is_none() {
        let mut d = Diagnostic::error(
            codes::TYPE_MISMATCH,
            format!("field `{field}` is {}, but this is {}", ty.describe(), describe(&lit.value)),
            file,
            lit.span,
            format!("expected {}", ty.describe()),
        );
        d = match (&lit.value, ty) {
            (L::Float(f), Type::I64) if !f.is_finite() => d.with_help("an i64 field holds whole numbers only"),
            (L::Float(f), Type::I64) if f.fract() == 0.0 => {
                let int = (*f as i64).to_string();
                d.with_help(format!("write the integer `{int}`")).with_fix(
                    format!("write `{int}`"),
                    file,
                    lit.span,
                    int,
                )
            }
            (L::Float(_), Type::I64) => d.with_help("an i64 field holds whole numbers only"),
            (_, Type::Bool) => d.with_help("write `true` or `false`"),
            (_, Type::Symbols(s)) => d.with_help(format!("write one of: {}", s.join(", "))),
            _ => d,
        };
        cx.diags.push(d);
    }
    value
}

/// Checks that an ordering comparison or a range applies to the field's type.
pub(super) fn ordered(cx: &mut Cx, file: FileId, ty: &Type, field: &str, op_span: Span, what: &str) -> bool {
    if ty.is_numeric() {
        return true;
    }
    cx.diags.push(
        Diagnostic::error(
            codes::BAD_OPERATOR,
            format!("{what} does not apply to field `{field}` of type {}", ty.describe()),
            file,
            op_span,
            "needs a number",
        )
        .with_help("bool and symbol fields can only be compared with `==` and `!=`"),
    );
    false
}
