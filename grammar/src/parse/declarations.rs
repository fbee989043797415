//! The declarations of a file: states, agents with their events, tables
//! and FSMs, from their pest pairs.

use super::*;

impl Builder<'_> {
    pub(super) fn states_block(&mut self, pair: P) -> StatesBlock {
        let span = self.span(&pair);
        let states = pair.into_inner().map(|p| self.state_decl(p)).collect();
        StatesBlock { states, span }
    }

    pub(super) fn state_decl(&mut self, pair: P) -> StateDecl {
        let span = self.span(&pair);
        let mut decl = StateDecl {
            name: Ident { name: String::new(), span },
            initial: None,
            is_final: None,
            description: None,
            span,
        };
        for p in pair.into_inner() {
            match p.as_rule() {
                Rule::ident => decl.name = self.ident(p),
                Rule::state_flag => {
                    let flag_span = self.span(&p);
                    if p.into_inner().next().map(|f| f.as_rule()) == Some(Rule::initial_kw) {
                        decl.initial = Some(flag_span);
                    } else {
                        decl.is_final = Some(flag_span);
                    }
                }
                Rule::string => decl.description = Some(self.string(p)),
                _ => {}
            }
        }
        decl
    }

    pub(super) fn agent(&mut self, pair: P) -> Option<Agent> {
        let span = self.span(&pair);
        let mut attributes = Vec::new();
        let mut name = None;
        let mut kind = None;
        let mut description = None;
        let mut members = Vec::new();
        for p in pair.into_inner() {
            match p.as_rule() {
                Rule::attribute => attributes.push(self.attribute(p)),
                Rule::ident => name = Some(self.ident(p)),
                Rule::agent_kind => {
                    let k = match p.as_str() {
                        "sensor" => AgentKind::Sensor,
                        "actuator" => AgentKind::Actuator,
                        "processing" => AgentKind::Processing,
                        _ => AgentKind::Interface,
                    };
                    kind = Some((k, self.span(&p)));
                }
                Rule::string => description = Some(self.string(p)),
                Rule::stale_decl => {
                    let s = self.span(&p);
                    if let Some(after) = p.into_inner().next().and_then(|d| self.duration(d)) {
                        members.push(AgentMember::Stale(StaleDecl { after, span: s }));
                    }
                }
                Rule::rate_decl => {
                    let s = self.span(&p);
                    let f = p.into_inner().next()?;
                    let fs = self.span(&f);
                    let text = f.into_inner().next()?.as_str();
                    match text.parse::<f64>() {
                        Ok(hertz) if hertz.is_finite() => members.push(AgentMember::Rate(RateDecl { hertz, span: s })),
                        _ => self.literal_error(fs, "this frequency"),
                    }
                }
                Rule::commands_decl => {
                    let s = self.span(&p);
                    let targets = p.into_inner().map(|t| self.ident(t)).collect();
                    members.push(AgentMember::Commands(CommandsDecl { targets, span: s }));
                }
                Rule::event_decl => members.push(AgentMember::Event(self.event_decl(p))),
                Rule::function_decl => {
                    let s = self.span(&p);
                    let mut inner = p.into_inner();
                    let name = self.ident(inner.next()?);
                    let description = inner.next().map(|d| self.string(d));
                    members.push(AgentMember::Function(FunctionDecl { name, description, span: s }));
                }
                Rule::table => {
                    let s = self.span(&p);
                    let entries = p.into_inner().filter_map(|e| self.table_entry(e)).collect();
                    members.push(AgentMember::Table(Table { entries, span: s }));
                }
                Rule::fsm => members.push(AgentMember::Fsm(self.fsm(p)?)),
                _ => {}
            }
        }
        let (kind, kind_span) = kind?;
        Some(Agent { attributes, name: name?, kind, kind_span, description, members, span })
    }

    pub(super) fn event_decl(&mut self, pair: P) -> EventDecl {
        let span = self.span(&pair);
        let mut decl =
            EventDecl { name: Ident { name: String::new(), span }, fields: Vec::new(), description: None, span };
        for p in pair.into_inner() {
            match p.as_rule() {
                Rule::ident => decl.name = self.ident(p),
                Rule::field_list => {
                    for f in p.into_inner() {
                        let fspan = self.span(&f);
                        let mut inner = f.into_inner();
                        let (Some(n), Some(t)) = (inner.next(), inner.next()) else { continue };
                        let name = self.ident(n);
                        let ty_span = self.span(&t);
                        let Some(t) = t.into_inner().next() else { continue };
                        let ty = match t.as_rule() {
                            Rule::type_f64 => FieldType::F64,
                            Rule::type_i64 => FieldType::I64,
                            Rule::type_bool => FieldType::Bool,
                            _ => FieldType::Symbols(t.into_inner().map(|s| self.ident(s)).collect()),
                        };
                        decl.fields.push(FieldDecl { name, ty, ty_span, span: fspan });
                    }
                }
                Rule::string => decl.description = Some(self.string(p)),
                _ => {}
            }
        }
        decl
    }

    pub(super) fn table_entry(&mut self, pair: P) -> Option<TableEntry> {
        let span = self.span(&pair);
        let mut inner = pair.into_inner();
        let sel = inner.next()?;
        let first = sel.clone().into_inner().next()?;
        let selector = if first.as_rule() == Rule::wildcard {
            Selector::Wildcard(self.span(&first))
        } else {
            Selector::States(sel.into_inner().map(|p| self.ident(p)).collect())
        };
        let action = self.action(inner.next()?)?;
        Some(TableEntry { selector, action, span })
    }

    pub(super) fn action(&mut self, pair: P) -> Option<Action> {
        let span = self.span(&pair);
        let a = pair.into_inner().next()?;
        let mode = match a.as_rule() {
            Rule::run_action => Mode::Running,
            Rule::wait_action => Mode::Waiting,
            _ => Mode::Sleeping,
        };
        let mut action = Action { mode, function: None, from: Vec::new(), to: Vec::new(), span };
        for p in a.into_inner() {
            match p.as_rule() {
                Rule::call => action.function = Some(self.ident(p.into_inner().next()?)),
                Rule::links => {
                    for l in p.into_inner() {
                        let names: Vec<Ident> = l.clone().into_inner().map(|i| self.ident(i)).collect();
                        if l.as_rule() == Rule::from_links {
                            action.from = names;
                        } else {
                            action.to = names;
                        }
                    }
                }
                _ => {}
            }
        }
        Some(action)
    }

    pub(super) fn fsm(&mut self, pair: P) -> Option<Fsm> {
        let span = self.span(&pair);
        let mut lines = Vec::new();
        for p in pair.into_inner() {
            let lspan = self.span(&p);
            match p.as_rule() {
                Rule::fsm_state => {
                    let mut name = None;
                    let mut initial = None;
                    let mut action = None;
                    for q in p.into_inner() {
                        match q.as_rule() {
                            Rule::ident => name = Some(self.ident(q)),
                            Rule::initial_kw => initial = Some(self.span(&q)),
                            Rule::action => action = self.action(q),
                            _ => {}
                        }
                    }
                    lines.push(FsmLine::State(FsmState { name: name?, initial, action: action?, span: lspan }));
                }
                Rule::fsm_transition => {
                    let mut inner = p.into_inner();
                    let from = self.ident(inner.next()?);
                    let to = self.ident(inner.next()?);
                    let t = inner.next()?.into_inner().next()?;
                    let trigger = match t.as_rule() {
                        Rule::state_test => Trigger::State(self.state_test(t)?),
                        _ => Trigger::Event(self.ident(t)),
                    };
                    lines.push(FsmLine::Transition(FsmTransition { from, to, trigger, span: lspan }));
                }
                _ => {}
            }
        }
        Some(Fsm { lines, span })
    }
}
