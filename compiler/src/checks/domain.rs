//! Exact value sets for payload fields: what values a field can take so that
//! a set of constant comparisons holds. Static checks intersect and subtract
//! them to decide whether conditions can hold together.
//!
//! - f64: a union of disjoint closed ranges of f64 values (an open end is the
//!   neighbouring f64: the values are discrete), plus a flag for NaN. NaN
//!   satisfies no comparison (not even `!=`), so any comparison removes it.
//! - i64: a union of disjoint closed integer ranges.
//! - bool and symbols: a bit set of the allowed values.

use crate::model::{FieldCheck, Operand, Type, Value};
use serde::Serialize;
use situ_grammar::ast::CmpOp;

/// A non-empty closed range of f64 values, `lo <= hi`, ends included.
/// f64 values are discrete, so an open end is the neighbouring value:
/// `x < 30.0` is `x <= 29.999999999999996`, and `(a, next_up(a))` is empty.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Interval {
    pub lo: f64,
    pub hi: f64,
}

impl Interval {
    /// Every f64 value but NaN, infinities included.
    pub const ALL: Interval = Interval { lo: f64::NEG_INFINITY, hi: f64::INFINITY };

    fn new(lo: f64, hi: f64) -> Option<Interval> {
        (lo <= hi).then_some(Interval { lo, hi })
    }

    fn intersect(self, o: Interval) -> Option<Interval> {
        Interval::new(self.lo.max(o.lo), self.hi.min(o.hi))
    }

    /// A value inside, preferring round numbers, for witnesses.
    pub fn sample(self) -> f64 {
        let (lo, hi) = (self.lo, self.hi);
        if lo <= 0.0 && 0.0 <= hi {
            return 0.0;
        }
        for candidate in [lo.ceil(), hi.floor()] {
            if candidate.is_finite() && lo <= candidate && candidate <= hi {
                return candidate;
            }
        }
        if lo.is_finite() {
            lo
        } else {
            hi
        }
    }
}

/// The values of one field that satisfy some constraints.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Domain {
    /// f64: disjoint intervals in order, and whether NaN is still possible.
    Real { intervals: Vec<Interval>, nan: bool },
    /// i64: disjoint closed ranges in order.
    Int(Vec<(i128, i128)>),
    /// bool or symbols: which of the `n` values are allowed (bit i: value i).
    Finite { allowed: u64, n: u32 },
}

impl Domain {
    /// Every value of the type.
    pub fn full(ty: &Type) -> Domain {
        match ty {
            Type::F64 => Domain::Real { intervals: vec![Interval::ALL], nan: true },
            Type::I64 => Domain::Int(vec![(i64::MIN as i128, i64::MAX as i128)]),
            Type::Bool => Domain::Finite { allowed: 0b11, n: 2 },
            Type::Symbols(s) => {
                let n = s.len().min(64) as u32;
                Domain::Finite { allowed: if n == 64 { u64::MAX } else { (1u64 << n) - 1 }, n }
            }
        }
    }

    pub fn is_empty(&self) -> bool {
        match self {
            Domain::Real { intervals, nan } => intervals.is_empty() && !nan,
            Domain::Int(r) => r.is_empty(),
            Domain::Finite { allowed, .. } => *allowed == 0,
        }
    }

    /// The values that satisfy `op value` (for this domain's type).
    pub fn of_comparison(ty: &Type, op: CmpOp, value: Value) -> Domain {
        let full = Domain::full(ty);
        match (full, value) {
            (Domain::Real { .. }, v) => {
                let v = match v {
                    Value::F64(f) => f,
                    Value::I64(i) => i as f64,
                    _ => return Domain::Real { intervals: vec![], nan: false },
                };
                if v.is_nan() {
                    // Nothing compares with NaN.
                    return Domain::Real { intervals: vec![], nan: false };
                }
                let (ninf, inf) = (f64::NEG_INFINITY, f64::INFINITY);
                // Nothing is below -inf or above inf (`next_down(-inf)` is -inf).
                let below = |hi: f64| if v == ninf { None } else { Interval::new(ninf, hi.next_down()) };
                let above = |lo: f64| if v == inf { None } else { Interval::new(lo.next_up(), inf) };
                let intervals = match op {
                    CmpOp::Lt => vec![below(v)],
                    CmpOp::Le => vec![Interval::new(ninf, v)],
                    CmpOp::Gt => vec![above(v)],
                    CmpOp::Ge => vec![Interval::new(v, inf)],
                    CmpOp::Eq => vec![Interval::new(v, v)],
                    CmpOp::Ne => vec![below(v), above(v)],
                };
                Domain::Real { intervals: intervals.into_iter().flatten().collect(), nan: false }
            }
            (Domain::Int(_), v) => {
                let v = match v {
                    Value::I64(i) => i as i128,
                    _ => return Domain::Int(vec![]),
                };
                let (min, max) = (i64::MIN as i128, i64::MAX as i128);
                let ranges = match op {
                    CmpOp::Lt => vec![(min, v - 1)],
                    CmpOp::Le => vec![(min, v)],
                    CmpOp::Gt => vec![(v + 1, max)],
                    CmpOp::Ge => vec![(v, max)],
                    CmpOp::Eq => vec![(v, v)],
                    CmpOp::Ne => vec![(min, v - 1), (v + 1, max)],
                };
                Domain::Int(ranges.into_iter().filter(|(a, b)| a <= b).collect())
            }
            (Domain::Finite { n, .. }, v) => {
                let i = match v {
                    Value::Bool(b) => u32::from(b),
                    Value::Symbol(s) => s,
                    _ => return Domain::Finite { allowed: 0, n },
                };
                let bit = if i < 64 { 1u64 << i } else { 0 };
                let all = if n == 64 { u64::MAX } else { (1u64 << n) - 1 };
                let allowed = match op {
                    CmpOp::Eq => bit,
                    CmpOp::Ne => all & !bit,
                    _ => all, // ordering on finite types is refused by the type checker
                };
                Domain::Finite { allowed, n }
            }
        }
    }

    /// The values that satisfy a constant field check; `None` when the check
    /// involves a variable (beyond what this domain decides exactly).
    pub fn of_check(ty: &Type, check: &FieldCheck) -> Option<Domain> {
        match check {
            // Binding a value tests nothing (NaN binds too).
            FieldCheck::Bind(_) => Some(Domain::full(ty)),
            FieldCheck::Compare { op, rhs: Operand::Value(v) } => Some(Domain::of_comparison(ty, *op, *v)),
            FieldCheck::Range { lo: Operand::Value(lo), hi: Operand::Value(hi), inclusive } => {
                let lo = Domain::of_comparison(ty, CmpOp::Ge, *lo);
                let hi = Domain::of_comparison(ty, if *inclusive { CmpOp::Le } else { CmpOp::Lt }, *hi);
                Some(lo.intersect(&hi))
            }
            _ => None,
        }
    }

    /// The values in both.
    pub fn intersect(&self, other: &Domain) -> Domain {
        match (self, other) {
            (Domain::Real { intervals: a, nan: na }, Domain::Real { intervals: b, nan: nb }) => {
                let mut out = Vec::new();
                for x in a {
                    for y in b {
                        if let Some(i) = x.intersect(*y) {
                            out.push(i);
                        }
                    }
                }
                out.sort_by(|x, y| x.lo.total_cmp(&y.lo));
                Domain::Real { intervals: out, nan: *na && *nb }
            }
            (Domain::Int(a), Domain::Int(b)) => {
                let mut out = Vec::new();
                for (a0, a1) in a {
                    for (b0, b1) in b {
                        let (lo, hi) = (*a0.max(b0), *a1.min(b1));
                        if lo <= hi {
                            out.push((lo, hi));
                        }
                    }
                }
                out.sort();
                Domain::Int(out)
            }
            (Domain::Finite { allowed: a, n }, Domain::Finite { allowed: b, .. }) => {
                Domain::Finite { allowed: a & b, n: *n }
            }
            // Different types never meet: nothing satisfies both.
            (a, _) => {
                let mut empty = a.clone();
                empty.clear();
                empty
            }
        }
    }

    /// Drops NaN from an f64 domain.
    pub fn remove_nan(&mut self) {
        if let Domain::Real { nan, .. } = self {
            *nan = false;
        }
    }

    fn clear(&mut self) {
        match self {
            Domain::Real { intervals, nan } => {
                intervals.clear();
                *nan = false;
            }
            Domain::Int(r) => r.clear(),
            Domain::Finite { allowed, .. } => *allowed = 0,
        }
    }

    /// The values of `self` not in `other`.
    pub fn subtract(&self, other: &Domain) -> Domain {
        match (self, other) {
            (Domain::Real { intervals, nan }, Domain::Real { intervals: b, nan: nb }) => {
                // The complement of b, then the intersection.
                let mut comp = Vec::new();
                let mut lo = f64::NEG_INFINITY;
                for i in b {
                    if i.lo > f64::NEG_INFINITY {
                        comp.extend(Interval::new(lo, i.lo.next_down()));
                    }
                    lo = i.hi.next_up();
                    if i.hi == f64::INFINITY {
                        lo = f64::NAN; // nothing above
                    }
                }
                if !lo.is_nan() {
                    comp.extend(Interval::new(lo, f64::INFINITY));
                }
                let d = Domain::Real { intervals: intervals.clone(), nan: *nan }
                    .intersect(&Domain::Real { intervals: comp, nan: true });
                match d {
                    Domain::Real { intervals, .. } => Domain::Real { intervals, nan: *nan && !nb },
                    other => other,
                }
            }
            (Domain::Int(a), Domain::Int(b)) => {
                let mut comp = Vec::new();
                let mut lo = i64::MIN as i128;
                for (b0, b1) in b {
                    if *b0 > lo {
                        comp.push((lo, b0 - 1));
                    }
                    lo = b1 + 1;
                }
                if lo <= i64::MAX as i128 {
                    comp.push((lo, i64::MAX as i128));
                }
                Domain::Int(a.clone()).intersect(&Domain::Int(comp))
            }
            (Domain::Finite { allowed: a, n }, Domain::Finite { allowed: b, .. }) => {
                Domain::Finite { allowed: a & !b, n: *n }
            }
            (a, _) => a.clone(),
        }
    }

    /// One value of the domain, as JSON, for witnesses (`None` if empty).
    pub fn sample(&self, ty: &Type) -> Option<serde_json::Value> {
        use serde_json::json;
        match (self, ty) {
            (Domain::Real { intervals, nan }, _) => match intervals.first() {
                Some(i) => Some(match i.sample() {
                    // JSON has no infinities: as the wire protocol writes them.
                    f if f == f64::INFINITY => json!("inf"),
                    f if f == f64::NEG_INFINITY => json!("-inf"),
                    f => json!(f),
                }),
                None if *nan => Some(json!("NaN")),
                None => None,
            },
            (Domain::Int(r), _) => r.first().map(|(lo, hi)| {
                let v = if *lo <= 0 && 0 <= *hi {
                    0
                } else if lo.abs() < hi.abs() {
                    *lo
                } else {
                    *hi
                };
                json!(v as i64)
            }),
            (Domain::Finite { allowed, .. }, Type::Bool) => {
                // bit 0 is `false`, bit 1 is `true`
                (*allowed != 0).then(|| json!(allowed & 1 == 0))
            }
            (Domain::Finite { allowed, .. }, Type::Symbols(s)) => {
                (0..s.len()).find(|i| *i < 64 && allowed & (1 << i) != 0).map(|i| json!(s[i]))
            }
            _ => None,
        }
    }
}
