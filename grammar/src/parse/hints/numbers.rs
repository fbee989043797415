//! Numbers, durations, frequencies and run lengths.

use super::{Advice, Cx, Kind};
use crate::ast::Span;
use crate::parse::Rule;

/// The units of durations, as written in messages.
pub(super) const UNITS: &str = "`ns`, `us`, `ms`, `s` or `min`";

/// A unit of time as people write it, and what situ calls it: the unit and a
/// factor (hours become minutes).
pub(super) fn time_unit(word: &str) -> Option<(&'static str, u64)> {
    Some(match word {
        "ns" | "nsec" | "nsecs" | "nanos" | "nanosecond" | "nanoseconds" | "NS" => ("ns", 1),
        "us" | "µs" | "usec" | "usecs" | "micros" | "microsecond" | "microseconds" | "US" => ("us", 1),
        "ms" | "msec" | "msecs" | "millis" | "millisecond" | "milliseconds" | "MS" | "Ms" => ("ms", 1),
        "s" | "sec" | "secs" | "second" | "seconds" | "S" => ("s", 1),
        "min" | "m" | "mins" | "minute" | "minutes" | "MIN" | "Min" => ("min", 1),
        "h" | "hr" | "hrs" | "hour" | "hours" | "H" => ("min", 60),
        _ => return None,
    })
}

/// A unit of frequency as people write it, and the factor to hertz.
pub(super) fn freq_unit(word: &str) -> Option<u64> {
    Some(match word {
        "Hz" | "hz" | "HZ" | "hZ" | "hertz" | "Hertz" => 1,
        "kHz" | "khz" | "KHz" | "kHZ" => 1000,
        _ => return None,
    })
}

/// `value × factor` of a decimal number, written back as a number.
pub(super) fn scaled(value: &str, factor: u64) -> Option<String> {
    if factor == 1 {
        return Some(value.to_string());
    }
    let v: f64 = value.parse().ok()?;
    let r = v * factor as f64;
    (r.is_finite() && r.fract() == 0.0 && r < 1e15).then(|| format!("{}", r as u64))
}

/// Durations and frequencies: a space before the unit, no unit, or a unit
/// situ does not know (`200 ms`, `stale after 200`, `2m`, `10 Hz`, `10hz`).
pub(super) fn quantities(cx: &Cx) -> Option<Advice> {
    let (dur, freq) = (cx.exp.duration(), cx.exp.frequency());
    if !dur && !freq {
        return None;
    }
    // The number: at the error, or just before it.
    let i = cx.at().unwrap_or(cx.toks.len());
    let (ni, num) = match (cx.tok(i), i.checked_sub(1).and_then(|j| cx.tok(j))) {
        (Some(t), _) if t.kind == Kind::Number && t.start == cx.pos => (i, t),
        (_, Some(t)) if t.kind == Kind::Number && cx.text[t.end..cx.pos.max(t.end)].trim().is_empty() => (i - 1, t),
        _ => return None,
    };
    let next = cx.tok(ni + 1).filter(|n| cx.same_line(&num, n));
    let what = if dur { "duration" } else { "frequency" };
    let unit_word = next.filter(|n| n.word());
    let known = |w: &str| if dur { time_unit(w) } else { freq_unit(w).map(|f| ("Hz", f)) };
    if let Some(u) = unit_word {
        if let Some((unit, factor)) = known(u.text) {
            let value = scaled(num.text, factor)?;
            let good = format!("{value}{unit}");
            let whole = Span::new(num.start, u.end);
            if u.start > num.end {
                return Some(
                    Advice::new(
                        format!("a {what} is written without a space: `{good}`"),
                        whole,
                        "no space between the number and its unit",
                        format!("write `{good}`"),
                    )
                    .fix(format!("write `{good}`"), whole, good),
                );
            }
            if u.text != unit || factor != 1 {
                let message = match (dur, u.text) {
                    (true, "m" | "M") => format!("`m` is not a unit of time (minutes are `min`): write `{good}`"),
                    (true, _) if factor == 60 => format!("situ has no hours: write `{good}`"),
                    (true, w) => format!("`{w}` is not a unit of time: write `{good}`"),
                    (false, _) if factor != 1 => format!("a frequency is in hertz: write `{good}`"),
                    (false, _) => format!("the unit of frequency is `Hz`, with a capital H: write `{good}`"),
                };
                return Some(
                    Advice::new(
                        message,
                        whole,
                        format!("write `{good}`"),
                        if dur {
                            format!("the units of time are {UNITS}: write `{good}`")
                        } else {
                            format!("write `{good}`")
                        },
                    )
                    .fix(format!("write `{good}`"), whole, good),
                );
            }
            return None;
        }
        if u.start == num.end {
            // An unknown unit glued to the number.
            let span = Span::new(num.start, u.end);
            let help = if dur {
                format!("the units of time are {UNITS}, as in `200ms`")
            } else {
                "a frequency is in `Hz`, as in `20Hz`".into()
            };
            return Some(Advice::new(
                format!(
                    "`{}` is not a {what}: situ does not know the unit `{}`",
                    &cx.text[span.start..span.end],
                    u.text
                ),
                span,
                "unknown unit",
                help,
            ));
        }
    }
    // No unit at all.
    let span = num.span();
    let mut advice = if dur {
        let events = cx.exp.lit("events");
        // Small numbers are more often seconds, large ones milliseconds.
        let ms_first = num.text.parse::<f64>().is_ok_and(|v| v >= 50.0);
        let order = if ms_first { ["ms", "s"] } else { ["s", "ms"] };
        let help = if events {
            format!(
                "write `{n} events` to count events, or a duration with one of the units {UNITS}: `{n}{u}`",
                n = num.text,
                u = order[0]
            )
        } else {
            format!(
                "write the unit right after the number, with no space: `{n}{}` or `{n}{}` (the units are {UNITS})",
                order[0],
                order[1],
                n = num.text
            )
        };
        let message = if events {
            format!("`{n}` needs a unit: write `{n} events` or a duration such as `{n}{}`", order[0], n = num.text)
        } else {
            format!("`{}` needs a unit: a duration is written like `{}{}`", num.text, num.text, order[0])
        };
        let mut a = Advice::new(message, span, "no unit", help);
        if events {
            a = a.fix(format!("write `{} events`", num.text), Span::new(num.end, num.end), " events");
        }
        for unit in order {
            a = a.fix(format!("write `{}{unit}`", num.text), Span::new(num.end, num.end), unit);
        }
        a
    } else {
        Advice::new(
            format!("`{}` needs a unit: a frequency is written `{}Hz`", num.text, num.text),
            span,
            "no unit",
            format!("write `{}Hz`, with no space", num.text),
        )
        .fix(format!("write `{}Hz`", num.text), Span::new(num.end, num.end), "Hz")
    };
    if next.is_some_and(|n| n.is(".") && n.start == num.end) {
        // `30.`: not a unit problem.
        return None;
    }
    advice.label = Some(format!("this {what} has no unit"));
    Some(advice)
}

/// `30.`, `.5` and `- 0.1`.
pub(super) fn float_forms(cx: &Cx) -> Option<Advice> {
    let i = cx.at()?;
    let t = cx.tok(i)?;
    let next = cx.tok(i + 1);
    if t.kind == Kind::Number && t.start == cx.pos {
        let dot = next.filter(|n| n.is(".") && n.start == t.end)?;
        if cx.tok(i + 2).is_some_and(|a| a.start == dot.end && a.kind == Kind::Number) {
            return None;
        }
        let good = format!("{}.0", t.text);
        let span = Span::new(t.start, dot.end);
        return Some(
            Advice::new(
                format!("`{}.` is not a number: a float has digits after its point", t.text),
                span,
                format!("write `{good}`"),
                format!("write `{good}`"),
            )
            .fix(format!("write `{good}`"), span, good),
        );
    }
    if t.is(".") && next.is_some_and(|n| n.kind == Kind::Number && n.start == t.end) {
        let n = next?;
        let good = format!("0.{}", n.text);
        let span = Span::new(t.start, n.end);
        return Some(
            Advice::new(
                format!("`.{}` is not a number: a float has digits before its point", n.text),
                span,
                format!("write `{good}`"),
                format!("write `{good}`"),
            )
            .fix(format!("write `{good}`"), span, good),
        );
    }
    if t.is("-") && next.is_some_and(|n| n.kind == Kind::Number && n.start > t.end && cx.same_line(&t, &n)) {
        let n = next?;
        let good = format!("-{}", n.text);
        let span = Span::new(t.start, n.end);
        return Some(
            Advice::new(
                "a minus sign must touch its number",
                span,
                format!("write `{good}`"),
                format!("write `{good}`"),
            )
            .fix(format!("write `{good}`"), span, good),
        );
    }
    None
}

/// `x 3` and `X3`: a run length is `x` and the number, with no space.
pub(super) fn run_length(cx: &Cx) -> Option<Advice> {
    let i = cx.at()?;
    let t = cx.tok(i)?;
    // `x 3`: the error is after the `x`.
    if let Some(b) = cx.before() {
        if b.is("x") && b.end <= cx.pos && t.kind == Kind::Number && cx.same_line(&b, &t) && t.start > b.end {
            let span = Span::new(b.start, t.end);
            let good = format!("x{}", t.text);
            return Some(
                Advice::new(
                    format!("a run length is written without a space: `{good}`"),
                    span,
                    "no space after `x`",
                    format!("write `{good}`"),
                )
                .fix(format!("write `{good}`"), span, good),
            );
        }
    }
    let digits = t.text.strip_prefix('X').filter(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()))?;
    if !cx.exp.rule(Rule::run_length) && !cx.exp.lit("x") {
        return None;
    }
    let good = format!("x{digits}");
    Some(
        Advice::new(
            format!("a run length is written with a small `x`: `{good}`"),
            t.span(),
            format!("write `{good}`"),
            format!("write `{good}`"),
        )
        .fix(format!("write `{good}`"), t.span(), good),
    )
}
