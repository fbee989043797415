//! Pictures, as Graphviz DOT text: the state transition graph (from the
//! static checks' transitions), the wiring graph of each state and the Rete
//! network (from a bundle). `situ graph` prints them or lays them out to SVG.
//!
//! One file per view: [`states`], [`wiring`], [`rete`]. The DOT is written
//! for two layout engines at once: Graphviz's `dot` (what `situ graph`
//! runs when it is installed: its layered layout with crossing reduction
//! is what keeps the states picture of a real rule file nearly free of
//! crossings and its labels on their edges) and the pure-Rust `layout-rs`
//! fallback, which keeps only shapes, fill colours, pen colours and
//! labels. So every distinction a picture makes (initial, final,
//! unreachable and trap states; running, waiting and sleeping agents;
//! shared Rete nodes) is carried by a fill colour and by a word in the
//! label, and only reinforced by borders (bold, double, dashed) that
//! Graphviz alone draws. Every picture has a title and a legend.
//!
//! Pure: no I/O and no process here (invariant 3); running `dot` is the
//! command line's business.

mod fsm;
mod rete;
mod states;
mod wiring;

pub use fsm::possible as fsm_possible;
pub use rete::rete;
pub use situ_bundle::Moment;
pub use states::{bundle_states, states, StateKind};
pub use wiring::{wiring, wiring_cell, wiring_legend, wiring_moment};

/// A DOT string literal.
pub(crate) fn q(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\"").replace('\n', "\\n"))
}

/// The attributes every picture starts with: one font, text of 14 pt.
pub(crate) fn header(name: &str, rankdir: &str, title: &str) -> String {
    format!(
        "digraph {name} {{\n  rankdir={rankdir};\n  fontname=\"Helvetica\";\n  fontsize=18;\n  labelloc=t;\n  label={};\n  \
         node [fontname=\"Helvetica\", fontsize=14];\n  edge [fontname=\"Helvetica\", fontsize=12];\n",
        q(title)
    )
}

/// A legend: a cluster of sample nodes, one per `(label, attributes)`,
/// chained by invisible edges so that it reads as one column or row.
pub(crate) fn legend(out: &mut String, entries: &[(String, String)]) {
    if entries.is_empty() {
        return;
    }
    out.push_str(
        "  subgraph cluster_legend {\n    label=\"legend\";\n    fontsize=14;\n    style=\"rounded\";\n    color=\"#9e9e9e\";\n",
    );
    for (i, (label, attrs)) in entries.iter().enumerate() {
        out.push_str(&format!("    legend{i} [label={}, {attrs}];\n", q(label)));
    }
    out.push_str("  }\n");
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check_source;
    use crate::checks::transitions::Transitions;

    const SRC: &str = "states { IT initial RS RO GL final LOST TRAP }
        agent LADAR sensor { event LAOBS { distance: f64 } event LAOBN function detect table { RO => run detect() to Fusion  _ => wait detect() } }
        agent Fusion processing { function fuse table { RO => run fuse() from LADAR  _ => sleep } }
        rule go { when state == IT and LAOBN then RS }
        rule obstacle { when state == RS and LAOBS(distance < 30.0) then RO }
        rule clear { when state == RO and LAOBN x3 then RS }
        rule done { when state == RS and LAOBN x9 then GL }
        rule stuck { when state == RO and LAOBS(distance < 1.0) then TRAP }
        rule stop1 { when state in {IT, RS, RO, TRAP} and LAOBS(distance < 0.1) then GL }
        rule stop2 { when state in {IT, RS, RO, TRAP} and LAOBS(distance < 0.2) then GL }";

    fn states_dot(src: &str) -> String {
        let c = check_source("t.situ", src);
        let tr = Transitions::build(&c.model);
        states(&c.model, &tr, "t.situ", &c.diagnostics)
    }

    #[test]
    fn the_states_view_marks_every_kind_of_state() {
        let dot = states_dot(
            &SRC.replace("rule stop1 { when state in {IT, RS, RO, TRAP}", "rule stop1 { when state in {IT, RS, RO}")
                .replace("rule stop2 { when state in {IT, RS, RO, TRAP}", "rule stop2 { when state in {IT, RS, RO}"),
        );
        assert!(dot.contains("\"LOST\" [label=\"LOST\\nunreachable\""), "{dot}");
        assert!(dot.contains("\"IT\" [label=\"IT\\ninitial\""), "{dot}");
        assert!(dot.contains("\"GL\" [label=\"GL\\nfinal\""), "{dot}");
        assert!(dot.contains("\"TRAP\" [label=\"TRAP\\ntrap: no way out\""), "{dot}");
        assert!(dot.contains("\"RS\" -> \"RO\" [label=\"obstacle\""), "{dot}");
        // The legend names only the kinds drawn.
        assert!(dot.contains("cluster_legend") && !dot.contains("dead end"), "{dot}");
    }

    #[test]
    fn rules_that_leave_many_states_are_drawn_once_from_a_group() {
        let dot = states_dot(SRC);
        assert!(dot.contains("\"any:IT,RS,RO,TRAP\" [label=\"from any of\\nIT RS RO TRAP\""), "{dot}");
        assert!(dot.contains("\"any:IT,RS,RO,TRAP\" -> \"GL\" [label=\"stop1\\nstop2\""), "{dot}");
        assert!(!dot.contains("\"IT\" -> \"GL\""), "{dot}");
        // One edge per pair of states.
        let c = check_source("t.situ", SRC);
        assert_eq!(dot.matches("\"RS\" -> \"GL\"").count(), 1, "{dot}");
        assert!(c.diagnostics.iter().any(|d| d.code == "E0301"));
    }

    #[test]
    fn a_states_picture_of_a_file_with_errors_draws_what_resolved() {
        let dot = states_dot(&format!("{SRC}\nrule broken {{ when state == RS and NOSUCH then RO }}"));
        assert!(dot.contains("\"RS\" -> \"RO\""), "{dot}");
        assert!(dot.contains("1 error"), "{dot}");
    }

    #[test]
    fn the_wiring_view_shows_modes_links_a_title_and_a_legend() {
        let c = check_source("t.situ", SRC);
        let content = crate::bundle::build(&c);
        let ro = content.state_id("RO").unwrap();
        let dot = wiring(&content, Some(ro));
        assert!(dot.contains("\"LADAR\" -> \"Fusion\";"), "{dot}");
        assert!(dot.contains("label=\"Wiring in RO\""), "{dot}");
        assert!(dot.contains("cluster_legend"), "{dot}");
        let rs = wiring(&content, Some(content.state_id("RS").unwrap()));
        assert!(!rs.contains("\"LADAR\" -> "), "{rs}");
        assert!(rs.contains("sleeping") && rs.contains("waiting"), "{rs}");
        assert!(wiring(&content, None).contains("subgraph \"cluster_RO\""));
        let cell = wiring_cell(&content, content.state_id("RS").unwrap());
        assert!(cell.contains("sleeping: Fusion"), "{cell}");
    }

    #[test]
    fn the_states_of_a_bundle_are_drawn_with_the_changes_recorded() {
        let c = check_source("t.situ", SRC);
        let content = crate::bundle::build(&c);
        let dot = bundle_states(&content, [("IT", "RS"), ("RS", "RO"), ("IT", "RS")]);
        assert!(
            dot.contains(
                "label=\"t.situ: 6 states (the transitions need the .situ source; edges: the changes recorded)\""
            ),
            "{dot}"
        );
        assert!(dot.contains("\"IT\" [label=\"IT\", fillcolor=\"#c8e6c9\", penwidth=3];"), "{dot}");
        assert!(dot.contains("\"GL\" [label=\"GL\", fillcolor=\"#bbdefb\", peripheries=2];"), "{dot}");
        assert_eq!(dot.matches("\"IT\" -> \"RS\";").count(), 1, "{dot}");
        assert!(dot.contains("\"RS\" -> \"RO\";"), "{dot}");
        let bare = bundle_states(&content, []);
        assert!(bare.contains("(the transitions need the .situ source)") && !bare.contains("->"), "{bare}");
    }

    #[test]
    fn the_rete_view_names_tests_and_rules_one_row_each() {
        let c = check_source("t.situ", SRC);
        let content = crate::bundle::build(&c);
        let dot = rete(&content, "t.situ");
        assert!(dot.contains("LAOBS(distance < 30.0)"), "{dot}");
        assert!(dot.contains("LAOBN x3"), "{dot}");
        assert!(dot.contains("obstacle → RO"), "{dot}");
        assert!(dot.contains("rank=sink"), "{dot}");
    }
}
