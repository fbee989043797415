use super::*;
use crate::text::path_to_uri;
use situ_verify::explore::Limits;
use situ_verify::property::Engines;
use situ_verify::random::Search;

const FIXTURE: &str = include_str!("../../tests/fixtures/verdicts.situ");

/// The budget under which the fixture's ladder is undecided.
const TINY: property::Options = property::Options {
    engines: Engines::Both,
    search: Search { seed: 1, cases: 8, length: 3 },
    limits: Limits { depth: 2, max_states: 1_000 },
    effort: 100_000,
    timeout: None,
};

/// A world with the fixture open, checked, its verdicts asked for.
fn opened(name: &str, text: &str) -> (World, PathBuf) {
    let path = PathBuf::from(format!("/nonexistent/situ-lsp/{name}.situ"));
    let mut w = World::default();
    w.verdicts.settings.options = TINY;
    w.open(path.clone(), Doc::new(path_to_uri(&path), text.into(), 1));
    w.verdicts.want(path.clone());
    w.refresh_fully();
    (w, path)
}

fn titles(w: &World, path: &Path) -> Vec<(u32, String)> {
    lenses(w, path).into_iter().map(|l| (l.range.start.line, l.title)).collect()
}

fn line_of(text: &str, needle: &str) -> u32 {
    text[..text.find(needle).unwrap_or_else(|| panic!("no {needle}"))].matches('\n').count() as u32
}

#[test]
fn each_verdict_is_a_lens_and_a_finding_with_the_codes_of_sarif() {
    let (mut w, path) = opened("kinds", FIXTURE);
    assert!(lenses(&w, &path).is_empty(), "nothing before a run");
    let runs = start(&mut w);
    assert_eq!(runs.len(), 1);
    let running = titles(&w, &path);
    assert_eq!(running.len(), 5, "{running:?}");
    assert!(running.iter().all(|(_, t)| t == "running…"), "{running:?}");
    let names: Vec<Range> = lenses(&w, &path).iter().map(|l| l.range).collect();
    let outcome = runs[0].run();
    let current = w.generation(&path);
    assert!(w.verdicts.accept(&path, runs[0].generation, current, outcome));
    let at = |needle: &str| line_of(FIXTURE, needle);
    let got = titles(&w, &path);
    assert_eq!(got[0], (at("property \"the lamp"), "proved (IC3)".into()), "{got:?}");
    assert_eq!(
        got[1],
        (at("property \"the first step"), "violated: 1 event (exhaustive exploration): append as a test".into())
    );
    assert_eq!(got[2], (at("property \"vacuous\""), "proved (IC3), vacuous: the premise never holds".into()));
    assert_eq!(
        got[3],
        (
            at("property \"the top"),
            "undecided: explored 2 events, IC3 stopped at 3 events (work budget), 8 random runs".into()
        )
    );
    assert_eq!(got[4].0, at("test \"one step"));
    let done: Vec<Range> = lenses(&w, &path).iter().map(|l| l.range).collect();
    assert_eq!(names, done, "at the same places, the names, running or done");
    assert!(got[4].1.starts_with("failed: "), "{got:?}");

    let uri = path_to_uri(&path);
    let found = &crate::diagnostics::all(&w)[&uri];
    let (_, found) = found.as_ref().expect("complete");
    let code = |c: &str| found.iter().filter(|f| f.code == c).collect::<Vec<_>>();
    let (violated, undecided, vacuous, failed) = (code("E0503"), code("E0502"), code("W0501"), code("E0504"));
    assert_eq!((violated.len(), undecided.len(), vacuous.len(), failed.len()), (1, 1, 1, 1), "{found:?}");
    assert!(violated[0].error && !undecided[0].error && !vacuous[0].error && failed[0].error);
    assert_eq!(violated[0].range.start.line, at("property \"the first step"));
    assert!(violated[0].message.contains("test \"counterexample: the first step is never taken\""));
    assert!(violated[0].related[0].1.starts_with("the run (exhaustive exploration, shortest):\n  start"));
    assert!(undecided[0].message.contains("symbolic: gave up at its work budget"), "{}", undecided[0].message);
    assert_eq!(failed[0].range.start.line, at("test \"one step"));
}

#[test]
fn the_appended_counterexample_parses_and_replays_the_run() {
    let (mut w, path) = opened("append", FIXTURE);
    let runs = start(&mut w);
    let current = w.generation(&path);
    assert!(w.verdicts.accept(&path, runs[0].generation, current, runs[0].run()));
    let insert = lenses(&w, &path).into_iter().find_map(|l| l.insert).expect("the violated property's");
    assert_eq!(insert.version, Some(1));
    let end = w.docs[&path].lines.range(FIXTURE, Span { start: FIXTURE.len(), end: FIXTURE.len() }).end;
    assert_eq!(insert.edit.range, Range { start: end, end });
    assert!(insert.edit.new_text.starts_with("\ntest \"counterexample: the first step is never taken\" {\n"));
    // The code action on the property carries the same edit.
    let actions = code_actions(&w, &path, lenses(&w, &path)[1].range);
    assert_eq!(actions.len(), 1);
    assert_eq!(actions[0].edit[&insert.uri], vec![insert.edit.clone()]);
    assert_eq!(actions[0].finding.code, "E0503");

    // Applied and saved, the block is a test that passes: the run reaches
    // the state the counterexample says; the property is still violated.
    let text = format!("{FIXTURE}{}", insert.edit.new_text);
    w.docs.insert(path.clone(), Doc::new(path_to_uri(&path), text.clone(), 2));
    w.touch(&path);
    w.verdicts.want(path.clone());
    w.refresh_fully();
    assert_eq!(w.analyses[&path].checked.errors(), 0, "{:?}", w.analyses[&path].checked.diagnostics);
    let runs = start(&mut w);
    let current = w.generation(&path);
    assert!(w.verdicts.accept(&path, runs[0].generation, current, runs[0].run()));
    let got = titles(&w, &path);
    assert_eq!(got.len(), 6);
    assert_eq!(got[5], (line_of(&text, "test \"counterexample"), "passed".into()));
    assert!(got[1].1.starts_with("violated: 1 event "), "{got:?}");
}

#[test]
fn a_run_overtaken_by_an_edit_or_a_newer_run_is_dropped() {
    let (mut w, path) = opened("stale", FIXTURE);
    let old = start(&mut w).remove(0);
    w.touch(&path); // an edit
    let current = w.generation(&path);
    assert!(!w.verdicts.accept(&path, old.generation, current, old.run()));
    assert!(lenses(&w, &path).is_empty(), "the verdicts of another text are not shown");
    // Saved: a newer run; the older one's result still comes in late.
    w.verdicts.want(path.clone());
    w.refresh_fully();
    let new = start(&mut w).remove(0);
    assert!(!w.verdicts.accept(&path, old.generation, current, old.run()));
    assert!(lenses(&w, &path).iter().all(|l| l.title == "running…"));
    assert!(w.verdicts.accept(&path, new.generation, current, new.run()));
    assert_eq!(lenses(&w, &path)[0].title, "proved (IC3)");
}

#[test]
fn nothing_runs_without_properties_or_tests_with_errors_or_when_disabled() {
    let (mut w, _) = opened("none", crate::world::SMALL);
    assert!(start(&mut w).is_empty());
    let (mut w, _) = opened("errors", &FIXTURE.replace("then S1", "then S9"));
    assert!(start(&mut w).is_empty());
    let (mut w, path) = opened("disabled", FIXTURE);
    w.verdicts.settings.enabled = false;
    assert!(start(&mut w).is_empty());
    assert!(lenses(&w, &path).is_empty());
}

#[test]
fn the_editor_budget_is_smaller_than_situ_tests() {
    let (e, d) = (EDITOR_OPTIONS, property::DEFAULT_OPTIONS);
    assert!(e.effort < d.effort && e.limits.max_states < d.limits.max_states && e.search.cases < d.search.cases);
    assert!(e.limits.depth < d.limits.depth && e.search.length < d.search.length);
}
