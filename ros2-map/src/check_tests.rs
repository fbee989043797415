//! Each check: three maps that raise it and three near misses that do not.

use super::*;
use situ_compiler::check_source;

const RULES: &str = r#"
states { IDLE initial DRIVING BLOCKED CHARGING DONE final }
agent Lidar sensor { event OBSTACLE { distance: f64 } event CLEAR }
agent Base actuator { event MOVING { speed: f64 } event STOPPED }
agent Battery sensor { event LOW { percent: f64, cells: i64 } }
agent Diag interface { event FAULT { level: {warn, error}, present: bool } }
agent Planner processing { event PLANNED }
rule go { when state == IDLE and PLANNED then DRIVING }
rule block { when state == DRIVING and OBSTACLE then BLOCKED }
rule free { when state == BLOCKED and CLEAR then DRIVING }
rule charge salience 5 { when state in {IDLE, DRIVING} and LOW then CHARGING }
rule fault salience 10 { when state != DONE and FAULT then DONE }
rule arrive salience 1 { when state == DRIVING and STOPPED then DONE }
rule towed salience 1 { when state == CHARGING and MOVING then DONE }
"#;

fn codes_of(map: &str) -> Vec<&'static str> {
    let checked = check_source("rules.situ", RULES);
    assert_eq!(checked.errors(), 0, "{:?}", checked.diagnostics);
    check_map(&checked.model, map, &Registry::carried(), FileId(1)).into_iter().map(|d| d.code).collect()
}

fn raises(code: &str, maps: [&str; 3]) {
    for map in maps {
        let found = codes_of(map);
        assert!(found.contains(&code), "expected {code} from:\n{map}\nfound {found:?}");
    }
}

fn spares(code: &str, maps: [&str; 3]) {
    for map in maps {
        let found = codes_of(map);
        assert!(!found.contains(&code), "unexpected {code} from:\n{map}\nfound {found:?}");
    }
}

/// One `[[event]]` of `agent`, `event` from `topic` as `ty`, then `rest`.
fn ev(agent: &str, event: &str, topic: &str, ty: &str, rest: &str) -> String {
    format!("[[event]]\nagent = \"{agent}\"\nevent = \"{event}\"\ntopic = \"{topic}\"\ntype = \"{ty}\"\n{rest}\n")
}

fn scan(event: &str, rest: &str) -> String {
    ev("Lidar", event, "/scan", "sensor_msgs/msg/LaserScan", rest)
}

fn odom(event: &str, rest: &str) -> String {
    ev("Base", event, "/odom", "nav_msgs/msg/Odometry", rest)
}

const DIST: &str = "[event.payload]\ndistance = \"min(ranges)\"";

/// The clean map of the tests: every event of every agent it maps.
fn clean() -> String {
    [
        scan("OBSTACLE", &format!("when = \"min(ranges) < 0.5\"\n{DIST}")),
        scan("CLEAR", "when = \"not (min(ranges) < 0.5)\""),
        odom("MOVING", "when = \"twist.twist.linear.x > 0.05\"\n[event.payload]\nspeed = \"twist.twist.linear.x * 3.6\""),
        odom("STOPPED", "when = \"twist.twist.linear.x <= 0.05\""),
        ev(
            "Battery",
            "LOW",
            "/battery",
            "sensor_msgs/BatteryState",
            "when = \"percentage < 0.2 and present\"\n[event.payload]\npercent = \"percentage * 100\"\ncells = \"len(cell_voltage)\"",
        ),
        ev(
            "Diag",
            "FAULT",
            "/diagnostics",
            "diagnostic_msgs/msg/DiagnosticArray",
            "when = \"status[0].level >= 2 and status[0].name == 'base'\"\n[event.payload]\nlevel = \"'error'\"\npresent = \"true\"",
        ),
        "[[node]]\nagent = \"Planner\"\nnode = \"/planner\"\n".into(),
    ]
    .join("\n")
}

#[test]
fn the_clean_map_has_no_findings() {
    assert_eq!(codes_of(&clean()), Vec::<&str>::new());
}

#[test]
fn bad_map() {
    raises(
        codes::ROS2_BAD_MAP,
        ["[[event]\n", "[[event]]\nagent = \"Lidar\"\n", "[[node]]\nagent = \"Base\"\nnode = 1\n"],
    );
    spares(codes::ROS2_BAD_MAP, ["", "# nothing mapped yet\n", "[[node]]\nagent = \"Base\"\nnode = \"/base\"\n"]);
}

#[test]
fn unknown_type() {
    raises(
        codes::ROS2_UNKNOWN_TYPE,
        [
            &ev("Lidar", "CLEAR", "/scan", "sensor_msgs/msg/LaserScn", ""),
            &ev("Lidar", "CLEAR", "/scan", "LaserScan", ""),
            &ev("Lidar", "CLEAR", "/scan", "sensor_msgs/srv/LaserScan", ""),
        ],
    );
    spares(
        codes::ROS2_UNKNOWN_TYPE,
        [
            &ev("Lidar", "CLEAR", "/scan", "sensor_msgs/LaserScan", ""),
            &ev("Lidar", "CLEAR", "/scan", "sensor_msgs/msg/LaserScan", ""),
            &ev("Lidar", "CLEAR", "/range", "sensor_msgs/Range", ""),
        ],
    );
}

#[test]
fn unknown_field() {
    raises(
        codes::ROS2_UNKNOWN_FIELD,
        [
            &scan("CLEAR", "when = \"min(range) > 1\""),
            &odom("STOPPED", "when = \"twist.linear.x == 0\""),
            &odom("STOPPED", "when = \"pose.covariance[36] > 1\""),
        ],
    );
    spares(
        codes::ROS2_UNKNOWN_FIELD,
        [
            &scan("CLEAR", "when = \"min(ranges) > 1\""),
            &odom("STOPPED", "when = \"twist.twist.linear.x == 0\""),
            &odom("STOPPED", "when = \"pose.covariance[35] > 1\""),
        ],
    );
}

#[test]
fn bad_expression() {
    raises(
        codes::ROS2_BAD_EXPRESSION,
        [
            &scan("CLEAR", "when = \"min(ranges) >\""),
            &scan("CLEAR", "when = \"ranges[1] = 2\""),
            &scan("OBSTACLE", "[event.payload]\ndistance = \"median(ranges)\""),
        ],
    );
    spares(
        codes::ROS2_BAD_EXPRESSION,
        [
            &scan("CLEAR", "when = \"min(ranges) > 2\""),
            &scan("CLEAR", "when = \"ranges[1] > 2\""),
            &scan("OBSTACLE", "[event.payload]\ndistance = \"mean(ranges)\""),
        ],
    );
}

#[test]
fn unknown_name() {
    raises(
        codes::ROS2_UNKNOWN_NAME,
        [
            &ev("Lidar", "CLEARED", "/scan", "sensor_msgs/LaserScan", ""),
            &ev("Laser", "CLEAR", "/scan", "sensor_msgs/LaserScan", ""),
            "[[node]]\nagent = \"Planer\"\nnode = \"/planner\"\n",
        ],
    );
    spares(
        codes::ROS2_UNKNOWN_NAME,
        [
            &ev("Lidar", "CLEAR", "/scan", "sensor_msgs/LaserScan", ""),
            &ev("Base", "STOPPED", "/odom", "nav_msgs/Odometry", ""),
            "[[node]]\nagent = \"Planner\"\nnode = \"/planner\"\n",
        ],
    );
}

#[test]
fn foreign_event() {
    raises(
        codes::ROS2_FOREIGN_EVENT,
        [
            &ev("Lidar", "STOPPED", "/odom", "nav_msgs/Odometry", ""),
            &ev("Base", "CLEAR", "/scan", "sensor_msgs/LaserScan", ""),
            &ev("Planner", "FAULT", "/diagnostics", "diagnostic_msgs/DiagnosticArray", ""),
        ],
    );
    spares(
        codes::ROS2_FOREIGN_EVENT,
        [
            &ev("Base", "STOPPED", "/odom", "nav_msgs/Odometry", ""),
            &ev("Lidar", "CLEAR", "/scan", "sensor_msgs/LaserScan", ""),
            // An unknown agent is E0405, not this.
            &ev("Nobody", "CLEAR", "/scan", "sensor_msgs/LaserScan", ""),
        ],
    );
}

#[test]
fn extra_payload_field() {
    raises(
        codes::ROS2_EXTRA_PAYLOAD,
        [
            &scan("OBSTACLE", &format!("{DIST}\nheight = \"0.3\"")),
            &scan("CLEAR", "[event.payload]\ndistance = \"1\""),
            &scan("OBSTACLE", "[event.payload]\ndistanse = \"min(ranges)\""),
        ],
    );
    spares(codes::ROS2_EXTRA_PAYLOAD, [&scan("OBSTACLE", DIST), &scan("CLEAR", ""), &scan("CLEAR", "[event.payload]")]);
}

#[test]
fn missing_payload_field() {
    raises(
        codes::ROS2_MISSING_PAYLOAD,
        [
            &scan("OBSTACLE", ""),
            &scan("OBSTACLE", "[event.payload]\ndistanse = \"min(ranges)\""),
            &ev("Battery", "LOW", "/b", "sensor_msgs/BatteryState", "[event.payload]\npercent = \"percentage\""),
        ],
    );
    spares(
        codes::ROS2_MISSING_PAYLOAD,
        [
            &scan("OBSTACLE", DIST),
            &scan("CLEAR", ""),
            &ev(
                "Battery",
                "LOW",
                "/b",
                "sensor_msgs/BatteryState",
                "[event.payload]\npercent = \"percentage\"\ncells = \"len(cell_voltage)\"",
            ),
        ],
    );
}

#[test]
fn type_mismatch() {
    raises(
        codes::ROS2_TYPE_MISMATCH,
        [
            &scan("OBSTACLE", "[event.payload]\ndistance = \"header.frame_id\""),
            &scan("CLEAR", "when = \"min(range_max) > 1\""),
            &scan("CLEAR", "when = \"header.frame_id == 2\""),
        ],
    );
    spares(
        codes::ROS2_TYPE_MISMATCH,
        [
            &scan("OBSTACLE", "[event.payload]\ndistance = \"range_max\""),
            &scan("CLEAR", "when = \"min(ranges) > 1\""),
            &scan("CLEAR", "when = \"header.frame_id == 'laser'\""),
        ],
    );
}

#[test]
fn payload_types_fit_fields() {
    let diag = |level: &str, present: &str| {
        ev(
            "Diag",
            "FAULT",
            "/d",
            "diagnostic_msgs/DiagnosticArray",
            &format!("[event.payload]\nlevel = \"{level}\"\npresent = \"{present}\""),
        )
    };
    let battery = |cells: &str| {
        ev(
            "Battery",
            "LOW",
            "/b",
            "sensor_msgs/BatteryState",
            &format!("[event.payload]\npercent = \"1\"\ncells = \"{cells}\""),
        )
    };
    raises(codes::ROS2_TYPE_MISMATCH, [&diag("'fatal'", "true"), &diag("'warn'", "1"), &battery("percentage")]);
    spares(
        codes::ROS2_TYPE_MISMATCH,
        [&diag("'warn'", "true"), &diag("status[0].name", "len(status) > 0"), &battery("len(cell_voltage)")],
    );
}

#[test]
fn when_not_a_condition() {
    raises(
        codes::ROS2_WHEN_NOT_BOOL,
        [
            &scan("CLEAR", "when = \"min(ranges)\""),
            &scan("CLEAR", "when = \"header.frame_id\""),
            &scan("CLEAR", "when = \"ranges\""),
        ],
    );
    spares(
        codes::ROS2_WHEN_NOT_BOOL,
        [
            &scan("CLEAR", "when = \"min(ranges) > 1\""),
            &scan("CLEAR", "when = \"header.frame_id != ''\""),
            &ev("Battery", "LOW", "/b", "sensor_msgs/BatteryState", "when = \"present\""),
        ],
    );
}

#[test]
fn unmapped_event() {
    raises(
        codes::ROS2_UNMAPPED_EVENT,
        [&scan("OBSTACLE", DIST), &scan("CLEAR", ""), &odom("MOVING", "[event.payload]\nspeed = \"1\"")],
    );
    spares(
        codes::ROS2_UNMAPPED_EVENT,
        [
            &format!("{}\n{}", scan("OBSTACLE", DIST), scan("CLEAR", "")),
            // Agents the map does not mention are not reported.
            "[[node]]\nagent = \"Base\"\nnode = \"/base\"\n",
            &ev("Battery", "LOW", "/b", "sensor_msgs/BatteryState", ""),
        ],
    );
}

#[test]
fn two_nodes_for_one_agent() {
    let node = |agent: &str, node: &str| format!("[[node]]\nagent = \"{agent}\"\nnode = \"{node}\"\n");
    raises(
        codes::ROS2_TWO_NODES,
        [
            &(node("Planner", "/a") + &node("Planner", "/b")),
            &(node("Planner", "/a") + &node("Planner", "/a") + "timeout = \"2s\"\n"),
            &(node("Base", "/a") + &node("Planner", "/b") + &node("Base", "/c")),
        ],
    );
    spares(
        codes::ROS2_TWO_NODES,
        [
            &node("Planner", "/a"),
            &(node("Planner", "/a") + &node("Base", "/b")),
            // The same entry twice is W0417.
            &(node("Planner", "/a") + &node("Planner", "/a")),
        ],
    );
}

#[test]
fn topic_with_two_types() {
    raises(
        codes::ROS2_TOPIC_TYPES,
        [
            &(scan("CLEAR", "") + &ev("Lidar", "OBSTACLE", "/scan", "sensor_msgs/Range", "")),
            &(odom("MOVING", "") + &ev("Base", "STOPPED", "/odom", "geometry_msgs/TwistStamped", "")),
            &(scan("CLEAR", "") + &ev("Lidar", "OBSTACLE", "/scan", "sensor_msgs/msg/Range", "")),
        ],
    );
    spares(
        codes::ROS2_TOPIC_TYPES,
        [
            &(scan("CLEAR", "") + &ev("Lidar", "OBSTACLE", "/scan", "sensor_msgs/LaserScan", "")),
            &(odom("MOVING", "") + &odom("STOPPED", "")),
            &(scan("CLEAR", "") + &ev("Lidar", "OBSTACLE", "/range", "sensor_msgs/Range", "")),
        ],
    );
}

fn node(agent: &str, name: &str, rest: &str) -> String {
    format!("[[node]]\nagent = \"{agent}\"\nnode = \"{name}\"\n{rest}\n")
}

#[test]
fn bad_nodes() {
    raises(
        codes::ROS2_BAD_NODE,
        [
            &node("Planner", "planner", ""),
            &node("Planner", "/planner", "failed = \"CLEAR\""),
            &node("Battery", "/battery", "failed = \"LOW\"\ntimeout = \"2\""),
        ],
    );
    spares(
        codes::ROS2_BAD_NODE,
        [
            &node("Planner", "/nav/planner_1", "failed = \"PLANNED\""),
            &node("Planner", "/planner", "timeout = \"250ms\""),
            &node("Base", "/base", "failed = \"STOPPED\"\ntimeout = \"3s\""),
        ],
    );
    for (name, ok) in [("/a", true), ("/a/b_c", true), ("/", false), ("/a//b", false), ("/1a", false), ("/a-b", false)]
    {
        assert_eq!(is_node_name(name), ok, "{name}");
    }
}

#[test]
fn a_failure_event_is_produced_by_the_map() {
    let map = node("Planner", "/planner", "failed = \"PLANNED\"");
    assert!(!codes_of(&map).contains(&codes::ROS2_UNMAPPED_EVENT));
    assert!(codes_of(&node("Planner", "/planner", "failed = \"PLANED\"")).contains(&codes::ROS2_UNKNOWN_NAME));
}

#[test]
fn every_finding_at_once_and_in_the_map() {
    let map = format!(
        "{}\n{}\n[[node]]\nagent = \"Ghost\"\nnode = \"/g\"\n",
        scan("OBSTACLE", "when = \"min(rangez) < 1\""),
        ev("Lidar", "CLEAR", "/scan", "sensor_msgs/Rang", "")
    );
    let checked = check_source("rules.situ", RULES);
    let found = check_map(&checked.model, &map, &Registry::carried(), FileId(1));
    let codes: Vec<_> = found.iter().map(|d| d.code).collect();
    for code in
        [codes::ROS2_UNKNOWN_FIELD, codes::ROS2_MISSING_PAYLOAD, codes::ROS2_UNKNOWN_TYPE, codes::ROS2_UNKNOWN_NAME]
    {
        assert!(codes.contains(&code), "{code} not in {codes:?}");
    }
    let field = found.iter().find(|d| d.code == codes::ROS2_UNKNOWN_FIELD).unwrap();
    assert_eq!(&map[field.primary.span.start..field.primary.span.end], "rangez");
    assert_eq!(field.help.as_deref().map(|h| h.starts_with("did you mean `ranges`?")), Some(true));
    for d in found.iter().filter(|d| d.primary.file == FileId(1)) {
        assert!(d.primary.span.start <= d.primary.span.end && d.primary.span.end <= map.len(), "{d:?}");
    }
}

/// The ```situ and ```toml blocks after a heading of a code's doc.
fn blocks<'a>(doc: &'a str, heading: &str, lang: &str) -> Vec<&'a str> {
    let start = doc.find(heading).expect("the heading");
    let section = &doc[start + heading.len()..];
    let section = &section[..section.find("\n## ").unwrap_or(section.len())];
    section.split(&format!("```{lang}\n")).skip(1).filter_map(|b| b.split("```").next()).collect()
}

#[test]
fn the_examples_of_the_codes_are_real() {
    // The examples of E0422 and E0423 need definition files and folders:
    // `the_examples_with_files_are_real` holds them to their codes.
    let with_files = [codes::ROS2_BAD_DEFINITION, codes::ROS2_BAD_MSG_PATH];
    let ros2 = |c: &&codes::Code| c.code.starts_with("E04") || c.code.starts_with("W04");
    for c in codes::ALL.iter().filter(ros2).filter(|c| !with_files.contains(&c.code)) {
        for (heading, raised) in [("## Example", true), ("## Use instead", false)] {
            let rules = blocks(c.explain, heading, "situ");
            let maps = blocks(c.explain, heading, "toml");
            assert!(!rules.is_empty() && !maps.is_empty(), "{}: {heading} needs rules and a map", c.code);
            let checked = check_source("rules.situ", rules[0]);
            assert_eq!(checked.errors(), 0, "{}: {heading}: the rules have errors", c.code);
            let found: Vec<_> = check_map(&checked.model, maps[0], &Registry::carried(), FileId(1))
                .into_iter()
                .map(|d| d.code)
                .collect();
            assert_eq!(found.contains(&c.code), raised, "{}: {heading}: found {found:?}", c.code);
        }
    }
}

/// The findings of `map` (rules `rules`) checked in folder `dir` with
/// `--msg-path DIR/robot_msgs` when `msg_path` is set.
fn codes_in(dir: &std::path::Path, rules: &str, map: &str, msg_path: bool) -> Vec<&'static str> {
    let checked = check_source("rules.situ", rules);
    assert_eq!(checked.errors(), 0, "{:?}", checked.diagnostics);
    let user = if msg_path { vec![dir.join("robot_msgs")] } else { Vec::new() };
    let (found, _) = crate::load::check_map_file(&checked.model, map, dir, &user, FileId(1));
    found.into_iter().map(|d| d.code).collect()
}

#[test]
fn the_examples_with_files_are_real() {
    let dir = std::env::temp_dir().join(format!("situ-code-examples-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let msg = dir.join("robot_msgs/msg");
    std::fs::create_dir_all(&msg).unwrap();
    // E0422: Arm.msg of the Example, then Gripper.msg of Use instead.
    let doc = codes::lookup("E0422").unwrap().explain;
    let (example, fix) = (blocks(doc, "## Example", "text"), blocks(doc, "## Use instead", "text"));
    std::fs::write(msg.join("Arm.msg"), example[0]).unwrap();
    let (rules, map) = (blocks(doc, "## Example", "situ")[0], blocks(doc, "## Example", "toml")[0]);
    assert!(codes_in(&dir, rules, map, true).contains(&codes::ROS2_BAD_DEFINITION));
    std::fs::write(msg.join("Gripper.msg"), fix[0]).unwrap();
    let (rules, map) = (blocks(doc, "## Use instead", "situ")[0], blocks(doc, "## Example", "toml")[0]);
    assert!(!codes_in(&dir, rules, map, true).contains(&codes::ROS2_BAD_DEFINITION));
    // E0423: the map in `dir/maps`, the package in `dir/robot_msgs`.
    let doc = codes::lookup("E0423").unwrap().explain;
    let maps = dir.join("maps");
    std::fs::create_dir_all(&maps).unwrap();
    let (rules, map) = (blocks(doc, "## Example", "situ")[0], blocks(doc, "## Example", "toml")[0]);
    assert!(codes_in(&maps, rules, map, false).contains(&codes::ROS2_BAD_MSG_PATH));
    let (rules, map) = (blocks(doc, "## Use instead", "situ")[0], blocks(doc, "## Use instead", "toml")[0]);
    let found = codes_in(&maps, rules, map, false);
    assert!(!found.contains(&codes::ROS2_BAD_MSG_PATH) && !found.contains(&codes::ROS2_UNKNOWN_TYPE), "{found:?}");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn deep_and_long_inputs_are_refused_not_crashed() {
    let checked = check_source("rules.situ", RULES);
    let deep_array = format!("x = {}", "[".repeat(100_000));
    let deep_table = format!("x = {}", "{a = ".repeat(100_000));
    let long_chain = scan("CLEAR", &format!("when = \"{} > 1\"", vec!["range_max"; 255].join(" + ")));
    for map in [deep_array, deep_table, long_chain] {
        let _ = check_map(&checked.model, &map, &Registry::carried(), FileId(1));
    }
}

mod no_panic {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(512))]

        /// Any cut, insertion or byte replacement of the clean map is checked
        /// without a panic, and every place is inside the map.
        #[test]
        fn mutated_maps(at in 0usize..2000, len in 0usize..40, insert in "[\\PC\\[\\]().\"'=<>!+*/ -]{0,12}") {
            let map = clean();
            let mut at = at.min(map.len());
            while !map.is_char_boundary(at) { at -= 1; }
            let mut end = (at + len).min(map.len());
            while !map.is_char_boundary(end) { end -= 1; }
            let mutated = format!("{}{}{}", &map[..at], insert, &map[end..]);
            let checked = check_source("rules.situ", RULES);
            for d in check_map(&checked.model, &mutated, &Registry::carried(), FileId(1)) {
                prop_assert!(d.primary.span.start <= d.primary.span.end && d.primary.span.end <= mutated.len());
            }
        }

        /// Any expression text parses or fails without a panic.
        #[test]
        fn any_expression(text in "[a-z0-9_\\[\\]().,'<>=!&|+*/ -]{0,80}") {
            let _ = crate::expr::parse(&text);
            let map = scan("CLEAR", &format!("when = {text:?}"));
            let checked = check_source("rules.situ", RULES);
            let _ = check_map(&checked.model, &map, &Registry::carried(), FileId(1));
        }
    }
}

/// The findings of `code` in `map`.
fn findings(map: &str, code: &str) -> Vec<Diagnostic> {
    let checked = check_source("rules.situ", RULES);
    check_map(&checked.model, map, &Registry::carried(), FileId(1)).into_iter().filter(|d| d.code == code).collect()
}

/// The text of the map at a finding's place.
fn at(map: &str, span: situ_grammar::ast::Span) -> &str {
    &map[span.start..span.end]
}

#[test]
fn bad_topic_names() {
    let topic = |t: &str| ev("Lidar", "CLEAR", t, "sensor_msgs/LaserScan", "");
    for bad in
        ["", "/wrist-range", "/e stop", "/2pick", "scan", "~/range", "/{robot}/scan", "/", "/a/", "/a//b", "/a__b"]
    {
        raises(codes::ROS2_BAD_TOPIC, [&topic(bad), &topic(bad), &topic(bad)]);
    }
    spares(codes::ROS2_BAD_TOPIC, [&topic("/scan"), &topic("/robot_1/arm/pick_2"), &topic("/_hidden/Scan9")]);

    // The place is the character at fault, the help and the fix the corrected name.
    let map = topic("/wrist-range");
    let d = &findings(&map, codes::ROS2_BAD_TOPIC)[0];
    assert_eq!(at(&map, d.primary.span), "-");
    assert!(d.help.as_deref().is_some_and(|h| h.contains("`topic = \"/wrist_range\"`")), "{d:?}");
    assert_eq!(d.fixes[0].edits[0].text, "/wrist_range");
    assert_eq!(at(&map, d.fixes[0].edits[0].span), "/wrist-range");
    let map = topic("scan");
    let d = &findings(&map, codes::ROS2_BAD_TOPIC)[0];
    assert!(d.message.contains("relative"), "{d:?}");
    assert!(d.help.as_deref().is_some_and(|h| h.contains("`topic = \"/scan\"`")), "{d:?}");
    let map = topic("/2pick");
    let d = &findings(&map, codes::ROS2_BAD_TOPIC)[0];
    assert_eq!(at(&map, d.primary.span), "2pick");
    assert!(d.help.as_deref().is_some_and(|h| h.contains("ros2 topic list")) && d.fixes.is_empty(), "{d:?}");
    // An empty name points at its quotes.
    let map = topic("");
    assert_eq!(at(&map, findings(&map, codes::ROS2_BAD_TOPIC)[0].primary.span), "\"\"");
}

#[test]
fn one_node_for_two_agents() {
    let n = |agent: &str, name: &str| node(agent, name, "");
    raises(
        codes::ROS2_SHARED_NODE,
        [
            &(n("Planner", "/a") + &n("Base", "/a")),
            &(n("Planner", "/nav/a") + &n("Base", "/b") + &n("Lidar", "/nav/a")),
            &(n("Planner", "/a") + &node("Base", "/a", "timeout = \"2s\"")),
        ],
    );
    spares(
        codes::ROS2_SHARED_NODE,
        [
            &(n("Planner", "/a") + &n("Base", "/b")),
            &(n("Planner", "/a") + &n("Planner", "/a")),
            // A misspelt agent is E0405, not a second agent.
            &(n("Planner", "/a") + &n("Planer", "/a")),
        ],
    );
    // Both places are labelled.
    let map = n("Planner", "/a") + &n("Base", "/a");
    let d = &findings(&map, codes::ROS2_SHARED_NODE)[0];
    assert_eq!(d.message, "`/a` plays `Planner` and `Base`");
    assert_eq!(
        (d.primary.span.start, d.secondary[0].span.start),
        (map.rfind("\"/a\"").unwrap(), map.find("\"/a\"").unwrap())
    );
    assert!(d.help.as_deref().is_some_and(|h| h.contains("remove one `[[node]]`")), "{d:?}");
}

#[test]
fn repeated_entries() {
    let obstacle = |ty: &str, when: &str, dist: &str| {
        ev("Lidar", "OBSTACLE", "/scan", ty, &format!("when = \"{when}\"\n[event.payload]\ndistance = \"{dist}\""))
    };
    let first = obstacle("sensor_msgs/msg/LaserScan", "min(ranges) < 0.5", "min(ranges)");
    raises(
        codes::ROS2_DUPLICATE_ENTRY,
        [
            &(first.clone() + &first),
            // The short form of the type, the expressions without their spaces.
            &(first.clone() + &obstacle("sensor_msgs/LaserScan", "min(ranges)<0.5", " min( ranges )")),
            // Two payloads for one message.
            &(first.clone() + &obstacle("sensor_msgs/LaserScan", "min(ranges) < 0.5", "range_max")),
        ],
    );
    spares(
        codes::ROS2_DUPLICATE_ENTRY,
        [
            &(first.clone() + &obstacle("sensor_msgs/LaserScan", "min(ranges) < 0.4", "min(ranges)")),
            &(first.clone()
                + &ev(
                    "Lidar",
                    "OBSTACLE",
                    "/front_scan",
                    "sensor_msgs/LaserScan",
                    &format!("when = \"min(ranges) < 0.5\"\n{DIST}"),
                )),
            &(scan("CLEAR", "") + &scan("CLEAR", "when = \"min(ranges) > 1\"")),
        ],
    );
    raises(
        codes::ROS2_DUPLICATE_ENTRY,
        [
            &(scan("CLEAR", "") + &scan("CLEAR", "")),
            &(node("Planner", "/p", "") + &node("Planner", "/p", "")),
            &(node("Planner", "/p", "timeout = \"1s\"") + &node("Planner", "/p", "timeout = \"1s\"")),
        ],
    );
    spares(
        codes::ROS2_DUPLICATE_ENTRY,
        [
            &(node("Planner", "/p", "") + &node("Planner", "/p", "timeout = \"2s\"")),
            &(node("Planner", "/p", "") + &node("Base", "/p", "")),
            &(scan("CLEAR", "") + &odom("STOPPED", "")),
        ],
    );
    // A warning, both entries labelled; the help says to remove one.
    let map = first.clone() + &first;
    let d = &findings(&map, codes::ROS2_DUPLICATE_ENTRY)[0];
    assert_eq!(d.severity, situ_grammar::diag::Severity::Warning);
    assert!(d.primary.span.start > d.secondary[0].span.start, "{d:?}");
    assert_eq!((at(&map, d.primary.span), at(&map, d.secondary[0].span)), ("\"OBSTACLE\"", "\"OBSTACLE\""));
    assert!(d.message.contains("posts `OBSTACLE` twice"), "{d:?}");
    assert!(d.help.as_deref().is_some_and(|h| h.contains("remove one")), "{d:?}");
}

#[test]
fn the_bridges_own_topics() {
    let read = |topic: &str| ev("Base", "STOPPED", topic, "std_msgs/msg/String", "when = \"data == 'IDLE'\"");
    raises(codes::ROS2_BRIDGE_TOPIC, [&read("/situ/state"), &read("/situ/agents"), &read("/situ")]);
    spares(codes::ROS2_BRIDGE_TOPIC, [&read("/situation"), &read("/robot/situ/state"), &read("/state")]);

    let diag = |topic: &str, when: &str| {
        ev(
            "Diag",
            "FAULT",
            topic,
            "diagnostic_msgs/msg/DiagnosticArray",
            &format!("when = \"{when}\"\n[event.payload]\nlevel = \"'error'\"\npresent = \"true\""),
        )
    };
    raises(
        codes::ROS2_BRIDGE_DIAGNOSTICS,
        [
            &diag("/diagnostics", "len(status) > 0 and status[0].level >= 0"),
            &diag("/diagnostics", "status[0].level >= 2 or status[0].hardware_id == 'base'"),
            &diag("/diagnostics", "status[0].level >= 2 and status[0].hardware_id == 'situ'"),
        ],
    );
    spares(
        codes::ROS2_BRIDGE_DIAGNOSTICS,
        [
            &diag("/diagnostics", "status[0].level >= 2 and status[0].hardware_id == 'base'"),
            &diag("/diagnostics", "status[0].level >= 2 and status[0].hardware_id != 'situ'"),
            &diag("/diagnostics_agg", "len(status) > 0 and status[0].level >= 0"),
        ],
    );
    let map = diag("/diagnostics", "status[0].level >= 0");
    let d = &findings(&map, codes::ROS2_BRIDGE_DIAGNOSTICS)[0];
    assert_eq!(d.severity, situ_grammar::diag::Severity::Warning);
    assert_eq!(at(&map, d.primary.span), "\"/diagnostics\"");
    assert!(d.help.as_deref().is_some_and(|h| h.contains("ignores the messages of its own writers")), "{d:?}");
}

#[test]
fn timeouts_are_written_as_the_rules_write_durations() {
    raises(
        codes::ROS2_BAD_NODE,
        [
            &node("Planner", "/p", "timeout = \"500 ms\""),
            &node("Planner", "/p", "timeout = \"2 sec\""),
            &node("Planner", "/p", "timeout = \"0s\""),
        ],
    );
    spares(
        codes::ROS2_BAD_NODE,
        [
            &node("Planner", "/p", "timeout = \"1.5s\""),
            &node("Planner", "/p", "timeout = \"2min\""),
            &node("Planner", "/p", "timeout = \"750us\""),
        ],
    );
    let map = node("Planner", "/p", "timeout = \"500 ms\"");
    let d = &findings(&map, codes::ROS2_BAD_NODE)[0];
    assert_eq!(at(&map, d.primary.span), "\"500 ms\"");
    assert!(d.help.as_deref().is_some_and(|h| h.contains("`timeout = \"500ms\"`")), "{d:?}");
    assert_eq!(d.fixes[0].edits[0].text, "500ms");
    let map = node("Planner", "/p", "timeout = \"soon\"");
    let d = &findings(&map, codes::ROS2_BAD_NODE)[0];
    assert!(d.help.as_deref().is_some_and(|h| h.contains("`\"1.5s\"`")) && d.fixes.is_empty(), "{d:?}");
}

#[test]
fn an_unknown_type_raises_no_follow_on_topic_finding() {
    spares(
        codes::ROS2_TOPIC_TYPES,
        [
            &(scan("CLEAR", "") + &ev("Lidar", "OBSTACLE", "/scan", "sensor_msgs/LaserScna", "")),
            &(ev("Lidar", "OBSTACLE", "/scan", "robot_msgs/Scan", "") + &scan("CLEAR", "")),
            &(scan("CLEAR", "") + &ev("Lidar", "OBSTACLE", "/scan", "LaserScan", "")),
        ],
    );
}

fn help_of(map: &str, code: &str) -> String {
    let checked = check_source("rules.situ", RULES);
    let found = check_map(&checked.model, map, &Registry::carried(), FileId(1));
    let d = found.iter().find(|d| d.code == code).unwrap_or_else(|| panic!("no {code} in {found:?}"));
    d.help.clone().unwrap_or_default()
}

#[test]
fn an_unknown_type_lists_the_types_of_its_package_or_where_situ_looked() {
    let help = help_of(&ev("Lidar", "CLEAR", "/scan", "sensor_msgs/msg/LaserScn", ""), codes::ROS2_UNKNOWN_TYPE);
    assert!(help.starts_with("did you mean `sensor_msgs/msg/LaserScan`? `sensor_msgs` has: BatteryState, "), "{help}");
    assert!(help.contains(", JointState, "), "{help}");
    let help = help_of(&ev("Lidar", "CLEAR", "/scan", "sensor_msgs/Zzz", ""), codes::ROS2_UNKNOWN_TYPE);
    assert!(help.starts_with("`sensor_msgs` has: BatteryState, "), "{help}");
    let help = help_of(&ev("Lidar", "CLEAR", "/scan", "robot_msgs/Scan", ""), codes::ROS2_UNKNOWN_TYPE);
    assert!(help.starts_with("no package `robot_msgs` in: the definitions situ carries; "), "{help}");
    let help = help_of(&ev("Lidar", "CLEAR", "/scan", "Scan", ""), codes::ROS2_UNKNOWN_TYPE);
    assert_eq!(help, "write the type as `package/msg/Name` or `package/Name`");
}

fn battery(when: &str) -> String {
    ev("Battery", "LOW", "/battery", "sensor_msgs/BatteryState", &format!("when = \"{when}\""))
}

fn diag(when: &str) -> String {
    ev("Diag", "FAULT", "/diagnostics", "diagnostic_msgs/DiagnosticArray", &format!("when = \"{when}\""))
}

#[test]
fn constants_by_name() {
    let fine = [
        battery("power_supply_status == POWER_SUPPLY_STATUS_CHARGING"),
        diag("len(status) > 0 and status[0].level >= DiagnosticStatus.ERROR"),
        ev("Lidar", "CLEAR", "/fix", "sensor_msgs/NavSatFix", "when = \"status.status == NavSatStatus.STATUS_FIX\""),
    ];
    for code in [codes::ROS2_UNKNOWN_FIELD, codes::ROS2_TYPE_MISMATCH, codes::ROS2_WHEN_NOT_BOOL] {
        spares(code, [&fine[0], &fine[1], &fine[2]]);
    }
    raises(
        codes::ROS2_TYPE_MISMATCH,
        [
            &battery("present == POWER_SUPPLY_STATUS_CHARGING"),
            &battery("POWER_SUPPLY_STATUS_CHARGING and present"),
            &diag("status[0].name == DiagnosticStatus.WARN"),
        ],
    );
    raises(
        codes::ROS2_UNKNOWN_FIELD,
        [
            &battery("power_supply_status == POWER_SUPPLY_STATUS_CHARGNG"),
            // KeyValue has no constants; Imu is not a type of DiagnosticArray's fields.
            &diag("status[0].level == KeyValue.ERROR"),
            &diag("status[0].level == Imu.ERROR"),
        ],
    );
    let help = help_of(&battery("power_supply_status == CHARGING"), codes::ROS2_UNKNOWN_FIELD);
    assert!(help.contains("; its constants: POWER_SUPPLY_STATUS_UNKNOWN, POWER_SUPPLY_STATUS_CHARGING, "), "{help}");
    let help = help_of(&diag("status[0].level == DiagnosticStatus.EROR"), codes::ROS2_UNKNOWN_FIELD);
    assert_eq!(
        help,
        "did you mean `DiagnosticStatus.ERROR`? `diagnostic_msgs/msg/DiagnosticStatus` has the constants: OK, WARN, ERROR, STALE"
    );
    let help = help_of(&diag("status[0].level == KeyValue.ERROR"), codes::ROS2_UNKNOWN_FIELD);
    assert_eq!(help, "`diagnostic_msgs/msg/KeyValue` has no constants");
}

#[test]
fn constants_type_as_their_type() {
    let reg = Registry::carried();
    let ty = |msg: &'static str, text: &str| {
        let s = map::Str { value: text.to_string(), span: situ_grammar::ast::Span::new(0, 0), inner: None };
        type_of(&s, msg, &reg, FileId(0)).ty
    };
    assert_eq!(ty("sensor_msgs/msg/BatteryState", "POWER_SUPPLY_STATUS_FULL"), Some(Ty::Int));
    assert_eq!(ty("diagnostic_msgs/msg/DiagnosticArray", "DiagnosticStatus.STALE"), Some(Ty::Int));
    assert_eq!(ty("diagnostic_msgs/msg/DiagnosticStatus", "DiagnosticStatus.OK"), Some(Ty::Int));
    assert_eq!(ty("std_msgs/msg/Bool", "data"), Some(Ty::Bool));
    // A field of the name wins over a type of the name.
    assert_eq!(ty("sensor_msgs/msg/NavSatFix", "status.status"), Some(Ty::Int));
    assert_eq!(ty("sensor_msgs/msg/BatteryState", "NOPE"), None);
}
