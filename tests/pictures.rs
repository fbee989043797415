//! True pictures: measured on the SVG, not on the DOT. No edge of a wiring
//! picture passes over a box other than its two ends (every state of every
//! rules file of the repository, `situ graph` and `situ run --out`, with
//! Graphviz and with the built-in layout); a link that depends on an FSM
//! state is drawn only where that FSM state can be active; the run's
//! timeline shows every visited state however short, with its name; the
//! built-in layout has the titles, the legend and about the size of
//! Graphviz's. The fixture is `tests/pictures/drone.situ`.

mod common;
use common::*;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

const DRONE: &str = "tests/pictures/drone.situ";

fn require_dot() {
    let ok = Command::new("dot").arg("-V").stderr(Stdio::null()).status().is_ok_and(|s| s.success());
    assert!(ok, "Graphviz's `dot` is missing: run scripts/install-graphviz.sh");
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Engine {
    Graphviz,
    Builtin,
}

fn run(engine: Engine, args: &[&str]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_situ"));
    c.args(args).env("NO_COLOR", "1");
    if engine == Engine::Builtin {
        c.env("SITU_LAYOUT", "builtin");
    }
    c.output().expect("the binary runs")
}

fn svg(engine: Engine, args: &[&str]) -> String {
    let o = run(engine, args);
    assert_eq!(code(&o), 0, "{engine:?} {args:?}: {}", text(&o));
    let s = stdout(&o);
    assert!(s.contains("<svg") && s.trim_end().ends_with("</svg>"), "{engine:?} {args:?}: {s}");
    s
}

fn unescape(s: &str) -> String {
    s.replace("&#45;", "-").replace("&gt;", ">").replace("&lt;", "<").replace("&quot;", "\"").replace("&amp;", "&")
}

fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let at = tag.find(&format!(" {name}=\""))? + name.len() + 3;
    Some(&tag[at..at + tag[at..].find('"')?])
}

/// The groups `<g … class="CLASS">…</g>` of an SVG (not nested in ours).
fn groups<'a>(svg: &'a str, class: &str) -> Vec<&'a str> {
    let mut out = Vec::new();
    let needle = format!("class=\"{class}\"");
    let mut from = 0;
    while let Some(i) = svg[from..].find(&needle) {
        let start = from + i;
        let end = start + svg[start..].find("</g>").expect("a closed group");
        out.push(&svg[start..end]);
        from = end;
    }
    out
}

fn title(group: &str) -> String {
    let a = group.find("<title>").expect("a title") + 7;
    unescape(&group[a..a + group[a..].find("</title>").unwrap()])
}

/// Numbers of a path or a points list, as they come.
fn numbers(s: &str) -> Vec<f64> {
    s.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == 'e'))
        .filter(|t| !t.is_empty() && t != &"-")
        .filter_map(|t| t.parse().ok())
        .collect()
}

/// Each node's box: its id and `(x0, y0, x1, y1)`, from its first shape.
fn boxes(svg: &str) -> Vec<(String, [f64; 4])> {
    let mut out = Vec::new();
    for g in groups(svg, "node") {
        let id = title(g);
        let shape = ["<polygon", "<path", "<rect", "<ellipse"]
            .iter()
            .filter_map(|s| g.find(s))
            .min()
            .map(|i| &g[i..i + g[i..].find('>').unwrap()])
            .expect("a shape");
        let b = if shape.starts_with("<rect") {
            let v = |n: &str| attr(shape, n).unwrap().parse::<f64>().unwrap();
            [v("x"), v("y"), v("x") + v("width"), v("y") + v("height")]
        } else if shape.starts_with("<ellipse") {
            let v = |n: &str| attr(shape, n).unwrap().parse::<f64>().unwrap();
            [v("cx") - v("rx"), v("cy") - v("ry"), v("cx") + v("rx"), v("cy") + v("ry")]
        } else {
            let nums = numbers(attr(shape, "points").or_else(|| attr(shape, "d")).unwrap());
            let xs = nums.iter().step_by(2);
            let ys = nums.iter().skip(1).step_by(2);
            [
                xs.clone().copied().fold(f64::INFINITY, f64::min),
                ys.clone().copied().fold(f64::INFINITY, f64::min),
                xs.copied().fold(f64::NEG_INFINITY, f64::max),
                ys.copied().fold(f64::NEG_INFINITY, f64::max),
            ]
        };
        out.push((id, b));
    }
    out
}

/// Points along a path's segments (`M`, `L`, `C`, `Q`, absolute), 16 a segment.
fn sample(d: &str) -> Vec<(f64, f64)> {
    let mut pts = Vec::new();
    let mut cur = (0.0, 0.0);
    let mut cmd = 'M';
    let mut nums: Vec<f64> = Vec::new();
    let flush = |cmd: char, nums: &mut Vec<f64>, cur: &mut (f64, f64), pts: &mut Vec<(f64, f64)>| {
        let p: Vec<(f64, f64)> = nums.chunks_exact(2).map(|c| (c[0], c[1])).collect();
        let n = match cmd {
            'C' => 3,
            'Q' => 2,
            _ => 1,
        };
        for group in p.chunks_exact(n) {
            for k in 0..=16 {
                let t = k as f64 / 16.0;
                let u = 1.0 - t;
                let at = match (cmd, group) {
                    ('C', [a, b, c]) => (
                        u * u * u * cur.0 + 3.0 * u * u * t * a.0 + 3.0 * u * t * t * b.0 + t * t * t * c.0,
                        u * u * u * cur.1 + 3.0 * u * u * t * a.1 + 3.0 * u * t * t * b.1 + t * t * t * c.1,
                    ),
                    ('Q', [a, b]) => (
                        u * u * cur.0 + 2.0 * u * t * a.0 + t * t * b.0,
                        u * u * cur.1 + 2.0 * u * t * a.1 + t * t * b.1,
                    ),
                    ('M', [a]) => *a,
                    (_, [a]) => (cur.0 + (a.0 - cur.0) * t, cur.1 + (a.1 - cur.1) * t),
                    _ => unreachable!(),
                };
                pts.push(at);
            }
            *cur = *group.last().unwrap();
        }
        nums.clear();
    };
    let mut token = String::new();
    for ch in d.chars().chain(std::iter::once(' ')) {
        if ch.is_ascii_digit() || ch == '.' || (ch == '-' && token.is_empty()) || (ch == 'e' && !token.is_empty()) {
            token.push(ch);
            continue;
        }
        if !token.is_empty() {
            nums.push(token.parse().expect("a number"));
            token.clear();
        }
        if ch == '-' {
            token.push(ch);
        } else if ch.is_ascii_alphabetic() {
            flush(cmd, &mut nums, &mut cur, &mut pts);
            cmd = ch;
        }
    }
    flush(cmd, &mut nums, &mut cur, &mut pts);
    pts
}

/// Every edge: its two ends and the points sampled along its path.
/// An edge: its tail, its head, the points sampled along it.
type Sampled = (String, String, Vec<(f64, f64)>);

fn edge_paths(svg: &str) -> Vec<Sampled> {
    groups(svg, "edge")
        .into_iter()
        .map(|g| {
            let t = title(g);
            let (a, b) = t.split_once("->").unwrap_or_else(|| panic!("an edge title: {t}"));
            let p = &g[g.find("<path").expect("a path")..];
            (a.to_string(), b.to_string(), sample(attr(p, "d").unwrap()))
        })
        .collect()
}

/// The edges that pass over a box other than their ends' (boxes taken
/// `margin` units in from each side), with the box.
fn over_boxes(svg: &str, margin: f64) -> Vec<String> {
    let boxes = boxes(svg);
    let mut out = Vec::new();
    for (a, b, pts) in edge_paths(svg) {
        for (id, r) in &boxes {
            if id == &a || id == &b {
                continue;
            }
            let inside =
                |&(x, y): &(f64, f64)| x > r[0] + margin && x < r[2] - margin && y > r[1] + margin && y < r[3] - margin;
            if let Some(p) = pts.iter().find(|p| inside(p)) {
                out.push(format!("{a} -> {b} passes over {id} at ({:.0}, {:.0})", p.0, p.1));
            }
        }
    }
    out
}

/// The rules files of the repository and the fixtures of this test.
fn rules_files() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else { return };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "situ") {
                out.push(p);
            }
        }
    }
    let mut out = Vec::new();
    for dir in ["rules", "examples", "tests/pictures"] {
        walk(Path::new(dir), &mut out);
    }
    out.sort();
    out
}

/// The states of a rules file, from its wiring DOT's clusters.
fn states(bundle: &str) -> Vec<String> {
    let dot = stdout(&situ(&["graph", bundle, "--view", "wiring"]));
    dot.lines()
        .filter_map(|l| l.trim().strip_prefix("subgraph \"cluster_"))
        .filter_map(|l| l.split('"').next())
        .filter(|s| *s != "legend")
        .map(str::to_string)
        .collect()
}

#[test]
fn the_crossing_measure_sees_an_edge_over_a_box() {
    let svg = r#"<g class="node"><title>A</title><rect x="0" y="0" width="10" height="10"/></g>
        <g class="node"><title>B</title><polygon points="40,0 50,0 50,10 40,10"/></g>
        <g class="node"><title>C</title><path d="M80,0 C85,0 90,0 90,10 L80,10"/></g>
        <g class="edge"><title>A&#45;&gt;C</title><path d="M10,5 C30,5 60,5 80,5"/></g>
        <g class="edge"><title>A&#45;&gt;B</title><path d="M10,5 L40,5"/></g>"#;
    assert_eq!(over_boxes(svg, 1.0), ["A -> C passes over B at (45, 5)"]);
    let around = svg.replace("M10,5 C30,5 60,5 80,5", "M10,5 C30,40 60,40 80,5");
    assert!(over_boxes(&around, 1.0).is_empty());
}

#[test]
fn no_wiring_edge_passes_over_a_box_in_any_state_of_any_rules_file() {
    require_dot();
    let dir = tempfile::tempdir().unwrap();
    let files = rules_files();
    assert!(files.len() >= 6, "{files:?}");
    let mut bad = Vec::new();
    let mut pictures = 0;
    for f in &files {
        let bundle = dir.path().join(format!("{}.json", f.file_stem().unwrap().to_string_lossy()));
        let bundle = bundle.to_str().unwrap();
        let o = situ(&["build", f.to_str().unwrap(), "-o", bundle]);
        assert_eq!(code(&o), 0, "{}: {}", f.display(), text(&o));
        let states = states(bundle);
        assert!(!states.is_empty(), "{}", f.display());
        for s in &states {
            for engine in [Engine::Graphviz, Engine::Builtin] {
                let picture = svg(engine, &["graph", bundle, "--view", "wiring", "--state", s, "--format", "svg"]);
                assert!(!boxes(&picture).is_empty(), "{engine:?} {} {s}: no boxes read", f.display());
                pictures += 1;
                for e in over_boxes(&picture, 2.0) {
                    bad.push(format!("{engine:?} {} in {s}: {e}", f.display()));
                }
            }
        }
    }
    assert!(pictures >= 60, "{pictures} pictures");
    assert!(bad.is_empty(), "{} edges over boxes:\n{}", bad.len(), bad.join("\n"));
}

/// `situ run DRONE --script … --out DIR` with `engine`: the files of DIR.
fn drone_run(engine: Engine, dir: &Path) -> (String, HashMap<String, String>) {
    let o = run(engine, &["run", DRONE, "--script", "an inspection", "--out", dir.to_str().unwrap()]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let files = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .filter(|e| e.path().extension().is_some_and(|x| x == "svg"))
        .map(|e| (e.file_name().to_string_lossy().into_owned(), std::fs::read_to_string(e.path()).unwrap()))
        .collect();
    (stdout(&o), files)
}

#[test]
fn the_wiring_a_run_saw_has_no_edge_over_a_box_and_is_drawn_as_situ_graph_draws() {
    require_dot();
    for engine in [Engine::Graphviz, Engine::Builtin] {
        let dir = tempfile::tempdir().unwrap();
        let (_, files) = drone_run(engine, dir.path());
        let inspect = files.get("wiring-Inspect.svg").expect("Inspect visited");
        // RemoteLink feeds both the planner and the operator there.
        let edges: Vec<(String, String)> = edge_paths(inspect).into_iter().map(|(a, b, _)| (a, b)).collect();
        for pair in [("RemoteLink", "Operator"), ("RemoteLink", "MissionPlanner"), ("MissionPlanner", "Operator")] {
            assert!(edges.contains(&(pair.0.into(), pair.1.into())), "{engine:?}: {pair:?} in {edges:?}");
        }
        for (name, picture) in files.iter().filter(|(n, _)| n.starts_with("wiring-")) {
            assert!(!boxes(picture).is_empty(), "{engine:?} {name}: no boxes read");
            let bad = over_boxes(picture, 2.0);
            assert!(bad.is_empty(), "{engine:?} {name}: {bad:?}");
            assert!(picture.contains("Wiring in "), "{engine:?} {name}: a title");
        }
    }
}

#[test]
fn fsm_links_are_drawn_only_where_their_fsm_state_can_be_active() {
    let dot = |s: &str| {
        let o = situ(&["graph", DRONE, "--view", "wiring", "--state", s]);
        assert_eq!(code(&o), 0, "{}", text(&o));
        stdout(&o)
    };
    let landed = dot("Landed");
    assert!(!landed.contains("Gimbal in Aiming") && !landed.contains("Gimbal in Recording"), "{landed}");
    assert!(landed.contains("(FSM: Stowed)"), "{landed}");
    let inspect = dot("Inspect");
    assert!(inspect.contains("\"MissionPlanner\" -> \"Gimbal\" [style=dashed"), "{inspect}");
    assert!(inspect.contains("Gimbal in Aiming") && inspect.contains("Gimbal in Recording"), "{inspect}");
    assert!(inspect.contains("(FSM: Aiming, Recording)"), "{inspect}");
    // The small multiples too: on the ground the gimbal has no link.
    let all = stdout(&situ(&["graph", DRONE, "--view", "wiring"]));
    let landed_cluster = &all[all.find("cluster_Landed").unwrap()..all.find("cluster_Takeoff").unwrap()];
    assert!(landed_cluster.contains("\"Landed/Gimbal\" ["), "{landed_cluster}");
    assert!(
        !landed_cluster.contains("-> \"Landed/Gimbal\"") && !landed_cluster.contains("\"Landed/Gimbal\" ->"),
        "{landed_cluster}"
    );
}

/// The state band's rectangles of a timeline: state name, width, tooltip.
fn state_rects(svg: &str, names: &[&str]) -> Vec<(String, f64, String)> {
    svg.lines()
        .filter(|l| l.starts_with("<rect x="))
        .filter_map(|l| {
            let tip = unescape(&l[l.find("<title>")? + 7..l.find("</title>")?]);
            let name = tip.split(':').next()?.to_string();
            names.contains(&name.as_str()).then(|| (name, attr(l, "width").unwrap().parse().unwrap(), tip))
        })
        .collect()
}

#[test]
fn the_timeline_shows_every_visited_state_however_short_with_its_name() {
    let dir = tempfile::tempdir().unwrap();
    let (out, files) = drone_run(Engine::Builtin, dir.path());
    let path = out.lines().find_map(|l| l.strip_prefix("path: ")).unwrap_or_else(|| panic!("a path: {out}"));
    let visited: Vec<&str> = path.split(" → ").collect();
    assert!(visited.contains(&"Emergency"), "{path}");
    let timeline = &files["timeline.svg"];
    let rects = state_rects(timeline, &visited);
    assert_eq!(rects.len(), visited.len(), "{rects:?}");
    let emergency = rects.iter().find(|r| r.0 == "Emergency").unwrap();
    // It was short: under a tenth of a second of a run of a minute.
    let times: Vec<f64> = emergency
        .2
        .split(": ")
        .nth(1)
        .unwrap()
        .split(" – ")
        .map(|t| t.trim_end_matches('s').parse().unwrap())
        .collect();
    assert!(times[1] - times[0] < 0.1, "{emergency:?}");
    for (name, width, tip) in &rects {
        assert!(*width >= 4.0, "{name} ({tip}) drawn {width} px wide");
        assert!(timeline.contains(&format!(">{name}</text>")), "the label of {name} is kept");
    }
}

fn size(svg: &str) -> (f64, f64) {
    let tag = &svg[svg.find("<svg").unwrap()..];
    let tag = &tag[..tag.find('>').unwrap()];
    // In px (`pt` is 4/3 px).
    let px = |s: &str| {
        let v = s.trim_end_matches(char::is_alphabetic).parse::<f64>().unwrap();
        if s.ends_with("pt") {
            v * 4.0 / 3.0
        } else {
            v
        }
    };
    (px(attr(tag, "width").unwrap()), px(attr(tag, "height").unwrap()))
}

#[test]
fn the_built_in_layout_has_titles_a_legend_and_about_graphviz_s_size() {
    require_dot();
    let args = ["graph", "rules/outdoor.situ", "--view", "states", "--format", "svg"];
    let (gw, gh) = size(&svg(Engine::Graphviz, &args));
    let (bw, bh) = size(&svg(Engine::Builtin, &args));
    assert!(bw <= 1.5 * gw && bh <= 1.5 * gh, "built-in {bw} × {bh}, Graphviz {gw} × {gh}");
    let wiring = svg(Engine::Builtin, &["graph", DRONE, "--view", "wiring", "--state", "Inspect", "--format", "svg"]);
    assert!(wiring.contains(">Wiring in Inspect: holding on a target, filming it</text>"), "{wiring}");
    // The legend is a legend: no agent box named after it.
    let ids: Vec<String> = boxes(&wiring).into_iter().map(|b| b.0).collect();
    assert!(ids.iter().all(|i| !i.starts_with("legend")), "{ids:?}");
    let legend = groups(&wiring, "legend");
    assert_eq!(legend.len(), 1, "{wiring}");
    for word in ["running", "sleeping", "FSM agent"] {
        assert!(legend[0].contains(word), "{word}: {}", legend[0]);
    }
}
