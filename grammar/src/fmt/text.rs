//! How each AST node is written: one function per node, from the node to
//! its text (or its cells, where a block aligns them in columns). No layout
//! decisions here: lines, blanks and comments are the formatter's.

use super::*;

/// A string literal, quoted and escaped.
pub(super) fn string(value: &str) -> String {
    let mut out = String::with_capacity(value.len() + 2);
    out.push('"');
    for c in value.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// `text "description"`, or `text`.
pub(super) fn with_description(text: String, description: &Option<StrLit>) -> String {
    match description {
        Some(d) => format!("{text} {}", string(&d.value)),
        None => text,
    }
}

/// A duration in the largest unit that divides it.
pub(super) fn duration(nanos: u64) -> String {
    const UNITS: [(u64, &str); 5] =
        [(60_000_000_000, "min"), (1_000_000_000, "s"), (1_000_000, "ms"), (1_000, "us"), (1, "ns")];
    if nanos == 0 {
        return "0s".into();
    }
    let (scale, unit) =
        UNITS.iter().find(|(scale, _)| nanos.checked_rem(*scale) == Some(0)).copied().unwrap_or((1, "ns"));
    format!("{}{unit}", nanos / scale)
}

/// A float that reads back as the same value, with a `.` or an exponent.
pub(super) fn float(value: f64) -> String {
    if !value.is_finite() {
        // `NaN`, `inf`, `-inf`: the literals of the language.
        return format!("{value}");
    }
    let text = format!("{value:?}");
    if text.contains(['.', 'e', 'E']) {
        text
    } else {
        format!("{text}.0")
    }
}

pub(super) fn literal(l: &Literal) -> String {
    match &l.value {
        LiteralValue::Float(f) => float(*f),
        LiteralValue::Int(i) => i.to_string(),
        LiteralValue::Bool(b) => b.to_string(),
        LiteralValue::Symbol(s) => s.clone(),
    }
}

pub(super) fn names(idents: &[Ident]) -> String {
    idents.iter().map(|i| i.name.as_str()).collect::<Vec<_>>().join(", ")
}

pub(super) fn state_decl(d: &StateDecl) -> Vec<String> {
    let mut text = d.name.name.clone();
    if d.initial.is_some() {
        text.push_str(" initial");
    }
    if d.is_final.is_some() {
        text.push_str(" final");
    }
    let mut cells = vec![text];
    cells.extend(d.description.as_ref().map(|d| string(&d.value)));
    cells
}

pub(super) fn event_decl(e: &EventDecl) -> String {
    let mut text = format!("event {}", e.name.name);
    if !e.fields.is_empty() {
        let fields: Vec<String> = e
            .fields
            .iter()
            .map(|f| {
                let ty = match &f.ty {
                    FieldType::F64 => "f64".to_string(),
                    FieldType::I64 => "i64".to_string(),
                    FieldType::Bool => "bool".to_string(),
                    FieldType::Symbols(s) => format!("{{{}}}", names(s)),
                };
                format!("{}: {ty}", f.name.name)
            })
            .collect();
        text = format!("{text} {{ {} }}", fields.join(", "));
    }
    with_description(text, &e.description)
}

pub(super) fn action(a: &Action) -> String {
    let mut text = a.mode.verb().to_string();
    if let Some(f) = &a.function {
        text = format!("{text} {}()", f.name);
    }
    if !a.from.is_empty() {
        text = format!("{text} from {}", names(&a.from));
    }
    if !a.to.is_empty() {
        text = format!("{text} to {}", names(&a.to));
    }
    text
}

pub(super) fn table_entry(e: &TableEntry) -> Vec<String> {
    let selector = match &e.selector {
        Selector::States(s) => names(s),
        Selector::Wildcard(_) => "_".into(),
    };
    vec![selector, format!("=> {}", action(&e.action))]
}

pub(super) fn fsm_line(line: &FsmLine) -> (u8, Vec<String>) {
    match line {
        FsmLine::State(s) => {
            let initial = if s.initial.is_some() { " initial" } else { "" };
            (FSM_STATE, vec![format!("{}{initial}", s.name.name), format!("=> {}", action(&s.action))])
        }
        FsmLine::Transition(t) => {
            let trigger = match &t.trigger {
                Trigger::State(s) => state_test(s),
                Trigger::Event(e) => e.name.clone(),
            };
            (TRANSITION, vec![t.from.name.clone(), format!("-> {}", t.to.name), format!("on {trigger}")])
        }
    }
}

pub(super) fn state_test(t: &StateTest) -> String {
    match (t.set_syntax, t.negated) {
        (true, false) => format!("state in {{{}}}", names(&t.states)),
        (true, true) => format!("state not in {{{}}}", names(&t.states)),
        (false, false) => format!("state == {}", names(&t.states)),
        (false, true) => format!("state != {}", names(&t.states)),
    }
}

pub(super) fn operand(o: &Operand) -> String {
    match o {
        Operand::Literal(l) => literal(l),
        Operand::Variable(v) => format!("?{}", v.name),
    }
}

pub(super) fn pattern(p: &Pattern) -> String {
    let mut text = p.event.name.clone();
    if !p.constraints.is_empty() {
        let constraints: Vec<String> = p
            .constraints
            .iter()
            .map(|c| match &c.test {
                FieldTest::Bind(v) => format!("{}: ?{}", c.field.name, v.name),
                FieldTest::Compare { op, rhs, .. } => format!("{} {} {}", c.field.name, op.symbol(), operand(rhs)),
                FieldTest::Range { lo, hi, inclusive } => {
                    let op = if *inclusive { "..=" } else { ".." };
                    format!("{} in {}{op}{}", c.field.name, operand(lo), operand(hi))
                }
            })
            .collect();
        text = format!("{text}({})", constraints.join(", "));
    }
    if let Some(r) = &p.run_length {
        text = format!("{text} x{}", r.count);
    }
    if let Some(w) = &p.within {
        text = format!("{text} within {}", duration(w.nanos));
    }
    text
}

pub(super) fn condition(c: &Condition) -> String {
    match c {
        Condition::State(s) => state_test(s),
        Condition::Pattern(p) => pattern(p),
        Condition::Not { pattern: p, .. } => format!("not {}", pattern(p)),
        Condition::Stale { agent, negated: false, .. } => format!("stale {}", agent.name),
        Condition::Stale { agent, negated: true, .. } => format!("not stale {}", agent.name),
    }
}

pub(super) fn event_instance(e: &EventInstance) -> String {
    let mut text = e.event.name.clone();
    if !e.arguments.is_empty() {
        let args: Vec<String> =
            e.arguments.iter().map(|a| format!("{}: {}", a.field.name, literal(&a.value))).collect();
        text = format!("{text}({})", args.join(", "));
    }
    if let Some(r) = &e.repeat {
        text = format!("{text} x{}", r.count);
    }
    if let Some(at) = &e.at {
        text = format!("{text} at {}", duration(at.nanos));
    }
    text
}

/// The keyword of a test clause and its comma-separated parts.
pub(super) fn test_clause(c: &TestClause) -> (&'static str, Vec<String>) {
    match c {
        TestClause::Given { items, .. } => {
            let parts = items
                .iter()
                .map(|g| match g {
                    GivenItem::State { state, .. } => format!("state {}", state.name),
                    GivenItem::Event(e) => event_instance(e),
                })
                .collect();
            ("given", parts)
        }
        TestClause::On { events, .. } => ("on", events.iter().map(event_instance).collect()),
        TestClause::Expect { expectations, .. } => {
            let parts = expectations
                .iter()
                .map(|e| match e {
                    Expectation::State { state, .. } => format!("state {}", state.name),
                    Expectation::Mode { agent, mode, .. } => format!("{} {}", agent.name, mode.adjective()),
                    Expectation::Runs { agent, function, .. } => format!("{} runs {}", agent.name, function.name),
                    Expectation::Link { from, to, present: true, .. } => format!("link {} -> {}", from.name, to.name),
                    Expectation::Link { from, to, present: false, .. } => {
                        format!("no link {} -> {}", from.name, to.name)
                    }
                })
                .collect();
            ("expect", parts)
        }
    }
}

/// `head a, b, c` at `indent`, continued after a comma one level deeper when
/// it would pass [`MAX_WIDTH`]; the result has no indentation on its first line.
pub(super) fn fill(indent: usize, head: &str, parts: &[String]) -> String {
    let mut text = head.to_string();
    let mut column = indent * INDENT.len() + head.len();
    for (i, part) in parts.iter().enumerate() {
        let comma = usize::from(i + 1 < parts.len());
        if i > 0 && column + 1 + part.len() + comma > MAX_WIDTH {
            text.push('\n');
            for _ in 0..=indent {
                text.push_str(INDENT);
            }
            column = (indent + 1) * INDENT.len();
        } else {
            text.push(' ');
            column += 1;
        }
        text.push_str(part);
        column += part.len();
        if comma == 1 {
            text.push(',');
            column += 1;
        }
    }
    text
}

pub(super) fn formula(f: &Formula) -> String {
    match f {
        Formula::Now(p) => predicate(p),
        Formula::Implies { premise, consequent, .. } => {
            let right = match consequent {
                Consequent::Now(q) => predicate(q),
                Consequent::Next { predicate: q, .. } => format!("next {}", predicate(q)),
                Consequent::Eventually { predicate: q, bound, .. } => {
                    let bound = match bound {
                        None => String::new(),
                        Some(Bound::Events { count, .. }) => format!(" within {count} events"),
                        Some(Bound::Time(d)) => format!(" within {}", duration(d.nanos)),
                    };
                    format!("eventually {}{bound}", predicate(q))
                }
            };
            format!("{} -> {right}", predicate(premise))
        }
    }
}

/// A property's formula in parentheses, unless they would make the property
/// fail to parse: nested too deep, or, for a formula of thousands of terms,
/// over the parser's call limit (`(P -> Q)` parses `P` twice).
pub(super) fn parenthesized(quantifier: &str, f: &Formula) -> String {
    let bare = formula(f);
    let wrapped = format!("({bare})");
    if crate::lex::max_nesting(&wrapped).0 >= crate::parse::MAX_NESTING {
        return bare;
    }
    if wrapped.len() > 4096 {
        let item = format!("property \"\" {{ {quantifier} {wrapped} }}");
        if !crate::parse(&item, FileId(0)).errors.is_empty() {
            return bare;
        }
    }
    wrapped
}

/// A predicate, with parentheses only where the tree needs them: an `or`
/// inside an `and`, a nested `or` or `and` of the same kind, and an `and` or
/// `or` under `not`.
pub(super) fn predicate(p: &Predicate) -> String {
    let grouped = |q: &Predicate| match q {
        Predicate::Or(..) | Predicate::And(..) => format!("({})", predicate(q)),
        _ => predicate(q),
    };
    match p {
        Predicate::Or(parts, _) => {
            let parts: Vec<String> =
                parts.iter().map(|q| if matches!(q, Predicate::Or(..)) { grouped(q) } else { predicate(q) }).collect();
            parts.join(" or ")
        }
        Predicate::And(parts, _) => parts.iter().map(grouped).collect::<Vec<_>>().join(" and "),
        Predicate::Not(q, _) => {
            // Iterative over chains of `not`, which may be long.
            let mut text = String::from("not ");
            let mut inner = &**q;
            while let Predicate::Not(deeper, _) = inner {
                text.push_str("not ");
                inner = deeper;
            }
            text + &grouped(inner)
        }
        Predicate::Bool(b, _) => b.to_string(),
        Predicate::State(t) => state_test(t),
        Predicate::Mode { agent, mode, .. } => format!("{} {}", agent.name, mode.adjective()),
        Predicate::Link { from, to, .. } => format!("link {} -> {}", from.name, to.name),
        Predicate::Stale { agent, .. } => format!("stale {}", agent.name),
        Predicate::Event(e) => pattern(e),
    }
}
