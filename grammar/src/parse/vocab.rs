//! How grammar rules are named in messages: the words for a rule, and the
//! literal tokens those words already name (so that a message does not list
//! both). Read by the error report and by the hints; imports neither.

use super::Rule;

/// The literal tokens that a rule's description already names.
pub(crate) fn implied(r: Rule) -> &'static [&'static str] {
    match r {
        Rule::agent_kind => &["sensor", "actuator", "processing", "interface"],
        Rule::field_type => &["f64", "i64", "bool", "{"],
        Rule::run_length => &["x"],
        Rule::string => &["\""],
        Rule::variable => &["?"],
        Rule::frequency => &[".", "Hz"],
        Rule::duration => &[".", "ns", "us", "ms", "s", "min"],
        Rule::state_flag => &["initial", "final"],
        Rule::mode_word => &["running", "sleeping", "waiting"],
        Rule::quantifier => &["always", "never"],
        Rule::range_op => &["..", "..="],
        Rule::cmp_op => &["==", "!=", "<", "<=", ">", ">="],
        Rule::action => &["run", "wait", "sleep"],
        Rule::float | Rule::int | Rule::uint => &[".", "-"],
        Rule::script_at | Rule::script_every | Rule::script_silent | Rule::script_random => {
            &["at", "every", "silent", "random"]
        }
        Rule::given_clause | Rule::on_clause | Rule::expect_clause => &["given", "on", "expect"],
        _ => &[],
    }
}

/// The words for grammar rules in error messages; `None` for rules that only
/// ever appear inside others.
pub(crate) fn describe(r: Rule) -> Option<&'static str> {
    Some(match r {
        Rule::ident => "a name",
        Rule::variable => "a variable (`?name`)",
        Rule::string => "a string",
        Rule::int | Rule::uint => "an integer",
        Rule::float | Rule::non_finite => "a number",
        Rule::duration => "a duration (`200ms`)",
        Rule::frequency => "a frequency (`20Hz`)",
        Rule::literal | Rule::operand => "a value",
        Rule::include => "`include`",
        Rule::states_block => "`states`",
        Rule::agent => "`agent`",
        Rule::rule => "`rule`",
        Rule::test => "`test`",
        Rule::property => "`property`",
        Rule::script => "`script`",
        Rule::script_at | Rule::script_every | Rule::script_silent | Rule::script_random => {
            "a script step (`at`, `every`, `silent`, `random`)"
        }
        Rule::script_event => "an event (`Agent.EVENT(field: value)`)",
        Rule::attribute => "an attribute (`#[allow(...)]`)",
        Rule::state_decl => "a state",
        Rule::state_flag => "a flag (`initial`, `final`)",
        Rule::agent_kind => "an agent kind (`sensor`, `actuator`, `processing` or `interface`)",
        Rule::stale_decl | Rule::rate_decl | Rule::event_decl | Rule::function_decl | Rule::table | Rule::fsm => {
            "an agent member (event, function, stale, rate, table, fsm)"
        }
        Rule::field_decl => "a field (`name: f64`)",
        Rule::field_type => "a type (`f64`, `i64`, `bool` or symbols `{a, b}`)",
        Rule::table_entry | Rule::selector => "a table entry (`RS => run f()`)",
        Rule::action => "an action (`run`, `wait`, `sleep`)",
        Rule::from_links => "`from`",
        Rule::to_links => "`to`",
        Rule::fsm_state | Rule::fsm_transition => "an FSM line",
        Rule::trigger => "a trigger (`state == S` or an event)",
        Rule::salience => "`salience`",
        Rule::condition | Rule::cond_term => "a condition",
        Rule::pattern | Rule::prop_pattern => "an event pattern",
        Rule::state_test => "a state test (`state == S`)",
        Rule::stale_test => "a staleness test (`stale AGENT`)",
        Rule::constraint => "a field constraint",
        Rule::cmp_op => "a comparison (`<`, `==`, ...)",
        Rule::range_op => "`..` or `..=`",
        Rule::run_length => "a run length (`x3`)",
        Rule::window => "`within`",
        Rule::given_clause | Rule::on_clause | Rule::expect_clause => "a clause (`given`, `on`, `expect`)",
        Rule::event_instance => "an event",
        Rule::expectation => "an expectation",
        Rule::mode_word => "a mode (`running`, `sleeping`, `waiting`)",
        Rule::quantifier => "a quantifier (`always`, `never`)",
        Rule::formula | Rule::predicate | Rule::atom => "a predicate",
        Rule::consequent => "a consequent (`next`, `eventually`, or a predicate)",
        Rule::bound => "`within`",
        Rule::EOI => "the end of the item",
        _ => return None,
    })
}
