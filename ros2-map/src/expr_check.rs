//! The checks of map expressions that are not about fields or types: a
//! division by a constant zero (E0419) and an index that is not an integer
//! (E0420). One function per check, each returning all its findings; they
//! are registered in [`crate::check`].

use crate::map::Map;
use crate::msgs::Registry;
use crate::types::{type_of, Typed};
use situ_compiler::model::Model;
use situ_grammar::diag::{Diagnostic, FileId};

/// Every expression of the map whose message type is known, typed.
fn typed<'a>(map: &'a Map, msgs: &'a Registry, file: FileId) -> impl Iterator<Item = Typed> + 'a {
    map.events.iter().flat_map(move |e| {
        let msg = msgs.lookup(&e.ty.value);
        let texts = e.when.iter().chain(e.payload.iter().map(|(_, v)| v));
        texts.filter_map(move |t| Some(type_of(t, msg?, msgs, file)))
    })
}

/// E0419: `x / 0`, `x / (1 - 1)`: a value never defined.
pub fn zero_divisions(_: &Model, map: &Map, msgs: &Registry, file: FileId) -> Vec<Diagnostic> {
    typed(map, msgs, file).flat_map(|t| t.zero_divisions).collect()
}

/// E0420: `status[0.0]`, `status['motor']`, `status[true]`.
pub fn non_integer_indexes(_: &Model, map: &Map, msgs: &Registry, file: FileId) -> Vec<Diagnostic> {
    typed(map, msgs, file).flat_map(|t| t.indexes).collect()
}
