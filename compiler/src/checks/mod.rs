//! Static checks over the checked [`Model`](crate::model::Model): the
//! semantic layer they share. [`domain`] decides constant payload
//! constraints exactly; [`situation`] turns rule conditions into sets of
//! working memories, meets them, and finds a concrete witness memory.

pub mod domain;
pub mod situation;

#[cfg(test)]
mod tests;
