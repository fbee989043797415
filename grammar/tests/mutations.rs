//! A mutation corpus of the repository's own `.situ` files: plausible user
//! mistakes (a dropped or doubled token, `:` for `==`, a unit left out or
//! spaced, a keyword as a name, wrong casing, `&&`, `||`, `->` for `=>`, ...)
//! applied one at a time, and the syntax errors they give checked:
//!
//! - no message is generic ("found a space" is only said with advice) or
//!   names a control character, and no list of expected tokens repeats
//!   itself;
//! - every fix a syntax error carries, applied to the file, removes that
//!   error (the fixed file has fewer errors, or none at the same place).
//!
//! `SITU_MUTATION_REPORT=1 cargo test -p situ-grammar --test mutations -- --nocapture`
//! prints every message by mutation, to review them as a user would.

use situ_grammar::diag::{Diagnostic, FileId};
use situ_grammar::parse;
use std::collections::BTreeMap;
use std::path::Path;

mod common;
use common::situ_files;

/// The repository's files that parse, as (name, text); `tests/checks/` is
/// sampled (it is large and alike).
fn corpus() -> Vec<(String, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut paths = Vec::new();
    for dir in ["rules", "examples", "tests/ui", "tests/run", "tests/verify", "tests/gen", "grammar/tests/fmt"] {
        situ_files(&root.join(dir), &mut paths);
    }
    let mut checks = Vec::new();
    situ_files(&root.join("tests/checks"), &mut checks);
    paths.extend(checks.into_iter().step_by(20));
    paths
        .into_iter()
        .filter_map(|p| {
            let text = std::fs::read_to_string(&p).ok()?;
            let name = p.strip_prefix(&root).unwrap_or(&p).display().to_string();
            parse(&text, FileId(0)).errors.is_empty().then_some((name, text))
        })
        .collect()
}

/// Byte ranges of the whole-word occurrences of `word` outside comments and
/// strings.
fn sites(text: &str, word: &str) -> Vec<usize> {
    let b = text.as_bytes();
    let is_word = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    let wordy = word.bytes().all(is_word);
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'"' => {
                i += 1;
                while i < b.len() && b[i] != b'"' && b[i] != b'\n' {
                    i += if b[i] == b'\\' { 2 } else { 1 };
                }
                i += 1;
                continue;
            }
            b'/' if b.get(i + 1) == Some(&b'/') => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
                continue;
            }
            _ => {}
        }
        if b[i..].starts_with(word.as_bytes())
            && (!wordy || ((i == 0 || !is_word(b[i - 1])) && b.get(i + word.len()).is_none_or(|c| !is_word(*c))))
        {
            out.push(i);
            i += word.len();
            continue;
        }
        i += 1;
    }
    out
}

/// Positions of durations (`200ms`) and frequencies (`10Hz`): (start of the
/// number, start of the unit, end).
fn quantities(text: &str) -> Vec<(usize, usize, usize)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit()
            && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_' || b[i - 1] == b'.'))
        {
            let start = i;
            while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
                i += 1;
            }
            let unit = i;
            while i < b.len() && b[i].is_ascii_alphabetic() {
                i += 1;
            }
            if matches!(&text[unit..i], "ns" | "us" | "ms" | "s" | "min" | "Hz") {
                out.push((start, unit, i));
            }
            continue;
        }
        i += 1;
    }
    // Not inside comments: keep those on a line before any `//`.
    out.retain(|(s, _, _)| {
        let line_start = text[..*s].rfind('\n').map_or(0, |p| p + 1);
        !text[line_start..*s].contains("//") && text[line_start..*s].matches('"').count() & 1 == 0
    });
    out
}

fn replace(text: &str, at: usize, len: usize, new: &str) -> String {
    format!("{}{}{}", &text[..at], new, &text[at + len..])
}

/// A named mistake: every way it applies to a text (at most a few).
type Mutation = (&'static str, fn(&str) -> Vec<String>);

/// Replaces occurrences of a whole word or token.
fn swap(text: &str, from: &str, to: &str) -> Vec<String> {
    sites(text, from).into_iter().map(|at| replace(text, at, from.len(), to)).collect()
}

fn mutations() -> Vec<Mutation> {
    vec![
        ("drop `}`", |t| swap(t, "}", "")),
        ("drop `{`", |t| swap(t, "{", "")),
        ("drop `then`", |t| swap(t, "then ", "")),
        ("drop `when`", |t| swap(t, "when ", "")),
        ("drop `and`", |t| swap(t, "and ", "")),
        ("drop `,`", |t| swap(t, ",", "")),
        ("drop `after`", |t| swap(t, "after ", "")),
        ("drop `=>`", |t| swap(t, "=>", "")),
        ("drop `(`", |t| swap(t, "(", "")),
        ("double `and`", |t| swap(t, "and", "and and")),
        ("double `,`", |t| swap(t, ",", ",,")),
        ("`==` for `:`", |t| swap(t, ":", " ==")),
        ("`:` for `==`", |t| swap(t, " ==", ":")),
        ("`=` for `==`", |t| swap(t, "==", "=")),
        ("`<>` for `!=`", |t| swap(t, "!=", "<>")),
        ("`&&` for `and`", |t| swap(t, "and", "&&")),
        ("`||` for `and`", |t| swap(t, "and", "||")),
        ("`or` for `and`", |t| swap(t, "and", "or")),
        ("`!` for `not `", |t| swap(t, "not ", "!")),
        ("`->` for `=>`", |t| swap(t, "=>", "->")),
        ("`=>` for `->`", |t| swap(t, "->", "=>")),
        ("`;` for `,`", |t| swap(t, ",", ";")),
        ("`;` at a line's end", |t| swap(t, "\n", ";\n")),
        ("`,` at a line's end", |t| swap(t, "\n", ",\n")),
        ("`When`", |t| swap(t, "when", "When")),
        ("`AND`", |t| swap(t, "and", "AND")),
        ("`Rule`", |t| swap(t, "rule", "Rule")),
        ("`Sensor`", |t| swap(t, "sensor", "Sensor")),
        ("`then A, B`", |t| {
            sites(t, "then")
                .into_iter()
                .filter_map(|at| {
                    let rest = &t[at + 5..];
                    let n = rest.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))?;
                    Some(replace(t, at + 5 + n, 0, ", FAULT"))
                })
                .collect()
        }),
        ("keyword as event name", |t| {
            sites(t, "event")
                .into_iter()
                .map(|at| replace(t, at + 6, 0, "on "))
                .map(|s| s.replacen("on on ", "on ", 1))
                .collect()
        }),
        ("keyword as state name", |t| {
            swap(t, "initial", "")
                .into_iter()
                .take(0)
                .chain(sites(t, "states {").into_iter().map(|at| replace(t, at + 8, 0, " state")))
                .collect()
        }),
        ("no unit", |t| quantities(t).into_iter().map(|(_, u, e)| replace(t, u, e - u, "")).collect()),
        ("space before unit", |t| quantities(t).into_iter().map(|(_, u, _)| replace(t, u, 0, " ")).collect()),
        ("unit `m`/`sec`/`hz`", |t| {
            quantities(t)
                .into_iter()
                .map(|(_, u, e)| {
                    let unit = match &t[u..e] {
                        "min" => "m",
                        "s" => "sec",
                        "ms" => "msec",
                        "Hz" => "hz",
                        other => other,
                    };
                    replace(t, u, e - u, unit)
                })
                .collect()
        }),
        ("`x 3`", |t| {
            sites(t, " x")
                .into_iter()
                .filter(|at| t[at + 2..].starts_with(|c: char| c.is_ascii_digit()))
                .map(|at| replace(t, at + 2, 0, " "))
                .collect()
        }),
        ("`30.`", |t| swap(t, ".0", ".")),
        ("`.5`", |t| swap(t, "0.", ".")),
        ("`function f()`", |t| {
            sites(t, "function")
                .into_iter()
                .filter_map(|at| {
                    let rest = &t[at + 9..];
                    let n = rest.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))?;
                    Some(replace(t, at + 9 + n, 0, "()"))
                })
                .collect()
        }),
        ("payload in `()`", |t| {
            sites(t, "event")
                .into_iter()
                .filter_map(|at| {
                    let line_end = t[at..].find('\n').map_or(t.len(), |p| at + p);
                    let open = t[at..line_end].find(" {").map(|p| at + p + 1)?;
                    let close = t[open..line_end].find('}').map(|p| open + p)?;
                    Some(format!("{}({}){}", &t[..open], &t[open + 1..close], &t[close + 1..]))
                })
                .collect()
        }),
        ("`float` for `f64`", |t| swap(t, "f64", "float")),
        ("no agent kind", |t| {
            let mut v = swap(t, "sensor ", "");
            v.extend(swap(t, "processing ", ""));
            v
        }),
        ("`'` for `\"`", |t| swap(t, "\"", "'")),
        ("`state ==` in a test", |t| swap(t, "expect state ", "expect state == ")),
        ("`running` for `run`", |t| swap(t, "run ", "running ")),
        ("`sleep` for `sleeping`", |t| swap(t, "sleeping", "sleep")),
        ("no quantifier", |t| {
            let mut v = swap(t, "always ", "");
            v.extend(swap(t, "never ", ""));
            v
        }),
    ]
}

/// The text with the fix's edits applied.
fn apply(text: &str, d: &Diagnostic, fix: usize) -> String {
    let mut edits: Vec<_> = d.fixes[fix].edits.iter().collect();
    edits.sort_by_key(|e| std::cmp::Reverse(e.span.start));
    let mut out = text.to_string();
    for e in edits {
        out.replace_range(e.span.start..e.span.end, &e.text);
    }
    out
}

/// At most `n` of the mutated texts, spread over the file.
fn pick(all: Vec<String>, n: usize) -> Vec<String> {
    if all.len() <= n {
        return all;
    }
    let step = all.len() / n;
    all.into_iter().step_by(step.max(1)).take(n).collect()
}

/// Whether a message lists one token twice (as in "`sensor`, … (sensor, …)").
fn repeats(message: &str) -> bool {
    let Some(list) = message.split(", found ").next().and_then(|m| m.strip_prefix("syntax error: expected ")) else {
        return false;
    };
    let tokens: Vec<&str> = list.split('`').skip(1).step_by(2).collect();
    tokens.iter().enumerate().any(|(i, t)| tokens[i + 1..].contains(t) || list.contains(&format!("({t}")))
}

#[test]
fn mutated_files_get_specific_messages_and_working_fixes() {
    let corpus = corpus();
    assert!(corpus.len() > 20, "too few files: {}", corpus.len());
    let mut report: BTreeMap<&str, BTreeMap<String, usize>> = BTreeMap::new();
    let mut failures = Vec::new();
    let (mut cases, mut fixes) = (0usize, 0usize);
    for (kind, mutate) in mutations() {
        for (name, text) in &corpus {
            for mutated in pick(mutate(text), 1) {
                let errors = parse(&mutated, FileId(0)).errors;
                cases += 1;
                for d in errors.iter().filter(|d| d.code == "E0001") {
                    let line = mutated[..d.primary.span.start].matches('\n').count() + 1;
                    let place = format!("{kind}: {name}:{line}");
                    let entry = format!(
                        "{}\n      label: {}\n      help: {}{}",
                        d.message,
                        d.primary.text,
                        d.help.as_deref().unwrap_or("-"),
                        if d.fixes.is_empty() {
                            String::new()
                        } else {
                            format!(
                                "\n      fixes: {}",
                                d.fixes.iter().map(|f| f.title.as_str()).collect::<Vec<_>>().join("; ")
                            )
                        }
                    );
                    *report.entry(kind).or_default().entry(entry).or_default() += 1;
                    if d.message.contains("U+000") || (d.message.contains("found a space") && d.help.is_none()) {
                        failures.push(format!("{place}: generic message: {}", d.message));
                    }
                    if repeats(&d.message) {
                        failures.push(format!("{place}: repeats itself: {}", d.message));
                    }
                    for f in 0..d.fixes.len() {
                        fixes += 1;
                        let fixed = apply(&mutated, d, f);
                        let after = parse(&fixed, FileId(0)).errors;
                        let same_place = after.iter().any(|e| e.primary.span.start == d.primary.span.start);
                        if after.len() >= errors.len() && same_place {
                            failures.push(format!(
                                "{place}: the fix `{}` of `{}` does not remove the error",
                                d.fixes[f].title, d.message
                            ));
                        }
                    }
                }
            }
        }
    }
    if std::env::var_os("SITU_MUTATION_REPORT").is_some() {
        println!("{cases} mutated files, {fixes} fixes checked");
        for (kind, messages) in &report {
            println!("\n== {kind}");
            for (m, n) in messages {
                println!("  [{n}] {m}");
            }
        }
    }
    assert!(cases > 500, "too few mutations: {cases}");
    assert!(failures.is_empty(), "{} failures:\n{}", failures.len(), failures.join("\n"));
}
