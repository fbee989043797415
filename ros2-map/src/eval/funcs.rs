//! The functions of map expressions on a decoded message: over the elements
//! of an array (`any all count min max mean find`, the second argument read
//! in the scope of each element), `index`, and the functions of numbers and
//! vectors (`abs sqrt hypot norm yaw pitch roll`).
//!
//! An element whose condition or number is NaN (a NaN reading, REP 117) is
//! skipped, as `min(ranges)` skips it; a missing value in an element makes
//! the whole function missing.

use super::{ev, fail, float, leaf, missing, number, Acc, EvalError, Scope, Val, Why};
use crate::cdr;
use crate::expr::{Expr, Func, Range, Reducer};

/// The value of `f(args)` in the scope `sc`.
pub(super) fn call<'a>(f: Func, args: &'a [Expr], sc: Scope<'a>, r: Range) -> Result<Val<'a>, EvalError> {
    let (Some(first), second) = (args.first(), args.get(1)) else { return fail(r, "a call without arguments") };
    if f.over_elements() {
        let items = elements(f, ev(first, sc)?, r)?;
        let Some(body) = second else { return fail(r, "a call without its second argument") };
        return over(f, items, body, r);
    }
    match f {
        Func::Index => {
            let items = elements(f, ev(first, sc)?, r)?;
            let Some(value) = second else { return fail(r, "a call without its second argument") };
            index(items, ev(value, sc)?, r)
        }
        Func::Abs => match ev(first, sc)? {
            Val::Int(i) => i.checked_abs().map(Val::Int).map_or_else(|| fail(r, "overflows an integer"), Ok),
            Val::Float(x) => Ok(Val::Float(x.abs())),
            v => fail(r, format!("`abs` of {}", super::describe(&v))),
        },
        Func::Sqrt => match float(ev(first, sc)?) {
            Some(x) if x < 0.0 => fail(r, format!("`sqrt` of a negative number ({x})")),
            Some(x) => number(x.sqrt(), r),
            None => fail(r, "`sqrt` of a value that is not a number"),
        },
        Func::Hypot => {
            let a = float(ev(first, sc)?);
            let Some(second) = second else { return fail(r, "a call without its second argument") };
            match (a, float(ev(second, sc)?)) {
                (Some(a), Some(b)) => number(a.hypot(b), r),
                _ => fail(r, "`hypot` of a value that is not a number"),
            }
        }
        Func::Norm => norm(ev(first, sc)?, r),
        _ => angle(f, ev(first, sc)?, r),
    }
}

/// The elements of the first argument of `f`.
fn elements<'a>(f: Func, v: Val<'a>, r: Range) -> Result<&'a [cdr::Value], EvalError> {
    match v {
        Val::Node(cdr::Value::Array(items)) => Ok(items),
        v => fail(r, format!("`{}` of {}, not of an array", f.name(), super::describe(&v))),
    }
}

/// `any all count find` of a condition, `min max mean` of a number, on each element.
fn over<'a>(f: Func, items: &'a [cdr::Value], body: &'a Expr, r: Range) -> Result<Val<'a>, EvalError> {
    let red = match f {
        Func::Min => Some(Reducer::Min),
        Func::Max => Some(Reducer::Max),
        Func::Mean => Some(Reducer::Mean),
        _ => None,
    };
    if let Some(red) = red {
        let mut acc = Acc::new(red);
        for item in items {
            let v = match ev(body, Scope { value: item, element: true }) {
                Err(e) if e.why == Why::NaN => continue,
                v => v?,
            };
            if !acc.add(v) {
                return fail(body.range(), format!("is {}, not a number", super::describe(&v)));
            }
        }
        return acc.finish(items.len(), r);
    }
    let mut count = 0i64;
    for item in items {
        let holds = match ev(body, Scope { value: item, element: true }) {
            Err(e) if e.why == Why::NaN => continue,
            Ok(Val::Bool(b)) => b,
            Err(e) => return Err(e),
            Ok(v) => return fail(body.range(), format!("is {}, not a condition", super::describe(&v))),
        };
        match (f, holds) {
            (Func::Any, true) => return Ok(Val::Bool(true)),
            (Func::All, false) => return Ok(Val::Bool(false)),
            (Func::Find, true) => return leaf(item, r),
            (_, true) => count += 1,
            (_, false) => {}
        }
    }
    match f {
        Func::Any => Ok(Val::Bool(false)),
        Func::All => Ok(Val::Bool(true)),
        Func::Count => Ok(Val::Int(count)),
        _ => missing(r, format!("no element of the {} matches", items.len())),
    }
}

/// Whether an element equals a value, as `==` compares; `None` when they
/// are not comparable. NaN equals nothing.
fn equal(item: &cdr::Value, v: Val<'_>) -> Option<bool> {
    Some(match (item, v) {
        (cdr::Value::Int(a), Val::Int(b)) => *a == b,
        (cdr::Value::Int(a), Val::Float(b)) => *a as f64 == b,
        (cdr::Value::Float(a), v) => *a == float(v)?,
        (cdr::Value::Str(a), Val::Str(b)) => a == b,
        (cdr::Value::Bool(a), Val::Bool(b)) => *a == b,
        _ => return None,
    })
}

/// `index(array, value)`: the index of the first element equal to `value`.
fn index(items: &[cdr::Value], value: Val<'_>, r: Range) -> Result<Val<'static>, EvalError> {
    for (i, item) in items.iter().enumerate() {
        match equal(item, value) {
            Some(true) => return Ok(Val::Int(i64::try_from(i).unwrap_or(i64::MAX))),
            Some(false) => {}
            None => return fail(r, format!("`index` of {} in an array of other values", super::describe(&value))),
        }
    }
    let shown = match value {
        Val::Str(s) => format!("'{s}'"),
        Val::Int(i) => i.to_string(),
        Val::Float(x) => x.to_string(),
        Val::Bool(b) => b.to_string(),
        Val::Node(_) => "the value".into(),
    };
    missing(r, format!("no element of the {} equals {shown}", items.len()))
}

/// A numeric field of a message.
fn num(v: &cdr::Value, name: &str) -> Option<f64> {
    match v.field(name)? {
        cdr::Value::Int(i) => Some(*i as f64),
        cdr::Value::Float(x) => Some(*x),
        _ => None,
    }
}

/// The Euclidean norm of a message's `x y z` (and `w` when it has one) or
/// of an array of numbers.
fn norm(v: Val<'_>, r: Range) -> Result<Val<'static>, EvalError> {
    let squares: Option<f64> = match v {
        Val::Node(cdr::Value::Array(items)) => items
            .iter()
            .map(|x| match x {
                cdr::Value::Int(i) => Some(*i as f64),
                cdr::Value::Float(f) => Some(*f),
                _ => None,
            })
            .try_fold(0.0, |s, x| Some(s + x? * x?)),
        Val::Node(m @ cdr::Value::Msg(_)) => {
            let w = num(m, "w").unwrap_or(0.0);
            ["x", "y", "z"].iter().try_fold(w * w, |s, n| num(m, n).map(|x| s + x * x))
        }
        _ => None,
    };
    match squares {
        Some(s) => number(s.sqrt(), r),
        None => fail(r, format!("`norm` of {}, not a vector", super::describe(&v))),
    }
}

/// `yaw`, `pitch` or `roll` of a quaternion (`x y z w`, any length but
/// zero), in radians: the Z-Y-X Euler angles, as tf2's `getRPY` gives them.
fn angle(f: Func, v: Val<'_>, r: Range) -> Result<Val<'static>, EvalError> {
    let q = match v {
        Val::Node(m) => (num(m, "x"), num(m, "y"), num(m, "z"), num(m, "w")),
        _ => (None, None, None, None),
    };
    let (Some(x), Some(y), Some(z), Some(w)) = q else {
        return fail(r, format!("`{}` of {}, not a quaternion", f.name(), super::describe(&v)));
    };
    let n = x * x + y * y + z * z + w * w;
    if n == 0.0 {
        return fail(r, "is of a zero quaternion, which has no angles");
    }
    let a = match f {
        Func::Roll => (2.0 * (w * x + y * z)).atan2(w * w - x * x - y * y + z * z),
        Func::Pitch => (2.0 * (w * y - z * x) / n).clamp(-1.0, 1.0).asin(),
        _ => (2.0 * (w * z + x * y)).atan2(w * w + x * x - y * y - z * z),
    };
    number(a, r)
}
