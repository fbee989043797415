//! Rules: conditions, patterns, constraints and their operands.

use super::*;

impl Builder<'_> {
    pub(super) fn rule(&mut self, pair: P) -> Option<Rule_> {
        let span = self.span(&pair);
        let mut attributes = Vec::new();
        let mut idents = Vec::new();
        let mut salience = None;
        let mut description = None;
        let mut conditions = Vec::new();
        for p in pair.into_inner() {
            match p.as_rule() {
                Rule::attribute => attributes.push(self.attribute(p)),
                Rule::ident => idents.push(self.ident(p)),
                Rule::salience => {
                    let s = self.span(&p);
                    let value = self.int(p.into_inner().next()?)?;
                    salience = Some(Salience { value, span: s });
                }
                Rule::string => description = Some(self.string(p)),
                Rule::condition => {
                    for term in p.into_inner() {
                        if let Some(c) = self.cond_term(term) {
                            conditions.push(c);
                        }
                    }
                }
                _ => {}
            }
        }
        let mut idents = idents.into_iter();
        let name = idents.next()?;
        let target = idents.next()?;
        Some(Rule_ { attributes, name, salience, description, conditions, target, span })
    }

    pub(super) fn cond_term(&mut self, pair: P) -> Option<Condition> {
        let inner = pair.into_inner().next()?;
        Some(match inner.as_rule() {
            Rule::state_test => Condition::State(self.state_test(inner)?),
            Rule::stale_test => {
                let span = self.span(&inner);
                let mut negated = false;
                let mut agent = None;
                for p in inner.into_inner() {
                    match p.as_rule() {
                        Rule::not_kw => negated = true,
                        _ => agent = Some(self.ident(p)),
                    }
                }
                Condition::Stale { agent: agent?, negated, span }
            }
            Rule::negation => {
                let span = self.span(&inner);
                Condition::Not { pattern: self.pattern(inner.into_inner().next()?)?, span }
            }
            _ => Condition::Pattern(self.pattern(inner)?),
        })
    }

    pub(super) fn state_test(&mut self, pair: P) -> Option<StateTest> {
        let span = self.span(&pair);
        let t = pair.into_inner().next()?;
        let (negated, set_syntax) = match t.as_rule() {
            Rule::state_in => (false, true),
            Rule::state_not_in => (true, true),
            Rule::state_eq => (false, false),
            _ => (true, false),
        };
        let states = t
            .into_inner()
            .flat_map(|p| if p.as_rule() == Rule::state_set { p.into_inner().collect::<Vec<_>>() } else { vec![p] })
            .map(|p| self.ident(p))
            .collect();
        Some(StateTest { negated, set_syntax, states, span })
    }

    pub(super) fn pattern(&mut self, pair: P) -> Option<Pattern> {
        let span = self.span(&pair);
        let mut event = None;
        let mut constraints = Vec::new();
        let mut run_length = None;
        let mut within = None;
        for p in pair.into_inner() {
            match p.as_rule() {
                Rule::ident => event = Some(self.ident(p)),
                Rule::constraints => {
                    for c in p.into_inner() {
                        if let Some(c) = self.constraint(c) {
                            constraints.push(c);
                        }
                    }
                }
                Rule::run_length => run_length = self.run_length(p),
                Rule::window => within = self.duration(p.into_inner().next()?),
                _ => {}
            }
        }
        Some(Pattern { event: event?, constraints, run_length, within, span })
    }

    pub(super) fn run_length(&mut self, pair: P) -> Option<RunLength> {
        let span = self.span(&pair);
        let count = self.uint(pair.into_inner().next()?)?;
        Some(RunLength { count, span })
    }

    pub(super) fn constraint(&mut self, pair: P) -> Option<Constraint> {
        let span = self.span(&pair);
        let mut inner = pair.into_inner();
        let field = self.ident(inner.next()?);
        let t = inner.next()?;
        let test = match t.as_rule() {
            Rule::binding => {
                let v = t.into_inner().next()?;
                let s = self.span(&v);
                FieldTest::Bind(Ident { name: v.as_str()[1..].to_string(), span: s })
            }
            Rule::range_test => {
                let mut r = t.into_inner();
                let lo = self.operand(r.next()?)?;
                let inclusive = r.next()?.as_str() == "..=";
                let hi = self.operand(r.next()?)?;
                FieldTest::Range { lo, hi, inclusive }
            }
            _ => {
                let mut r = t.into_inner();
                let o = r.next()?;
                let op_span = self.span(&o);
                let op = match o.as_str() {
                    "==" => CmpOp::Eq,
                    "!=" => CmpOp::Ne,
                    "<=" => CmpOp::Le,
                    ">=" => CmpOp::Ge,
                    "<" => CmpOp::Lt,
                    _ => CmpOp::Gt,
                };
                FieldTest::Compare { op, op_span, rhs: self.operand(r.next()?)? }
            }
        };
        Some(Constraint { field, test, span })
    }

    pub(super) fn operand(&mut self, pair: P) -> Option<Operand> {
        let inner = pair.into_inner().next()?;
        if inner.as_rule() == Rule::variable {
            let span = self.span(&inner);
            return Some(Operand::Variable(Ident { name: inner.as_str()[1..].to_string(), span }));
        }
        Some(Operand::Literal(self.literal(inner)?))
    }

    pub(super) fn literal(&mut self, pair: P) -> Option<Literal> {
        let span = self.span(&pair);
        let inner = pair.into_inner().next()?;
        let value = match inner.as_rule() {
            Rule::float => LiteralValue::Float(self.float(inner)?),
            Rule::int => LiteralValue::Int(self.int(inner)?),
            Rule::boolean => LiteralValue::Bool(inner.as_str() == "true"),
            Rule::non_finite => LiteralValue::Float(match inner.as_str() {
                "NaN" => f64::NAN,
                "-inf" => f64::NEG_INFINITY,
                _ => f64::INFINITY,
            }),
            _ => LiteralValue::Symbol(inner.as_str().to_string()),
        };
        Some(Literal { value, span })
    }
}
