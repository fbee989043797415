//! situ as a library: the operations a user performs on situation rules
//! (check, format, build, load, test, run on a script, replay),
//! with typed options, results and errors. The command line (`situ`) is a
//! client of this crate, as the Python package and the C API are: it parses
//! arguments, calls these functions, prints what they return and maps
//! [`Error`] to exit codes. Nothing here prints.
//!
//! ```
//! let checked = situ_api::check(situ_api::Input::Text {
//!     name: "door.situ",
//!     text: "states { Closed initial Open }\n\
//!            agent Door sensor { event OPENED }\n\
//!            rule opened { when state == Closed and OPENED then Open }\n",
//! })?;
//! assert_eq!(checked.errors(), 0);
//! let bundle = situ_api::build(&checked, &situ_api::BuildOptions::default())?;
//! let program = situ_api::load(&bundle.bytes, &situ_api::Trust::Any)?;
//! assert_eq!(program.content.states.len(), 2);
//! # Ok::<(), situ_api::Error>(())
//! ```

mod board;
mod error;
mod program;
mod runs;
mod suite;

pub use board::{
    AgentNow, Arg, Board, BoardError, Change, Clock, Counters, Fact, FactNow, FieldValue, Fields, Fired, Posted,
    Refusal, Reloaded, Why,
};
pub use error::Error;
pub use program::{
    build, check, findings_json, format, is_source, load, load_path, BuildOptions, Built, Input, Program,
};
pub use runs::{replay, run_script, Drive, Recording, Replayed};
pub use situ_compiler::bundle::{Content, Encoding, Loaded, Trust};
pub use situ_compiler::{Checked, Diagnostic, Severity};
pub use situ_runtime::replay::ReplayReport;
pub use situ_runtime::script::report::ScriptReport;
pub use situ_verify::suite::FileOutcome;
pub use suite::{blocks, test, test_records, Block, SuiteReport, TestOptions, Verdict};
