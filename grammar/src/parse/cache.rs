//! Parsing a file again after an edit, re-parsing only the items the edit
//! touched. An item's parse depends on its text alone, but for where it
//! starts (every span is shifted by that) and the file its errors name: the
//! cache keeps each item's parse at offset 0 of no file, keyed by its text,
//! and hands out a copy moved to where the item is now. An item that moved
//! (an edit above it) keeps its parse.
//!
//! The cache is a value its owner (an editor's language server) holds and
//! passes in; it is bounded: [`ItemCache::end_round`] drops every item not
//! parsed since the previous round, so that it holds about the items of the
//! files of one round (a check of the open documents, say).

use super::{parse_items, parse_one, ItemParse, Parsed};
use crate::diag::FileId;
use crate::shift::{move_diagnostic, Shift};
use std::collections::HashMap;

/// Items' parses by their text, for [`ItemCache::parse`].
#[derive(Debug, Default)]
pub struct ItemCache {
    entries: HashMap<Box<str>, Entry>,
    /// The current round: entries used in it survive its end.
    round: u64,
    /// How many items were parsed (not found here) since the cache was made.
    misses: u64,
}

#[derive(Debug)]
struct Entry {
    /// The parse at offset 0, its errors in `FileId(0)`.
    parse: ItemParse,
    /// The last round this entry was used in.
    round: u64,
}

impl ItemCache {
    pub fn new() -> ItemCache {
        ItemCache::default()
    }

    /// Parses `src` as [`crate::parse`] does, with the same result, parsing
    /// only the items that are not in the cache.
    pub fn parse(&mut self, src: &str, file: FileId) -> Parsed {
        let round = self.round;
        let misses = &mut self.misses;
        let entries = &mut self.entries;
        parse_items(src, file, |text, offset| {
            let entry = match entries.get_mut(text) {
                Some(entry) => entry,
                None => {
                    *misses += 1;
                    let parse = parse_one(text, 0, FileId(0));
                    entries.entry(text.into()).or_insert(Entry { parse, round })
                }
            };
            entry.round = round;
            let mut parse = entry.parse.clone();
            if offset != 0 {
                parse.item.shift(offset);
            }
            for d in &mut parse.errors {
                move_diagnostic(d, offset, file);
            }
            parse
        })
    }

    /// Ends a round: drops every item not parsed since the previous end.
    pub fn end_round(&mut self) {
        let round = self.round;
        self.entries.retain(|_, e| e.round == round);
        self.round += 1;
    }

    /// How many items are kept.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// How many items were parsed because they were not kept, since the
    /// cache was made.
    pub fn misses(&self) -> u64 {
        self.misses
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parse;

    const SRC: &str = "states { IT initial RD }\nagent A sensor { event E(x: f64) }\n\
        rule r1 { when E(x > 1.5) then RD }\nrule r2 { when E(x: ?v) and state == IT then RD }\n";

    fn same(a: &Parsed, b: &Parsed) {
        assert_eq!(a.file, b.file);
        assert_eq!(a.errors, b.errors);
        assert_eq!(a.comments, b.comments);
    }

    #[test]
    fn an_edit_reparses_the_item_it_touches_only() {
        let mut cache = ItemCache::new();
        same(&cache.parse(SRC, FileId(3)), &parse(SRC, FileId(3)));
        assert_eq!(cache.misses(), 4);
        // One more letter in the agent's name: the rules after it move.
        let edited = SRC.replace("agent A ", "agent AB ");
        same(&cache.parse(&edited, FileId(3)), &parse(&edited, FileId(3)));
        assert_eq!(cache.misses(), 5, "one item parsed again");
    }

    #[test]
    fn moved_errors_name_their_place_and_file() {
        let mut cache = ItemCache::new();
        let broken = "rule r { when E then }\nrule s { when then X }\n";
        same(&cache.parse(broken, FileId(1)), &parse(broken, FileId(1)));
        let moved = format!("states {{ A initial }}\n\n{broken}");
        let parsed = cache.parse(&moved, FileId(2));
        same(&parsed, &parse(&moved, FileId(2)));
        assert_eq!(parsed.errors.len(), 2);
        assert!(parsed.errors.iter().all(|d| d.primary.file == FileId(2)));
        assert_eq!(cache.misses(), 3, "only the new item is parsed");
    }

    #[test]
    fn a_round_drops_the_items_it_did_not_see() {
        let mut cache = ItemCache::new();
        cache.parse(SRC, FileId(0));
        cache.end_round();
        assert_eq!(cache.len(), 4);
        cache.parse("rule r9 { when E then RD }", FileId(0));
        cache.end_round();
        assert_eq!(cache.len(), 1, "only the last round's item is kept");
    }
}
