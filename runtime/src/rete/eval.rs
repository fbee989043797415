//! Comparing payload values as the language reference (§10.3) says: an
//! integer compares with a float by exact numeric value, NaN satisfies no
//! comparison (not even `!=`), symbols and booleans only (in)equality.

use situ_bundle::{Check, Cmp, Operand, Test, Value};
use std::cmp::Ordering;

/// `a op b`.
#[inline]
pub fn compare(op: Cmp, a: Value, b: Value) -> bool {
    match (a, b) {
        (Value::F64(x), Value::F64(y)) => float(op, x, y),
        (Value::I64(x), Value::I64(y)) => ordering(op, x.cmp(&y)),
        (Value::F64(x), Value::I64(y)) => mixed(x, y).is_some_and(|o| ordering(op, o)),
        (Value::I64(x), Value::F64(y)) => mixed(y, x).is_some_and(|o| ordering(op, o.reverse())),
        (Value::Bool(x), Value::Bool(y)) => equality(op, x == y),
        (Value::Symbol(x), Value::Symbol(y)) => equality(op, x == y),
        _ => false,
    }
}

/// `lo <= x < hi` (`<= hi` when inclusive).
#[inline]
pub fn in_range(x: Value, lo: Value, hi: Value, inclusive: bool) -> bool {
    compare(Cmp::Ge, x, lo) && compare(if inclusive { Cmp::Le } else { Cmp::Lt }, x, hi)
}

/// Whether a payload passes a test on its own fields (a test on another
/// fact's field passes nothing: it needs the other fact).
pub fn passes(t: &Test, payload: &[Value]) -> bool {
    passes_with(t, payload, |_, _| None)
}

/// Whether a payload passes a test, the other facts' fields read by
/// `fact(agent, field)` (`None`: no such fact, and the test fails).
pub fn passes_with(t: &Test, payload: &[Value], fact: impl Fn(u32, u32) -> Option<Value>) -> bool {
    let get = |o: &Operand| match o {
        Operand::Value(v) => Some(*v),
        Operand::Own { field } => payload.get(*field as usize).copied(),
        Operand::Fact { agent, field } => fact(*agent, *field),
    };
    let Some(&x) = payload.get(t.field as usize) else { return false };
    match &t.check {
        Check::Compare { op, rhs } => get(rhs).is_some_and(|y| compare(*op, x, y)),
        Check::Range { lo, hi, inclusive } => match (get(lo), get(hi)) {
            (Some(lo), Some(hi)) => in_range(x, lo, hi, *inclusive),
            _ => false,
        },
    }
}

#[inline]
// `x < y || x > y` is not `x != y`: it is false for NaN, as the language wants.
#[allow(clippy::double_comparisons)]
pub(super) fn float(op: Cmp, x: f64, y: f64) -> bool {
    match op {
        Cmp::Eq => x == y,
        // IEEE `!=` holds for NaN; the language's does not.
        Cmp::Ne => x < y || x > y,
        Cmp::Lt => x < y,
        Cmp::Le => x <= y,
        Cmp::Gt => x > y,
        Cmp::Ge => x >= y,
    }
}

#[inline]
fn ordering(op: Cmp, o: Ordering) -> bool {
    match op {
        Cmp::Eq => o == Ordering::Equal,
        Cmp::Ne => o != Ordering::Equal,
        Cmp::Lt => o == Ordering::Less,
        Cmp::Le => o != Ordering::Greater,
        Cmp::Gt => o == Ordering::Greater,
        Cmp::Ge => o != Ordering::Less,
    }
}

#[inline]
fn equality(op: Cmp, equal: bool) -> bool {
    match op {
        Cmp::Eq => equal,
        Cmp::Ne => !equal,
        _ => false,
    }
}

/// How a float compares with an integer, exactly; `None` for NaN.
fn mixed(x: f64, y: i64) -> Option<Ordering> {
    if x.is_nan() {
        return None;
    }
    // i64 spans [-2^63, 2^63); outside it the float wins outright.
    const TWO_63: f64 = 9_223_372_036_854_775_808.0;
    if x >= TWO_63 {
        return Some(Ordering::Greater);
    }
    if x < -TWO_63 {
        return Some(Ordering::Less);
    }
    let whole = x.floor();
    match (whole as i64).cmp(&y) {
        Ordering::Equal if x > whole => Some(Ordering::Greater),
        o => Some(o),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nan_satisfies_nothing() {
        let nan = Value::F64(f64::NAN);
        for op in [Cmp::Eq, Cmp::Ne, Cmp::Lt, Cmp::Le, Cmp::Gt, Cmp::Ge] {
            assert!(!compare(op, nan, Value::F64(1.0)), "{op:?}");
            assert!(!compare(op, Value::F64(1.0), nan), "{op:?}");
            assert!(!compare(op, nan, Value::I64(1)), "{op:?}");
        }
        assert!(!in_range(nan, Value::F64(f64::NEG_INFINITY), Value::F64(f64::INFINITY), true));
    }

    #[test]
    fn integers_and_floats_compare_exactly() {
        assert!(compare(Cmp::Gt, Value::F64(2.5), Value::I64(2)));
        assert!(compare(Cmp::Lt, Value::I64(2), Value::F64(2.5)));
        assert!(compare(Cmp::Eq, Value::F64(3.0), Value::I64(3)));
        assert!(compare(Cmp::Lt, Value::F64(-2.5), Value::I64(-2)));
        // 2^53 + 1 is not a float: the nearest float is 2^53, which is less.
        let big = (1i64 << 53) + 1;
        assert!(compare(Cmp::Lt, Value::F64((1u64 << 53) as f64), Value::I64(big)));
        assert!(compare(Cmp::Gt, Value::F64(1e19), Value::I64(i64::MAX)));
        assert!(compare(Cmp::Lt, Value::F64(-1e19), Value::I64(i64::MIN)));
    }

    #[test]
    fn ranges_are_half_open_unless_inclusive() {
        let (lo, hi) = (Value::F64(1.0), Value::F64(2.0));
        assert!(in_range(Value::F64(1.0), lo, hi, false));
        assert!(!in_range(Value::F64(2.0), lo, hi, false));
        assert!(in_range(Value::F64(2.0), lo, hi, true));
        assert!(!in_range(Value::F64(3.0), Value::F64(4.0), Value::F64(2.0), true), "lo > hi is empty");
    }

    #[test]
    fn symbols_and_booleans_only_test_equality() {
        assert!(compare(Cmp::Eq, Value::Symbol(1), Value::Symbol(1)));
        assert!(compare(Cmp::Ne, Value::Bool(true), Value::Bool(false)));
        assert!(!compare(Cmp::Lt, Value::Symbol(0), Value::Symbol(1)));
        assert!(!compare(Cmp::Eq, Value::Bool(true), Value::Symbol(1)), "different types never match");
    }
}
