//! The AST of `script` items (`situ run --script`), built from pest pairs
//! like the rest of an item (see `parse.rs`).

use crate::ast::*;
use crate::parse::{Builder, Rule, P};

impl Builder<'_> {
    /// `script "name" { step* }`.
    pub(crate) fn script(&mut self, pair: P) -> Option<Script> {
        let span = self.span(&pair);
        let mut inner = pair.into_inner();
        let name = self.string(inner.next()?);
        let mut steps = Vec::new();
        for step in inner {
            steps.extend(self.script_step(step));
        }
        Some(Script { name, steps, span })
    }

    fn script_step(&mut self, pair: P) -> Option<ScriptStep> {
        let span = self.span(&pair);
        // Without the spaces and comments pest leaves at the end.
        let span = Span::new(span.start, span.start + code_len(pair.as_str()));
        let kind = pair.as_rule();
        let mut inner = pair.into_inner();
        Some(match kind {
            Rule::script_at => {
                let time = self.duration(inner.next()?)?;
                let event = self.script_event(inner.next()?)?;
                ScriptStep::At { time, event, span }
            }
            Rule::script_every => {
                let period = self.duration(inner.next()?)?;
                let event = self.script_event(inner.next()?)?;
                let from = self.duration(inner.next()?)?;
                let to = self.duration(inner.next()?)?;
                ScriptStep::Every { period, event, from, to, span }
            }
            Rule::script_silent => {
                let agent = self.ident(inner.next()?);
                let from = self.duration(inner.next()?)?;
                let to = self.duration(inner.next()?)?;
                ScriptStep::Silent { agent, from, to, span }
            }
            Rule::script_random => {
                let length = self.duration(inner.next()?)?;
                let seed_pair = inner.next()?;
                let seed_span = self.span(&seed_pair);
                let seed = self.uint(seed_pair)?;
                let from = match inner.next() {
                    Some(p) => Some(self.duration(p)?),
                    None => None,
                };
                ScriptStep::Random { length, seed, seed_span, from, span }
            }
            _ => return None,
        })
    }

    fn script_event(&mut self, pair: P) -> Option<ScriptEvent> {
        let span = self.span(&pair);
        let span = Span::new(span.start, span.start + code_len(pair.as_str()));
        let mut agent = None;
        let mut event = None;
        let mut arguments = Vec::new();
        for p in pair.into_inner() {
            match p.as_rule() {
                Rule::script_agent => agent = Some(self.ident(p.into_inner().next()?)),
                Rule::ident => event = Some(self.ident(p)),
                Rule::arguments => arguments = self.arguments(p)?,
                _ => {}
            }
        }
        Some(ScriptEvent { agent, event: event?, arguments, span })
    }
}

/// The length of `text` up to the end of its last token: trailing spaces and
/// `//` comments left out (strings kept whole).
fn code_len(text: &str) -> usize {
    let bytes = text.as_bytes();
    let (mut i, mut end) = (0, 0);
    while i < bytes.len() {
        match bytes[i] {
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                while i < bytes.len() && bytes[i] != b'\n' {
                    i += 1;
                }
            }
            b'"' => {
                i = crate::lex::skip_string(bytes, i);
                end = i;
            }
            c if c.is_ascii_whitespace() => i += 1,
            _ => {
                i += 1;
                end = i;
            }
        }
    }
    end
}

/// A script step as the formatter writes it, on one line, given how the
/// formatter writes durations and literals.
pub(crate) fn step_text(step: &ScriptStep, short: fn(u64) -> String, literal: fn(&Literal) -> String) -> String {
    // Times of a timeline read best in seconds (`90.5s`, `300s`), short
    // ones in their own unit (`100ms`).
    let duration = |nanos: u64| {
        if nanos >= 1_000_000_000 && nanos.is_multiple_of(1_000_000) {
            let (whole, ms) = (nanos / 1_000_000_000, nanos / 1_000_000 % 1000);
            if ms == 0 {
                format!("{whole}s")
            } else {
                format!("{whole}.{}s", format!("{ms:03}").trim_end_matches('0'))
            }
        } else {
            short(nanos)
        }
    };
    let event = |e: &ScriptEvent| {
        let mut text = match &e.agent {
            Some(a) => format!("{}.{}", a.name, e.event.name),
            None => e.event.name.clone(),
        };
        if !e.arguments.is_empty() {
            let args: Vec<String> =
                e.arguments.iter().map(|a| format!("{}: {}", a.field.name, literal(&a.value))).collect();
            text = format!("{text}({})", args.join(", "));
        }
        text
    };
    match step {
        ScriptStep::At { time, event: e, .. } => format!("at {} {}", duration(time.nanos), event(e)),
        ScriptStep::Every { period, event: e, from, to, .. } => format!(
            "every {} {} from {} to {}",
            duration(period.nanos),
            event(e),
            duration(from.nanos),
            duration(to.nanos)
        ),
        ScriptStep::Silent { agent, from, to, .. } => {
            format!("silent {} from {} to {}", agent.name, duration(from.nanos), duration(to.nanos))
        }
        ScriptStep::Random { length, seed, from, .. } => {
            let mut text = format!("random {} seed {seed}", duration(length.nanos));
            if let Some(f) = from {
                text = format!("{text} from {}", duration(f.nanos));
            }
            text
        }
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn code_ends_before_trailing_comments() {
        assert_eq!(super::code_len("at 1s X   // note\n  "), 7);
        assert_eq!(super::code_len("at 1s X(a: \"//\") "), 16);
        assert_eq!(super::code_len("  "), 0);
    }
}
