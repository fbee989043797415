//! Reading a `.events` stream (bench/README.md): one event per line,
//! `TIMESTAMP NAME VALUE…`, `#` lines are comments.

use crate::model::{Ev, Event, FieldType, Value};

/// A malformed line: its 1-based number and what is wrong.
#[derive(Debug, PartialEq)]
pub struct ParseError {
    pub line: usize,
    pub msg: String,
}

/// Parses a whole stream. Comment lines (first non-blank character `#`) and
/// blank lines are skipped and not counted as events.
pub fn parse(bytes: &[u8]) -> Result<Vec<Event>, ParseError> {
    // One event per line at most: a cheap upper bound that avoids regrowing.
    let mut events = Vec::with_capacity(bytes.iter().filter(|&&b| b == b'\n').count() + 1);
    for (i, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let n = i + 1;
        let line = std::str::from_utf8(raw)
            .map_err(|_| ParseError { line: n, msg: "the line is not valid UTF-8".to_string() })?
            .trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        events.push(parse_line(line, n).map_err(|msg| ParseError { line: n, msg })?);
    }
    Ok(events)
}

/// Parses one event line (not a comment, not blank).
pub fn parse_line(line: &str, n: usize) -> Result<Event, String> {
    let mut words = line.split_ascii_whitespace();
    let t_word = words.next().ok_or("empty line")?;
    let t: u64 = t_word
        .parse()
        .map_err(|_| format!("bad timestamp `{t_word}`: expected a non-negative integer of nanoseconds"))?;
    let name = words.next().ok_or_else(|| format!("timestamp `{t_word}` without an event name"))?;
    let ev = Ev::from_name(name).ok_or_else(|| format!("unknown event `{name}`"))?;
    let fields = ev.fields();
    let mut p = [Value::None; 2];
    for (k, ty) in fields.iter().enumerate() {
        let w = words
            .next()
            .ok_or_else(|| format!("event `{name}` has {} payload field(s), the line gives {k}", fields.len()))?;
        p[k] = match *ty {
            FieldType::F64 => match w.parse::<f64>() {
                Ok(x) if w.bytes().any(|b| b.is_ascii_digit()) => Value::F64(x),
                _ => return Err(format!("field {} of `{name}`: `{w}` is not an f64", k + 1)),
            },
            FieldType::I64 => {
                Value::I64(w.parse().map_err(|_| format!("field {} of `{name}`: `{w}` is not an i64", k + 1))?)
            }
            FieldType::Sym(symbols) => match symbols.iter().position(|s| *s == w) {
                Some(s) => Value::Sym(s as u8),
                None => {
                    return Err(format!("field {} of `{name}`: `{w}` is not one of {{{}}}", k + 1, symbols.join(", ")))
                }
            },
        };
    }
    if let Some(extra) = words.next() {
        return Err(format!("event `{name}` has {} payload field(s); unexpected `{extra}`", fields.len()));
    }
    Ok(Event { t, agent: ev.agent(), ev, line: u32::try_from(n).unwrap_or(u32::MAX), p })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Agent;

    #[test]
    fn parses_the_readme_example() {
        let text = "# situ events v1 rules/outdoor.situ seed=1\n\
                    10000000 LOFIX 0.250\n\
                    20000000 LAOBS 12.500 0.500\n\
                    \n\
                    30000000 RFRT 0.020 left\n\
                    35000000 LAOBN\n\
                    40000000 DRFAULT -7\n\
                    50000000 SVSTOP danger\r\n";
        let evs = parse(text.as_bytes()).unwrap();
        assert_eq!(evs.len(), 6);
        assert_eq!((evs[0].t, evs[0].ev, evs[0].agent), (10_000_000, Ev::LOFIX, Agent::Localization));
        assert_eq!(evs[0].p, [Value::F64(0.25), Value::None]);
        assert_eq!(evs[1].p, [Value::F64(12.5), Value::F64(0.5)]);
        assert_eq!(evs[2].p, [Value::F64(0.02), Value::Sym(0)]);
        assert_eq!((evs[2].line, evs[3].ev, evs[3].p), (5, Ev::LAOBN, [Value::None; 2]));
        assert_eq!(evs[4].p[0], Value::I64(-7));
        assert_eq!(evs[5].p[0], Value::Sym(2));
    }

    fn err(text: &str) -> ParseError {
        parse(text.as_bytes()).unwrap_err()
    }

    #[test]
    fn malformed_lines_are_errors_with_their_line() {
        let e = err("# header\n10 LAOBN\n20 LAOBZ\n");
        assert_eq!(e.line, 3);
        assert!(e.msg.contains("unknown event `LAOBZ`"), "{}", e.msg);

        let e = err("10 LAOBS 12.000\n");
        assert_eq!(e.line, 1);
        assert!(e.msg.contains("has 2 payload field(s), the line gives 1"), "{}", e.msg);

        let e = err("10 LAOBN 1.000\n");
        assert!(e.msg.contains("unexpected `1.000`"), "{}", e.msg);

        assert!(err("10 LOFIX abc\n").msg.contains("not an f64"));
        assert!(err("10 LOFIX .\n").msg.contains("not an f64"));
        assert!(err("10 DRFAULT 1.5\n").msg.contains("not an i64"));
        assert!(err("10 RFRT 0.020 up\n").msg.contains("not one of {left, right}"));
        assert!(err("-10 TCHB\n").msg.contains("bad timestamp"));
        assert!(err("1.5 TCHB\n").msg.contains("bad timestamp"));
        assert!(err("10\n").msg.contains("without an event name"));
        let e = parse(b"10 TCHB\n20 TC\xffHB\n").unwrap_err();
        assert_eq!((e.line, e.msg.as_str()), (2, "the line is not valid UTF-8"));
    }
}
