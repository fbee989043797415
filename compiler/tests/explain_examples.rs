//! The examples of `situ explain` are real: for every code, the `Example`
//! block raises it, and the `Use instead` block parses and does not. (The
//! blocks may be fragments, so other findings, such as names declared
//! elsewhere, are not counted.)

use situ_compiler::{check_source, codes};

/// The ```situ blocks after a heading.
fn blocks_after<'a>(doc: &'a str, heading: &str) -> Vec<&'a str> {
    let Some(start) = doc.find(heading) else { return Vec::new() };
    let section = &doc[start + heading.len()..];
    let section = &section[..section.find("\n## ").unwrap_or(section.len())];
    section.split("```situ\n").skip(1).filter_map(|b| b.split("```").next()).collect()
}

/// Codes whose example cannot be one self-contained text: they need bytes
/// that are not UTF-8, other files, or very long input (W0321: a rule base
/// with too many cycles to examine; its inputs are in `tests/checks/`).
const NOT_SELF_CONTAINED: &[&str] = [
    codes::NOT_UTF8,
    codes::INCLUDE_NOT_FOUND,
    codes::INCLUDE_CYCLE,
    codes::TOO_DEEP,
    codes::TOO_MANY_ERRORS,
    codes::INCLUDE_TOO_DEEP,
    codes::INCOMPLETE_CHECK,
]
.as_slice();

#[test]
fn examples_raise_their_code_and_fixes_are_clean() {
    let mut failures = Vec::new();
    for c in codes::ALL {
        let examples = blocks_after(c.explain, "## Example");
        let fixes = blocks_after(c.explain, "## Use instead");
        if examples.is_empty() || fixes.is_empty() {
            failures.push(format!("{}: needs a ```situ block under Example and under Use instead", c.code));
            continue;
        }
        // A map raises the ROS 2 map's codes, not rules alone: situ-ros2-map's
        // `the_examples_of_the_codes_are_real` holds their examples to them.
        // Likewise `situ test` raises the verdicts' codes: situ-verify's
        // `the_examples_of_the_verdict_codes_are_real` holds theirs.
        if NOT_SELF_CONTAINED.contains(&c.code) || codes::is_ros2_map(c.code) || codes::is_verdict(c.code) {
            continue;
        }
        for ex in examples {
            let checked = check_source("example.situ", ex);
            if !checked.visible().any(|d| d.code == c.code) {
                let got: Vec<_> = checked.visible().map(|d| d.code).collect();
                failures.push(format!("{}: the Example does not raise it (got {got:?})", c.code));
            }
        }
        for fix in fixes {
            let checked = check_source("fixed.situ", fix);
            let got: Vec<_> = checked
                .visible()
                .filter(|d| d.code == c.code || d.code == codes::SYNTAX)
                .map(|d| format!("{} {}", d.code, d.message))
                .collect();
            if !got.is_empty() {
                failures.push(format!("{}: Use instead still raises {got:?}", c.code));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
