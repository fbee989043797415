//! Which script a run plays (`script::pick`) and which demo agents a
//! process runs (`demo::agents`): library decisions, typed refusals.

use situ_compiler::loader::FsLoader;
use situ_runtime::demo;
use situ_runtime::script::{pick, PickError};
use std::path::Path;
use std::sync::{Arc, Mutex};

fn mower_scripts() -> Vec<situ_compiler::bundle::spec::ScriptSpec> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/mower/mower.situ");
    let checked = situ_compiler::check(&path, &FsLoader).expect("the mower reads");
    assert_eq!(checked.errors(), 0);
    situ_compiler::spec::scripts(&checked)
}

#[test]
fn the_first_script_unless_one_is_named() {
    let scripts = mower_scripts();
    assert_eq!(pick(&scripts, None).expect("a first script").name, "a day on the lawn");
    assert_eq!(pick(&scripts, Some("an hour of mowing")).expect("named").name, "an hour of mowing");
    let e = pick(&scripts, Some("a night")).expect_err("no such script");
    assert_eq!(
        e,
        PickError::NoSuchScript {
            name: "a night".into(),
            known: vec!["a day on the lawn".into(), "an hour of mowing".into()]
        }
    );
    assert_eq!(e.to_string(), "no script \"a night\"; the scripts are: \"a day on the lawn\", \"an hour of mowing\"");
    assert_eq!(pick(&[], None).err(), Some(PickError::NoScripts));
}

#[test]
fn the_demo_runs_the_agents_it_has_and_names_the_others() {
    let log: demo::Log = Arc::new(Mutex::new(Vec::new()));
    let agents = demo::agents(&["LADAR".into(), "Drive".into()], log.clone()).expect("both are demo agents");
    let names: Vec<&str> = agents.iter().map(|a| a.name()).collect();
    assert_eq!(names, ["LADAR", "Drive"]);
    let e = demo::agents(&["Sonar".into()], log).err().expect("no sonar in the demo");
    assert_eq!(e.missing, "Sonar");
    assert!(e.to_string().starts_with("the demo stack has no agent `Sonar` (it has RFCCD, LADAR"), "{e}");
}
