//! Runs without a robot: a rules file on one of its scripts or on the guided
//! random generator (every agent a stand-in that follows its table or FSM),
//! and a recording replayed on a bundle.

use crate::{Error, Program, Trust};
use situ_compiler::bundle::sign::KeyId;
use situ_compiler::bundle::{self, Content, Encoding};
use situ_compiler::spec;
use situ_runtime::record::mcap::read::{attached_bundle, read_recording, Reading};
use situ_runtime::record::mcap::McapRecorder;
use situ_runtime::record::Sink;
use situ_runtime::replay::{replay_reading, ReplayReport};
use situ_runtime::script::report::ScriptReport;
use situ_runtime::script::{pick, Driver, ScriptRun};
use std::path::Path;
use std::sync::Arc;

/// What drives a scripted run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Drive {
    /// The rules' `script` block of this name, or their first one.
    Script(Option<String>),
    /// The guided random generator, from this seed.
    Random(u64),
}

/// Runs a program on a script or on the random generator, in simulated
/// time, to `until` (ns; default: the script's end, or five minutes of
/// random events), recorded to `record` (MCAP, the bundle attached; written
/// beside it and renamed when whole). Scripts are read from the program's
/// source: a bundle carries none.
pub fn run_script(
    program: &Program,
    drive: &Drive,
    until: Option<u64>,
    record: Option<&Path>,
) -> Result<ScriptReport, Error> {
    let driver = match drive {
        Drive::Random(seed) => Driver::Random { seed: *seed },
        Drive::Script(name) => {
            let scripts = program.checked.as_ref().map(spec::scripts).unwrap_or_default();
            Driver::Script(pick(&scripts, name.as_deref())?.clone())
        }
    };
    let write = |source| Error::Write { what: "the run's recording", source };
    let partial = record.map(bundle::file::partial_path);
    let sink: Option<Box<dyn Sink>> = match &partial {
        None => None,
        Some(path) => {
            let bytes = program.bytes.clone().unwrap_or_else(|| bundle::encode(&program.content, Encoding::Json));
            Some(Box::new(McapRecorder::create(path, program.content.clone(), &bytes).map_err(write)?))
        }
    };
    let mut run = ScriptRun::new(program.content.clone(), driver, until, sink);
    run.run(&mut |_| {});
    let report = run.finish().map_err(write)?;
    if let (Some(partial), Some(path)) = (&partial, record) {
        std::fs::rename(partial, path).map_err(write)?;
    }
    Ok(report)
}

/// A recording read and checked whole (up to a cut, for a run that was
/// killed), ready to be replayed on a bundle.
pub struct Recording {
    bytes: Vec<u8>,
    reading: Reading,
}

impl Recording {
    /// Reads a recording's bytes: MCAP, undamaged up to its end or a cut.
    pub fn read(bytes: Vec<u8>) -> Result<Recording, Error> {
        let reading = read_recording(&bytes)?;
        Ok(Recording { bytes, reading })
    }

    /// The messages read (up to the cut, for a recording cut short).
    pub fn messages(&self) -> usize {
        self.reading.messages.len()
    }

    /// Feeds the recorded events to `bundle`, or to the bundle attached to
    /// the recording (verified under `trust`), and says where the states
    /// differ.
    pub fn replay(&self, bundle: Option<Arc<Content>>, trust: &Trust) -> Result<Replayed, Error> {
        let (content, signed_by) = match bundle {
            Some(c) => (c, None),
            None => {
                let bytes = attached_bundle(&self.bytes).ok_or(Error::NoAttachedBundle)?;
                let loaded = crate::load(&bytes, trust).map_err(|e| Error::Attached(Box::new(e)))?;
                (Arc::new(loaded.content), loaded.signer)
            }
        };
        let report = replay_reading(&self.reading, content)?;
        Ok(Replayed { report, signed_by })
    }
}

/// A replay: where the states of the recording and of the bundle differ,
/// and, for a bundle attached to the recording and verified under a policy
/// that asks for signatures, the key that signed it.
#[derive(Debug)]
pub struct Replayed {
    pub report: ReplayReport,
    pub signed_by: Option<KeyId>,
}

/// [`Recording::read`] then [`Recording::replay`].
pub fn replay(recording: &[u8], bundle: Option<Arc<Content>>, trust: &Trust) -> Result<Replayed, Error> {
    Recording::read(recording.to_vec())?.replay(bundle, trust)
}
