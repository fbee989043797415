//! The registry of live handles. A handle given to C is a slot's index and
//! the slot's generation packed into a pointer-sized number, never an
//! address: situ never dereferences it. Freeing a handle bumps its slot's
//! generation, so a freed handle (even after its slot is reused), a number
//! that was never a handle, and a handle of another kind are all answered
//! with `SITU_ERR_HANDLE`. Not detected: a handle forged to equal a live
//! one, and a slot reused 2^32 times (2^16 on 32-bit targets) between a
//! free and a stale use.
//!
//! Each item is behind an `Arc`: a call clones it out of the registry and
//! works without holding the registry's lock, so a callback may free the
//! board whose call is running it (the call finishes on its own clone).

use crate::error::{situ_status, Failure};
use std::any::Any;
use std::sync::{Arc, Mutex, MutexGuard};

/// What a handle holds: an item of some [`Kind`].
type Item = Arc<dyn Any + Send + Sync>;

/// A kind of item: how it is named in errors. Each kind is declared beside
/// its item (a program, a board, a view), so the registry knows none of them.
pub(crate) trait Kind: Any + Send + Sync {
    const WHAT: &'static str;
}

struct Slot {
    generation: usize,
    item: Option<Item>,
}

struct Registry {
    slots: Vec<Slot>,
    free: Vec<usize>,
    live: usize,
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry { slots: Vec::new(), free: Vec::new(), live: 0 });

const HALF: u32 = usize::BITS / 2;
const LOW: usize = (1 << HALF) - 1;

fn registry() -> MutexGuard<'static, Registry> {
    // Nothing panics while the lock is held: a poisoned lock holds a whole registry.
    REGISTRY.lock().unwrap_or_else(|e| e.into_inner())
}

fn encode(index: usize, generation: usize) -> usize {
    (generation << HALF) | (index + 1)
}

/// Registers an item; its handle.
pub(crate) fn insert<T: Kind>(value: T) -> usize {
    let mut r = registry();
    let index = match r.free.pop() {
        Some(i) => i,
        None if r.slots.len() < LOW - 1 => {
            r.slots.push(Slot { generation: 1, item: None });
            r.slots.len() - 1
        }
        // More live handles than a slot index can name: a caller that
        // never frees. Refusing needs a status; this is far past any use.
        None => panic!("more than {} live situ handles", LOW - 1),
    };
    r.slots[index].item = Some(Arc::new(value));
    r.live += 1;
    encode(index, r.slots[index].generation)
}

fn unknown<T: Kind>() -> Failure {
    Failure::new(
        situ_status::SITU_ERR_HANDLE,
        format!("not a live {}: freed already, never made by situ, or a handle of another kind", T::WHAT),
    )
}

/// The slot index of a live handle of kind `T`.
fn find<T: Kind>(r: &Registry, handle: usize) -> Result<usize, Failure> {
    if handle == 0 {
        return Err(Failure::new(situ_status::SITU_ERR_NULL, format!("the {} is null", T::WHAT)));
    }
    let (index, generation) = ((handle & LOW).wrapping_sub(1), handle >> HALF);
    match r.slots.get(index) {
        Some(Slot { generation: g, item: Some(item) }) if *g == generation && (**item).is::<T>() => Ok(index),
        _ => Err(unknown::<T>()),
    }
}

/// The item of a live handle of kind `T`.
pub(crate) fn get<T: Kind>(handle: usize) -> Result<Arc<T>, Failure> {
    let r = registry();
    let index = find::<T>(&r, handle)?;
    let item = r.slots[index].item.clone().expect("found above");
    item.downcast::<T>().map_err(|_| unknown::<T>())
}

/// Frees a handle of kind `T`; a null handle is nothing to free.
pub(crate) fn remove<T: Kind>(handle: usize) -> Result<(), Failure> {
    if handle == 0 {
        return Ok(());
    }
    let item = {
        let mut r = registry();
        let index = find::<T>(&r, handle)?;
        let slot = &mut r.slots[index];
        // The generation has HALF bits; 0 is never a live generation.
        slot.generation = (slot.generation + 1) & LOW;
        if slot.generation == 0 {
            slot.generation = 1;
        }
        let item = slot.item.take();
        r.free.push(index);
        r.live -= 1;
        item
    };
    // Dropped outside the lock: a board's drop is the board's work.
    drop(item);
    Ok(())
}

/// How many handles are live.
pub(crate) fn live() -> usize {
    registry().live
}
