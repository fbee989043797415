//! `situ graph`: the pictures of a real rule file read at their size (fit
//! in 2000 × 2000 px with text of at least 11 px, the states picture with
//! at most a handful of edge crossings, counted here from the SVG's edge
//! paths), findings are drawn and not refused, diagnostics go to standard
//! error, and any valid or partly valid file draws. The SVGs are laid out
//! by Graphviz's `dot` (`scripts/install-graphviz.sh`): a missing `dot`
//! fails these tests.

mod common;
use common::*;
use std::process::{Command, Stdio};

fn require_dot() {
    let ok = Command::new("dot").arg("-V").stderr(Stdio::null()).status().is_ok_and(|s| s.success());
    assert!(ok, "Graphviz's `dot` is missing: run scripts/install-graphviz.sh");
}

/// The attribute `name` of an XML tag's text.
fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let at = tag.find(&format!(" {name}=\""))? + name.len() + 3;
    Some(&tag[at..at + tag[at..].find('"')?])
}

/// A length in px (`pt` is 4/3 px).
fn px(s: &str) -> f64 {
    let v: f64 = s.trim_end_matches(char::is_alphabetic).parse().unwrap();
    if s.ends_with("pt") {
        v * 4.0 / 3.0
    } else {
        v
    }
}

/// The size of the picture once scaled to fit 2000 × 2000 px (never
/// enlarged), and its smallest text in px at that size.
fn fitted(svg: &str) -> (f64, f64, f64) {
    let start = svg.find("<svg").unwrap();
    let tag = &svg[start..start + svg[start..].find('>').unwrap()];
    let (w, h) = (px(attr(tag, "width").unwrap()), px(attr(tag, "height").unwrap()));
    let vb_w: f64 = attr(tag, "viewBox").unwrap().split_whitespace().nth(2).unwrap().parse().unwrap();
    let fit = (2000.0 / w).min(2000.0 / h).min(1.0);
    let unit = w / vb_w * fit;
    // Nested pictures (small multiples) are placed at their own size: one unit each.
    let smallest = svg
        .match_indices("font-size=\"")
        .map(|(i, m)| {
            let s = &svg[i + m.len()..];
            s[..s.find('"').unwrap()].parse::<f64>().unwrap()
        })
        .fold(f64::INFINITY, f64::min);
    (w * fit, h * fit, smallest * unit)
}

/// Every edge of a Graphviz SVG as a polyline (its Bézier curves sampled).
fn edges(svg: &str) -> Vec<Vec<(f64, f64)>> {
    let mut out = Vec::new();
    for (i, _) in svg.match_indices("class=\"edge\"") {
        let rest = &svg[i..];
        let path = &rest[rest.find("<path").unwrap()..];
        let d = attr(path, "d").unwrap();
        let nums: Vec<(f64, f64)> = d
            .split([' ', 'M', 'C'])
            .filter(|p| p.contains(','))
            .map(|p| {
                let (x, y) = p.split_once(',').unwrap();
                (x.parse().unwrap(), y.parse().unwrap())
            })
            .collect();
        let mut line = vec![nums[0]];
        for c in nums[1..].chunks_exact(3) {
            let p0 = *line.last().unwrap();
            for k in 1..=8 {
                let t = k as f64 / 8.0;
                let b = |a: f64, b: f64, c: f64, d: f64| {
                    (1.0 - t).powi(3) * a
                        + 3.0 * (1.0 - t).powi(2) * t * b
                        + 3.0 * (1.0 - t) * t * t * c
                        + t.powi(3) * d
                };
                line.push((b(p0.0, c[0].0, c[1].0, c[2].0), b(p0.1, c[0].1, c[1].1, c[2].1)));
            }
        }
        out.push(line);
    }
    out
}

/// Pairwise crossings of the edges, not counting where edges meet at a node
/// (within 12 units of an end of either).
fn crossings(edges: &[Vec<(f64, f64)>]) -> usize {
    let cross = |p: (f64, f64), q: (f64, f64), r: (f64, f64), s: (f64, f64)| -> Option<(f64, f64)> {
        let d = (q.0 - p.0) * (s.1 - r.1) - (q.1 - p.1) * (s.0 - r.0);
        if d.abs() < 1e-9 {
            return None;
        }
        let t = ((r.0 - p.0) * (s.1 - r.1) - (r.1 - p.1) * (s.0 - r.0)) / d;
        let u = ((r.0 - p.0) * (q.1 - p.1) - (r.1 - p.1) * (q.0 - p.0)) / d;
        (t > 0.0 && t < 1.0 && u > 0.0 && u < 1.0).then_some((p.0 + t * (q.0 - p.0), p.1 + t * (q.1 - p.1)))
    };
    let near_end = |x: (f64, f64), e: &[(f64, f64)]| {
        [e[0], e[e.len() - 1]].iter().any(|p| ((p.0 - x.0).powi(2) + (p.1 - x.1).powi(2)).sqrt() < 12.0)
    };
    let mut n = 0;
    for (i, a) in edges.iter().enumerate() {
        for b in &edges[i + 1..] {
            for sa in a.windows(2) {
                for sb in b.windows(2) {
                    if let Some(x) = cross(sa[0], sa[1], sb[0], sb[1]) {
                        if !near_end(x, a) && !near_end(x, b) {
                            n += 1;
                        }
                    }
                }
            }
        }
    }
    n
}

fn svg_of(args: &[&str]) -> String {
    let o = situ(args);
    assert_eq!(code(&o), 0, "{args:?}: {}", stderr(&o));
    let svg = stdout(&o);
    assert!(svg.contains("<svg") && svg.trim_end().ends_with("</svg>"), "{args:?}: {svg}");
    svg
}

/// DOT that Graphviz accepts.
fn assert_valid_dot(dot: &str) {
    let mut child = Command::new("dot")
        .arg("-Tsvg")
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    use std::io::Write as _;
    child.stdin.take().unwrap().write_all(dot.as_bytes()).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "dot refuses: {}\n{dot}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn every_picture_of_outdoor_fits_2000_px_with_text_of_11_px() {
    require_dot();
    for args in [
        &["--view", "states"][..],
        &["--view", "rete"],
        &["--view", "wiring"],
        &["--view", "wiring", "--state", "RO"],
        &["--view", "wiring", "--state", "IT"],
    ] {
        for file in ["rules/outdoor.situ", "rules/ugv.situ"] {
            let mut all = vec!["graph", file, "--format", "svg"];
            all.extend_from_slice(args);
            if file.ends_with("ugv.situ") && args.contains(&"--state") {
                continue;
            }
            let (w, h, text) = fitted(&svg_of(&all));
            // Scaled to fit by construction: allow the rounding of the scaling.
            assert!(w <= 2000.001 && h <= 2000.001, "{all:?}: {w} × {h}");
            assert!(text >= 11.0, "{all:?}: text of {text:.1} px at {w:.0} × {h:.0}");
        }
    }
}

#[test]
fn the_states_picture_of_outdoor_has_a_handful_of_crossings() {
    require_dot();
    let svg = svg_of(&["graph", "rules/outdoor.situ", "--view", "states", "--format", "svg"]);
    let e = edges(&svg);
    assert!(e.len() >= 20, "{} edges", e.len());
    let n = crossings(&e);
    assert!(n <= 5, "{n} crossings");
    // The emergencies and stops are drawn once, from groups.
    assert!(svg.contains("from any of") && svg.contains("from any state but"), "{svg}");
    for kind in ["initial", "final"] {
        assert!(svg.contains(&format!(">{kind}</text>")), "{kind}");
    }
}

#[test]
fn the_crossing_count_sees_crossings() {
    // Two diagonals of a square cross once; edges that meet at a node do not.
    let x = vec![vec![(0.0, 0.0), (100.0, 100.0)], vec![(0.0, 100.0), (100.0, 0.0)], vec![(0.0, 0.0), (0.0, 100.0)]];
    assert_eq!(crossings(&x), 1);
}

const FINDINGS: &str = "states { IT initial RS LOST TRAP DONE final }
agent A sensor { event GO event HALT { d: f64 } function f table { _ => run f() } }
rule go { when state == IT and GO then RS }
rule trapped { when state == RS and HALT(d < 1.0) then TRAP }
rule done { when state == RS and HALT(d > 5.0) then DONE }
rule lost { when state == LOST and GO then RS }
";

#[test]
fn findings_are_drawn_and_diagnostics_go_to_standard_error() {
    require_dot();
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "findings.situ", FINDINGS);
    let o = situ(&["graph", &f, "--view", "states"]);
    assert_eq!(code(&o), 1, "an error (the unreachable state): exit 1, the picture drawn: {}", stderr(&o));
    let dot = stdout(&o);
    assert!(dot.starts_with("digraph states") && !dot.contains("E0301"), "{dot}");
    assert!(dot.contains("LOST\\nunreachable") && dot.contains("TRAP\\ntrap: no way out"), "{dot}");
    assert!(stderr(&o).contains("E0301"), "{}", stderr(&o));
    assert_valid_dot(&dot);
    let svg = situ(&["graph", &f, "--view", "states", "--format", "svg"]);
    assert!(stdout(&svg).contains(">unreachable</text>") && stdout(&svg).contains("#ffcdd2"), "{}", stdout(&svg));
    // With `-o`, the picture is written all the same.
    let out = dir.path().join("x.dot");
    let o = situ(&["graph", &f, "--view", "states", "-o", out.to_str().unwrap()]);
    assert_eq!(code(&o), 1);
    assert_valid_dot(&std::fs::read_to_string(&out).unwrap());
}

#[test]
fn a_file_with_a_type_error_draws_its_states_and_refuses_the_other_views() {
    require_dot();
    let dir = tempfile::tempdir().unwrap();
    let bad = FINDINGS.replace(
        "rule lost { when state == LOST and GO then RS }",
        "rule lost { when state == RS and HALT(d < true) then LOST }",
    );
    let f = write(dir.path(), "bad.situ", bad);
    let o = situ(&["graph", &f, "--view", "states"]);
    assert_eq!(code(&o), 1);
    let dot = stdout(&o);
    assert!(dot.contains("\"IT\" -> \"RS\"") && dot.contains("rules with errors are not drawn"), "{dot}");
    assert!(!stderr(&o).is_empty() && !dot.contains("error["), "{}", stderr(&o));
    assert_valid_dot(&dot);
    for view in ["wiring", "rete"] {
        let o = situ(&["graph", &f, "--view", view]);
        assert_eq!(code(&o), 1, "{}", stderr(&o));
        assert!(stdout(&o).is_empty() && stderr(&o).contains("the states view draws what resolved"), "{}", stderr(&o));
    }
}

/// A generated file of `n` states in a ring with shortcuts, an emergency
/// from every state, and agents that run in some states.
fn generated(n: usize) -> String {
    let mut s = String::from("states {\n");
    for i in 0..n {
        let role = match i {
            0 => " initial",
            _ if i == n - 1 => " final",
            _ => "",
        };
        s.push_str(&format!("  S{i}{role} \"state number {i}\"\n"));
    }
    s.push_str("  EM\n}\nagent A sensor { event NEXT event SKIP event BAD function f table { S0, S1 => run f() to B  _ => wait f() } }\n");
    s.push_str("agent B processing { function g table { S0 => run g()  _ => sleep } }\n");
    for i in 0..n - 1 {
        s.push_str(&format!("rule next{i} {{ when state == S{i} and NEXT then S{} }}\n", i + 1));
        if i + 3 < n {
            s.push_str(&format!("rule skip{i} {{ when state == S{i} and SKIP then S{} }}\n", i + 3));
        }
    }
    s.push_str(&format!("rule emergency {{ when state not in {{EM, S{}}} and BAD then EM }}\n", n - 1));
    s.push_str("rule recover { when state == EM and NEXT then S0 }\n");
    s
}

#[test]
fn a_forty_state_file_draws_in_every_view() {
    require_dot();
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "forty.situ", generated(40));
    let o = situ(&["check", &f]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    for view in ["states", "rete", "wiring"] {
        let dot = situ(&["graph", &f, "--view", view]);
        assert_eq!(code(&dot), 0, "{}", stderr(&dot));
        assert_valid_dot(&stdout(&dot));
        svg_of(&["graph", &f, "--view", view, "--format", "svg"]);
    }
    let dot = stdout(&situ(&["graph", &f, "--view", "states"]));
    assert_eq!(dot.matches("-> \"EM\"").count(), 1, "the emergency is drawn once: {dot}");
}

#[test]
fn the_built_in_layout_keeps_the_distinctions_in_fill_colours() {
    let run = |args: &[&str]| {
        let o = Command::new(env!("CARGO_BIN_EXE_situ")).args(args).env("SITU_LAYOUT", "builtin").output().unwrap();
        assert_eq!(code(&o), 0, "{}", stderr(&o));
        assert!(stderr(&o).contains("built-in layout"), "{}", stderr(&o));
        stdout(&o)
    };
    let svg = run(&["graph", "rules/outdoor.situ", "--view", "states", "--format", "svg"]);
    for fill in ["#c8e6c9", "#bbdefb", "#eeeeee"] {
        assert!(svg.contains(fill), "{fill}");
    }
    let svg = run(&["graph", "rules/outdoor.situ", "--view", "wiring", "--format", "svg"]);
    for fill in ["#c8e6c9", "#fff9c4", "#bbdefb"] {
        assert!(svg.contains(fill), "{fill}");
    }
    assert!(svg.contains("Wiring of every state"), "small multiples in SVG too");
}

#[test]
fn the_states_dot_of_ugv_is_stable() {
    let o = situ(&["graph", "rules/ugv.situ", "--view", "states"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    insta::assert_snapshot!(stdout(&o));
}
