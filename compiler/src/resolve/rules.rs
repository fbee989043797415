//! Phase 3: situation rules. Conditions are resolved against the declared
//! events and fields, literals are typed, and variables are scoped: a variable
//! is bound by `field: ?v` in a positive pattern of the rule and visible in the
//! whole rule; a variable bound inside `not` is visible only in that pattern.

use super::{types, Cx};
use crate::codes;
use crate::model::*;
use situ_grammar::ast;
use situ_grammar::diag::{Diagnostic, FileId};

pub(super) fn rule(cx: &mut Cx, file: FileId, rule: &ast::Rule) {
    let origin = Cx::origin(file, rule.name.span);
    if let Some(first) = cx.rule_names.get(&rule.name.name).copied() {
        cx.duplicate("rule", &rule.name.name, file, rule.name.span, first);
    } else {
        cx.rule_names.insert(rule.name.name.clone(), origin);
    }
    let mut scope = Vec::new();
    for c in &rule.conditions {
        if let ast::Condition::Pattern(p) = c {
            collect_binds(cx, file, p, &mut scope);
        }
    }
    let mut ok = true;
    let (mut guards, mut patterns, mut negations, mut stale) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    // Which variables have had their binding site: the first positive
    // `field: ?v` binds, every later one is an equality test.
    let mut bound = Vec::new();
    for c in &rule.conditions {
        match c {
            ast::Condition::State(test) => {
                let before = cx.diags.len();
                guards.push(cx.state_set(file, test));
                ok &= cx.diags.len() == before;
            }
            ast::Condition::Pattern(p) => match pattern(cx, file, p, &mut scope, &mut bound) {
                Some(p) => patterns.push(p),
                None => ok = false,
            },
            ast::Condition::Not { pattern: p, .. } => {
                // The rule's variables are bound outside: here they are
                // tested; a variable first bound here is local to `not`.
                let mut local = scope.clone();
                let mut local_bound = vec![true; scope.len()];
                collect_binds(cx, file, p, &mut local);
                match pattern(cx, file, p, &mut local, &mut local_bound) {
                    Some(p) => negations.push(p),
                    None => ok = false,
                }
            }
            ast::Condition::Stale { agent, negated, span } => match stale_agent(cx, file, agent) {
                Some(a) => stale.push(StaleTest { agent: a, negated: *negated, origin: Cx::origin(file, *span) }),
                None => ok = false,
            },
        }
    }
    let target = cx.state(file, &rule.target);
    if let (true, Some(target)) = (ok, target) {
        cx.model.rules.push(Rule {
            name: rule.name.name.clone(),
            salience: rule.salience.as_ref().map_or(0, |s| s.value),
            description: rule.description.as_ref().map(|d| d.value.clone()),
            guards,
            patterns,
            negations,
            stale,
            variables: scope,
            target,
            origin,
            item: Cx::origin(file, rule.span),
        });
    }
}

/// The agent of a `stale AGENT` test; it must declare `stale after`.
pub(super) fn stale_agent(cx: &mut Cx, file: FileId, name: &ast::Ident) -> Option<AgentId> {
    let agent = cx.agent(file, name)?;
    if cx.model.agent(agent).stale_after.is_none() {
        cx.diags.push(
            Diagnostic::error(
                codes::NEVER_STALE,
                format!("agent `{}` never goes stale", name.name),
                file,
                name.span,
                "has no `stale after`",
            )
            .with_label(cx.model.agent(agent).origin.file, cx.model.agent(agent).origin.span, "declared here")
            .with_help(format!("add `stale after 200ms` (or the time you need) to agent `{}`", name.name)),
        );
        return None;
    }
    Some(agent)
}

/// Defines the variables a pattern binds. Lookups are silent here: the
/// pattern's names are reported when the pattern itself is resolved.
pub(super) fn collect_binds(cx: &mut Cx, file: FileId, pat: &ast::Pattern, scope: &mut Vec<Variable>) {
    let Some(&event) = cx.events.get(&pat.event.name) else { return };
    for c in &pat.constraints {
        let ast::FieldTest::Bind(var) = &c.test else { continue };
        let Some(field) = cx.model.event(event).field(&c.field.name) else { continue };
        let ty = cx.model.event(event).fields[field].ty.clone();
        match scope.iter().find(|v| v.name == var.name) {
            Some(v) if !v.ty.comparable(&ty) => {
                let d = variable_type(file, var, &ty, v);
                cx.diags.push(d);
            }
            Some(_) => {}
            None => scope.push(Variable { name: var.name.clone(), ty, origin: Cx::origin(file, var.span) }),
        }
    }
}

fn variable_type(file: FileId, var: &ast::Ident, ty: &Type, bound: &Variable) -> Diagnostic {
    Diagnostic::error(
        codes::VARIABLE_TYPE,
        format!("variable `?{}` is {}, but used here as {}", var.name, bound.ty.describe(), ty.describe()),
        file,
        var.span,
        format!("used as {}", ty.describe()),
    )
    .with_label(bound.origin.file, bound.origin.span, format!("bound to a {} here", bound.ty.describe()))
    .with_help("a variable compares values of one type; use another variable")
}

/// Resolves one pattern; `None` when something in it does not resolve.
/// `bound[v]` says whether `?v` already has its binding site: a `field: ?v`
/// of a variable not bound yet becomes its [`FieldCheck::Bind`], any other
/// one an equality test with it.
pub(super) fn pattern(
    cx: &mut Cx,
    file: FileId,
    pat: &ast::Pattern,
    scope: &mut [Variable],
    bound: &mut Vec<bool>,
) -> Option<Pattern> {
    bound.resize(scope.len(), false);
    let event = cx.event(file, &pat.event)?;
    let mut ok = true;
    let mut tests = Vec::new();
    for c in &pat.constraints {
        let Some(field) = cx.field(file, event, &c.field) else {
            ok = false;
            continue;
        };
        let ty = cx.model.event(event).fields[field].ty.clone();
        let name = c.field.name.as_str();
        let check = match &c.test {
            ast::FieldTest::Bind(var) => scope.iter().position(|v| v.name == var.name).map(|v| {
                if std::mem::replace(&mut bound[v], true) {
                    FieldCheck::Compare { op: ast::CmpOp::Eq, rhs: Operand::Var(v) }
                } else {
                    FieldCheck::Bind(v)
                }
            }),
            ast::FieldTest::Compare { op, op_span, rhs } => {
                let fits =
                    !op.is_ordering() || types::ordered(cx, file, &ty, name, *op_span, &format!("`{}`", op.symbol()));
                let rhs = operand(cx, file, rhs, &ty, name, scope);
                rhs.filter(|_| fits).map(|rhs| FieldCheck::Compare { op: *op, rhs })
            }
            ast::FieldTest::Range { lo, hi, inclusive } => {
                let fits = types::ordered(cx, file, &ty, name, c.span, "a range");
                let lo = operand(cx, file, lo, &ty, name, scope);
                let hi = operand(cx, file, hi, &ty, name, scope);
                match (fits, lo, hi) {
                    (true, Some(lo), Some(hi)) => Some(FieldCheck::Range { lo, hi, inclusive: *inclusive }),
                    _ => None,
                }
            }
        };
        match check {
            Some(check) => tests.push(FieldTest { field, check, origin: Cx::origin(file, c.span) }),
            None => ok = false,
        }
    }
    let run_length = match &pat.run_length {
        Some(rl) => {
            ok &= cx.positive(file, rl.count, rl.span, "a run length");
            rl.count
        }
        None => 1,
    };
    if let Some(w) = &pat.within {
        ok &= cx.positive(file, w.nanos, w.span, "a window");
    }
    ok.then(|| Pattern {
        event,
        tests,
        run_length,
        within: pat.within.map(|w| w.nanos),
        origin: Cx::origin(file, pat.span),
    })
}

fn operand(
    cx: &mut Cx,
    file: FileId,
    op: &ast::Operand,
    ty: &Type,
    field: &str,
    scope: &[Variable],
) -> Option<Operand> {
    match op {
        ast::Operand::Literal(lit) => {
            let value = types::literal(cx, file, lit, ty, field)?;
            if matches!(value, Value::F64(f) if f.is_nan()) {
                // NaN satisfies no comparison (not even `!=`): the test
                // would never hold.
                cx.diags.push(
                    Diagnostic::error(
                        codes::BAD_OPERATOR,
                        format!("a comparison of field `{field}` with `NaN` never holds"),
                        file,
                        lit.span,
                        "NaN is neither equal to, different from nor ordered with any value",
                    )
                    .with_help(format!(
                        "`NaN` is for test and script payloads; to react to a NaN `{field}`, require the event and exclude both `{field} < 0.0` and `{field} >= 0.0` with `not`"
                    )),
                );
                return None;
            }
            Some(Operand::Value(value))
        }
        ast::Operand::Variable(var) => {
            let Some(id) = scope.iter().position(|v| v.name == var.name) else {
                cx.diags.push(
                    Diagnostic::error(
                        codes::UNBOUND_VARIABLE,
                        format!("variable `?{}` is not bound", var.name),
                        file,
                        var.span,
                        "never bound",
                    )
                    .with_help(format!(
                        "bind it in a pattern of this rule that is not under `not`, e.g. `EVENT(field: ?{})`",
                        var.name
                    )),
                );
                return None;
            };
            if !scope[id].ty.comparable(ty) {
                cx.diags.push(variable_type(file, var, ty, &scope[id]));
                return None;
            }
            Some(Operand::Var(id))
        }
    }
}
