//! The central registry of diagnostic codes. Every finding the compiler can
//! report has an entry here with its severity, a one-line title, and the long
//! text `situ explain` prints (one Markdown file per code in `docs/codes/`).

use situ_grammar::diag::Severity;

/// One diagnostic code.
#[derive(Debug, Clone, Copy)]
pub struct Code {
    /// `E0101`; shown to users as `situ::E0101`.
    pub code: &'static str,
    pub severity: Severity,
    /// A short title.
    pub title: &'static str,
    /// The long text: What it does / Why is this bad / Example / Use instead.
    pub explain: &'static str,
}

macro_rules! codes {
    ($( $konst:ident = $code:literal, $sev:ident, $title:literal; )*) => {
        $(
            #[doc = $title]
            pub const $konst: &str = $code;
        )*
        /// Every code, in order.
        pub const ALL: &[Code] = &[
            $( Code {
                code: $code,
                severity: Severity::$sev,
                title: $title,
                explain: include_str!(concat!("../docs/codes/", $code, ".md")),
            }, )*
        ];
    };
}

codes! {
    SYNTAX = "E0001", Error, "syntax error";
    NOT_UTF8 = "E0002", Error, "the file is not UTF-8 text";
    INCLUDE_NOT_FOUND = "E0003", Error, "included file cannot be read";
    INCLUDE_CYCLE = "E0004", Error, "include cycle";
    TOO_DEEP = "E0006", Error, "nesting too deep";
    BAD_LITERAL = "E0007", Error, "literal out of range";
    TOO_MANY_ERRORS = "E0008", Error, "too many syntax errors";
    INCLUDE_TOO_DEEP = "E0009", Error, "include chain too deep";
    UNDEFINED_STATE = "E0101", Error, "undefined state";
    DUPLICATE = "E0102", Error, "duplicate definition";
    UNDEFINED_AGENT = "E0103", Error, "undefined agent";
    UNDEFINED_EVENT = "E0104", Error, "undefined event";
    UNDEFINED_FUNCTION = "E0105", Error, "undefined function";
    UNDEFINED_FIELD = "E0106", Error, "undefined payload field";
    INITIAL_STATE = "E0107", Error, "not exactly one initial state";
    UNBOUND_VARIABLE = "E0108", Error, "unbound variable";
    UNDEFINED_FSM_STATE = "E0109", Error, "undefined FSM state";
    FOREIGN_TRIGGER = "E0110", Error, "FSM triggered by another agent's event";
    BAD_ALLOW = "E0111", Error, "bad code in allow";
    CONFLICTING_MEMBERS = "E0112", Error, "conflicting agent members";
    MISSING_FIELD = "E0113", Error, "test event without every payload field";
    NEVER_STALE = "E0114", Error, "stale test on an agent that never goes stale";
    FSM_INITIAL = "E0115", Error, "not exactly one initial FSM state";
    SELF_LINK = "E0116", Error, "agent links to itself";
    TEST_TIME_ORDER = "E0117", Error, "test event earlier than the previous one";
    FOREIGN_SCRIPT_EVENT = "E0118", Error, "script event named with another agent";
    SCRIPT_TIME_ORDER = "E0119", Error, "script step that starts before the previous one";
    OVERLAPPING_EVERY = "E0120", Error, "periodic script events that overlap";
    BAD_INTERVAL = "E0121", Error, "script interval that is empty or too dense";
    EVENT_IN_SILENCE = "E0122", Error, "script event of an agent told to be silent";
    RATE_OUT_OF_RANGE = "E0123", Error, "agent rate out of range";
    TYPE_MISMATCH = "E0201", Error, "type mismatch";
    UNKNOWN_SYMBOL = "E0202", Error, "unknown symbol";
    BAD_OPERATOR = "E0203", Error, "operator does not apply to this type";
    ZERO = "E0204", Error, "zero count or length";
    VARIABLE_TYPE = "E0205", Error, "variable used with incompatible types";
    UNREACHABLE_STATE = "E0301", Error, "unreachable state";
    CONFLICTING_RULES = "E0302", Error, "conflicting rules";
    SHADOWED_RULE = "W0303", Warning, "rule shadowed by rules of higher salience";
    UNSATISFIABLE_RULE = "E0304", Error, "rule that can never fire";
    OSCILLATION = "E0305", Error, "rules that oscillate";
    TRAP_STATE = "W0306", Warning, "non-final state with no way out";
    DEAD_END = "W0307", Warning, "state from which no final state is reachable";
    UNUSED_EVENT = "W0308", Warning, "event no rule or FSM reads";
    NEVER_RUNNING = "W0309", Warning, "agent that never runs";
    UNUSED_FUNCTION = "W0310", Warning, "function never called";
    NO_TABLE_ENTRY = "W0311", Warning, "state without a table entry";
    DUPLICATE_ENTRY = "W0312", Warning, "state with two table entries";
    UNREACHABLE_FSM_STATE = "W0313", Warning, "unreachable FSM state";
    NONDETERMINISTIC_FSM = "W0314", Warning, "FSM transitions that fire on the same input";
    LINK_TO_IDLE = "W0315", Warning, "link to or from an agent that is not running";
    ACTUATOR_WITHOUT_INPUT = "W0316", Warning, "running actuator with no input";
    SENSOR_WITHOUT_OUTPUT = "W0317", Warning, "running sensor whose outputs go nowhere";
    DATA_CYCLE = "W0318", Warning, "data cycle";
    MAY_CONFLICT = "W0319", Warning, "rules that may conflict";
    CONCURRENT_COMMANDS = "W0320", Warning, "actuator commanded by several agents at once";
    INCOMPLETE_CHECK = "W0321", Warning, "static check stopped at its work budget";
    ROS2_BAD_MAP = "E0401", Error, "ROS 2 map that is not a valid map";
    ROS2_UNKNOWN_TYPE = "E0402", Error, "unknown ROS 2 message type";
    ROS2_UNKNOWN_FIELD = "E0403", Error, "field not in the ROS 2 message";
    ROS2_BAD_EXPRESSION = "E0404", Error, "malformed map expression";
    ROS2_UNKNOWN_NAME = "E0405", Error, "map names an agent or event the rules do not have";
    ROS2_FOREIGN_EVENT = "E0406", Error, "event mapped for an agent that does not report it";
    ROS2_EXTRA_PAYLOAD = "E0407", Error, "map fills a payload field the event does not have";
    ROS2_MISSING_PAYLOAD = "E0408", Error, "payload field the map does not fill";
    ROS2_TYPE_MISMATCH = "E0409", Error, "type mismatch in a map expression";
    ROS2_WHEN_NOT_BOOL = "E0410", Error, "`when` that is not a condition";
    ROS2_UNMAPPED_EVENT = "W0411", Warning, "event of a mapped agent that no map entry produces";
    ROS2_TWO_NODES = "E0412", Error, "agent played by two lifecycle nodes";
    ROS2_TOPIC_TYPES = "E0413", Error, "topic read as two message types";
    ROS2_BAD_NODE = "E0414", Error, "lifecycle node entry the bridge cannot use";
    ROS2_BAD_TOPIC = "E0415", Error, "topic name that is not a fully qualified ROS 2 name";
    ROS2_SHARED_NODE = "E0416", Error, "lifecycle node given to two agents";
    ROS2_DUPLICATE_ENTRY = "W0417", Warning, "map entry that repeats another";
    ROS2_BRIDGE_TOPIC = "E0418", Error, "map that reads the bridge's own `/situ` topics";
    ROS2_ZERO_DIVISION = "E0419", Error, "division by a constant zero in a map expression";
    ROS2_BAD_INDEX = "E0420", Error, "array index in a map expression that is not an integer";
    ROS2_BAD_DEFINITION = "E0422", Error, "ROS 2 message definition that does not load";
    ROS2_BAD_MSG_PATH = "E0423", Error, "`msg_path` folder that is not a folder";
    ROS2_BRIDGE_DIAGNOSTICS = "W0421", Warning, "map that reads `/diagnostics` without naming the reporter";
    VACUOUS_PROPERTY = "W0501", Warning, "property whose premise never holds";
    UNDECIDED_PROPERTY = "E0502", Error, "property neither proved nor violated";
    VIOLATED_PROPERTY = "E0503", Error, "property broken by a run";
    FAILED_TEST = "E0504", Error, "test whose expectations do not hold";
}

/// Whether the code is a property's verdict (E05xx, W05xx: `situ test`,
/// crate `situ-verify`): the checkers raise it, never `situ check`.
pub fn is_verdict(code: &str) -> bool {
    code.get(1..3) == Some("05")
}

/// Whether the code is a ROS 2 map's (E04xx, W04xx: `situ check
/// --ros2-map`, crate `situ-ros2-map`): a map raises it, never rules alone.
pub fn is_ros2_map(code: &str) -> bool {
    code.get(1..3) == Some("04")
}

/// Looks a code up, with or without its `situ::` prefix, in any case.
pub fn lookup(code: &str) -> Option<&'static Code> {
    let code = code.strip_prefix("situ::").unwrap_or(code);
    ALL.iter().find(|c| c.code.eq_ignore_ascii_case(code))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parser_codes_are_registered() {
        use situ_grammar::parse;
        for code in [parse::SYNTAX, parse::TOO_DEEP, parse::BAD_LITERAL, parse::TOO_MANY_ERRORS] {
            assert!(lookup(code).is_some(), "{code} is not in the registry");
        }
    }

    #[test]
    fn every_code_is_unique_and_documented() {
        let mut seen = std::collections::BTreeSet::new();
        for c in ALL {
            assert!(seen.insert(c.code), "{} twice", c.code);
            assert!(c.explain.starts_with(&format!("# {}", c.code)), "{}: doc must start with its code", c.code);
            for section in ["## What it does", "## Why is this bad", "## Example", "## Use instead"] {
                assert!(c.explain.contains(section), "{}: missing `{section}`", c.code);
            }
            let expected_sev = if c.code.starts_with('W') { Severity::Warning } else { Severity::Error };
            assert_eq!(c.severity, expected_sev, "{}: the letter of a code is its severity", c.code);
        }
    }

    #[test]
    fn lookup_accepts_prefix_and_case() {
        assert_eq!(lookup("situ::e0101").map(|c| c.code), Some("E0101"));
        assert!(lookup("E9999").is_none());
    }
}
