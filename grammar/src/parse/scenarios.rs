//! Tests and properties: event instances, expectations and formulas.

use super::*;

impl Builder<'_> {
    pub(super) fn test(&mut self, pair: P) -> Option<Test> {
        let span = self.span(&pair);
        let mut inner = pair.into_inner();
        let name = self.string(inner.next()?);
        let mut clauses = Vec::new();
        for c in inner {
            let cspan = self.span(&c);
            match c.as_rule() {
                Rule::given_clause => {
                    let mut items = Vec::new();
                    for g in c.into_inner() {
                        let g = g.into_inner().next()?;
                        if g.as_rule() == Rule::given_state {
                            let s = self.span(&g);
                            items.push(GivenItem::State { state: self.ident(g.into_inner().next()?), span: s });
                        } else {
                            items.push(GivenItem::Event(self.event_instance(g)?));
                        }
                    }
                    clauses.push(TestClause::Given { items, span: cspan });
                }
                Rule::on_clause => {
                    let events = c.into_inner().filter_map(|e| self.event_instance(e)).collect();
                    clauses.push(TestClause::On { events, span: cspan });
                }
                Rule::expect_clause => {
                    let mut expectations = Vec::new();
                    for e in c.into_inner() {
                        expectations.push(self.expectation(e)?);
                    }
                    clauses.push(TestClause::Expect { expectations, span: cspan });
                }
                _ => {}
            }
        }
        Some(Test { name, clauses, span })
    }

    pub(super) fn event_instance(&mut self, pair: P) -> Option<EventInstance> {
        let span = self.span(&pair);
        let mut event = None;
        let mut arguments = Vec::new();
        let mut repeat = None;
        let mut at = None;
        for p in pair.into_inner() {
            match p.as_rule() {
                Rule::ident => event = Some(self.ident(p)),
                Rule::arguments => arguments = self.arguments(p)?,
                Rule::run_length => repeat = self.run_length(p),
                Rule::at_time => at = self.duration(p.into_inner().next()?),
                _ => {}
            }
        }
        Some(EventInstance { event: event?, arguments, repeat, at, span })
    }

    /// `(field: value, …)` of an event instance; a literal out of range is
    /// reported and its argument left out.
    pub(crate) fn arguments(&mut self, pair: P) -> Option<Vec<Argument>> {
        let mut arguments = Vec::new();
        for a in pair.into_inner() {
            let span = self.span(&a);
            let mut ai = a.into_inner();
            let field = self.ident(ai.next()?);
            let Some(value) = self.literal(ai.next()?) else { continue };
            arguments.push(Argument { field, value, span });
        }
        Some(arguments)
    }

    pub(super) fn expectation(&mut self, pair: P) -> Option<Expectation> {
        let e = pair.into_inner().next()?;
        let span = self.span(&e);
        let kind = e.as_rule();
        let mut inner = e.into_inner();
        Some(match kind {
            Rule::expect_state => Expectation::State { state: self.ident(inner.next()?), span },
            Rule::expect_link | Rule::expect_no_link => {
                let from = self.ident(inner.next()?);
                let to = self.ident(inner.next()?);
                Expectation::Link { from, to, present: kind == Rule::expect_link, span }
            }
            Rule::expect_runs => {
                let agent = self.ident(inner.next()?);
                let function = self.ident(inner.next()?);
                Expectation::Runs { agent, function, span }
            }
            _ => {
                let agent = self.ident(inner.next()?);
                let mode = mode_word(inner.next()?.as_str());
                Expectation::Mode { agent, mode, span }
            }
        })
    }

    pub(super) fn property(&mut self, pair: P) -> Option<Property> {
        let span = self.span(&pair);
        let mut inner = pair.into_inner();
        let name = self.string(inner.next()?);
        let quantifier = if inner.next()?.as_str() == "always" { Quantifier::Always } else { Quantifier::Never };
        let formula = self.formula(inner.next()?)?;
        Some(Property { name, quantifier, formula, span })
    }

    pub(super) fn formula(&mut self, pair: P) -> Option<Formula> {
        let span = self.span(&pair);
        let mut inner = pair.into_inner();
        let first = inner.next()?;
        if first.as_rule() == Rule::formula {
            return self.formula(first);
        }
        let premise = self.predicate(first)?;
        let Some(c) = inner.next() else { return Some(Formula::Now(premise)) };
        let c = c.into_inner().next()?;
        let cspan = self.span(&c);
        let consequent = match c.as_rule() {
            Rule::next_q => Consequent::Next { predicate: self.predicate(c.into_inner().next()?)?, span: cspan },
            Rule::eventually_q => {
                let mut ci = c.into_inner();
                let predicate = self.predicate(ci.next()?)?;
                let bound = match ci.next() {
                    Some(b) => {
                        let b = b.into_inner().next()?;
                        let bspan = self.span(&b);
                        if b.as_rule() == Rule::event_bound {
                            Some(Bound::Events { count: self.uint(b.into_inner().next()?)?, span: bspan })
                        } else {
                            Some(Bound::Time(self.duration(b)?))
                        }
                    }
                    None => None,
                };
                Consequent::Eventually { predicate, bound, span: cspan }
            }
            _ => Consequent::Now(self.predicate(c)?),
        };
        Some(Formula::Implies { premise, consequent, span })
    }

    /// `predicate`, `conjunction`, `negated`, `not_p` and `atom`, flattened so
    /// that a single child does not make a one-element `Or` or `And`.
    pub(super) fn predicate(&mut self, pair: P) -> Option<Predicate> {
        let span = self.span(&pair);
        let kind = pair.as_rule();
        let mut children: Vec<P> = pair.into_inner().collect();
        match kind {
            Rule::predicate | Rule::conjunction => {
                if children.len() == 1 {
                    return self.predicate(children.pop()?);
                }
                let parts = children.into_iter().map(|c| self.predicate(c)).collect::<Option<Vec<_>>>()?;
                Some(if kind == Rule::predicate { Predicate::Or(parts, span) } else { Predicate::And(parts, span) })
            }
            Rule::negated => self.predicate(children.pop()?),
            Rule::not_p => Some(Predicate::Not(Box::new(self.predicate(children.pop()?)?), span)),
            Rule::atom => {
                let a = children.pop()?;
                let aspan = self.span(&a);
                match a.as_rule() {
                    Rule::predicate => self.predicate(a),
                    Rule::boolean => Some(Predicate::Bool(a.as_str() == "true", aspan)),
                    Rule::state_test => Some(Predicate::State(self.state_test(a)?)),
                    Rule::atom_stale => {
                        Some(Predicate::Stale { agent: self.ident(a.into_inner().next()?), span: aspan })
                    }
                    Rule::atom_link => {
                        let mut i = a.into_inner();
                        let from = self.ident(i.next()?);
                        let to = self.ident(i.next()?);
                        Some(Predicate::Link { from, to, span: aspan })
                    }
                    Rule::atom_mode => {
                        let mut i = a.into_inner();
                        let agent = self.ident(i.next()?);
                        let mode = mode_word(i.next()?.as_str());
                        Some(Predicate::Mode { agent, mode, span: aspan })
                    }
                    _ => Some(Predicate::Event(self.pattern(a)?)),
                }
            }
            _ => None,
        }
    }
}
